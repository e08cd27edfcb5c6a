#include "app/VectorWidthRelaunch.h"

#include "render/GpuScene.h"
#include "util/Error.h"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <unistd.h>
#include <vector>

namespace vkrt {

namespace {

/// Set in the relaunched process: the width it was started for (never relaunch twice).
constexpr const char* kRelaunchedVariable = "VKRT_RELAUNCHED_AT_VECTOR_WIDTH";

std::vector<std::string>& savedCommandLine()
{
    static std::vector<std::string> arguments;
    return arguments;
}

} // namespace

void rememberCommandLine(int argc, char** argv) { savedCommandLine().assign(argv, argv + argc); }

void addVectorWidthOption(CLI::App& command, VectorWidthChoice& choice)
{
    command.add_option_function<std::string>(
        "--vector-width",
        [&choice](const std::string& name) {
            std::optional<VectorWidthChoice> named = vectorWidthChoiceNamed(name);
            if (!named) throw CLI::ValidationError("--vector-width " + name, "expected auto, 256 or 512");
            choice = *named;
        },
        "lavapipe's SIMD width in bits: 256 (8 lanes), 512 (16 lanes, a CPU with AVX-512), or auto (default: 512 "
        "where it measured faster, Mesa 26 or later on a scene without meshes; else 256; a width set in "
        "$LP_NATIVE_VECTOR_WIDTH stands). vkrt starts itself again with the width set");
}

VectorWidthFacts vectorWidthFacts(const VulkanContext& context, const Scene& scene, bool driverAccel)
{
    VectorWidthFacts facts;
    facts.runningBits = lavapipeVectorBits(context.deviceInfo());
    facts.mesa = mesaVersion(context.deviceInfo());
    facts.avx512 = cpuHasAvx512();
    facts.meshes = meshTriangleCount(scene) > 0;
    facts.driverAccel = driverAccel;
    const char* width = std::getenv("LP_NATIVE_VECTOR_WIDTH");
    facts.widthFromEnvironment = width && *width && !std::getenv(kRelaunchedVariable);
    return facts;
}

void relaunchAtVectorWidth(int bits, const VectorWidthFacts& facts)
{
    if (!facts.runningBits || *facts.runningBits == bits) return;
    if (const char* relaunched = std::getenv(kRelaunchedVariable)) {
        std::fprintf(stderr, "vkrt: warning: started again for %d-bit vectors (%s), lavapipe still runs at %d bits\n",
                     bits, relaunched, *facts.runningBits);
        return;
    }
    const std::vector<std::string>& arguments = savedCommandLine();
    if (arguments.empty()) return; // not the command-line program
    const std::string width = std::to_string(bits);
    setenv("LP_NATIVE_VECTOR_WIDTH", width.c_str(), 1);
    setenv(kRelaunchedVariable, width.c_str(), 1);
    // Mesa's shader cache key leaves the width out: each width has its own cache.
    if (bits != 256) setenv("MESA_SHADER_CACHE_DIR", mesaCacheDirForWidth(bits).c_str(), 1);
    std::vector<char*> argv;
    for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
    argv.push_back(nullptr);
    std::fflush(nullptr);
    execv("/proc/self/exe", argv.data());
    throw GpuError(std::string("--vector-width: could not start vkrt again at ") + width +
                   " bits: " + std::strerror(errno));
}

} // namespace vkrt
