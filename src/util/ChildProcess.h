#pragma once
// A child process that a runner can always account for: it runs in its own
// process group (so a timeout kills it together with anything it started),
// its standard output and error go to a log file, it reads /dev/null, and it
// dies with this process (PR_SET_PDEATHSIG), so that no Ctrl-C, SIGTERM or
// crash of the runner leaves a render running in the background.
// Linux only, like the rest of vkrt's process handling.
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

/// How a child ended.
struct ExitStatus {
    bool signaled = false; ///< killed by `signal`, else exited with `code`
    int code = 0;
    int signal = 0;
    /// "exited with status 2", "killed by SIGSEGV".
    std::string describe() const;
};

/// "SIGSEGV", "SIGABRT", ... ("signal 42" for one without a name).
std::string signalName(int signal);

class ChildProcess {
public:
    /// Starts `argv` (argv[0] is the program's path). Throws GpuError naming
    /// the program when the process cannot be made; a program that cannot be
    /// executed exits with status 127 after writing why to the log.
    /// Start children from one thread only: PR_SET_PDEATHSIG fires when the
    /// thread that started the child ends.
    ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log);
    /// Kills a child that still runs, and reaps it.
    ~ChildProcess();
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;

    /// The exit status once the child has ended; never blocks.
    std::optional<ExitStatus> poll();
    /// SIGKILL to the child's process group, then waits for the child.
    ExitStatus kill();
    /// Seconds since the start.
    double seconds() const;

private:
    pid_t m_pid = -1;
    std::chrono::steady_clock::time_point m_start;
    std::optional<ExitStatus> m_exit;
};

/// The running executable's path (/proc/self/exe), to start it again as a child.
std::filesystem::path currentExecutable();

} // namespace vkrt
