// Scene-file reader: TOML text -> toml++ tree -> validated Scene.
//
// Every check reports the exact position of the offending value (or of the
// enclosing table when something is missing) together with the value's full
// dotted path, because scene files are written by hand and an error that only
// says "bad radius" is useless in a file with a hundred spheres. The located
// reading itself is scene/TomlReader.h; this file knows what a scene holds.
#include "scene/SceneParser.h"

#include "scene/FeatureSet.h"
#include "scene/MaterialUse.h"

#include "io/ImageHeader.h"
#include "material/Metals.h"
#include "mesh/MeshGeometry.h"
#include "mesh/MeshLoader.h"
#include "scene/FileMaterialImport.h"
#include "scene/GltfScene.h"
#include "scene/SceneOverrides.h"

#include "scene/ParseContext.h"
#include "scene/SceneValues.h"
#include "scene/TextureParameters.h"
#include "scene/TomlReader.h"
#include "scene/kinds/Kinds.h"
#include "util/Hash.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace vkrt {
namespace {

namespace fs = std::filesystem;
using Keys = KeyList;

// ------------------------------------------------------------ scalar values

double readFov(const Field& field)
{
    const double value = readNumber(field);
    if (!(value > 0 && value < 180))
        field.fail("must be strictly between 0 and 180 degrees, got " + formatNumber(value));
    return value;
}

// ---------------------------------------------------------- vectors, colours

// -------------------------------------------------------------------- render

constexpr std::array<std::string_view, 2> renderKeys{"integrator", "max_depth"};
constexpr std::array<EnumName<Integrator>, 2> integrators{
    {{"whitted", Integrator::Whitted}, {"path", Integrator::Path}}};

Integrator readIntegrator(const Field& field) { return readChoice(field, "integrator", integrators).value; }
int readMaxDepth(const Field& field) { return static_cast<int>(readInteger(field, 1, SceneLimits::maxDepth)); }

RenderSettings readRender(const TableField& table)
{
    table.rejectUnknownKeys(renderKeys);
    RenderSettings render;
    render.integrator = readOr(table, "integrator", render.integrator, readIntegrator);
    render.maxDepth = readOr(table, "max_depth", render.maxDepth, readMaxDepth);
    return render;
}

// -------------------------------------------------------------------- camera

constexpr std::array<std::string_view, 8> cameraKeys{
    "eye", "target", "up", "fov", "width", "height", "aperture_radius", "focus_distance"};

glm::dvec3 readTarget(const Field& field, const glm::dvec3& eye)
{
    const glm::dvec3 target = readVector(field);
    if (target == eye) field.fail("must differ from camera.eye (the view direction would be undefined)");
    return target;
}

glm::dvec3 readUp(const TableField& camera, const glm::dvec3& viewDirection)
{
    const std::optional<Field> field = camera.find("up");
    const glm::dvec3 up = field ? readVector(*field) : glm::dvec3(0, 1, 0);
    const std::optional<glm::dvec3> unitUp = normalized(up);
    if (!unitUp) field->fail("must not be zero-length"); // the default is not, so field exists
    if (!isParallel(*unitUp, viewDirection)) return up;
    if (field) field->fail("must not be parallel to the view direction (target - eye)");
    camera.field().fail("the default up [0, 1, 0] is parallel to the view direction (target - eye); set 'up'");
}

uint32_t readImageSide(const Field& field)
{
    return static_cast<uint32_t>(readInteger(field, 1, SceneLimits::maxImageSide));
}

void readResolution(const TableField& table, Camera& camera)
{
    camera.width = readOr(table, "width", camera.width, readImageSide);
    camera.height = readOr(table, "height", camera.height, readImageSide);
    const uint64_t pixels = uint64_t{camera.width} * camera.height;
    if (pixels <= SceneLimits::maxImagePixels) return;
    const Field blamed = table.find("height").value_or(table.find("width").value_or(table.field()));
    blamed.fail("width * height = " + std::to_string(pixels) + " pixels exceeds the limit of " +
                std::to_string(SceneLimits::maxImagePixels));
}

Camera readCamera(const TableField& table)
{
    table.rejectUnknownKeys(cameraKeys);
    Camera camera;
    camera.eye = readVector(table.require("eye"));
    camera.target = readTarget(table.require("target"), camera.eye);
    camera.up = readUp(table, *normalized(difference(camera.eye, camera.target)));
    camera.fovY = readOr(table, "fov", camera.fovY, readFov); // 45 degrees, as Camera says
    readResolution(table, camera);
    camera.apertureRadius = readOr(table, "aperture_radius", 0.0, readNonNegative);
    if (const auto focus = table.find("focus_distance")) camera.focusDistance = readPositive(*focus);
    // The same rules that check overrides (SceneOverrides.h): the two can never disagree.
    if (const auto problem = cameraProblem(camera)) table.field().fail(*problem);
    return camera;
}

// ----------------------------------------------------------------- materials

// Every kind takes `normal_map` (a tangent-space normal map; TextureParameters.h).
constexpr std::array<std::string_view, 3> lambertKeys{"type", "albedo", "normal_map"};
constexpr std::array<std::string_view, 5> phongKeys{"type", "diffuse", "specular", "shininess", "normal_map"};
constexpr std::array<std::string_view, 5> mirrorKeys{"type", "reflectance", "fresnel", "ior", "normal_map"};
constexpr std::array<std::string_view, 6> glossyKeys{"type", "reflectance", "exponent", "fresnel", "ior", "normal_map"};
constexpr std::array<std::string_view, 5> dielectricKeys{"type", "ior", "absorption", "fresnel", "normal_map"};
constexpr std::array<std::string_view, 8> conductorKeys{"type", "roughness", "anisotropy", "metal",
                                                        "eta",  "k",         "tint",       "normal_map"};
constexpr std::array<std::string_view, 6> rough_dielectricKeys{"type",       "roughness", "ior",
                                                               "absorption", "fresnel",   "normal_map"};
constexpr std::array<std::string_view, 5> plasticKeys{"type", "diffuse", "roughness", "ior", "normal_map"};
constexpr std::array<std::string_view, 26> pbrKeys{"type",
                                                   "base_color",
                                                   "metallic",
                                                   "roughness",
                                                   "emission",
                                                   "normal_map",
                                                   "ior",
                                                   "specular",
                                                   "specular_color",
                                                   "sheen_color",
                                                   "sheen_roughness",
                                                   "clearcoat",
                                                   "clearcoat_roughness",
                                                   "transmission",
                                                   "thin_walled",
                                                   "attenuation_color",
                                                   "attenuation_distance",
                                                   "iridescence",
                                                   "iridescence_ior",
                                                   "iridescence_thickness",
                                                   "iridescence_thickness_range",
                                                   "absorption",
                                                   "anisotropy",
                                                   "anisotropy_rotation",
                                                   "anisotropy_texture",
                                                   "clearcoat_normal_map"};

/// A colour parameter: a value, or a texture table whose texel is the colour
/// (the constant becomes 1, which the texel multiplies on the GPU).
Color readColorParameter(const TableField& table, std::string_view key, Color fallback, Material& material,
                         TextureSlot slot, TextureAtlas& textures)
{
    const std::optional<Field> field = table.find(key);
    if (!field) return fallback;
    if (!isTextureTable(*field)) return readUnitColor(*field);
    material.textures[size_t(slot)] = readTextureTable(*field, TextureUse::Color, textures);
    return Color(1.0);
}

/// A parameter in [0, 1] (roughness, metallic): a value or a texture table.
double readUnitParameter(const TableField& table, std::string_view key, double fallback, Material& material,
                         TextureSlot slot, TextureAtlas& textures)
{
    const std::optional<Field> field = table.find(key);
    if (!field) return fallback;
    if (!isTextureTable(*field)) return readNumberIn(*field, NumberRange{0.0, 1.0});
    material.textures[size_t(slot)] = readTextureTable(*field, TextureUse::Scalar, textures);
    return 1.0;
}

void readNormalMap(const TableField& table, Material& material, TextureAtlas& textures)
{
    const std::optional<Field> field = table.find("normal_map");
    if (!field) return;
    if (!isTextureTable(*field))
        field->fail("expected a texture table ({ texture = \"normals.png\", ... }), got " +
                    describeType(field->node()));
    material.textures[size_t(TextureSlot::Normal)] =
        readTextureTable(*field, TextureUse::NormalMap, textures, &material.normalStrength);
}

constexpr std::array<EnumName<FresnelMode>, 2> reflectorFresnelModes{
    {{"none", FresnelMode::None}, {"schlick", FresnelMode::Schlick}}};
constexpr std::array<EnumName<FresnelMode>, 2> dielectricFresnelModes{
    {{"schlick", FresnelMode::Schlick}, {"exact", FresnelMode::Exact}}};

FresnelMode readReflectorFresnel(const Field& field)
{
    return readChoice(field, "fresnel mode", reflectorFresnelModes).value;
}

FresnelMode readDielectricFresnel(const Field& field)
{
    return readChoice(field, "fresnel mode", dielectricFresnelModes).value;
}

/// `material = "file"` on a mesh: the file's own materials (glTF).
constexpr std::string_view kFileMaterial = "file";

void readLambert(const TableField& table, Material& material, ParseContext& context)
{
    material.diffuse = readColorParameter(table, "albedo", Color(0.8), material, TextureSlot::Color, context.textures);
}

void readPhong(const TableField& table, Material& material, ParseContext& context)
{
    material.diffuse = readColorParameter(table, "diffuse", Color(0.8), material, TextureSlot::Color, context.textures);
    material.specular =
        readColorParameter(table, "specular", Color(0.0), material, TextureSlot::Specular, context.textures);
    material.exponent = readOr(table, "shininess", 32.0, readNonNegative);
}

/// Mirror and glossy share an optional Schlick term whose R0 comes from `ior`.
void readReflectorFresnelTerm(const TableField& table, Material& material)
{
    material.fresnel = readOr(table, "fresnel", FresnelMode::None, readReflectorFresnel);
    material.ior = readOr(table, "ior", 1.5, readIor);
}

void readMirror(const TableField& table, Material& material, ParseContext& context)
{
    material.specular =
        readColorParameter(table, "reflectance", Color(1.0), material, TextureSlot::Specular, context.textures);
    readReflectorFresnelTerm(table, material);
}

void readGlossy(const TableField& table, Material& material, ParseContext& context)
{
    material.specular =
        readColorParameter(table, "reflectance", Color(1.0), material, TextureSlot::Specular, context.textures);
    material.exponent = readOr(table, "exponent", 100.0, readNonNegative);
    readReflectorFresnelTerm(table, material);
}

void readDielectric(const TableField& table, Material& material, ParseContext&)
{
    material.ior = readOr(table, "ior", 1.5, readIor);
    material.absorption = readOr(table, "absorption", Color(0.0), readRadiance);
    material.fresnel = readOr(table, "fresnel", FresnelMode::Default, readDielectricFresnel);
}

double readUnitInterval(const Field& field) { return readNumberIn(field, NumberRange{0.0, 1.0}); }

/// Anisotropy 1 would give one of the alphas zero width: [0, 1).
double readAnisotropy(const Field& field) { return readNumberIn(field, NumberRange{0.0, 1.0, false, true}); }

const Metal& readMetal(const Field& field)
{
    const std::string name = readString(field);
    if (const Metal* metal = findMetal(name)) return *metal;
    const std::vector<std::string> owned = metalNames();
    const std::vector<std::string_view> names(owned.begin(), owned.end());
    field.fail("unknown metal " + quote(name) + didYouMean(name, names) + " (expected one of: " + joinList(names) +
               ", or give eta and k)");
}

Color toColor(const std::array<double, 3>& c) { return {c[0], c[1], c[2]}; }

/// A conductor's complex index: a named metal, or eta and k (both, per channel).
void readConductorIor(const TableField& table, Material& material)
{
    const std::optional<Field> metal = table.find("metal"), eta = table.find("eta"), k = table.find("k");
    if (metal && (eta || k)) (eta ? *eta : *k).fail("give either 'metal' or 'eta' and 'k', not both");
    if (!eta && !k) { // the default: Mitsuba's material "none", which reflects everything at every angle
        const Metal& chosen = metal ? readMetal(*metal) : *findMetal("none");
        material.eta = toColor(chosen.eta);
        material.k = toColor(chosen.k);
        return;
    }
    if (!eta || !k) {
        table.field().fail(std::string("a conductor with '") + (eta ? "eta" : "k") + "' needs '" + (eta ? "k" : "eta") +
                           "' too");
    }
    material.eta = readRadiance(*eta);
    material.k = readRadiance(*k);
}

void readConductor(const TableField& table, Material& material, ParseContext& context)
{
    material.roughness = readUnitParameter(table, "roughness", 0.0, material, TextureSlot::Roughness, context.textures);
    material.anisotropy = readOr(table, "anisotropy", 0.0, readAnisotropy);
    material.specular =
        readColorParameter(table, "tint", Color(1.0), material, TextureSlot::Specular, context.textures);
    readConductorIor(table, material);
}

/// Roughness 0 is the smooth dielectric itself: the same kind, kernel and
/// image. The default is Mitsuba's roughdielectric alpha = 0.1.
void readRoughDielectric(const TableField& table, Material& material, ParseContext& context)
{
    readDielectric(table, material, context);
    material.roughness =
        readUnitParameter(table, "roughness", std::sqrt(0.1), material, TextureSlot::Roughness, context.textures);
    if (material.roughness == 0.0) material.type = MaterialType::Dielectric; // never with a texture (its constant is 1)
}

/// Mitsuba's defaults: polypropylene (1.49), diffuse 0.5; roughness 0 is the smooth coating.
void readPlastic(const TableField& table, Material& material, ParseContext& context)
{
    material.diffuse = readColorParameter(table, "diffuse", Color(0.5), material, TextureSlot::Color, context.textures);
    if (const auto roughness = table.find("roughness"); roughness && isTextureTable(*roughness))
        roughness->fail("a plastic's roughness cannot be a texture: its coating's energy table is computed per "
                        "material (use a constant, or a conductor or pbr material)");
    material.roughness = readOr(table, "roughness", 0.0, readUnitInterval);
    material.ior = readOr(table, "ior", 1.49, readIor);
    if (material.ior == 1.0) table.find("ior")->fail("must differ from 1 (a coating of index 1 is no coating)");
}

/// KHR_materials_transmission and _volume: `transmission` (or its texture's R),
/// `thin_walled` (glTF's default without a volume: true), and inside a volume
/// the absorption as glTF writes it (attenuation_color reached after
/// attenuation_distance) or as vkrt's glass does (`absorption`, per unit).
void readPbrTransmission(const TableField& table, Material& material, ParseContext& context)
{
    PbrLayers& layers = material.layers;
    layers.transmission =
        readUnitParameter(table, "transmission", 0.0, material, TextureSlot::Transmission, context.textures);
    const std::optional<Field> thin = table.find("thin_walled");
    const std::optional<Field> color = table.find("attenuation_color");
    const std::optional<Field> distance = table.find("attenuation_distance");
    const std::optional<Field> absorption = table.find("absorption");
    if (thin && !layers.transmits()) thin->fail("applies to a transmitting material: set transmission above 0");
    layers.thinWalled = thin ? readBool(*thin) : true;
    for (const std::optional<Field>& inside : {color, distance, absorption})
        if (inside && !layers.volumetric())
            inside->fail("absorbs inside a volume: needs transmission above 0 and thin_walled = false");
    if (absorption && (color || distance))
        absorption->fail("give the absorption either as `absorption` or as attenuation_color and "
                         "attenuation_distance, not both");
    if (absorption) material.absorption = readOr(table, "absorption", Color(0.0), readRadiance);
    if (color || distance) {
        const Color reached = color ? readUnitColor(*color) : Color(1.0);
        const double length = distance ? readPositive(*distance) : std::numeric_limits<double>::infinity();
        material.absorption = absorptionOfAttenuation(reached, length);
    }
}

/// KHR_materials_iridescence: `iridescence` (or its texture's R), the film's
/// `iridescence_ior` and `iridescence_thickness` in nanometres: a number, or a
/// texture whose texel (its `channel`; glTF's is G) mixes across
/// `iridescence_thickness_range` ([100, 400], glTF's defaults).
void readPbrIridescence(const TableField& table, Material& material, ParseContext& context)
{
    PbrLayers& layers = material.layers;
    layers.iridescence =
        readUnitParameter(table, "iridescence", 0.0, material, TextureSlot::Iridescence, context.textures);
    layers.iridescenceIor = readOr(table, "iridescence_ior", 1.3, readIor);
    const std::optional<Field> thickness = table.find("iridescence_thickness");
    const std::optional<Field> range = table.find("iridescence_thickness_range");
    if (thickness && isTextureTable(*thickness)) {
        material.textures[size_t(TextureSlot::IridescenceThickness)] =
            readTextureTable(*thickness, TextureUse::Scalar, context.textures);
        if (range) {
            const toml::array* bounds = range->node().as_array();
            const auto bound = [&](size_t i) { return readNonNegative(range->element(i, *bounds->get(i))); };
            if (!bounds || bounds->size() != 2)
                range->fail("expected [minimum, maximum] in nanometres, got " + describeType(range->node()));
            layers.iridescenceThicknessMin = bound(0);
            layers.iridescenceThicknessMax = bound(1);
            if (layers.iridescenceThicknessMax < layers.iridescenceThicknessMin)
                range->fail("the minimum exceeds the maximum");
        }
    } else {
        if (range) range->fail("applies to a textured iridescence_thickness (a number is the thickness itself)");
        if (thickness) layers.iridescenceThicknessMax = readNonNegative(*thickness);
    }
}

/// KHR_materials_anisotropy: `anisotropy` (the strength, in [0, 1]),
/// `anisotropy_rotation` (degrees counter-clockwise from the surface's
/// tangent) and `anisotropy_texture` (glTF's encoding: RG the direction in
/// the tangent frame as (d + 1) / 2, which the rotation turns; B scales the
/// strength).
void readPbrAnisotropy(const TableField& table, Material& material, ParseContext& context)
{
    PbrLayers& layers = material.layers;
    layers.anisotropy = readOr(table, "anisotropy", 0.0, readUnitInterval);
    layers.anisotropyRotation = readOr(table, "anisotropy_rotation", 0.0, readNumber) * std::numbers::pi / 180.0;
    if (const std::optional<Field> texture = table.find("anisotropy_texture")) {
        if (!(layers.anisotropy > 0.0)) texture->fail("applies to an anisotropic material: set anisotropy above 0");
        if (!isTextureTable(*texture))
            texture->fail("expected a texture table ({ texture = \"directions.png\" }), got " +
                          describeType(texture->node()));
        material.textures[size_t(TextureSlot::Anisotropy)] =
            readTextureTable(*texture, TextureUse::Vector, context.textures);
    }
}

/// KHR_materials_clearcoat's clearcoatNormalTexture: the coat's own normal map
/// (a texture table with `strength`, as `normal_map`). Without it the coat is
/// not normal-mapped, whatever the base's `normal_map` does.
void readClearcoatNormalMap(const TableField& table, Material& material, ParseContext& context)
{
    const std::optional<Field> field = table.find("clearcoat_normal_map");
    if (!field) return;
    if (!(material.layers.clearcoat > 0.0)) field->fail("applies to a coated material: set clearcoat above 0");
    if (!isTextureTable(*field))
        field->fail("expected a texture table ({ texture = \"normals.png\", ... }), got " +
                    describeType(field->node()));
    material.textures[size_t(TextureSlot::ClearcoatNormal)] =
        readTextureTable(*field, TextureUse::NormalMap, context.textures, &material.clearcoatNormalStrength);
}

/// The glTF extension layers (KHR_materials_ior, _specular, _sheen, _clearcoat; their defaults).
/// specular_color may exceed 1, as specularColorFactor may (the F0 it scales stays at most 1).
void readPbrLayers(const TableField& table, Material& material, ParseContext& context)
{
    material.ior = readOr(table, "ior", 1.5, readIor);
    PbrLayers& layers = material.layers;
    layers.specular =
        readUnitParameter(table, "specular", 1.0, material, TextureSlot::SpecularFactor, context.textures);
    if (const std::optional<Field> color = table.find("specular_color")) {
        if (isTextureTable(*color)) {
            material.textures[size_t(TextureSlot::Specular)] =
                readTextureTable(*color, TextureUse::Color, context.textures);
        } else {
            layers.specularColor = readRadiance(*color);
        }
    }
    layers.sheenColor =
        readColorParameter(table, "sheen_color", Color(0.0), material, TextureSlot::SheenColor, context.textures);
    layers.sheenRoughness =
        readUnitParameter(table, "sheen_roughness", 0.0, material, TextureSlot::SheenRoughness, context.textures);
    layers.clearcoat = readUnitParameter(table, "clearcoat", 0.0, material, TextureSlot::Clearcoat, context.textures);
    layers.clearcoatRoughness = readUnitParameter(table, "clearcoat_roughness", 0.0, material,
                                                  TextureSlot::ClearcoatRoughness, context.textures);
    readClearcoatNormalMap(table, material, context);
    readPbrTransmission(table, material, context);
    readPbrIridescence(table, material, context);
    readPbrAnisotropy(table, material, context);
}

/// glTF 2.0's defaults: base colour 1, metallic 1, roughness 1.
void readPbr(const TableField& table, Material& material, ParseContext& context)
{
    material.diffuse =
        readColorParameter(table, "base_color", Color(1.0), material, TextureSlot::Color, context.textures);
    material.metallic = readUnitParameter(table, "metallic", 1.0, material, TextureSlot::Metallic, context.textures);
    material.roughness = readUnitParameter(table, "roughness", 1.0, material, TextureSlot::Roughness, context.textures);
    material.emission = readOr(table, "emission", Color(0.0), readRadiance);
    readPbrLayers(table, material, context);
}

struct MaterialKind {
    std::string_view name;
    MaterialType type;
    Keys keys;
    void (*read)(const TableField&, Material&, ParseContext&);
};

// The registry (shared/Kinds.h) names each kind's key list `nameKeys` and its reader `readType`.
#define VKRT_MATERIAL_KIND_ENTRY(KIND, Type, name, value, delta) \
    MaterialKind{#name, MaterialType::Type, name##Keys, read##Type},
const std::array<MaterialKind, kMaterialKindCount> materialKinds{{VKRT_MATERIAL_KINDS(VKRT_MATERIAL_KIND_ENTRY)}};
#undef VKRT_MATERIAL_KIND_ENTRY

/// Every key some kind of the table accepts: a key of another kind gets a
/// more precise message than "unknown".
template <class Kind, size_t N>
std::vector<std::string_view> keysOfEveryKind(const std::array<Kind, N>& kinds)
{
    std::vector<std::string_view> keys;
    for (const Kind& kind : kinds)
        for (std::string_view key : kind.keys)
            if (!contains(keys, key)) keys.push_back(key);
    return keys;
}

const std::vector<std::string_view> allMaterialKeys = keysOfEveryKind(materialKinds);

Material readMaterial(std::string_view name, const TableField& table, ParseContext& context)
{
    // A copy: GCC 14 cannot tell that the reference would not dangle.
    const MaterialKind kind = readChoice(table.require("type"), "material type", materialKinds);
    table.rejectUnknownKeys(kind.keys, allMaterialKeys, "material type " + quote(kind.name));
    Material material;
    material.name = name;
    material.type = kind.type;
    material.where = table.field().location();
    if (name == kFileMaterial)
        table.field().fail("the material name \"file\" is reserved: `material = \"file\"` gives a mesh its "
                           "file's own materials");
    kind.read(table, material, context);
    readNormalMap(table, material, context.textures);
    return material;
}

std::vector<Material> readMaterials(const TableField& table, ParseContext& context)
{
    std::vector<Material> materials;
    for (const auto& [name, field] : table.entriesInFileOrder())
        materials.push_back(readMaterial(name, TableField(field), context));
    return materials;
}

/// Resolves the material names used by objects to indices into Scene::materials.
class MaterialIndex {
public:
    explicit MaterialIndex(const std::vector<Material>& materials)
    {
        for (size_t i = 0; i < materials.size(); ++i) {
            m_index.emplace(materials[i].name, static_cast<uint32_t>(i));
            m_names.push_back(materials[i].name);
        }
    }

    uint32_t resolve(const Field& field) const
    {
        const std::string name = readString(field);
        const auto found = m_index.find(name);
        if (found == m_index.end()) field.fail(unknownMessage(name));
        return found->second;
    }

private:
    std::string unknownMessage(const std::string& name) const
    {
        std::vector<std::string_view> names(m_names.begin(), m_names.end());
        const std::string message = "unknown material " + quote(name);
        if (names.empty()) return message + " (no materials are defined; add a [materials." + name + "] table)";
        const std::string suggestion = didYouMean(name, names);
        // Listing a handful of names helps when nothing is close; a long list would bury the message.
        if (suggestion.empty() && names.size() <= 10) return message + " (defined: " + joinList(names) + ")";
        return message + suggestion;
    }

    std::map<std::string, uint32_t, std::less<>> m_index;
    std::vector<std::string> m_names;
};

// ------------------------------------------------------------------- objects
// Each kind's keys and reader are in its own file (scene/kinds/).

struct ShapeReader {
    std::string_view name;
    Keys keys;
    void (*read)(const TableField&, uint32_t, ParseContext&);
};

#define VKRT_SHAPE_KIND_ENTRY(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    ShapeReader{#name, field##Keys(), read##Type},
const std::array<ShapeReader, kShapeKindCount> shapeKinds{{VKRT_SHAPE_KINDS(VKRT_SHAPE_KIND_ENTRY)}};
#undef VKRT_SHAPE_KIND_ENTRY
const std::vector<std::string_view> allShapeKeys = keysOfEveryKind(shapeKinds);

void readObject(const TableField& table, const MaterialIndex& materials, ParseContext& context)
{
    const Scene& scene = context.scene;
    const ShapeReader kind = readChoice(table.require("shape"), "shape", shapeKinds);
    table.rejectUnknownKeys(kind.keys, allShapeKeys, "shape " + quote(kind.name));
    const Field materialField = table.require("material");
    const bool mesh = kind.read == readMesh;
    if (mesh && readString(materialField) == kFileMaterial) return readMesh(table, kFileMaterialIndex, context);
    const uint32_t material = materials.resolve(materialField);
    if (!mesh)
        if (auto problem = nonMeshMaterialProblem(scene.materials[material])) materialField.fail(*problem);
    kind.read(table, material, context);
}

// -------------------------------------------------------------------- lights

struct LightReader {
    std::string_view name;
    Keys keys;
    void (*read)(const TableField&, ParseContext&);
};

#define VKRT_LIGHT_KIND_ENTRY(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    LightReader{#name, field##Keys(), read##Type},
const std::array<LightReader, kLightKindCount> lightKinds{{VKRT_LIGHT_KINDS(VKRT_LIGHT_KIND_ENTRY)}};
#undef VKRT_LIGHT_KIND_ENTRY
const std::vector<std::string_view> allLightKeys = keysOfEveryKind(lightKinds);

void readLight(const TableField& table, ParseContext& context)
{
    const LightReader kind = readChoice(table.require("type"), "light type", lightKinds);
    table.rejectUnknownKeys(kind.keys, allLightKeys, "light type " + quote(kind.name));
    kind.read(table, context);
}

// ---------------------------------------------------------------- background

constexpr std::array<std::string_view, 3> backgroundKeys{"color", "cubemap", "environment"};
constexpr std::array<std::string_view, 3> environmentKeys{"file", "scale", "rotate"};
/// Vulkan cube face order, matching Cubemap::facePaths.
constexpr std::array<std::string_view, 6> faceKeys{"px", "nx", "py", "ny", "pz", "nz"};

void checkImageExtension(const Field& field, const fs::path& path)
{
    const std::string extension = lowercase(path.extension().string());
    if (extension != ".exr" && extension != ".png")
        field.fail("cubemap faces must be .exr or .png files, got " + quote(path.string()));
}

std::string readFacePath(const Field& field)
{
    const fs::path path = readPath(field);
    checkImageExtension(field, path);
    checkRegularFile(field, path);
    return path.string();
}

Cubemap readCubemap(const TableField& table)
{
    table.rejectUnknownKeys(faceKeys);
    Cubemap cubemap;
    cubemap.where = table.field().location();
    for (size_t i = 0; i < faceKeys.size(); ++i) cubemap.facePaths[i] = readFacePath(table.require(faceKeys[i]));
    return cubemap;
}

EnvironmentMap readEnvironmentMap(const TableField& table)
{
    table.rejectUnknownKeys(environmentKeys);
    EnvironmentMap map;
    map.where = table.field().location();
    map.scale = readOr(table, "scale", map.scale, readRadiance);
    map.rotation = glm::dmat3(readOr(table, "rotate", glm::dmat4(1.0), readRotation));
    const Field fileField = table.require("file");
    const fs::path path = readPath(fileField);
    const std::string extension = lowercase(path.extension().string());
    if (extension != ".exr" && extension != ".hdr")
        fileField.fail("an environment map must be a lat-long .exr or .hdr file, got " + quote(path.string()));
    checkRegularFile(fileField, path);
    map.path = path.string();
    return map;
}

/// The one key of a background that says where its radiance comes from.
void refuseSecondSource(const TableField& table, const Field& second, std::string_view secondName)
{
    for (std::string_view first : {"color", "cubemap"}) {
        if (first == secondName) return;
        if (const auto other = table.find(first))
            second.fail("cannot be combined with background." + std::string(first) + " (line " +
                        std::to_string(other->location().line) + "); use one or the other");
    }
}

Background readBackground(const TableField& table)
{
    table.rejectUnknownKeys(backgroundKeys);
    Background background;
    background.color = readOr(table, "color", Color(0.0), readRadiance);
    if (const auto cubemap = table.find("cubemap")) {
        refuseSecondSource(table, *cubemap, "cubemap");
        background.cubemap = readCubemap(TableField(*cubemap));
    }
    if (const auto environment = table.find("environment")) {
        refuseSecondSource(table, *environment, "environment");
        background.environment = readEnvironmentMap(TableField(*environment));
    }
    return background;
}

// --------------------------------------------------------------------- scene

constexpr std::array<std::string_view, 7> topLevelKeys{"render", "camera",     "materials", "objects",
                                                       "lights", "background", "import"};
constexpr std::array<std::string_view, 1> importKeys{"gltf"};

/// `[import] gltf = "model.glb"`: the file's meshes and lights join the
/// scene, and its camera unless the scene has a [camera].
void readImport(const TableField& table, bool hasCamera, ParseContext& context)
{
    table.rejectUnknownKeys(importKeys);
    const Field field = table.require("gltf");
    const fs::path path = readPath(field);
    if (!isGltfPath(path)) field.fail("expected a glTF file (.gltf or .glb), got " + quote(path.string()));
    checkRegularFile(field, path);
    try {
        importGltf(path, {}, !hasCamera, context);
    } catch (const SceneError&) {
        throw;
    } catch (const InputError& error) {
        field.fail(std::string("cannot import the glTF scene: ") + error.what());
    }
}

void readScene(const TableField& top, ParseContext& context)
{
    top.rejectUnknownKeys(topLevelKeys);
    Scene& scene = context.scene;
    if (const auto render = top.find("render")) scene.render = readRender(TableField(*render));
    const std::optional<Field> import = top.find("import");
    const std::optional<Field> camera = top.find("camera");
    if (camera || !import) scene.camera = readCamera(TableField(top.require("camera")));
    if (const auto materials = top.find("materials")) scene.materials = readMaterials(TableField(*materials), context);
    const MaterialIndex materialIndex(scene.materials);
    const auto object = [&](const TableField& table) { readObject(table, materialIndex, context); };
    if (const auto objects = top.find("objects")) forEachTable(*objects, object);
    const auto light = [&](const TableField& table) { readLight(table, context); };
    if (const auto lights = top.find("lights")) forEachTable(*lights, light);
    if (const auto background = top.find("background")) scene.background = readBackground(TableField(*background));
    // After the scene's own materials and objects: the file's materials are appended to them.
    if (import) readImport(TableField(*import), camera.has_value(), context);
}

} // namespace

Scene parseSceneString(std::string_view text, const std::string& path)
{
    Scene scene;
    MeshGeometryCache meshes;
    auto textures = std::make_shared<TextureAtlas>();
    ParseContext context{scene, *textures, meshes, {}};
    const TomlSource source{path, fs::path(path).parent_path()};
    const toml::table root = parseToml(text, source);
    readScene(TableField(Field(source, root, "")), context);
    textures->settle(); // the images, decoded in parallel: a bad one is refused here, at its key
    if (scene.background.environment) {
        if (auto warning = latLongShapeWarning(*scene.background.environment, path + ": background.environment.file"))
            scene.warnings.push_back(*warning);
    }
    if (!sceneGivesLight(scene))
        scene.warnings.push_back(path + ": nothing in the scene gives light (no [[lights]], no emission, a black "
                                        "background without a map): the image will be black");
    scene.path = path;
    scene.fileHash = fnv1a64(text);
    if (textures->recordCount() > 0) scene.textures = std::move(textures);
    return scene;
}

Material parseMaterialTable(std::string_view text, const std::string& source, const std::string& name,
                            const std::filesystem::path& baseDir)
{
    Scene scratch;
    MeshGeometryCache meshes;
    TextureAtlas textures;
    ParseContext context{scratch, textures, meshes, {}};
    const TomlSource toml{source, baseDir};
    const toml::table root = parseToml(text, toml);
    const Field table(toml, root, "materials." + name);
    Material material = readMaterial(name, TableField(table), context);
    // The scene's textures live in one atlas made with the scene; a new one would need a new upload path.
    if (material.hasTextures() || textures.recordCount() > 0)
        table.fail("a material set from outside the scene file cannot use textures (write it in the scene file)");
    return material;
}

std::optional<std::string> latLongShapeWarning(const EnvironmentMap& map, const std::string& what)
{
    ImageExtent extent;
    try {
        extent = imageFileExtent(map.path);
    } catch (const InputError&) {
        return std::nullopt;
    }
    const uint64_t w = extent.width, h = extent.height;
    if (h == 0 || w == 2 * h || w == 2 * (h - 1)) return std::nullopt;
    return what + " " + map.path + " is " + extent.str() +
           ", not 2:1: a lat-long map spans 360 degrees across and 180 down, so it will look stretched (a "
           "cubemap face is a [background.cubemap] face)";
}

Scene parseSceneFile(const std::string& path) { return parseSceneString(readFileBytes(path, "scene file"), path); }

} // namespace vkrt
