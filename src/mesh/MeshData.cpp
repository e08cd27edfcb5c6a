#include "mesh/MeshData.h"

#include <cmath>

namespace vkrt {

void computeSmoothNormals(MeshData& mesh)
{
    // The unnormalised cross product of two edges is the face normal scaled by
    // twice the area, so summing it weights each face by its area. Doubles:
    // float cross products of large coordinates can overflow.
    std::vector<glm::dvec3> sums(mesh.positions.size(), glm::dvec3(0.0));
    for (const glm::uvec3& triangle : mesh.triangles) {
        const glm::dvec3 p0 = mesh.positions[triangle.x];
        const glm::dvec3 areaNormal =
            glm::cross(glm::dvec3(mesh.positions[triangle.y]) - p0, glm::dvec3(mesh.positions[triangle.z]) - p0);
        for (int corner = 0; corner < 3; ++corner) sums[triangle[corner]] += areaNormal;
    }
    mesh.normals.resize(mesh.positions.size());
    for (size_t vertex = 0; vertex < sums.size(); ++vertex) {
        const double length = glm::length(sums[vertex]);
        // (0, 0, 0) tells the renderer to use the face normal (MeshData.h).
        mesh.normals[vertex] =
            length > 0.0 && std::isfinite(length) ? glm::vec3(sums[vertex] / length) : glm::vec3(0.0f);
    }
}

void applyNormalMode(MeshData& mesh, NormalMode mode)
{
    switch (mode) {
    case NormalMode::File: break;
    case NormalMode::Smooth: computeSmoothNormals(mesh); break;
    case NormalMode::Face: mesh.normals.clear(); break;
    }
}

} // namespace vkrt
