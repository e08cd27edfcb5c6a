// A glTF 2.0 file as a scene (scene/GltfScene.h): the file read once by
// mesh/GltfReader, mapped here to the scene: each glTF mesh becomes one
// geometry, each placement of it (a node, an EXT_mesh_gpu_instancing copy)
// a mesh instance sharing that geometry; cameras and KHR_lights_punctual
// lights are placed by the world transforms of the nodes that carry them.
#include "scene/GltfScene.h"

#include "mesh/GltfReader.h"
#include "mesh/MeshGeometry.h"
#include "scene/FileMaterialImport.h"
#include "scene/SceneOverrides.h"
#include "scene/SceneParser.h"
#include "scene/TomlReader.h"
#include "scene/kinds/Kinds.h"
#include "texture/TextureAtlas.h"
#include "util/Error.h"
#include "util/Hash.h"
#include "util/Parallel.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace vkrt {

namespace {

namespace fs = std::filesystem;

glm::dvec3 pointOf(const glm::dmat4& m) { return glm::dvec3(m * glm::dvec4(0, 0, 0, 1)); }
glm::dvec3 axisOf(const glm::dmat4& m, const glm::dvec3& local) { return glm::dvec3(m * glm::dvec4(local, 0.0)); }

// ------------------------------------------------------------------ cameras

/// "0 ('Front'), 1" : the file's cameras that its scene places, in file order.
std::string cameraList(const GltfModel& model)
{
    std::set<uint32_t> placed;
    for (const GltfPlaced& c : model.cameras) placed.insert(c.index);
    std::string known;
    for (uint32_t index : placed) {
        std::string name = model.cameraDefinitions[index].name;
        if (name.empty())
            for (const GltfPlaced& c : model.cameras)
                if (c.index == index && name.empty()) name = c.nodeName;
        known += (known.empty() ? "" : ", ") + std::to_string(index) + (name.empty() ? "" : " (" + quote(name) + ")");
    }
    return known;
}

/// The camera instance `--camera` names (or the first), or nullopt for none.
std::optional<GltfPlaced> chosenCamera(const GltfModel& model, const std::optional<std::string>& choice)
{
    if (!choice) {
        if (model.cameras.empty()) return std::nullopt;
        return model.cameras.front();
    }
    const std::string& text = *choice;
    const bool isIndex = !text.empty() && text.size() < 10 && text.find_first_not_of("0123456789") == std::string::npos;
    for (const GltfPlaced& c : model.cameras) {
        const std::string& name = model.cameraDefinitions[c.index].name;
        if ((isIndex && c.index == std::stoul(text)) || (!name.empty() && name == text) ||
            (!c.nodeName.empty() && c.nodeName == text))
            return c;
    }
    throw InputError("--camera " + text + ": " + model.file.string() + " has no such camera (" +
                     (model.cameras.empty() ? std::string("it has none") : "its cameras: " + cameraList(model)) + ")");
}

/// vkrt's camera from a glTF camera on its node.
Camera cameraFrom(const GltfModel& model, const GltfPlaced& placed, const Aabb& bounds)
{
    const GltfCamera& definition = model.cameraDefinitions[placed.index];
    const std::string where = "cameras[" + std::to_string(placed.index) + "]";
    Camera c;
    c.eye = pointOf(placed.world);
    const std::optional<glm::dvec3> forward = normalized(axisOf(placed.world, {0, 0, -1}));
    const std::optional<glm::dvec3> up = normalized(axisOf(placed.world, {0, 1, 0}));
    if (!forward || !up || isParallel(*forward, *up))
        failInFile(model.file, where + ": its node's transform collapses the camera's axes");
    // The target sets where the viewer orbits and the default focus: the
    // point of the view axis nearest the scene's centre, at least a little ahead.
    const double ahead = bounds.empty() ? 1.0 : glm::dot(bounds.centre() - c.eye, *forward);
    const double size = bounds.empty() ? 1.0 : glm::length(bounds.upper - bounds.lower);
    c.target = c.eye + *forward * std::max(ahead, 1e-3 * std::max(size, 1e-30));
    c.up = *up;
    double aspect = 4.0 / 3.0;
    if (definition.orthographic) {
        // The node's scale scales the view like everything else it carries.
        const double scaleX = glm::length(axisOf(placed.world, {1, 0, 0}));
        const double scaleY = glm::length(axisOf(placed.world, {0, 1, 0}));
        c.orthographicHeight = 2.0 * std::abs(definition.ymag) * scaleY;
        aspect = (std::abs(definition.xmag) * scaleX) / (std::abs(definition.ymag) * scaleY);
    } else {
        c.fovY = glm::degrees(definition.yfov);
        aspect = definition.aspectRatio.value_or(aspect);
    }
    // 640 pixels on the longer side: a tall camera gets a tall image, not one
    // 640 wide and thousands high. An aspect that leaves the shorter side
    // under a pixel is no image.
    const double longer = 640.0;
    const double shorter = aspect >= 1.0 ? longer / aspect : longer * aspect;
    if (!(shorter >= 0.5))
        failInFile(model.file, where + ": the aspect ratio " + formatNumber(aspect) + " leaves an image of " +
                                   std::to_string(int(longer)) + " pixels less than one pixel " +
                                   (aspect >= 1.0 ? "high" : "wide") +
                                   " (vkrt renders aspect ratios from 1:640 to 640:1)");
    c.width = uint32_t(aspect >= 1.0 ? longer : std::lround(shorter));
    c.height = uint32_t(aspect >= 1.0 ? std::lround(shorter) : longer);
    if (auto problem = cameraProblem(c)) failInFile(model.file, where + ": " + *problem);
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

void addLight(const GltfModel& model, const GltfPlaced& placed, Scene& scene)
{
    const GltfLight& light = model.lightDefinitions[placed.index];
    const std::string where = "extensions.KHR_lights_punctual.lights[" + std::to_string(placed.index) + "]";
    if (light.hasRange)
        scene.warnings.push_back(model.file.string() + ": " + where +
                                 ".range: ignored (vkrt's lights fall off with the inverse square of distance only)");
    const Color power = light.color * light.intensity;
    const glm::dvec3 position = pointOf(placed.world);
    const std::optional<glm::dvec3> direction = normalized(axisOf(placed.world, {0, 0, -1}));
    if (light.type == "point") {
        scene.pointLights.push_back({position, power});
        return;
    }
    if (!direction) failInFile(model.file, where + ": its node's transform collapses the light's direction");
    if (light.type == "directional") {
        scene.directionalLights.push_back({*direction, power, 0.0});
        return;
    }
    scene.spotLights.push_back(
        {position, *direction, power, glm::degrees(light.innerConeAngle), glm::degrees(light.outerConeAngle)});
}

// ------------------------------------------------------------------- meshes

/// The file materials the placed meshes use, imported into the scene; the
/// others are never loaded (their textures neither). Returns, per file
/// material, its scene material (the first used one for unused entries, which no triangle names).
std::vector<uint32_t> importUsedMaterials(const GltfModel& model, const SourceLocation& where, ParseContext& context)
{
    std::vector<bool> used(model.materials.size(), false), placed(model.meshes.size(), false);
    for (const GltfInstance& instance : model.instances) placed[instance.mesh] = true;
    for (size_t mesh = 0; mesh < placed.size(); ++mesh) // each mesh once, however often it is placed
        if (placed[mesh])
            for (uint32_t m : model.meshes[mesh].triangleMaterials) used[m] = true;
    std::vector<FileMaterial> materials;
    std::vector<uint32_t> position(model.materials.size(), 0);
    for (size_t i = 0; i < used.size(); ++i)
        if (used[i]) {
            position[i] = uint32_t(materials.size());
            materials.push_back(model.materials[i]);
        }
    const std::vector<uint32_t> imported = importFileMaterials(materials, model.file, where, context.textures,
                                                               context.scene.materials, context.scene.warnings);
    std::vector<uint32_t> sceneIndex(model.materials.size(), imported.empty() ? 0 : imported.front());
    for (size_t i = 0; i < used.size(); ++i)
        if (used[i]) sceneIndex[i] = imported[position[i]];
    return sceneIndex;
}

/// One mesh instance per placement, each glTF mesh one shared geometry. Returns the instances' world bounds.
Aabb addMeshes(GltfModel& model, ParseContext& context)
{
    const SourceLocation where{model.file.string(), 0, 0};
    const std::vector<uint32_t> materials = importUsedMaterials(model, where, context);
    // Each placed mesh's geometry (tangents, BVH) once, all of them in
    // parallel: one after another they took 0.48 s of the 1.2 s warm start of
    // a model of 102 meshes (MetalRoughSpheresNoTextures). A failure is the
    // first placed mesh's, as it was then.
    std::vector<uint32_t> placed; // each mesh once, in the order of its first placement
    std::vector<bool> seen(model.meshes.size(), false);
    for (const GltfInstance& instance : model.instances)
        if (!seen[instance.mesh]) {
            seen[instance.mesh] = true;
            placed.push_back(instance.mesh);
        }
    std::vector<std::shared_ptr<const MeshGeometry>> geometries(model.meshes.size());
    forEachInParallel(placed.size(), [&](size_t k) {
        const uint32_t index = placed[k];
        const std::string& name = model.meshNames[index];
        const fs::path label =
            model.file.string() + "#mesh " + std::to_string(index) + (name.empty() ? "" : " (" + name + ")");
        geometries[index] = makeMeshGeometry(std::move(model.meshes[index]), NormalMode::File, label);
    });
    Aabb bounds;
    for (const GltfInstance& instance : model.instances) {
        Mesh mesh;
        mesh.geometry = geometries[instance.mesh];
        mesh.objectToWorld = instance.world;
        mesh.fileMaterials = materials;
        mesh.material = materials.front();
        mesh.where = where;
        bounds.extend(boundsOf(mesh));
        context.scene.meshes.push_back(std::move(mesh));
    }
    return bounds;
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
    GltfReadOptions read;
    read.scene = options.scene;
    read.variant = options.variant;
    GltfModel model = readGltfModel(file, read);
    scene.importedFiles.push_back(file);
    scene.importedFiles.insert(scene.importedFiles.end(), model.referencedFiles.begin(), model.referencedFiles.end());
    if (model.instances.empty()) failInFile(file, "its scene places no triangle mesh: nothing to render");
    for (const std::string& warning : model.warnings) scene.warnings.push_back(file.string() + ": " + warning);
    const Aabb bounds = addMeshes(model, context);
    for (const GltfPlaced& light : model.lights) addLight(model, light, scene);
    if (!takeCamera) {
        if (options.camera) throw InputError("--camera " + *options.camera + ": the scene's own [camera] is used");
        return;
    }
    const std::optional<GltfPlaced> chosen = chosenCamera(model, options.camera);
    scene.camera = chosen ? cameraFrom(model, *chosen, bounds) : framingCamera(bounds);
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
    textures->settle(); // the images, decoded in parallel: a bad one is refused here
    // Only KHR_lights_punctual lights switch the studio light off: emissive
    // surfaces alone (a lamp, a helmet's display) keep it.
    const bool lit = !scene.pointLights.empty() || !scene.spotLights.empty() || !scene.directionalLights.empty();
    if (options.environment) {
        EnvironmentMap map;
        map.path = *options.environment;
        map.where = {"--environment", 0, 0};
        const std::string extension = lowercase(fs::path(map.path).extension().string());
        if (extension != ".exr" && extension != ".hdr")
            throw InputError("--environment " + map.path + ": an environment map must be a lat-long .exr or .hdr file");
        std::error_code error;
        const fs::file_status status = fs::status(map.path, error);
        if (!fs::exists(status)) throw InputError("--environment " + map.path + ": no such file");
        if (!fs::is_regular_file(status))
            throw InputError("--environment " + map.path + ": is " +
                             (fs::is_directory(status) ? "a directory" : "not a regular file") + ", not an image file");
        if (auto warning = latLongShapeWarning(map, "--environment")) scene.warnings.push_back(*warning);
        scene.background.environment = map;
    } else if (!lit) {
        // A file without lights: the studio gradient, against which a white model still reads (a
        // uniform sky lights a white model exactly as bright as itself).
        EnvironmentMap studio;
        studio.studio = true;
        studio.where = {"the default studio environment", 0, 0};
        scene.background.environment = studio;
    }
    scene.path = path;
    scene.fileHash = fnv1a64(readFileBytes(path, "glTF file", size_t(1) << 31));
    if (textures->recordCount() > 0) scene.textures = std::move(textures);
    return scene;
}

} // namespace vkrt
