#pragma once
// Whether a device silently ends long shader loops. Mesa's lavapipe before
// version 25 stops every loop of a group of 8 invocations after 65,535 passes
// in total, with no error (shared/NUMERICS.md, docs/platform.md); Mesa 25 and
// real GPUs run loops to completion. The loop-budget guard follows this.
#include <cstdint>
#include <optional>
#include <string>

namespace vkrt {

class VulkanContext;
struct DeviceInfo;

struct LoopCap {
    /// Loop passes one invocation may run before the device cuts it short; none: no cap.
    std::optional<uint32_t> budget;
    /// How that was decided, for people: the probe's result or the driver rule.
    std::string evidence;

    bool capped() const { return budget.has_value(); }
    /// One line for `vkrt info` and the EXR metadata, e.g.
    /// "none (Mesa 25 lavapipe runs loops to completion)".
    std::string describe() const;
};

/// The Mesa major version in a lavapipe driver description ("llvmpipe: Mesa 25.0.7 (LLVM 15.0.6)"), if any.
std::optional<int> mesaMajorVersion(const std::string& driver);

/// How a device's cap is found: lavapipe from Mesa 25 on is known not to cap
/// (measured), other lavapipe versions run a probe dispatch, other devices do
/// not cap. `alwaysProbe` runs the probe on any lavapipe (tests check the rule).
LoopCap detectLoopCap(const VulkanContext& context, bool alwaysProbe = false);

/// Runs a 100,000-pass loop in one group of 8 invocations and reports the passes
/// that completed: fewer than 100,000 means the device caps loops.
uint32_t probeCompletedLoopPasses(const VulkanContext& context);

} // namespace vkrt
