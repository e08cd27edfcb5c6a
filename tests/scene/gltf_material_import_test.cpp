// glTF materials as vkrt materials (scene/FileMaterialImport.cpp), through
// parseGltfScene on files written here: the PBR extension layers with their
// factors and each texture in the slot and channel its extension names, and
// transmission with KHR_materials_volume's attenuation inside a volume.
#include "scene/FeatureSet.h"
#include "scene/GltfScene.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"
#include "texture/TextureTestFiles.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

/// One triangle with TEXCOORD_0 and TEXCOORD_1 whose material is `material`
/// (textures index 0 is a 2 x 2 PNG beside the file).
Scene importOne(const std::string& name, const std::string& material, const std::string& used)
{
    const fs::path dir = freshTempDir("gltf-material-import");
    write8BitPng(dir / "grey.png", 2, 2, 4, std::vector<uint8_t>(16, 128));
    writeText(dir / (name + ".gltf"), triangleGltf(R"("materials": [)" + material + R"(], "textures": [{"source": 0}],
                             "images": [{"uri": "grey.png"}], "extensionsUsed": )" +
                                                   used));
    return parseGltfScene((dir / (name + ".gltf")).string());
}

TEST(GltfMaterialImport, PbrLayersTakeTheirFactorsAndTexturesInTheirChannels)
{
    const Scene scene = importOne("layers", R"({"extensions": {
        "KHR_materials_ior": {"ior": 1.7},
        "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [2, 1, 0.5],
                                   "specularTexture": {"index": 0}, "specularColorTexture": {"index": 0}},
        "KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.4, 0.2], "sheenRoughnessFactor": 0.6,
                                "sheenRoughnessTexture": {"index": 0}},
        "KHR_materials_clearcoat": {"clearcoatFactor": 1, "clearcoatRoughnessFactor": 0.1,
                                    "clearcoatTexture": {"index": 0}, "clearcoatRoughnessTexture": {"index": 0}}}})",
                                  R"(["KHR_materials_ior", "KHR_materials_specular", "KHR_materials_sheen",
                                       "KHR_materials_clearcoat"])");
    ASSERT_EQ(scene.materials.size(), 1u);
    const Material& m = scene.materials[0];
    EXPECT_EQ(m.type, MaterialType::Pbr);
    EXPECT_TRUE(m.hasPbrLayers());
    EXPECT_DOUBLE_EQ(m.ior, 1.7f);
    EXPECT_DOUBLE_EQ(m.layers.specular, 0.5);
    EXPECT_EQ(m.layers.specularColor, Color(2.0, 1.0, 0.5));
    EXPECT_EQ(m.layers.sheenColor, Color(0.9f, 0.4f, 0.2f));
    EXPECT_DOUBLE_EQ(m.layers.sheenRoughness, 0.6f);
    EXPECT_DOUBLE_EQ(m.layers.clearcoat, 1.0);
    EXPECT_DOUBLE_EQ(m.layers.clearcoatRoughness, 0.1f);
    // The channels the extensions name: specular strength A, sheen roughness A, coat R, coat roughness G.
    const std::pair<TextureSlot, uint32_t> channels[] = {{TextureSlot::SpecularFactor, 3},
                                                         {TextureSlot::SheenRoughness, 3},
                                                         {TextureSlot::Clearcoat, 0},
                                                         {TextureSlot::ClearcoatRoughness, 1}};
    for (const auto& [slot, channel] : channels) {
        ASSERT_TRUE(m.texture(slot).has_value()) << int(slot);
        EXPECT_EQ(m.texture(slot)->channel, channel) << int(slot);
    }
    EXPECT_TRUE(m.texture(TextureSlot::Specular).has_value()) << "specularColorTexture multiplies the F0 colour";
    EXPECT_FALSE(m.texture(TextureSlot::SheenColor).has_value());
}

TEST(GltfMaterialImport, AMaterialWithoutExtensionsKeepsThePlainPbrKernel)
{
    // The file's defaults (iridescenceIor 1.3f, a float) must not count as layers.
    const Scene scene = importOne("plain", R"({"pbrMetallicRoughness": {"roughnessFactor": 0.5}})", "[]");
    EXPECT_FALSE(scene.materials.at(0).hasPbrLayers());
    EXPECT_FALSE(featuresOf(scene).pbrLayers);
    const Scene film = importOne("film", R"({"extensions": {"KHR_materials_iridescence": {"iridescenceIor": 1.8}}})",
                                 R"(["KHR_materials_iridescence"])");
    EXPECT_FALSE(film.materials.at(0).hasPbrLayers()) << "an iridescence factor of 0 is no film";
}

TEST(GltfMaterialImport, TransmittingVolumesAbsorbAsTheirAttenuationSays)
{
    // sigma = -ln(attenuationColor) / attenuationDistance per channel, inside a volume of the file's index.
    const std::string volume = R"({"pbrMetallicRoughness": {"roughnessFactor": 0}, "extensions": {
        "KHR_materials_transmission": {"transmissionFactor": 0.75}, "KHR_materials_ior": {"ior": 1.4},
        "KHR_materials_volume": {"thicknessFactor": 1, "attenuationDistance": 2,
                                 "attenuationColor": [0.5, 1, 0.25]}}})";
    const std::string used = R"(["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"])";
    const Scene scene = importOne("volume", volume, used);
    ASSERT_EQ(scene.materials.size(), 1u);
    const Material& glass = scene.materials[0];
    EXPECT_EQ(glass.type, MaterialType::Pbr);
    EXPECT_EQ(glass.layers.transmission, 0.75) << "a partial transmission is kept, not rounded";
    EXPECT_TRUE(glass.layers.volumetric());
    EXPECT_NEAR(glass.ior, 1.4, 1e-6);
    EXPECT_NEAR(glass.absorption.r, std::log(2.0) / 2.0, 1e-7);
    EXPECT_EQ(glass.absorption.g, 0.0);
    EXPECT_NEAR(glass.absorption.b, std::log(4.0) / 2.0, 1e-7);
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();

    // Thin-walled (thickness 0): no volume to refract into or absorb in.
    std::string thin = volume;
    thin.replace(thin.find("\"thicknessFactor\": 1"), 20, "\"thicknessFactor\": 0");
    const Scene thinScene = importOne("thin", thin, used);
    EXPECT_TRUE(thinScene.materials.at(0).layers.thinWalled);
    EXPECT_FALSE(thinScene.materials.at(0).layers.volumetric());
    EXPECT_EQ(thinScene.materials.at(0).absorption, Color(0.0));
}

