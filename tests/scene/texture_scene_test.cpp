// Textured material parameters in scene files (docs/scene-format.md,
// "Textures"): what a texture table sets, and every way one can be wrong,
// each with its position in the file.
#include "mesh/MeshGeometry.h"
#include "scene/FeatureSet.h"
#include "scene/SceneParser.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"
#include "texture/TextureAtlas.h"
#include "texture/TextureImage.h"
#include "texture/TextureTestFiles.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

namespace vkrt::test {
namespace {

const std::string kCamera = "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 45\n";
// Appended to every scene, so that a warning seen here is about what the test checks.
const std::string kLight = "\n[[lights]]\ntype = \"point\"\nposition = [0, 3, 3]\nintensity = 1\n";

class SceneParserTextures : public ::testing::Test {
protected:
    void SetUp() override
    {
        m_dir = textureTestDir();
        write8BitPng(m_dir / "grey.png", 2, 2, 3, std::vector<uint8_t>(12, 128));
        std::ofstream(m_dir / "notes.png") << "not an image at all\n";
        writePng(m_dir / "four-bit.png", 2, 2, 4, 0, {});
        std::ofstream(m_dir / "no-uvs.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    }

    Scene parse(const std::string& body) const { return parseSceneString(kCamera + body + kLight, scenePath()); }
    std::string scenePath() const { return (m_dir / "scene.toml").string(); }

    /// The message of the SceneError `body` raises (empty if none).
    std::string errorOf(const std::string& body) const
    {
        try {
            parse(body);
        } catch (const SceneError& e) {
            return e.what();
        }
        return "";
    }

    std::filesystem::path m_dir;
};

const std::string kSphere = "[[objects]]\nshape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n";

TEST_F(SceneParserTextures, ATextureTableSetsTheSlotAndReplacesTheConstant)
{
    const Scene scene = parse("[materials.m]\ntype = \"lambert\"\n"
                              "albedo = { texture = \"grey.png\", scale = [4, 2], wrap = [\"clamp\", \"mirror\"] }\n" +
                              kSphere);
    const Material& m = scene.materials[0];
    ASSERT_TRUE(m.texture(TextureSlot::Color).has_value());
    EXPECT_EQ(m.diffuse, Color(1.0)) << "the texel is the albedo: the constant it multiplies is 1";
    EXPECT_EQ(m.texture(TextureSlot::Color)->scale, glm::dvec2(4, 2));
    ASSERT_TRUE(scene.textures);
    const TextureBuffers buffers = scene.textures->pack();
    ASSERT_EQ(buffers.records.size(), 1u);
    EXPECT_EQ(buffers.records[0].wrapU, gpu::TEXTURE_WRAP_CLAMP);
    EXPECT_EQ(buffers.records[0].wrapV, gpu::TEXTURE_WRAP_MIRROR);
    const FeatureSet features = featuresOf(scene);
    EXPECT_TRUE(features.textures);
    EXPECT_FALSE(features.normalMaps);
}

TEST_F(SceneParserTextures, ScalarTexturesPickTheirChannelAndKeepRoughKinds)
{
    const Scene scene = parse("[materials.m]\ntype = \"rough_dielectric\"\n"
                              "roughness = { texture = \"grey.png\", channel = \"b\", linear = true }\n"
                              "[materials.n]\ntype = \"pbr\"\nmetallic = { texture = \"grey.png\", channel = \"a\" }\n"
                              "normal_map = { texture = \"grey.png\", strength = 0.5 }\n" +
                              kSphere +
                              "[[objects]]\nshape = \"sphere\"\ncenter = [3, 0, 0]\nradius = 1\n"
                              "material = \"n\"\n");
    const Material& glass = scene.materials[0];
    EXPECT_EQ(glass.type, MaterialType::RoughDielectric) << "a textured roughness is never the smooth kind";
    EXPECT_EQ(glass.roughness, 1.0);
    ASSERT_TRUE(glass.texture(TextureSlot::Roughness).has_value());
    EXPECT_EQ(glass.texture(TextureSlot::Roughness)->channel, 2u);
    const Material& pbr = scene.materials[1];
    EXPECT_EQ(pbr.texture(TextureSlot::Metallic)->channel, 3u);
    EXPECT_EQ(pbr.normalStrength, 0.5);
    EXPECT_TRUE(featuresOf(scene).normalMaps);
    // The same file as sRGB and as linear data are two images; the normal map reuses the linear one.
    EXPECT_EQ(scene.textures->imageCount(), 2u);
}

TEST_F(SceneParserTextures, SceneWithoutTexturesHasNoAtlasAndNoTextureFeature)
{
    const Scene scene = parse("[materials.m]\ntype = \"lambert\"\nalbedo = 0.5\n" + kSphere);
    EXPECT_FALSE(scene.textures);
    EXPECT_FALSE(featuresOf(scene).textures);
}

// ------------------------------------------------------ file materials (glTF)

std::string cubeObjects(int count)
{
    std::string text;
    for (int i = 0; i < count; ++i)
        text += "[[objects]]\nshape = \"mesh\"\nfile = \"" + (assetsDir() / "gltf" / "Cube" / "Cube.gltf").string() +
                "\"\nmaterial = \"file\"\ntranslate = [" + std::to_string(3 * i) + ", 0, 0]\n";
    return text;
}

TEST_F(SceneParserTextures, GltfCubeGetsItsTexturedMetallicRoughnessMaterialOncePerFile)
{
    const Scene scene = parse("[materials.m]\ntype = \"lambert\"\n" + kSphere + cubeObjects(2));
    ASSERT_EQ(scene.materials.size(), 2u) << "two instances of one file share its materials";
    const Material& cube = scene.materials[1];
    EXPECT_EQ(cube.type, MaterialType::Pbr);
    EXPECT_EQ(cube.name, "Cube.gltf#Cube");
    // glTF's factors default to 1: each is the constant its texel multiplies.
    EXPECT_EQ(cube.diffuse, Color(1.0));
    EXPECT_EQ(cube.roughness, 1.0);
    EXPECT_EQ(cube.metallic, 1.0);
    ASSERT_TRUE(cube.texture(TextureSlot::Color) && cube.texture(TextureSlot::Roughness) &&
                cube.texture(TextureSlot::Metallic));
    // glTF's metallicRoughnessTexture: roughness in G, metallic in B, one linear image for both.
    EXPECT_EQ(cube.texture(TextureSlot::Roughness)->channel, 1u);
    EXPECT_EQ(cube.texture(TextureSlot::Metallic)->channel, 2u);
    EXPECT_EQ(cube.texture(TextureSlot::Roughness)->record, cube.texture(TextureSlot::Metallic)->record);
    EXPECT_FALSE(cube.hasNormalMap());
    EXPECT_EQ(scene.textures->imageCount(), 2u);
    ASSERT_EQ(scene.meshes.size(), 2u);
    EXPECT_EQ(scene.meshes[0].fileMaterials, std::vector<uint32_t>{1});
    EXPECT_EQ(scene.meshes[1].fileMaterials, std::vector<uint32_t>{1});
    EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
    const FeatureSet features = featuresOf(scene);
    EXPECT_TRUE(features.fileMaterials && features.textures && features.has(MaterialType::Pbr));
}

TEST_F(SceneParserTextures, UnsupportedGltfFeaturesAreLocatedWarnings)
{
    const std::string gltf = triangleGltf(
        R"("materials": [{"name": "Coat", "alphaMode": "BLEND",
                          "pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
                              "extensions": {"KHR_texture_transform": {"scale": [2, 2], "texCoord": 1}}}},
                          "extensions": {"KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1}}}],
            "textures": [{"source": 0}], "images": [{"uri": "grey.png"}],
            "extensionsUsed": ["KHR_texture_transform", "KHR_materials_diffuse_transmission"])");
    std::ofstream(m_dir / "coat.gltf") << gltf;
    const Scene scene = parse("[[objects]]\nshape = \"mesh\"\nfile = \"coat.gltf\"\nmaterial = \"file\"\n");
    ASSERT_EQ(scene.materials.size(), 1u);
    EXPECT_TRUE(scene.materials[0].texture(TextureSlot::Color).has_value());
    std::string all;
    for (const std::string& w : scene.warnings) {
        all += w + "\n";
        EXPECT_EQ(w.rfind(scenePath() + ":8:12: coat.gltf#Coat: ", 0), 0u) << w;
    }
    // KHR_texture_transform is honoured, its texCoord override too (the primitive's TEXCOORD_1 is the uv set read).
    for (const char* named : {"KHR_materials_diffuse_transmission"})
        EXPECT_NE(all.find(named), std::string::npos) << named << " is not named in:\n" << all;
    EXPECT_EQ(all.find("TEXCOORD"), std::string::npos) << all;
    // alphaMode BLEND is honoured: no warning, and the material keeps it.
    EXPECT_EQ(all.find("alphaMode"), std::string::npos) << all;
    EXPECT_EQ(scene.materials[0].alphaMode, AlphaMode::Blend);
}

TEST_F(SceneParserTextures, FileMaterialsNeedAFileWithMaterials)
{
    std::ofstream(m_dir / "uvs.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
    const std::string error = errorOf("[[objects]]\nshape = \"mesh\"\nfile = \"uvs.obj\"\nmaterial = \"file\"\n");
    EXPECT_NE(error.find(scenePath() + ":8:12: "), std::string::npos) << error;
    EXPECT_NE(error.find("has none"), std::string::npos) << error;
}

TEST_F(SceneParserTextures, MissingGltfTextureIsAnErrorAtTheMaterialKey)
{
    std::ofstream(m_dir / "lost.gltf") << triangleGltf(
        R"("materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
            "textures": [{"source": 0}], "images": [{"uri": "nowhere.png"}])");
    const std::string error = errorOf("[[objects]]\nshape = \"mesh\"\nfile = \"lost.gltf\"\nmaterial = \"file\"\n");
    EXPECT_NE(error.find(scenePath() + ":8:12: "), std::string::npos) << error;
    EXPECT_NE(error.find("nowhere.png"), std::string::npos) << error;
}

// glTF samplers' filters reach the texture records (TextureRecord::filters):
// the base colour's NEAREST_MIPMAP_NEAREST, the metallic-roughness map's
// LINEAR (no mip maps); the emissive texture reads the base colour's image
// without a sampler, so it is a record of its own over the same texels.
TEST_F(SceneParserTextures, GltfSamplerFiltersReachTheTextureRecords)
{
    std::ofstream(m_dir / "filtered.gltf") << triangleGltf(
        R"("materials": [{"emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 2},
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 1}}}],
          "textures": [{"source": 0, "sampler": 0}, {"source": 0, "sampler": 1}, {"source": 0}],
          "samplers": [{"magFilter": 9728, "minFilter": 9984}, {"magFilter": 9729, "minFilter": 9729}],
          "images": [{"uri": "grey.png"}])");
    const Scene scene = parse("[[objects]]\nshape = \"mesh\"\nfile = \"filtered.gltf\"\nmaterial = \"file\"\n");
    ASSERT_EQ(scene.materials.size(), 1u);
    const Material& m = scene.materials[0];
    ASSERT_TRUE(m.texture(TextureSlot::Color) && m.texture(TextureSlot::Roughness) && m.texture(TextureSlot::Emission));
    ASSERT_TRUE(scene.textures);
    const std::vector<gpu::TextureRecord> records = scene.textures->records();
    const gpu::TextureRecord& color = records.at(m.texture(TextureSlot::Color)->record);
    const gpu::TextureRecord& roughness = records.at(m.texture(TextureSlot::Roughness)->record);
    const gpu::TextureRecord& emission = records.at(m.texture(TextureSlot::Emission)->record);
    EXPECT_EQ(color.filters,
              gpu::TEXTURE_FILTER_MAG_NEAREST | gpu::TEXTURE_FILTER_MIN_NEAREST | gpu::TEXTURE_FILTER_MIP_NEAREST);
    EXPECT_EQ(roughness.filters, gpu::TEXTURE_FILTER_MIP_NONE);
    EXPECT_EQ(emission.filters, 0u);
    EXPECT_NE(m.texture(TextureSlot::Emission)->record, m.texture(TextureSlot::Color)->record);
    EXPECT_EQ(emission.levelOffset[0], color.levelOffset[0]);
    EXPECT_EQ(scene.textures->imageCount(), 2u); // grey.png as sRGB and as linear data
}

