#pragma once
// The SIMD width lavapipe compiles kernels for (its LP_NATIVE_VECTOR_WIDTH:
// 256 bits, 8 lanes, by default on an AVX2 CPU; 512 bits, 16 lanes, where
// the CPU has AVX-512). lavapipe reads the width once, when the Vulkan
// loader first loads it, so a different width means setting it before any
// Vulkan call: `vkrt render` relaunches itself for it (app/VectorWidthRelaunch).
// What `auto` picks is measured (docs/performance.md, "Round four"): 512 bits
// pays only on Mesa >= 26 and only for kernels without meshes.
#include "gpu/VulkanContext.h"

#include <optional>
#include <string>

namespace vkrt {

enum class VectorWidthChoice { Auto, Bits256, Bits512 };

std::optional<VectorWidthChoice> vectorWidthChoiceNamed(const std::string& name);
std::string vectorWidthChoiceName(VectorWidthChoice choice);

/// The width lavapipe reports in its device name ("llvmpipe (LLVM 19.1.7, 256 bits)"); nullopt for other devices.
std::optional<int> lavapipeVectorBits(const DeviceInfo& device);

/// Mesa's major and minor version from the driver string ("... Mesa 26.1.6 ..."), or nullopt.
std::optional<std::pair<int, int>> mesaVersion(const DeviceInfo& device);

/// Whether this CPU runs 512-bit vectors natively (AVX-512 F, BW, DQ and VL, what LLVM's 512-bit code needs).
bool cpuHasAvx512();

/// What a render needs to know to choose.
struct VectorWidthFacts {
    std::optional<int> runningBits;          ///< lavapipe's width now (nullopt: not lavapipe)
    std::optional<std::pair<int, int>> mesa; ///< the driver's Mesa version
    bool avx512 = false;                     ///< cpuHasAvx512()
    bool meshes = false;                     ///< the scene has mesh instances
    bool driverAccel = false;                ///< the render uses the driver's ray queries
    bool widthFromEnvironment = false;       ///< $LP_NATIVE_VECTOR_WIDTH was set by the user
};

/// The width to run at: nullopt keeps the running one. Throws InputError for
/// an explicit choice that cannot run (not lavapipe, no AVX-512, the ray-query
/// kernel that Mesa 26 lavapipe crashes compiling at 512 bits).
std::optional<int> chooseVectorBits(VectorWidthChoice choice, const VectorWidthFacts& facts);

/// The Mesa shader cache folder for a width: lavapipe's cache key does not
/// include the width, so code compiled at one width must never be loaded at
/// the other. `base`: $MESA_SHADER_CACHE_DIR, else $XDG_CACHE_HOME, else ~/.cache.
std::string mesaCacheDirForWidth(int bits);

} // namespace vkrt
