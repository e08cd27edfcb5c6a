#pragma once
// `vkrt regress --compare-drivers A.json B.json`: every case on two Vulkan
// drivers (docs/regress.md, "Comparing two drivers"). Each image is tested
// against the reference as in a normal run, and the two images against each
// other with the same per-value and pooled test (B's image as the reference,
// at the same spp); the render time B/A is reported per case. The timed
// renders run one at a time unless --jobs says otherwise.
#include "regress/Expectations.h"
#include "regress/RegressionRun.h"
#include "regress/Suite.h"

#include <vector>

namespace vkrt {

/// Passed when every case passes on both drivers and the two images agree
/// (and, with --fail-on-slowdown, B is not slower than max_slowdown x A);
/// Failed otherwise; Interrupted on Ctrl-C. Only --skips of the expectations applies.
Outcome compareDrivers(const RegressionSuite& suite, const std::vector<RegressionCase>& cases,
                       const Expectations& expectations, const RegressOptions& options);

} // namespace vkrt
