#pragma once
// A triangle mesh as read from a file: object-space float32 vertices (what
// every mesh format stores), optional per-vertex normals and texture
// coordinates, and triangles as vertex-index triples. Produced only by
// loadMeshFile (MeshLoader.h) or the procedural generators (Procedural.h),
// which guarantee: every index < positions.size(); normals and uvs are empty
// or have one entry per position; every coordinate is finite; at least one
// triangle. Degenerate (zero-area) triangles are kept: they are never hit.
#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace vkrt {

struct MeshData {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals; ///< unit vertex normals, or empty
    std::vector<glm::vec2> uvs;     ///< texture coordinates, or empty
    std::vector<glm::uvec3> triangles;
    std::vector<glm::vec4> tangents;         ///< per vertex: xyz along +u, w = +-1 (bitangent = w cross(n, t)), or empty
    std::vector<uint32_t> triangleMaterials; ///< per triangle: the file material it uses, or empty
};

/// How a mesh's shading normals are chosen (scene format `normals = ...`).
enum class NormalMode {
    File,   ///< the file's vertex normals where it has them, else the face normal
    Smooth, ///< area-weighted vertex normals computed from the triangles
    Face,   ///< the geometric (face) normal everywhere
};

/// Replaces mesh.normals by area-weighted averages of the adjacent faces'
/// normals, vertices at exactly the same position sharing one (mesh files
/// and assimp's OBJ importer split a surface's vertices); a vertex whose faces are all
/// degenerate gets no valid normal and its triangles fall back to the face
/// normal (its normal is stored as (0, 0, 0)).
void computeSmoothNormals(MeshData& mesh);

/// Applies `mode`: File keeps what the file gave, Smooth computes, Face drops normals.
void applyNormalMode(MeshData& mesh, NormalMode mode);

} // namespace vkrt
