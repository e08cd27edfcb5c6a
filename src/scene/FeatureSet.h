#pragma once
// What a scene uses: its shape, light and material kinds (the registry of
// shared/Kinds.h), its environment and its integrator. The kernel variant
// (render/KernelVariant.h) turns this, plus render options, into defines and
// bindings. Data flow: Scene -> FeatureSet -> KernelVariant -> SPIR-V -> pipeline.
#include "scene/Scene.h"

#include <array>
#include <string>

namespace vkrt {

struct FeatureSet {
    std::array<bool, kShapeKindCount> shapes{};           ///< indexed by ShapeKind
    std::array<bool, kLightKindCount> lights{};           ///< indexed by LightKind
    std::array<bool, kMaterialKindCount> materialTypes{}; ///< indexed by MaterialType
    bool cubemap = false;
    bool latLong = false;             ///< a lat-long environment map
    bool environmentSampling = false; ///< importance-sample the map (cubemap: path integrator only)
    bool meshNormals = false;         ///< some mesh has per-vertex shading normals
    bool emitters = false;            ///< some triangle light or mesh emits (the emitters array: shared/SceneTypes.h)
    bool textures = false;            ///< some material in use has a texture
    bool normalMaps = false;          ///< ... a normal map
    bool emissionTextures = false;    ///< some emissive mesh's emission is textured (meshEmissionTextured)
    bool fileMaterials = false;       ///< some mesh uses its file's materials (one per triangle)
    bool vertexColors = false;        ///< ... and its file's vertex colours (glTF COLOR_0)
    bool pbrLayers = false;           ///< some pbr material has a glTF extension layer (Material::hasPbrLayers)
    /// ... the lobe, indexed by PbrLobe (Material::hasPbrLobe; anisotropy needs the hit's tangent frame)
    std::array<bool, kPbrLobeCount> pbrLobes{};
    bool secondUvs = false;    ///< some material in use reads a mesh's second uv set (glTF TEXCOORD_1)
    bool thinLens = false;     ///< the camera has an aperture (depth of field)
    bool orthographic = false; ///< the camera projects orthographically (parallel rays)
    bool alpha = false;        ///< some mesh material is alpha-tested (glTF alphaMode MASK or BLEND)
    bool lightTable = false;   ///< more lights than kMaxEnumeratedLights: sampled from a table (render/LightTable.h)
    Integrator integrator = Integrator::Whitted;

    /// Every feature on: the "uber" kernel, for comparison (`--uber`).
    static FeatureSet everything(Integrator integrator);

    bool anyPrimitive() const;
    /// Some material needs the surfaces' tangent frames: a normal map, or a pbr anisotropy.
    bool tangentFrames() const { return normalMaps || has(PbrLobe::Anisotropy); }
    bool has(ShapeKind kind) const { return shapes[size_t(kind)]; }
    bool has(LightKind kind) const { return lights[size_t(kind)]; }
    bool has(MaterialType type) const { return materialTypes[size_t(type)]; }
    bool has(PbrLobe lobe) const { return pbrLobes[size_t(lobe)]; }

    bool operator==(const FeatureSet&) const = default;
};

FeatureSet featuresOf(const Scene& scene);

/// Point, spot and directional lights the kernel tests one by one at most;
/// more go into the light table (render/LightTable.h).
inline constexpr size_t kMaxEnumeratedLights = 8;

/// The lights a shading point would sample one by one: every light that is
/// not a triangle light (those are emitters, sampled together).
size_t enumeratedLightCount(const Scene& scene);

/// Whether the scene's lights go into the light table.
bool usesLightTable(const Scene& scene);

/// Whether the mesh's file colours its vertices (glTF COLOR_0) for its file
/// materials: only a file's own materials take its colours.
bool meshHasVertexColors(const Mesh& mesh);

/// Whether some triangle of the mesh emits: its own `emission`, or an emissive material.
bool meshEmits(const Scene& scene, const Mesh& mesh);

/// Whether the emission of a material an emitting mesh uses is textured: a
/// non-zero `emission` with an emission texture, on a mesh without an
/// `emission` of its own (which replaces its materials' emission, texture and all).
bool emissionTextured(const Material& material);
bool meshEmissionTextured(const Scene& scene, const Mesh& mesh);
/// Whether anything in the scene gives light: a light, an emitting mesh, an
/// environment map or a background colour other than black.
bool sceneGivesLight(const Scene& scene);

/// Whether some material of the mesh is alpha-tested (MASK or BLEND).
bool meshAlphaTested(const Scene& scene, const Mesh& mesh);

std::string integratorName(Integrator integrator);
std::string materialTypeName(MaterialType type);
/// Names in the variant description and EXR metadata: "spheres", "point-lights".
std::string featureName(ShapeKind kind);
std::string featureName(LightKind kind);

} // namespace vkrt
