// The emitters' alias table of a mesh whose glTF material has an emission
// texture (render/GpuScene: emitterTableOf, render/EmissionPower.h): each
// triangle's power is factor x strength x the texture's mean over its uv
// footprint x area x pi, so a triangle over black texels has power 0 and the
// table never chooses it, whatever its emissiveFactor. Closed form: three
// quads, each mapped inside one band of a three-band texture (white, black,
// sRGB grey 128), inset by a texel so that no bilinear lookup reaches the next
// band.
#include "render/GpuScene.h"
#include "render/KernelVariant.h"
#include "scene/FeatureSet.h"
#include "scene/GltfScene.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"
#include "texture/TextureImage.h"
#include "texture/TextureTestFiles.h"

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

constexpr uint8_t kBandCodes[3] = {255, 0, 128}; // sRGB, left to right

/// 24 x 8 texels, three bands of 8 columns.
void writeBands(const fs::path& file)
{
    std::vector<uint8_t> samples;
    for (uint32_t y = 0; y < 8; ++y)
        for (uint32_t x = 0; x < 24; ++x) samples.insert(samples.end(), 3, kBandCodes[x / 8]);
    write8BitPng(file, 24, 8, 3, samples);
}

/// Quad q (unit square at x in [2q, 2q + 1], z = 0, facing +z) on texels
/// 1 ... 6 of band q (u in [(8q + 1) / 24, (8q + 7) / 24], v in [1/8, 7/8]).
GltfQuad bandQuad(int q)
{
    const float x0 = 2.0f * float(q), x1 = x0 + 1.0f;
    const float u0 = (8.0f * float(q) + 1.0f) / 24.0f, u1 = (8.0f * float(q) + 7.0f) / 24.0f;
    const float v0 = 1.0f / 8.0f, v1 = 7.0f / 8.0f;
    return GltfQuad{{{{x0, 0, 0}, {x1, 0, 0}, {x1, 1, 0}, {x0, 1, 0}}}, {{{u0, v1}, {u1, v1}, {u1, v0}, {u0, v0}}}};
}

/// emissiveFactor (1, 0.5, 0.25) x KHR_materials_emissive_strength 4.
std::string emissiveMaterial(bool textured)
{
    return R"("extensionsUsed": ["KHR_materials_emissive_strength"],
  "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]}, "emissiveFactor": [1, 0.5, 0.25],)" +
           std::string(textured ? R"( "emissiveTexture": {"index": 0},)" : "") +
           R"( "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}}}],
  "textures": [{"source": 0}], "images": [{"uri": "bands.png"}])";
}

Scene bandsScene(const fs::path& dir, bool textured)
{
    writeBands(dir / "bands.png");
    writeText(dir / "quads.gltf", quadsGltf({bandQuad(0), bandQuad(1), bandQuad(2)}, emissiveMaterial(textured)));
    return sceneFromText(R"([render]
integrator = "path"
[camera]
eye = [3, 0.5, 5]
target = [3, 0.5, 0]
fov = 60
width = 64
height = 64
[[objects]]
shape = "mesh"
file = "quads.gltf"
material = "file"
)",
                         (dir / "scene.toml").string());
}

/// The probability that the alias table picks each emitter: slot i kept
/// with probability threshold[i], else its alias.
std::vector<double> pickProbabilities(const EmitterTable& table)
{
    const size_t n = table.pdf.size();
    std::vector<double> p(n, 0.0);
    for (size_t i = 0; i < n; ++i) {
        const double keep = std::clamp(double(table.threshold[i]), 0.0, 1.0);
        p[i] += keep / double(n);
        p[table.alias[i]] += (1.0 - keep) / double(n);
    }
    return p;
}

TEST(EmissionTable, ATriangleOverBlackTexelsHasPowerZeroAndIsNeverChosen)
{
    const fs::path dir = freshTempDir("emission-table");
    const Scene scene = bandsScene(dir, true);
    ASSERT_EQ(scene.meshes.size(), 1u);
    const GpuSceneStatic fixed = prepareStaticScene(scene);
    const EmitterTable& table = fixed.emitters;
    ASSERT_EQ(table.pdf.size(), 6u);

    // Triangles in leaf order: each one's band from its emitter record's position.
    const GpuSceneData data = convertScene(scene, FrameSettings{}, fixed);
    ASSERT_EQ(data.emitters.size(), 6u);
    const double factorMean = (4.0 + 2.0 + 1.0) / 3.0;
    double expectedTotal = 0.0;
    const std::vector<double> picked = pickProbabilities(table);
    for (size_t i = 0; i < 6; ++i) {
        const gpu::Emitter& e = data.emitters[i];
        const double x = (double(e.v0.x) + e.v1.x + e.v2.x) / 3.0 + scene.camera.eye.x; // camera-relative
        const int band = int(std::floor(x / 2.0));
        ASSERT_TRUE(band >= 0 && band < 3) << "emitter " << i << " at x " << x;
        const double texel = srgbToLinear(kBandCodes[band] / 255.0);
        const double power = factorMean * texel * 0.5 * glm::pi<double>();
        expectedTotal += power;
        EXPECT_NE(e.textures, gpu::NO_EMISSION_TEXTURE) << "emitter " << i << " reads no emission texture";
        if (kBandCodes[band] == 0) {
            EXPECT_EQ(table.pdf[i], 0.0) << "a triangle over black texels has power";
            EXPECT_EQ(e.pdf, 0.0f);
            EXPECT_EQ(picked[i], 0.0) << "the alias table can choose a black triangle";
        } else {
            EXPECT_GT(picked[i], 0.0);
        }
        reportStat("emission_table_pdf_" + std::to_string(i), table.pdf[i]);
    }
    // The texels are decoded as the kernel decodes them (code / 255 in float): 1e-6.
    EXPECT_NEAR(table.totalPower, expectedTotal, 1e-6 * expectedTotal);
    for (size_t i = 0; i < 6; ++i) {
        const gpu::Emitter& e = data.emitters[i];
        const double x = (double(e.v0.x) + e.v1.x + e.v2.x) / 3.0 + scene.camera.eye.x;
        const double texel = srgbToLinear(kBandCodes[int(std::floor(x / 2.0))] / 255.0);
        EXPECT_NEAR(table.pdf[i], factorMean * texel * 0.5 * glm::pi<double>() / expectedTotal, 1e-6);
        EXPECT_NEAR(picked[i], table.pdf[i], 1e-6) << "alias table against pdf, emitter " << i;
    }
}

