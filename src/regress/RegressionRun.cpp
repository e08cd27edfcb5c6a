#include "regress/RegressionRun.h"

#include "io/AtomicFile.h"
#include "io/ExrFile.h"
#include "io/OutputPaths.h"
#include "regress/AttemptPool.h"
#include "regress/CaseTest.h"
#include "regress/CompareDrivers.h"
#include "regress/Expectations.h"
#include "regress/Reports.h"
#include "regress/Suite.h"
#include "render/RenderSession.h"
#include "scene/SceneInputs.h"
#include "util/ChildProcess.h"
#include "util/Error.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <unistd.h>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

constexpr uint32_t kReferenceSeed = 0x5eed5eed; // never a test seed

void writeText(const fs::path& path, const std::string& text)
{
    writeBytesAtomically(path, text); // every write checked: an unchecked ofstream's last flush can fail silently
}

// ---------------------------------------------------------------- --update

/// First line of a git command's output in `dir`, or nullopt.
std::optional<std::string> gitLine(const fs::path& dir, const std::string& arguments)
{
    std::string command = "git -C '" + dir.string() + "' " + arguments + " 2>/dev/null";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return std::nullopt;
    char buffer[4096] = {};
    size_t n = fread(buffer, 1, sizeof buffer - 1, pipe);
    int status = pclose(pipe);
    std::string line(buffer, n);
    line = line.substr(0, line.find('\n'));
    if (status != 0 || line.empty()) return std::nullopt;
    return line;
}

/// "commit abc… " plus a warning when shaders or sources differ from it.
std::string commitDescription(const fs::path& dir)
{
    std::optional<std::string> commit = gitLine(dir, "rev-parse HEAD");
    if (!commit) return "commit unknown";
    std::optional<std::string> dirty = gitLine(dir, "status --porcelain -- shaders src");
    return "commit " + *commit + (dirty ? " with uncommitted changes in shaders/ or src/" : "");
}

/// The path relative to the git checkout holding it, else absolute.
std::string repositoryPath(const fs::path& file)
{
    fs::path absolute = fs::weakly_canonical(file);
    std::optional<std::string> top = gitLine(absolute.parent_path(), "rev-parse --show-toplevel");
    fs::path relative = top ? absolute.lexically_relative(fs::path(*top)) : fs::path();
    bool inside = !relative.empty() && *relative.begin() != "..";
    return inside ? relative.string() : absolute.string();
}

void writeReferenceReadme(const VulkanContext& context, const RegressionSuite& suite, const RegressionCase& c,
                          const Scene& scene, double seconds)
{
    std::time_t now = std::time(nullptr);
    char date[64];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    std::ostringstream readme;
    readme << "# vkrt reference: " << c.name << "\n\n| | |\n|---|---|\n| scene | `" << repositoryPath(c.scene)
           << "` |\n| command | `vkrt regress --update --suite " << repositoryPath(suite.path) << " --filter " << c.name
           << "` |\n| vkrt | " << VKRT_VERSION << ", " << commitDescription(c.scene.parent_path()) << " |\n| device | "
           << context.deviceInfo().name << " (" << context.deviceInfo().driver << ") |\n| image | "
           << scene.camera.width << " x " << scene.camera.height << " |\n| spp | " << c.referenceSpp << " (seed "
           << kReferenceSeed << ") |\n| date | " << date << " |\n| render time | " << std::lround(seconds)
           << " s |\n\n`mean.exr` is the per-pixel mean, `variance.exr` the variance of that mean (sample variance / "
              "spp).\n";
    writeText(c.referenceDir / "README.md", readme.str());
}

