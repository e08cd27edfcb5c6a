#include "scene/FileMaterialImport.h"

#include "mesh/FileMaterials.h"
#include "mesh/MeshGeometry.h"

namespace vkrt {
namespace {

/// A file material's texture in the scene's atlas; a load failure becomes a
/// SceneError at the mesh's `material` key that names the mesh file.
uint32_t addFileTexture(const FileTexture& texture, bool linear, const MeshGeometry& geometry,
                        const SourceLocation& where, TextureAtlas& atlas)
{
    try {
        // Embedded bytes go through the same header check and budget as a
        // file, before they are decoded: a small .glb may hold a PNG bomb.
        if (!texture.embedded.empty())
            return atlas.addEncoded(texture.embedded, texture.name, linear, texture.wrapU, texture.wrapV);
        return atlas.add(TextureRequest{texture.file, linear, texture.wrapU, texture.wrapV});
    } catch (const InputError& error) {
        throw SceneError(where, "a texture of the mesh file " + geometry.file.string() + ": " + error.what());
    }
}

MaterialTexture slot(uint32_t record, uint32_t channel = 0)
{
    return MaterialTexture{record, channel, glm::dvec2(1.0)};
}

std::string displayName(const FileMaterial& f, size_t index)
{
    if (!f.name.empty()) return f.name;
    return f.fileIndex < 0 ? "default material" : "material " + std::to_string(index);
}

/// glTF 2.0 metallic-roughness as vkrt's pbr kind: the factors are the
/// constants each texel multiplies (glTF's own rule), G and B of the
/// metallic-roughness texture are roughness and metallic.
Material toPbr(const FileMaterial& f, size_t index, const MeshGeometry& geometry, const SourceLocation& where,
               TextureAtlas& atlas)
{
    Material m;
    m.type = MaterialType::Pbr;
    m.name = geometry.file.filename().string() + "#" + displayName(f, index);
    m.where = where;
    m.diffuse = Color(f.baseColorFactor.r, f.baseColorFactor.g, f.baseColorFactor.b);
    m.metallic = f.metallicFactor;
    m.roughness = f.roughnessFactor;
    m.emission = Color(f.emissiveFactor);
    auto set = [&](TextureSlot which, MaterialTexture texture) { m.textures[size_t(which)] = texture; };
    if (f.baseColorTexture)
        set(TextureSlot::Color, slot(addFileTexture(*f.baseColorTexture, false, geometry, where, atlas)));
    if (f.metallicRoughnessTexture) {
        const uint32_t record = addFileTexture(*f.metallicRoughnessTexture, true, geometry, where, atlas);
        set(TextureSlot::Roughness, slot(record, 1));
        set(TextureSlot::Metallic, slot(record, 2));
    }
    if (f.normalTexture) {
        set(TextureSlot::Normal, slot(addFileTexture(*f.normalTexture, true, geometry, where, atlas)));
        m.normalStrength = f.normalScale;
    }
    return m;
}

/// What vkrt does not honour of a file material, one located warning each.
void warnAbout(const FileMaterial& f, const Material& m, const SourceLocation& where,
               std::vector<std::string>& warnings)
{
    const std::string prefix = where.str() + ": " + m.name + ": ";
    for (const std::string& phrase : f.unsupported) warnings.push_back(prefix + phrase);
    if (f.emissiveTexture)
        warnings.push_back(prefix + "emissiveTexture is not supported: the emission is the constant emissiveFactor");
    if (f.baseColorFactor.a < 1.0f && f.alphaMode == AlphaMode::Opaque)
        warnings.push_back(prefix + "baseColorFactor's alpha is ignored (alphaMode OPAQUE)");
}

} // namespace

std::vector<uint32_t> importFileMaterials(const MeshGeometry& geometry, const SourceLocation& where,
                                          TextureAtlas& atlas, std::vector<Material>& materials,
                                          std::vector<std::string>& warnings)
{
    const std::vector<FileMaterial>& fileMaterials = geometry.data.materials;
    if (fileMaterials.empty())
        throw SceneError(where, "material = \"file\" needs a mesh file with materials of its own (glTF 2.0); " +
                                    geometry.file.string() + " has none: name a [materials.NAME] table instead");
    std::vector<uint32_t> indices;
    for (size_t i = 0; i < fileMaterials.size(); ++i) {
        Material m = toPbr(fileMaterials[i], i, geometry, where, atlas);
        warnAbout(fileMaterials[i], m, where, warnings);
        indices.push_back(uint32_t(materials.size()));
        materials.push_back(std::move(m));
    }
    return indices;
}

} // namespace vkrt
