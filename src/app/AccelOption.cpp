// --accel, the same for every command that renders.
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

} // namespace vkrt
