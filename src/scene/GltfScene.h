#pragma once
// A glTF 2.0 file as a scene (`vkrt render model.glb`) or imported into a
// TOML scene (`[import] gltf = "model.glb"`): its meshes with their own
// materials (one mesh instance of the whole file: assimp flattens the node
// hierarchy: each glTF mesh one geometry, each node placing it an instance),
// its cameras and its
// KHR_lights_punctual lights, placed by the nodes that carry them.
//
// Conventions (glTF 2.0): a camera looks down its node's -Z with +Y up;
// `yfov` is the vertical field of view in radians; a light shines down its
// node's -Z. Point and spot intensity (candela) is taken as radiant intensity
// in W/sr and directional intensity (lux) as irradiance in W/m²: no 683 lm/W
// factor, so a file's lights keep their relative strengths and a white
// `intensity = 1` light gives what vkrt's own `intensity = 1` gives.
#include "scene/ParseContext.h"
#include "scene/Scene.h"

#include <filesystem>
#include <optional>
#include <string>

namespace vkrt {

/// What the command line chooses about a glTF scene.
struct GltfSceneOptions {
    /// `--camera NAME|INDEX`: a camera by its or its node's name, or by its
    /// index in the file's `cameras`; unset: the first camera met walking
    /// the scene's nodes.
    std::optional<std::string> camera;
    /// `--environment FILE`: a lat-long map lighting the scene; unset: a
    /// white constant environment for a file without KHR_lights_punctual
    /// lights (emissive materials alone keep it), black otherwise.
    std::optional<std::string> environment;
    /// `--scene NAME|INDEX`: one of the file's `scenes`; unset: its `scene`, else the first.
    std::optional<std::string> scene;
    /// `--variant NAME|INDEX`: a KHR_materials_variants variant; unset: the default materials.
    std::optional<std::string> variant;
};

/// Whether `path` names a glTF file (.gltf or .glb, any case).
bool isGltfPath(const std::filesystem::path& path);

/// Adds the file's meshes (as one mesh instance with the file's materials)
/// and lights to the scene being parsed; with `takeCamera` its camera too
/// (or, without one, a camera that frames the file's bounding box). Throws
/// SceneError/InputError naming the file and what is wrong; what vkrt does
/// not honour becomes a warning naming the file.
void importGltf(const std::filesystem::path& file, const GltfSceneOptions& options, bool takeCamera,
                ParseContext& context);

/// The whole scene of a glTF file: path integrator, max_depth 8, its camera,
/// meshes and lights, and the background GltfSceneOptions says.
Scene parseGltfScene(const std::string& path, const GltfSceneOptions& options = {});

} // namespace vkrt
