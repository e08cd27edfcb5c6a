#include "render/RenderMemory.h"

#include "render/Renderer.h"
#include "scene/Scene.h"
#include "shared/SceneTypes.h"
#include "util/Error.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <sys/resource.h>

namespace vkrt {
namespace {

constexpr uint64_t kRgbFloatBytes = 3 * sizeof(float);
/// A shard's tally (render/Tally.h): mean and M2 per channel and a count, in double.
constexpr uint64_t kTallyBytes = 7 * sizeof(double);

/// "MemAvailable:   123456 kB" from /proc/meminfo.
std::optional<uint64_t> kernelMemAvailable()
{
    std::ifstream in("/proc/meminfo");
    for (std::string line; std::getline(in, line);) {
        unsigned long long kib = 0;
        if (std::sscanf(line.c_str(), "MemAvailable: %llu kB", &kib) == 1) return uint64_t(kib) * 1024;
    }
    return std::nullopt;
}

std::optional<uint64_t> readNumberFile(const std::string& path)
{
    std::ifstream in(path);
    unsigned long long value = 0;
    if (in >> value) return uint64_t(value); // "max" (no limit) fails to parse: nullopt
    return std::nullopt;
}

/// This process's cgroup (v2: the one "0::/path" line of /proc/self/cgroup) limit less its use.
std::optional<uint64_t> cgroupMemoryLeft()
{
    std::ifstream in("/proc/self/cgroup");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("0::", 0) != 0) continue;
        const std::string dir = "/sys/fs/cgroup" + line.substr(3);
        const auto limit = readNumberFile(dir + "/memory.max");
        const auto used = readNumberFile(dir + "/memory.current");
        if (!limit) return std::nullopt;
        return *limit > used.value_or(0) ? *limit - used.value_or(0) : 0;
    }
    return std::nullopt;
}

/// A "Vm...:  123 kB" line of /proc/self/status: VmSize (what RLIMIT_AS
/// counts) or VmData (private writable memory: what RLIMIT_DATA counts).
uint64_t processSize(const char* field)
{
    std::ifstream in("/proc/self/status");
    const std::string prefix = std::string(field) + ":";
    for (std::string line; std::getline(in, line);) {
        unsigned long long kib = 0;
        if (line.rfind(prefix, 0) == 0 && std::sscanf(line.c_str() + prefix.size(), "%llu", &kib) == 1)
            return uint64_t(kib) * 1024;
    }
    return 0;
}

std::optional<uint64_t> resourceLimitLeft(int resource, const char* sizeField)
{
    rlimit limit{};
    if (getrlimit(resource, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return std::nullopt;
    const uint64_t size = processSize(sizeField);
    return uint64_t(limit.rlim_cur) > size ? uint64_t(limit.rlim_cur) - size : 0;
}

} // namespace

RenderMemory renderMemoryOf(const Scene& scene, const RenderOptions& options)
{
    RenderMemory need;
    need.pixels = uint64_t(scene.camera.width) * scene.camera.height;
    need.deviceBytesPerPixel = sizeof(gpu::AccumPixel);
    need.errorEstimate = options.variance;
    if (options.variance) need.deviceBytesPerPixel += varianceBytesPerPixel(options.sobol);
    if (options.aov) need.deviceBytesPerPixel += sizeof(gpu::AovPixel);
    // Each buffer is downloaded whole (Buffer::download) and turned into the
    // mean image, the variance image and a shard's tally; the EXR writer
    // holds one more RGB copy. Measured (docs/robustness.md) 54, 162 and 496
    // bytes per pixel for no, independent and Sobol' error estimates, below
    // these sums because not all of it is live at once.
    need.hostBytesPerPixel = need.deviceBytesPerPixel + 2 * kRgbFloatBytes;
    if (options.variance) need.hostBytesPerPixel += kRgbFloatBytes + kTallyBytes;
    if (options.aov) need.hostBytesPerPixel += 3 * kRgbFloatBytes + sizeof(float); // AovImages, then the EXR's copy
    return need;
}

std::optional<uint64_t> availableHostMemory()
{
    std::optional<uint64_t> least;
    for (const std::optional<uint64_t>& bound :
         {kernelMemAvailable(), cgroupMemoryLeft(), resourceLimitLeft(RLIMIT_AS, "VmSize"),
          resourceLimitLeft(RLIMIT_DATA, "VmData")})
        if (bound) least = least ? std::min(*least, *bound) : *bound;
    return least;
}

std::string formatBytes(uint64_t bytes)
{
    if (bytes < 1000) return std::to_string(bytes) + " bytes";
    const char* units[] = {"bytes", "kB", "MB", "GB", "TB"};
    double value = double(bytes);
    int unit = 0;
    while (value >= 1000 && unit < 4) value /= 1000, ++unit;
    std::ostringstream text;
    text.precision(3);
    text << value << " " << units[unit];
    return text.str();
}

void checkRenderMemory(const Scene& scene, const RenderMemory& need, bool deviceIsHostMemory, uint64_t deviceHeapBytes,
                       std::optional<uint64_t> hostAvailable)
{
    const std::string size = std::to_string(scene.camera.width) + "x" + std::to_string(scene.camera.height);
    const std::string advice = std::string("; render a smaller image (--width, --height)") +
                               (need.errorEstimate ? ", or without the error estimate" : "");
    const uint64_t hostNeed = need.hostBytes() + (deviceIsHostMemory ? need.deviceBytes() : 0);
    const uint64_t perPixel = need.hostBytesPerPixel + (deviceIsHostMemory ? need.deviceBytesPerPixel : 0);
    if (hostAvailable && hostNeed > *hostAvailable)
        throw InputError(scene.path + ": a " + size + " render needs about " + formatBytes(hostNeed) + " of memory (" +
                         std::to_string(perPixel) + " bytes per pixel), but only " + formatBytes(*hostAvailable) +
                         " is available" + advice);
    if (!deviceIsHostMemory && deviceHeapBytes > 0 && need.deviceBytes() > deviceHeapBytes)
        throw InputError(scene.path + ": a " + size + " render needs about " + formatBytes(need.deviceBytes()) +
                         " of GPU memory (" + std::to_string(need.deviceBytesPerPixel) +
                         " bytes per pixel), but the device has " + formatBytes(deviceHeapBytes) + advice);
}

} // namespace vkrt