TEST_F(SceneParserTextures, FilterNearestTurnsOffEveryInterpolation)
{
    const Scene scene = parse("[materials.m]\ntype = \"lambert\"\n"
                              "albedo = { texture = \"grey.png\", filter = \"nearest\" }\n" +
                              kSphere);
    const std::vector<gpu::TextureRecord> records = scene.textures->records();
    ASSERT_EQ(records.size(), 1u);
    EXPECT_EQ(records[0].filters,
              gpu::TEXTURE_FILTER_MAG_NEAREST | gpu::TEXTURE_FILTER_MIN_NEAREST | gpu::TEXTURE_FILTER_MIP_NEAREST);
    const Scene linear = parse("[materials.m]\ntype = \"lambert\"\n"
                               "albedo = { texture = \"grey.png\", filter = \"linear\" }\n" +
                               kSphere);
    EXPECT_EQ(linear.textures->records()[0].filters, 0u);
}

// ---------------------------------------------------------------------------
// Images embedded in a glTF (data: URIs, .glb) meet the texture budget from
// their header, before they are decoded, as image files do (issue 26).

/// The members of triangleGltf for one material whose base colour is the embedded PNG `png`.
std::string embeddedPngMaterial(const std::string& png)
{
    return R"("materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
            "textures": [{"source": 0}], "images": [{"uri": ")" +
           dataUri("image/png", png) + R"("}])";
}

