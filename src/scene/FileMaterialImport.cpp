#include "scene/FileMaterialImport.h"

#include "mesh/MeshGeometry.h"

namespace vkrt {

std::vector<uint32_t> importFileMaterials(const MeshGeometry& geometry, const SourceLocation& where,
                                          TextureAtlas& atlas, std::vector<Material>& materials,
                                          std::vector<std::string>& warnings)
{
    (void)atlas;
    (void)materials;
    (void)warnings;
    throw SceneError(where, "the mesh file " + geometry.file.string() + " has no materials vkrt can read");
}

} // namespace vkrt
