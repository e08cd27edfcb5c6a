#include "mesh/MeshData.h"

#include <cmath>
#include <cstring>
#include <unordered_map>

namespace vkrt {

namespace {

/// Bit pattern of a position: equal keys are exactly equal coordinates
/// (after folding -0 into +0, which compares equal).
struct PositionKey {
    uint32_t bits[3];
    bool operator==(const PositionKey&) const = default;
};

struct PositionHash {
    size_t operator()(const PositionKey& k) const
    {
        return (size_t(k.bits[0]) * 73856093u) ^ (size_t(k.bits[1]) * 19349663u) ^ (size_t(k.bits[2]) * 83492791u);
    }
};

PositionKey keyOf(glm::vec3 p)
{
    PositionKey key;
    for (int i = 0; i < 3; ++i) {
        const float v = p[i] == 0.0f ? 0.0f : p[i];
        std::memcpy(&key.bits[i], &v, sizeof v);
    }
    return key;
}

/// For every vertex, the first vertex at exactly its position: mesh files
/// (and assimp's OBJ importer, which gives each face corner its own vertex)
/// often split a surface's vertices, and smoothing must join them again.
std::vector<uint32_t> weldByPosition(const std::vector<glm::vec3>& positions)
{
    std::unordered_map<PositionKey, uint32_t, PositionHash> first;
    first.reserve(positions.size());
    std::vector<uint32_t> weld(positions.size());
    for (uint32_t v = 0; v < positions.size(); ++v) weld[v] = first.try_emplace(keyOf(positions[v]), v).first->second;
    return weld;
}

} // namespace

void computeSmoothNormals(MeshData& mesh)
{
    // The unnormalised cross product of two edges is the face normal scaled by
    // twice the area, so summing it weights each face by its area. Doubles:
    // float cross products of large coordinates can overflow. Vertices at the
    // same position share one sum.
    const std::vector<uint32_t> weld = weldByPosition(mesh.positions);
    std::vector<glm::dvec3> sums(mesh.positions.size(), glm::dvec3(0.0));
    for (const glm::uvec3& triangle : mesh.triangles) {
        const glm::dvec3 p0 = mesh.positions[triangle.x];
        const glm::dvec3 areaNormal = glm::cross(glm::dvec3(mesh.positions[triangle.y]) - p0,
                                                 glm::dvec3(mesh.positions[triangle.z]) - p0);
        for (int corner = 0; corner < 3; ++corner) sums[weld[triangle[corner]]] += areaNormal;
    }
    mesh.normals.resize(mesh.positions.size());
    for (size_t vertex = 0; vertex < sums.size(); ++vertex) {
        const double length = glm::length(sums[weld[vertex]]);
        // (0, 0, 0) tells the renderer to use the face normal (MeshData.h).
        mesh.normals[vertex] =
            length > 0.0 && std::isfinite(length) ? glm::vec3(sums[weld[vertex]] / length) : glm::vec3(0.0f);
    }
}

void applyNormalMode(MeshData& mesh, NormalMode mode)
{
    switch (mode) {
    case NormalMode::File:
        break;
    case NormalMode::Smooth:
        computeSmoothNormals(mesh);
        break;
    case NormalMode::Face:
        mesh.normals.clear();
        break;
    }
}

} // namespace vkrt
