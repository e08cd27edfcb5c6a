#include "regress/Reports.h"

#include "regress/CaseTest.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>

namespace vkrt {

namespace {

constexpr CaseStatus kStatusOrder[] = {CaseStatus::Pass,  CaseStatus::ExpectedFail, CaseStatus::KnownFlake,
                                       CaseStatus::Flake, CaseStatus::Skip,         CaseStatus::Fail,
                                       CaseStatus::Crash, CaseStatus::Timeout,      CaseStatus::UnexpectedPass};

std::string referenceLabel(const RegressionCase& c)
{
    return std::string(c.source == ReferenceSource::Mitsuba ? "mitsuba" : "vkrt") + ", " +
           std::to_string(c.referenceSpp) + " spp";
}

/// The status as report.md shows it: what fails the run in bold.
std::string statusCell(CaseStatus status, bool slow)
{
    std::string name = statusName(status);
    return (failsTheRun(status) ? "**" + name + "**" : name) + (slow ? " (slow)" : "");
}

std::string xmlEscape(const std::string& text)
{
    std::string out;
    for (char ch : text) {
        if (ch == '<') out += "&lt;";
        else if (ch == '>') out += "&gt;";
        else if (ch == '&') out += "&amp;";
        else if (ch == '"') out += "&quot;";
        else if (ch == '\n') out += "&#10;";
        // XML 1.0 has no other control characters, not even as references:
        // one in a message (a driver's, a file name's) made the report unreadable.
        else if (static_cast<unsigned char>(ch) < 0x20 && ch != '\t' && ch != '\r') out += "\xEF\xBF\xBD";
        else out += ch;
    }
    return out;
}

std::string fileLabel(const std::filesystem::path& path, size_t entries, const char* what)
{
    return "`" + path.string() + "` (" + std::to_string(entries) + " " + what + ")";
}

std::string expectationsLine(const RunDescription& run)
{
    if (!run.expectations) return "";
    std::string line;
    auto add = [&](const std::string& part) { line += (line.empty() ? "- " : ", ") + part; };
    if (!run.baseline.empty()) add("baseline: " + fileLabel(run.baseline, run.expectations->baseline.size(), "cases"));
    if (!run.flakes.empty()) add("flakes: " + fileLabel(run.flakes, run.expectations->flakes.size(), "patterns"));
    if (!run.skips.empty()) add("skips: " + fileLabel(run.skips, run.expectations->skips.size(), "patterns"));
    return line.empty() ? "" : line + "\n";
}

std::string jobsLine(unsigned jobs)
{
    if (jobs == 0) return "- jobs: 0 (every case in this process, one at a time)\n";
    return "- jobs: " + std::to_string(jobs) + " child process" + (jobs > 1 ? "es" : "") + " at once" +
           (jobs > 1 ? " (the seconds of a case include the CPU it shared with the others)" : "") + "\n";
}

std::string markdownHeader(const RegressionSuite& suite, const std::vector<CaseResult>& results, RunStatus status,
                           const RunDescription& run)
{
    std::vector<StatusLine> lines;
    for (const CaseResult& r : results) lines.push_back(statusLine(r));
    std::ostringstream md;
    md << "# vkrt regression report\n\n"
       << "- suite: `" << suite.path.string() << "`\n- device: " << run.device << "\n"
       << "- driver manifest: " << (run.driverManifest.empty() ? "system default" : "`" + run.driverManifest + "`")
       << "\n- seed: " << run.seed << " (a case that fails unexpectedly is re-run once with seed " << run.retrySeed
       << ")\n"
       << jobsLine(run.jobs) << "- accel: " << run.accel << "\n";
    for (const Define& d : run.kernelDefines)
        md << "- kernel define (test hook): `" << d.first << "=" << d.second << "`\n";
    if (!run.injectFault.empty()) md << "- injected SPIR-V fault: `" << run.injectFault << "`\n";
    md << expectationsLine(run) << "- rule: " << ruleDescription(suite) << "\n- result: **" << statusCounts(lines)
       << "**, " << unexpectedCount(lines) << " unexpected";
    if (results.size() < status.total)
        md << " (" << results.size() << " of " << status.total << " cases"
           << (status.interrupted ? ": **interrupted**" : " so far") << ")";
    md << "\n\n";
    return md.str();
}

std::string markdownRow(const CaseResult& r)
{
    const CaseAttempt* a = r.shown();
    const std::string notes = tableCell(r.message());
    if (!a || !a->tested())
        return "| " + r.spec.name + " | " + statusCell(r.status, false) + " | | | | | | | | | " +
               referenceLabel(r.spec) + " | " + notes + " |\n";
    char line[768];
    const double baseline = r.spec.baselineSeconds;
    std::string baselineText = baseline > 0 ? std::to_string(baseline).substr(0, 5) : "-";
    std::string ratio = baseline > 0 ? std::to_string(a->seconds / baseline).substr(0, 4) : "-";
    std::string rejected = std::to_string(a->rejectedSamples);
    if (r.spec.maxRejected) rejected += " (max " + std::to_string(r.spec.maxRejected) + ")";
    std::snprintf(line, sizeof line, "| %s | %s | %.3f %% | %+.2f | %.3g | %.3g | %s | %.2f | %s | %s | %s | ",
                  r.spec.name.c_str(), statusCell(r.status, a->slow).c_str(), 100.0 * a->test.fractionPassed(),
                  a->test.pooledZ, a->test.minPValue, a->relMse, rejected.c_str(), a->seconds, baselineText.c_str(),
                  ratio.c_str(), referenceLabel(r.spec).c_str());
    return line + notes + " |\n";
}

/// The numbers and images of the first attempt that failed its test.
std::string failureSection(const CaseResult& r)
{
    auto failed =
        std::find_if(r.attempts.begin(), r.attempts.end(), [](const CaseAttempt& a) { return a.wroteImages; });
    if (failed == r.attempts.end()) return "";
    const ReferenceTestResult& t = failed->test;
    const std::string base = safeName(r.spec.name);
    std::ostringstream md;
    md << "\n## " << r.spec.name << "\n\n"
       << statusName(r.status) << ". Seed " << failed->seed << ": " << t.tested - t.passed << " of " << t.tested
       << " values beyond |z| = " << t.threshold << "; pooled z " << t.pooledZ << " (limit " << t.pooledThreshold
       << "); " << failed->rejectedSamples << " rejected samples"
       << (failed->note.empty() ? "" : " (" + failed->note + ")") << ". Result with variance: `" << base
       << "-result.exr`, p-values: `" << base << "-pvalues.exr`.\n\n"
       << "| reference | result | difference | significance |\n| --- | --- | --- | --- |\n"
       << "| ![](" << base << "-reference.png) | ![](" << base << "-result.png) | ![](" << base
       << "-difference.png) | ![](" << base << "-significance.png) |\n";
    return md.str();
}

/// What became of the attempts that never reached their test, and where their output is.
std::string problemSection(const CaseResult& r)
{
    std::ostringstream md;
    for (const CaseAttempt& a : r.attempts)
        if (!a.log.empty())
            md << "- seed " << a.seed << ": " << statusName(a.status) << ", " << a.problem << "; output: `" << a.log
               << "`\n";
    const std::string list = md.str();
    return list.empty() ? "" : "\n## " + r.spec.name + ": " + statusName(r.status) + "\n\n" + list;
}

} // namespace

StatusLine statusLine(const CaseResult& r)
{
    const CaseAttempt* a = r.shown();
    return {r.spec.name, r.status, r.duration(), r.message(), a && a->slow};
}

std::string statusCounts(const std::vector<StatusLine>& lines)
{
    std::string text;
    for (CaseStatus status : kStatusOrder) {
        const auto n =
            std::count_if(lines.begin(), lines.end(), [&](const StatusLine& l) { return l.status == status; });
        if (n) text += (text.empty() ? "" : ", ") + std::to_string(n) + " " + statusName(status);
    }
    return text.empty() ? "no cases" : text;
}

size_t unexpectedCount(const std::vector<StatusLine>& lines)
{
    return size_t(std::count_if(lines.begin(), lines.end(), [](const StatusLine& l) { return failsTheRun(l.status); }));
}

Outcome finishRun(const std::vector<StatusLine>& lines, bool interrupted, size_t cases)
{
    std::printf("%s; %zu unexpected", statusCounts(lines).c_str(), unexpectedCount(lines));
    if (interrupted) {
        std::printf(" (interrupted after %zu of %zu cases)\n", lines.size(), cases);
        return Outcome::of(OutcomeKind::Interrupted);
    }
    std::printf("\n");
    return unexpectedCount(lines) ? Outcome::of(OutcomeKind::Failed) : Outcome::passed();
}

std::string resultsCsv(const std::vector<StatusLine>& lines, bool unexpectedOnly)
{
    std::string csv;
    char duration[32];
    for (const StatusLine& l : lines) {
        if (unexpectedOnly && !failsTheRun(l.status)) continue;
        std::snprintf(duration, sizeof duration, "%.3f", l.duration);
        csv += l.name + "," + statusName(l.status) + "," + duration + "\n";
    }
    return csv;
}

std::vector<std::pair<std::string, std::string>> junitProperties(const std::string& injectFault)
{
    if (injectFault.empty()) return {};
    return {{"inject", injectFault}};
}

std::string junitReport(const std::vector<StatusLine>& lines,
                        const std::vector<std::pair<std::string, std::string>>& properties)
{
    std::ostringstream xml;
    size_t failures = 0, errors = 0, skipped = 0;
    double total = 0;
    for (const StatusLine& l : lines) {
        failures += l.status == CaseStatus::Fail || l.status == CaseStatus::UnexpectedPass;
        errors += l.status == CaseStatus::Crash || l.status == CaseStatus::Timeout;
        skipped += l.status == CaseStatus::Skip;
        total += l.duration;
    }
    xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuite name=\"vkrt-regress\" tests=\"" << lines.size()
        << "\" failures=\"" << failures << "\" errors=\"" << errors << "\" skipped=\"" << skipped << "\" time=\""
        << total << "\">\n";
    if (!properties.empty()) {
        xml << "  <properties>\n";
        for (const auto& [name, value] : properties)
            xml << "    <property name=\"" << xmlEscape(name) << "\" value=\"" << xmlEscape(value) << "\"/>\n";
        xml << "  </properties>\n";
    }
    for (const StatusLine& l : lines) {
        xml << "  <testcase classname=\"vkrt.regress\" name=\"" << xmlEscape(l.name) << "\" time=\"" << l.duration
            << "\"";
        const std::string message = xmlEscape(statusName(l.status) + (l.message.empty() ? "" : ": " + l.message));
        if (l.status == CaseStatus::Pass) {
            xml << "/>\n";
            continue;
        }
        xml << ">\n";
        if (l.status == CaseStatus::Fail || l.status == CaseStatus::UnexpectedPass)
            xml << "    <failure message=\"" << message << "\"/>\n";
        else if (l.status == CaseStatus::Crash || l.status == CaseStatus::Timeout)
            xml << "    <error message=\"" << message << "\"/>\n";
        else if (l.status == CaseStatus::Skip) xml << "    <skipped/>\n";
        else xml << "    <system-out>" << message << "</system-out>\n";
        xml << "  </testcase>\n";
    }
    xml << "</testsuite>\n";
    return xml.str();
}

std::string markdownReport(const RegressionSuite& suite, const std::vector<CaseResult>& results, RunStatus status,
                           const RunDescription& run)
{
    std::ostringstream md;
    md << markdownHeader(suite, results, status, run)
       << "| case | status | values passing | pooled z | smallest p | relMSE | rejected | seconds | baseline | ratio "
          "| reference | notes |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    for (const CaseResult& r : results) md << markdownRow(r);
    for (const CaseResult& r : results) md << failureSection(r) << problemSection(r);
    return md.str();
}

std::string ruleDescription(const RegressionSuite& suite)
{
    std::ostringstream rule;
    rule << "at least " << 100.0 * suite.minPass << " % of values pass a Sidak-corrected z-test at alpha "
         << suite.alpha << ", |pooled z| within alpha " << suite.pooledAlpha
         << " (per channel, Sidak over 3), no more rejected (non-finite) samples than the case's max_rejected "
            "(default 0) (docs/regress.md); slow = more than "
         << suite.maxSlowdown << " x baseline";
    return rule.str();
}

std::string tableCell(std::string text)
{
    std::replace(text.begin(), text.end(), '\n', ' ');
    std::replace(text.begin(), text.end(), '|', '/');
    return text;
}

void printResult(const CaseResult& r, size_t done, size_t total)
{
    const CaseAttempt* a = r.shown();
    const int width = int(std::to_string(total).size());
    std::printf("[%*zu/%zu] %-34s %-8s", width, done, total, r.spec.name.c_str(), statusName(r.status).c_str());
    if (a && a->tested())
        std::printf(" %.3f%% pass  pooled z %+.2f  %.2f s%s%s", 100.0 * a->test.fractionPassed(), a->test.pooledZ,
                    a->seconds,
                    a->rejectedSamples ? ("  " + std::to_string(a->rejectedSamples) + " rejected samples").c_str() : "",
                    a->slow ? "  (slower than baseline)" : "");
    std::printf("\n");
    if (!r.message().empty()) std::printf("    %s\n", r.message().c_str());
    std::fflush(stdout);
}

} // namespace vkrt
