#include "render/KernelVariant.h"

#include "shared/Bindings.h"
#include "shared/SceneTypes.h"

#include <algorithm>
#include <cctype>

namespace vkrt {

namespace {

/// A feature of the variant that is on or off: its define, its binding, its name.
struct OptionalFeature {
    bool on;
    std::string define;
    int binding; // -1: no buffer of its own
    std::string name;
};

/// Every optional feature in the stable order of defines, bindings and descriptions:
/// the shape and light arrays (from the registry), the environment, then render options.
std::vector<OptionalFeature> optionalFeatures(const KernelVariant& v)
{
    const FeatureSet& f = v.features;
    std::vector<OptionalFeature> list;
#define VKRT_SHAPE_FEATURE(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    list.push_back(                                                                         \
        {f.has(ShapeKind::Type), "VKRT_HAS_" #ARRAY, int(gpu::BINDING_##ARRAY), featureName(ShapeKind::Type)});
#define VKRT_LIGHT_FEATURE(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    list.push_back(                                                                         \
        {f.has(LightKind::Type), "VKRT_HAS_" #ARRAY, int(gpu::BINDING_##ARRAY), featureName(LightKind::Type)});
    VKRT_SHAPE_KINDS(VKRT_SHAPE_FEATURE)
    VKRT_LIGHT_KINDS(VKRT_LIGHT_FEATURE)
#undef VKRT_SHAPE_FEATURE
#undef VKRT_LIGHT_FEATURE
    // Meshes: the geometry buffers and the top-level BVH come with the mesh
    // array; the driver backend has its own structures instead of the BVHs.
    const bool meshes = f.has(ShapeKind::Mesh);
    const bool ownBvh = meshes && !v.driverAccel;
    list.push_back({ownBvh, "VKRT_HAS_MESH_NODES", int(gpu::BINDING_MESH_NODES), ""});
    list.push_back({meshes, "VKRT_HAS_MESH_TRIANGLES", int(gpu::BINDING_MESH_TRIANGLES), ""});
    list.push_back({ownBvh, "VKRT_HAS_TOP_NODES", int(gpu::BINDING_TOP_NODES), ""});
    list.push_back({ownBvh, "VKRT_HAS_TOP_REFS", int(gpu::BINDING_TOP_REFS), ""});
    list.push_back({v.driverAccel, "VKRT_ACCEL_DRIVER", int(gpu::BINDING_TOP_LEVEL), "driver-accel"});
    list.push_back({meshes && f.meshNormals, "VKRT_HAS_MESH_NORMALS", int(gpu::BINDING_MESH_NORMALS), "mesh-normals"});
    list.push_back({f.emitters, "VKRT_HAS_EMITTERS", int(gpu::BINDING_EMITTERS), "emitters"});
    list.push_back({f.lightTable, "VKRT_LIGHT_TABLE", int(gpu::BINDING_LIGHT_TABLE), "light-table"});
    // Textures: the texel buffer, the texture records and each material's slots;
    // meshes add their triangles' uvs, tangents for normal maps, and each
    // triangle's material when they use their file's materials.
    list.push_back({f.textures, "VKRT_HAS_TEXTURES", int(gpu::BINDING_TEXTURE_TEXELS), "textures"});
    list.push_back({f.textures, "VKRT_HAS_TEXTURE_RECORDS", int(gpu::BINDING_TEXTURE_RECORDS), ""});
    list.push_back({f.textures, "VKRT_HAS_MATERIAL_TEXTURES", int(gpu::BINDING_MATERIAL_TEXTURES), ""});
    list.push_back({f.textures && f.normalMaps, "VKRT_HAS_NORMAL_MAPS", -1, "normal-maps"});
    list.push_back({meshes && f.textures, "VKRT_HAS_MESH_UVS", int(gpu::BINDING_MESH_UVS), ""});
    list.push_back({meshes && f.textures && f.secondUvs, "VKRT_HAS_MESH_UVS1", int(gpu::BINDING_MESH_UVS1), "uv1"});
    list.push_back(
        {meshes && f.textures && f.tangentFrames(), "VKRT_HAS_MESH_TANGENTS", int(gpu::BINDING_MESH_TANGENTS), ""});
    // An emission texture is read by the emitters at the mesh triangle's uvs.
    list.push_back({meshes && f.emitters && f.textures && f.emissionTextures, "VKRT_HAS_EMISSION_TEXTURES", -1,
                    "emission-textures"});
    list.push_back(
        {meshes && f.fileMaterials, "VKRT_HAS_MESH_MATERIALS", int(gpu::BINDING_MESH_MATERIALS), "file-materials"});
    list.push_back({meshes && f.vertexColors, "VKRT_HAS_MESH_COLORS", int(gpu::BINDING_MESH_COLORS), "vertex-colors"});
    // Alpha-tested mesh materials (glTF MASK, BLEND): each material's coverage,
    // tested at every candidate triangle hit (lib/alpha.glsl).
    list.push_back({meshes && f.alpha, "VKRT_HAS_ALPHA", int(gpu::BINDING_MATERIAL_ALPHA), "alpha"});
    // The rough plastics' coating tables come with the plastic kind.
    // The glTF extension layers of pbr materials (their sheen table is a material table too).
    const bool pbrLayers = f.has(MaterialType::Pbr) && f.pbrLayers;
    list.push_back({pbrLayers, "VKRT_PBR_LAYERS", -1, "pbr-layers"});
    // Each lobe of the registry (shared/Kinds.h) where some material has it;
    // an anisotropic one also needs the textured variants' tangent frames.
#define VKRT_PBR_LOBE_FEATURE(LOBE, Lobe, name, value)                                                         \
    list.push_back({pbrLayers && f.has(PbrLobe::Lobe) && (PbrLobe::Lobe != PbrLobe::Anisotropy || f.textures), \
                    "VKRT_PBR_" #LOBE, -1, "pbr-" #name});
    VKRT_PBR_LOBES(VKRT_PBR_LOBE_FEATURE)
#undef VKRT_PBR_LOBE_FEATURE
    list.push_back({f.has(MaterialType::Plastic) || (f.has(MaterialType::Pbr) && f.pbrLayers),
                    "VKRT_HAS_MATERIAL_TABLES", int(gpu::BINDING_MATERIAL_TABLES), ""});
    list.push_back({f.thinLens, "VKRT_THIN_LENS", -1, "thin-lens"});
    list.push_back({f.orthographic, "VKRT_ORTHOGRAPHIC", -1, "orthographic"});
    list.push_back({f.cubemap, "VKRT_HAS_CUBEMAP", int(gpu::BINDING_ENVIRONMENT), "cubemap"});
    list.push_back({f.latLong, "VKRT_HAS_LATLONG", int(gpu::BINDING_ENVIRONMENT), "lat-long"});
    list.push_back({f.environmentSampling, "VKRT_ENVIRONMENT_SAMPLING", int(gpu::BINDING_ENVIRONMENT_CDF),
                    "environment-sampling"});
    list.push_back({v.variance, "VKRT_VARIANCE", int(gpu::BINDING_MOMENTS), "variance"});
    list.push_back({v.aov, "VKRT_AOV", int(gpu::BINDING_AOVS), "aov"});
    list.push_back({v.sobolSampler, "VKRT_SAMPLER_SOBOL", -1, "sobol"});
    return list;
}

std::string upper(std::string text)
{
    for (char& c : text) c = char(std::toupper(static_cast<unsigned char>(c)));
    return text;
}

} // namespace

const std::vector<SceneArrayBinding>& sceneArrayBindings()
{
#define VKRT_ARRAY_BINDING(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    SceneArrayBinding{gpu::BINDING_##ARRAY, gpu::UNIFORM_##ARRAY},
    static const std::vector<SceneArrayBinding> bindings{SceneArrayBinding{gpu::BINDING_MATERIALS,
                                                                           gpu::UNIFORM_MATERIALS},
                                                         VKRT_SHAPE_KINDS(VKRT_ARRAY_BINDING)
                                                             VKRT_LIGHT_KINDS(VKRT_ARRAY_BINDING)};
#undef VKRT_ARRAY_BINDING
    return bindings;
}

bool sceneFitsUniformBuffers(const Scene& scene)
{
    // Triangle lights count before zero-area ones are dropped: an upper bound.
    bool fits = scene.materials.size() <= gpu::UNIFORM_MATERIALS;
#define VKRT_ARRAY_FITS(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    fits = fits && scene.array.size() <= gpu::UNIFORM_##ARRAY;
    VKRT_SHAPE_KINDS(VKRT_ARRAY_FITS)
    VKRT_LIGHT_KINDS(VKRT_ARRAY_FITS)
#undef VKRT_ARRAY_FITS
    return fits;
}

bool KernelVariant::isUniformBinding(uint32_t binding) const
{
    if (binding == gpu::BINDING_UNIFORMS) return true;
    const auto& arrays = sceneArrayBindings();
    bool sceneArray = std::any_of(arrays.begin(), arrays.end(), [&](const auto& a) { return a.binding == binding; });
    return uniformScene && sceneArray;
}

std::vector<std::pair<std::string, std::string>> KernelVariant::defines() const
{
    std::vector<std::pair<std::string, std::string>> result;
    result.emplace_back("VKRT_INTEGRATOR_" + upper(integratorName(features.integrator)), "1");
    if (features.anyPrimitive()) result.emplace_back("VKRT_HAS_MATERIALS", "1");
    for (const auto& feature : optionalFeatures(*this))
        if (feature.on) result.emplace_back(feature.define, "1");
    for (MaterialType type : kAllMaterialTypes)
        if (features.has(type)) result.emplace_back("VKRT_MATERIAL_" + upper(materialTypeName(type)), "1");
    if (uniformScene) result.emplace_back("VKRT_UNIFORM_SCENE", "1");
    if (groupLoopCount) result.emplace_back("VKRT_GROUP_LOOP_COUNT", "1");
    if (sceneAddresses) result.emplace_back("VKRT_SCENE_ADDRESSES", "1");
    if (multiChunkTextures()) {
        result.emplace_back("VKRT_TEXTURE_CHUNKS", std::to_string(textureChunks));
        result.emplace_back("VKRT_TEXTURE_CHUNK_SHIFT", std::to_string(textureChunkShift));
    }
    // Variance under the Sobol' sampler comes from independently scrambled batches.
    if (variance && sobolSampler) result.emplace_back("VKRT_SOBOL_BATCHES", std::to_string(gpu::VARIANCE_BATCHES));
    return result;
}

bool KernelVariant::multiChunkTextures() const { return features.textures && textureChunks > 1; }

uint32_t KernelVariant::descriptorCount(uint32_t binding) const
{
    return binding == gpu::BINDING_TEXTURE_TEXELS && multiChunkTextures() ? textureChunks : 1;
}

std::vector<uint32_t> KernelVariant::bindings() const
{
    std::vector<uint32_t> result = {gpu::BINDING_UNIFORMS, gpu::BINDING_ACCUMULATION, gpu::BINDING_STATS,
                                    gpu::BINDING_FRAME_RUN};
    if (features.anyPrimitive()) result.push_back(gpu::BINDING_MATERIALS);
    for (const auto& feature : optionalFeatures(*this))
        if (feature.on && feature.binding >= 0) result.push_back(uint32_t(feature.binding));
    if (staged) result.push_back(gpu::BINDING_STAGED_LANES);
    return result;
}

std::string KernelVariant::describe() const
{
    std::string text = integratorName(features.integrator) + ";";
    for (const auto& feature : optionalFeatures(*this))
        if (feature.on && !feature.name.empty()) text += " " + feature.name;
    if (multiChunkTextures()) text += " texture-buffers=" + std::to_string(textureChunks);
    text += ";";
    for (MaterialType type : kAllMaterialTypes)
        if (features.has(type)) text += " " + materialTypeName(type);
    text += uniformScene ? "; uniform-scene" : "; storage-scene";
    if (staged) text += "; staged";
    return text;
}

} // namespace vkrt