std::string fileBytes(const std::filesystem::path& file)
{
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const std::string kFileMaterialMesh = "[[objects]]\nshape = \"mesh\"\nfile = \"embedded.gltf\"\nmaterial = \"file\"\n";

/// The budget's refusal of a 16384x16384 embedded image of `gltf`, at the mesh's `material` key.
std::string budgetRefusal(const std::string& scenePath, const std::filesystem::path& gltf)
{
    return scenePath + ":8:12: a texture of the mesh file " + gltf.string() + ": " + gltf.string() +
           " (embedded image 0): a 16384x16384 texture brings the scene's textures to 268435456 texels, more than "
           "the 67108864 (one 8192x8192) vkrt loads for one scene; use smaller textures";
}

TEST_F(SceneParserTextures, EmbeddedImageOverTheBudgetIsRefusedFromItsHeaderBeforeDecoding)
{
    // A PNG bomb's header and the first 4 KiB of its pixel data: decoding it
    // fails (the data stops short), so only a check of the header before any
    // decoding gives the budget's message.
    const std::string bomb = fileBytes(writePngBomb(m_dir / "bomb.png", 16384));
    const std::filesystem::path gltf = m_dir / "embedded.gltf";
    std::ofstream(gltf) << triangleGltf(embeddedPngMaterial(bomb.substr(0, 4096)));
    EXPECT_EQ(errorOf(kFileMaterialMesh), budgetRefusal(scenePath(), gltf));
}

TEST_F(SceneParserTextures, EmbeddedImageWithinTheBudgetLoads)
{
    const std::filesystem::path grey = m_dir / "grey.png";
    std::ofstream(m_dir / "embedded.gltf") << triangleGltf(embeddedPngMaterial(fileBytes(grey)));
    const Scene scene = parse(kFileMaterialMesh);
    ASSERT_EQ(scene.materials.size(), 1u);
    ASSERT_TRUE(scene.materials[0].texture(TextureSlot::Color).has_value());
    ASSERT_TRUE(scene.textures);
    EXPECT_EQ(scene.textures->imageCount(), 1u);
    EXPECT_NEAR(scene.textures->meanOf(scene.materials[0].texture(TextureSlot::Color)->record)[0],
                srgbToLinear(128.0 / 255.0), 1e-6);
}

TEST_F(SceneParserTextures, VkrtRefusesAnEmbeddedPngBombInBoundedMemory)
{
    // vkrt_cpu_tests is built alone by the sanitizer preset; vkrt reads the scene before any Vulkan call.
    if (!std::filesystem::exists(VKRT_BINARY)) GTEST_SKIP() << VKRT_BINARY << " is not built";
    // The whole bomb (1.7 MB; 4 GiB decoded as float RGBA) in a data: URI.
    const std::filesystem::path gltf = m_dir / "embedded.gltf";
    std::ofstream(gltf) << triangleGltf(embeddedPngMaterial(fileBytes(writePngBomb(m_dir / "bomb.png", 16384))));
    writeText(scenePath(), kCamera + kFileMaterialMesh);
    const std::filesystem::path output = m_dir / "out.exr";
    const ProcessResult result = runVkrt({"render", scenePath(), "-o", output.string()});
    EXPECT_EQ(result.exitCode, 2) << result.output;
    EXPECT_NE(result.output.find(budgetRefusal(scenePath(), gltf)), std::string::npos) << result.output;
    EXPECT_LT(result.peakResidentBytes, kBadInputMemoryLimit);
    EXPECT_FALSE(std::filesystem::exists(output));
}

struct BadTexture {
    const char* name;
    std::string body;
    std::string location; ///< "line:column"
    std::string message;
};

class SceneParserTexturesBad : public SceneParserTextures, public ::testing::WithParamInterface<BadTexture> {};

TEST_P(SceneParserTexturesBad, ReportsMessageAndPosition)
{
    const BadTexture& bad = GetParam();
    const std::string error = errorOf(bad.body);
    ASSERT_FALSE(error.empty()) << bad.name << ": no error";
    EXPECT_NE(error.find(scenePath() + ":" + bad.location + ": "), std::string::npos) << error;
    EXPECT_NE(error.find(bad.message), std::string::npos) << error;
}

const std::string kLambert = "[materials.m]\ntype = \"lambert\"\n";

const BadTexture kBadTextures[] = {
    {"MissingFile", kLambert + "albedo = { texture = \"absent.png\" }\n" + kSphere, "7:22", "absent.png"},
    {"NotAnImage", kLambert + "albedo = { texture = \"notes.png\" }\n" + kSphere, "7:22", "notes.png"},
    {"UnsupportedDepth", kLambert + "albedo = { texture = \"four-bit.png\" }\n" + kSphere, "7:22", "four-bit.png"},
    {"NoTextureKey", kLambert + "albedo = { scale = 2 }\n" + kSphere, "7:10", "'texture'"},
    {"MisspeltKey", kLambert + "albedo = { texure = \"grey.png\" }\n" + kSphere, "7:12",
     "unknown key 'texure'; did you mean 'texture'?"},
    {"ChannelOnAColour", kLambert + "albedo = { texture = \"grey.png\", channel = \"r\" }\n" + kSphere, "7:34",
     "unknown key 'channel'"},
    {"UnknownChannel",
     "[materials.m]\ntype = \"conductor\"\nroughness = { texture = \"grey.png\", channel = \"x\" }\n" + kSphere, "7:47",
     "unknown channel 'x'"},
    {"UnknownWrapMode", kLambert + "albedo = { texture = \"grey.png\", wrap = \"repet\" }\n" + kSphere, "7:41",
     "unknown wrap mode 'repet'; did you mean 'repeat'?"},
    {"UnknownFilter", kLambert + "albedo = { texture = \"grey.png\", filter = \"nearst\" }\n" + kSphere, "7:43",
     "unknown filter 'nearst'; did you mean 'nearest'?"},
    {"ZeroScale", kLambert + "albedo = { texture = \"grey.png\", scale = [1, 0] }\n" + kSphere, "7:46",
     "must not be zero"},
    {"ScaleTriple", kLambert + "albedo = { texture = \"grey.png\", scale = [1, 2, 3] }\n" + kSphere, "7:42",
     "a pair [su, sv]"},
    {"TexturedPlasticRoughness",
     "[materials.m]\ntype = \"plastic\"\nroughness = { texture = \"grey.png\" }\n" + kSphere, "7:13",
     "a plastic's roughness cannot be a texture"},
    {"NormalMapNotATable", kLambert + "normal_map = \"grey.png\"\n" + kSphere, "7:14", "expected a texture table"},
    {"NormalMapLinearKey", kLambert + "normal_map = { texture = \"grey.png\", linear = true }\n" + kSphere, "7:38",
     "unknown key 'linear'"},
    {"TexturedMeshWithoutUvs",
     kLambert + "albedo = { texture = \"grey.png\" }\n[[objects]]\nshape = \"mesh\"\nfile = \"no-uvs.obj\"\n"
                "material = \"m\"\n",
     "11:12", "has no texture coordinates"},
    {"EmissiveMaterialOnASphere", "[materials.m]\ntype = \"pbr\"\nemission = [1, 1, 1]\n" + kSphere, "12:12",
     "only meshes can use an emissive material"},
    {"ReservedMaterialName", "[materials.file]\ntype = \"lambert\"\n", "5:1", "reserved"},
};

INSTANTIATE_TEST_SUITE_P(AllCases, SceneParserTexturesBad, ::testing::ValuesIn(kBadTextures),
                         [](const auto& info) { return std::string(info.param.name); });

} // namespace
} // namespace vkrt::test
