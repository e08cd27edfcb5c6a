#include "regress/CompareDrivers.h"

#include "io/AtomicFile.h"
#include "io/ExrFile.h"
#include "regress/AttemptPool.h"
#include "regress/CaseTest.h"
#include "regress/Reports.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

/// One side of a comparison: a driver (empty: the system's) and, for
/// --compare-accel, the traversal backend.
struct ComparedSide {
    fs::path manifest;
    std::optional<AccelChoice> accel;

    std::string describe() const
    {
        std::string text = manifest.empty() ? "the system's driver" : "`" + manifest.string() + "`";
        if (accel) text += ", --accel " + accelChoiceName(*accel);
        return text;
    }
};

/// One case on both sides (two drivers, or two traversal backends).
struct Comparison {
    RegressionCase spec;
    std::optional<CaseAttempt> a, b;
    std::optional<ReferenceTestResult> between; ///< A's image tested against B's, when both rendered
    double identical = NAN;                     ///< the fraction of values bit-for-bit equal in A and B
    bool agree = false;                         ///< `between` passed the suite's rule
    bool slow = false;                          ///< B/A beyond the suite's max_slowdown
    bool final = false;
    CaseStatus status = CaseStatus::Skip;

    /// Render time B/A (warm-up excluded); NaN when a side has no time.
    double ratio() const
    {
        if (!a || !b || !a->tested() || !b->tested() || !(a->seconds > 0)) return NAN;
        return b->seconds / a->seconds;
    }
};

/// The case's status over both drivers: a crash or timeout on either side
/// first, then a failure on either side, images that differ, or (with
/// --fail-on-slowdown) a slowdown.
CaseStatus combinedStatus(const Comparison& c, bool failOnSlowdown)
{
    for (CaseStatus worst : {CaseStatus::Crash, CaseStatus::Timeout})
        if (c.a->status == worst || c.b->status == worst) return worst;
    const bool failed =
        c.a->status != CaseStatus::Pass || c.b->status != CaseStatus::Pass || !c.agree || (failOnSlowdown && c.slow);
    return failed ? CaseStatus::Fail : CaseStatus::Pass;
}

std::string fixed(double value, int decimals)
{
    if (!std::isfinite(value)) return "";
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", decimals, value);
    return text;
}

/// Where two drivers compute alike, the same seed gives the same bits: worth
/// telling apart from "statistically the same" (a change of rounding).
double identicalFraction(const Image& a, const Image& b)
{
    size_t same = 0;
    for (size_t i = 0; i < a.rgb.size() && i < b.rgb.size(); ++i) same += a.rgb[i] == b.rgb[i];
    return a.rgb.empty() ? 1.0 : double(same) / double(a.rgb.size());
}

std::string agreeWord(const Comparison& c) { return c.between ? (c.agree ? "yes" : "no") : "-"; }

std::string sideStatus(const std::optional<CaseAttempt>& side) { return side ? statusName(side->status) : "-"; }

std::string sideMessage(const char* label, const std::optional<CaseAttempt>& side)
{
    if (!side || side->status == CaseStatus::Pass) return "";
    std::string text = std::string(label) + ": " + statusName(side->status);
    if (!side->problem.empty()) text += " (" + side->problem + ")";
    return text;
}

std::string message(const Comparison& c)
{
    std::string text;
    for (const std::string& part : {sideMessage("A", c.a), sideMessage("B", c.b),
                                    std::string(c.between && !c.agree ? "the two images differ" : ""),
                                    std::string(c.slow ? "B slower than max_slowdown x A" : "")})
        if (!part.empty()) text += (text.empty() ? "" : "; ") + part;
    return text;
}

StatusLine statusLineOf(const Comparison& c)
{
    const double duration = (c.a ? c.a->wallSeconds : 0.0) + (c.b ? c.b->wallSeconds : 0.0);
    return {c.spec.name, c.status, duration, message(c), c.slow};
}

/// What each side's children reported about the device they ran on.
struct SideDevices {
    std::string a, b;
};

class DriverComparison {
public:
    DriverComparison(const RegressionSuite& suite, const std::vector<RegressionCase>& cases,
                     const RegressOptions& options, std::array<ComparedSide, 2> sides)
        : m_suite(suite),
          m_options(options),
          m_sides(std::move(sides))
    {
        for (const RegressionCase& c : cases) m_cases.push_back({c});
    }

