#pragma once
// Procedural test meshes (spheres, grids, random triangle soups) and mesh
// file writers, for tests, benchmarks (tools/bench_meshes.sh) and scenes.
// Every generator is deterministic and returns MeshData that keeps its
// promises: indices in range, finite coordinates, at least one triangle,
// triangles counter-clockwise seen from the side their normals face.
#include "mesh/MeshData.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <filesystem>

namespace vkrt {

/// A UV sphere (stacks x slices, a single vertex at each pole, vertices
/// shared) with exact radial normals: 2 * slices * (stacks - 1) triangles,
/// the fewest of that form (slices about twice the stacks) that reach
/// `trianglesAtLeast`.
MeshData makeUvSphere(uint32_t trianglesAtLeast, glm::vec3 centre, float radius);

/// An icosahedron subdivided `subdivisions` (0 ... 10) times: 20 * 4^n
/// triangles, vertices on the sphere, radial normals.
MeshData makeIcosphere(int subdivisions, glm::vec3 centre, float radius);

/// A grid of n x n quads on z = 0 over [-1, 1]^2 (2 n^2 triangles, normals +z,
/// uvs over [0, 1]^2); neighbouring triangles share their vertices exactly.
MeshData makeGrid(uint32_t n);

/// `n` small random triangles in the unit cube [0, 1]^3, from a fixed
/// generator (the same mesh for the same seed on every platform), no normals.
MeshData makeRandomSoup(uint32_t n, uint32_t seed);

/// The parallelogram corner, corner + edgeU, corner + edgeU + edgeV, corner + edgeV (two triangles).
MeshData makeQuad(glm::vec3 corner, glm::vec3 edgeU, glm::vec3 edgeV);

/// Wavefront OBJ: v, vn, vt and f lines (1-based, v/vt/vn) with round-trip float precision.
void writeObj(const MeshData& mesh, const std::filesystem::path& path);

/// PLY (binary little-endian or ASCII): float x y z [nx ny nz] [s t]
/// vertices, faces as `list uchar uint vertex_indices`.
void writePly(const MeshData& mesh, const std::filesystem::path& path, bool binary);

} // namespace vkrt
