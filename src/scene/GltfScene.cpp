// A glTF 2.0 file as a scene (scene/GltfScene.h). The meshes and materials
// come through the mesh reader (kinds/Mesh.cpp, which checks the file before
// assimp reads it); the cameras and lights are read here from the file's
// JSON, placed by the world transforms of the nodes that carry them.
#include "scene/GltfScene.h"

#include "mesh/FileMaterials.h"
#include "scene/SceneOverrides.h"
#include "scene/TomlReader.h"
#include "scene/kinds/Kinds.h"
#include "texture/TextureAtlas.h"
#include "mesh/MeshGeometry.h"
#include "util/Hash.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace vkrt {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

[[noreturn]] void fail(const fs::path& file, const std::string& what)
{
    throw InputError(file.string() + ": " + what);
}

std::string formatIndex(const char* array, size_t index) { return std::string(array) + "[" + std::to_string(index) + "]"; }

/// A finite number at `key` of `object`, or `fallback` when absent.
double number(const fs::path& file, const json& object, const char* key, double fallback, const std::string& where)
{
    if (!object.is_object() || !object.contains(key)) return fallback;
    const json& value = object[key];
    if (!value.is_number() || !std::isfinite(value.get<double>()))
        fail(file, where + "." + key + ": expected a finite number");
    return value.get<double>();
}

glm::dvec3 numbers3(const fs::path& file, const json& object, const char* key, glm::dvec3 fallback,
                    const std::string& where)
{
    if (!object.contains(key)) return fallback;
    const json& value = object[key];
    if (!value.is_array() || value.size() != 3) fail(file, where + "." + key + ": expected 3 numbers");
    glm::dvec3 out;
    for (int i = 0; i < 3; ++i) {
        if (!value[size_t(i)].is_number() || !std::isfinite(value[size_t(i)].get<double>()))
            fail(file, where + "." + key + ": expected finite numbers");
        out[i] = value[size_t(i)].get<double>();
    }
    return out;
}

/// A node's transform relative to its parent: `matrix` (column-major) or T R S.
glm::dmat4 localTransform(const fs::path& file, const json& node, const std::string& where)
{
    if (node.contains("matrix")) {
        const json& m = node["matrix"];
        if (!m.is_array() || m.size() != 16) fail(file, where + ".matrix: expected 16 numbers");
        glm::dmat4 matrix;
        for (int i = 0; i < 16; ++i) {
            if (!m[size_t(i)].is_number()) fail(file, where + ".matrix: expected 16 numbers");
            matrix[i / 4][i % 4] = m[size_t(i)].get<double>();
        }
        return matrix;
    }
    const glm::dvec3 t = numbers3(file, node, "translation", glm::dvec3(0.0), where);
    const glm::dvec3 s = numbers3(file, node, "scale", glm::dvec3(1.0), where);
    glm::dquat r(1.0, 0.0, 0.0, 0.0);
    if (node.contains("rotation")) {
        const json& q = node["rotation"];
        if (!q.is_array() || q.size() != 4) fail(file, where + ".rotation: expected a quaternion of 4 numbers");
        for (size_t i = 0; i < 4; ++i)
            if (!q[i].is_number()) fail(file, where + ".rotation: expected a quaternion of 4 numbers");
        r = glm::normalize(glm::dquat(q[3].get<double>(), q[0].get<double>(), q[1].get<double>(), q[2].get<double>()));
    }
    return glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(r) * glm::scale(glm::dmat4(1.0), s);
}

/// A camera or light and the world transform of the node that carries it.
struct Placed {
    size_t index;         ///< into `cameras` or the lights of KHR_lights_punctual
    std::string nodeName; ///< "" when the node has none
    glm::dmat4 world;
};

struct PlacedThings {
    std::vector<Placed> cameras;
    std::vector<Placed> lights;
};

/// The scene's root nodes: scenes[scene] (default 0), or without scenes every node that is no child.
std::vector<size_t> rootNodes(const json& doc, size_t nodeCount)
{
    std::vector<size_t> roots;
    const size_t sceneIndex = doc.contains("scene") && doc["scene"].is_number_unsigned() ? doc["scene"].get<size_t>() : 0;
    if (doc.contains("scenes") && doc["scenes"].is_array() && sceneIndex < doc["scenes"].size()) {
        const json& scene = doc["scenes"][sceneIndex];
        if (scene.contains("nodes") && scene["nodes"].is_array())
            for (const json& n : scene["nodes"])
                if (n.is_number_unsigned() && n.get<size_t>() < nodeCount) roots.push_back(n.get<size_t>());
        return roots;
    }
    std::vector<bool> child(nodeCount, false);
    for (size_t i = 0; i < nodeCount; ++i)
        if (doc["nodes"][i].contains("children") && doc["nodes"][i]["children"].is_array())
            for (const json& c : doc["nodes"][i]["children"])
                if (c.is_number_unsigned() && c.get<size_t>() < nodeCount) child[c.get<size_t>()] = true;
    for (size_t i = 0; i < nodeCount; ++i)
        if (!child[i]) roots.push_back(i);
    return roots;
}

