// Scene-file reader: TOML text -> toml++ tree -> validated Scene.
//
// Every check reports the exact position of the offending value (or of the
// enclosing table when something is missing) together with the value's full
// dotted path, because scene files are written by hand and an error that only
// says "bad radius" is useless in a file with a hundred spheres. The located
// reading itself is scene/TomlReader.h; this file knows what a scene holds.
#include "scene/SceneParser.h"

#include "material/Metals.h"
#include "mesh/MeshGeometry.h"
#include "mesh/MeshLoader.h"
#include "scene/FileMaterialImport.h"
#include "scene/SceneOverrides.h"

#include "scene/TextureParameters.h"
#include "scene/TomlReader.h"
#include "util/Hash.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace vkrt {
namespace {

namespace fs = std::filesystem;
using Keys = KeyList;

// ------------------------------------------------------------ scalar values

double readIor(const Field& field)
{
    const double value = readNumber(field);
    if (value < 1) field.fail("must be >= 1, got " + formatNumber(value));
    if (value > SceneLimits::maxIor)
        field.fail("must be <= " + formatNumber(SceneLimits::maxIor) + ", got " + formatNumber(value));
    return value;
}

double readFov(const Field& field)
{
    const double value = readNumber(field);
    if (!(value > 0 && value < 180))
        field.fail("must be strictly between 0 and 180 degrees, got " + formatNumber(value));
    return value;
}

// ---------------------------------------------------------- vectors, colours

std::array<glm::dvec3, 3> readVertices(const Field& field) { return readTriple(field, "points", readVector); }

enum class ColorRange { Unit, NonNegative };

double checkChannel(const Field& field, double value, ColorRange range)
{
    if (range == ColorRange::Unit && !(value >= 0 && value <= 1))
        field.fail("must be in [0, 1], got " + formatNumber(value));
    if (value < 0) field.fail("must be >= 0, got " + formatNumber(value));
    // Colours reach the GPU as they are, in 32-bit floats, where this would be
    // infinite. (Positions may exceed it: they are made camera-relative in
    // double precision first.)
    if (value > std::numeric_limits<float>::max())
        field.fail("must be at most 3.4e38 (the largest 32-bit float; vkrt renders with those), got " +
                   formatNumber(value));
    return value;
}

/// A colour is three channels or one number meaning grey.
Color readColor(const Field& field, ColorRange range)
{
    const auto channel = [range](const Field& f) { return checkChannel(f, readNumber(f), range); };
    if (field.node().is_number()) return Color(channel(field));
    if (!field.node().is_array())
        field.fail("expected a colour (a number or an array of 3 numbers), got " + describeType(field.node()));
    const auto c = readTriple(field, "numbers", channel);
    return {c[0], c[1], c[2]};
}

Color readUnitColor(const Field& field) { return readColor(field, ColorRange::Unit); }
Color readRadiance(const Field& field) { return readColor(field, ColorRange::NonNegative); }

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

constexpr std::array<std::string_view, 6> cameraKeys{"eye", "target", "up", "fov", "width", "height"};

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
    camera.fovY = readFov(table.require("fov"));
    readResolution(table, camera);
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
constexpr std::array<std::string_view, 6> pbrKeys{"type",      "base_color", "metallic",
                                                  "roughness", "emission",   "normal_map"};

/// The textures of the scene being parsed (set by parseSceneString for the duration of a parse).
thread_local TextureAtlas* t_textures = nullptr;

/// A colour parameter: a value, or a texture table whose texel is the colour
/// (the constant becomes 1, which the texel multiplies on the GPU).
Color readColorParameter(const TableField& table, std::string_view key, Color fallback, Material& material,
                         TextureSlot slot)
{
    const std::optional<Field> field = table.find(key);
    if (!field) return fallback;
    if (!isTextureTable(*field)) return readUnitColor(*field);
    VKRT_CHECK(t_textures != nullptr);
    material.textures[size_t(slot)] = readTextureTable(*field, TextureUse::Color, *t_textures);
    return Color(1.0);
}

/// A parameter in [0, 1] (roughness, metallic): a value or a texture table.
double readUnitParameter(const TableField& table, std::string_view key, double fallback, Material& material,
                         TextureSlot slot)
{
    const std::optional<Field> field = table.find(key);
    if (!field) return fallback;
    if (!isTextureTable(*field)) return readNumberIn(*field, NumberRange{0.0, 1.0});
    VKRT_CHECK(t_textures != nullptr);
    material.textures[size_t(slot)] = readTextureTable(*field, TextureUse::Scalar, *t_textures);
    return 1.0;
}

void readNormalMap(const TableField& table, Material& material)
{
    const std::optional<Field> field = table.find("normal_map");
    if (!field) return;
    if (!isTextureTable(*field))
        field->fail("expected a texture table ({ texture = \"normals.png\", ... }), got " +
                    describeType(field->node()));
    VKRT_CHECK(t_textures != nullptr);
    material.textures[size_t(TextureSlot::Normal)] =
        readTextureTable(*field, TextureUse::NormalMap, *t_textures, &material.normalStrength);
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

void readLambert(const TableField& table, Material& material)
{
    material.diffuse = readColorParameter(table, "albedo", Color(0.8), material, TextureSlot::Color);
}

void readPhong(const TableField& table, Material& material)
{
    material.diffuse = readColorParameter(table, "diffuse", Color(0.8), material, TextureSlot::Color);
    material.specular = readColorParameter(table, "specular", Color(0.0), material, TextureSlot::Specular);
    material.exponent = readOr(table, "shininess", 32.0, readNonNegative);
}

/// Mirror and glossy share an optional Schlick term whose R0 comes from `ior`.
void readReflectorFresnelTerm(const TableField& table, Material& material)
{
    material.fresnel = readOr(table, "fresnel", FresnelMode::None, readReflectorFresnel);
    material.ior = readOr(table, "ior", 1.5, readIor);
}

void readMirror(const TableField& table, Material& material)
{
    material.specular = readColorParameter(table, "reflectance", Color(1.0), material, TextureSlot::Specular);
    readReflectorFresnelTerm(table, material);
}

void readGlossy(const TableField& table, Material& material)
{
    material.specular = readColorParameter(table, "reflectance", Color(1.0), material, TextureSlot::Specular);
    material.exponent = readOr(table, "exponent", 100.0, readNonNegative);
    readReflectorFresnelTerm(table, material);
}

void readDielectric(const TableField& table, Material& material)
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

void readConductor(const TableField& table, Material& material)
{
    material.roughness = readUnitParameter(table, "roughness", 0.0, material, TextureSlot::Roughness);
    material.anisotropy = readOr(table, "anisotropy", 0.0, readAnisotropy);
    material.specular = readColorParameter(table, "tint", Color(1.0), material, TextureSlot::Specular);
    readConductorIor(table, material);
}

/// Roughness 0 is the smooth dielectric itself: the same kind, kernel and
/// image. The default is Mitsuba's roughdielectric alpha = 0.1.
void readRoughDielectric(const TableField& table, Material& material)
{
    readDielectric(table, material);
    material.roughness = readUnitParameter(table, "roughness", std::sqrt(0.1), material, TextureSlot::Roughness);
    if (material.roughness == 0.0) material.type = MaterialType::Dielectric; // never with a texture (its constant is 1)
}

/// Mitsuba's defaults: polypropylene (1.49), diffuse 0.5; roughness 0 is the smooth coating.
void readPlastic(const TableField& table, Material& material)
{
    material.diffuse = readColorParameter(table, "diffuse", Color(0.5), material, TextureSlot::Color);
    if (const auto roughness = table.find("roughness"); roughness && isTextureTable(*roughness))
        roughness->fail("a plastic's roughness cannot be a texture: its coating's energy table is computed per "
                        "material (use a constant, or a conductor or pbr material)");
    material.roughness = readOr(table, "roughness", 0.0, readUnitInterval);
    material.ior = readOr(table, "ior", 1.49, readIor);
    if (material.ior == 1.0) table.find("ior")->fail("must differ from 1 (a coating of index 1 is no coating)");
}

/// glTF 2.0's defaults: base colour 1, metallic 1, roughness 1.
void readPbr(const TableField& table, Material& material)
{
    material.diffuse = readColorParameter(table, "base_color", Color(1.0), material, TextureSlot::Color);
    material.metallic = readUnitParameter(table, "metallic", 1.0, material, TextureSlot::Metallic);
    material.roughness = readUnitParameter(table, "roughness", 1.0, material, TextureSlot::Roughness);
    material.emission = readOr(table, "emission", Color(0.0), readRadiance);
}

struct MaterialKind {
    std::string_view name;
    MaterialType type;
    Keys keys;
    void (*read)(const TableField&, Material&);
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

Material readMaterial(std::string_view name, const TableField& table)
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
    kind.read(table, material);
    readNormalMap(table, material);
    return material;
}

std::vector<Material> readMaterials(const TableField& table)
{
    std::vector<Material> materials;
    for (const auto& [name, field] : table.entriesInFileOrder())
        materials.push_back(readMaterial(name, TableField(field)));
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

constexpr std::array<std::string_view, 4> sphereKeys{"shape", "material", "center", "radius"};
constexpr std::array<std::string_view, 4> boxKeys{"shape", "material", "min", "max"};
constexpr std::array<std::string_view, 3> triangleKeys{"shape", "material", "vertices"};
constexpr std::array<std::string_view, 4> planeKeys{"shape", "material", "point", "normal"};

void readSphere(const TableField& table, uint32_t material, Scene& scene)
{
    scene.spheres.push_back({readVector(table.require("center")), readPositive(table.require("radius")), material});
}

void checkBoxExtent(const Field& maxField, const glm::dvec3& min, const glm::dvec3& max)
{
    static constexpr char axes[] = "xyz";
    for (int axis = 0; axis < 3; ++axis) {
        if (min[axis] < max[axis]) continue;
        maxField.fail("must be greater than min in every component, but " + std::string(1, axes[axis]) +
                      ": min = " + formatNumber(min[axis]) + " >= max = " + formatNumber(max[axis]));
    }
}

void readBox(const TableField& table, uint32_t material, Scene& scene)
{
    const glm::dvec3 min = readVector(table.require("min"));
    const Field maxField = table.require("max");
    const glm::dvec3 max = readVector(maxField);
    checkBoxExtent(maxField, min, max);
    scene.boxes.push_back({min, max, material});
}

void readTriangle(const TableField& table, uint32_t material, Scene& scene)
{
    // Degenerate triangles are accepted on purpose: meshes exported by tools
    // contain them, and the renderer handles them.
    scene.triangles.push_back({readVertices(table.require("vertices")), material});
}

void readPlane(const TableField& table, uint32_t material, Scene& scene)
{
    const glm::dvec3 point = readVector(table.require("point"));
    const Field normalField = table.require("normal");
    const std::optional<glm::dvec3> normal = normalized(readVector(normalField));
    if (!normal) normalField.fail("must not be zero-length");
    scene.planes.push_back({point, *normal, material});
}

constexpr std::array<std::string_view, 11> meshKeys{"shape",
                                                    "material",
                                                    "file",
                                                    "scale",
                                                    "rotate",
                                                    "translate",
                                                    "matrix",
                                                    "normals",
                                                    "emission",
                                                    "two_sided",
                                                    "allow_outside_references"};

void checkRegularFile(const Field& field, const fs::path& path);
constexpr std::array<std::string_view, 2> rotateKeys{"axis", "angle"};

/// The geometries of the scene being parsed, so that instances of one file
/// share one (set by parseSceneString for the duration of a parse).
thread_local MeshGeometryCache* t_meshCache = nullptr;
/// The scene materials made from each geometry's file materials, so that instances share them.
thread_local std::map<const MeshGeometry*, std::vector<uint32_t>>* t_fileMaterials = nullptr;

/// readMesh's material for `material = "file"`.
constexpr uint32_t kFileMaterialIndex = UINT32_MAX;

std::vector<uint32_t> fileMaterialsOf(const MeshGeometry& geometry, const Field& materialField, Scene& scene)
{
    VKRT_CHECK(t_fileMaterials != nullptr && t_textures != nullptr);
    const auto known = t_fileMaterials->find(&geometry);
    if (known != t_fileMaterials->end()) return known->second;
    std::vector<uint32_t> indices;
    try {
        indices = importFileMaterials(geometry, materialField.location(), *t_textures, scene.materials, scene.warnings);
    } catch (const SceneError&) {
        throw;
    } catch (const InputError& error) {
        materialField.fail(error.what());
    }
    t_fileMaterials->emplace(&geometry, indices);
    return indices;
}

/// `scale`: one number or three, none zero (a negative one mirrors).
glm::dvec3 readScale(const Field& field)
{
    glm::dvec3 scale = field.node().is_array() ? readVector(field) : glm::dvec3(readNumber(field));
    for (int axis = 0; axis < 3; ++axis)
        if (scale[axis] == 0.0) field.fail("must not be zero (it would flatten the mesh)");
    return scale;
}

/// `rotate = { axis = [x, y, z], angle = degrees }`, right-handed about the axis.
glm::dmat4 readRotation(const Field& field)
{
    const TableField table(field);
    table.rejectUnknownKeys(rotateKeys);
    const Field axisField = table.require("axis");
    const std::optional<glm::dvec3> axis = normalized(readVector(axisField));
    if (!axis) axisField.fail("must not be zero-length");
    const double angle = readNumber(table.require("angle"));
    return glm::rotate(glm::dmat4(1.0), glm::radians(angle), *axis);
}

/// `matrix`: four rows of four numbers, an invertible affine transform.
glm::dmat4 readMatrix(const Field& field)
{
    const toml::array* rows = field.node().as_array();
    if (!rows || rows->size() != 4)
        field.fail("expected 4 rows of 4 numbers, got " +
                   (rows ? std::to_string(rows->size()) + " row(s)" : describeType(field.node())));
    glm::dmat4 m(1.0);
    for (size_t r = 0; r < 4; ++r) {
        const Field row = field.element(r, *rows->get(r));
        const toml::array* values = row.node().as_array();
        if (!values || values->size() != 4)
            row.fail("expected a row of 4 numbers, got " +
                     (values ? std::to_string(values->size()) + " element(s)" : describeType(row.node())));
        for (size_t c = 0; c < 4; ++c) m[int(c)][int(r)] = readNumber(row.element(c, *values->get(c)));
    }
    if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
        field.fail("the last row must be [0, 0, 0, 1] (an affine transform)");
    const double det = glm::determinant(glm::dmat3(m));
    if (!(std::abs(det) > 0.0) || !std::isfinite(det)) field.fail("is singular (its 3x3 part has determinant 0)");
    const glm::dmat4 inverse = glm::inverse(m);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(inverse[c][r])) field.fail("cannot be inverted in double precision");
    return m;
}

glm::dmat4 readObjectToWorld(const TableField& table)
{
    if (const auto matrix = table.find("matrix")) {
        for (std::string_view key : {"scale", "rotate", "translate"})
            if (const auto other = table.find(key))
                other->fail("cannot be combined with matrix (line " + std::to_string(matrix->location().line) +
                            "); give the whole transform as the matrix, or use scale, rotate and translate");
        return readMatrix(*matrix);
    }
    const glm::dvec3 scale = readOr(table, "scale", glm::dvec3(1.0), readScale);
    const glm::dmat4 rotation = readOr(table, "rotate", glm::dmat4(1.0), readRotation);
    const glm::dvec3 translation = readOr(table, "translate", glm::dvec3(0.0), readVector);
    return glm::translate(glm::dmat4(1.0), translation) * rotation * glm::scale(glm::dmat4(1.0), scale);
}

constexpr std::array<EnumName<NormalMode>, 3> normalModes{
    {{"file", NormalMode::File}, {"smooth", NormalMode::Smooth}, {"face", NormalMode::Face}}};

std::filesystem::path readMeshPath(const Field& field)
{
    const fs::path path = readPath(field);
    const std::string extension = lowercase(path.extension().string());
    const auto& supported = supportedMeshExtensions();
    if (std::find(supported.begin(), supported.end(), extension) == supported.end()) {
        std::vector<std::string_view> names(supported.begin(), supported.end());
        field.fail("unsupported mesh file " + quote(path.string()) + " (supported: " + joinList(names) + ")");
    }
    checkRegularFile(field, path);
    return path;
}

/// Every material a mesh instance uses.
std::vector<uint32_t> materialsOf(const Mesh& mesh)
{
    return mesh.fileMaterials.empty() ? std::vector<uint32_t>{mesh.material} : mesh.fileMaterials;
}

/// Textures need the file's texture coordinates; an emissive material needs no `emission` of the mesh's own.
void checkMeshMaterials(const Mesh& mesh, const Field& materialField, const Scene& scene)
{
    for (uint32_t index : materialsOf(mesh)) {
        const Material& m = scene.materials[index];
        if (m.hasTextures() && mesh.geometry->data.uvs.empty())
            materialField.fail("material " + quote(m.name) + " has textures, but the mesh file " +
                               quote(mesh.geometry->file.string()) +
                               " has no texture coordinates (export it with uvs)");
        if (m.emission != Color(0.0) && mesh.emission != Color(0.0))
            materialField.fail("material " + quote(m.name) +
                               " emits already; give the mesh either `emission` or an emissive material");
    }
}

void readMesh(const TableField& table, uint32_t material, Scene& scene)
{
    Mesh mesh;
    mesh.material = material;
    mesh.where = table.field().location();
    const Field fileField = table.require("file");
    const fs::path file = readMeshPath(fileField);
    const NormalMode normals = readOr(table, "normals", NormalMode::File, [](const Field& field) {
        return readChoice(field, "normals mode", normalModes).value;
    });
    // The scene is the user's own, so it may trust a mesh file's references outside its folder.
    MeshLoadOptions loadOptions;
    loadOptions.allowOutsideReferences = readOr(table, "allow_outside_references", false, readBool);
    mesh.objectToWorld = readObjectToWorld(table);
    mesh.emission = readOr(table, "emission", Color(0.0), readRadiance);
    if (const auto twoSided = table.find("two_sided")) {
        if (!table.find("emission")) twoSided->fail("only applies to an emissive mesh (one with `emission`)");
        mesh.twoSided = readBool(*twoSided);
    }
    try {
        VKRT_CHECK(t_meshCache != nullptr);
        mesh.geometry = t_meshCache->get(file, normals, loadOptions);
    } catch (const SceneError&) {
        throw;
    } catch (const InputError& error) {
        fileField.fail(std::string("cannot load the mesh: ") + error.what());
    }
    const Field materialField = table.require("material");
    if (material == kFileMaterialIndex) {
        mesh.fileMaterials = fileMaterialsOf(*mesh.geometry, materialField, scene);
        mesh.material = mesh.fileMaterials.front();
    }
    checkMeshMaterials(mesh, materialField, scene);
    scene.meshes.push_back(std::move(mesh));
}

struct ShapeReader {
    std::string_view name;
    Keys keys;
    void (*read)(const TableField&, uint32_t, Scene&);
};

#define VKRT_SHAPE_KIND_ENTRY(KIND, Type, name, value, field, array, ARRAY, capacity) \
    ShapeReader{#name, field##Keys, read##Type},
const std::array<ShapeReader, kShapeKindCount> shapeKinds{{VKRT_SHAPE_KINDS(VKRT_SHAPE_KIND_ENTRY)}};
#undef VKRT_SHAPE_KIND_ENTRY
const std::vector<std::string_view> allShapeKeys = keysOfEveryKind(shapeKinds);

void readObject(const TableField& table, const MaterialIndex& materials, Scene& scene)
{
    const ShapeReader kind = readChoice(table.require("shape"), "shape", shapeKinds);
    table.rejectUnknownKeys(kind.keys, allShapeKeys, "shape " + quote(kind.name));
    const Field materialField = table.require("material");
    const bool mesh = kind.read == readMesh;
    if (mesh && readString(materialField) == kFileMaterial) return readMesh(table, kFileMaterialIndex, scene);
    const uint32_t material = materials.resolve(materialField);
    if (!mesh && scene.materials[material].emission != Color(0.0))
        materialField.fail("material " + quote(scene.materials[material].name) +
                           " emits; only meshes can use an emissive material (use a mesh, or a [[lights]] entry)");
    kind.read(table, material, scene);
}

// -------------------------------------------------------------------- lights

constexpr std::array<std::string_view, 3> pointLightKeys{"type", "position", "intensity"};
constexpr std::array<std::string_view, 4> triangleLightKeys{"type", "vertices", "radiance", "two_sided"};

void readPointLight(const TableField& table, Scene& scene)
{
    scene.pointLights.push_back({readVector(table.require("position")), readRadiance(table.require("intensity"))});
}

void readTriangleLight(const TableField& table, Scene& scene)
{
    TriangleLight light;
    light.vertices = readVertices(table.require("vertices"));
    light.radiance = readRadiance(table.require("radiance"));
    light.twoSided = readOr(table, "two_sided", false, readBool);
    scene.triangleLights.push_back(light);
}

struct LightReader {
    std::string_view name;
    Keys keys;
    void (*read)(const TableField&, Scene&);
};

#define VKRT_LIGHT_KIND_ENTRY(KIND, Type, name, value, field, array, ARRAY, capacity) \
    LightReader{#name, field##Keys, read##Type},
const std::array<LightReader, kLightKindCount> lightKinds{{VKRT_LIGHT_KINDS(VKRT_LIGHT_KIND_ENTRY)}};
#undef VKRT_LIGHT_KIND_ENTRY
const std::vector<std::string_view> allLightKeys = keysOfEveryKind(lightKinds);

void readLight(const TableField& table, Scene& scene)
{
    const LightReader kind = readChoice(table.require("type"), "light type", lightKinds);
    table.rejectUnknownKeys(kind.keys, allLightKeys, "light type " + quote(kind.name));
    kind.read(table, scene);
}

// ---------------------------------------------------------------- background

constexpr std::array<std::string_view, 2> backgroundKeys{"color", "cubemap"};
/// Vulkan cube face order, matching Cubemap::facePaths.
constexpr std::array<std::string_view, 6> faceKeys{"px", "nx", "py", "ny", "pz", "nz"};

void checkImageExtension(const Field& field, const fs::path& path)
{
    const std::string extension = lowercase(path.extension().string());
    if (extension != ".exr" && extension != ".png")
        field.fail("cubemap faces must be .exr or .png files, got " + quote(path.string()));
}

void checkRegularFile(const Field& field, const fs::path& path)
{
    std::error_code error;
    const fs::file_status status = fs::status(path, error);
    if (!fs::exists(status)) field.fail("file " + quote(path.string()) + " does not exist");
    if (!fs::is_regular_file(status)) field.fail(quote(path.string()) + " is not a regular file");
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

Background readBackground(const TableField& table)
{
    table.rejectUnknownKeys(backgroundKeys);
    Background background;
    background.color = readOr(table, "color", Color(0.0), readRadiance);
    const std::optional<Field> cubemap = table.find("cubemap");
    if (!cubemap) return background;
    if (const auto color = table.find("color"))
        cubemap->fail("cannot be combined with background.color (line " + std::to_string(color->location().line) +
                      "); use one or the other");
    background.cubemap = readCubemap(TableField(*cubemap));
    return background;
}

// --------------------------------------------------------------------- scene

/// Every shading point samples each `[[lights]]` triangle and tests each for
/// shadow rays without a BVH: the Whitted integrator's cost grows with the
/// square of their number, the path integrator's linearly (docs/robustness.md,
/// 64x48 pixels on 2 cores: Whitted 84k samples/s at 50 lights, 6.2k at 200,
/// 0.75k at 500; path 46k at 500, 5.1k at 5000). An emissive mesh is sampled
/// from a power-proportional table and traced through its BVH instead.
void warnAboutManyTriangleLights(const Field& lights, Scene& scene)
{
    const size_t count = scene.triangleLights.size();
    const bool whitted = scene.render.integrator == Integrator::Whitted;
    if (count <= (whitted ? 64u : 1000u)) return;
    scene.warnings.push_back(lights.location().str() + ": " + std::to_string(count) +
                             " triangle lights: each shading point samples every one, so the " +
                             (whitted ? "Whitted integrator's cost grows with the square of their number"
                                      : "path integrator's cost grows with their number") +
                             "; many emitting triangles render much faster as a mesh with `emission` "
                             "(docs/scene-format.md)");
}

constexpr std::array<std::string_view, 6> topLevelKeys{"render",  "camera", "materials",
                                                       "objects", "lights", "background"};

Scene readScene(const TableField& top)
{
    top.rejectUnknownKeys(topLevelKeys);
    Scene scene;
    if (const auto render = top.find("render")) scene.render = readRender(TableField(*render));
    scene.camera = readCamera(TableField(top.require("camera")));
    if (const auto materials = top.find("materials")) scene.materials = readMaterials(TableField(*materials));
    const MaterialIndex materialIndex(scene.materials);
    const auto object = [&](const TableField& table) { readObject(table, materialIndex, scene); };
    if (const auto objects = top.find("objects")) forEachTable(*objects, object);
    const auto light = [&](const TableField& table) { readLight(table, scene); };
    if (const auto lights = top.find("lights")) {
        forEachTable(*lights, light);
        warnAboutManyTriangleLights(*lights, scene);
    }
    if (const auto background = top.find("background")) scene.background = readBackground(TableField(*background));
    return scene;
}

} // namespace

/// Points a thread-local at `value` for one parse, restoring what it held before.
template <class T>
class ParseState {
public:
    ParseState(T*& slot, T* value) : m_slot(slot), m_previous(slot) { slot = value; }
    ~ParseState() { m_slot = m_previous; }
    ParseState(const ParseState&) = delete;
    ParseState& operator=(const ParseState&) = delete;

private:
    T*& m_slot;
    T* m_previous;
};

Scene parseSceneString(std::string_view text, const std::string& path)
{
    MeshGeometryCache meshes;
    auto textures = std::make_shared<TextureAtlas>();
    std::map<const MeshGeometry*, std::vector<uint32_t>> fileMaterials;
    const ParseState meshState(t_meshCache, &meshes);
    const ParseState textureState(t_textures, textures.get());
    const ParseState fileMaterialState(t_fileMaterials, &fileMaterials);
    const TomlSource source{path, fs::path(path).parent_path()};
    const toml::table root = parseToml(text, source);
    Scene scene = readScene(TableField(Field(source, root, "")));
    scene.path = path;
    scene.fileHash = fnv1a64(text);
    if (textures->recordCount() > 0) scene.textures = std::move(textures);
    return scene;
}

Scene parseSceneFile(const std::string& path) { return parseSceneString(readFileBytes(path, "scene file"), path); }

} // namespace vkrt
