#pragma once
// Process-wide signal handling, so that no signal leaves a mess or a mystery:
// temporary outputs are removed on SIGINT, SIGTERM and SIGHUP; Ctrl-C asks a
// render to stop and a second Ctrl-C ends the process at once; a Vulkan
// driver that crashes is named as the culprit instead of a bare "Segmentation
// fault". Every handler uses only async-signal-safe calls (write, unlink,
// _exit, raise) on data prepared before the signal.
#include <atomic>
#include <filesystem>

namespace vkrt {

/// The statuses the handlers exit with; src/app/ decides them (Commands.h).
struct SignalExitCodes {
    int interrupted = 130;  ///< a second Ctrl-C
    int driverCrashed = 70; ///< a crash inside a DriverCrashGuard
};

/// Installs the SIGINT/SIGTERM/SIGHUP handlers that remove registered
/// temporaries and then die of the signal as before. Only signals with the
/// default action get them: one the parent set to be ignored (nohup, a
/// background job's SIGINT) stays ignored, and a handler installed earlier
/// stays. Idempotent; the classes below call it themselves, main() calls it
/// first to set the codes.
void installSignalHandlers(const SignalExitCodes& codes);
void installSignalHandlers();

/// Registers a temporary file for removal should a signal end the process
/// while this object lives (it does not remove the file itself). The path is
/// made absolute here, so it stays right whatever the working directory later.
/// Throws InputError if the path is too long to store or too many temporaries
/// exist at once.
class TemporaryFileGuard {
public:
    explicit TemporaryFileGuard(const std::filesystem::path& path);
    ~TemporaryFileGuard();
    TemporaryFileGuard(const TemporaryFileGuard&) = delete;
    TemporaryFileGuard& operator=(const TemporaryFileGuard&) = delete;

private:
    int m_slot = -1;
};

/// While alive, the first SIGINT only sets stopRequested() (cleared on
/// construction) so that a render can stop at its next check and keep what it
/// has; a second SIGINT removes registered temporaries and exits at once with
/// SignalExitCodes::interrupted. The previous SIGINT action is restored on
/// destruction.
class StopOnInterrupt {
public:
    StopOnInterrupt();
    ~StopOnInterrupt();
    StopOnInterrupt(const StopOnInterrupt&) = delete;
    StopOnInterrupt& operator=(const StopOnInterrupt&) = delete;

    static const std::atomic<bool>& stopRequested();
};

/// While alive, SIGSEGV, SIGBUS, SIGILL and SIGFPE print "vkrt: the Vulkan
/// driver crashed (SIGSEGV) while <activity>", remove registered temporaries
/// and exit with SignalExitCodes::driverCrashed. Arm it only around calls into
/// the driver (instance and device creation, waits for the GPU): elsewhere a
/// crash is vkrt's own and keeps the default action (a core dump). `activity`
/// must outlive the guard (a string literal). Guards nest; arm them from one
/// thread (the driver's own threads are covered while one is armed).
class DriverCrashGuard {
public:
    explicit DriverCrashGuard(const char* activity);
    ~DriverCrashGuard();
    DriverCrashGuard(const DriverCrashGuard&) = delete;
    DriverCrashGuard& operator=(const DriverCrashGuard&) = delete;

private:
    const char* m_previousActivity = nullptr;
};

} // namespace vkrt
