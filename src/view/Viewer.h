#pragma once
// `vkrt view`: a GLFW window showing the progressive render as it converges,
// with camera controls, and scripted sessions for tests.
#include "render/Accel.h"
#include "render/Outcome.h"
#include "scene/GltfScene.h"

#include <cstdint>
#include <optional>
#include <string>

namespace vkrt {

struct ViewOptions {
    std::string scenePath;
    GltfSceneOptions gltf; ///< --camera, --environment for a glTF scene
    std::string device;
    uint32_t seed = 0;
    std::optional<uint32_t> width; ///< render size (default: the scene's)
    std::optional<uint32_t> height;
    std::optional<uint32_t> frames; ///< render this many frames, then exit (after --screenshot)
    std::string screenshot;         ///< PNG of the displayed image at exit
    std::string script;             ///< scripted session (src/view/ViewerScript.h)
    float exposure = 0.0f;
    bool filmic = false;
    bool variance = false;
    bool validation = false;
    uint64_t maxBandBytes = 0; ///< test hook: SessionConfig::maxBandBytes
    AccelChoice accel = AccelChoice::Auto; ///< --accel
};

/// Runs the viewer; Passed, or ValidationMessages with them. Bad input (scene,
/// --width/--height, script) throws InputError before any window opens.
Outcome runViewer(const ViewOptions& options);

/// The key list printed by `H`.
const char* viewerHelp();

} // namespace vkrt
