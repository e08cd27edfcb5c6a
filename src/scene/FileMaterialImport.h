#pragma once
// Mesh files' own materials (`material = "file"` on a glTF mesh) as scene
// materials: glTF 2.0 metallic-roughness becomes the `pbr` kind, its
// textures enter the scene's TextureAtlas, and whatever vkrt cannot honour
// (extensions, alpha modes, emissive textures, ...) becomes a warning that
// names it, located at the mesh's `material` key.
#include "mesh/FileMaterials.h"
#include "scene/Scene.h"
#include "texture/TextureAtlas.h"

#include <filesystem>

#include <string>
#include <vector>

namespace vkrt {

/// Beer-Lambert absorption per unit length of a volume whose white light turns
/// `color` after `distance` (KHR_materials_volume's attenuationColor and
/// attenuationDistance; TOML's attenuation_color and attenuation_distance):
/// -ln(color) / distance per channel, 0 for an infinite distance. A channel of
/// 0 absorbs as one of 1e-9 does (opaque within a few distances), not infinitely.
Color absorptionOfAttenuation(const Color& color, double distance);

/// Appends one Material per material of the geometry's file to `materials`
/// and returns their indices, in the order of the file's materials (the
/// geometry's triangleMaterials index this list). Throws SceneError at
/// `where` when the file has no materials or a texture cannot be loaded.
/// The same for a list of a file's materials (a glTF scene's, GltfReader.h);
/// `file` names them in material names and messages.
std::vector<uint32_t> importFileMaterials(const std::vector<FileMaterial>& fileMaterials,
                                          const std::filesystem::path& file, const SourceLocation& where,
                                          TextureAtlas& atlas, std::vector<Material>& materials,
                                          std::vector<std::string>& warnings);

std::vector<uint32_t> importFileMaterials(const MeshGeometry& geometry, const SourceLocation& where,
                                          TextureAtlas& atlas, std::vector<Material>& materials,
                                          std::vector<std::string>& warnings);

} // namespace vkrt
