#pragma once
// vkrt's own PLY reader (ASCII and both binary byte orders). Assimp 5.2's
// PLY importer trusts the file: a truncated body, a header without
// `end_header` or counts the file cannot hold made it crash or loop for
// minutes (tools/fuzz.sh found such files), and it keeps one triangle of
// each `tristrips` element. PLY is small enough to read exactly, checking
// every count, index and value, with the line (ASCII) or byte offset
// (binary) of what is wrong.
#include "mesh/MeshData.h"

#include <filesystem>

namespace vkrt {

/// Reads the `vertex` (x, y, z; optional nx, ny, nz and u, v / s, t /
/// texture_u, texture_v) and `face` (list vertex_indices or vertex_index;
/// polygons become triangle fans, faces of fewer than 3 vertices are dropped)
/// elements of a PLY 1.0 file; other elements are read past. Throws
/// InputError ("FILE:LINE: ..." or "FILE: byte N: ...") for anything malformed.
MeshData readPlyFile(const std::filesystem::path& file);

} // namespace vkrt