/// Renders one vkrt reference; false when Ctrl-C stopped it (nothing written).
bool updateReference(const VulkanContext& context, const RegressionSuite& suite, const RegressionCase& c,
                     const RegressOptions& options)
{
    std::printf("updating %s: %llu spp ...\n", c.name.c_str(), static_cast<unsigned long long>(c.referenceSpp));
    std::fflush(stdout);
    Scene scene = caseScene(suite, c);
    auto start = std::chrono::steady_clock::now();
    std::optional<Rendered> r = renderCase(context, scene, uint32_t(c.referenceSpp), kReferenceSeed, options);
    if (!r) return false;
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (r->rejectedSamples)
        std::printf("warning: %s: %llu non-finite samples were rejected\n", c.name.c_str(),
                    static_cast<unsigned long long>(r->rejectedSamples));
    fs::create_directories(c.referenceDir);
    writeExr(c.referenceDir / "mean.exr", r->mean, r->metadata);
    writeExr(c.referenceDir / "variance.exr", r->variance, r->metadata);
    writeReferenceReadme(context, suite, c, scene, seconds);
    std::printf("updated %s (%.1f s)\n", c.referenceDir.c_str(), seconds);
    return true;
}

/// The files --update writes for a case: none may be one its scene reads
/// (a texture kept in the reference's own folder), nor the scene or suite.
void refuseReferencesThatAreInputs(const RegressionSuite& suite, const RegressionCase& c)
{
    const Scene scene = caseScene(suite, c);
    std::vector<NamedFile> inputs = filesTheSceneRead(scene);
    inputs.push_back({"the scene file of case " + c.name, c.scene});
    inputs.push_back({"the suite file", suite.path});
    const std::string role = "the reference of case " + c.name;
    refuseOverlappingFiles(inputs, {{role + " (mean)", c.referenceDir / "mean.exr"},
                                    {role + " (variance)", c.referenceDir / "variance.exr"},
                                    {role + " (its README)", c.referenceDir / "README.md"}});
}

Outcome updateReferences(const VulkanContext& context, const RegressionSuite& suite,
                         const std::vector<RegressionCase>& cases, const RegressOptions& options)
{
    // Every case is checked before the first is rendered: a refusal leaves every reference as it was.
    for (const RegressionCase& c : cases)
        if (c.source != ReferenceSource::Mitsuba) refuseReferencesThatAreInputs(suite, c);
    std::set<fs::path> updated;
    for (const RegressionCase& c : cases) {
        if (c.source == ReferenceSource::Mitsuba) {
            std::printf("kept %s (made by Mitsuba 3: tools/make_reference.py)\n", c.name.c_str());
            continue;
        }
        if (!updated.insert(c.referenceDir).second) {
            std::printf("kept %s (its reference %s was just updated by another case)\n", c.name.c_str(),
                        c.referenceDir.c_str());
            continue;
        }
        if (interrupted() || !updateReference(context, suite, c, options)) {
            std::printf("interrupted: %s and later references not updated\n", c.name.c_str());
            return Outcome::of(OutcomeKind::Interrupted);
        }
    }
    return Outcome::passed();
}

// ---------------------------------------------------------------- set-up

std::vector<RegressionCase> selectedCases(const RegressionSuite& suite, const std::vector<std::string>& filters)
{
    std::vector<RegressionCase> cases;
    auto matches = [&](const std::string& name) {
        return filters.empty() || std::any_of(filters.begin(), filters.end(),
                                              [&](const std::string& f) { return name.find(f) != std::string::npos; });
    };
    for (const auto& c : suite.cases)
        if (matches(c.name)) cases.push_back(c);
    if (cases.empty()) {
        std::string list;
        for (const auto& f : filters) list += (list.empty() ? "" : ", ") + f;
        throw InputError("--filter " + list + ": no case of " + suite.path.string() + " matches");
    }
    return cases;
}

/// The value of the first "key": "value" pair in JSON text ("" if absent).
std::string jsonString(const std::string& text, const std::string& key)
{
    size_t at = text.find("\"" + key + "\"");
    if (at == std::string::npos) return "";
    size_t colon = text.find(':', at), open = text.find('"', colon == std::string::npos ? at : colon);
    size_t close = open == std::string::npos ? open : text.find('"', open + 1);
    return close == std::string::npos ? "" : text.substr(open + 1, close - open - 1);
}

