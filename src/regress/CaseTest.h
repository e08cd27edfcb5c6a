#pragma once
// One attempt at a regression case, in this process: render the case's scene
// at its size, spp and seed (with the per-pixel variance), test the image
// against the reference (docs/regress.md, "The statistical rule"), and write
// the failure images. `vkrt regress` runs it here (--jobs 0, --update) or in a
// child process per attempt (regress/AttemptPool.h).
#include "regress/CaseResult.h"
#include "regress/RegressionRun.h"
#include "regress/Suite.h"
#include "render/RenderSession.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

struct Reference {
    Image mean, variance; ///< variance of the mean
};

/// A case with its scene parsed and its reference loaded and checked.
struct PreparedCase {
    RegressionCase spec;
    Scene scene;
    Reference reference;
};

/// The case's scene at the case's size, checked with the scene parser's limits.
Scene caseScene(const RegressionSuite& suite, const RegressionCase& c);

/// Checks every given case before anything renders; one InputError lists all problems.
std::vector<PreparedCase> prepareCases(const RegressionSuite& suite, const std::vector<RegressionCase>& cases);

struct Rendered {
    Image mean, variance;
    double seconds = 0.0;
    uint64_t rejectedSamples = 0;
    Metadata metadata; ///< the session's, for the images written from it
};

/// Renders `spp` frames after a warm-up frame, with a per-pixel variance;
/// nullopt when Ctrl-C stopped it.
std::optional<Rendered> renderCase(const VulkanContext& context, const Scene& scene, uint32_t spp, uint32_t seed,
                                   const RegressOptions& options);

/// The suite's test of `rendered` (at `spp`) against `reference` (made with `referenceSpp`).
ReferenceTestResult testRender(const Rendered& rendered, uint32_t spp, const Reference& reference,
                               uint64_t referenceSpp, const RegressionSuite& suite);

/// BASE-reference.png, -result.png, -difference.png, -significance.png,
/// -result.exr (with the variance layer) and -pvalues.exr in `dir`.
void writeFailureImages(const std::filesystem::path& dir, const std::string& base, const Rendered& rendered,
                        const Reference& reference, const ReferenceTestResult& test);

/// The case name as a file name: anything but letters, digits, '-' and '_' becomes '_'.
std::string safeName(std::string name);

/// What one attempt is asked to do besides rendering and testing.
struct AttemptPlan {
    int number = 1;                        ///< 1, or 2 for the re-run
    uint32_t seedOffset = 0;               ///< added to the suite's seed
    std::filesystem::path failureImageDir; ///< write the failure images here (empty: nowhere)
    std::filesystem::path imageOut;        ///< write the render here, mean and "variance" layer (compare-drivers)
};

/// Renders and tests one case; nullopt when Ctrl-C stopped it. An error while
/// rendering is a Fail whose problem says what. Obeys the test hooks of
/// docs/regress.md ("Test hooks"): VKRT_TEST_CRASH_CASE, VKRT_TEST_HANG_CASE
/// and VKRT_TEST_FLAKY_CASE, each naming one case.
std::optional<CaseAttempt> runAttempt(const VulkanContext& context, const RegressionSuite& suite,
                                      const PreparedCase& prepared, const RegressOptions& options,
                                      const AttemptPlan& plan);

} // namespace vkrt
