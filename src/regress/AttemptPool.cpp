#include "regress/AttemptPool.h"

#include "io/AtomicFile.h"
#include "render/RenderSession.h"
#include "util/Error.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

#include <unistd.h>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

constexpr double kMinimumTimeout = 120.0;         // seconds: no case is cut short below this
constexpr double kBaselineFactor = 30.0;          // x baseline_seconds: room for a loaded machine and --jobs
constexpr double kStartUpPerSession = 60.0;       // seconds: start-up and a cold kernel compile per session
constexpr double kTimeoutWithoutBaseline = 600.0; // seconds: a case that says nothing of its time
constexpr auto kPollInterval = std::chrono::milliseconds(20);
constexpr size_t kLogTailBytes = size_t(1) << 20; // a child's output kept in --report-dir: its last MiB

/// The last `limit` bytes of a file ("" if it cannot be read).
std::string fileTail(const fs::path& path, size_t limit)
{
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in) return "";
    const std::streamoff size = in.tellg();
    const std::streamoff start = std::max<std::streamoff>(0, size - std::streamoff(limit));
    in.seekg(start);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return text;
}

/// The child's last words: its last non-empty line of output, shortened.
std::string lastLine(const std::string& log)
{
    size_t end = log.find_last_not_of(" \t\r\n");
    if (end == std::string::npos) return "";
    const size_t newline = log.rfind('\n', end);
    const size_t begin = newline == std::string::npos ? 0 : newline + 1;
    std::string line = log.substr(begin, end + 1 - begin);
    return line.size() > 300 ? line.substr(0, 300) + "..." : line;
}

std::string withLastWords(std::string what, const std::string& log)
{
    const std::string words = lastLine(log);
    return words.empty() ? what : what + ": " + words;
}

std::optional<CaseAttempt> readReportedAttempt(const fs::path& path, std::string& why)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        why = "without a result";
        return std::nullopt;
    }
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    try {
        return attemptFromJson(text);
    } catch (const InputError& e) {
        why = std::string("with an unreadable result (") + e.what() + ")";
        return std::nullopt;
    }
}

std::string seconds(double value)
{
    std::ostringstream text;
    text << value;
    return text.str();
}

} // namespace

TemporaryFolder::TemporaryFolder()
{
    std::string pattern = (fs::temp_directory_path() / "vkrt-regress-XXXXXX").string();
    if (!mkdtemp(pattern.data()))
        throw InputError("cannot make a folder in " + fs::temp_directory_path().string() +
                         " for the cases' results (set TMPDIR to a writable folder)");
    m_path = pattern;
}

TemporaryFolder::~TemporaryFolder()
{
    std::error_code ignored;
    fs::remove_all(m_path, ignored);
}

std::vector<std::string> childCommand(const RegressOptions& options, bool forwardSlowdown)
{
    std::vector<std::string> argv{currentExecutable().string(),         "regress", "--suite",
                                  fs::absolute(options.suite).string(), "--accel", accelChoiceName(options.accel)};
    if (!options.device.empty()) argv.insert(argv.end(), {"--device", options.device});
    for (const Define& d : options.kernelDefines)
        argv.insert(argv.end(), {"--kernel-define", d.first + "=" + d.second});
    if (forwardSlowdown && options.failOnSlowdown) argv.insert(argv.end(), {"--fail-on-slowdown"});
    return argv;
}

double caseTimeoutSeconds(const RegressionCase& c, std::optional<double> override)
{
    if (override) return *override;
    if (c.baselineSeconds <= 0) return kTimeoutWithoutBaseline;
    return std::max(kMinimumTimeout, kBaselineFactor * c.baselineSeconds) + kStartUpPerSession * c.shards;
}

struct AttemptPool::Running {
    AttemptJob job;
    fs::path result, log;
    std::unique_ptr<ChildProcess> child;
};

AttemptPool::AttemptPool(unsigned jobs, std::vector<std::string> childArguments, fs::path logDir, InProcess inProcess)
    : m_jobs(jobs),
      m_childArguments(std::move(childArguments)),
      m_logDir(std::move(logDir)),
      m_inProcess(std::move(inProcess))
{
    if (m_jobs > 0) m_workDir.emplace();
}

void AttemptPool::add(AttemptJob job) { m_queue.push_back(std::move(job)); }
void AttemptPool::addNext(AttemptJob job) { m_queue.push_front(std::move(job)); }

bool AttemptPool::run(const Done& done) { return m_jobs == 0 ? runHere(done) : runInChildren(done); }

