// --accel and --scene-reads, the same for every command that renders.
#include "app/Commands.h"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

namespace vkrt {

void addAccelOption(CLI::App& command, AccelChoice& choice)
{
    command.add_option_function<std::string>(
        "--accel",
        [&choice](const std::string& name) {
            std::optional<AccelChoice> named = accelChoiceNamed(name);
            if (!named) throw CLI::ValidationError("--accel " + name, "expected own, driver or auto");
            choice = *named;
        },
        "Traversal backend: own (vkrt's BVH in the kernel), driver (the device's acceleration structures "
        "through VK_KHR_ray_query), or auto (default: the one measured faster for this device and scene; own "
        "where the device lacks ray queries)");
}

void addSceneReadsOption(CLI::App& command, SceneReads& reads)
{
    command.add_option_function<std::string>(
        "--scene-reads",
        [&reads](const std::string& name) {
            if (name == "auto") reads = SceneReads::Auto;
            else if (name == "address") reads = SceneReads::Address;
            else if (name == "descriptor") reads = SceneReads::Descriptor;
            else throw CLI::ValidationError("--scene-reads " + name, "expected auto, address or descriptor");
        },
        "How the kernel reads the scene's buffers: address (through their device addresses), descriptor "
        "(through their descriptors) or auto (default: the one measured to compile faster on the device; "
        "docs/performance.md). The same image either way");
}

} // namespace vkrt
