#pragma once
// Whether a material may be used where the scene uses it: the rules the scene
// parser applies to each object as it reads it, and the Python module applies
// again when it replaces a material (one validator for both).
#include "scene/Scene.h"

#include <optional>
#include <string>

namespace vkrt {

/// Why a shape other than a mesh cannot use `material` (only meshes may emit).
std::optional<std::string> nonMeshMaterialProblem(const Material& material);

/// Why `mesh` cannot use `material`: textures read uv sets the mesh file does
/// not have, or both the mesh and the material emit.
std::optional<std::string> meshMaterialProblem(const Mesh& mesh, const Material& material);

/// The first problem of material `index` with any object of `scene` that uses it.
std::optional<std::string> materialUseProblem(const Scene& scene, uint32_t index);

} // namespace vkrt