/// Every camera and light instance, walking the scene's node trees depth first.
PlacedThings placeThings(const fs::path& file, const json& doc)
{
    PlacedThings out;
    if (!doc.contains("nodes") || !doc["nodes"].is_array()) return out;
    const json& nodes = doc["nodes"];
    struct Visit {
        size_t node;
        glm::dmat4 parent;
        uint32_t depth;
    };
    std::vector<Visit> stack;
    for (size_t root : rootNodes(doc, nodes.size())) stack.push_back({root, glm::dmat4(1.0), 1});
    std::set<size_t> seen; // the file was checked for cycles; this keeps the walk finite regardless
    while (!stack.empty()) {
        const Visit visit = stack.back();
        stack.pop_back();
        const std::string where = formatIndex("nodes", visit.node);
        if (visit.depth > kMaxGltfNodeDepth) fail(file, where + ": the node hierarchy is deeper than allowed");
        if (!seen.insert(visit.node).second) fail(file, where + ": a node is reached twice (a cycle or two parents)");
        const json& node = nodes[visit.node];
        if (!node.is_object()) fail(file, where + ": expected an object");
        const glm::dmat4 world = visit.parent * localTransform(file, node, where);
        const std::string name = node.contains("name") && node["name"].is_string() ? node["name"].get<std::string>() : "";
        if (node.contains("camera") && node["camera"].is_number_unsigned())
            out.cameras.push_back({node["camera"].get<size_t>(), name, world});
        if (node.contains("extensions") && node["extensions"].contains("KHR_lights_punctual")) {
            const json& ref = node["extensions"]["KHR_lights_punctual"];
            if (ref.contains("light") && ref["light"].is_number_unsigned())
                out.lights.push_back({ref["light"].get<size_t>(), name, world});
        }
        if (node.contains("children") && node["children"].is_array()) {
            const json& children = node["children"];
            for (size_t c = children.size(); c-- > 0;)
                if (children[c].is_number_unsigned() && children[c].get<size_t>() < nodes.size())
                    stack.push_back({children[c].get<size_t>(), world, visit.depth + 1});
        }
    }
    return out;
}

glm::dvec3 pointOf(const glm::dmat4& m) { return glm::dvec3(m * glm::dvec4(0, 0, 0, 1)); }
glm::dvec3 axisOf(const glm::dmat4& m, const glm::dvec3& local) { return glm::dvec3(m * glm::dvec4(local, 0.0)); }

// ------------------------------------------------------------------ cameras

/// The camera instance `--camera` names (or the first), or nullopt for none.
std::optional<Placed> chosenCamera(const fs::path& file, const json& doc, const std::vector<Placed>& cameras,
                                   const std::optional<std::string>& choice)
{
    if (!choice) {
        if (cameras.empty()) return std::nullopt;
        return cameras.front();
    }
    const size_t cameraCount = doc.contains("cameras") && doc["cameras"].is_array() ? doc["cameras"].size() : 0;
    const std::string& text = *choice;
    const bool isIndex = !text.empty() && text.size() < 10 && text.find_first_not_of("0123456789") == std::string::npos;
    for (const Placed& c : cameras) {
        const json& camera = doc["cameras"][c.index];
        const bool named = camera.contains("name") && camera["name"].is_string() && camera["name"] == text;
        if ((isIndex && c.index == std::stoul(text)) || named || (!c.nodeName.empty() && c.nodeName == text))
            return c;
    }
    std::string known;
    for (const Placed& c : cameras) {
        const json& camera = doc["cameras"][c.index];
        std::string name = camera.contains("name") && camera["name"].is_string() ? camera["name"].get<std::string>()
                                                                                 : c.nodeName;
        known += (known.empty() ? "" : ", ") + std::to_string(c.index) + (name.empty() ? "" : " (" + quote(name) + ")");
    }
    throw InputError("--camera " + text + ": " + file.string() + " has no such camera (" +
                     (cameraCount == 0 ? std::string("it has none") : "its cameras: " + known) + ")");
}

