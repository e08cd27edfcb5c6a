#include "scene/MaterialUse.h"

#include "mesh/MeshGeometry.h"
#include "scene/TomlReader.h"
#include "scene/kinds/Kinds.h"

#include <algorithm>

namespace vkrt {

std::optional<std::string> nonMeshMaterialProblem(const Material& material)
{
    if (material.emission == Color(0.0)) return std::nullopt;
    return "material " + quote(material.name) +
           " emits; only meshes can use an emissive material (use a mesh, or a [[lights]] entry)";
}

std::optional<std::string> meshMaterialProblem(const Mesh& mesh, const Material& m)
{
    if (m.readsUvSet(0) && mesh.geometry->data.uvs.empty())
        return "material " + quote(m.name) + " has textures, but the mesh file " + quote(mesh.geometry->file.string()) +
               " has no texture coordinates (export it with uvs)";
    if (m.readsUvSet(1) && mesh.geometry->data.uvs1.empty())
        return "material " + quote(m.name) + " samples a texture through TEXCOORD_1, which the mesh " +
               quote(mesh.geometry->file.string()) + " does not have";
    if (m.emission != Color(0.0) && mesh.emission != Color(0.0))
        return "material " + quote(m.name) + " emits already; give the mesh either `emission` or an emissive material";
    return std::nullopt;
}

std::optional<std::string> materialUseProblem(const Scene& scene, uint32_t index)
{
    const Material& material = scene.materials[index];
    // Every shape array but the meshes' (the registry, shared/Kinds.h).
#define VKRT_CHECK_SHAPE_USE(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    if constexpr (ShapeKind::Type != ShapeKind::Mesh)                                         \
        for (const auto& shape : scene.array)                                                 \
            if (shape.material == index)                                                      \
                if (auto problem = nonMeshMaterialProblem(material)) return *problem + " (a " #name " uses it)";
    VKRT_SHAPE_KINDS(VKRT_CHECK_SHAPE_USE)
#undef VKRT_CHECK_SHAPE_USE
    for (const Mesh& mesh : scene.meshes) {
        const bool uses = mesh.fileMaterials.empty() ? mesh.material == index
                                                     : std::find(mesh.fileMaterials.begin(), mesh.fileMaterials.end(),
                                                                 index) != mesh.fileMaterials.end();
        if (uses)
            if (auto problem = meshMaterialProblem(mesh, material)) return problem;
    }
    return std::nullopt;
}

} // namespace vkrt
