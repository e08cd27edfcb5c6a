#pragma once
// The reports of `vkrt regress` (docs/regress.md, "The report"): report.md for
// people, JUnit XML for CI systems, results.csv and failures.csv in
// deqp-runner's form for scripts and as the next run's --baseline, and the
// console lines.
#include "gpu/ShaderCompiler.h"
#include "regress/CaseResult.h"
#include "regress/Expectations.h"
#include "regress/Suite.h"
#include "render/Outcome.h"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace vkrt {

/// Where the run stands: "12 of 24 cases", plus "interrupted" when it ended early.
struct RunStatus {
    size_t total = 0;
    bool interrupted = false;
};

/// What report.md's header says about the run besides the suite.
struct RunDescription {
    std::string device;         ///< "NAME (DRIVER)"
    std::string driverManifest; ///< --driver, or empty for the system's drivers
    uint32_t seed = 0;          ///< the suite's seed plus --seed-offset
    uint32_t retrySeed = 0;     ///< the seed of re-runs
    unsigned jobs = 0;          ///< child processes at once; 0: in this process
    std::string accel;          ///< --accel
    std::vector<Define> kernelDefines;
    std::string injectFault; ///< --inject: the SPIR-V fault injected, or empty
    std::filesystem::path baseline, flakes, skips;
    const Expectations* expectations = nullptr;
};

/// A case's line in results.csv, failures.csv and the JUnit file.
struct StatusLine {
    std::string name;
    CaseStatus status = CaseStatus::Pass;
    double duration = 0.0; ///< seconds
    std::string message;   ///< what happened beyond the status
    bool slow = false;
};

StatusLine statusLine(const CaseResult& result);

/// "38 Pass, 1 Flake, 1 Fail" over the lines, in the order of CaseStatus.
std::string statusCounts(const std::vector<StatusLine>& lines);
/// How many lines fail the run (failsTheRun).
size_t unexpectedCount(const std::vector<StatusLine>& lines);
/// Prints a run's last line (the counts, and how far an interrupted run got
/// of its `cases`) and returns its outcome: Interrupted, Failed on an
/// unexpected result, else Passed.
Outcome finishRun(const std::vector<StatusLine>& lines, bool interrupted, size_t cases);

/// `test,status,duration` lines, no header (deqp-runner's results.csv);
/// `unexpectedOnly` keeps the lines that fail the run (failures.csv).
std::string resultsCsv(const std::vector<StatusLine>& lines, bool unexpectedOnly);

/// One <testcase> per line: a <failure> for Fail and UnexpectedPass, an
/// <error> for Crash and Timeout, <skipped/> for Skip; the rest pass (a
/// Flake's or ExpectedFail's story in <system-out>). The run's `properties`
/// (name, value), if any, go in the suite's <properties>.
std::string junitReport(const std::vector<StatusLine>& lines,
                        const std::vector<std::pair<std::string, std::string>>& properties = {});

/// The JUnit properties of a run: the injected SPIR-V fault, if any.
std::vector<std::pair<std::string, std::string>> junitProperties(const std::string& injectFault);

std::string markdownReport(const RegressionSuite& suite, const std::vector<CaseResult>& results, RunStatus status,
                           const RunDescription& run);

/// The rule the suite tests with, as one sentence for report headers.
std::string ruleDescription(const RegressionSuite& suite);
/// Text for a Markdown table cell: no newlines, no '|'.
std::string tableCell(std::string text);

/// One console line per finished case (and one more for its story); `done` of `total`.
void printResult(const CaseResult& result, size_t done, size_t total);

} // namespace vkrt