/// A perspective camera from a glTF camera on its node; nullopt (with a
/// warning) for an orthographic one, which vkrt cannot render.
std::optional<Camera> cameraFrom(const fs::path& file, const json& doc, const Placed& placed, const Aabb& bounds,
                                 std::vector<std::string>& warnings)
{
    const std::string where = formatIndex("cameras", placed.index);
    if (!doc.contains("cameras") || !doc["cameras"].is_array() || placed.index >= doc["cameras"].size())
        fail(file, "a node names camera " + std::to_string(placed.index) + ", which the file does not have");
    const json& camera = doc["cameras"][placed.index];
    if (!camera.contains("type") || camera["type"] != "perspective") {
        warnings.push_back(file.string() + ": " + where +
                           ": only perspective cameras are rendered; this one is replaced by a camera framing the scene");
        return std::nullopt;
    }
    if (!camera.contains("perspective") || !camera["perspective"].is_object())
        fail(file, where + ": a perspective camera needs its `perspective` object");
    const json& perspective = camera["perspective"];
    const double yfov = number(file, perspective, "yfov", 0.0, where + ".perspective");
    if (!(yfov > 0.0 && yfov < glm::pi<double>()))
        fail(file, where + ".perspective.yfov: must be strictly between 0 and pi radians, got " + formatNumber(yfov));
    const double aspect = number(file, perspective, "aspectRatio", 4.0 / 3.0, where + ".perspective");
    if (!(aspect > 0.0)) fail(file, where + ".perspective.aspectRatio: must be > 0, got " + formatNumber(aspect));
    Camera c;
    c.eye = pointOf(placed.world);
    const std::optional<glm::dvec3> forward = normalized(axisOf(placed.world, {0, 0, -1}));
    const std::optional<glm::dvec3> up = normalized(axisOf(placed.world, {0, 1, 0}));
    if (!forward || !up || isParallel(*forward, *up))
        fail(file, where + ": its node's transform collapses the camera's axes");
    // The target sets where the viewer orbits and the default focus: the
    // point of the view axis nearest the scene's centre, at least a little ahead.
    const double ahead = bounds.empty() ? 1.0 : glm::dot(bounds.centre() - c.eye, *forward);
    const double size = bounds.empty() ? 1.0 : glm::length(bounds.upper - bounds.lower);
    c.target = c.eye + *forward * std::max(ahead, 1e-3 * std::max(size, 1e-30));
    c.up = *up;
    c.fovY = glm::degrees(yfov);
    c.width = 640;
    c.height = uint32_t(std::clamp(std::lround(640.0 / aspect), 1l, long(SceneLimits::maxImageSide)));
    if (auto problem = cameraProblem(c)) fail(file, where + ": " + *problem);
    return c;
}

/// A camera looking at the whole box from the front, slightly above and to the right.
Camera framingCamera(const Aabb& bounds)
{
    Camera c;
    c.fovY = 40.0;
    const glm::dvec3 centre = bounds.empty() ? glm::dvec3(0.0) : bounds.centre();
    const double radius = bounds.empty() ? 1.0 : std::max(0.5 * glm::length(bounds.upper - bounds.lower), 1e-6);
    const double distance = 1.1 * radius / std::sin(glm::radians(c.fovY / 2.0));
    c.target = centre;
    c.eye = centre + distance * glm::normalize(glm::dvec3(0.35, 0.3, 1.0));
    c.up = glm::dvec3(0, 1, 0);
    return c;
}

// ------------------------------------------------------------------- lights

void addLight(const fs::path& file, const json& lights, const Placed& placed, Scene& scene)
{
    const std::string where = "extensions.KHR_lights_punctual.lights[" + std::to_string(placed.index) + "]";
    if (placed.index >= lights.size()) fail(file, where + ": no such light (a node names it)");
    const json& light = lights[placed.index];
    if (!light.is_object() || !light.contains("type") || !light["type"].is_string())
        fail(file, where + ": expected an object with a `type`");
    const Color color = numbers3(file, light, "color", Color(1.0), where);
    const double intensity = number(file, light, "intensity", 1.0, where);
    if (!(intensity >= 0.0) || glm::any(glm::lessThan(color, Color(0.0))))
        fail(file, where + ": color and intensity must be >= 0");
    const Color power = color * intensity;
    if (std::max({power.r, power.g, power.b}) > std::numeric_limits<float>::max())
        fail(file, where + ": color x intensity is beyond 32-bit float range");
    if (light.contains("range"))
        scene.warnings.push_back(file.string() + ": " + where +
                                 ".range: ignored (vkrt's lights fall off with the inverse square of distance only)");
    const std::string type = light["type"];
    const glm::dvec3 position = pointOf(placed.world);
    const std::optional<glm::dvec3> direction = normalized(axisOf(placed.world, {0, 0, -1}));
    if (type == "point") {
        scene.pointLights.push_back({position, power});
    } else if (type == "directional" || type == "spot") {
        if (!direction) fail(file, where + ": its node's transform collapses the light's direction");
        if (type == "directional") {
            scene.directionalLights.push_back({*direction, power, 0.0});
            return;
        }
        const json spot = light.contains("spot") ? light["spot"] : json::object();
        const double inner = number(file, spot, "innerConeAngle", 0.0, where + ".spot");
        const double outer = number(file, spot, "outerConeAngle", glm::pi<double>() / 4.0, where + ".spot");
        if (!(outer > 0.0 && outer <= glm::pi<double>() / 2.0) || !(inner >= 0.0 && inner <= outer))
            fail(file, where + ".spot: needs 0 <= innerConeAngle <= outerConeAngle <= pi/2 and outerConeAngle > 0");
        scene.spotLights.push_back({position, *direction, power, glm::degrees(inner), glm::degrees(outer)});
    } else {
        fail(file, where + ".type: unknown light type " + quote(type) + " (point, spot, directional)");
    }
}