std::unique_ptr<VulkanContext> openContext(const RegressOptions& options)
{
    try {
        return std::make_unique<VulkanContext>(ContextOptions{options.device, false, std::nullopt});
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        if (options.driver.empty()) throw;
        throw GpuError("--driver " + options.driver + ": the Vulkan loader could not use this driver (" + e.what() +
                       "); is its library_path loadable, and does it list a device?");
    }
}

// ---------------------------------------------------------------- the suite

/// The run in progress: every case's result once it is final, in the suite's
/// order, and the reports rewritten after each (an interrupted run keeps what finished).
class SuiteRun {
public:
    SuiteRun(const RegressionSuite& suite, const std::vector<RegressionCase>& cases, const Expectations& expectations,
             const RegressOptions& options, RunDescription description)
        : m_suite(suite),
          m_expectations(expectations),
          m_options(options),
          m_description(std::move(description))
    {
        for (const RegressionCase& c : cases) m_results.push_back({c, {}, CaseStatus::Skip});
        for (size_t i = 0; i < cases.size(); ++i) m_index[cases[i].name] = i;
        m_final.assign(cases.size(), false);
    }

    /// Skipped cases are final at once.
    void skip(size_t index) { finish(index, CaseStatus::Skip); }

    /// The first attempt of a case that is not skipped.
    AttemptJob firstJob(size_t index) const
    {
        const RegressionCase& c = m_results[index].spec;
        AttemptPlan plan{1, m_options.seedOffset, m_options.reportDir, {}};
        return {c.name, m_suite.seed + plan.seedOffset, plan, m_options.driver, std::nullopt, "", timeoutFor(c)};
    }

    /// Records an attempt; returns the re-run to make, if the case needs one.
    std::optional<AttemptJob> record(const AttemptJob& job, CaseAttempt attempt)
    {
        const size_t index = m_index.at(job.caseName);
        CaseResult& r = m_results[index];
        r.attempts.push_back(std::move(attempt));
        if (r.attempts.size() == 1 && needsRetry(r.spec.name, r.attempts.front().status, m_expectations))
            return retryJob(job, r.attempts.front());
        std::vector<CaseStatus> statuses;
        for (const CaseAttempt& a : r.attempts) statuses.push_back(a.status);
        finish(index, caseStatus(r.spec.name, statuses, m_expectations));
        return std::nullopt;
    }

    /// Passed, Failed when a case fails the run, Interrupted when it was stopped.
    Outcome end(bool completed)
    {
        m_interrupted = !completed;
        writeReports();
        return finishRun(finishedLines(), m_interrupted, m_results.size());
    }

private:
    const RegressionSuite& m_suite;
    const Expectations& m_expectations;
    const RegressOptions& m_options;
    RunDescription m_description;
    std::vector<CaseResult> m_results;
    std::vector<bool> m_final;
    std::map<std::string, size_t> m_index;
    size_t m_finished = 0;
    bool m_interrupted = false;

    double timeoutFor(const RegressionCase& c) const { return caseTimeoutSeconds(c, m_options.caseTimeout); }

    /// A fresh seed; the failure images only if the first attempt wrote none.
    AttemptJob retryJob(const AttemptJob& first, const CaseAttempt& firstAttempt) const
    {
        AttemptJob job = first;
        job.plan.number = 2;
        job.plan.seedOffset = m_options.seedOffset + kRetrySeedShift;
        job.seed = m_suite.seed + job.plan.seedOffset;
        if (firstAttempt.wroteImages) job.plan.failureImageDir.clear();
        return job;
    }

    void finish(size_t index, CaseStatus status)
    {
        m_results[index].status = status;
        m_final[index] = true;
        printResult(m_results[index], ++m_finished, m_results.size());
        writeReports();
    }

