#include "io/OutputPaths.h"

#include "io/AtomicFile.h"
#include "util/Error.h"

#include <cerrno>
#include <cstring>
#include <optional>

#include <sys/stat.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

/// Which file a path names: its inode when it exists (so hard and symbolic
/// links match), else its absolute path with existing links resolved.
struct FileIdentity {
    fs::path resolved;
    std::optional<std::pair<dev_t, ino_t>> inode;
    bool nullDevice = false;
};

FileIdentity identityOf(const fs::path& path)
{
    FileIdentity identity;
    std::error_code error;
    identity.resolved = fs::weakly_canonical(fs::absolute(path, error), error);
    if (error) identity.resolved = fs::absolute(path).lexically_normal();
    struct stat info {};
    if (::stat(path.c_str(), &info) == 0) {
        identity.inode = std::make_pair(info.st_dev, info.st_ino);
        struct stat null {};
        identity.nullDevice = S_ISCHR(info.st_mode) && ::stat("/dev/null", &null) == 0 && info.st_rdev == null.st_rdev;
    }
    return identity;
}

bool sameFile(const FileIdentity& a, const FileIdentity& b)
{
    if (a.inode && b.inode) return *a.inode == *b.inode;
    return a.resolved == b.resolved;
}

/// Identities of the non-empty paths, in order.
std::vector<std::pair<const NamedFile*, FileIdentity>> identities(const std::vector<NamedFile>& files)
{
    std::vector<std::pair<const NamedFile*, FileIdentity>> result;
    for (const NamedFile& file : files)
        if (!file.path.empty()) result.emplace_back(&file, identityOf(file.path));
    return result;
}

/// A long render must not end unable to save: the directory must let us in.
void checkDirectoryWritable(const NamedFile& output, const OutputTarget& target)
{
    if (target.kind == OutputTargetKind::Discarded) return;
    const fs::path directory = target.path.has_parent_path() ? target.path.parent_path() : fs::path(".");
    if (::access(directory.c_str(), W_OK | X_OK) != 0)
        throw InputError(output.path.string() + ": " + output.role + ": cannot write in directory '" +
                         directory.string() + "': " + std::strerror(errno));
}

} // namespace

void refuseOverlappingFiles(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs)
{
    const auto in = identities(inputs), out = identities(outputs);
    for (size_t i = 0; i < out.size(); ++i) {
        const auto& [output, identity] = out[i];
        for (const auto& [input, inputIdentity] : in)
            if (sameFile(identity, inputIdentity))
                throw InputError(output->path.string() + ": " + output->role + " is the same file as " + input->role +
                                 " " + input->path.string() + "; refusing to overwrite an input");
        if (identity.nullDevice) continue;
        for (size_t j = 0; j < i; ++j)
            if (sameFile(identity, out[j].second))
                throw InputError(output->path.string() + ": " + output->role + " is the same file as " +
                                 out[j].first->role + " " + out[j].first->path.string() +
                                 "; each output needs its own file");
    }
}

void checkOutputs(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs)
{
    refuseOverlappingFiles(inputs, outputs);
    for (const NamedFile& output : outputs)
        if (!output.path.empty()) checkDirectoryWritable(output, resolveOutputTarget(output.path));
}

} // namespace vkrt
