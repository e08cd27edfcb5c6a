#pragma once
// A mesh file ready to render: its MeshData with triangles in BVH leaf order
// and the BVH over them, in the mesh's own coordinates. Instances (scene
// `[[objects]] shape = "mesh"`) share one MeshGeometry per (file, normals).
#include "accel/Bvh.h"
#include "mesh/MeshData.h"
#include "mesh/ReferencePolicy.h"

#include <filesystem>
#include <map>
#include <memory>
#include <tuple>
#include <utility>

namespace vkrt {

struct MeshGeometry {
    std::filesystem::path file;
    NormalMode normals = NormalMode::File;
    MeshData data; ///< triangles reordered: data.triangles[i] is leaf slot i
    Bvh bvh;
    Aabb bounds; ///< object space
    double loadSeconds = 0.0;
    /// Bytes this geometry occupies on the GPU (nodes, triangles, normals, uvs, tangents, materials).
    size_t gpuBytes() const;
};

/// Loads, applies the normal mode, computes tangents where there are uvs and
/// the file gave none, builds the BVH and reorders the triangles.
std::shared_ptr<const MeshGeometry> makeMeshGeometry(const std::filesystem::path& file, NormalMode normals,
                                                     const MeshLoadOptions& options = {});
/// The same from data already in memory (procedural meshes, tests).
std::shared_ptr<const MeshGeometry> makeMeshGeometry(MeshData data, NormalMode normals, std::filesystem::path name);

/// One scene's geometries, so that instances of the same file share one.
/// The load options are part of the key: a file refused under the default
/// reference rule may load for an instance that allows outside references.
class MeshGeometryCache {
public:
    std::shared_ptr<const MeshGeometry> get(const std::filesystem::path& file, NormalMode normals,
                                            const MeshLoadOptions& options = {});

private:
    using Key = std::tuple<std::filesystem::path, NormalMode, MeshLoadOptions>;
    std::map<Key, std::shared_ptr<const MeshGeometry>> m_loaded;
};

} // namespace vkrt