    std::vector<CaseResult> finishedResults() const
    {
        std::vector<CaseResult> finished;
        for (size_t i = 0; i < m_results.size(); ++i)
            if (m_final[i]) finished.push_back(m_results[i]);
        return finished;
    }

    std::vector<StatusLine> finishedLines() const
    {
        std::vector<StatusLine> lines;
        for (const CaseResult& r : finishedResults()) lines.push_back(statusLine(r));
        return lines;
    }

    void writeReports() const
    {
        const std::vector<CaseResult> finished = finishedResults();
        const std::vector<StatusLine> lines = finishedLines();
        const fs::path& dir = m_options.reportDir;
        if (!dir.empty()) {
            writeText(dir / "report.md",
                      markdownReport(m_suite, finished, {m_results.size(), m_interrupted}, m_description));
            writeText(dir / "results.csv", resultsCsv(lines, false));
            writeText(dir / "failures.csv", resultsCsv(lines, true));
        }
        if (!m_options.junit.empty())
            writeText(m_options.junit, junitReport(lines, junitProperties(m_options.injectFault)));
    }
};

RunDescription describeRun(const VulkanContext& context, const RegressionSuite& suite, const Expectations& expectations,
                           const RegressOptions& options)
{
    RunDescription run;
    run.device = context.deviceInfo().name + " (" + context.deviceInfo().driver + ")";
    run.driverManifest = options.driver;
    run.seed = suite.seed + options.seedOffset;
    run.retrySeed = suite.seed + options.seedOffset + kRetrySeedShift;
    run.jobs = jobsFor(options);
    run.accel = accelChoiceName(options.accel);
    run.kernelDefines = options.kernelDefines;
    run.injectFault = options.injectFault;
    run.baseline = options.baseline;
    run.flakes = options.flakes;
    run.skips = options.skips;
    run.expectations = &expectations;
    return run;
}

Outcome runSuite(const VulkanContext& context, const RegressionSuite& suite, const std::vector<RegressionCase>& cases,
                 const std::vector<PreparedCase>& prepared, const Expectations& expectations,
                 const RegressOptions& options)
{
    SuiteRun run(suite, cases, expectations, options, describeRun(context, suite, expectations, options));
    auto inProcess = [&](const AttemptJob& job) {
        auto pc = std::find_if(prepared.begin(), prepared.end(),
                               [&](const PreparedCase& p) { return p.spec.name == job.caseName; });
        return runAttempt(context, suite, *pc, options, job.plan);
    };
    AttemptPool pool(jobsFor(options), childCommand(options, true), options.reportDir, inProcess);
    for (size_t i = 0; i < cases.size(); ++i) {
        if (expectations.isSkipped(cases[i].name)) run.skip(i);
        else pool.add(run.firstJob(i));
    }
    const bool completed = pool.run([&](const AttemptJob& job, CaseAttempt attempt) {
        if (std::optional<AttemptJob> retry = run.record(job, std::move(attempt))) pool.addNext(std::move(*retry));
    });
    return run.end(completed);
}

// ---------------------------------------------------------------- the child process

const RegressionCase& caseNamed(const RegressionSuite& suite, const std::string& name)
{
    auto it =
        std::find_if(suite.cases.begin(), suite.cases.end(), [&](const RegressionCase& c) { return c.name == name; });
    if (it == suite.cases.end()) throw InputError("--run-case " + name + ": no such case in " + suite.path.string());
    return *it;
}