    void skip(size_t index) { finish(index, CaseStatus::Skip); }

    /// Both drivers' attempts at a case; which runs first alternates from case
    /// to case, so that a drift in the machine's speed favours neither.
    std::vector<AttemptJob> attemptsFor(size_t index) const
    {
        std::vector<AttemptJob> jobs;
        for (int k = 0; k < 2; ++k) {
            const int side = (k + int(index)) % 2;
            const RegressionCase& c = m_cases[index].spec;
            AttemptPlan plan{1, m_options.seedOffset, {}, imagePath(index, side)};
            const ComparedSide& s = m_sides[size_t(side)];
            jobs.push_back({c.name, m_suite.seed + plan.seedOffset, plan, s.manifest.string(), s.accel,
                            side == 0 ? "A" : "B", caseTimeoutSeconds(c, m_options.caseTimeout)});
        }
        return jobs;
    }

    void record(const AttemptJob& job, CaseAttempt attempt)
    {
        const size_t index = indexOf(job.caseName);
        Comparison& c = m_cases[index];
        (job.tag == "A" ? c.a : c.b) = std::move(attempt);
        noteDevice(job.tag, job.tag == "A" ? *c.a : *c.b);
        if (!c.a || !c.b) return;
        testTheImagesAgainstEachOther(index);
        c.slow = c.ratio() > m_suite.maxSlowdown;
        finish(index, combinedStatus(c, m_options.failOnSlowdown));
    }

    Outcome end(bool completed)
    {
        m_interrupted = !completed;
        writeReports();
        return finishRun(finishedLines(), m_interrupted, m_cases.size());
    }

private:
    const RegressionSuite& m_suite;
    const RegressOptions& m_options;
    std::array<ComparedSide, 2> m_sides;
    std::vector<Comparison> m_cases;
    TemporaryFolder m_images;
    SideDevices m_devices;
    size_t m_finished = 0;
    bool m_interrupted = false;

    size_t indexOf(const std::string& name) const
    {
        for (size_t i = 0; i < m_cases.size(); ++i)
            if (m_cases[i].spec.name == name) return i;
        return 0; // never: every job is one of our cases
    }

    fs::path imagePath(size_t index, int side) const
    {
        return m_images.path() / ("case-" + std::to_string(index) + (side == 0 ? "-A.exr" : "-B.exr"));
    }

    void noteDevice(const std::string& tag, const CaseAttempt& attempt)
    {
        std::string& device = tag == "A" ? m_devices.a : m_devices.b;
        if (device.empty() && !attempt.device.empty()) device = attempt.device + " (" + attempt.driver + ")";
    }

    /// A's render against B's, both at the case's spp: the reference test with
    /// B as the reference, so Welch's sum of the two variances (with the
    /// larger one as a floor) and the pooled test per channel.
    void testTheImagesAgainstEachOther(size_t index)
    {
        Comparison& c = m_cases[index];
        if (!fs::exists(imagePath(index, 0)) || !fs::exists(imagePath(index, 1))) return;
        try {
            ExrContents a = readExr(imagePath(index, 0)), b = readExr(imagePath(index, 1));
            Rendered renderedA{a.image, a.layers.at("variance"), c.a->seconds, c.a->rejectedSamples, a.metadata};
            Reference referenceB{b.image, b.layers.at("variance")};
            c.between = testRender(renderedA, c.spec.spp, referenceB, c.spec.spp, m_suite);
            c.identical = identicalFraction(a.image, b.image);
            c.agree = c.between->passedRule(m_suite.minPass);
            if (!c.agree && !m_options.reportDir.empty())
                writeFailureImages(m_options.reportDir, safeName(c.spec.name) + "-A-vs-B", renderedA, referenceB,
                                   *c.between);
        } catch (const std::exception& e) {
            c.a->problem +=
                (c.a->problem.empty() ? "" : "; ") + std::string("its image cannot be compared: ") + e.what();
        }
    }

    void finish(size_t index, CaseStatus status)
    {
        m_cases[index].status = status;
        m_cases[index].final = true;
        printComparison(m_cases[index], ++m_finished);
        writeReports();
    }

