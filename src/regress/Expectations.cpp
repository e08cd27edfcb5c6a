#include "regress/Expectations.h"

#include "util/Error.h"

#include <re2/re2.h>

#include <algorithm>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

std::string trimmed(const std::string& text)
{
    const char* space = " \t\r\n";
    size_t begin = text.find_first_not_of(space);
    if (begin == std::string::npos) return "";
    return text.substr(begin, text.find_last_not_of(space) - begin + 1);
}

/// What a message shows of a value from a file: its first 96 bytes.
std::string echoed(const std::string& text)
{
    constexpr size_t kShown = 96;
    std::string shown = text.substr(0, kShown);
    if (text.size() > kShown) shown.append("...");
    return shown;
}

/// The file's lines, each with "file:line"; blank lines and `#` comments left out.
std::vector<std::pair<std::string, std::string>> meaningfulLines(const fs::path& path, const std::string& option)
{
    std::error_code error;
    const fs::file_status status = fs::status(path, error);
    if (!fs::exists(status)) throw InputError(option + " " + path.string() + ": no such file");
    // A FIFO or a device could block or never end; a directory is no list.
    if (!fs::is_regular_file(status))
        throw InputError(option + " " + path.string() + ": is " +
                         (fs::is_directory(status) ? "a directory" : "not a regular file") + ", not a text file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(option + " " + path.string() + ": cannot read it");
    std::vector<std::pair<std::string, std::string>> lines;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        if (line.size() > kMaxExpectationLineBytes)
            throw InputError(path.string() + ":" + std::to_string(number) + ": a line of " +
                             std::to_string(line.size()) + " bytes, more than the " +
                             std::to_string(kMaxExpectationLineBytes) + " vkrt reads ('" + echoed(line) + "')");
        line = trimmed(line);
        if (line.empty() || line[0] == '#') continue;
        lines.emplace_back(path.string() + ":" + std::to_string(number), line);
    }
    if (in.bad()) throw InputError(option + " " + path.string() + ": cannot read it");
    return lines;
}

std::vector<std::string> fieldsOf(const std::string& line)
{
    std::vector<std::string> fields;
    std::istringstream in(line);
    for (std::string field; std::getline(in, field, ',');) fields.push_back(trimmed(field));
    if (!line.empty() && line.back() == ',') fields.push_back("");
    return fields;
}

/// Only the statuses a case can be expected to end with; the others are
/// outcomes of a comparison with the baseline, and listing one is a mistake
/// the message explains.
CaseStatus expectableStatus(const std::string& where, const std::string& text)
{
    std::optional<CaseStatus> status = statusNamed(text);
    if (status && isFailure(*status)) return *status;
    std::string why = "expected Fail, Crash or Timeout";
    if (status == CaseStatus::UnexpectedPass) why += " (UnexpectedPass: the case passes now; remove the line)";
    else if (status == CaseStatus::Flake || status == CaseStatus::KnownFlake) why += " (list flaky cases in --flakes)";
    else if (status == CaseStatus::Skip) why += " (list skipped cases in --skips)";
    throw InputError(where + ": status '" + text + "' cannot be expected: " + why);
}

} // namespace

std::optional<CaseStatus> Expectations::expectedStatus(const std::string& name) const
{
    auto it = baseline.find(name);
    if (it == baseline.end()) return std::nullopt;
    return it->second.status;
}

namespace {
bool anyMatches(const std::vector<NamePattern>& patterns, const std::string& name)
{
    return std::any_of(patterns.begin(), patterns.end(), [&](const NamePattern& p) { return p.foundIn(name); });
}
} // namespace

bool NamePattern::foundIn(const std::string& name) const { return re2::RE2::PartialMatch(name, *regex); }

bool Expectations::isKnownFlake(const std::string& name) const { return anyMatches(flakes, name); }
bool Expectations::isSkipped(const std::string& name) const { return anyMatches(skips, name); }

std::map<std::string, ExpectedStatus> readBaseline(const fs::path& path)
{
    std::map<std::string, ExpectedStatus> baseline;
    for (const auto& [where, line] : meaningfulLines(path, "--baseline")) {
        std::vector<std::string> fields = fieldsOf(line);
        if (fields.size() < 2 || fields.size() > 3 || fields[0].empty() || fields[1].empty())
            throw InputError(where + ": expected 'case-name,Status' (e.g. 'extreme/tir,Fail'), got '" + echoed(line) +
                             "'");
        ExpectedStatus expected{expectableStatus(where, fields[1]), where};
        auto [first, inserted] = baseline.emplace(fields[0], expected);
        if (!inserted)
            throw InputError(where + ": case " + echoed(fields[0]) + " is already listed (" + first->second.where +
                             ")");
    }
    return baseline;
}

std::vector<NamePattern> readNamePatterns(const fs::path& path, const std::string& option)
{
    std::vector<NamePattern> patterns;
    for (const auto& [where, line] : meaningfulLines(path, option)) {
        re2::RE2::Options options;
        options.set_log_errors(false);
        // RE2 bounds its memory; a pattern that needs more is refused, not run.
        options.set_max_mem(8 << 20);
        auto regex = std::make_shared<const re2::RE2>(line, options);
        if (!regex->ok())
            throw InputError(where + ": not a regular expression: '" + echoed(line) + "' (" + regex->error() + ")");
        patterns.push_back({std::move(regex), line, where});
    }
    return patterns;
}

Expectations readExpectations(const fs::path& baseline, const fs::path& flakes, const fs::path& skips)
{
    Expectations expectations;
    if (!baseline.empty()) expectations.baseline = readBaseline(baseline);
    if (!flakes.empty()) expectations.flakes = readNamePatterns(flakes, "--flakes");
    if (!skips.empty()) expectations.skips = readNamePatterns(skips, "--skips");
    return expectations;
}

std::vector<std::string> baselineLinesNamingNoCase(const Expectations& expectations,
                                                   const std::vector<std::string>& names)
{
    std::vector<std::string> warnings;
    for (const auto& [name, expected] : expectations.baseline)
        if (std::find(names.begin(), names.end(), name) == names.end())
            warnings.push_back(expected.where + ": no case named " + echoed(name) + " in the suite");
    return warnings;
}

bool needsRetry(const std::string& name, CaseStatus first, const Expectations& expectations)
{
    return isFailure(first) && expectations.expectedStatus(name) != first;
}

CaseStatus caseStatus(const std::string& name, const std::vector<CaseStatus>& attempts,
                      const Expectations& expectations)
{
    const CaseStatus first = attempts.empty() ? CaseStatus::Skip : attempts.front();
    const std::optional<CaseStatus> expected = expectations.expectedStatus(name);
    if (first == CaseStatus::Skip) return first;
    if (first == CaseStatus::Pass) return expected ? CaseStatus::UnexpectedPass : CaseStatus::Pass;
    if (expected == first) return CaseStatus::ExpectedFail;
    if (attempts.size() > 1 && attempts[1] == CaseStatus::Pass)
        return expectations.isKnownFlake(name) ? CaseStatus::KnownFlake : CaseStatus::Flake;
    return first;
}

} // namespace vkrt