bool AttemptPool::runHere(const Done& done)
{
    while (!m_queue.empty()) {
        if (interrupted()) return false;
        AttemptJob job = std::move(m_queue.front());
        m_queue.pop_front();
        const auto start = std::chrono::steady_clock::now();
        std::optional<CaseAttempt> attempt = m_inProcess(job);
        if (!attempt) return false;
        attempt->wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        done(job, std::move(*attempt));
    }
    return true;
}

bool AttemptPool::runInChildren(const Done& done)
{
    std::vector<Running> running;
    while (!m_queue.empty() || !running.empty()) {
        // Ctrl-C: the children go at once (their partial renders are of no use); the destructors reap them.
        if (interrupted()) return false;
        while (running.size() < m_jobs && !m_queue.empty()) {
            running.push_back(start(std::move(m_queue.front())));
            m_queue.pop_front();
        }
        bool anyFinished = false;
        for (size_t i = 0; i < running.size();) {
            std::optional<CaseAttempt> attempt = finished(running[i]);
            if (!attempt) {
                ++i;
                continue;
            }
            AttemptJob job = std::move(running[i].job);
            running.erase(running.begin() + std::ptrdiff_t(i));
            done(job, std::move(*attempt));
            anyFinished = true;
        }
        if (!anyFinished) std::this_thread::sleep_for(kPollInterval);
    }
    return true;
}

AttemptPool::Running AttemptPool::start(AttemptJob job)
{
    const std::string stem = "attempt-" + std::to_string(++m_started);
    Running r{std::move(job), m_workDir->path() / (stem + ".json"), m_workDir->path() / (stem + ".log"), nullptr};
    const AttemptPlan& plan = r.job.plan;
    std::vector<std::string> argv = m_childArguments;
    argv.insert(argv.end(), {"--run-case", r.job.caseName, "--case-result", r.result.string(), "--attempt",
                             std::to_string(plan.number), "--seed-offset", std::to_string(plan.seedOffset)});
    if (!r.job.driver.empty()) argv.insert(argv.end(), {"--driver", r.job.driver});
    if (r.job.accel) {
        // childCommand gave the run's --accel: this attempt's replaces it.
        auto accel = std::find(argv.begin(), argv.end(), "--accel");
        VKRT_CHECK(accel != argv.end() && accel + 1 != argv.end());
        *(accel + 1) = accelChoiceName(*r.job.accel);
    }
    if (!plan.failureImageDir.empty()) argv.insert(argv.end(), {"--report-dir", plan.failureImageDir.string()});
    if (!plan.imageOut.empty()) argv.insert(argv.end(), {"--case-image", plan.imageOut.string()});
    r.child = std::make_unique<ChildProcess>(argv, r.log);
    return r;
}

std::optional<CaseAttempt> AttemptPool::finished(Running& r)
{
    if (std::optional<ExitStatus> status = r.child->poll()) return collect(r, *status, false);
    if (r.child->seconds() > r.job.timeoutSeconds) return collect(r, r.child->kill(), true);
    return std::nullopt;
}

CaseAttempt AttemptPool::collect(Running& r, const ExitStatus& status, bool timedOut)
{
    std::string why;
    std::optional<CaseAttempt> reported = readReportedAttempt(r.result, why);
    CaseAttempt attempt = reported.value_or(CaseAttempt{});
    attempt.number = r.job.plan.number;
    attempt.seed = r.job.seed;
    attempt.wallSeconds = r.child->seconds();
    const std::string log = fileTail(r.log, kLogTailBytes);
    if (timedOut) {
        attempt.status = CaseStatus::Timeout;
        attempt.problem = "ran past its " + seconds(r.job.timeoutSeconds) + " s timeout and was killed";
    } else if (status.signaled || !reported || status.code != 0) {
        // A process that reported and then crashed (a driver's teardown) crashed all the same.
        const std::string after = reported ? " after reporting " + statusName(reported->status) : " " + why;
        attempt.status = CaseStatus::Crash;
        attempt.problem = withLastWords(status.describe() + after, log);
    }
    attempt.log = keepLog(r, attempt);
    return attempt;
}

/// The output of a child that did not pass for a reason its test does not
/// tell, kept as NAME[-TAG]-attemptK.log in --report-dir.
std::string AttemptPool::keepLog(const Running& r, const CaseAttempt& attempt) const
{
    const bool testSaysWhy =
        attempt.status == CaseStatus::Pass || (attempt.status == CaseStatus::Fail && attempt.problem.empty());
    if (m_logDir.empty() || testSaysWhy) return "";
    const std::string name = safeName(r.job.caseName) + (r.job.tag.empty() ? "" : "-" + r.job.tag) + "-attempt" +
                             std::to_string(r.job.plan.number) + ".log";
    writeBytesAtomically(m_logDir / name, fileTail(r.log, kLogTailBytes));
    return name;
}

} // namespace vkrt
