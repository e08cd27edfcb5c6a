// glTF materials (src/mesh/FileMaterials.h) through loadMeshFile: the Cube
// and box01 assets, glTF files written here with known materials (factors,
// samplers, embedded and percent-encoded images, unsupported extensions,
// primitives in an order assimp renumbers), malformed materials; and
// decodeTextureImage, which reads the embedded images.
#include "io/ExrFile.h"
#include "mesh/MeshGeometry.h"
#include "mesh/MeshLoader.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"
#include "texture/TextureImage.h"
#include "util/Error.h"

#include "texture/TextureTestFiles.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>

namespace fs = std::filesystem;
using namespace vkrt;
using vkrt::test::dataUri;
using vkrt::test::put;
using vkrt::test::triangleBuffer;
using vkrt::test::triangleGltf;

using vkrt::test::assetsDir;

namespace {

fs::path cubeDir() { return assetsDir() / "gltf" / "Cube"; }

fs::path testDir()
{
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    return test::freshTempDir(std::string("materials-") + info->test_suite_name() + "-" + info->name());
}

fs::path writeFile(const fs::path& path, const std::string& bytes)
{
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    return path;
}

std::string readFile(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<uint8_t> bytesOf(const std::string& text) { return {text.begin(), text.end()}; }

std::string loadError(const fs::path& file)
{
    try {
        loadMeshFile(file);
    } catch (const InputError& error) {
        return error.what();
    }
    ADD_FAILURE() << "expected an InputError for " << file;
    return {};
}

bool mentions(const std::vector<std::string>& list, const std::string& word)
{
    return std::any_of(list.begin(), list.end(),
                       [&](const std::string& s) { return s.find(word) != std::string::npos; });
}

std::string joined(const std::vector<std::string>& list)
{
    std::string text;
    for (const std::string& s : list) text += "[" + s + "] ";
    return text;
}

} // namespace

// ---------------------------------------------------------------------------
// Assets

TEST(MeshFileMaterials, CubeHasOneTexturedMetallicRoughnessMaterial)
{
    const MeshData cube = loadMeshFile(cubeDir() / "Cube.gltf");
    ASSERT_EQ(cube.materials.size(), 1u);
    const FileMaterial& m = cube.materials[0];
    EXPECT_EQ(m.name, "Cube");
    EXPECT_EQ(m.fileIndex, 0);
    ASSERT_TRUE(m.baseColorTexture);
    EXPECT_TRUE(fs::equivalent(m.baseColorTexture->file, cubeDir() / "Cube_BaseColor.png"));
    EXPECT_FALSE(m.baseColorTexture->embedded);
    ASSERT_TRUE(m.metallicRoughnessTexture);
    EXPECT_TRUE(fs::equivalent(m.metallicRoughnessTexture->file, cubeDir() / "Cube_MetallicRoughness.png"));
    // Cube.gltf states no factors: glTF's defaults, 1.
    EXPECT_EQ(m.baseColorFactor, glm::vec4(1.0f));
    EXPECT_EQ(m.metallicFactor, 1.0f);
    EXPECT_EQ(m.roughnessFactor, 1.0f);
    EXPECT_EQ(m.emissiveFactor, glm::vec3(0.0f));
    EXPECT_FALSE(m.normalTexture);
    EXPECT_FALSE(m.emissiveTexture);
    EXPECT_EQ(m.alphaMode, AlphaMode::Opaque);
    EXPECT_FALSE(m.doubleSided);
    // Its sampler is {}: repeat both ways.
    EXPECT_EQ(m.baseColorTexture->wrapU, TextureWrap::Repeat);
    EXPECT_EQ(m.baseColorTexture->wrapV, TextureWrap::Repeat);
    EXPECT_TRUE(m.unsupported.empty()) << joined(m.unsupported);
    ASSERT_EQ(cube.triangleMaterials.size(), cube.triangles.size());
    for (uint32_t material : cube.triangleMaterials) EXPECT_EQ(material, 0u);
}

TEST(MeshFileMaterials, GlbBoxWithEmbeddedBufferLoadsItsFactors)
{
    const MeshData box = loadMeshFile(assetsDir() / "gltf" / "box01.glb");
    ASSERT_EQ(box.materials.size(), 1u);
    // box01.glb's JSON: baseColorFactor [0.5, 0.5, 0.5, 1], metallic 0, roughness 0.33000001311302185.
    EXPECT_EQ(box.materials[0].baseColorFactor, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
    EXPECT_EQ(box.materials[0].metallicFactor, 0.0f);
    EXPECT_EQ(box.materials[0].roughnessFactor, 0.33f);
    EXPECT_FALSE(box.materials[0].baseColorTexture);
    EXPECT_EQ(box.triangleMaterials, std::vector<uint32_t>(12, 0u));
    // It has uvs and no TANGENT: the geometry computes them.
    EXPECT_TRUE(box.tangents.empty());
    const auto geometry = makeMeshGeometry(box, NormalMode::File, "box01.glb");
    EXPECT_EQ(geometry->data.tangents.size(), box.positions.size());
}

TEST(MeshFileMaterials, ObjAndPlyHaveNone)
{
    const MeshData spot = loadMeshFile(assetsDir() / "spot.obj");
    EXPECT_TRUE(spot.materials.empty());
    EXPECT_TRUE(spot.triangleMaterials.empty());
    EXPECT_TRUE(loadMeshFile(assetsDir() / "bunny_lowres.ply").materials.empty());
}

// ---------------------------------------------------------------------------
// Written files

TEST(MeshFileMaterials, FactorsSamplersImagesAndEveryUnsupportedFeature)
{
    const fs::path dir = testDir();
    const std::string png = readFile(cubeDir() / "Cube_MetallicRoughness.png");
    const std::string rest = R"(
  "extensionsUsed": ["KHR_texture_transform", "KHR_materials_diffuse_transmission", "KHR_lights_punctual"],
  "materials": [{"name": "Coated", "alphaMode": "BLEND", "doubleSided": true, "emissiveFactor": [1, 0.5, 0],
    "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 0.75], "metallicFactor": 0.25, "roughnessFactor": 0.5,
      "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [2, 3], "offset": [0.5, 0.25],
                                                                                 "rotation": 0.125}}}},
    "normalTexture": {"index": 1, "scale": 0.5, "texCoord": 1},
    "extensions": {"KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1.0}}}],
  "textures": [{"source": 0, "sampler": 0}, {"source": 1}],
  "samplers": [{"wrapS": 33071, "wrapT": 33648}],
  "images": [{"uri": "base%20color.png"}, {"uri": ")" +
                             dataUri("image/png", png) + R"("}])";
    const MeshData mesh = loadMeshFile(writeFile(dir / "coated.gltf", triangleGltf(rest)));
    ASSERT_EQ(mesh.materials.size(), 1u);
    const FileMaterial& m = mesh.materials[0];
    EXPECT_EQ(m.name, "Coated");
    EXPECT_EQ(m.baseColorFactor, glm::vec4(0.5f, 0.25f, 1.0f, 0.75f));
    EXPECT_EQ(m.metallicFactor, 0.25f);
    EXPECT_EQ(m.roughnessFactor, 0.5f);
    EXPECT_EQ(m.emissiveFactor, glm::vec3(1.0f, 0.5f, 0.0f));
    EXPECT_EQ(m.alphaMode, AlphaMode::Blend);
    EXPECT_TRUE(m.doubleSided);
    // The URI is percent-decoded and resolved against the file's folder; the file need not exist.
    ASSERT_TRUE(m.baseColorTexture);
    EXPECT_EQ(m.baseColorTexture->file, dir / "base color.png");
    EXPECT_EQ(m.baseColorTexture->wrapU, TextureWrap::Clamp);  // 33071 CLAMP_TO_EDGE
    EXPECT_EQ(m.baseColorTexture->wrapV, TextureWrap::Mirror); // 33648 MIRRORED_REPEAT
    // The data: URI image: its bytes, which decode as the file they came from.
    ASSERT_TRUE(m.normalTexture);
    EXPECT_EQ(m.normalScale, 0.5f);
    EXPECT_TRUE(m.normalTexture->file.empty());
    ASSERT_TRUE(m.normalTexture->embedded);
    EXPECT_EQ(*m.normalTexture->embedded, bytesOf(png));
    EXPECT_EQ(m.normalTexture->wrapU, TextureWrap::Repeat);
    const TextureImage decoded = decodeTextureImage(*m.normalTexture->embedded, m.normalTexture->name, true);
    EXPECT_EQ(decoded.pixels.rgba, loadTextureImage(cubeDir() / "Cube_MetallicRoughness.png", true).pixels.rgba);
    // KHR_texture_transform is read (scene/FileMaterialImport.cpp turns it into vkrt's uv space).
    EXPECT_EQ(m.baseColorTexture->scale, glm::dvec2(2.0, 3.0));
    EXPECT_EQ(m.baseColorTexture->offset, glm::dvec2(0.5, 0.25));
    EXPECT_EQ(m.baseColorTexture->rotation, 0.125);
    EXPECT_FALSE(mentions(m.unsupported, "KHR_texture_transform")) << joined(m.unsupported);
    // Each unsupported feature named.
    EXPECT_TRUE(mentions(m.unsupported, "KHR_materials_diffuse_transmission")) << joined(m.unsupported);
    EXPECT_FALSE(mentions(m.unsupported, "alphaMode")) << joined(m.unsupported); // honoured (lib/alpha.glsl)
    // Each texture reads its own uv set: mixing TEXCOORD_0 and TEXCOORD_1 is nothing to warn about.
    EXPECT_FALSE(mentions(m.unsupported, "TEXCOORD")) << joined(m.unsupported);
    // KHR_lights_punctual is implemented, and the file places no light: nothing to say.
    EXPECT_FALSE(mentions(m.unsupported, "KHR_lights_punctual")) << joined(m.unsupported);
    EXPECT_EQ(m.unsupported.size(), 1u) << joined(m.unsupported);
}

