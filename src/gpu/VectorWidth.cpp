#include "gpu/VectorWidth.h"

#include "util/Error.h"

#include <cstdlib>
#include <regex>

namespace vkrt {

std::optional<VectorWidthChoice> vectorWidthChoiceNamed(const std::string& name)
{
    if (name == "auto") return VectorWidthChoice::Auto;
    if (name == "256") return VectorWidthChoice::Bits256;
    if (name == "512") return VectorWidthChoice::Bits512;
    return std::nullopt;
}

std::string vectorWidthChoiceName(VectorWidthChoice choice)
{
    switch (choice) {
    case VectorWidthChoice::Bits256: return "256";
    case VectorWidthChoice::Bits512: return "512";
    case VectorWidthChoice::Auto: break;
    }
    return "auto";
}

std::optional<int> lavapipeVectorBits(const DeviceInfo& device)
{
    if (device.driverId != vk::DriverId::eMesaLlvmpipe) return std::nullopt;
    static const std::regex bits(R"(, (\d+) bits\))");
    std::smatch match;
    if (!std::regex_search(device.name, match, bits)) return std::nullopt;
    return std::stoi(match[1].str());
}

std::optional<std::pair<int, int>> mesaVersion(const DeviceInfo& device)
{
    static const std::regex version(R"(Mesa (\d+)\.(\d+))");
    std::smatch match;
    if (!std::regex_search(device.driver, match, version)) return std::nullopt;
    return std::make_pair(std::stoi(match[1].str()), std::stoi(match[2].str()));
}

bool cpuHasAvx512()
{
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
           __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
#else
    return false;
#endif
}

namespace {

bool mesa26OrLater(const VectorWidthFacts& facts) { return facts.mesa && facts.mesa->first >= 26; }

void checkExplicit512(const VectorWidthFacts& facts)
{
    if (!facts.runningBits)
        throw InputError("--vector-width 512: the width is lavapipe's (LP_NATIVE_VECTOR_WIDTH); this device is not "
                         "lavapipe");
    if (!facts.avx512)
        throw InputError("--vector-width 512: this CPU lacks AVX-512 (F, BW, DQ and VL), so 512-bit kernels would "
                         "be emulated; use 256 or auto");
    if (facts.driverAccel && mesa26OrLater(facts))
        throw InputError("--vector-width 512 with the driver's traversal: lavapipe of Mesa 26 aborts compiling the "
                         "ray-query kernel at 512 bits (docs/performance.md, \"Round four\"); use --accel own or "
                         "--vector-width 256");
}

} // namespace

std::optional<int> chooseVectorBits(VectorWidthChoice choice, const VectorWidthFacts& facts)
{
    switch (choice) {
    case VectorWidthChoice::Bits256:
        if (!facts.runningBits)
            throw InputError("--vector-width 256: the width is lavapipe's (LP_NATIVE_VECTOR_WIDTH); this device is "
                             "not lavapipe");
        return 256;
    case VectorWidthChoice::Bits512: checkExplicit512(facts); return 512;
    case VectorWidthChoice::Auto: break;
    }
    // The user's own $LP_NATIVE_VECTOR_WIDTH stands (but not into the abort
    // below); so does any device but lavapipe.
    if (facts.widthFromEnvironment && facts.runningBits == 512 && facts.driverAccel && mesa26OrLater(facts))
        throw InputError("$LP_NATIVE_VECTOR_WIDTH=512 with the driver's traversal: lavapipe of Mesa 26 aborts "
                         "compiling the ray-query kernel at 512 bits (docs/performance.md, \"Round four\"); unset "
                         "it, or use --accel own");
    if (!facts.runningBits || facts.widthFromEnvironment) return std::nullopt;
    // Measured (docs/performance.md, "Round four"): on Mesa 26.1 512 bits gave
    // 1.2-1.3x samples/s on scenes without meshes and 0.8x with them; on Mesa
    // 25.0 0.7-0.98x on every scene. The driver's ray-query kernel aborts Mesa
    // 26 at 512 bits.
    const bool pays = facts.avx512 && mesa26OrLater(facts) && !facts.meshes && !facts.driverAccel;
    return pays ? 512 : 256;
}

std::string mesaCacheDirForWidth(int bits)
{
    std::string base;
    if (const char* dir = std::getenv("MESA_SHADER_CACHE_DIR"); dir && *dir) base = dir;
    else if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) base = xdg;
    else if (const char* home = std::getenv("HOME"); home && *home) base = std::string(home) + "/.cache";
    else base = "/tmp";
    return base + "/vkrt-lavapipe-" + std::to_string(bits) + "-bit";
}

} // namespace vkrt
