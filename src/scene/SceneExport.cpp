#include "scene/SceneExport.h"

#include "mesh/MeshGeometry.h"
#include "scene/FeatureSet.h"
#include "texture/TextureAtlas.h"

#include <nlohmann/json.hpp>
#include <numbers>

#include <filesystem>
#include <limits>

namespace vkrt {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

// ------------------------------------------------------------------ values

Json vec(const glm::dvec3& v) { return Json::array({v.x, v.y, v.z}); }
Json vec(const glm::dvec2& v) { return Json::array({v.x, v.y}); }

Json points(const std::array<glm::dvec3, 3>& p) { return Json::array({vec(p[0]), vec(p[1]), vec(p[2])}); }

/// Row by row, as the scene format's `matrix` (glm stores columns).
Json rows(const glm::dmat4& m)
{
    Json out = Json::array();
    for (int r = 0; r < 4; ++r) out.push_back(Json::array({m[0][r], m[1][r], m[2][r], m[3][r]}));
    return out;
}

Json rows(const glm::dmat3& m)
{
    Json out = Json::array();
    for (int r = 0; r < 3; ++r) out.push_back(Json::array({m[0][r], m[1][r], m[2][r]}));
    return out;
}

Json bounds(const Aabb& box) { return {{"min", vec(box.lower)}, {"max", vec(box.upper)}}; }

/// Absolute and without `.` or `..` steps; symlinks are kept (the file vkrt opened by that name).
std::string absolutePath(const fs::path& path) { return fs::absolute(path).lexically_normal().string(); }

std::string hex64(uint64_t value)
{
    static constexpr char digits[] = "0123456789abcdef";
    std::string out(16, '0');
    for (int i = 15; i >= 0; --i, value >>= 4) out[size_t(i)] = digits[value & 15];
    return out;
}

const char* fresnelName(FresnelMode mode)
{
    switch (mode) {
    case FresnelMode::None: return "none";
    case FresnelMode::Schlick: return "schlick";
    case FresnelMode::Exact: return "exact";
    case FresnelMode::Default: break;
    }
    return "default";
}

const char* normalsName(NormalMode mode)
{
    switch (mode) {
    case NormalMode::File: return "file";
    case NormalMode::Smooth: return "smooth";
    case NormalMode::Face: return "face";
    }
    return "file";
}

const char* wrapName(uint32_t wrap)
{
    switch (wrap) {
    case gpu::TEXTURE_WRAP_CLAMP: return "clamp";
    case gpu::TEXTURE_WRAP_MIRROR: return "mirror";
    default: return "repeat";
    }
}

/// A record's filters (gpu::TEXTURE_FILTER_* bits): magnified, minified within a level, between levels.
Json filterJson(uint32_t bits)
{
    auto within = [&](uint32_t nearest) { return bits & nearest ? "nearest" : "linear"; };
    const char* mip = bits & gpu::TEXTURE_FILTER_MIP_NONE      ? "none"
                      : bits & gpu::TEXTURE_FILTER_MIP_NEAREST ? "nearest"
                                                               : "linear";
    return {{"mag", within(gpu::TEXTURE_FILTER_MAG_NEAREST)},
            {"min", within(gpu::TEXTURE_FILTER_MIN_NEAREST)},
            {"mip", mip}};
}

const char* encodingName(uint32_t format)
{
    switch (format) {
    case gpu::TEXTURE_FORMAT_RGBA8_SRGB: return "rgba8_srgb";
    case gpu::TEXTURE_FORMAT_RGBA8_UNORM: return "rgba8_linear";
    default: return "rgba16f";
    }
}

// ---------------------------------------------------------------- textures

/// The scene's texture records, for the materials' texture slots.
struct TextureTable {
    const TextureAtlas* atlas = nullptr;
    std::vector<gpu::TextureRecord> records;
};

TextureTable textureTable(const Scene& scene)
{
    TextureTable table{scene.textures.get(), {}};
    // The atlas keeps each record's size, encoding and wrap modes only in its GPU form.
    if (table.atlas) table.records = table.atlas->records();
    return table;
}

/// A record's image: its file (absolute) unless it came from bytes inside a mesh file.
Json textureSource(const TextureTable& table, uint32_t record)
{
    const std::string& name = table.atlas->nameOf(record);
    std::error_code error;
    const bool isFile = fs::is_regular_file(name, error);
    return {{"name", name}, {"file", isFile ? Json(absolutePath(name)) : Json(nullptr)}};
}

Json textureRecord(const TextureTable& table, uint32_t record)
{
    const gpu::TextureRecord& r = table.records[record];
    Json out = textureSource(table, record);
    out["width"] = r.width;
    out["height"] = r.height;
    out["levels"] = r.levels;
    out["encoding"] = encodingName(r.format);
    out["wrap"] = Json::array({wrapName(r.wrapU), wrapName(r.wrapV)});
    out["filter"] = filterJson(r.filters);
    return out;
}

Json textureRecords(const TextureTable& table)
{
    Json out = Json::array();
    for (uint32_t i = 0; i < table.records.size(); ++i) out.push_back(textureRecord(table, i));
    return out;
}

// --------------------------------------------------------------- materials

/// Writes one material's parameters under the scene format's keys.
class MaterialWriter {
public:
    MaterialWriter(const Material& material, const TextureTable& textures, Json& out)
        : m_material(material),
          m_textures(textures),
          m_out(out)
    {
    }

