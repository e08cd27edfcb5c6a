#include "scene/FeatureSet.h"
#include "scene/kinds/Kinds.h"

#include "mesh/MeshGeometry.h"

#include <algorithm>
#include <type_traits>

namespace vkrt {

std::string integratorName(Integrator integrator) { return integrator == Integrator::Path ? "path" : "whitted"; }

std::string materialTypeName(MaterialType type) { return std::string(kindName(type)); }

std::string featureName(ShapeKind kind)
{
#define VKRT_ARRAY_NAME(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    case ShapeKind::Type: return #array;
    switch (kind) {
        VKRT_SHAPE_KINDS(VKRT_ARRAY_NAME)
    }
#undef VKRT_ARRAY_NAME
    return "unknown";
}

std::string featureName(LightKind kind) { return std::string(kindName(kind)) + "-lights"; }

bool FeatureSet::anyPrimitive() const { return std::find(shapes.begin(), shapes.end(), true) != shapes.end(); }

FeatureSet FeatureSet::everything(Integrator integrator)
{
    FeatureSet all;
    all.shapes.fill(true);
    all.lights.fill(true);
    all.materialTypes.fill(true);
    all.cubemap = true;
    all.environmentSampling = integrator == Integrator::Path;
    all.meshNormals = true;
    all.emitters = true;
    all.textures = true;
    all.normalMaps = true;
    all.emissionTextures = true;
    all.fileMaterials = true;
    all.vertexColors = true;
    all.secondUvs = true;
    all.pbrLayers = true;
    all.pbrLobes.fill(true);
    all.thinLens = true;
    all.orthographic = true;
    all.alpha = true;
    all.lightTable = true; // compiled and reflected here; a render's uber kernel takes the scene's (uberFeatures)
    all.integrator = integrator;
    return all;
}

namespace {

/// Marks the material of every record of the scene's shape arrays (and every
/// file material of a mesh) as used, with its textures.
void markMaterialsUsed(const Scene& scene, FeatureSet& set)
{
    auto markUsed = [&](uint32_t index) {
        const Material& material = scene.materials[index];
        set.materialTypes[size_t(material.type)] = true;
        // An anisotropic lobe turns with the tangent frame, which the textured variants compute.
        set.textures = set.textures || material.hasTextures() || material.pbrAnisotropic();
        set.normalMaps = set.normalMaps || material.hasNormalMap();
        set.secondUvs = set.secondUvs || material.readsUvSet(1);
        set.pbrLayers = set.pbrLayers || material.hasPbrLayers();
        for (size_t lobe = 0; lobe < kPbrLobeCount; ++lobe)
            set.pbrLobes[lobe] = set.pbrLobes[lobe] || material.hasPbrLobe(PbrLobe(lobe));
    };
#define VKRT_MARK_SHAPE_MATERIALS(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    for (const auto& shape : scene.array) markUsed(shape.material);
    VKRT_SHAPE_KINDS(VKRT_MARK_SHAPE_MATERIALS)
#undef VKRT_MARK_SHAPE_MATERIALS
    for (const Mesh& mesh : scene.meshes)
        for (uint32_t index : mesh.fileMaterials) markUsed(index);
}

} // namespace

bool meshHasVertexColors(const Mesh& mesh)
{
    return !mesh.fileMaterials.empty() && !mesh.geometry->data.colors.empty();
}

bool meshEmits(const Scene& scene, const Mesh& mesh)
{
    if (mesh.emission != Color(0.0)) return true;
    if (scene.materials[mesh.material].emission != Color(0.0)) return true;
    for (uint32_t index : mesh.fileMaterials)
        if (scene.materials[index].emission != Color(0.0)) return true;
    return false;
}

bool emissionTextured(const Material& material)
{
    return material.emission != Color(0.0) && material.texture(TextureSlot::Emission).has_value();
}

bool meshEmissionTextured(const Scene& scene, const Mesh& mesh)
{
    if (mesh.emission != Color(0.0)) return false;
    if (mesh.fileMaterials.empty()) return emissionTextured(scene.materials[mesh.material]);
    for (uint32_t index : mesh.fileMaterials)
        if (emissionTextured(scene.materials[index])) return true;
    return false;
}

bool meshAlphaTested(const Scene& scene, const Mesh& mesh)
{
    if (scene.materials[mesh.material].alphaTested()) return true;
    for (uint32_t index : mesh.fileMaterials)
        if (scene.materials[index].alphaTested()) return true;
    return false;
}

bool sceneGivesLight(const Scene& scene)
{
    if (scene.background.color != Color(0.0) || scene.background.cubemap || scene.background.environment) return true;
    size_t lights = 0;
#define VKRT_COUNT_LIGHTS(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) lights += scene.array.size();
    VKRT_LIGHT_KINDS(VKRT_COUNT_LIGHTS)
#undef VKRT_COUNT_LIGHTS
    if (lights > 0) return true;
    return std::any_of(scene.meshes.begin(), scene.meshes.end(),
                       [&](const Mesh& mesh) { return meshEmits(scene, mesh); });
}

size_t enumeratedLightCount(const Scene& scene)
{
    size_t count = 0;
#define VKRT_COUNT_ENUMERATED(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if constexpr (!std::is_same_v<Type, TriangleLight>) count += scene.array.size();
    VKRT_LIGHT_KINDS(VKRT_COUNT_ENUMERATED)
#undef VKRT_COUNT_ENUMERATED
    return count;
}

bool usesLightTable(const Scene& scene) { return enumeratedLightCount(scene) > kMaxEnumeratedLights; }

FeatureSet featuresOf(const Scene& scene)
{
    FeatureSet set;
    for (ShapeKind kind : kAllShapeKinds) set.shapes[size_t(kind)] = scene.count(kind) > 0;
    for (LightKind kind : kAllLightKinds) set.lights[size_t(kind)] = scene.count(kind) > 0;
    set.cubemap = scene.background.cubemap.has_value();
    set.latLong = scene.background.environment.has_value();
    // The Whitted integrator has always seen a cubemap only where its rays
    // escape; a lat-long map (often with a small bright sun) is sampled by both.
    set.environmentSampling = (set.cubemap && scene.render.integrator == Integrator::Path) || set.latLong;
    set.integrator = scene.render.integrator;
    set.thinLens = scene.camera.thinLens();
    set.orthographic = scene.camera.orthographic();
    set.lightTable = usesLightTable(scene);
    for (const TriangleLight& light : scene.triangleLights) set.emitters = set.emitters || emits(light);
    for (const Mesh& mesh : scene.meshes) {
        set.meshNormals = set.meshNormals || !mesh.geometry->data.normals.empty();
        set.emitters = set.emitters || meshEmits(scene, mesh);
        set.emissionTextures = set.emissionTextures || meshEmissionTextured(scene, mesh);
        set.fileMaterials = set.fileMaterials || !mesh.fileMaterials.empty();
        set.vertexColors = set.vertexColors || meshHasVertexColors(mesh);
        set.alpha = set.alpha || meshAlphaTested(scene, mesh);
    }
    markMaterialsUsed(scene, set);
    return set;
}

} // namespace vkrt
