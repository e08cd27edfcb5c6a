#pragma once
// The validated, in-memory scene. Everything here is in double precision and in
// world space; conversion to the GPU's float32, camera-relative form happens in
// render/GpuScene. A Scene is only ever produced by parseScene*, which has
// already checked every value, so consumers need not re-validate.
#include "io/Image.h"
#include "mesh/AlphaMode.h"
#include "shared/Kinds.h"
#include "shared/TextureTypes.h"
#include "util/Error.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vkrt {

struct MeshGeometry; // mesh/MeshGeometry.h
class TextureAtlas;  // texture/TextureAtlas.h

using Color = glm::dvec3; ///< linear RGB

/// Documented hard limits of the scene format (docs/scene-format.md).
struct SceneLimits {
    static constexpr uint32_t maxImageSide = ImageLimits::maxSide;
    static constexpr uint64_t maxImagePixels = ImageLimits::maxPixels;
    static constexpr int maxDepth = 64;
    static constexpr double maxIor = 1e30;
};

enum class Integrator { Whitted, Path };

struct RenderSettings {
    Integrator integrator = Integrator::Whitted;
    int maxDepth = 5; ///< longest path (camera ray = depth 1)
};

/// Pinhole or thin-lens camera; fovY is the full vertical field of view in degrees.
struct Camera {
    glm::dvec3 eye{0, 0, 0};
    glm::dvec3 target{0, 0, -1};
    glm::dvec3 up{0, 1, 0};
    double fovY = 45.0;
    uint32_t width = 640;
    uint32_t height = 480;
    /// Thin lens (Mitsuba 3's `thinlens`): the lens radius (0: a pinhole) and
    /// the distance from the eye to the plane in focus, along the viewing
    /// direction (unset: the distance to `target`, which moves with it).
    double apertureRadius = 0.0;
    std::optional<double> focusDistance;
    /// Orthographic projection (a glTF orthographic camera): the full height
    /// of the view in scene units, the width following the image's aspect;
    /// 0: perspective (fovY). Parallel rays along the view direction from the
    /// plane through `eye`.
    double orthographicHeight = 0.0;

    bool thinLens() const { return apertureRadius > 0.0; }
    bool orthographic() const { return orthographicHeight > 0.0; }
    double resolvedFocusDistance() const;
};

// ------------------------------------------------ kinds (shared/Kinds.h)

#define VKRT_KIND_ENUMERATOR(KIND, Type, name, value, ...) Type = value,
#define VKRT_KIND_NAME(KIND, Type, name, value, ...) #name,

/// A material kind; the values are the GPU's MATERIAL_* constants.
enum class MaterialType : uint32_t { VKRT_MATERIAL_KINDS(VKRT_KIND_ENUMERATOR) };
/// A shape kind; the values are the GPU's SHAPE_* constants.
enum class ShapeKind : uint32_t { VKRT_SHAPE_KINDS(VKRT_KIND_ENUMERATOR) };
/// A light kind; the values are the GPU's LIGHT_* constants.
enum class LightKind : uint32_t { VKRT_LIGHT_KINDS(VKRT_KIND_ENUMERATOR) };

/// A glTF extension lobe of pbr materials the kernel compiles only where used.
enum class PbrLobe : uint32_t { VKRT_PBR_LOBES(VKRT_KIND_ENUMERATOR) };
#define VKRT_PLUS_ONE_LOBE(...) +1
inline constexpr size_t kPbrLobeCount = 0 VKRT_PBR_LOBES(VKRT_PLUS_ONE_LOBE);
#undef VKRT_PLUS_ONE_LOBE
/// The lobes' names (the feature "pbr-name" of `vkrt info`), indexed by value.
inline constexpr std::array<std::string_view, kPbrLobeCount> kPbrLobeNames{VKRT_PBR_LOBES(VKRT_KIND_NAME)};

inline constexpr size_t kMaterialKindCount = gpu::MATERIAL_KIND_COUNT;
inline constexpr size_t kShapeKindCount = gpu::SHAPE_KIND_COUNT;
inline constexpr size_t kLightKindCount = gpu::LIGHT_KIND_COUNT;