    const Material& material() const { return m_material; }
    void value(const char* key, Json value) { m_out[key] = std::move(value); }
    /// A parameter that may be textured: its constant, and its texture if it has one.
    void textured(const char* key, Json constant, TextureSlot slot)
    {
        m_out[key] = std::move(constant);
        texture(key, slot);
    }

    void texture(const char* key, TextureSlot slot)
    {
        const std::optional<MaterialTexture>& t = m_material.texture(slot);
        if (!t) return;
        static constexpr const char* channels[] = {"r", "g", "b", "a"};
        Json entry = textureSource(m_textures, t->record);
        entry["record"] = t->record;
        entry["channel"] = channels[t->channel & 3];
        entry["scale"] = vec(t->scale);
        entry["offset"] = vec(t->offset);
        entry["rotation"] = t->rotation;
        m_out["textures"][key] = std::move(entry);
    }

private:
    const Material& m_material;
    const TextureTable& m_textures;
    Json& m_out;
};

/// The Fresnel term the integrator uses for a material without a `fresnel` key.
FresnelMode resolvedFresnel(const Material& m, Integrator integrator)
{
    if (m.fresnel != FresnelMode::Default) return m.fresnel;
    if (m.type == MaterialType::Dielectric && integrator == Integrator::Whitted) return FresnelMode::Schlick;
    if (m.type == MaterialType::Dielectric || m.type == MaterialType::RoughDielectric) return FresnelMode::Exact;
    return FresnelMode::None;
}

/// A material kind of the registry, for the overloads below.
template <MaterialType T>
struct MaterialKindTag {
};

void fresnelTerm(MaterialWriter& w, Integrator integrator)
{
    w.value("fresnel", fresnelName(resolvedFresnel(w.material(), integrator)));
    w.value("fresnel_explicit", w.material().fresnel != FresnelMode::Default);
}

void parameters(MaterialKindTag<MaterialType::Lambert>, MaterialWriter& w, Integrator)
{
    w.textured("albedo", vec(w.material().diffuse), TextureSlot::Color);
}

void parameters(MaterialKindTag<MaterialType::Phong>, MaterialWriter& w, Integrator)
{
    w.textured("diffuse", vec(w.material().diffuse), TextureSlot::Color);
    w.textured("specular", vec(w.material().specular), TextureSlot::Specular);
    w.value("shininess", w.material().exponent);
}

void parameters(MaterialKindTag<MaterialType::Mirror>, MaterialWriter& w, Integrator integrator)
{
    w.textured("reflectance", vec(w.material().specular), TextureSlot::Specular);
    fresnelTerm(w, integrator);
    w.value("ior", w.material().ior);
}

void parameters(MaterialKindTag<MaterialType::Glossy>, MaterialWriter& w, Integrator integrator)
{
    w.textured("reflectance", vec(w.material().specular), TextureSlot::Specular);
    w.value("exponent", w.material().exponent);
    fresnelTerm(w, integrator);
    w.value("ior", w.material().ior);
}

void parameters(MaterialKindTag<MaterialType::Dielectric>, MaterialWriter& w, Integrator integrator)
{
    w.value("ior", w.material().ior);
    w.value("absorption", vec(w.material().absorption));
    fresnelTerm(w, integrator);
}

void parameters(MaterialKindTag<MaterialType::Conductor>, MaterialWriter& w, Integrator)
{
    w.textured("roughness", w.material().roughness, TextureSlot::Roughness);
    w.value("anisotropy", w.material().anisotropy);
    w.value("eta", vec(w.material().eta));
    w.value("k", vec(w.material().k));
    w.textured("tint", vec(w.material().specular), TextureSlot::Specular);
}

void parameters(MaterialKindTag<MaterialType::RoughDielectric>, MaterialWriter& w, Integrator integrator)
{
    parameters(MaterialKindTag<MaterialType::Dielectric>{}, w, integrator);
    w.textured("roughness", w.material().roughness, TextureSlot::Roughness);
}

void parameters(MaterialKindTag<MaterialType::Plastic>, MaterialWriter& w, Integrator)
{
    w.textured("diffuse", vec(w.material().diffuse), TextureSlot::Color);
    w.value("roughness", w.material().roughness);
    w.value("ior", w.material().ior);
}

void parameters(MaterialKindTag<MaterialType::Pbr>, MaterialWriter& w, Integrator)
{
    w.textured("base_color", vec(w.material().diffuse), TextureSlot::Color);
    w.textured("metallic", w.material().metallic, TextureSlot::Metallic);
    w.textured("roughness", w.material().roughness, TextureSlot::Roughness);
    w.textured("emission", vec(w.material().emission), TextureSlot::Emission);
    const PbrLayers& layers = w.material().layers;
    w.value("ior", w.material().ior);
    w.textured("specular", layers.specular, TextureSlot::SpecularFactor);
    w.textured("specular_color", vec(layers.specularColor), TextureSlot::Specular);
    w.textured("sheen_color", vec(layers.sheenColor), TextureSlot::SheenColor);
    w.textured("sheen_roughness", layers.sheenRoughness, TextureSlot::SheenRoughness);
    w.textured("clearcoat", layers.clearcoat, TextureSlot::Clearcoat);
    w.textured("clearcoat_roughness", layers.clearcoatRoughness, TextureSlot::ClearcoatRoughness);
    w.textured("transmission", layers.transmission, TextureSlot::Transmission);
    w.value("thin_walled", layers.thinWalled);
    w.value("absorption", vec(w.material().absorption));
    w.textured("iridescence", layers.iridescence, TextureSlot::Iridescence);
    w.value("iridescence_ior", layers.iridescenceIor);
    w.textured("iridescence_thickness", layers.iridescenceThicknessMax, TextureSlot::IridescenceThickness);
    w.value("iridescence_thickness_range",
            Json::array({layers.iridescenceThicknessMin, layers.iridescenceThicknessMax}));
    w.value("anisotropy", layers.anisotropy);
    w.value("anisotropy_rotation", layers.anisotropyRotation * 180.0 / std::numbers::pi);
    w.texture("anisotropy_texture", TextureSlot::Anisotropy);
    w.texture("clearcoat_normal_map", TextureSlot::ClearcoatNormal);
}

/// Every kind's parameters; a kind added to shared/Kinds.h without an overload above does not compile.
void kindParameters(MaterialWriter& w, Integrator integrator)
{
#define VKRT_EXPORT_MATERIAL_CASE(KIND, Type, name, value, delta) \
    case MaterialType::Type: parameters(MaterialKindTag<MaterialType::Type>{}, w, integrator); break;
    switch (w.material().type) {
        VKRT_MATERIAL_KINDS(VKRT_EXPORT_MATERIAL_CASE)
    }
#undef VKRT_EXPORT_MATERIAL_CASE
}

Json material(const Material& m, const TextureTable& textures, Integrator integrator)
{
    Json out = {{"name", m.name}, {"type", std::string(kindName(m.type))}};
    MaterialWriter writer(m, textures, out);
    kindParameters(writer, integrator);
    writer.texture("normal_map", TextureSlot::Normal);
    if (m.texture(TextureSlot::Normal)) out["textures"]["normal_map"]["strength"] = m.normalStrength;
    if (m.texture(TextureSlot::ClearcoatNormal))
        out["textures"]["clearcoat_normal_map"]["strength"] = m.clearcoatNormalStrength;
    if (!out.contains("textures")) out["textures"] = Json::object();
    // glTF alphaMode (file materials only); absent for opaque materials.
    if (m.alphaTested())
        out["alpha"] = {{"mode", m.alphaMode == AlphaMode::Mask ? "MASK" : "BLEND"},
                        {"cutoff", m.alphaCutoff},
                        {"alpha", m.alpha}};
    out["where"] = m.where.str();
    return out;
}

Json materials(const Scene& scene, const TextureTable& textures)
{
    Json out = Json::array();
    for (const Material& m : scene.materials) out.push_back(material(m, textures, scene.render.integrator));
    return out;
}

// ------------------------------------------------------- shapes and lights

Json record(const Sphere& s) { return {{"center", vec(s.center)}, {"radius", s.radius}, {"material", s.material}}; }

Json record(const Box& b) { return {{"min", vec(b.min)}, {"max", vec(b.max)}, {"material", b.material}}; }

Json record(const Triangle& t) { return {{"vertices", points(t.vertices)}, {"material", t.material}}; }

Json record(const Plane& p) { return {{"point", vec(p.point)}, {"normal", vec(p.normal)}, {"material", p.material}}; }

/// The box of every vertex placed by the instance's matrix (in double).
Aabb worldBounds(const Mesh& mesh)
{
    Aabb box;
    for (const glm::vec3& p : mesh.geometry->data.positions)
        box.extend(glm::dvec3(mesh.objectToWorld * glm::dvec4(glm::dvec3(p), 1.0)));
    return box;
}

Json geometry(const MeshGeometry& g)
{
    return {{"vertices", g.data.positions.size()},
            {"triangles", g.data.triangles.size()},
            {"has_normals", !g.data.normals.empty()},
            {"has_uvs", !g.data.uvs.empty()},
            {"has_uvs1", !g.data.uvs1.empty()},
            {"has_tangents", !g.data.tangents.empty()},
            {"bounds", bounds(g.bounds)}};
}

Json record(const Mesh& m)
{
    return {{"file", absolutePath(m.geometry->file)},
            {"normals", normalsName(m.geometry->normals)},
            {"matrix", rows(m.objectToWorld)},
            {"material", m.material},
            {"file_materials", m.fileMaterials},
            {"emission", vec(m.emission)},
            {"two_sided", m.twoSided},
            {"geometry", geometry(*m.geometry)},
            {"world_bounds", bounds(worldBounds(m))},
            {"where", m.where.str()}};
}

Json record(const PointLight& l) { return {{"position", vec(l.position)}, {"intensity", vec(l.intensity)}}; }

Json record(const DirectionalLight& l)
{
    return {{"direction", vec(l.direction)}, {"irradiance", vec(l.irradiance)}, {"angle", l.angle}};
}

Json record(const SpotLight& l)
{
    return {{"position", vec(l.position)},
            {"direction", vec(l.direction)},
            {"intensity", vec(l.intensity)},
            {"inner_cone_angle", l.innerConeAngle},
            {"outer_cone_angle", l.outerConeAngle}};
}

Json record(const TriangleLight& l)
{
    return {{"vertices", points(l.vertices)}, {"radiance", vec(l.radiance)}, {"two_sided", l.twoSided}};
}

/// One kind's records; a kind without a `record` overload does not compile.
template <class Record>
Json records(const std::vector<Record>& all)
{
    Json out = Json::array();
    for (const Record& r : all) out.push_back(record(r));
    return out;
}

#define VKRT_EXPORT_ARRAY(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    out[#name] = records(scene.array);

Json shapes(const Scene& scene)
{
    Json out = Json::object();
    VKRT_SHAPE_KINDS(VKRT_EXPORT_ARRAY)
    return out;
}

Json lights(const Scene& scene)
{
    Json out = Json::object();
    VKRT_LIGHT_KINDS(VKRT_EXPORT_ARRAY)
    return out;
}
#undef VKRT_EXPORT_ARRAY

// ------------------------------------------------- camera, render, background

Json camera(const Camera& c)
{
    return {{"eye", vec(c.eye)},
            {"target", vec(c.target)},
            {"up", vec(c.up)},
            {"fov", c.fovY},
            {"width", c.width},
            {"height", c.height},
            {"aperture_radius", c.apertureRadius},
            {"focus_distance", c.resolvedFocusDistance()},
            {"orthographic_height", c.orthographicHeight}};
}

Json renderSettings(const RenderSettings& r)
{
    return {{"integrator", integratorName(r.integrator)}, {"max_depth", r.maxDepth}};
}

Json background(const Background& b)
{
    Json out = {{"color", vec(b.color)}, {"cubemap", nullptr}, {"environment", nullptr}};
    if (b.cubemap) {
        static constexpr const char* faces[] = {"px", "nx", "py", "ny", "pz", "nz"};
        for (size_t i = 0; i < 6; ++i) out["cubemap"][faces[i]] = absolutePath(b.cubemap->facePaths[i]);
    }
    if (b.environment)
        out["environment"] = {{"file", b.environment->studio ? Json(nullptr) : Json(absolutePath(b.environment->path))},
                              {"builtin", b.environment->studio ? Json("studio") : Json(nullptr)},
                              {"scale", vec(b.environment->scale)},
                              {"matrix", rows(b.environment->rotation)}};
    return out;
}

Json source(const Scene& scene)
{
    const bool inMemory = scene.path == "<string>";
    return {{"path", inMemory ? scene.path : absolutePath(scene.path)}, {"hash", "fnv1a64:" + hex64(scene.fileHash)}};
}

} // namespace

nlohmann::ordered_json exportScene(const Scene& scene)
{
    const TextureTable textures = textureTable(scene);
    return {{"format", "vkrt-scene"},
            {"version", kSceneJsonVersion},
            {"scene", source(scene)},
            {"render", renderSettings(scene.render)},
            {"camera", camera(scene.camera)},
            {"materials", materials(scene, textures)},
            {"shapes", shapes(scene)},
            {"lights", lights(scene)},
            {"background", background(scene.background)},
            {"textures", textureRecords(textures)},
            {"warnings", scene.warnings}};
}

std::string exportSceneText(const Scene& scene)
{
    return exportScene(scene).dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

} // namespace vkrt
