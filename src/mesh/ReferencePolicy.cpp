#include "mesh/ReferencePolicy.h"

#include "util/Error.h"

#include <assimp/DefaultIOSystem.h>

#include <cerrno>
#include <cstring>
#include <system_error>

namespace vkrt {

namespace fs = std::filesystem;

namespace {

/// `path` made absolute with every symlink and ".." of its existing part
/// followed (what opening it would reach), or lexically normalised when
/// that fails (a folder that cannot be read).
fs::path resolved(const fs::path& path)
{
    std::error_code error;
    fs::path absolute = fs::absolute(path, error);
    if (error) absolute = path;
    fs::path result = fs::weakly_canonical(absolute, error);
    return error ? absolute.lexically_normal() : result;
}

bool isInside(const fs::path& path, const fs::path& folder)
{
    const fs::path relative = path.lexically_relative(folder);
    return !relative.empty() && *relative.begin() != "..";
}

/// Why a path the policy allows cannot be opened, or "" when it can.
std::string unopenableReason(const fs::path& path)
{
    std::error_code error;
    const fs::file_status status = fs::status(path, error);
    if (!fs::exists(status)) return "no such file";
    if (fs::is_directory(status)) return "is a directory, not a file";
    if (!fs::is_regular_file(status)) return "is not a regular file";
    return "";
}

/// Assimp's own file system, restricted to what the policy allows.
class ConfinedIoSystem : public Assimp::DefaultIOSystem {
public:
    ConfinedIoSystem(const ReferencePolicy& policy, ReferenceLog& log) : m_policy(policy), m_log(log) {}

    bool Exists(const char* file) const override
    {
        if (isMeshFile(file)) return DefaultIOSystem::Exists(file);
        // Assimp probes names it guesses (an OBJ's material library under
        // other spellings); a refused or non-file one simply does not exist.
        return m_policy.allows(file) && unopenableReason(resolved(file)).empty();
    }

    Assimp::IOStream* Open(const char* file, const char* mode) override
    {
        if (std::strpbrk(mode, "wa+")) return nullptr; // an import never writes
        if (isMeshFile(file)) return DefaultIOSystem::Open(file, mode);
        if (!m_policy.allows(file)) {
            if (!m_log.refused) m_log.refused = file;
            return nullptr;
        }
        // Open what was checked: the resolved path, not the name again.
        const fs::path target = resolved(file);
        if (const std::string reason = unopenableReason(target); !reason.empty()) {
            noteMissing(file, reason);
            return nullptr;
        }
        Assimp::IOStream* stream = DefaultIOSystem::Open(target.c_str(), mode);
        if (!stream) noteMissing(file, "cannot be opened (" + std::string(std::strerror(errno)) + ")");
        else m_log.opened.push_back(target);
        return stream;
    }

private:
    bool isMeshFile(const char* file) const { return m_policy.meshFile().string() == file; }

    void noteMissing(const char* file, const std::string& reason)
    {
        if (m_log.missing) return;
        m_log.missing = file;
        m_log.missingReason = reason;
    }

    const ReferencePolicy& m_policy;
    ReferenceLog& m_log;
};

} // namespace

ReferencePolicy::ReferencePolicy(fs::path meshFile, MeshLoadOptions options)
    // The folder the user named, with its symlinks followed, not that of the
    // mesh file's own target: a symlinked mesh's references sit beside the link.
    : m_meshFile(std::move(meshFile)),
      m_folder(resolved(fs::absolute(m_meshFile).parent_path())),
      m_options(options)
{
}

bool ReferencePolicy::allows(const fs::path& path) const
{
    return m_options.allowOutsideReferences || isInside(resolved(path), m_folder);
}

void ReferencePolicy::check(const fs::path& path, const std::string& uri, const std::string& what, int line) const
{
    if (allows(path)) return;
    const std::string where = m_meshFile.string() + (line > 0 ? ":" + std::to_string(line) : "");
    throw InputError(where + ": " + (what.empty() ? "" : what + " ") + "references '" + uri + "' outside its folder (" +
                     m_folder.string() + "): it resolves to " + resolved(path).string() +
                     "; a mesh file may only use files in its own folder (set allow_outside_references = true "
                     "on the mesh in the scene to allow it for trusted input)");
}

std::string ReferencePolicy::uriOf(const std::string& path) const
{
    const std::string prefix = m_meshFile.parent_path().string();
    if (prefix.empty() || path.compare(0, prefix.size(), prefix) != 0) return path;
    size_t start = prefix.size();
    while (start < path.size() && path[start] == '/') ++start;
    return path.substr(start);
}

Assimp::IOSystem* newConfinedIoSystem(const ReferencePolicy& policy, ReferenceLog& log)
{
    return new ConfinedIoSystem(policy, log);
}

} // namespace vkrt
