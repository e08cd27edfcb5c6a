#pragma once
// What the kernels' float32 arithmetic can hold: a value the scene file
// accepts in double precision must also survive the kernel's products and
// squared lengths (normalize() squares each component and sums three). A
// thin lens focused at 1e20 rendered black: its focus point's squared length,
// 1e40, overflows float32 (3.4e38) and every ray direction became NaN.
namespace vkrt {

/// The largest magnitude of a length, distance or texture-coordinate factor
/// vkrt passes to a kernel: three squares of it sum to 3e36, within float32.
inline constexpr double kMaxKernelMagnitude = 1e18;

} // namespace vkrt
