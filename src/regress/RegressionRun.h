#pragma once
// `vkrt regress`: renders every case of a suite, tests it against its
// reference, and writes a Markdown report, failure images, JUnit XML and
// deqp-runner's results.csv / failures.csv. Cases run in child processes, up
// to --jobs at once (regress/AttemptPool.h); --compare-drivers runs every case
// on two drivers (regress/CompareDrivers.h).
#include "gpu/ShaderCompiler.h"
#include "render/Outcome.h"
#include "render/RenderSession.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

struct RegressOptions {
    std::filesystem::path suite;
    std::vector<std::string> filters; ///< run cases whose name contains any of these (all when empty)
    std::string driver;               ///< Vulkan ICD manifest (JSON) to load instead of the system's
    std::string device;
    std::filesystem::path junit;     ///< JUnit XML output (optional)
    std::filesystem::path reportDir; ///< report.md, results.csv, failures.csv and failure images
    bool update = false;             ///< regenerate the vkrt-made references
    uint32_t seedOffset = 0;         ///< added to the suite's seed (repeat runs)
    bool failOnSlowdown = false;
    AccelChoice accel = AccelChoice::Auto;   ///< --accel: the traversal backend of every case
    std::vector<Define> kernelDefines;       ///< test hooks: build every kernel with these
    std::string injectFault;                 ///< --inject: the SPIR-V fault every kernel runs with (gpu/SpirvFault.h)
    std::optional<unsigned> jobs;            ///< --jobs: child processes at once, 0: in this process (default: jobsFor)
    std::optional<double> caseTimeout;       ///< --case-timeout: seconds per case process (default: caseTimeoutSeconds)
    std::filesystem::path baseline;          ///< --baseline: expected failures, `case-name,Status` lines
    std::filesystem::path flakes;            ///< --flakes: regular expressions of known flaky cases
    std::filesystem::path skips;             ///< --skips: regular expressions of cases not to run
    std::vector<std::string> compareDrivers; ///< --compare-drivers A.json B.json
    bool compareAccel = false;               ///< --compare-accel: own (A) against driver (B) on one driver
    /// Whether the run compares two configurations (--compare-drivers or --compare-accel).
    bool compares() const { return !compareDrivers.empty() || compareAccel; }

    // The child process's side (hidden options, given by regress/AttemptPool.cpp):
    /// --run-case: make one attempt at this case. Set (even to "") only in a
    /// child: a child never runs the suite itself.
    std::optional<std::string> runCase;
    std::filesystem::path caseResult; ///< --case-result: write the attempt here (JSON)
    std::filesystem::path caseImage;  ///< --case-image: write the render here (EXR with variance)
    int attempt = 1;                  ///< --attempt: 1, or 2 for the re-run
};

/// A re-run's seed offset is the run's plus this: a seed no first attempt of
/// a run with a nearby --seed-offset uses.
inline constexpr uint32_t kRetrySeedShift = 65536;

/// Child processes at once: --jobs when given; else 1 with --fail-on-slowdown
/// or --compare-drivers (timed renders must not share the CPU); else the
/// number of cores.
unsigned jobsFor(const RegressOptions& options);

/// Runs the suite: Passed when no case ends with a status that fails the run
/// (regress/CaseStatus.h), Failed otherwise, DeviceFailure when no device can
/// be opened, Interrupted on Ctrl-C (the finished cases are reported). Bad
/// input (manifest, references, baseline files, options) throws InputError
/// before anything renders. With `runCase` set it is the child process that
/// makes one attempt and writes it to `caseResult`.
Outcome runRegression(const RegressOptions& options);

/// Creates --report-dir (and its parents); InputError naming the option if it cannot.
void createReportDir(const std::filesystem::path& dir);

/// Checks a Vulkan ICD manifest: InputError naming `option` and the path if it
/// is missing, not a JSON ICD manifest, or names a library file that does not
/// exist. Returns the manifest's absolute path.
std::filesystem::path checkIcdManifest(const std::filesystem::path& icdManifest, const std::string& option);

/// Points the Vulkan loader at one ICD manifest after checking it (as
/// checkIcdManifest, option --driver). Call before any instance exists.
void selectVulkanDriver(const std::filesystem::path& icdManifest);

} // namespace vkrt
