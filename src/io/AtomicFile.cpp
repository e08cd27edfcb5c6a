#include "io/AtomicFile.h"

#include "util/Error.h"
#include "util/Signals.h"

#include <cerrno>
#include <cstring>
#include <random>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

// ---------------------------------------------------------------- what is at the path

constexpr int kMaxSymlinkHops = 40; // as Linux's own limit (ELOOP)

std::string errnoText() { return std::strerror(errno); }

/// The path shown in messages: the one given, plus where its links lead.
std::string shown(const fs::path& given, const fs::path& resolved)
{
    return resolved == given ? given.string() : given.string() + " (a link to " + resolved.string() + ")";
}

const char* fileKindName(mode_t mode)
{
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

bool isNullDevice(const struct stat& info)
{
    struct stat null {};
    return S_ISCHR(info.st_mode) && stat("/dev/null", &null) == 0 && S_ISCHR(null.st_mode) &&
           info.st_rdev == null.st_rdev;
}

fs::path directoryOf(const fs::path& file) { return file.has_parent_path() ? file.parent_path() : fs::path("."); }

fs::path linkTarget(const fs::path& link)
{
    fs::path target = fs::read_symlink(link);
    return target.is_absolute() ? target : directoryOf(link) / target;
}

OutputTarget newFileAt(const fs::path& given, const fs::path& resolved)
{
    const fs::path directory = directoryOf(resolved);
    std::error_code error;
    if (!fs::is_directory(directory, error))
        throw InputError(shown(given, resolved) + ": cannot write: directory '" + directory.string() +
                         "' does not exist");
    return {resolved, OutputTargetKind::NewFile};
}

// ---------------------------------------------------------------- the temporary

/// Beside the target, hidden, unique to this process; the extension stays last
/// because some writers pick the format from it.
fs::path temporaryPathFor(const fs::path& target)
{
    std::random_device random;
    const std::string stem = target.stem().string().substr(0, 160); // the name must stay under NAME_MAX
    return directoryOf(target) / ("." + stem + ".tmp-" + std::to_string(getpid()) + "-" + std::to_string(random()) +
                                  target.extension().string());
}

/// A temporary file that becomes the target on commit() and is removed
/// otherwise (on an exception, or by util/Signals.h on a signal).
class TemporaryOutput {
public:
    TemporaryOutput(const fs::path& given, const OutputTarget& target)
        : m_given(given),
          m_target(target),
          m_path(temporaryPathFor(target.path)),
          m_removeOnSignal(m_path)
    {
        // An existing file's mode comes on commit; until then nobody else may read it.
        const mode_t mode = target.kind == OutputTargetKind::ExistingFile ? 0600 : 0666;
        m_fd = ::open(m_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
        if (m_fd < 0) fail("cannot create a temporary file beside it: " + errnoText());
    }
    ~TemporaryOutput()
    {
        if (m_fd >= 0) ::close(m_fd);
        if (!m_committed) ::unlink(m_path.c_str());
    }
    TemporaryOutput(const TemporaryOutput&) = delete;
    TemporaryOutput& operator=(const TemporaryOutput&) = delete;

    const fs::path& path() const { return m_path; }

    void writeAll(std::string_view bytes)
    {
        while (!bytes.empty()) {
            const ssize_t n = ::write(m_fd, bytes.data(), bytes.size());
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) fail(errnoText());
            bytes.remove_prefix(size_t(n));
        }
    }

    /// Gives it the old file's mode, flushes it to disk and renames it over the target.
    void commit()
    {
        if (m_target.kind == OutputTargetKind::ExistingFile) keepModeOfTarget();
        if (::fsync(m_fd) != 0) fail(errnoText());
        const int fd = m_fd;
        m_fd = -1;
        if (::close(fd) != 0) fail(errnoText());
        if (::rename(m_path.c_str(), m_target.path.c_str()) != 0) fail(errnoText());
        m_committed = true;
        syncDirectory();
    }

private:
    fs::path m_given;
    OutputTarget m_target;
    fs::path m_path;
    TemporaryFileGuard m_removeOnSignal;
    int m_fd = -1;
    bool m_committed = false;

    [[noreturn]] void fail(const std::string& why) const
    {
        throw InputError(shown(m_given, m_target.path) + ": cannot write: " + why);
    }

    void keepModeOfTarget() const
    {
        struct stat old {};
        if (::stat(m_target.path.c_str(), &old) != 0) return; // removed meanwhile: a new file then
        // The owner first: chown clears set-user-ID bits that chmod then restores.
        // Only root may give a file away; where even root may not (NFS), the owner is ours.
        if (geteuid() == 0 && ::fchown(m_fd, old.st_uid, old.st_gid) != 0 && errno != EPERM) fail(errnoText());
        if (::fchmod(m_fd, old.st_mode & 07777) != 0) fail(errnoText());
    }

    /// Makes the rename itself durable; a file system that cannot sync directories loses nothing else.
    void syncDirectory() const
    {
        const int fd = ::open(directoryOf(m_target.path).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
        if (fd < 0) return;
        (void)::fsync(fd);
        ::close(fd);
    }
};

} // namespace

OutputTarget resolveOutputTarget(const fs::path& path)
{
    fs::path current = path;
    for (int hop = 0; hop <= kMaxSymlinkHops; ++hop) {
        struct stat info {};
        if (::lstat(current.c_str(), &info) != 0) {
            if (errno == ENOENT) return newFileAt(path, current);
            throw InputError(shown(path, current) + ": cannot write: " + errnoText());
        }
        if (S_ISLNK(info.st_mode)) {
            current = linkTarget(current);
            continue;
        }
        if (S_ISREG(info.st_mode)) return {current, OutputTargetKind::ExistingFile};
        if (isNullDevice(info)) return {current, OutputTargetKind::Discarded};
        throw InputError(shown(path, current) + ": is " + fileKindName(info.st_mode) +
                         "; vkrt writes only regular files (or /dev/null, to discard an output)");
    }
    throw InputError(path.string() + ": cannot write: too many levels of symbolic links");
}

void writeFileAtomically(const fs::path& path, const std::function<void(const fs::path&)>& write)
{
    const OutputTarget target = resolveOutputTarget(path);
    if (target.kind == OutputTargetKind::Discarded) return;
    TemporaryOutput temporary(path, target);
    write(temporary.path());
    temporary.commit();
}

void writeBytesAtomically(const fs::path& path, std::string_view bytes)
{
    const OutputTarget target = resolveOutputTarget(path);
    if (target.kind == OutputTargetKind::Discarded) return;
    TemporaryOutput temporary(path, target);
    temporary.writeAll(bytes);
    temporary.commit();
}

} // namespace vkrt
