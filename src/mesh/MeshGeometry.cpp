#include "mesh/MeshGeometry.h"

#include "mesh/MeshLoader.h"
#include "shared/Bindings.h"
#include "util/Error.h"

#include <chrono>

namespace vkrt {

namespace {

/// Puts `perTriangle` in the BVH's leaf order: slot i gets triangle order[i]'s entry.
template <typename T>
void reorder(std::vector<T>& perTriangle, const std::vector<uint32_t>& order)
{
    if (perTriangle.empty()) return;
    std::vector<T> reordered(order.size());
    for (size_t slot = 0; slot < order.size(); ++slot) reordered[slot] = perTriangle[order[slot]];
    perTriangle = std::move(reordered);
}

/// Puts the triangles (and what belongs to them: their materials; per-vertex
/// arrays follow through the indices) in the BVH's leaf order, so that a
/// leaf's triangles are contiguous on the GPU.
void reorderTriangles(MeshData& data, const std::vector<uint32_t>& order)
{
    reorder(data.triangles, order);
    reorder(data.triangleMaterials, order);
}

Aabb boundsOf(const MeshData& data)
{
    Aabb box;
    for (const glm::uvec3& t : data.triangles)
        for (int k = 0; k < 3; ++k) box.extend(glm::dvec3(data.positions[t[k]]));
    return box;
}

} // namespace

size_t MeshGeometry::gpuBytes() const
{
    size_t bytes = bvh.nodes.size() * sizeof(gpu::BvhNode) + data.triangles.size() * sizeof(gpu::MeshTriangle);
    if (!data.normals.empty()) bytes += data.triangles.size() * sizeof(gpu::MeshNormals);
    // Uploaded per triangle corner in leaf order: a vec2 uv and a vec4 tangent each, one material index per triangle.
    if (!data.uvs.empty()) bytes += data.triangles.size() * 3 * sizeof(glm::vec2);
    if (!data.uvs1.empty()) bytes += data.triangles.size() * 3 * sizeof(glm::vec2);
    if (!data.tangents.empty()) bytes += data.triangles.size() * 3 * sizeof(glm::vec4);
    if (!data.triangleMaterials.empty()) bytes += data.triangles.size() * sizeof(uint32_t);
    if (!data.colors.empty()) bytes += data.triangles.size() * 3 * sizeof(glm::vec4);
    return bytes;
}

std::shared_ptr<const MeshGeometry> makeMeshGeometry(MeshData data, NormalMode normals, std::filesystem::path name)
{
    auto geometry = std::make_shared<MeshGeometry>();
    geometry->file = std::move(name);
    geometry->normals = normals;
    applyNormalMode(data, normals);
    // After the normal mode: generated tangents are perpendicular to the normals the mesh keeps.
    if (!tangentUvs(data).empty() && data.tangents.empty()) computeTangents(data);
    const std::vector<Aabb> boxes = triangleBoxes(data.positions, data.triangles);
    geometry->bvh = buildBvh(boxes);
    if (geometry->bvh.depth > gpu::BVH_STACK_SIZE)
        throw InputError(geometry->file.string() + ": the mesh's BVH is " + std::to_string(geometry->bvh.depth) +
                         " levels deep, more than the " + std::to_string(gpu::BVH_STACK_SIZE) +
                         " the kernel's traversal stack holds");
    reorderTriangles(data, geometry->bvh.order);
    geometry->bounds = boundsOf(data);
    geometry->data = std::move(data);
    return geometry;
}

std::shared_ptr<const MeshGeometry> makeMeshGeometry(const std::filesystem::path& file, NormalMode normals,
                                                     const MeshLoadOptions& options)
{
    const auto start = std::chrono::steady_clock::now();
    MeshData data = loadMeshFile(file, options);
    const double loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    auto geometry = makeMeshGeometry(std::move(data), normals, file);
    auto editable = std::const_pointer_cast<MeshGeometry>(geometry);
    editable->loadSeconds = loadSeconds;
    return geometry;
}

std::shared_ptr<const MeshGeometry> MeshGeometryCache::get(const std::filesystem::path& file, NormalMode normals,
                                                           const MeshLoadOptions& options)
{
    std::error_code error;
    std::filesystem::path key = std::filesystem::weakly_canonical(file, error);
    if (error) key = file;
    auto& slot = m_loaded[{key, normals, options}];
    if (!slot) slot = makeMeshGeometry(file, normals, options);
    return slot;
}

} // namespace vkrt