    void printComparison(const Comparison& c, size_t done) const
    {
        const int width = int(std::to_string(m_cases.size()).size());
        std::printf("[%*zu/%zu] %-34s %-8s A %-7s B %-7s", width, done, m_cases.size(), c.spec.name.c_str(),
                    statusName(c.status).c_str(), sideStatus(c.a).c_str(), sideStatus(c.b).c_str());
        if (c.between)
            std::printf(" A vs B %.3f%% pass  pooled z %+.2f  %.1f%% identical", 100.0 * c.between->fractionPassed(),
                        c.between->pooledZ, 100.0 * c.identical);
        if (std::isfinite(c.ratio())) std::printf("  %.2f s / %.2f s = %.2f", c.a->seconds, c.b->seconds, c.ratio());
        std::printf("\n");
        if (!message(c).empty()) std::printf("    %s\n", message(c).c_str());
        std::fflush(stdout);
    }

    std::vector<StatusLine> finishedLines() const
    {
        std::vector<StatusLine> lines;
        for (const Comparison& c : m_cases)
            if (c.final) lines.push_back(statusLineOf(c));
        return lines;
    }

    std::string compareCsv() const
    {
        std::string csv = "case,statusA,statusB,agree,secondsA,secondsB,ratio\n";
        for (const Comparison& c : m_cases) {
            if (!c.final) continue;
            const double secondsA = c.a && c.a->tested() ? c.a->seconds : NAN;
            const double secondsB = c.b && c.b->tested() ? c.b->seconds : NAN;
            csv += c.spec.name + "," + sideStatus(c.a) + "," + sideStatus(c.b) + "," + agreeWord(c) + "," +
                   fixed(secondsA, 4) + "," + fixed(secondsB, 4) + "," + fixed(c.ratio(), 3) + "\n";
        }
        return csv;
    }

    std::string markdownRow(const Comparison& c) const
    {
        auto side = [](const std::optional<CaseAttempt>& s) {
            if (!s) return std::string("-");
            if (!s->tested()) return statusName(s->status);
            return statusName(s->status) + ", " + fixed(100.0 * s->test.fractionPassed(), 3) + " %, z " +
                   fixed(s->test.pooledZ, 2);
        };
        std::string status = statusName(c.status);
        if (failsTheRun(c.status)) status = "**" + status + "**";
        return "| " + c.spec.name + " | " + status + (c.slow ? " (slow)" : "") + " | " + side(c.a) + " | " + side(c.b) +
               " | " + (c.between ? fixed(100.0 * c.between->fractionPassed(), 3) + " %" : "-") + " | " +
               (c.between ? fixed(c.between->pooledZ, 2) : "-") + " | " +
               (c.between ? fixed(100.0 * c.identical, 1) + " %" : "-") + " | " +
               (c.a && c.a->tested() ? fixed(c.a->seconds, 2) : "-") + " | " +
               (c.b && c.b->tested() ? fixed(c.b->seconds, 2) : "-") + " | " + fixed(c.ratio(), 2) + " | " +
               tableCell(message(c)) + " |\n";
    }

    std::string imagesSection(const Comparison& c) const
    {
        if (!c.between || c.agree || m_options.reportDir.empty()) return "";
        const std::string base = safeName(c.spec.name) + "-A-vs-B";
        std::ostringstream md;
        md << "\n## " << c.spec.name << ": A and B differ\n\n"
           << c.between->tested - c.between->passed << " of " << c.between->tested
           << " values beyond |z| = " << c.between->threshold << "; pooled z " << c.between->pooledZ << " (limit "
           << c.between->pooledThreshold << ").\n\n| B | A | difference | significance |\n| --- | --- | --- | --- |\n"
           << "| ![](" << base << "-reference.png) | ![](" << base << "-result.png) | ![](" << base
           << "-difference.png) | ![](" << base << "-significance.png) |\n";
        return md.str();
    }

