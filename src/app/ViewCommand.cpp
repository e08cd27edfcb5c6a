// `vkrt view SCENE`: the progressive viewer (src/view/Viewer.cpp).
#include "app/Commands.h"
#include "app/ExitCodes.h"
#include "io/OutputPaths.h"
#include "util/Error.h"
#include "view/Viewer.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <memory>

namespace vkrt {

CommandRunner addViewCommand(CLI::App& app)
{
    auto o = std::make_shared<ViewOptions>();
    CLI::App* cmd = app.add_subcommand("view", "Watch a scene converge in a window (keys: press H)");
    // "SCENE", not "scene": CLI11 2.4 (Debian 13) refuses a positional named like an option (--scene).
    cmd->add_option("SCENE", o->scenePath, "Scene file (TOML, or a glTF .gltf/.glb file as a scene)")->required();
    cmd->add_option("--camera", o->gltf.camera, "glTF scene: the camera to look through (name or index)");
    cmd->add_option("--scene", o->gltf.scene, "glTF file: which of its scenes to show (name or index)");
    cmd->add_option("--variant", o->gltf.variant, "glTF file: a KHR_materials_variants variant (name or index)");
    cmd->add_option("--environment", o->gltf.environment,
                    "glTF scene: a lat-long .exr/.hdr map lighting it (default: the grey studio gradient for a file "
                    "without lights, else black)");
    cmd->add_option("--device", o->device, "Vulkan device index or name");
    cmd->add_option("--seed", o->seed, "Random seed");
    addAccelOption(*cmd, o->accel);
    // Checked with the scene parser's limits (SceneOverrides.h) once the scene is read.
    cmd->add_option("--width", o->width, "Render width (default: the scene's)");
    cmd->add_option("--height", o->height, "Render height (default: the scene's)");
    cmd->add_option("--frames", o->frames, "Render this many frames, then exit")->check(CLI::Range(0u, 1u << 24));
    cmd->add_option("--screenshot", o->screenshot,
                    "Save the displayed image (PNG) after --frames frames (64 without it), then exit");
    cmd->add_option("--script", o->script, "Run a scripted session (docs/viewer.md)")
        ->excludes(cmd->get_option("--frames"))
        ->excludes(cmd->get_option("--screenshot"));
    cmd->add_option("--exposure", o->exposure, "Display exposure in stops")->check(CLI::Range(-64.0, 64.0));
    cmd->add_flag("--filmic", o->filmic, "Filmic tone curve instead of clamping");
    cmd->add_flag("--variance", o->variance, "Estimate variance (shows the estimated error in the title)");
    cmd->add_flag("--validation", o->validation, "Enable Vulkan validation; any message makes the exit status 3");
    cmd->add_option("--max-band-bytes", o->maxBandBytes,
                    "Render and display in bands whose per-pixel buffers hold at most this many bytes (test hook)")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 40))
        ->group("");
    return [o] {
        if (!std::isfinite(o->exposure)) throw InputError("--exposure: must be a finite number");
        checkOutputs({{"the scene file", o->scenePath}, {"--script", o->script}}, {{"--screenshot", o->screenshot}});
        return exitCodeFor(runViewer(*o));
    };
}

} // namespace vkrt
