// vkrt-load-probe: what a node load costs on a Vulkan device when every lane
// of a subgroup loads its own node (a per-lane gather) against when the
// compiler knows they all load the same one (subgroup-uniform), the question
// a packet BVH walk stands on. An optional target:
//   cmake --build build --target vkrt-load-probe
//   vkrt-load-probe [--nodes N] [--steps N] [--repeats N] [--json]
// Each invocation follows a chain of nodes whose links are random (a BVH walk
// is a chain of dependent loads); tools/kernels/load_probe.comp has the kernel.
// Six runs: per-lane code on distinct chains, per-lane code on one chain per
// workgroup (the lanes agree at run time, the compiler does not know), uniform
// code (subgroupBroadcastFirst) on one chain per workgroup, one lane loading
// (subgroupElect) and broadcasting the node to the others, uniform code
// with the one subgroup sum per node that a packet walk's decisions take, and
// per-lane code on distinct chains loading through the buffer's device address.
#include "gpu/Buffer.h"
#include "gpu/ComputeKernel.h"
#include "gpu/ShaderCompiler.h"
#include "gpu/VulkanContext.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <span>
#include <string>
#include <vector>

namespace {

struct ProbeSettings {
    uint32_t nodes = 1u << 17; // 4 MiB of nodes: the bunny's tree is of this size
    uint32_t steps = 256;
    uint32_t invocations = 1u << 16;
    int repeats = 7;
    bool json = false;
};

struct Push {
    uint32_t steps;
    uint32_t nodeCount;
    uint32_t nodesAddress[2]; ///< the nodes' device address, low word first (LOAD_MODE 4)
};

uint32_t parseCount(const char* option, const char* text)
{
    char* end = nullptr;
    const unsigned long value = std::strtoul(text, &end, 10);
    if (*text == '\0' || *end != '\0' || value == 0 || value > (1ul << 26)) {
        std::fprintf(stderr, "vkrt-load-probe: %s wants a whole number from 1 to 2^26, got '%s'\n", option, text);
        std::exit(2);
    }
    return uint32_t(value);
}

ProbeSettings parseArguments(int argc, char** argv)
{
    ProbeSettings settings;
    for (int i = 1; i < argc; ++i) {
        const std::string option = argv[i];
        if (option == "--json") {
            settings.json = true;
            continue;
        }
        if (i + 1 >= argc || (option != "--nodes" && option != "--steps" && option != "--repeats")) {
            std::fprintf(stderr, "usage: vkrt-load-probe [--nodes N] [--steps N] [--repeats N] [--json]\n");
            std::exit(2);
        }
        const uint32_t value = parseCount(option.c_str(), argv[++i]);
        if (option == "--nodes") settings.nodes = value;
        else if (option == "--steps") settings.steps = value;
        else settings.repeats = int(value);
    }
    return settings;
}

/// Two vec4 per node: a box of side ~1 near the origin, its link in lower.w.
std::vector<float> makeNodes(uint32_t count)
{
    std::mt19937 random(7);
    std::uniform_real_distribution<float> offset(-1.0f, 1.0f);
    std::uniform_int_distribution<uint32_t> link(0, count - 1);
    std::vector<float> nodes(size_t(count) * 8);
    for (uint32_t n = 0; n < count; ++n) {
        float* node = &nodes[size_t(n) * 8];
        for (int k = 0; k < 3; ++k) {
            node[k] = offset(random);
            node[4 + k] = node[k] + 1.0f;
        }
        node[3] = std::bit_cast<float>(link(random));
        node[7] = 0.25f;
    }
    return nodes;
}

/// Chain starts: one per invocation, or one per workgroup of 64 (so every
/// subgroup, of 8 or 16 lanes, walks one chain).
std::vector<uint32_t> makeStarts(uint32_t invocations, uint32_t nodes, bool shared)
{
    std::mt19937 random(11);
    std::uniform_int_distribution<uint32_t> start(0, nodes - 1);
    std::vector<uint32_t> starts(invocations);
    for (uint32_t i = 0; i < invocations; ++i) starts[i] = shared && i % 64 != 0 ? starts[i - i % 64] : start(random);
    return starts;
}

struct Timing {
    const char* name;
    double firstDispatchSeconds; // the driver's compile (lavapipe compiles at the first dispatch) and one run
    double medianSeconds;
    double nanosecondsPerNode; // per invocation and node
};

Timing timeKernel(const vkrt::VulkanContext& context, const char* name, int loadMode, bool sharedChains,
                  const ProbeSettings& settings, const vkrt::Buffer& nodes)
{
    using namespace vkrt;
    KernelSource source{defaultShaderRoot(),
                        "../tools/kernels/load_probe.comp",
                        {{"LOAD_MODE", std::to_string(loadMode)}}};
    const std::vector<uint32_t> spirv = compileGlsl(source);
    constexpr vk::BufferUsageFlags kStorage = vk::BufferUsageFlagBits::eStorageBuffer;
    Buffer starts = makeBufferFrom(context, makeStarts(settings.invocations, settings.nodes, sharedChains), kStorage);
    Buffer sums(context, settings.invocations * sizeof(float), kStorage, MemoryUse::Device);
    ComputeKernel kernel(context, spirv,
                         {{0, vk::DescriptorType::eStorageBuffer},
                          {1, vk::DescriptorType::eStorageBuffer},
                          {2, vk::DescriptorType::eStorageBuffer}},
                         sizeof(Push));
    kernel.bind(0, nodes);
    kernel.bind(1, starts);
    kernel.bind(2, sums);
    const vk::DeviceAddress address = nodes.address(context);
    const Push push{settings.steps, settings.nodes, {uint32_t(address), uint32_t(address >> 32)}};
    auto dispatch = [&] {
        context.submitAndWait([&](vk::CommandBuffer cmd) {
            kernel.recordDispatch(cmd, std::as_bytes(std::span(&push, 1)), vk::Extent2D(settings.invocations / 64, 1));
        });
    };
    const auto first = std::chrono::steady_clock::now();
    dispatch(); // the first dispatch pays the driver's compile
    const double firstSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - first).count();
    std::vector<double> seconds;
    for (int r = 0; r < settings.repeats; ++r) {
        const auto start = std::chrono::steady_clock::now();
        dispatch();
        seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::sort(seconds.begin(), seconds.end());
    const double median = seconds[seconds.size() / 2];
    return {name, firstSeconds, median, median * 1e9 / (double(settings.invocations) * settings.steps)};
}

} // namespace