// The samplers' magFilter and minFilter (glTF 2.0, 5.26), one file per case.
TEST(MeshFileMaterials, SamplerFiltersAreRead)
{
    using Mip = TextureFilter::Mip;
    const std::vector<std::pair<std::string, TextureFilter>> cases{
        {R"({"magFilter": 9728, "minFilter": 9728})", {true, true, Mip::None}},    // NEAREST, NEAREST
        {R"({"magFilter": 9729, "minFilter": 9729})", {false, false, Mip::None}},  // LINEAR, LINEAR
        {R"({"minFilter": 9984})", {false, true, Mip::Nearest}},                   // NEAREST_MIPMAP_NEAREST
        {R"({"minFilter": 9985})", {false, false, Mip::Nearest}},                  // LINEAR_MIPMAP_NEAREST
        {R"({"minFilter": 9986})", {false, true, Mip::Linear}},                    // NEAREST_MIPMAP_LINEAR
        {R"({"magFilter": 9728, "minFilter": 9987})", {true, false, Mip::Linear}}, // NEAREST, LINEAR_MIPMAP_LINEAR
        {R"({"wrapS": 33071})", {}},                                               // undefined: vkrt's default
    };
    for (size_t i = 0; i < cases.size(); ++i) {
        SCOPED_TRACE(cases[i].first);
        const std::string rest = R"("materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
            "textures": [{"source": 0, "sampler": 0}], "samplers": [)" +
                                 cases[i].first + R"(], "images": [{"uri": "grey.png"}])";
        const MeshData mesh =
            loadMeshFile(writeFile(testDir() / ("filters-" + std::to_string(i) + ".gltf"), triangleGltf(rest)));
        ASSERT_EQ(mesh.materials.size(), 1u);
        ASSERT_TRUE(mesh.materials[0].baseColorTexture);
        EXPECT_EQ(mesh.materials[0].baseColorTexture->filter, cases[i].second);
        EXPECT_TRUE(mesh.materials[0].unsupported.empty()) << joined(mesh.materials[0].unsupported);
    }
}