TEST(GltfMaterialImport, TransmissionAndIridescenceTakeTheirFactorsAndTextures)
{
    const std::string json = R"({"extensions": {
        "KHR_materials_transmission": {"transmissionFactor": 0.5, "transmissionTexture": {"index": 0}},
        "KHR_materials_iridescence": {"iridescenceFactor": 0.8, "iridescenceTexture": {"index": 0},
            "iridescenceIor": 1.6, "iridescenceThicknessMinimum": 50, "iridescenceThicknessMaximum": 700,
            "iridescenceThicknessTexture": {"index": 0}}}})";
    const Scene scene = importOne("layers", json, R"(["KHR_materials_transmission", "KHR_materials_iridescence"])");
    const Material& m = scene.materials.at(0);
    EXPECT_EQ(m.layers.transmission, 0.5);
    EXPECT_EQ(m.layers.iridescence, float(0.8));
    EXPECT_EQ(m.layers.iridescenceIor, float(1.6));
    EXPECT_EQ(m.layers.iridescenceThicknessMin, 50.0);
    EXPECT_EQ(m.layers.iridescenceThicknessMax, 700.0);
    // The channels the extensions name: transmission and iridescence in R, the thickness in G.
    for (const auto& [slot, channel] : std::vector<std::pair<TextureSlot, uint32_t>>{
             {TextureSlot::Transmission, 0}, {TextureSlot::Iridescence, 0}, {TextureSlot::IridescenceThickness, 1}}) {
        ASSERT_TRUE(m.texture(slot).has_value()) << int(slot);
        EXPECT_EQ(m.texture(slot)->channel, channel) << int(slot);
    }
    const FeatureSet features = featuresOf(scene);
    EXPECT_TRUE(features.has(PbrLobe::Transmission) && features.has(PbrLobe::Iridescence));
}

TEST(GltfMaterialImport, AnisotropyAndTheCoatsNormalMapTakeTheirFactorsAndTextures)
{
    const std::string json = R"({"normalTexture": {"index": 0}, "extensions": {
        "KHR_materials_anisotropy": {"anisotropyStrength": 0.6, "anisotropyRotation": 1.25,
                                     "anisotropyTexture": {"index": 0}},
        "KHR_materials_clearcoat": {"clearcoatFactor": 1, "clearcoatNormalTexture": {"index": 0, "scale": 0.5}}}})";
    const Scene scene = importOne("brushed", json, R"(["KHR_materials_anisotropy", "KHR_materials_clearcoat"])");
    const Material& m = scene.materials.at(0);
    EXPECT_EQ(m.layers.anisotropy, float(0.6));
    EXPECT_EQ(m.layers.anisotropyRotation, float(1.25)) << "radians, as the file writes them";
    ASSERT_TRUE(m.texture(TextureSlot::Anisotropy).has_value());
    ASSERT_TRUE(m.texture(TextureSlot::ClearcoatNormal).has_value());
    EXPECT_TRUE(m.texture(TextureSlot::Normal).has_value()) << "the base keeps its own normal map";
    EXPECT_EQ(m.clearcoatNormalStrength, 0.5);
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
    const FeatureSet features = featuresOf(scene);
    EXPECT_TRUE(features.has(PbrLobe::Anisotropy) && features.tangentFrames());

    // Without a strength the direction texture changes nothing: no anisotropic kernel for it.
    const Scene none = importOne("none", R"({"extensions": {"KHR_materials_anisotropy": {
        "anisotropyTexture": {"index": 0}}}})",
                                 R"(["KHR_materials_anisotropy"])");
    EXPECT_FALSE(none.materials.at(0).pbrAnisotropic());
    EXPECT_FALSE(featuresOf(none).pbrLayers);
}

TEST(GltfMaterialImport, AnisotropyRotationMustBeAFiniteNumber)
{
    const fs::path dir = freshTempDir("gltf-material-import");
    writeText(dir / "bad.gltf", triangleGltf(R"("materials": [{"extensions": {"KHR_materials_anisotropy":
        {"anisotropyStrength": 1, "anisotropyRotation": "left"}}}], "extensionsUsed": ["KHR_materials_anisotropy"])"));
    try {
        parseGltfScene((dir / "bad.gltf").string());
        FAIL() << "accepted a rotation that is no number";
    } catch (const std::exception& error) {
        EXPECT_NE(std::string(error.what()).find("KHR_materials_anisotropy.anisotropyRotation must be a finite number"),
                  std::string::npos)
            << error.what();
        EXPECT_NE(std::string(error.what()).find("bad.gltf"), std::string::npos) << error.what();
    }
}

} // namespace
} // namespace vkrt::test
