#include "util/ChildProcess.h"

#include "util/Error.h"

#include <cerrno>
#include <csignal>
#include <cstring>

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

namespace vkrt {

namespace {

ExitStatus exitStatusOf(int status)
{
    if (WIFSIGNALED(status)) return {true, 0, WTERMSIG(status)};
    return {false, WEXITSTATUS(status), 0};
}

/// Between fork and exec only async-signal-safe calls are allowed (the parent
/// may have other threads, e.g. a Vulkan driver's): no allocation, no stdio.
[[noreturn]] void execInChild(char* const* argv, const char* log, pid_t parent)
{
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127); // the parent already died: PDEATHSIG came too late
    int input = open("/dev/null", O_RDONLY);
    int output = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (input < 0 || output < 0) _exit(127);
    dup2(input, STDIN_FILENO);
    dup2(output, STDOUT_FILENO);
    dup2(output, STDERR_FILENO);
    // The default actions: ignored signals stay ignored across exec, and the child must die of SIGINT and SIGTERM.
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) signal(sig, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    execv(argv[0], argv);
    const char* why = "vkrt: cannot execute the child process\n";
    (void)!write(STDERR_FILENO, why, strlen(why));
    _exit(127);
}

} // namespace

std::string signalName(int signal)
{
    if (const char* abbreviation = sigabbrev_np(signal)) return std::string("SIG") + abbreviation;
    return "signal " + std::to_string(signal);
}

std::string ExitStatus::describe() const
{
    return signaled ? "killed by " + signalName(signal) : "exited with status " + std::to_string(code);
}

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log)
{
    std::vector<char*> pointers;
    for (const std::string& a : argv) pointers.push_back(const_cast<char*>(a.c_str()));
    pointers.push_back(nullptr);
    const std::string logPath = log.string();
    const pid_t parent = getpid();
    m_start = std::chrono::steady_clock::now();
    m_pid = fork();
    if (m_pid < 0) throw GpuError("cannot start " + argv.front() + ": fork failed: " + std::strerror(errno));
    if (m_pid == 0) execInChild(pointers.data(), logPath.c_str(), parent);
    setpgid(m_pid, m_pid); // also here, so that a kill right after the start reaches the group
}

ChildProcess::~ChildProcess()
{
    if (!m_exit) kill();
}

std::optional<ExitStatus> ChildProcess::poll()
{
    if (m_exit) return m_exit;
    int status = 0;
    pid_t done = waitpid(m_pid, &status, WNOHANG);
    if (done == m_pid) m_exit = exitStatusOf(status);
    return m_exit;
}

ExitStatus ChildProcess::kill()
{
    if (m_exit) return *m_exit;
    ::kill(-m_pid, SIGKILL);
    ::kill(m_pid, SIGKILL); // should the group not exist yet
    int status = 0;
    while (waitpid(m_pid, &status, 0) < 0 && errno == EINTR) {
    }
    m_exit = exitStatusOf(status);
    return *m_exit;
}

double ChildProcess::seconds() const
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
}

std::filesystem::path currentExecutable()
{
    std::error_code error;
    std::filesystem::path path = std::filesystem::read_symlink("/proc/self/exe", error);
    if (error) throw GpuError("cannot find vkrt's own executable (/proc/self/exe): " + error.message());
    return path;
}

} // namespace vkrt
