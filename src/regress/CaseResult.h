#pragma once
// What running a regression case produced: its attempts (a case that fails
// unexpectedly is run a second time, with a fresh seed), and its status.
// An attempt made in a child process comes back as JSON (attemptToJson).
#include "regress/CaseStatus.h"
#include "regress/Suite.h"
#include "render/ErrorMetrics.h"

#include <filesystem>
#include <string>
#include <vector>

namespace vkrt {

/// One render and test of a case.
struct CaseAttempt {
    int number = 1;                       ///< 1, or 2 for the re-run
    uint32_t seed = 0;                    ///< the render seed (the suite's plus the seed offset)
    CaseStatus status = CaseStatus::Fail; ///< Pass, Fail, Crash or Timeout
    std::string problem;          ///< why it did not pass when its test did not say: the error, the signal, the timeout
    std::string note;             ///< what a test hook did to it
    bool slow = false;            ///< slower than baseline_seconds x max_slowdown
    ReferenceTestResult test;     ///< tested == 0 when it never got that far; pValues stay in the process
    double relMse = 0.0;          ///< against the reference
    uint64_t rejectedSamples = 0; ///< non-finite samples the kernel dropped
    double seconds = 0.0;         ///< render time, warm-up (the driver's compile) excluded
    double wallSeconds = 0.0;     ///< the whole attempt as the runner saw it (process start to exit)
    bool wroteImages = false;     ///< its failure images are in --report-dir
    std::string device, driver;   ///< where it ran (empty when it never got that far)
    std::string log;              ///< the child's output saved in --report-dir (file name), if any

    bool tested() const { return test.tested > 0; }
};

/// A case's outcome: every attempt, and the status after the expectations
/// (regress/Expectations.h).
struct CaseResult {
    RegressionCase spec;
    std::vector<CaseAttempt> attempts; ///< none for a skipped case
    CaseStatus status = CaseStatus::Skip;

    /// Seconds of all attempts as the runner saw them (results.csv's duration).
    double duration() const;
    /// The attempt whose numbers the reports show: the first.
    const CaseAttempt* shown() const { return attempts.empty() ? nullptr : &attempts.front(); }
    /// One line on what happened beyond the numbers: the problem, the re-run and its seed.
    std::string message() const;
};

/// An attempt as a child process writes it for its parent (--case-result).
std::string attemptToJson(const CaseAttempt& attempt);
/// The attempt a child wrote; InputError when the text is not one.
CaseAttempt attemptFromJson(const std::string& text);

} // namespace vkrt