/// The child's attempt (--run-case): the parent reads what this writes. An
/// error becomes a Fail that says what; only Ctrl-C or death write nothing.
Outcome runCaseForParent(const RegressOptions& options)
{
    if (options.caseResult.empty()) throw InputError("--run-case " + *options.runCase + " needs --case-result FILE");
    const RegressionSuite suite = readRegressionSuite(options.suite);
    const RegressionCase& c = caseNamed(suite, *options.runCase);
    const AttemptPlan plan{options.attempt, options.seedOffset, options.reportDir, options.caseImage};
    CaseAttempt attempt;
    attempt.number = plan.number;
    attempt.seed = suite.seed + plan.seedOffset;
    try {
        if (!options.driver.empty()) selectVulkanDriver(options.driver);
        const PreparedCase prepared = std::move(prepareCases(suite, {c}).front());
        InterruptGuard interrupt;
        std::unique_ptr<VulkanContext> context = openContext(options);
        std::optional<CaseAttempt> made = runAttempt(*context, suite, prepared, options, plan);
        if (!made) return Outcome::of(OutcomeKind::Interrupted);
        attempt = std::move(*made);
    } catch (const std::exception& e) {
        attempt.status = CaseStatus::Fail;
        attempt.problem = e.what();
    }
    writeText(options.caseResult, attemptToJson(attempt));
    return Outcome::passed();
}

// ---------------------------------------------------------------- checks

/// Combinations that cannot mean anything, refused before any work.
void refuseContradictions(const RegressOptions& options)
{
    if (options.update && !options.kernelDefines.empty())
        throw InputError(
            "--update cannot be combined with --kernel-define: references must come from unmodified kernels");
    if (options.update && !options.injectFault.empty())
        throw InputError("--update cannot be combined with --inject: references must come from unmodified kernels");
    const bool expectations = !options.baseline.empty() || !options.flakes.empty() || !options.skips.empty();
    if (options.update && expectations)
        throw InputError("--update renders the references of the --filter'ed cases; it takes no --baseline, "
                         "--flakes or --skips");
    if (!options.compares()) return;
    const std::string option = options.compareAccel ? "--compare-accel" : "--compare-drivers";
    if (options.compareAccel && !options.compareDrivers.empty())
        throw InputError("--compare-accel and --compare-drivers: compare one pair at a time");
    if (options.update) throw InputError(option + " cannot be combined with --update");
    if (!options.compareDrivers.empty() && !options.driver.empty())
        throw InputError("--compare-drivers names both drivers; it cannot be combined with --driver");
    if (!options.baseline.empty() || !options.flakes.empty())
        throw InputError(option + " tests two configurations against each other; --baseline and --flakes describe "
                                  "one run (--skips is allowed)");
    if (options.jobs == 0u) throw InputError("--jobs 0: " + option + " runs each side in processes of its own");
}

/// Prints a warning for each baseline line that names no case of the suite.
void warnAboutUnknownBaselineCases(const RegressionSuite& suite, const Expectations& expectations)
{
    std::vector<std::string> names;
    for (const RegressionCase& c : suite.cases) names.push_back(c.name);
    for (const std::string& warning : baselineLinesNamingNoCase(expectations, names))
        std::fprintf(stderr, "vkrt: warning: %s\n", warning.c_str());
}

std::vector<RegressionCase> casesToRun(const std::vector<RegressionCase>& cases, const Expectations& expectations)
{
    std::vector<RegressionCase> run;
    for (const RegressionCase& c : cases)
        if (!expectations.isSkipped(c.name)) run.push_back(c);
    return run;
}

} // namespace

unsigned jobsFor(const RegressOptions& options)
{
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    // More children than cores only share them (--jobs 10000 started every case at once).
    if (options.jobs) return std::min(*options.jobs, cores);
    if (options.failOnSlowdown || options.compares()) return 1;
    return cores;
}

void createReportDir(const fs::path& dir)
{
    std::error_code error;
    fs::create_directories(dir, error);
    if (error || !fs::is_directory(dir))
        throw InputError("--report-dir " + dir.string() + ": cannot create it (" +
                         (error ? error.message() : "not a directory") + ")");
}