    std::string markdownReport() const
    {
        const std::vector<StatusLine> lines = finishedLines();
        const unsigned jobs = jobsFor(m_options);
        std::ostringstream md;
        md << "# vkrt " << (m_options.compareAccel ? "backend" : "driver") << " comparison\n\n- suite: `"
           << m_suite.path.string() << "`\n"
           << "- A: " << m_sides[0].describe() << ": " << (m_devices.a.empty() ? "device unknown" : m_devices.a)
           << "\n- B: " << m_sides[1].describe() << ": " << (m_devices.b.empty() ? "device unknown" : m_devices.b)
           << "\n- seed: " << m_suite.seed + m_options.seedOffset
           << " (both drivers render the same seed; no re-runs)\n"
           << "- jobs: " << jobs
           << (jobs == 1 ? " (the timed renders ran one at a time; A or B first, alternating from case to case)"
                         : " (**the renders shared the CPU: the times and B/A are distorted**)")
           << "\n- rule: " << ruleDescription(m_suite)
           << "; A vs B: the same test with B's image as the reference at the case's spp; B/A is the render time "
              "(warm-up excluded), slow beyond "
           << m_suite.maxSlowdown << (m_options.failOnSlowdown ? " (fails the case: --fail-on-slowdown)" : "")
           << "\n- result: **" << statusCounts(lines) << "**, " << unexpectedCount(lines) << " unexpected";
        if (lines.size() < m_cases.size())
            md << " (" << lines.size() << " of " << m_cases.size() << " cases"
               << (m_interrupted ? ": **interrupted**" : " so far") << ")";
        md << "\n\n| case | status | A vs reference | B vs reference | A vs B values passing | A vs B pooled z | "
              "identical values | seconds A | seconds B | B/A | notes |\n"
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
        for (const Comparison& c : m_cases)
            if (c.final) md << markdownRow(c);
        for (const Comparison& c : m_cases)
            if (c.final) md << imagesSection(c);
        return md.str();
    }

    void writeReports() const
    {
        const std::vector<StatusLine> lines = finishedLines();
        const fs::path& dir = m_options.reportDir;
        if (!dir.empty()) {
            writeBytesAtomically(dir / "report.md", markdownReport());
            writeBytesAtomically(dir / "results.csv", resultsCsv(lines, false));
            writeBytesAtomically(dir / "failures.csv", resultsCsv(lines, true));
            writeBytesAtomically(dir / "compare.csv", compareCsv());
        }
        if (!m_options.junit.empty())
            writeBytesAtomically(m_options.junit, junitReport(lines, junitProperties(m_options.injectFault)));
    }
};

} // namespace

Outcome compareDrivers(const RegressionSuite& suite, const std::vector<RegressionCase>& cases,
                       const Expectations& expectations, const RegressOptions& options)
{
    std::array<ComparedSide, 2> sides;
    if (options.compareAccel) {
        const fs::path manifest = options.driver.empty() ? fs::path() : checkIcdManifest(options.driver, "--driver");
        sides = {ComparedSide{manifest, AccelChoice::Own}, ComparedSide{manifest, AccelChoice::Driver}};
    } else {
        sides = {ComparedSide{checkIcdManifest(options.compareDrivers.at(0), "--compare-drivers"), std::nullopt},
                 ComparedSide{checkIcdManifest(options.compareDrivers.at(1), "--compare-drivers"), std::nullopt}};
    }
    std::vector<RegressionCase> runnable;
    for (const RegressionCase& c : cases)
        if (!expectations.isSkipped(c.name)) runnable.push_back(c);
    prepareCases(suite, runnable); // every reference is checked before anything renders
    if (!options.reportDir.empty()) createReportDir(options.reportDir);
    const unsigned jobs = jobsFor(options);
    if (jobs > 1)
        std::fprintf(stderr,
                     "vkrt: warning: --jobs %u: the renders share the CPU, so their times and B/A are "
                     "distorted (lavapipe uses every core in each process)\n",
                     jobs);

    InterruptGuard interrupt;
    DriverComparison comparison(suite, cases, options, sides);
    AttemptPool pool(jobs, childCommand(options, false), options.reportDir, nullptr);
    for (size_t i = 0; i < cases.size(); ++i) {
        if (expectations.isSkipped(cases[i].name)) comparison.skip(i);
        else
            for (AttemptJob& job : comparison.attemptsFor(i)) pool.add(std::move(job));
    }
    const bool completed =
        pool.run([&](const AttemptJob& job, CaseAttempt attempt) { comparison.record(job, std::move(attempt)); });
    return comparison.end(completed);
}

} // namespace vkrt