// A filter glTF does not define is an error naming the file, the material and the sampler.
TEST(MeshFileMaterials, InvalidSamplerFiltersAreErrorsNamingTheFileAndSampler)
{
    const std::vector<std::pair<std::string, std::string>> cases{
        {R"({"magFilter": 9984})", "sampler 1: magFilter is 9984; glTF allows 9728 (NEAREST) and 9729 (LINEAR)"},
        {R"({"minFilter": 9730})", "sampler 1: minFilter is 9730; glTF allows 9728 (NEAREST), 9729 (LINEAR) and "
                                   "9984 to 9987 (the MIPMAP filters)"},
        {R"({"minFilter": "LINEAR"})", "sampler 1: minFilter is \"LINEAR\";"},
        {R"({"magFilter": -9728})", "sampler 1: magFilter is -9728;"},
    };
    for (const auto& [sampler, expected] : cases) {
        SCOPED_TRACE(sampler);
        const std::string rest =
            R"("materials": [{"name": "Pixel", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
               "textures": [{"source": 0, "sampler": 1}], "samplers": [{}, )" +
            sampler + R"(], "images": [{"uri": "grey.png"}])";
        const fs::path file = writeFile(testDir() / "bad-filter.gltf", triangleGltf(rest));
        const std::string message = loadError(file);
        EXPECT_EQ(message.rfind(file.string() + ": material 0 'Pixel': baseColorTexture's sampler 1: ", 0), 0u)
            << message;
        EXPECT_NE(message.find(expected), std::string::npos) << message;
    }
}

