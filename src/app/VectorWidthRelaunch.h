#pragma once
// `vkrt render --vector-width`: lavapipe reads its SIMD width once, when the
// Vulkan loader loads it, so running at another width means starting again
// with $LP_NATIVE_VECTOR_WIDTH set (gpu/VectorWidth.h says what auto picks).
#include "gpu/VectorWidth.h"
#include "scene/Scene.h"

namespace CLI {
class App;
}

namespace vkrt {

/// main() keeps the command line for a relaunch to repeat.
void rememberCommandLine(int argc, char** argv);

/// --vector-width auto|256|512 on a command that renders.
void addVectorWidthOption(CLI::App& command, VectorWidthChoice& choice);

/// What chooseVectorBits needs, from the device, the scene and the traversal that will run.
VectorWidthFacts vectorWidthFacts(const VulkanContext& context, const Scene& scene, bool driverAccel);

/// Re-executes this vkrt with lavapipe at `bits` when that differs from the
/// running width, unless this process is already such a relaunch (then it
/// warns and goes on at the running width). Returns only when it does not
/// relaunch; on a failed exec it throws.
void relaunchAtVectorWidth(int bits, const VectorWidthFacts& facts);

} // namespace vkrt
