// --accel, the same for every command that renders.
#include "app/Commands.h"

#include <CLI/CLI.hpp>

#include <map>

namespace vkrt {

void addAccelOption(CLI::App& command, AccelChoice& choice)
{
    const std::map<std::string, AccelChoice> names{
        {"own", AccelChoice::Own}, {"driver", AccelChoice::Driver}, {"auto", AccelChoice::Auto}};
    command
        .add_option("--accel", choice,
                    "Traversal backend: own (vkrt's BVH in the kernel), driver (the device's acceleration "
                    "structures through VK_KHR_ray_query), or auto (default: the one measured faster for "
                    "this device and scene; own where the device lacks ray queries)")
        ->transform(CLI::CheckedTransformer(names));
}

} // namespace vkrt