int main(int argc, char** argv)
{
    const ProbeSettings settings = parseArguments(argc, argv);
    try {
        vkrt::VulkanContext context;
        const vkrt::Buffer nodes = vkrt::makeBufferFrom(context, makeNodes(settings.nodes),
                                                        vk::BufferUsageFlagBits::eStorageBuffer |
                                                            vk::BufferUsageFlagBits::eShaderDeviceAddress);
        const std::vector<Timing> timings{
            timeKernel(context, "per-lane, distinct nodes", 0, false, settings, nodes),
            timeKernel(context, "per-lane, one node per subgroup", 0, true, settings, nodes),
            timeKernel(context, "uniform, one node per subgroup", 1, true, settings, nodes),
            timeKernel(context, "one lane loads, broadcast", 2, true, settings, nodes),
            timeKernel(context, "uniform + one subgroupAdd per node", 3, true, settings, nodes),
            timeKernel(context, "per-lane, through device address", 4, false, settings, nodes),
        };
        const double base = timings[0].medianSeconds;
        const char* lpWidth = std::getenv("LP_NATIVE_VECTOR_WIDTH");
        if (settings.json) {
            std::printf("{\"device\": \"%s\", \"driver\": \"%s\", \"lp_native_vector_width\": \"%s\", "
                        "\"nodes\": %u, \"steps\": %u, \"invocations\": %u, \"runs\": [",
                        context.deviceInfo().name.c_str(), context.deviceInfo().driver.c_str(), lpWidth ? lpWidth : "",
                        settings.nodes, settings.steps, settings.invocations);
            for (size_t i = 0; i < timings.size(); ++i)
                std::printf("%s{\"name\": \"%s\", \"first_dispatch_s\": %.6f, \"median_s\": %.6f, "
                            "\"ns_per_node\": %.4f, \"speedup\": %.3f}",
                            i ? ", " : "", timings[i].name, timings[i].firstDispatchSeconds, timings[i].medianSeconds,
                            timings[i].nanosecondsPerNode, base / timings[i].medianSeconds);
            std::printf("]}\n");
        } else {
            std::printf("%s (%s)%s%s\n", context.deviceInfo().name.c_str(), context.deviceInfo().driver.c_str(),
                        lpWidth ? ", LP_NATIVE_VECTOR_WIDTH=" : "", lpWidth ? lpWidth : "");
            std::printf("%u nodes, %u dependent loads per invocation, %u invocations, median of %d\n", settings.nodes,
                        settings.steps, settings.invocations, settings.repeats);
            for (const Timing& t : timings)
                std::printf("  %-34s %8.4f s  %7.3f ns/node  %5.2fx  (first dispatch %.3f s)\n", t.name,
                            t.medianSeconds, t.nanosecondsPerNode, base / t.medianSeconds, t.firstDispatchSeconds);
        }
    } catch (const std::exception& error) {
        std::fprintf(stderr, "vkrt-load-probe: %s\n", error.what());
        return 1;
    }
    return 0;
}
