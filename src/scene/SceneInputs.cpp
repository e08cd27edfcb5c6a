#include "scene/SceneInputs.h"

#include "mesh/MeshGeometry.h"
#include "texture/TextureAtlas.h"

namespace vkrt {

std::vector<NamedFile> filesTheSceneRead(const Scene& scene)
{
    std::vector<NamedFile> files;
    for (const Mesh& mesh : scene.meshes) files.push_back({"a mesh the scene loads", mesh.geometry->file});
    if (scene.textures)
        for (uint32_t r = 0; r < scene.textures->recordCount(); ++r)
            files.push_back({"a texture the scene loads", scene.textures->nameOf(r)});
    if (scene.background.cubemap)
        for (const std::string& face : scene.background.cubemap->facePaths)
            files.push_back({"a cube face the scene loads", face});
    if (scene.background.environment && !scene.background.environment->studio)
        files.push_back({"the environment map the scene loads", scene.background.environment->path});
    return files;
}

} // namespace vkrt