/// The scene file's names of each kind, indexed by the kind's value.
inline constexpr std::array<std::string_view, kMaterialKindCount> kMaterialNames{VKRT_MATERIAL_KINDS(VKRT_KIND_NAME)};
inline constexpr std::array<std::string_view, kShapeKindCount> kShapeNames{VKRT_SHAPE_KINDS(VKRT_KIND_NAME)};
inline constexpr std::array<std::string_view, kLightKindCount> kLightNames{VKRT_LIGHT_KINDS(VKRT_KIND_NAME)};
#undef VKRT_KIND_ENUMERATOR
#undef VKRT_KIND_NAME

/// Every kind of a concept, in value order (for loops over the registry).
template <class Kind, size_t N>
constexpr std::array<Kind, N> allKinds()
{
    std::array<Kind, N> kinds{};
    for (size_t i = 0; i < N; ++i) kinds[i] = Kind(i);
    return kinds;
}
inline constexpr auto kAllMaterialTypes = allKinds<MaterialType, kMaterialKindCount>();
inline constexpr auto kAllShapeKinds = allKinds<ShapeKind, kShapeKindCount>();
inline constexpr auto kAllLightKinds = allKinds<LightKind, kLightKindCount>();

constexpr std::string_view kindName(MaterialType type) { return kMaterialNames[size_t(type)]; }
constexpr std::string_view kindName(ShapeKind kind) { return kShapeNames[size_t(kind)]; }
constexpr std::string_view kindName(LightKind kind) { return kLightNames[size_t(kind)]; }

namespace kinds_check {
/// The registry lists each kind with value = its position, so value-indexed tables line up.
#define VKRT_KIND_IN_ORDER(KIND, Type, name, value, ...) &&(value == position++)
constexpr bool materialsInOrder()
{
    int position = 0;
    return true VKRT_MATERIAL_KINDS(VKRT_KIND_IN_ORDER);
}
constexpr bool shapesInOrder()
{
    int position = 0;
    return true VKRT_SHAPE_KINDS(VKRT_KIND_IN_ORDER);
}
constexpr bool lightsInOrder()
{
    int position = 0;
    return true VKRT_LIGHT_KINDS(VKRT_KIND_IN_ORDER);
}
#undef VKRT_KIND_IN_ORDER

template <size_t N>
constexpr bool namesUnique(const std::array<std::string_view, N>& names)
{
    for (size_t i = 0; i < N; ++i)
        for (size_t j = i + 1; j < N; ++j)
            if (names[i] == names[j]) return false;
    return true;
}
} // namespace kinds_check

static_assert(kinds_check::materialsInOrder() && kinds_check::shapesInOrder() && kinds_check::lightsInOrder(),
              "shared/Kinds.h: list each kind with value 0, 1, 2, ... in order");
