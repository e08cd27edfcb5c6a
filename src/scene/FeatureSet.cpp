#include "scene/FeatureSet.h"

#include "shared/Bindings.h"
#include "shared/SceneTypes.h"

namespace vkrt {

namespace {

constexpr MaterialType kAllMaterialTypes[] = {MaterialType::Lambert, MaterialType::Phong, MaterialType::Mirror,
                                              MaterialType::Glossy, MaterialType::Dielectric};

/// Each optional feature: its flag, its define, the binding it needs, its name.
struct OptionalFeature {
    bool FeatureSet::*flag;
    const char* define;
    int binding; // -1: no buffer of its own
    const char* name;
};

constexpr OptionalFeature kOptionalFeatures[] = {
    {&FeatureSet::spheres, "VKRT_HAS_SPHERES", int(gpu::BINDING_SPHERES), "spheres"},
    {&FeatureSet::boxes, "VKRT_HAS_BOXES", int(gpu::BINDING_BOXES), "boxes"},
    {&FeatureSet::triangles, "VKRT_HAS_TRIANGLES", int(gpu::BINDING_TRIANGLES), "triangles"},
    {&FeatureSet::planes, "VKRT_HAS_PLANES", int(gpu::BINDING_PLANES), "planes"},
    {&FeatureSet::pointLights, "VKRT_HAS_POINT_LIGHTS", int(gpu::BINDING_POINT_LIGHTS), "point-lights"},
    {&FeatureSet::triangleLights, "VKRT_HAS_TRIANGLE_LIGHTS", int(gpu::BINDING_TRIANGLE_LIGHTS), "triangle-lights"},
    {&FeatureSet::cubemap, "VKRT_HAS_CUBEMAP", int(gpu::BINDING_ENVIRONMENT), "cubemap"},
    {&FeatureSet::environmentSampling, "VKRT_ENVIRONMENT_SAMPLING", int(gpu::BINDING_ENVIRONMENT_CDF),
     "environment-sampling"},
    {&FeatureSet::variance, "VKRT_VARIANCE", int(gpu::BINDING_MOMENTS), "variance"},
    {&FeatureSet::sobolSampler, "VKRT_SAMPLER_SOBOL", -1, "sobol"},
};

std::string upper(std::string text)
{
    for (char& c : text) c = char(std::toupper(static_cast<unsigned char>(c)));
    return text;
}

} // namespace

std::string integratorName(Integrator integrator) { return integrator == Integrator::Path ? "path" : "whitted"; }

std::string materialTypeName(MaterialType type)
{
    switch (type) {
    case MaterialType::Lambert: return "lambert";
    case MaterialType::Phong: return "phong";
    case MaterialType::Mirror: return "mirror";
    case MaterialType::Glossy: return "glossy";
    case MaterialType::Dielectric: return "dielectric";
    }
    return "unknown";
}

FeatureSet FeatureSet::everything(Integrator integrator)
{
    FeatureSet all;
    for (const auto& feature : kOptionalFeatures) all.*feature.flag = true;
    all.variance = false; // render options, not scene content
    all.sobolSampler = false;
    all.environmentSampling = integrator == Integrator::Path;
    all.materialTypes.fill(true);
    all.integrator = integrator;
    return all;
}

FeatureSet featuresOf(const Scene& scene)
{
    FeatureSet set;
    set.spheres = !scene.spheres.empty();
    set.boxes = !scene.boxes.empty();
    set.triangles = !scene.triangles.empty();
    set.planes = !scene.planes.empty();
    set.pointLights = !scene.pointLights.empty();
    set.triangleLights = !scene.triangleLights.empty();
    set.cubemap = scene.background.cubemap.has_value();
    set.environmentSampling = set.cubemap && scene.render.integrator == Integrator::Path;
    set.integrator = scene.render.integrator;
    set.uniformScene = sceneFitsUniformBuffers(scene);
    auto markUsed = [&](uint32_t material) { set.materialTypes[size_t(scene.materials[material].type)] = true; };
    for (const auto& s : scene.spheres) markUsed(s.material);
    for (const auto& b : scene.boxes) markUsed(b.material);
    for (const auto& t : scene.triangles) markUsed(t.material);
    for (const auto& p : scene.planes) markUsed(p.material);
    return set;
}

bool sceneFitsUniformBuffers(const Scene& scene)
{
    // Triangle lights count before zero-area ones are dropped: an upper bound.
    return scene.materials.size() <= gpu::UNIFORM_MATERIALS && scene.spheres.size() <= gpu::UNIFORM_SPHERES &&
           scene.boxes.size() <= gpu::UNIFORM_BOXES && scene.triangles.size() <= gpu::UNIFORM_TRIANGLES &&
           scene.planes.size() <= gpu::UNIFORM_PLANES && scene.pointLights.size() <= gpu::UNIFORM_POINT_LIGHTS &&
           scene.triangleLights.size() <= gpu::UNIFORM_TRIANGLE_LIGHTS;
}

bool FeatureSet::isUniformBinding(uint32_t binding) const
{
    if (binding == gpu::BINDING_UNIFORMS) return true;
    bool sceneArray = binding == gpu::BINDING_MATERIALS || binding == gpu::BINDING_SPHERES ||
                      binding == gpu::BINDING_BOXES || binding == gpu::BINDING_TRIANGLES ||
                      binding == gpu::BINDING_PLANES || binding == gpu::BINDING_POINT_LIGHTS ||
                      binding == gpu::BINDING_TRIANGLE_LIGHTS;
    return uniformScene && sceneArray;
}

std::vector<std::pair<std::string, std::string>> FeatureSet::defines() const
{
    std::vector<std::pair<std::string, std::string>> result;
    result.emplace_back("VKRT_INTEGRATOR_" + upper(integratorName(integrator)), "1");
    if (anyPrimitive()) result.emplace_back("VKRT_HAS_MATERIALS", "1");
    for (const auto& feature : kOptionalFeatures)
        if (this->*feature.flag) result.emplace_back(feature.define, "1");
    for (MaterialType type : kAllMaterialTypes)
        if (has(type)) result.emplace_back("VKRT_MATERIAL_" + upper(materialTypeName(type)), "1");
    if (uniformScene) result.emplace_back("VKRT_UNIFORM_SCENE", "1");
    // Variance under the Sobol' sampler comes from independently scrambled batches.
    if (variance && sobolSampler) result.emplace_back("VKRT_SOBOL_BATCHES", std::to_string(gpu::VARIANCE_BATCHES));
    return result;
}

std::vector<uint32_t> FeatureSet::bindings() const
{
    std::vector<uint32_t> result = {gpu::BINDING_UNIFORMS, gpu::BINDING_ACCUMULATION, gpu::BINDING_STATS};
    if (anyPrimitive()) result.push_back(gpu::BINDING_MATERIALS);
    for (const auto& feature : kOptionalFeatures)
        if (this->*feature.flag && feature.binding >= 0) result.push_back(uint32_t(feature.binding));
    return result;
}

std::string FeatureSet::describe() const
{
    std::string text = integratorName(integrator) + ";";
    for (const auto& feature : kOptionalFeatures)
        if (this->*feature.flag) text += std::string(" ") + feature.name;
    text += ";";
    for (MaterialType type : kAllMaterialTypes)
        if (has(type)) text += " " + materialTypeName(type);
    text += uniformScene ? "; uniform-scene" : "; storage-scene";
    return text;
}

} // namespace vkrt
