#pragma once
// Mesh files -> MeshData: OBJ through Open Asset Import Library (assimp),
// PLY (ASCII and binary, either byte order) through PlyReader, glTF 2.0
// (.gltf + .bin, .glb) through GltfReader (its instances flattened into one mesh).
// Every failure is an InputError whose message names the file and, where the
// format allows, the line (OBJ) or element and byte offset (PLY): unreadable
// or unsupported files, syntax errors, indices out of range, NaN or infinite
// coordinates, files without triangles. Never a crash, whatever the bytes.
#include "mesh/MeshData.h"
#include "mesh/ReferencePolicy.h"

#include <filesystem>

namespace vkrt {

/// Loads every mesh of the file (all objects, groups, glTF nodes with their
/// node transforms applied) as one MeshData; polygons are triangulated,
/// points and lines are ignored. PLY triangle strips are refused with an
/// error: Debian 12's assimp (5.2.5) keeps one triangle per strip (its bug
/// #2337), and a silently wrong mesh is worse than none. The files the mesh
/// file references (glTF buffers and images, OBJ material libraries) must lie
/// in its folder unless `options` allow more (ReferencePolicy.h); one that is
/// refused or cannot be read is an error naming it. PLY references nothing.
MeshData loadMeshFile(const std::filesystem::path& file, const MeshLoadOptions& options = {});

/// The extensions loadMeshFile accepts (lower case, with the dot).
const std::vector<std::string>& supportedMeshExtensions();

} // namespace vkrt
