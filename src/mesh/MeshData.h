#pragma once
// A triangle mesh as read from a file: object-space float32 vertices (what
// every mesh format stores), optional per-vertex normals, texture
// coordinates and tangents, triangles as vertex-index triples, and the
// file's materials (glTF) with one per triangle. Produced only by
// loadMeshFile (MeshLoader.h) or the procedural generators (Procedural.h),
// which guarantee: every index < positions.size(); normals, uvs and
// tangents are empty or have one entry per position (uvs1 too); tangents only where
// there are tangentUvs; every coordinate is finite; at least one triangle;
// triangleMaterials is empty exactly when materials is, else has one entry
// per triangle, each < materials.size(). Normals are unit or (0, 0, 0) (use
// the face normal); tangents are unit with w = +1 or -1. Degenerate
// (zero-area) triangles are kept: they are never hit.
#include "mesh/FileMaterials.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace vkrt {

struct MeshData {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals; ///< unit vertex normals, or empty
    std::vector<glm::vec2> uvs;     ///< texture coordinates, or empty
    /// A second set (glTF TEXCOORD_1, read where a texture samples through it), or empty.
    std::vector<glm::vec2> uvs1;
    /// The set (0: uvs, 1: uvs1) whose derivatives the tangents follow: glTF's
    /// normal texture's (3.7.2.1), computed tangents included.
    uint32_t tangentUvSet = 0;
    /// Per vertex, or empty: xyz the unit tangent along increasing u (dp/du),
    /// perpendicular to the vertex normal (to the smooth normal where the
    /// mesh has none); w = +1 or -1 so that w * cross(normal, xyz) is the
    /// bitangent, along increasing v. From the file (glTF TANGENT) or computeTangents.
    std::vector<glm::vec4> tangents;
    /// Per vertex, or empty: linear RGBA (glTF COLOR_0; white where a primitive has none).
    std::vector<glm::vec4> colors;
    std::vector<glm::uvec3> triangles;
    /// Per triangle, its index into `materials`; empty when `materials` is.
    std::vector<uint32_t> triangleMaterials;
    /// The file's materials that its triangles use (glTF 2.0 only; OBJ and PLY leave it empty).
    std::vector<FileMaterial> materials;
    /// The files besides the mesh file that loading it read (glTF buffers, an
    /// OBJ's material library): inputs that no output may replace.
    std::vector<std::filesystem::path> referencedFiles;
};

/// The texture coordinates the tangents belong to (MeshData::tangentUvSet).
inline const std::vector<glm::vec2>& tangentUvs(const MeshData& mesh)
{
    return mesh.tangentUvSet == 1 ? mesh.uvs1 : mesh.uvs;
}

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

/// Applies `mode`: File keeps what the file gave, Smooth computes, Face drops
/// normals. Tangents are made perpendicular to the new normals again (to the
/// smooth normals for Face), keeping their handedness w.
void applyNormalMode(MeshData& mesh, NormalMode mode);

/// Fills mesh.tangents from tangentUvs(mesh) (which it needs; none: no tangents),
/// MikkTSpace's construction as far as shading sees it: each triangle's
/// tangent and bitangent from its uv derivatives, each made perpendicular to
/// the corner's vertex normal (the smooth normal where the mesh has none or
/// the vertex's is (0, 0, 0)), normalised and summed weighted by the corner's
/// angle; w from the side of cross(normal, tangent) the summed bitangent is
/// on. Vertices with the same position, normal and uv share one sum; vertices
/// at one position with different uvs (a seam) do not. Triangles whose uvs
/// are degenerate (zero uv area) contribute nothing. Unlike MikkTSpace, a
/// vertex where mirrored triangles meet is not split: its w is the
/// majority's. A vertex that receives no tangent gets the one of a fixed
/// orthonormal frame around its normal (perpendicularTo), w = +1, so that no
/// tangent is ever NaN or zero.
void computeTangents(MeshData& mesh);

/// A unit vector perpendicular to the unit vector n: the first axis of Duff et
/// al.'s frame (2017, "Building an orthonormal basis, revisited"), continuous
/// in n except where n.z changes sign. The tangent of last resort.
glm::vec3 perpendicularTo(glm::vec3 n);

} // namespace vkrt
