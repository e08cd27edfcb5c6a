#pragma once
// Runs the attempts of regression cases the way Mesa CI's deqp-runner runs
// tests: each in a child process (vkrt itself, `regress --run-case NAME`),
// up to --jobs at once, each with a timeout. A child that dies of a signal or
// exits without a result is a Crash, one that runs past its time is killed
// with its process group and is a Timeout; the other cases go on. Ctrl-C
// kills the children and keeps what finished. With --jobs 0 the attempts run
// in this process instead, one after the other (for a debugger; no crash or
// timeout protection).
#include "regress/CaseResult.h"
#include "regress/CaseTest.h"
#include "regress/Suite.h"
#include "util/ChildProcess.h"

#include <deque>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

/// The time a case's process may run (docs/regress.md, "Timeouts"):
/// `override` (--case-timeout) when given; else max(120 s, 30 x
/// baseline_seconds) plus 60 s per shard for start-up and kernel compiles (a
/// cold lavapipe compile takes 10-40 s); 600 s for a case without a baseline.
double caseTimeoutSeconds(const RegressionCase& c, std::optional<double> override);


/// The child's command line up to the per-attempt options: this executable,
/// "regress" and the options every attempt of the run shares (--suite,
/// --device, --accel, --kernel-define; --fail-on-slowdown when `forwardSlowdown`).
std::vector<std::string> childCommand(const RegressOptions& options, bool forwardSlowdown);

/// A private folder under TMPDIR (vkrt-regress-XXXXXX) for the files children
/// hand back; removed with everything in it when this object goes.
class TemporaryFolder {
public:
    TemporaryFolder();
    ~TemporaryFolder();
    TemporaryFolder(const TemporaryFolder&) = delete;
    TemporaryFolder& operator=(const TemporaryFolder&) = delete;
    const std::filesystem::path& path() const { return m_path; }

private:
    std::filesystem::path m_path;
};

/// One attempt to make.
struct AttemptJob {
    std::string caseName;
    uint32_t seed = 0;  ///< the render seed, for the report of an attempt that never reported
    AttemptPlan plan;   ///< number, seed offset, image outputs
    std::string driver; ///< the child's --driver (empty: none)
    std::optional<AccelChoice> accel; ///< the child's --accel instead of the run's (--compare-accel)
    std::string tag;    ///< tells apart two attempts of one case in file names ("A", "B"; may be empty)
    double timeoutSeconds = 600.0;
};

class AttemptPool {
public:
    /// Makes an attempt in this process (--jobs 0); nullopt when Ctrl-C stopped it.
    using InProcess = std::function<std::optional<CaseAttempt>(const AttemptJob&)>;
    /// Called with every finished attempt, in the order they finish; may add jobs.
    using Done = std::function<void(const AttemptJob&, CaseAttempt)>;

    /// `childArguments`: the child's command line up to the per-attempt options
    /// (the executable, "regress", and the options every attempt shares).
    /// `logDir`: where the output of children that did not pass is kept (empty: nowhere).
    AttemptPool(unsigned jobs, std::vector<std::string> childArguments, std::filesystem::path logDir,
                InProcess inProcess);
    AttemptPool(const AttemptPool&) = delete;
    AttemptPool& operator=(const AttemptPool&) = delete;

    void add(AttemptJob job);     ///< after the queued ones
    void addNext(AttemptJob job); ///< before them: a re-run, so that its case finishes soon

    /// Runs every queued job and those `done` adds; false when Ctrl-C stopped
    /// it (the children are killed; the attempts that finished were reported).
    bool run(const Done& done);

private:
    struct Running;

    unsigned m_jobs;
    std::vector<std::string> m_childArguments;
    std::filesystem::path m_logDir;
    InProcess m_inProcess;
    std::deque<AttemptJob> m_queue;
    std::optional<TemporaryFolder> m_workDir; ///< the children's results and logs
    size_t m_started = 0;

    bool runHere(const Done& done);
    bool runInChildren(const Done& done);
    Running start(AttemptJob job);
    std::optional<CaseAttempt> finished(Running& running);
    CaseAttempt collect(Running& running, const ExitStatus& status, bool timedOut);
    std::string keepLog(const Running& running, const CaseAttempt& attempt) const;
};

} // namespace vkrt