TEST(MeshFileMaterials, MaskAndBlendAreReadAndNotListedAsUnsupported)
{
    const std::string mask = R"("materials": [{"alphaMode": "MASK", "alphaCutoff": 0.25}])";
    const MeshData masked = loadMeshFile(writeFile(testDir() / "mask.gltf", triangleGltf(mask)));
    ASSERT_EQ(masked.materials.size(), 1u);
    EXPECT_EQ(masked.materials[0].alphaMode, AlphaMode::Mask);
    EXPECT_EQ(masked.materials[0].alphaCutoff, 0.25f);
    EXPECT_TRUE(masked.materials[0].unsupported.empty()) << joined(masked.materials[0].unsupported);

    const std::string blend = R"("materials": [{"alphaMode": "BLEND"}])";
    const MeshData blended = loadMeshFile(writeFile(testDir() / "blend.gltf", triangleGltf(blend)));
    EXPECT_EQ(blended.materials.at(0).alphaMode, AlphaMode::Blend);
    EXPECT_TRUE(blended.materials[0].unsupported.empty()) << joined(blended.materials[0].unsupported);

    const std::string opaque = R"("materials": [{"alphaMode": "OPAQUE"}])";
    const MeshData plain = loadMeshFile(writeFile(testDir() / "opaque.gltf", triangleGltf(opaque)));
    EXPECT_TRUE(plain.materials.at(0).unsupported.empty()) << joined(plain.materials[0].unsupported);
}

TEST(MeshFileMaterials, PrimitiveWithoutMaterialGetsGltfsDefault)
{
    const MeshData mesh = loadMeshFile(writeFile(testDir() / "default.gltf", triangleGltf("\"extras\": {}", "")));
    ASSERT_EQ(mesh.materials.size(), 1u);
    const FileMaterial& m = mesh.materials[0];
    EXPECT_EQ(m.fileIndex, -1);
    EXPECT_EQ(m.baseColorFactor, glm::vec4(1.0f)); // glTF 2.0 spec, material defaults
    EXPECT_EQ(m.metallicFactor, 1.0f);
    EXPECT_EQ(m.roughnessFactor, 1.0f);
    EXPECT_FALSE(m.baseColorTexture);
    EXPECT_EQ(mesh.triangleMaterials, std::vector<uint32_t>{0u});
}