static_assert(kinds_check::namesUnique(kMaterialNames), "shared/Kinds.h: two materials share a name");
static_assert(kinds_check::namesUnique(kShapeNames), "shared/Kinds.h: two shapes share a name");
static_assert(kinds_check::namesUnique(kLightNames), "shared/Kinds.h: two lights share a name");
#define VKRT_CHECK_MATERIAL_VALUE(KIND, Type, name, value, ...) \
    static_assert(uint32_t(MaterialType::Type) == gpu::MATERIAL_##KIND);
#define VKRT_CHECK_SHAPE_VALUE(KIND, Type, name, value, ...) static_assert(int(ShapeKind::Type) == gpu::SHAPE_##KIND);
#define VKRT_CHECK_LIGHT_VALUE(KIND, Type, name, value, ...) static_assert(int(LightKind::Type) == gpu::LIGHT_##KIND);
VKRT_MATERIAL_KINDS(VKRT_CHECK_MATERIAL_VALUE)
VKRT_SHAPE_KINDS(VKRT_CHECK_SHAPE_VALUE)
VKRT_LIGHT_KINDS(VKRT_CHECK_LIGHT_VALUE)
#undef VKRT_CHECK_MATERIAL_VALUE
#undef VKRT_CHECK_SHAPE_VALUE
#undef VKRT_CHECK_LIGHT_VALUE

/// How reflection strength depends on angle. Default lets the integrator pick
/// (Whitted: Schlick for dielectrics, none otherwise; path: exact for dielectrics).
enum class FresnelMode { Default, None, Schlick, Exact };

/// A material parameter's texture (scene `albedo = { texture = ... }`, glTF
/// texture references): a record of the scene's TextureAtlas, looked up at
/// uv * scale; scalars read component `channel` (0 = r ... 3 = a).
struct MaterialTexture {
    uint32_t record = 0;
    uint32_t channel = 0;
    glm::dvec2 scale{1.0};
    /// glTF KHR_texture_transform: uv' = R(rotation) (uv * scale) + offset,
    /// rotation in radians, counter-clockwise in uv.
    glm::dvec2 offset{0.0};
    double rotation = 0.0;
    /// The surface's uv set it reads: 0, or 1 (a mesh's MeshData::uvs1, glTF TEXCOORD_1).
    uint32_t texCoord = 0;
};

/// Which parameter a texture drives (gpu::TEXTURE_SLOT_*).
enum class TextureSlot : uint32_t {
    Color = gpu::TEXTURE_SLOT_COLOR,                                ///< diffuse / albedo / base_color
    Specular = gpu::TEXTURE_SLOT_SPECULAR,                          ///< specular / reflectance / tint
    Roughness = gpu::TEXTURE_SLOT_ROUGHNESS,                        ///< perceptual roughness
    Metallic = gpu::TEXTURE_SLOT_METALLIC,                          ///< pbr metallic
    SpecularFactor = gpu::TEXTURE_SLOT_SPECULAR_FACTOR,             ///< pbr specular (A)
    SheenColor = gpu::TEXTURE_SLOT_SHEEN_COLOR,                     ///< pbr sheen_color
    SheenRoughness = gpu::TEXTURE_SLOT_SHEEN_ROUGHNESS,             ///< pbr sheen_roughness (A)
    Clearcoat = gpu::TEXTURE_SLOT_CLEARCOAT,                        ///< pbr clearcoat (R)
    ClearcoatRoughness = gpu::TEXTURE_SLOT_CLEARCOAT_ROUGHNESS,     ///< pbr clearcoat_roughness (G)
    Transmission = gpu::TEXTURE_SLOT_TRANSMISSION,                  ///< pbr transmission (R)
    Iridescence = gpu::TEXTURE_SLOT_IRIDESCENCE,                    ///< pbr iridescence (R)
    IridescenceThickness = gpu::TEXTURE_SLOT_IRIDESCENCE_THICKNESS, ///< pbr iridescence_thickness (G: min to max)
    Anisotropy = gpu::TEXTURE_SLOT_ANISOTROPY,            ///< pbr anisotropy_texture (RG direction, B strength)
    ClearcoatNormal = gpu::TEXTURE_SLOT_CLEARCOAT_NORMAL, ///< pbr clearcoat_normal_map
    Normal = gpu::TEXTURE_SLOT_NORMAL,                    ///< tangent-space normal map
    Emission = gpu::TEXTURE_SLOT_EMISSION,                ///< emitted radiance (glTF emissiveTexture; meshes only)
};
inline constexpr size_t kTextureSlotCount = gpu::TEXTURE_SLOT_COUNT;

/// The glTF PBR extension layers of a pbr material (the Khronos extensions'
/// names and defaults; lib/bsdf.glsl evaluates them). The defaults leave the
/// plain metallic-roughness material, and its kernel (FeatureSet::pbrLayers).
struct PbrLayers {
    double specular = 1.0;           ///< KHR_materials_specular specularFactor: dielectric F90, scales F0
    Color specularColor{1.0};        ///< specularColorFactor: scales the dielectric F0 (may exceed 1)
    Color sheenColor{0.0};           ///< KHR_materials_sheen sheenColorFactor
    double sheenRoughness = 0.0;     ///< sheenRoughnessFactor
    double clearcoat = 0.0;          ///< KHR_materials_clearcoat clearcoatFactor
    double clearcoatRoughness = 0.0; ///< clearcoatRoughnessFactor (perceptual; alpha = roughness^2)
    double transmission = 0.0;       ///< KHR_materials_transmission transmissionFactor
    /// KHR_materials_volume absent or of thickness 0: transmitted light passes
    /// unrefracted and enters no medium. Otherwise the mesh bounds a volume of
    /// index `ior` absorbing by Material::absorption (attenuationColor and _Distance).
    bool thinWalled = true;
    double iridescence = 0.0;               ///< KHR_materials_iridescence iridescenceFactor
    double iridescenceIor = 1.3;            ///< iridescenceIor: the thin film's index
    double iridescenceThicknessMin = 100.0; ///< iridescenceThicknessMinimum (nm): where its texture reads 0
    double iridescenceThicknessMax = 400.0; ///< iridescenceThicknessMaximum (nm): where it reads 1; without one
    /// KHR_materials_anisotropy: anisotropyStrength stretches the base's GGX
    /// alpha along a direction anisotropyRotation (radians) counter-clockwise
    /// from the surface's tangent: alpha_t = mix(alpha, 1, strength^2).
    double anisotropy = 0.0;
    double anisotropyRotation = 0.0;

    bool sheen() const { return sheenColor != Color(0.0); }
    /// Whether these layers use a lobe (shared/Kinds.h: VKRT_PBR_LOBES).
    bool has(PbrLobe lobe) const
    {
        switch (lobe) {
        case PbrLobe::Transmission: return transmits();
        case PbrLobe::Iridescence: return iridescence > 0.0;
        case PbrLobe::Anisotropy: return anisotropy > 0.0;
        case PbrLobe::Sheen: return sheen();
        case PbrLobe::Clearcoat: return clearcoat > 0.0;
        }
        return false;
    }
    /// Light crosses the surface (the kernel's VKRT_PBR_TRANSMISSION).
    bool transmits() const { return transmission > 0.0; }
    /// The surface bounds a refracting, absorbing volume.
    bool volumetric() const { return transmits() && !thinWalled; }
    /// Some layer changes the material: the parameters of a layer whose
    /// factor is 0 (a glTF file's iridescenceIor, say) change nothing and keep
    /// the plain kernel.
    bool active() const
    {
        return specular != 1.0 || specularColor != Color(1.0) || sheen() || clearcoat > 0.0 || transmits() ||
               iridescence > 0.0 || anisotropy > 0.0;
    }
    bool operator==(const PbrLayers&) const = default;
};

struct Material {
    std::string name;
    MaterialType type = MaterialType::Lambert;
    Color diffuse{0.8};    ///< lambert `albedo`, phong `diffuse`
    Color specular{0.0};   ///< phong `specular`; mirror/glossy `reflectance`
    double exponent = 0.0; ///< phong `shininess`, glossy `exponent`
    double ior = 1.5;      ///< dielectric IOR; also Schlick's R0 for mirror/glossy
    Color absorption{0.0}; ///< dielectric, volumetric pbr: Beer–Lambert κ per unit length
    FresnelMode fresnel = FresnelMode::Default;
    /// conductor, rough_dielectric, plastic, pbr: perceptual roughness in [0, 1]; GGX alpha = roughness²
    double roughness = 0.0;
    double anisotropy = 0.0; ///< conductor: in [0, 1); stretches alpha along the frame's tangent
    Color eta{0.0};          ///< conductor: real part of the complex index of refraction
    Color k{0.0};            ///< conductor: imaginary part (extinction)
    double metallic = 0.0;   ///< pbr
    Color emission{0.0};     ///< pbr: emitted radiance (meshes only: their triangles become lights)
    /// pbr, the glTF extension layers (defaults: none; `ior` above is KHR_materials_ior's):
    PbrLayers layers;
    /// Textured parameters; a texel multiplies the parameter's constant above
    /// (1 for the scene's textures, a glTF file's factor for its own).
    std::array<std::optional<MaterialTexture>, kTextureSlotCount> textures{};
    double normalStrength = 1.0;          ///< scales a normal map's tangent-plane components (glTF normalTexture.scale)
    double clearcoatNormalStrength = 1.0; ///< ... the clear coat's (glTF clearcoatNormalTexture.scale)
    /// Coverage (glTF alphaMode; meshes only): alpha = `alpha` times the colour
    /// texture's A channel; MASK keeps the surface where alpha >= alphaCutoff,
    /// BLEND keeps it with probability alpha (lib/alpha.glsl).
    AlphaMode alphaMode = AlphaMode::Opaque;
    double alphaCutoff = 0.5;
    double alpha = 1.0;
    // Colours reuse the members above: conductor `tint` is specular, plastic
    // `diffuse` and pbr `base_color` are diffuse; plastic and rough_dielectric use ior.
    SourceLocation where; ///< the [materials.NAME] table

    const std::optional<MaterialTexture>& texture(TextureSlot slot) const { return textures[size_t(slot)]; }
    bool hasTextures() const;
    /// Whether a texture of it reads uv set `set` (MaterialTexture::texCoord).
    bool readsUvSet(uint32_t set) const;
    /// A normal map of the base or of the coat (both tilt a normal in the hit's tangent frame).
    bool hasNormalMap() const
    {
        return texture(TextureSlot::Normal).has_value() || texture(TextureSlot::ClearcoatNormal).has_value();
    }
    /// A pbr material with a glTF extension layer (or a KHR_materials_ior index other than 1.5).
    bool hasPbrLayers() const;
    /// A pbr material with the lobe (an anisotropic one: its base's GGX lobe
    /// stretches along the hit's tangent frame).
    bool hasPbrLobe(PbrLobe lobe) const { return type == MaterialType::Pbr && layers.has(lobe); }
    bool pbrTransmits() const { return hasPbrLobe(PbrLobe::Transmission); }
    bool pbrAnisotropic() const { return hasPbrLobe(PbrLobe::Anisotropy); }
    bool alphaTested() const { return alphaMode != AlphaMode::Opaque; }
};

inline double Camera::resolvedFocusDistance() const { return focusDistance.value_or(glm::length(target - eye)); }

inline bool Material::hasTextures() const
{
    for (const auto& t : textures)
        if (t) return true;
    return false;
}

inline bool Material::hasPbrLayers() const { return type == MaterialType::Pbr && (layers.active() || ior != 1.5); }

inline bool Material::readsUvSet(uint32_t set) const
{
    for (const auto& t : textures)
        if (t && t->texCoord == set) return true;
    return false;
}

struct Sphere {
    glm::dvec3 center;
    double radius;
    uint32_t material;
};

/// Axis-aligned box.
struct Box {
    glm::dvec3 min;
    glm::dvec3 max;
    uint32_t material;
};

struct Triangle {
    std::array<glm::dvec3, 3> vertices;
    uint32_t material;
};

/// Infinite plane through `point` with unit `normal`.
struct Plane {
    glm::dvec3 point;
    glm::dvec3 normal;
    uint32_t material;
};

/// An instance of a mesh file: its shared geometry (object space) placed by
/// objectToWorld (scale, then rotation, then translation, or a `matrix`).
/// With a non-zero emission every triangle is an area light of that
/// radiance on its counter-clockwise side (both sides if twoSided), like a
/// `[[lights]] type = "triangle"`; its material still scatters.
struct Mesh {
    std::shared_ptr<const MeshGeometry> geometry;
    glm::dmat4 objectToWorld{1.0};
    uint32_t material = 0;
    /// `material = "file"`: triangle t uses Scene::materials[fileMaterials[geometry's triangleMaterials[t]]]
    /// (empty: every triangle uses `material`).
    std::vector<uint32_t> fileMaterials;
    Color emission{0.0};
    bool twoSided = false;
    SourceLocation where; ///< the [[objects]] table
};

/// Isotropic point light; intensity is radiant intensity (W/sr) per channel.
struct PointLight {
    glm::dvec3 position;
    Color intensity;
};

/// Triangular area light of constant emitted radiance. It emits on the side its
/// vertex winding faces (counter-clockwise seen from the lit side) unless twoSided.
struct TriangleLight {
    std::array<glm::dvec3, 3> vertices;
    Color radiance;
    bool twoSided = false;
};

/// A light from infinitely far away in one direction (a sun): `direction` is
/// where its light travels (unit); `irradiance` is per channel on a surface
/// facing it (W/m^2); `angle` is its apparent diameter in degrees, 0 for a
/// delta light, else a disk of uniform radiance (a soft sun, sampled as a cone).
struct DirectionalLight {
    glm::dvec3 direction;
    Color irradiance;
    double angle = 0.0;
};

/// A spot light: a point light at `position` shining along unit `direction`,
/// `intensity` (W/sr) on its axis, falling off between the cone half-angles
/// (degrees) as glTF's KHR_lights_punctual says; inner == outer is a hard edge.
struct SpotLight {
    glm::dvec3 position;
    glm::dvec3 direction;
    Color intensity;
    double innerConeAngle = 0.0;
    double outerConeAngle = 45.0;
};

/// Six cubemap faces, paths resolved relative to the scene file.
struct Cubemap {
    /// +x, -x, +y, -y, +z, -z (Vulkan cube face order)
    std::array<std::string, 6> facePaths;
    SourceLocation where;
};

/// A lat-long (equirectangular) environment map, Mitsuba 3's `envmap`
/// convention: column i at u = (i + 0.5) / width, row j at v = j / (height -
/// 1) (row 0 looks up, +y), bilinear between texels; the map direction at
/// (u, v) is (sin phi sin theta, cos theta, -cos phi sin theta), phi = 2 pi u,
/// theta = pi v, and `rotation` turns it into the world's.
struct EnvironmentMap {
    std::string path; ///< .exr or .hdr, resolved relative to the scene file (empty for the studio)
    /// The built-in studio gradient (render/Environment.h: studioEnvironment),
    /// a glTF scene's default light: no file.
    bool studio = false;
    Color scale{1.0};
    glm::dmat3 rotation{1.0};
    SourceLocation where; ///< the [background.environment] table
};

struct Background {
    Color color{0.0};                          ///< constant radiance when there is no map
    std::optional<Cubemap> cubemap;            ///< environment radiance from six faces
    std::optional<EnvironmentMap> environment; ///< ... or from a lat-long map
};

struct Scene {
    std::string path; ///< the file it came from ("<string>" for text)
    /// The glTF files it imports (`[import] gltf`) and the buffer files they
    /// read: inputs that no output may replace (SceneInputs.h).
    std::vector<std::filesystem::path> importedFiles;
    uint64_t fileHash = 0; ///< FNV-1a 64 of the file's bytes
    RenderSettings render;
    Camera camera;
    std::vector<Material> materials;
    // One array per shape and light kind: spheres, boxes, ..., pointLights, triangleLights.
#define VKRT_SCENE_ARRAY_MEMBER(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    std::vector<Type> array;
    VKRT_SHAPE_KINDS(VKRT_SCENE_ARRAY_MEMBER)
    VKRT_LIGHT_KINDS(VKRT_SCENE_ARRAY_MEMBER)
#undef VKRT_SCENE_ARRAY_MEMBER
    Background background;
    /// Every texture the materials use (null without textures).
    std::shared_ptr<const TextureAtlas> textures;
    /// What the scene asks for that vkrt cannot honour exactly, each located
    /// ("file:line:column: ..."); the commands print them as warnings.
    std::vector<std::string> warnings;

    size_t primitiveCount() const;
    /// Records of one kind (triangle lights: before zero-area ones are dropped).
    size_t count(ShapeKind kind) const;
    size_t count(LightKind kind) const;
};

#define VKRT_SCENE_COUNT_CASE(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    case decltype(kind)::Type: return array.size();
inline size_t Scene::count(ShapeKind kind) const
{
    switch (kind) {
        VKRT_SHAPE_KINDS(VKRT_SCENE_COUNT_CASE)
    }
    return 0;
}
inline size_t Scene::count(LightKind kind) const
{
    switch (kind) {
        VKRT_LIGHT_KINDS(VKRT_SCENE_COUNT_CASE)
    }
    return 0;
}
#undef VKRT_SCENE_COUNT_CASE

inline size_t Scene::primitiveCount() const
{
    size_t total = 0;
    for (ShapeKind kind : kAllShapeKinds) total += count(kind);
    return total;
}

} // namespace vkrt
