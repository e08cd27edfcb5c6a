#pragma once
// The memory a render of a given image size holds, stated before anything is
// allocated, and checked against what this process can still get: a
// 16384x4096 render with an error estimate needs gigabytes, and running out
// half-way (or being killed by the kernel's OOM killer) helps nobody.
#include <cstdint>
#include <optional>
#include <string>

namespace vkrt {

struct RenderOptions; // render/Renderer.h
struct Scene;         // scene/Scene.h

/// Per-pixel bytes of a render, split by where they live.
struct RenderMemory {
    uint64_t pixels = 0;
    uint64_t deviceBytesPerPixel = 0; ///< the per-pixel GPU buffers (accumulation, variance)
    uint64_t hostBytesPerPixel = 0;   ///< their downloaded copies and the images made from them
    bool errorEstimate = false;       ///< the variance buffers are part of it
    uint64_t deviceBytes() const { return pixels * deviceBytesPerPixel; }
    uint64_t hostBytes() const { return pixels * hostBytesPerPixel; }
};

RenderMemory renderMemoryOf(const Scene& scene, const RenderOptions& options);

/// Bytes this process can still allocate: the smallest of the kernel's
/// MemAvailable, the cgroup's memory.max less its current use (a Slurm job's
/// limit) and RLIMIT_AS / RLIMIT_DATA less this process's size; none known: nullopt.
std::optional<uint64_t> availableHostMemory();

/// "4.45 GB" style text (decimal units, three significant digits).
std::string formatBytes(uint64_t bytes);

/// Throws InputError naming the scene when the render would need more host
/// memory than is available (`deviceIsHostMemory`: the device's buffers are
/// host memory too, as on lavapipe; otherwise they are checked against
/// `deviceHeapBytes`, the device-local heap).
void checkRenderMemory(const Scene& scene, const RenderMemory& need, bool deviceIsHostMemory, uint64_t deviceHeapBytes,
                       std::optional<uint64_t> hostAvailable);

} // namespace vkrt