TEST(MeshFileMaterials, TrianglesKeepTheirMaterialsWhenAssimpRenumbersThem)
{
    // Three triangles at x = 0, 10, 20. Node 0 (mesh 0: material 2, then no
    // material) has child node 1 (mesh 1: material 0). Assimp reads a node's
    // children before its mesh, so it meets material 0 first; material 1 is unused.
    std::string buffer;
    for (float x : {0.f, 10.f, 20.f})
        for (float v : {x, 0.f, 0.f, x + 1.f, 0.f, 0.f, x, 1.f, 0.f}) put(buffer, v);
    const std::string json = R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, "children": [1]}, {"mesh": 1}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 2}, {"attributes": {"POSITION": 1}}]},
             {"primitives": [{"attributes": {"POSITION": 2}, "material": 0}]}],
  "materials": [{"name": "A", "pbrMetallicRoughness": {"roughnessFactor": 0.125}}, {"name": "B"},
                {"pbrMetallicRoughness": {"roughnessFactor": 0.875}, "extensions": {"KHR_materials_diffuse_transmission": {}}}],
  "extensionsUsed": ["KHR_materials_diffuse_transmission"],
  "buffers": [{"uri": ")" + dataUri("application/octet-stream", buffer) +
                             R"(", "byteLength": 108}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 108}],
  "accessors": [
    {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 0, "byteOffset": 36, "componentType": 5126, "count": 3, "type": "VEC3", "min": [10, 0, 0], "max": [11, 1, 0]},
    {"bufferView": 0, "byteOffset": 72, "componentType": 5126, "count": 3, "type": "VEC3", "min": [20, 0, 0], "max": [21, 1, 0]}]})";
    const MeshData mesh = loadMeshFile(writeFile(testDir() / "order.gltf", json));
    ASSERT_EQ(mesh.triangles.size(), 3u);
    ASSERT_EQ(mesh.materials.size(), 3u); // A, the unnamed one and the default; not B
    for (size_t t = 0; t < 3; ++t) {
        const FileMaterial& m = mesh.materials.at(mesh.triangleMaterials.at(t));
        const float x = mesh.positions[mesh.triangles[t].x].x;
        SCOPED_TRACE("triangle at x = " + std::to_string(x));
        if (x < 5.0f) {
            EXPECT_EQ(m.fileIndex, 2);
            EXPECT_EQ(m.roughnessFactor, 0.875f);
            EXPECT_TRUE(mentions(m.unsupported, "KHR_materials_diffuse_transmission")) << joined(m.unsupported);
        } else if (x < 15.0f) {
            EXPECT_EQ(m.fileIndex, -1);
            EXPECT_EQ(m.roughnessFactor, 1.0f);
            EXPECT_TRUE(m.unsupported.empty()) << joined(m.unsupported);
        } else {
            EXPECT_EQ(m.fileIndex, 0);
            EXPECT_EQ(m.name, "A");
            EXPECT_EQ(m.roughnessFactor, 0.125f);
            EXPECT_TRUE(m.unsupported.empty()) << joined(m.unsupported);
        }
    }
}

