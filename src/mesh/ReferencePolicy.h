#pragma once
// Which other files a mesh file may make vkrt open: a glTF's buffers and
// images, an OBJ's material libraries. A downloaded model is untrusted input:
// a buffer uri that climbs to /etc/passwd must not become vertex data, nor an
// OBJ's `mtllib ../../x.mtl` make the importer read folders above the scene.
// By default a referenced file must lie inside the mesh file's own folder
// (subfolders included) after ".." and symlinks are followed; the scene file,
// which the user wrote, may allow more for trusted input
// (`allow_outside_references = true` on the mesh). The mesh file's own path
// is the user's (the scene names it) and is never restricted here.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace Assimp {
class IOSystem;
}

namespace vkrt {

/// How loadMeshFile treats one mesh file (MeshLoader.h).
struct MeshLoadOptions {
    /// Files the mesh references may lie anywhere (scene key `allow_outside_references`).
    bool allowOutsideReferences = false;

    auto operator<=>(const MeshLoadOptions&) const = default;
};

/// The reference rule for one mesh file.
class ReferencePolicy {
public:
    ReferencePolicy(std::filesystem::path meshFile, MeshLoadOptions options);

    /// Whether the mesh file may open `path` (a path as the importer builds
    /// it: the mesh file's folder joined with the reference).
    bool allows(const std::filesystem::path& path) const;

    /// Throws InputError "FILE[:LINE]: WHAT references 'URI' outside its
    /// folder (DIR): ... (set allow_outside_references ...)" unless `path`,
    /// which `uri` names, is allowed. `what` says which reference ("buffer
    /// 0"), or is empty; `line` is the mesh file's line naming it, or 0.
    void check(const std::filesystem::path& path, const std::string& uri, const std::string& what = "",
               int line = 0) const;

    /// The reference as the file wrote it, recovered from a path the importer
    /// built (the mesh file's folder prefix removed; other paths unchanged).
    std::string uriOf(const std::string& path) const;

    const std::filesystem::path& meshFile() const { return m_meshFile; }

private:
    std::filesystem::path m_meshFile;
    std::filesystem::path m_folder; ///< the mesh file's folder, absolute, symlinks followed
    MeshLoadOptions m_options;
};

/// What the importer tried to open beyond the mesh file, for the error message.
struct ReferenceLog {
    std::optional<std::string> refused;        ///< the first path the policy refused to open
    std::optional<std::string> missing;        ///< the first path that could not be opened
    std::string missingReason;                 ///< why ("no such file", "is a directory", ...)
    std::vector<std::filesystem::path> opened; ///< every file besides the mesh file that was opened
};

/// A new assimp file system (Importer::SetIOHandler takes ownership) that
/// opens the mesh file itself and every other file only if `policy` allows
/// it, noting refused and unopenable files in `log`. Both must outlive it.
Assimp::IOSystem* newConfinedIoSystem(const ReferencePolicy& policy, ReferenceLog& log);

} // namespace vkrt
