#include "scene/SceneInputs.h"

#include "mesh/MeshGeometry.h"
#include "texture/TextureAtlas.h"

#include <set>

namespace vkrt {

std::vector<NamedFile> filesTheSceneRead(const Scene& scene)
{
    // Each file once: a mesh placed 262,144 times is one file to compare outputs against, not 262,144.
    std::vector<NamedFile> files;
    std::set<std::filesystem::path> listed;
    const auto add = [&](const char* role, const std::filesystem::path& path) {
        if (listed.insert(path).second) files.push_back({role, path});
    };
    std::set<const MeshGeometry*> geometries;
    for (const Mesh& mesh : scene.meshes) {
        if (!geometries.insert(mesh.geometry.get()).second) continue;
        add("a mesh the scene loads", mesh.geometry->file);
        for (const std::filesystem::path& file : mesh.geometry->data.referencedFiles)
            add("a file a mesh of the scene reads", file);
    }
    for (const std::filesystem::path& file : scene.importedFiles)
        add("a glTF file the scene imports, or a buffer it reads", file);
    if (scene.textures)
        for (uint32_t r = 0; r < scene.textures->recordCount(); ++r)
            add("a texture the scene loads", scene.textures->nameOf(r));
    if (scene.background.cubemap)
        for (const std::string& face : scene.background.cubemap->facePaths) add("a cube face the scene loads", face);
    if (scene.background.environment && !scene.background.environment->studio)
        add("the environment map the scene loads", scene.background.environment->path);
    return files;
}

} // namespace vkrt