TEST(EmissionTable, WithoutTheTextureEveryTriangleOfTheFactorHasEqualPower)
{
    const Scene scene = bandsScene(freshTempDir("emission-table-plain"), false);
    const GpuSceneStatic fixed = prepareStaticScene(scene);
    ASSERT_EQ(fixed.emitters.pdf.size(), 6u);
    for (double p : fixed.emitters.pdf) EXPECT_NEAR(p, 1.0 / 6.0, 1e-12);
    const GpuSceneData data = convertScene(scene, FrameSettings{}, fixed);
    for (const gpu::Emitter& e : data.emitters) EXPECT_EQ(e.textures, gpu::NO_EMISSION_TEXTURE);
}

// The variant: a textured emission compiles the emitters' texture lookups in;
// the same scene without the texture keeps its kernel.
TEST(EmissionTable, OnlyATexturedEmissionChangesTheKernelVariant)
{
    const FeatureSet textured = featuresOf(bandsScene(freshTempDir("emission-variant-a"), true));
    const FeatureSet plain = featuresOf(bandsScene(freshTempDir("emission-variant-b"), false));
    EXPECT_TRUE(textured.emissionTextures);
    EXPECT_FALSE(plain.emissionTextures);
    auto defines = [](const FeatureSet& f) {
        std::vector<std::string> names;
        for (const auto& [name, value] : KernelVariant(f).defines()) names.push_back(name);
        return names;
    };
    const auto a = defines(textured), b = defines(plain);
    EXPECT_NE(std::find(a.begin(), a.end(), "VKRT_HAS_EMISSION_TEXTURES"), a.end());
    EXPECT_EQ(std::find(b.begin(), b.end(), "VKRT_HAS_EMISSION_TEXTURES"), b.end());
    EXPECT_TRUE(FeatureSet::everything(Integrator::Path).emissionTextures);
}

// glTF import: the emissive texture becomes the material's emission slot
// (sRGB, with its KHR_texture_transform), without the old "not supported"
// warning; a file whose only emitters are emissive surfaces keeps the studio light.
TEST(EmissionTable, TheEmissiveTextureIsImportedWithItsTransformAndTheStudioStays)
{
    const fs::path dir = freshTempDir("emission-import");
    writeBands(dir / "bands.png");
    std::string material = emissiveMaterial(true);
    const std::string plain = R"("emissiveTexture": {"index": 0},)";
    material.replace(material.find(plain), plain.size(),
                     R"("emissiveTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [2, 3]}}},)");
    const std::string used = R"("KHR_materials_emissive_strength"])";
    material.replace(material.find(used), used.size(),
                     R"("KHR_materials_emissive_strength", "KHR_texture_transform"])");
    writeText(dir / "quads.gltf", quadsGltf({bandQuad(0)}, material));
    const Scene scene = parseGltfScene((dir / "quads.gltf").string());
    ASSERT_TRUE(scene.background.environment.has_value()) << "emissive surfaces alone switched the studio off";
    EXPECT_TRUE(scene.background.environment->studio);
    ASSERT_EQ(scene.meshes.size(), 1u);
    ASSERT_GE(scene.meshes[0].fileMaterials.size(), 1u); // by file material index (glTF's default last)
    const Material& m = scene.materials[scene.meshes[0].fileMaterials[0]];
    EXPECT_EQ(m.emission, Color(4.0, 2.0, 1.0));
    const auto& slot = m.texture(TextureSlot::Emission);
    ASSERT_TRUE(slot.has_value());
    EXPECT_EQ(slot->scale, glm::dvec2(2.0, 3.0));
    ASSERT_NE(scene.textures, nullptr);
    EXPECT_EQ(scene.textures->widthOf(slot->record), 24u);
    for (const std::string& warning : scene.warnings)
        EXPECT_EQ(warning.find("emissiveTexture"), std::string::npos) << warning;
    EXPECT_TRUE(featuresOf(scene).emissionTextures);
}

} // namespace
} // namespace vkrt::test
