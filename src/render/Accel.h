#pragma once
// The traversal backend of a session (`--accel`): which code answers the
// kernel's traceClosest/traceAny.
#include <optional>
#include <string>

namespace vkrt {

struct DeviceInfo; // gpu/VulkanContext.h
struct Scene;      // scene/Scene.h

/// Which traversal answers traceClosest/traceAny (docs/architecture.md,
/// "Two traversal backends"): vkrt's own BVH walk in the compute kernel, or
/// the driver's acceleration structures through VK_KHR_ray_query. Auto picks
/// per device and scene (resolveAccel).
enum class AccelChoice { Own, Driver, Auto };
enum class Accel { Own, Driver };

/// "own", "driver" or "auto" (the --accel values); nullopt otherwise.
std::optional<AccelChoice> accelChoiceNamed(const std::string& name);
std::string accelName(Accel accel);
/// The one backend policy: a given choice is kept (Driver on a device
/// without ray queries is an InputError saying what it lacks); Auto takes
/// the driver's where it measured faster (docs/performance.md).
Accel resolveAccel(AccelChoice choice, const DeviceInfo& device, const Scene& scene);

} // namespace vkrt
