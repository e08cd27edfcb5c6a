#include "util/Signals.h"

#include "util/Error.h"

#include <array>
#include <climits>
#include <csignal>
#include <cstring>
#include <mutex>

#include <unistd.h>

namespace vkrt {

namespace {

static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "signal handlers may only touch lock-free atomics");

// ---------------------------------------------------------------- state the handlers read

std::atomic<int> g_interruptedExitCode{SignalExitCodes{}.interrupted};
std::atomic<int> g_driverCrashedExitCode{SignalExitCodes{}.driverCrashed};

/// One registered temporary: `armed` is set only once `path` is complete, so
/// a handler never reads a half-copied path.
struct TemporarySlot {
    std::atomic<bool> taken{false};
    std::atomic<bool> armed{false};
    char path[PATH_MAX] = {};
};
constexpr int kTemporarySlots = 32; // vkrt writes one output at a time; regress a few
std::array<TemporarySlot, kTemporarySlots> g_temporaries;

std::atomic<bool> g_stopRequested{false};
std::atomic<int> g_interruptsSeen{0};
std::atomic<const char*> g_driverActivity{nullptr};

// ---------------------------------------------------------------- async-signal-safe helpers

void writeToStderr(const char* text) noexcept
{
    size_t length = std::strlen(text);
    while (length > 0) {
        ssize_t n = ::write(STDERR_FILENO, text, length);
        if (n <= 0) return; // nothing better to do inside a handler
        text += n;
        length -= size_t(n);
    }
}

void removeTemporaries() noexcept
{
    for (TemporarySlot& slot : g_temporaries)
        if (slot.armed.load()) ::unlink(slot.path);
}

const char* signalName(int signal) noexcept
{
    switch (signal) {
    case SIGSEGV: return "SIGSEGV";
    case SIGBUS: return "SIGBUS";
    case SIGILL: return "SIGILL";
    case SIGFPE: return "SIGFPE";
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    }
    return "a signal";
}

/// Dies of `signal` with its default action, so the parent sees what killed us.
[[noreturn]] void dieOf(int signal) noexcept
{
    std::signal(signal, SIG_DFL);
    sigset_t unblock;
    sigemptyset(&unblock);
    sigaddset(&unblock, signal);
    sigprocmask(SIG_UNBLOCK, &unblock, nullptr);
    ::raise(signal);
    _exit(128 + signal); // only if the default action did not end the process
}

// ---------------------------------------------------------------- handlers

extern "C" void onTerminatingSignal(int signal)
{
    removeTemporaries();
    dieOf(signal);
}

extern "C" void onInterruptRequest(int)
{
    if (g_interruptsSeen.fetch_add(1) == 0) {
        g_stopRequested.store(true);
        // Said because the stop waits for the GPU (or a hung driver): the user learns the way out.
        writeToStderr("\nvkrt: interrupted: stopping after the current frames (Ctrl-C again to stop at once)\n");
        return;
    }
    writeToStderr("\nvkrt: interrupted again: stopping at once\n");
    removeTemporaries();
    _exit(g_interruptedExitCode.load());
}

extern "C" void onDriverCrash(int signal)
{
    const char* activity = g_driverActivity.load();
    writeToStderr("vkrt: the Vulkan driver crashed (");
    writeToStderr(signalName(signal));
    writeToStderr(") while ");
    writeToStderr(activity ? activity : "using the GPU");
    writeToStderr("\n");
    removeTemporaries();
    _exit(g_driverCrashedExitCode.load());
}

// ---------------------------------------------------------------- installation

struct sigaction actionFor(void (*handler)(int), int flags = 0)
{
    struct sigaction action {};
    action.sa_handler = handler;
    sigemptyset(&action.sa_mask);
    action.sa_flags = flags;
    return action;
}

/// Installs `handler` for `signal` only over the default action: an ignored
/// signal (nohup, a shell's background job) was the parent's wish, and a
/// handler someone installed before us is theirs.
void installOverDefault(int signal, void (*handler)(int))
{
    struct sigaction previous {};
    if (sigaction(signal, nullptr, &previous) != 0 || (previous.sa_flags & SA_SIGINFO) ||
        previous.sa_handler != SIG_DFL)
        return;
    struct sigaction action = actionFor(handler);
    sigaction(signal, &action, nullptr);
}

/// A stack for the crash handler, so that a driver overflowing its stack is reported too.
void useAlternateSignalStack()
{
    static std::array<char, 64 * 1024> stack;
    stack_t alternate{};
    alternate.ss_sp = stack.data();
    alternate.ss_size = stack.size();
    sigaltstack(&alternate, nullptr);
}

constexpr int kCrashSignals[] = {SIGSEGV, SIGBUS, SIGILL, SIGFPE};
struct sigaction g_crashActionsBefore[std::size(kCrashSignals)];
int g_crashGuardDepth = 0; // only the arming thread touches it

} // namespace

