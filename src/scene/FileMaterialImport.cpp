#include "scene/FileMaterialImport.h"

#include "mesh/FileMaterials.h"
#include "mesh/MeshGeometry.h"

#include <algorithm>
#include <cmath>

namespace vkrt {
namespace {

/// A file material's texture in the scene's atlas; a load failure becomes a
/// SceneError at the mesh's `material` key that names the mesh file.
uint32_t addFileTexture(const FileTexture& texture, bool linear, const std::filesystem::path& file,
                        const SourceLocation& where, TextureAtlas& atlas)
{
    try {
        // Embedded bytes go through the same header check and budget as a
        // file, before they are decoded: a small .glb may hold a PNG bomb.
        if (texture.embedded)
            return atlas.addEncoded(texture.embedded, texture.name, linear, texture.wrapU, texture.wrapV,
                                    texture.filter);
        return atlas.add(TextureRequest{texture.file, linear, texture.wrapU, texture.wrapV, texture.filter});
    } catch (const InputError& error) {
        throw SceneError(where, "a texture of the mesh file " + file.string() + ": " + error.what());
    }
}

/// The texture's KHR_texture_transform in vkrt's uv space. glTF transforms
/// g = (u, v) with v down from the image's top row: g' = R(theta) S g + o,
/// R(theta) = [c s; -s c]. vkrt's uvs have v up from the bottom row (the mesh
/// loader's uv = (u, 1 - v); lib/texture.glsl reads row 1 - v), so in its
/// space the same lookup is R(-theta) S uv + (ox + s sy, 1 - oy - c sy).
MaterialTexture slot(uint32_t record, const FileTexture& texture, uint32_t channel = 0)
{
    const double c = std::cos(texture.rotation), s = std::sin(texture.rotation);
    const glm::dvec2 offset(texture.offset.x + s * texture.scale.y, 1.0 - texture.offset.y - c * texture.scale.y);
    return MaterialTexture{record, channel, texture.scale, offset, -texture.rotation, texture.texCoord};
}

std::string displayName(const FileMaterial& f, size_t index)
{
    if (!f.name.empty()) return f.name;
    return f.fileIndex < 0 ? "default material" : "material " + std::to_string(index);
}

/// KHR_materials_volume's Beer-Lambert coefficient per world unit, -ln(attenuationColor) /
/// attenuationDistance, inside a volumetric (thickness > 0) material; 0 for a thin-walled one or
/// without attenuation.
Color volumeAbsorption(const FileMaterial& f)
{
    if (!(f.thicknessFactor > 0.0f)) return Color(0.0);
    return absorptionOfAttenuation(Color(f.attenuationColor), f.attenuationDistance);
}

/// KHR_materials_ior, _specular, _sheen, _clearcoat, _transmission, _volume,
/// _iridescence and _anisotropy as the pbr material's layers: factors as
/// constants, each texture's channel as the extension says (sRGB colours,
/// strengths in A, the coat in R and its roughness in G; normal and direction
/// textures linear, read whole).
void addLayers(const FileMaterial& f, const std::filesystem::path& file, const SourceLocation& where,
               TextureAtlas& atlas, Material& m)
{
    m.ior = f.ior;
    m.layers.specular = f.specularFactor;
    m.layers.specularColor = Color(f.specularColorFactor);
    m.layers.sheenColor = Color(f.sheenColorFactor);
    m.layers.sheenRoughness = f.sheenRoughnessFactor;
    m.layers.clearcoat = f.clearcoatFactor;
    m.layers.clearcoatRoughness = f.clearcoatRoughnessFactor;
    m.layers.transmission = f.transmission;
    // A path tracer has the mesh itself: thicknessFactor (and its texture, for
    // rasterizers) only says whether the surface bounds a volume.
    m.layers.thinWalled = !(f.thicknessFactor > 0.0f);
    if (m.layers.volumetric()) m.absorption = volumeAbsorption(f);
    m.layers.iridescence = f.iridescenceFactor;
    m.layers.iridescenceIor = f.iridescenceIor;
    m.layers.iridescenceThicknessMin = f.iridescenceThicknessMinimum;
    m.layers.iridescenceThicknessMax = f.iridescenceThicknessMaximum;
    m.layers.anisotropy = f.anisotropyStrength;
    m.layers.anisotropyRotation = f.anisotropyRotation;
    auto add = [&](const std::optional<FileTexture>& texture, bool linear, TextureSlot which, uint32_t channel) {
        if (texture)
            m.textures[size_t(which)] = slot(addFileTexture(*texture, linear, file, where, atlas), *texture, channel);
    };
    add(f.specularTexture, true, TextureSlot::SpecularFactor, 3);
    add(f.specularColorTexture, false, TextureSlot::Specular, 0);
    add(f.sheenColorTexture, false, TextureSlot::SheenColor, 0);
    add(f.sheenRoughnessTexture, true, TextureSlot::SheenRoughness, 3);
    add(f.clearcoatTexture, true, TextureSlot::Clearcoat, 0);
    add(f.clearcoatRoughnessTexture, true, TextureSlot::ClearcoatRoughness, 1);
    add(f.transmissionTexture, true, TextureSlot::Transmission, 0);
    add(f.iridescenceTexture, true, TextureSlot::Iridescence, 0);
    add(f.iridescenceThicknessTexture, true, TextureSlot::IridescenceThickness, 1);
    if (m.layers.anisotropy > 0.0) add(f.anisotropyTexture, true, TextureSlot::Anisotropy, 0);
    if (m.layers.clearcoat > 0.0) {
        add(f.clearcoatNormalTexture, true, TextureSlot::ClearcoatNormal, 0);
        m.clearcoatNormalStrength = f.clearcoatNormalScale;
    }
}

/// glTF 2.0 metallic-roughness as vkrt's pbr kind: the factors are the
/// constants each texel multiplies (glTF's own rule), G and B of the
/// metallic-roughness texture are roughness and metallic, and the emissive
/// texture (sRGB) multiplies the emission.
Material toPbr(const FileMaterial& f, size_t index, const std::filesystem::path& file, const SourceLocation& where,
               TextureAtlas& atlas)
{
    Material m;
    m.type = MaterialType::Pbr;
    m.name = file.filename().string() + "#" + displayName(f, index);
    m.where = where;
    m.diffuse = Color(f.baseColorFactor.r, f.baseColorFactor.g, f.baseColorFactor.b);
    m.metallic = f.metallicFactor;
    m.roughness = f.roughnessFactor;
    m.emission = Color(f.emissiveFactor);
    // Coverage: baseColorFactor.a times the colour texture's A (lib/alpha.glsl).
    m.alphaMode = f.alphaMode;
    m.alphaCutoff = f.alphaCutoff;
    m.alpha = f.baseColorFactor.a;
    auto set = [&](TextureSlot which, MaterialTexture texture) { m.textures[size_t(which)] = texture; };
    if (f.baseColorTexture)
        set(TextureSlot::Color,
            slot(addFileTexture(*f.baseColorTexture, false, file, where, atlas), *f.baseColorTexture));
    if (f.metallicRoughnessTexture) {
        const uint32_t record = addFileTexture(*f.metallicRoughnessTexture, true, file, where, atlas);
        set(TextureSlot::Roughness, slot(record, *f.metallicRoughnessTexture, 1));
        set(TextureSlot::Metallic, slot(record, *f.metallicRoughnessTexture, 2));
    }
    // emissiveFactor already carries KHR_materials_emissive_strength (mesh/FileMaterials).
    if (f.emissiveTexture)
        set(TextureSlot::Emission,
            slot(addFileTexture(*f.emissiveTexture, false, file, where, atlas), *f.emissiveTexture));
    if (f.normalTexture) {
        set(TextureSlot::Normal, slot(addFileTexture(*f.normalTexture, true, file, where, atlas), *f.normalTexture));
        m.normalStrength = f.normalScale;
    }
    addLayers(f, file, where, atlas, m);
    return m;
}

/// KHR_materials_unlit: the base colour (factor x texture, sRGB) reaches the
/// camera as it is. An emitter of that radiance with a black Lambert surface:
/// seen directly it is exactly its colour, and no light it receives changes
/// it. Like every emitter it also lights its surroundings (Blender's glTF
/// importer makes unlit materials emission shaders too). The colour texture
/// stays in its slot for the alpha test (its A channel); its RGB multiplies
/// the black albedo.
Material toUnlit(Material pbr)
{
    Material m = pbr;
    m.type = MaterialType::Lambert;
    m.emission = pbr.diffuse;
    m.textures[size_t(TextureSlot::Emission)] = pbr.texture(TextureSlot::Color);
    m.diffuse = Color(0.0);
    for (size_t slot = 0; slot < kTextureSlotCount; ++slot)
        if (slot != size_t(TextureSlot::Color) && slot != size_t(TextureSlot::Emission)) m.textures[slot].reset();
    m.layers = PbrLayers{};
    m.absorption = Color(0.0);
    m.metallic = 0.0;
    m.roughness = 0.0;
    return m;
}

/// What vkrt does not honour of a file material, one located warning each.
void warnAbout(const FileMaterial& f, const Material& m, const SourceLocation& where,
               std::vector<std::string>& warnings)
{
    const std::string prefix = where.str() + ": " + m.name + ": ";
    for (const std::string& phrase : f.unsupported) warnings.push_back(prefix + phrase);
    if (f.normalTexture && f.normalTexture->rotation != 0.0)
        warnings.push_back(prefix + "normalTexture's KHR_texture_transform rotation turns its uvs, not its tangent "
                                    "frame: the normals are tilted the wrong way");
    if (f.clearcoatNormalTexture && f.clearcoatNormalTexture->rotation != 0.0)
        warnings.push_back(prefix + "clearcoatNormalTexture's KHR_texture_transform rotation turns its uvs, not its "
                                    "tangent frame: the coat's normals are tilted the wrong way");
    if (f.clearcoatFactor > 0.0f && f.emissiveFactor != glm::vec3(0.0f))
        warnings.push_back(prefix + "the emission is not darkened by the clear coat's Fresnel");
    if (f.baseColorFactor.a < 1.0f && f.alphaMode == AlphaMode::Opaque)
        warnings.push_back(prefix + "baseColorFactor's alpha is ignored (alphaMode OPAQUE)");
}

} // namespace

Color absorptionOfAttenuation(const Color& color, double distance)
{
    if (!std::isfinite(distance)) return Color(0.0);
    Color sigma;
    for (int c = 0; c < 3; ++c) sigma[c] = -std::log(std::max(color[c], 1e-9)) / distance;
    return sigma;
}

std::vector<uint32_t> importFileMaterials(const std::vector<FileMaterial>& fileMaterials,
                                          const std::filesystem::path& file, const SourceLocation& where,
                                          TextureAtlas& atlas, std::vector<Material>& materials,
                                          std::vector<std::string>& warnings)
{
    std::vector<uint32_t> indices;
    for (size_t i = 0; i < fileMaterials.size(); ++i) {
        Material m = toPbr(fileMaterials[i], i, file, where, atlas);
        if (fileMaterials[i].unlit) m = toUnlit(std::move(m));
        warnAbout(fileMaterials[i], m, where, warnings);
        indices.push_back(uint32_t(materials.size()));
        materials.push_back(std::move(m));
    }
    return indices;
}

std::vector<uint32_t> importFileMaterials(const MeshGeometry& geometry, const SourceLocation& where,
                                          TextureAtlas& atlas, std::vector<Material>& materials,
                                          std::vector<std::string>& warnings)
{
    if (geometry.data.materials.empty())
        throw SceneError(where, "material = \"file\" needs a mesh file with materials of its own (glTF 2.0); " +
                                    geometry.file.string() + " has none: name a [materials.NAME] table instead");
    return importFileMaterials(geometry.data.materials, geometry.file, where, atlas, materials, warnings);
}

} // namespace vkrt