fs::path checkIcdManifest(const fs::path& icdManifest, const std::string& option)
{
    const std::string named = option + " " + icdManifest.string();
    fs::path path = fs::absolute(icdManifest);
    if (!fs::is_regular_file(path)) throw InputError(named + ": no such file");
    std::ifstream in(path);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) throw InputError(named + ": cannot read it");
    if (text.find("\"ICD\"") == std::string::npos)
        throw InputError(named + ": not a Vulkan ICD manifest (no \"ICD\" object)");
    std::string library = jsonString(text, "library_path");
    if (library.empty()) throw InputError(named + ": the ICD manifest has no \"library_path\"");
    // A bare file name is looked up by the dynamic linker; a path is relative to the manifest.
    fs::path libraryPath =
        (fs::path(library).is_absolute() ? fs::path(library) : path.parent_path() / library).lexically_normal();
    if (library.find('/') != std::string::npos && !fs::exists(libraryPath))
        throw InputError(named + ": its library_path " + libraryPath.string() + " does not exist");
    return path;
}

void selectVulkanDriver(const fs::path& icdManifest)
{
    const fs::path path = checkIcdManifest(icdManifest, "--driver");
    setenv("VK_DRIVER_FILES", path.c_str(), 1);
    setenv("VK_ICD_FILENAMES", path.c_str(), 1); // older loaders
}

/// Seconds `vkrt devices` may take to open a driver before the run calls it hung.
constexpr double kDriverProbeSeconds = 60.0;

/// A driver under test is first opened in a child (`vkrt devices`) under a
/// deadline, as every case is: an ICD manifest naming the Vulkan loader
/// itself hung the parent in vkCreateInstance, with no timeout. A child that
/// hangs or crashes fails the run as a device failure; one that ends, well or
/// not, has shown that opening the driver returns, and the parent opens it
/// (its own message names what the loader could not use).
void proveDriverInChild(const RegressOptions& options)
{
    const double limit = std::min(options.caseTimeout.value_or(kDriverProbeSeconds), kDriverProbeSeconds);
    const fs::path log = fs::temp_directory_path() / ("vkrt-driver-probe-" + std::to_string(getpid()) + ".log");
    std::optional<ExitStatus> status;
    {
        ChildProcess child({currentExecutable().string(), "devices"}, log);
        while (!(status = child.poll()) && child.seconds() < limit)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        if (!status) child.kill();
    }
    std::error_code ignored;
    fs::remove(log, ignored);
    const std::string named = "--driver " + options.driver;
    if (!status)
        throw GpuError(named + ": opening the driver did not return within " + std::to_string(int(limit)) +
                       " s (`vkrt devices` in a child hung; the run's process never opens it)");
    if (status->signaled)
        throw GpuError(named + ": opening the driver crashed (`vkrt devices` in a child was " + status->describe() +
                       ")");
}

Outcome runRegression(const RegressOptions& options)
{
    if (options.runCase) return runCaseForParent(options);
    RegressionSuite suite = readRegressionSuite(options.suite);
    refuseContradictions(options);
    const std::vector<RegressionCase> cases = selectedCases(suite, options.filters);
    const Expectations expectations = readExpectations(options.baseline, options.flakes, options.skips);
    warnAboutUnknownBaselineCases(suite, expectations);
    if (options.compares()) return compareDrivers(suite, cases, expectations, options);
    if (!options.driver.empty()) {
        selectVulkanDriver(options.driver);
        proveDriverInChild(options);
    }
    std::vector<PreparedCase> prepared;
    if (!options.update) prepared = prepareCases(suite, casesToRun(cases, expectations));
    if (!options.reportDir.empty()) createReportDir(options.reportDir);

    InterruptGuard interrupt;
    std::unique_ptr<VulkanContext> context = openContext(options);
    if (options.update) return updateReferences(*context, suite, cases, options);
    return runSuite(*context, suite, cases, prepared, expectations, options);
}

} // namespace vkrt
