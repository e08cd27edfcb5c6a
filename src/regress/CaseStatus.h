#pragma once
// The statuses of a regression case, named and meant as Mesa CI's deqp-runner
// names them (docs/regress.md, "Statuses"), so that a driver developer's
// habits, baseline files and scripts carry over.
#include <optional>
#include <string>

namespace vkrt {

enum class CaseStatus {
    Pass,           ///< rendered, and the image passed its test
    Fail,           ///< the image failed its test, or the case could not render
    Crash,          ///< the case's process died of a signal or exited without a result
    Timeout,        ///< the case's process ran past its time and was killed
    Flake,          ///< failed, then passed when re-run with a fresh seed
    Skip,           ///< matched --skips: not run
    ExpectedFail,   ///< failed as the --baseline says it does
    UnexpectedPass, ///< the --baseline says it fails, but it passed
    KnownFlake,     ///< a Flake that --flakes lists
};

/// "Pass", "Fail", ... (the spelling of results.csv and baseline files).
std::string statusName(CaseStatus status);
/// The status of that exact name; nullopt for anything else.
std::optional<CaseStatus> statusNamed(const std::string& name);

/// Fail, Crash or Timeout: an attempt, or a case, that did not pass.
bool isFailure(CaseStatus status);
/// The statuses that fail a run (exit 4): Fail, Crash, Timeout and
/// UnexpectedPass. A Flake does not, as in deqp-runner: it passed on the re-run.
bool failsTheRun(CaseStatus status);

} // namespace vkrt
