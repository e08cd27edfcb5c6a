// `vkrt devices`: every Vulkan device, which one vkrt would pick, and why any
// device cannot be used.
#include "app/Commands.h"
#include "gpu/VectorWidth.h"
#include "gpu/VulkanContext.h"
#include "util/Error.h"

#include "GitCommit.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <cstdlib>
#include <optional>

namespace vkrt {

namespace {

std::optional<uint32_t> defaultChoice(const std::vector<DeviceInfo>& devices)
{
    try {
        return defaultDeviceIndex(devices);
    } catch (const GpuError&) {
        return std::nullopt; // every device is listed below with its reason
    }
}

/// The --accel backends the device offers and what auto picks on it.
std::string traversalSummary(const DeviceInfo& d)
{
    if (!d.rayQuery()) return "own only (it lacks " + d.rayQueryMissing + " for --accel driver)";
    if (d.type != vk::PhysicalDeviceType::eCpu) return "own or driver (VK_KHR_ray_query); auto picks driver";
    return "own or driver (VK_KHR_ray_query); auto picks driver for scenes of 1 to " +
           std::to_string(kDriverAccelMaxCpuTriangles) + " mesh triangles, own for the rest";
}

/// lavapipe's SIMD width now, and what `vkrt render --vector-width auto` would run at.
std::optional<std::string> vectorWidthSummary(const DeviceInfo& d)
{
    const std::optional<int> bits = lavapipeVectorBits(d);
    if (!bits) return std::nullopt;
    VectorWidthFacts facts;
    facts.runningBits = bits;
    facts.mesa = mesaVersion(d);
    facts.avx512 = cpuHasAvx512();
    std::string text = std::to_string(*bits) + " bits";
    if (const char* set = std::getenv("LP_NATIVE_VECTOR_WIDTH"); set && *set)
        return text + " ($LP_NATIVE_VECTOR_WIDTH=" + set + ", which `vkrt render --vector-width auto` keeps)";
    const std::optional<int> analytic = chooseVectorBits(VectorWidthChoice::Auto, facts);
    text += "; `vkrt render --vector-width auto` runs " + std::to_string(analytic.value_or(*bits)) +
            " for scenes without meshes, 256 with meshes";
    if (!facts.avx512) text += " (this CPU lacks AVX-512)";
    return text;
}

} // namespace

std::string versionText()
{
    std::string text = "vkrt " VKRT_VERSION " (commit " VKRT_GIT_COMMIT ")\n";
    try {
        tuneSoftwareRasterizerThreads();
        const std::vector<DeviceInfo> devices = listVulkanDevices();
        const DeviceInfo& d = devices.at(defaultDeviceIndex(devices));
        text += "Vulkan device: " + d.name + " (" + d.typeName() + ", Vulkan " + d.apiVersionString() + ", " +
                d.driver + ")";
    } catch (const std::exception& e) {
        text += "Vulkan device: none usable (" + std::string(e.what()) + "); `vkrt devices` says why";
    }
    return text;
}

CommandRunner addDevicesCommand(CLI::App& app)
{
    app.add_subcommand("devices", "List Vulkan devices and whether vkrt can use them");
    return [] {
        tuneSoftwareRasterizerThreads();
        auto devices = listVulkanDevices();
        auto chosen = defaultChoice(devices);
        for (const DeviceInfo& d : devices) {
            std::printf("%s%u: %s (%s, Vulkan %s, %s)\n", chosen == d.index ? "* " : "  ", d.index, d.name.c_str(),
                        d.typeName().c_str(), d.apiVersionString().c_str(), d.driver.c_str());
            if (!d.suitable()) std::printf("     unsuitable: it %s\n", d.unsuitableReason.c_str());
            else std::printf("     traversal: %s\n", traversalSummary(d).c_str());
            if (auto width = vectorWidthSummary(d)) std::printf("     vector width: %s\n", width->c_str());
        }
        if (devices.empty()) std::printf("no Vulkan devices (install mesa-vulkan-drivers for lavapipe)\n");
        if (!chosen) return int(kExitFailure);
        std::printf("(* = default; choose another with --device INDEX|NAME)\n");
        return int(kExitOk);
    };
}

} // namespace vkrt