TEST(MeshFileMaterials, EmbeddedImageInAGlb)
{
    // A .glb whose BIN chunk holds the triangle and, after it, a PNG (image bufferView 4).
    const std::string png = readFile(cubeDir() / "Cube_MetallicRoughness.png");
    std::string bin = triangleBuffer() + png;
    bin.append((4 - bin.size() % 4) % 4, '\0');
    std::string json = R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"material": 0, "attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 3}]}],
  "materials": [{"pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 0}}}],
  "textures": [{"source": 0}], "images": [{"bufferView": 4, "mimeType": "image/png"}],
  "buffers": [{"byteLength": )" +
                       std::to_string(bin.size()) + R"(}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                  {"buffer": 0, "byteOffset": 60, "byteLength": 24}, {"buffer": 0, "byteOffset": 84, "byteLength": 6},
                  {"buffer": 0, "byteOffset": 92, "byteLength": )" +
                       std::to_string(png.size()) + R"(}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
    {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}]})";
    const fs::path file = writeFile(testDir() / "embedded.glb", vkrt::test::glbBytes(json, bin));
    const MeshData mesh = loadMeshFile(file);
    ASSERT_EQ(mesh.materials.size(), 1u);
    ASSERT_TRUE(mesh.materials[0].metallicRoughnessTexture);
    const FileTexture& texture = *mesh.materials[0].metallicRoughnessTexture;
    ASSERT_TRUE(texture.embedded);
    EXPECT_EQ(*texture.embedded, bytesOf(png));
    EXPECT_EQ(texture.name.rfind(file.string(), 0), 0u) << texture.name; // messages start with the file
}

// ---------------------------------------------------------------------------
// Malformed materials: an InputError naming the file

TEST(MeshFileMaterials, MalformedMaterialsAreErrorsNamingTheFile)
{
    const std::vector<std::pair<std::string, std::string>> cases{
        {"texture-index", R"("materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 5}}}])"},
        {"roughness", R"("materials": [{"name": "Rough", "pbrMetallicRoughness": {"roughnessFactor": 2}}])"},
        {"colour", R"("materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, -1, 1, 1]}}])"},
        {"image-index", R"("materials": [{"normalTexture": {"index": 0}}], "textures": [{"source": 3}])"},
    };
    for (const auto& [name, rest] : cases) {
        SCOPED_TRACE(name);
        const fs::path file = writeFile(testDir() / (name + ".gltf"), triangleGltf(rest));
        const std::string message = loadError(file);
        EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0u) << message;
    }
    const fs::path rough = testDir() / "roughness.gltf";
    writeFile(rough, triangleGltf(cases[1].second));
    const std::string message = loadError(rough);
    EXPECT_NE(message.find("roughnessFactor"), std::string::npos) << message;
    EXPECT_NE(message.find("'Rough'"), std::string::npos) << message;
}

// ---------------------------------------------------------------------------
// decodeTextureImage

TEST(TextureImageDecode, PngBytesDecodeExactlyAsTheFile)
{
    for (const bool linear : {false, true}) {
        const fs::path file = cubeDir() / "Cube_BaseColor.png";
        const TextureImage fromFile = loadTextureImage(file, linear);
        const TextureImage fromBytes = decodeTextureImage(bytesOf(readFile(file)), "embedded", linear);
        EXPECT_EQ(fromBytes.pixels.width, fromFile.pixels.width);
        EXPECT_EQ(fromBytes.pixels.height, fromFile.pixels.height);
        EXPECT_EQ(fromBytes.encoding, fromFile.encoding);
        EXPECT_TRUE(fromBytes.pixels.rgba == fromFile.pixels.rgba);
    }
}

TEST(TextureImageDecode, ExrBytesDecodeExactlyAsTheFile)
{
    Image rgb(3, 2);
    for (size_t i = 0; i < rgb.rgb.size(); ++i) rgb.rgb[i] = 0.25f * float(i) + 0.1f;
    const fs::path file = testDir() / "linear.exr";
    writeExr(file, rgb, {});
    const TextureImage fromFile = loadTextureImage(file, false);
    const TextureImage fromBytes = decodeTextureImage(bytesOf(readFile(file)), "embedded.exr", false);
    EXPECT_EQ(fromBytes.pixels.width, 3u);
    EXPECT_EQ(fromBytes.pixels.height, 2u);
    EXPECT_EQ(fromBytes.encoding, TexelEncoding::Half);
    EXPECT_TRUE(fromBytes.pixels.rgba == fromFile.pixels.rgba);
    EXPECT_EQ(fromBytes.pixels.at(1, 0)[0], rgb.at(1, 0)[0]);
}