void installSignalHandlers(const SignalExitCodes& codes)
{
    g_interruptedExitCode.store(codes.interrupted);
    g_driverCrashedExitCode.store(codes.driverCrashed);
    installSignalHandlers();
}

void installSignalHandlers()
{
    static std::once_flag once;
    std::call_once(once, [] {
        for (int signal : {SIGINT, SIGTERM, SIGHUP}) installOverDefault(signal, onTerminatingSignal);
        useAlternateSignalStack();
    });
}

// ---------------------------------------------------------------- TemporaryFileGuard

TemporaryFileGuard::TemporaryFileGuard(const std::filesystem::path& path)
{
    installSignalHandlers();
    const std::string absolute = std::filesystem::absolute(path).string();
    if (absolute.size() >= PATH_MAX) throw InputError(path.string() + ": path too long to write");
    for (int i = 0; i < kTemporarySlots && m_slot < 0; ++i) {
        bool expected = false;
        if (g_temporaries[size_t(i)].taken.compare_exchange_strong(expected, true)) m_slot = i;
    }
    if (m_slot < 0) throw InputError(path.string() + ": too many outputs written at once");
    TemporarySlot& slot = g_temporaries[size_t(m_slot)];
    std::memcpy(slot.path, absolute.c_str(), absolute.size() + 1);
    slot.armed.store(true);
}

TemporaryFileGuard::~TemporaryFileGuard()
{
    TemporarySlot& slot = g_temporaries[size_t(m_slot)];
    slot.armed.store(false);
    slot.taken.store(false);
}

// ---------------------------------------------------------------- StopOnInterrupt

namespace {
struct sigaction g_interruptActionBefore {};
int g_stopScopes = 0; // nested scopes share the outermost one's handler
} // namespace

StopOnInterrupt::StopOnInterrupt()
{
    installSignalHandlers();
    g_stopRequested.store(false);
    g_interruptsSeen.store(0);
    if (g_stopScopes++ > 0) return;
    struct sigaction action = actionFor(onInterruptRequest);
    sigaction(SIGINT, &action, &g_interruptActionBefore);
}

StopOnInterrupt::~StopOnInterrupt()
{
    if (--g_stopScopes == 0) sigaction(SIGINT, &g_interruptActionBefore, nullptr);
}

const std::atomic<bool>& StopOnInterrupt::stopRequested() { return g_stopRequested; }

// ---------------------------------------------------------------- DriverCrashGuard

DriverCrashGuard::DriverCrashGuard(const char* activity) : m_previousActivity(g_driverActivity.load())
{
    installSignalHandlers();
    g_driverActivity.store(activity);
    if (g_crashGuardDepth++ > 0) return;
    struct sigaction action = actionFor(onDriverCrash, SA_ONSTACK);
    for (size_t i = 0; i < std::size(kCrashSignals); ++i)
        sigaction(kCrashSignals[i], &action, &g_crashActionsBefore[i]);
}

DriverCrashGuard::~DriverCrashGuard()
{
    g_driverActivity.store(m_previousActivity);
    if (--g_crashGuardDepth > 0) return;
    for (size_t i = 0; i < std::size(kCrashSignals); ++i)
        sigaction(kCrashSignals[i], &g_crashActionsBefore[i], nullptr);
}

} // namespace vkrt