/// The file as one mesh instance with its own materials, read as a scene's
/// `[[objects]]` table would be (the same checks, references kept inside its folder).
void addMeshes(const fs::path& file, ParseContext& context)
{
    toml::table table{{"shape", "mesh"}, {"material", "file"}, {"file", fs::absolute(file).string()}};
    const TomlSource source{file.string(), file.parent_path()};
    readMesh(TableField(Field(source, table, "")), kFileMaterialIndex, context);
}

json parseDocument(const fs::path& file)
{
    json doc = json::parse(readGltfJson(file), nullptr, /*allow_exceptions=*/false);
    if (doc.is_discarded() || !doc.is_object()) fail(file, "the glTF JSON cannot be parsed");
    return doc;
}

} // namespace

bool isGltfPath(const fs::path& path)
{
    const std::string extension = lowercase(path.extension().string());
    return extension == ".gltf" || extension == ".glb";
}

void importGltf(const fs::path& file, const GltfSceneOptions& options, bool takeCamera, ParseContext& context)
{
    Scene& scene = context.scene;
    addMeshes(file, context); // first: it checks the whole file before anything else reads it
    // Its lights are honoured here, unlike a mesh object's file's.
    std::erase_if(scene.warnings, [](const std::string& w) {
        return w.find("KHR_lights_punctual: file extension not supported") != std::string::npos;
    });
    const Aabb bounds = boundsOf(scene.meshes.back());
    const json doc = parseDocument(file);
    const PlacedThings placed = placeThings(file, doc);
    if (!placed.lights.empty()) {
        const json* lights = nullptr;
        if (doc.contains("extensions") && doc["extensions"].contains("KHR_lights_punctual") &&
            doc["extensions"]["KHR_lights_punctual"].contains("lights"))
            lights = &doc["extensions"]["KHR_lights_punctual"]["lights"];
        if (!lights || !lights->is_array()) fail(file, "a node names a KHR_lights_punctual light, but there are none");
        for (const Placed& light : placed.lights) addLight(file, *lights, light, scene);
    }
    if (!takeCamera) {
        if (options.camera) throw InputError("--camera " + *options.camera + ": the scene's own [camera] is used");
        return;
    }
    std::optional<Camera> camera;
    if (const auto chosen = chosenCamera(file, doc, placed.cameras, options.camera))
        camera = cameraFrom(file, doc, *chosen, bounds, scene.warnings);
    scene.camera = camera ? *camera : framingCamera(bounds);
}

Scene parseGltfScene(const std::string& path, const GltfSceneOptions& options)
{
    Scene scene;
    scene.render.integrator = Integrator::Path;
    scene.render.maxDepth = 8;
    MeshGeometryCache meshes;
    auto textures = std::make_shared<TextureAtlas>();
    ParseContext context{scene, *textures, meshes, {}};
    importGltf(path, options, true, context);
    // Only KHR_lights_punctual lights switch the white sky off: emissive
    // surfaces alone (a lamp, a helmet's display) keep it.
    const bool lit = !scene.pointLights.empty() || !scene.spotLights.empty() || !scene.directionalLights.empty();
    if (options.environment) {
        EnvironmentMap map;
        map.path = *options.environment;
        map.where = {"--environment", 0, 0};
        const std::string extension = lowercase(fs::path(map.path).extension().string());
        if (extension != ".exr" && extension != ".hdr")
            throw InputError("--environment " + map.path + ": an environment map must be a lat-long .exr or .hdr file");
        if (!fs::is_regular_file(map.path)) throw InputError("--environment " + map.path + ": no such file");
        scene.background.environment = map;
    } else if (!lit) {
        scene.background.color = Color(1.0); // a file without lights: a white sky, as glTF viewers show it
    }
    scene.path = path;
    scene.fileHash = fnv1a64(readFileBytes(path, "glTF file", size_t(1) << 31));
    if (textures->recordCount() > 0) scene.textures = std::move(textures);
    return scene;
}

} // namespace vkrt
