#pragma once
// What a driver is expected to do, in the files of Mesa CI's deqp-runner
// (docs/regress.md, "Baseline files"): a baseline of known failures
// (`case-name,Status` lines, as in a previous run's failures.csv), and lists
// of regular expressions naming known flakes and cases to skip. With them only
// unexpected results fail a run.
#include "regress/CaseStatus.h"

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace re2 {
class RE2;
}

namespace vkrt {

/// One line of a --flakes or --skips file: an RE2 expression (the syntax of
/// deqp-runner's Rust regex), matched in time linear in the name.
struct NamePattern {
    std::shared_ptr<const re2::RE2> regex;
    std::string text;  ///< as written, for messages
    std::string where; ///< "file:line"

    bool foundIn(const std::string& name) const;
};

/// The longest --flakes/--skips pattern and baseline line vkrt reads (bytes).
inline constexpr size_t kMaxExpectationLineBytes = 1024;

struct ExpectedStatus {
    CaseStatus status = CaseStatus::Fail; ///< Fail, Crash or Timeout
    std::string where;                    ///< "file:line" of the baseline line
};

struct Expectations {
    std::map<std::string, ExpectedStatus> baseline; ///< --baseline, by case name
    std::vector<NamePattern> flakes;                ///< --flakes
    std::vector<NamePattern> skips;                 ///< --skips

    std::optional<CaseStatus> expectedStatus(const std::string& name) const;
    bool isKnownFlake(const std::string& name) const;
    bool isSkipped(const std::string& name) const;
};

/// Reads a baseline: lines `case-name,Status` (a third field, the duration of
/// a results.csv or failures.csv line, is allowed and ignored), blank lines
/// and `#` comments. Status is Fail, Crash or Timeout. Errors are InputError
/// "file:line: ...": a line without a status, an unknown or meaningless
/// status, a case listed twice.
std::map<std::string, ExpectedStatus> readBaseline(const std::filesystem::path& path);

/// Reads one regular expression (RE2 syntax, as deqp-runner's Rust regex) per
/// line, blank lines and `#` comments skipped; a case matches when the
/// expression is found anywhere in its name (deqp-runner's rule). A bad
/// expression, or a line over kMaxExpectationLineBytes, is an InputError
/// "file:line: ..." (what it echoes of the line cut at 96 bytes).
std::vector<NamePattern> readNamePatterns(const std::filesystem::path& path, const std::string& option);

/// The three files of the options (empty paths: none).
Expectations readExpectations(const std::filesystem::path& baseline, const std::filesystem::path& flakes,
                              const std::filesystem::path& skips);

/// "file:line: no case named X in the suite" for each baseline line that names
/// no case of `names` (a misspelt name would otherwise silently expect nothing).
std::vector<std::string> baselineLinesNamingNoCase(const Expectations& expectations,
                                                   const std::vector<std::string>& names);

/// Whether an attempt that ended with `first` (Pass, Fail, Crash or Timeout)
/// is re-run: an unexpected failure is, to tell a flake from a regression.
bool needsRetry(const std::string& name, CaseStatus first, const Expectations& expectations);

/// The case's status from its attempts' statuses (one, or two after a
/// re-run) and the expectations:
///  - passed, and listed in the baseline: UnexpectedPass; passed: Pass;
///  - failed as the baseline says: ExpectedFail;
///  - failed, then passed: KnownFlake when --flakes lists it, else Flake;
///  - failed twice: the first attempt's status (Fail, Crash or Timeout).
CaseStatus caseStatus(const std::string& name, const std::vector<CaseStatus>& attempts,
                      const Expectations& expectations);

} // namespace vkrt
