#pragma once
// The traversal backend of a session (`--accel`): which code answers the
// kernel's traceClosest/traceAny.
#include <cstdint>
#include <optional>
#include <string>

namespace vkrt {

struct DeviceInfo; // gpu/VulkanContext.h

/// Which traversal answers traceClosest/traceAny (docs/architecture.md,
/// "Two traversal backends"): vkrt's own BVH walk in the compute kernel, or
/// the driver's acceleration structures through VK_KHR_ray_query. Auto picks
/// per device and scene (resolveAccel).
enum class AccelChoice { Own, Driver, Auto };
enum class Accel { Own, Driver };

/// "own", "driver" or "auto" (the --accel values); nullopt otherwise.
std::optional<AccelChoice> accelChoiceNamed(const std::string& name);
std::string accelName(Accel accel);
/// --accel's spelling of a choice ("own", "driver", "auto").
std::string accelChoiceName(AccelChoice choice);
/// Auto takes the driver's traversal on a CPU device (lavapipe) only for
/// scenes whose meshes render at most this many triangles in all.
constexpr uint64_t kDriverAccelMaxCpuTriangles = 256;

/// The one backend policy: a given choice is kept (Driver on a device
/// without ray queries is an InputError saying what it lacks); Auto takes
/// the driver's where it measured faster (docs/performance.md, "Two
/// traversal backends"): on every GPU, and on lavapipe for scenes with a
/// few mesh triangles (1 to kDriverAccelMaxCpuTriangles, `meshTriangles`
/// rendered in all); the own backend elsewhere and without ray queries.
Accel resolveAccel(AccelChoice choice, const DeviceInfo& device, uint64_t meshTriangles);

} // namespace vkrt