TEST(TextureImageDecode, BadBytesNameTheImage)
{
    const auto error = [](const std::string& bytes) {
        try {
            decodeTextureImage(bytesOf(bytes), "model.glb (embedded image 3)", false);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        ADD_FAILURE() << "no InputError";
        return std::string();
    };
    const std::string prefix = "model.glb (embedded image 3): ";
    EXPECT_EQ(error("").rfind(prefix, 0), 0u);
    const std::string garbage = error("this is not an image");
    EXPECT_EQ(garbage.rfind(prefix + "not an image file", 0), 0u) << garbage;
    const std::string exr = error(std::string("\x76\x2f\x31\x01", 4) + "garbage");
    EXPECT_EQ(exr.rfind(prefix + "not a readable EXR file", 0), 0u) << exr;
    const std::string png = readFile(cubeDir() / "Cube_MetallicRoughness.png");
    const std::string truncated = error(png.substr(0, png.size() / 2));
    EXPECT_EQ(truncated.rfind(prefix, 0), 0u) << truncated;
}

// ---------------------------------------------------------------------------
// Buffer bounds, checked before assimp (whose glTF reader copies past them)

TEST(MeshFileMaterials, AccessorBeyondItsBufferViewIsAnErrorNotAnOverflow)
{
    // The fuzzer's find: 6 VEC3 floats (72 bytes) from byte 72 of a 108-byte view.
    std::string buffer(108, '\0');
    const std::string json = R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"uri": ")" + dataUri("application/octet-stream", buffer) +
                             R"(", "byteLength": 108}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 108}],
  "accessors": [{"bufferView": 0, "byteOffset": 72, "componentType": 5126, "count": 6, "type": "VEC3"}]})";
    const fs::path file = writeFile(testDir() / "overflow.gltf", json);
    const std::string message = loadError(file);
    EXPECT_EQ(message.rfind(file.string() + ": accessor 0 needs 144 bytes of bufferView 0, which has 108", 0), 0u)
        << message;

    std::string view = json;
    const std::string viewLength = R"("byteOffset": 0, "byteLength": 108})";
    view.replace(view.find(viewLength), viewLength.size(), R"("byteOffset": 0, "byteLength": 200})");
    const fs::path viewFile = writeFile(testDir() / "view.gltf", view);
    const std::string viewMessage = loadError(viewFile);
    EXPECT_EQ(viewMessage.rfind(viewFile.string() + ": bufferView 0 ends at byte 200 of a buffer of 108 bytes", 0), 0u)
        << viewMessage;
}

TEST(MeshFileMaterials, NonAsciiNamesMatchAndDuplicateKeysAreRefused)
{
    const std::string named = "\"materials\": [{\"name\": \"Mat\xc3\xa9riau\"}]"; // UTF-8 bytes in the file
    const MeshData mesh = loadMeshFile(writeFile(testDir() / "utf8.gltf", triangleGltf(named)));
    ASSERT_EQ(mesh.materials.size(), 1u);
    EXPECT_EQ(mesh.materials[0].fileIndex, 0); // matched by name although the name is not ASCII
    EXPECT_EQ(mesh.materials[0].name, "Mat\xc3\xa9riau");

    const std::string twice = R"("materials": [{"alphaMode": "BLEND", "alphaMode": "OPAQUE"}])";
    const fs::path file = writeFile(testDir() / "twice.gltf", triangleGltf(twice));
    const std::string message = loadError(file);
    EXPECT_EQ(message.rfind(file.string() + ": the glTF JSON has the key 'alphaMode' twice", 0), 0u) << message;
}
