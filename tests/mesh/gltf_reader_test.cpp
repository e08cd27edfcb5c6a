// The glTF reader (mesh/GltfReader.h) on files each test writes: exact node
// transforms of any size, meshes placed by several nodes and by
// EXT_mesh_gpu_instancing as instances of one mesh, primitives that differ
// in their attributes, strips and fans, sparse and interleaved accessors,
// normalized vertex colours, negative scales, scenes, and the extension rules.
#include "mesh/GltfReader.h"
#include "mesh/MeshGeometry.h"
#include "mesh/MeshLoader.h"
#include "scene/GltfScene.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

fs::path testDir()
{
    static const fs::path dir = freshTempDir("gltf-reader");
    return dir;
}

/// One triangle in the z = 0 plane: (0,0,0) (1,0,0) (0,1,0), with an optional uv set.
uint32_t triangleMesh(GltfBuilder& b, bool uvs = false, std::optional<uint32_t> material = {})
{
    json attributes = {{"POSITION", b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3")}};
    if (uvs) attributes["TEXCOORD_0"] = b.floats({0, 0, 1, 0, 0, 1}, "VEC2");
    return b.mesh(attributes, std::nullopt, 4, material);
}

TEST(GltfReader, SmallNodeTranslationsArePlacedExactly)
{
    // assimp's identity test (tolerance 1e-2) dropped translations like these.
    GltfBuilder b;
    const uint32_t mesh = triangleMesh(b);
    b.node({{"mesh", mesh}, {"translation", {0.001, -0.004, 0.0}}});
    b.node({{"mesh", mesh}, {"translation", {1e-7, 0.0, 0.0}}});
    const GltfModel model = readGltfModel(b.write(testDir() / "small.gltf"));
    ASSERT_EQ(model.instances.size(), 2u);
    EXPECT_EQ(model.instances[0].world[3], glm::dvec4(0.001, -0.004, 0.0, 1.0));
    EXPECT_EQ(model.instances[1].world[3], glm::dvec4(1e-7, 0.0, 0.0, 1.0));
    const MeshData flat = loadMeshFile(b.write(testDir() / "small2.gltf"));
    ASSERT_EQ(flat.triangles.size(), 2u);
    EXPECT_FLOAT_EQ(flat.positions[flat.triangles[0].x].x, 0.001f);
    EXPECT_FLOAT_EQ(flat.positions[flat.triangles[0].x].y, -0.004f);
    EXPECT_FLOAT_EQ(flat.positions[flat.triangles[1].y].x, 1.0f + 1e-7f);
}

TEST(GltfReader, AMeshPlacedTwiceAndByGpuInstancingIsOneMeshWithInstances)
{
    GltfBuilder b;
    const uint32_t mesh = triangleMesh(b);
    b.node({{"mesh", mesh}, {"translation", {5.0, 0.0, 0.0}}});
    const uint32_t translations = b.floats({0, 0, 0, 0, 2, 0, 0, 4, 0}, "VEC3");
    const uint32_t scales = b.floats({1, 1, 1, 2, 2, 2, 3, 3, 3}, "VEC3");
    b.node({{"mesh", mesh},
            {"translation", {0.0, 0.0, 1.0}},
            {"extensions",
             {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", translations}, {"SCALE", scales}}}}}}}});
    b.doc()["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
    b.doc()["extensionsRequired"] = {"EXT_mesh_gpu_instancing"};
    const GltfModel model = readGltfModel(b.write(testDir() / "instanced.gltf"));
    ASSERT_EQ(model.meshes.size(), 1u);
    EXPECT_EQ(model.meshes[0].triangles.size(), 1u);
    ASSERT_EQ(model.instances.size(), 4u);
    // The node's transform, then each copy's own (EXT_mesh_gpu_instancing: instance x node).
    EXPECT_EQ(model.instances[2].world[3], glm::dvec4(0.0, 2.0, 1.0, 1.0));
    EXPECT_EQ(model.instances[3].world[0][0], 3.0);
    EXPECT_TRUE(model.warnings.empty());
    // The scene keeps them as instances sharing one geometry.
    const Scene scene = parseGltfScene(b.write(testDir() / "instanced-scene.gltf").string());
    ASSERT_EQ(scene.meshes.size(), 4u);
    for (const Mesh& m : scene.meshes) EXPECT_EQ(m.geometry, scene.meshes[0].geometry);
}

TEST(GltfReader, PrimitivesWithAndWithoutTextureCoordinatesShareAFile)
{
    // The Khronos validator's rule: only a primitive whose material samples a
    // texture needs uvs; the others are fine without them.
    GltfBuilder b;
    b.doc()["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}, {{"name", "plain"}}};
    b.doc()["textures"] = {{{"source", 0}}};
    b.doc()["images"] = {{{"uri", "texture.png"}}};
    const uint32_t textured = triangleMesh(b, true, 0);
    const uint32_t plain = triangleMesh(b, false, 1);
    b.node({{"mesh", textured}});
    b.node({{"mesh", plain}, {"translation", {2.0, 0.0, 0.0}}});
    const GltfModel model = readGltfModel(b.write(testDir() / "mixed.gltf"));
    ASSERT_EQ(model.instances.size(), 2u);
    EXPECT_EQ(model.meshes[0].uvs.size(), 3u);
    EXPECT_TRUE(model.meshes[1].uvs.empty());
    // Flattened, the plain triangle gets (0, 0) uvs.
    const MeshData flat = flattenGltfModel(model);
    EXPECT_EQ(flat.uvs.size(), flat.positions.size());

    // A textured primitive without uvs is the error, and it is named.
    GltfBuilder bad;
    bad.doc()["materials"] = b.doc()["materials"];
    bad.doc()["textures"] = b.doc()["textures"];
    bad.doc()["images"] = b.doc()["images"];
    bad.node({{"mesh", triangleMesh(bad, false, 0)}});
    const std::string error = inputErrorOf([&] { readGltfModel(bad.write(testDir() / "bad-uvs.gltf")); });
    EXPECT_NE(error.find("meshes[0].primitives[0]"), std::string::npos) << error;
    EXPECT_NE(error.find("TEXCOORD_0"), std::string::npos) << error;
}

TEST(GltfReader, TheSecondUvSetIsReadWhereATextureReadsIt)
{
    // Material 0 reads its base colour through TEXCOORD_1 and its normal map
    // through KHR_texture_transform's texCoord override to 1; material 1 reads
    // set 0 only, so its primitive's TEXCOORD_1 (a lightmap's, say) is not kept.
    GltfBuilder b;
    b.doc()["materials"] = json::parse(R"([
        {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}},
         "normalTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": 1}}}},
        {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])");
    b.doc()["textures"] = {{{"source", 0}}};
    b.doc()["images"] = {{{"uri", "texture.png"}}};
    auto twoSets = [&](uint32_t material) {
        return b.mesh({{"POSITION", b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3")},
                       {"NORMAL", b.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3")},
                       {"TEXCOORD_0", b.floats({0, 0, 0, 0, 0, 0}, "VEC2")},
                       {"TEXCOORD_1", b.floats({0, 0, 1, 0, 0, 1}, "VEC2")}},
                      std::nullopt, 4, material);
    };
    b.node({{"mesh", twoSets(0)}});
    b.node({{"mesh", twoSets(1)}});
    const GltfModel model = readGltfModel(b.write(testDir() / "second-set.gltf"));
    ASSERT_EQ(model.meshes.size(), 2u);
    const MeshData& second = model.meshes[0];
    ASSERT_EQ(second.uvs1.size(), 3u);
    // v turned up, as set 0's (MeshData.h): file (1, 0) -> (1, 1), (0, 1) -> (0, 0).
    EXPECT_EQ(second.uvs1[1], glm::vec2(1.0f, 1.0f));
    EXPECT_EQ(second.uvs1[2], glm::vec2(0.0f, 0.0f));
    EXPECT_EQ(second.uvs[1], glm::vec2(0.0f, 1.0f));
    EXPECT_EQ(second.tangentUvSet, 1u) << "the normal map reads set 1: the tangents follow it";
    EXPECT_TRUE(model.meshes[1].uvs1.empty());
    EXPECT_EQ(model.meshes[1].tangentUvSet, 0u);
    // Set 1's tangent is along its increasing u: +x here (set 0 is degenerate and gives none).
    const auto geometry = makeMeshGeometry(second, NormalMode::File, "second-set.gltf");
    ASSERT_EQ(geometry->data.tangents.size(), 3u);
    EXPECT_NEAR(geometry->data.tangents[0].x, 1.0f, 1e-6f);

    // A file's TANGENT means what the tangents computed from its uvs mean:
    // w = +1 on a triangle whose file uvs are laid out as an image seen from
    // the front (u right, v down) is the computed handedness.
    GltfBuilder carried;
    carried.doc()["materials"] = json::parse(R"([{"normalTexture": {"index": 0}}])");
    carried.doc()["textures"] = b.doc()["textures"];
    carried.doc()["images"] = b.doc()["images"];
    auto uvTriangle = [&](GltfBuilder& builder, bool withTangents) {
        json attributes{{"POSITION", builder.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3")},
                        {"NORMAL", builder.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3")},
                        // Image up (+y here) is file v decreasing.
                        {"TEXCOORD_0", builder.floats({0, 1, 1, 1, 0, 0}, "VEC2")}};
        if (withTangents) attributes["TANGENT"] = builder.floats({1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1}, "VEC4");
        return builder.mesh(attributes, std::nullopt, 4, 0);
    };
    carried.node({{"mesh", uvTriangle(carried, true)}});
    const MeshData fromFile = readGltfModel(carried.write(testDir() / "carried.gltf")).meshes.at(0);
    GltfBuilder computed;
    computed.doc()["materials"] = carried.doc()["materials"];
    computed.doc()["textures"] = b.doc()["textures"];
    computed.doc()["images"] = b.doc()["images"];
    computed.node({{"mesh", uvTriangle(computed, false)}});
    const auto computedGeometry =
        makeMeshGeometry(readGltfModel(computed.write(testDir() / "computed.gltf")).meshes.at(0), NormalMode::File,
                         "computed.gltf");
    ASSERT_EQ(fromFile.tangents.size(), 3u);
    ASSERT_EQ(computedGeometry->data.tangents.size(), 3u);
    for (size_t v = 0; v < 3; ++v) {
        EXPECT_EQ(fromFile.tangents[v], glm::vec4(1, 0, 0, 1)) << "vertex " << v;
        EXPECT_NEAR(computedGeometry->data.tangents[v].x, 1.0f, 1e-6f) << "vertex " << v;
        EXPECT_EQ(computedGeometry->data.tangents[v].w, fromFile.tangents[v].w) << "vertex " << v;
    }

    // A primitive without the TEXCOORD_1 its material reads is refused, by name.
    GltfBuilder bad;
    bad.doc()["materials"] = b.doc()["materials"];
    bad.doc()["textures"] = b.doc()["textures"];
    bad.doc()["images"] = b.doc()["images"];
    bad.node({{"mesh", triangleMesh(bad, true, 0)}});
    const std::string error = inputErrorOf([&] { readGltfModel(bad.write(testDir() / "bad-uv1.gltf")); });
    EXPECT_NE(error.find("meshes[0].primitives[0]"), std::string::npos) << error;
    EXPECT_NE(error.find("TEXCOORD_1"), std::string::npos) << error;
}

TEST(GltfReader, PbrExtensionLayersAreReadWithTheirTextures)
{
    // KHR_materials_specular, _sheen and _clearcoat: every factor, and each
    // texture with its own uv set; the pbr material gets them as its layers.
    GltfBuilder b;
    b.doc()["extensionsUsed"] = {"KHR_materials_specular", "KHR_materials_sheen", "KHR_materials_clearcoat"};
    b.doc()["materials"] = json::parse(R"([{
        "extensions": {
          "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [2, 1, 0.5],
                                     "specularTexture": {"index": 0}, "specularColorTexture": {"index": 0}},
          "KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.4, 0.2], "sheenRoughnessFactor": 0.6,
                                  "sheenColorTexture": {"index": 0, "texCoord": 1, "extensions":
                                      {"KHR_texture_transform": {"scale": [2, 3]}}}},
          "KHR_materials_clearcoat": {"clearcoatFactor": 1, "clearcoatRoughnessFactor": 0.1,
                                      "clearcoatRoughnessTexture": {"index": 0},
                                      "clearcoatNormalTexture": {"index": 0}}}}])");
    b.doc()["textures"] = {{{"source", 0}}};
    b.doc()["images"] = {{{"uri", "texture.png"}}};
    b.node({{"mesh", b.mesh({{"POSITION", b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3")},
                             {"TEXCOORD_0", b.floats({0, 0, 1, 0, 0, 1}, "VEC2")},
                             {"TEXCOORD_1", b.floats({0, 0, 1, 0, 0, 1}, "VEC2")}},
                            std::nullopt, 4, 0)}});
    const GltfModel model = readGltfModel(b.write(testDir() / "layers.gltf"));
    EXPECT_TRUE(model.warnings.empty()) << model.warnings.front();
    const FileMaterial& m = model.materials.at(0);
    EXPECT_EQ(m.specularFactor, 0.5f);
    EXPECT_EQ(m.specularColorFactor, glm::vec3(2.0f, 1.0f, 0.5f));
    EXPECT_TRUE(m.specularTexture && m.specularColorTexture);
    EXPECT_EQ(m.sheenColorFactor, glm::vec3(0.9f, 0.4f, 0.2f));
    EXPECT_EQ(m.sheenRoughnessFactor, 0.6f);
    ASSERT_TRUE(m.sheenColorTexture);
    EXPECT_EQ(m.sheenColorTexture->texCoord, 1u);
    EXPECT_EQ(m.sheenColorTexture->scale, glm::dvec2(2.0, 3.0)) << "a layer texture's KHR_texture_transform";
    EXPECT_FALSE(model.meshes.at(0).uvs1.empty()) << "the sheen texture reads TEXCOORD_1";
    EXPECT_EQ(m.clearcoatFactor, 1.0f);
    EXPECT_EQ(m.clearcoatRoughnessFactor, 0.1f);
    EXPECT_TRUE(m.clearcoatRoughnessTexture && m.clearcoatNormalTexture && !m.clearcoatTexture);

    // Out of range factors are errors naming the file and the material.
    GltfBuilder bad;
    bad.doc()["materials"] = json::parse(R"([{"extensions": {"KHR_materials_sheen": {"sheenRoughnessFactor": 2}}}])");
    bad.node({{"mesh", triangleMesh(bad, false, 0)}});
    const std::string error = inputErrorOf([&] { readGltfModel(bad.write(testDir() / "bad-sheen.gltf")); });
    EXPECT_NE(error.find("bad-sheen.gltf"), std::string::npos) << error;
    EXPECT_NE(error.find("sheenRoughnessFactor"), std::string::npos) << error;
}

TEST(GltfReader, StripsAndFansBecomeTrianglesWithTheirWinding)
{
    GltfBuilder b;
    const uint32_t positions = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 1, 2, 0}, "VEC3");
    const uint32_t strip = b.mesh({{"POSITION", positions}}, std::nullopt, 5);
    const uint32_t fan = b.mesh({{"POSITION", positions}}, std::nullopt, 6);
    const uint32_t lines = b.mesh({{"POSITION", positions}}, std::nullopt, 1);
    b.node({{"mesh", strip}});
    b.node({{"mesh", fan}});
    b.node({{"mesh", lines}});
    const GltfModel model = readGltfModel(b.write(testDir() / "modes.gltf"));
    // glTF 3.7.2.1: strip triangle i = {i, i + 1 + i % 2, i + 2 - i % 2}; fan = {i, i + 1, 0}.
    ASSERT_EQ(model.meshes[0].triangles.size(), 3u);
    EXPECT_EQ(model.meshes[0].triangles[1], glm::uvec3(1, 3, 2));
    ASSERT_EQ(model.meshes[1].triangles.size(), 3u);
    EXPECT_EQ(model.meshes[1].triangles[0], glm::uvec3(1, 2, 0));
    // Every strip triangle faces +z like the first (counter-clockwise seen from +z).
    for (const glm::uvec3& t : model.meshes[0].triangles) {
        const auto& p = model.meshes[0].positions;
        EXPECT_GT(glm::cross(p[t.y] - p[t.x], p[t.z] - p[t.x]).z, 0.0f);
    }
    EXPECT_TRUE(model.meshes[2].triangles.empty());
    EXPECT_EQ(model.instances.size(), 2u); // the lines are not placed
    ASSERT_EQ(model.warnings.size(), 1u);
    EXPECT_NE(model.warnings[0].find("lines"), std::string::npos);
}

TEST(GltfReader, SparseInterleavedAndNormalizedAccessors)
{
    GltfBuilder b;
    // Positions with no bufferView (zeros), made a triangle by a sparse substitution of elements 1 and 2.
    const uint32_t sparseIndices = b.accessor(std::vector<uint16_t>{1, 2}, "SCALAR", 5123);
    const uint32_t sparseValues = b.floats({1, 0, 0, 0, 1, 0}, "VEC3");
    json& accessors = b.doc()["accessors"];
    json sparse = {{"count", 2},
                   {"indices", {{"bufferView", accessors[sparseIndices]["bufferView"]}, {"componentType", 5123}}},
                   {"values", {{"bufferView", accessors[sparseValues]["bufferView"]}}}};
    accessors.push_back({{"componentType", 5126}, {"count", 3}, {"type", "VEC3"}, {"sparse", sparse}});
    const uint32_t positions = uint32_t(accessors.size() - 1);
    // Colours as normalized unsigned bytes: 255 is 1, 51 is 0.2.
    const uint32_t colors = b.accessor(std::vector<uint8_t>{255, 51, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255}, "VEC4",
                                       5121, /*normalized=*/true);
    b.node({{"mesh", b.mesh({{"POSITION", positions}, {"COLOR_0", colors}})}});
    const GltfModel model = readGltfModel(b.write(testDir() / "sparse.gltf"));
    const MeshData& mesh = model.meshes[0];
    ASSERT_EQ(mesh.positions.size(), 3u);
    EXPECT_EQ(mesh.positions[0], glm::vec3(0.0f));
    EXPECT_EQ(mesh.positions[1], glm::vec3(1, 0, 0));
    EXPECT_EQ(mesh.positions[2], glm::vec3(0, 1, 0));
    ASSERT_EQ(mesh.colors.size(), 3u);
    EXPECT_FLOAT_EQ(mesh.colors[0].r, 1.0f);
    EXPECT_FLOAT_EQ(mesh.colors[0].g, 0.2f);
    EXPECT_FLOAT_EQ(mesh.colors[1].g, 1.0f);
    EXPECT_FLOAT_EQ(mesh.colors[2].b, 1.0f);

    // Interleaved: position and normal in one view with byteStride 24.
    GltfBuilder i;
    const uint32_t both = i.floats({0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 0, 1}, "VEC3");
    json& view = i.doc()["bufferViews"][i.doc()["accessors"][both]["bufferView"].get<size_t>()];
    view["byteStride"] = 24;
    i.doc()["accessors"][both]["count"] = 3;
    json normal = i.doc()["accessors"][both];
    normal["byteOffset"] = 12;
    i.doc()["accessors"].push_back(normal);
    i.node({{"mesh", i.mesh({{"POSITION", both}, {"NORMAL", 1}})}});
    const MeshData interleaved = readGltfModel(i.write(testDir() / "interleaved.gltf")).meshes[0];
    EXPECT_EQ(interleaved.positions[2], glm::vec3(0, 1, 0));
    EXPECT_EQ(interleaved.normals[1], glm::vec3(0, 0, 1));
}

TEST(GltfReader, ANegativeScaleKeepsTheFrontSide)
{
    // glTF 3.7.4: a mirroring transform reverses the winding, so the same
    // side stays the front. Flattened, the triangle's winding normal follows
    // the transformed vertex normal.
    GltfBuilder b;
    const uint32_t positions = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    const uint32_t normals = b.floats({0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
    b.node({{"mesh", b.mesh({{"POSITION", positions}, {"NORMAL", normals}})}, {"scale", {-1.0, 1.0, 1.0}}});
    const MeshData flat = loadMeshFile(b.write(testDir() / "mirror.gltf"));
    const glm::uvec3 t = flat.triangles[0];
    const glm::vec3 winding =
        glm::cross(flat.positions[t.y] - flat.positions[t.x], flat.positions[t.z] - flat.positions[t.x]);
    EXPECT_GT(glm::dot(winding, flat.normals[t.x]), 0.0f);
    EXPECT_EQ(flat.normals[t.x], glm::vec3(0, 0, 1));
}

TEST(GltfReader, ScenesAreChosenByNameOrIndex)
{
    GltfBuilder b;
    const uint32_t mesh = triangleMesh(b);
    b.node({{"mesh", mesh}});
    b.node({{"mesh", mesh}, {"translation", {3, 0, 0}}});
    b.doc()["scenes"] = {{{"name", "left"}, {"nodes", {0}}}, {{"name", "both"}, {"nodes", {0, 1}}}};
    b.doc()["scene"] = 1;
    const fs::path file = b.write(testDir() / "scenes.gltf");
    EXPECT_EQ(readGltfModel(file).instances.size(), 2u);
    GltfReadOptions options;
    options.scene = "left";
    EXPECT_EQ(readGltfModel(file, options).instances.size(), 1u);
    options.scene = "0";
    EXPECT_EQ(readGltfModel(file, options).sceneName, "left");
    options.scene = "right";
    const std::string error = inputErrorOf([&] { readGltfModel(file, options); });
    EXPECT_NE(error.find("--scene right"), std::string::npos) << error;
    EXPECT_NE(error.find("1 ('both')"), std::string::npos) << error;
}

TEST(GltfReader, RequiredExtensionsMustBeImplementedUsedOnesAreNamedOnce)
{
    GltfBuilder b;
    b.node({{"mesh", triangleMesh(b)}});
    b.doc()["extensionsUsed"] = {"KHR_materials_diffuse_transmission", "KHR_lights_punctual"};
    const GltfModel model = readGltfModel(b.write(testDir() / "used.gltf"));
    ASSERT_EQ(model.warnings.size(), 1u);
    EXPECT_NE(model.warnings[0].find("KHR_materials_diffuse_transmission"), std::string::npos);
    b.doc()["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    const std::string error = inputErrorOf([&] { readGltfModel(b.write(testDir() / "required.gltf")); });
    EXPECT_NE(error.find("extensionsRequired names KHR_draco_mesh_compression"), std::string::npos) << error;
}

TEST(GltfReader, AMaterialVariantReplacesTheMaterialsItMaps)
{
    // KHR_materials_variants: --variant picks each primitive's mapped
    // material; without it, the primitive's own; an unknown one lists them.
    GltfBuilder b;
    b.doc()["materials"] = {{{"name", "plain"}}, {{"name", "red"}}, {{"name", "blue"}}};
    b.doc()["extensionsUsed"] = {"KHR_materials_variants"};
    b.doc()["extensions"]["KHR_materials_variants"]["variants"] = json::array({{{"name", "Red"}}, {{"name", "Blue"}}});
    const uint32_t mesh = triangleMesh(b, false, 0);
    const json mappings = json::array({{{"material", 1}, {"variants", {0}}}, {{"material", 2}, {"variants", {1}}}});
    b.doc()["meshes"][mesh]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"] = mappings;
    b.node({{"mesh", mesh}});
    const fs::path file = b.write(testDir() / "variants.gltf");
    const GltfModel plain = readGltfModel(file);
    EXPECT_EQ(plain.meshes[0].triangleMaterials[0], 0u);
    EXPECT_TRUE(plain.warnings.empty()); // the extension is implemented
    GltfReadOptions options;
    options.variant = "Blue";
    EXPECT_EQ(readGltfModel(file, options).meshes[0].triangleMaterials[0], 2u);
    options.variant = "0";
    EXPECT_EQ(readGltfModel(file, options).meshes[0].triangleMaterials[0], 1u);
    options.variant = "Green";
    const std::string error = inputErrorOf([&] { readGltfModel(file, options); });
    EXPECT_NE(error.find("--variant Green"), std::string::npos) << error;
    EXPECT_NE(error.find("1 ('Blue')"), std::string::npos) << error;
}

TEST(GltfReader, BadAccessorsAndIndicesAreNamed)
{
    GltfBuilder b;
    const uint32_t positions = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    b.node({{"mesh", b.mesh({{"POSITION", positions}}, b.indices({0, 1, 7}))}});
    std::string error = inputErrorOf([&] { readGltfModel(b.write(testDir() / "index.gltf")); });
    EXPECT_NE(error.find("meshes[0].primitives[0].indices[2] is 7"), std::string::npos) << error;
    b.doc()["accessors"][positions]["count"] = 4; // past its bufferView
    error = inputErrorOf([&] { readGltfModel(b.write(testDir() / "count.gltf")); });
    EXPECT_NE(error.find("accessor 0"), std::string::npos) << error;
}

// glTF 3.7.2.1: a TRIANGLES primitive's vertex count is a multiple of 3; the
// sweep's 8 indices had their last two dropped without a word.
TEST(GltfReader, TrianglesOfAnIndexCountNotAMultipleOfThreeAreRefused)
{
    GltfBuilder b;
    const uint32_t positions = b.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, "VEC3");
    b.node({{"mesh", b.mesh({{"POSITION", positions}}, b.indices({0, 1, 2, 1, 3, 2, 0, 1}))}});
    const std::string error = inputErrorOf([&] { readGltfModel(b.write(testDir() / "eight.gltf")); });
    EXPECT_NE(error.find(
                  "eight.gltf: meshes[0].primitives[0]: a TRIANGLES primitive of 8 indices, not a multiple of 3"),
              std::string::npos)
        << error;
    GltfBuilder unindexed;
    const uint32_t four = unindexed.floats({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}, "VEC3");
    unindexed.node({{"mesh", unindexed.mesh({{"POSITION", four}})}});
    const std::string second = inputErrorOf([&] { readGltfModel(unindexed.write(testDir() / "four.gltf")); });
    EXPECT_NE(second.find("a TRIANGLES primitive of 4 vertices, not a multiple of 3"), std::string::npos) << second;
}

} // namespace
} // namespace vkrt::test
