// Files a mesh file references (issue 26): glTF buffers and images and OBJ
// material libraries resolve inside the mesh file's folder unless the scene
// allows more; missing ones are named; node hierarchies and JSON nesting
// are bounded before assimp sees them (src/mesh/ReferencePolicy.h,
// FileMaterials.h). Every input is written here, in a fresh folder.
#include "mesh/FileMaterials.h"
#include "mesh/MeshGeometry.h"
#include "mesh/MeshLoader.h"
#include "scene/GltfScene.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"
#include "util/Error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

/// A fresh folder named after the running test.
fs::path testDir()
{
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    return freshTempDir(std::string("refs-") + info->test_suite_name() + "-" + info->name());
}

fs::path writeFile(const fs::path& path, const std::string& bytes)
{
    fs::create_directories(path.parent_path());
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path;
}

/// One triangle (0,0,0) (size,0,0) (0,size,0), indices 0 1 2: 44 bytes.
std::string triangleBytes(float size)
{
    std::string bytes;
    for (float v : {0.f, 0.f, 0.f, size, 0.f, 0.f, 0.f, size, 0.f}) put(bytes, v);
    for (uint16_t i : {0, 1, 2}) put(bytes, i);
    bytes.append(2, '\0');
    return bytes;
}

const std::string kInlineBuffer = dataUri("application/octet-stream", triangleBytes(1.0f));

/// A glTF 2.0 of one triangle read from buffer `uri` (none: a .glb's binary
/// chunk), with `nodes` (node 0 is the scene's root) and more top-level
/// members in `rest`.
std::string gltf(const std::string& uri, const std::string& nodes = R"([{"mesh": 0}])", const std::string& rest = "")
{
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": )" + nodes + R"(,
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "buffers": [{)" +
           (uri.empty() ? "" : R"("uri": ")" + uri + R"(", )") + R"("byteLength": 44}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}])" +
           rest + "}";
}

/// `depth` nodes, each the only child of the one before; the last holds the mesh.
std::string nodeChain(int depth)
{
    std::string nodes = "[";
    for (int i = 0; i + 1 < depth; ++i) nodes += R"({"children": [)" + std::to_string(i + 1) + "]}, ";
    return nodes + R"({"mesh": 0}])";
}

std::string fileText(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The message of the InputError loading `file` must throw.
std::string loadError(const fs::path& file, MeshLoadOptions options = {})
{
    try {
        loadMeshFile(file, options);
    } catch (const InputError& error) {
        return error.what();
    }
    ADD_FAILURE() << "expected an InputError for " << file;
    return {};
}

const MeshLoadOptions kAllowOutside{.allowOutsideReferences = true};

/// "../" `levels` times, built here so that no path in this file climbs out of the repository.
std::string up(int levels)
{
    std::string path;
    for (int i = 0; i < levels; ++i) path += "../";
    return path;
}

/// A scene-like tree: DIR/secret/tri2.bin (a triangle of size 5) and the
/// mesh folder DIR/scene/model, two levels below DIR.
struct Tree {
    fs::path root = testDir();
    fs::path model = root / "scene" / "model";
    fs::path secret = writeFile(root / "secret" / "tri2.bin", triangleBytes(5.0f));
};

// ---------------------------------------------------------------------------
// glTF buffers

TEST(MeshReferences, GltfBufferEscapingTheFolderIsRefusedNamingIt)
{
    const Tree tree;
    const fs::path file = writeFile(tree.model / "tri.gltf", gltf("../../secret/tri2.bin"));
    const std::string message = loadError(file);
    EXPECT_EQ(message.rfind(file.string() + ": buffer 0 references '../../secret/tri2.bin' outside its folder (", 0),
              0u)
        << message;
    EXPECT_NE(message.find(fs::canonical(tree.secret).string()), std::string::npos) << message;
    EXPECT_NE(message.find("allow_outside_references = true"), std::string::npos) << message;
}

TEST(MeshReferences, AbsoluteAndDeepEscapesToSystemFilesAreRefused)
{
    const Tree tree;
    for (const std::string& uri :
         {std::string("/etc/passwd"), up(40) + "etc/passwd", std::string("%2E%2E/%2E%2E/x.bin")}) {
        const fs::path file = writeFile(tree.model / "tri.gltf", gltf(uri));
        const std::string message = loadError(file);
        EXPECT_NE(message.find("buffer 0 references '" + uri + "' outside its folder"), std::string::npos) << message;
    }
}

TEST(MeshReferences, SymlinkInsideTheFolderPointingOutsideIsRefused)
{
    const Tree tree;
    fs::create_directories(tree.model);
    fs::create_symlink(tree.secret, tree.model / "link.bin");
    const fs::path file = writeFile(tree.model / "tri.gltf", gltf("link.bin"));
    const std::string message = loadError(file);
    EXPECT_NE(message.find("references 'link.bin' outside its folder"), std::string::npos) << message;
    EXPECT_NE(message.find("resolves to " + fs::canonical(tree.secret).string()), std::string::npos) << message;
}

TEST(MeshReferences, FilesInsideTheFolderLoadThroughSubfoldersAndInnerSymlinks)
{
    const Tree tree;
    writeFile(tree.model / "bin" / "tri.bin", triangleBytes(2.0f));
    fs::create_symlink(tree.model / "bin" / "tri.bin", tree.model / "inner-link.bin");
    for (const std::string uri : {"bin/tri.bin", "bin/../bin/tri.bin", "inner-link.bin"}) {
        const MeshData mesh = loadMeshFile(writeFile(tree.model / "tri.gltf", gltf(uri)));
        ASSERT_EQ(mesh.positions.size(), 3u) << uri;
        EXPECT_EQ(mesh.positions[1], glm::vec3(2, 0, 0)) << uri;
    }
}

TEST(MeshReferences, OptionAllowsReferencesOutsideTheFolder)
{
    const Tree tree;
    fs::create_directories(tree.model);
    fs::create_symlink(tree.secret, tree.model / "link.bin");
    for (const std::string& uri :
         {std::string("../../secret/tri2.bin"), std::string("link.bin"), fs::canonical(tree.secret).string()}) {
        const fs::path file = writeFile(tree.model / "tri.gltf", gltf(uri));
        EXPECT_NE(loadError(file).find("outside its folder"), std::string::npos) << uri;
        if (uri[0] == '/') continue; // assimp joins the folder and an absolute uri: no file
        const MeshData mesh = loadMeshFile(file, kAllowOutside);
        ASSERT_EQ(mesh.positions.size(), 3u) << uri;
        EXPECT_EQ(mesh.positions[1], glm::vec3(5, 0, 0)) << uri; // the secret buffer's triangle
    }
}

TEST(MeshReferences, MissingBufferFileIsNamed)
{
    const fs::path dir = testDir();
    const fs::path file = writeFile(dir / "tri.gltf", gltf("absent.bin"));
    const std::string message = loadError(file);
    EXPECT_EQ(message.rfind(file.string() + ": the referenced file 'absent.bin' cannot be read: ", 0), 0u) << message;
    EXPECT_NE(message.find((dir / "absent.bin").string() + ": no such file"), std::string::npos) << message;
}

// ---------------------------------------------------------------------------
// glTF images

/// triangleGltf's members for one material whose base colour is image `uri`.
std::string imageMaterial(const std::string& uri)
{
    return R"("materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
  "textures": [{"source": 0}], "images": [{"uri": ")" +
           uri + R"("}])";
}

TEST(MeshReferences, ImageUrisEscapingTheFolderAreRefused)
{
    const Tree tree;
    writeFile(tree.root / "outside.png", "not read");
    for (const std::string& uri : {std::string("../../outside.png"), (tree.root / "outside.png").string()}) {
        const fs::path file = writeFile(tree.model / "textured.gltf", triangleGltf(imageMaterial(uri)));
        const std::string message = loadError(file);
        EXPECT_EQ(message.rfind(file.string() + ": image 0 references '" + uri + "' outside its folder", 0), 0u)
            << message;
        // Allowed, the material names the file outside (the scene loads it as any texture).
        const MeshData mesh = loadMeshFile(file, kAllowOutside);
        ASSERT_EQ(mesh.materials.size(), 1u);
        ASSERT_TRUE(mesh.materials[0].baseColorTexture);
        EXPECT_EQ(fs::weakly_canonical(mesh.materials[0].baseColorTexture->file),
                  fs::weakly_canonical(tree.root / "outside.png"));
    }
}

TEST(MeshReferences, ImageUriInASubfolderIsKept)
{
    const fs::path dir = testDir();
    const MeshData mesh =
        loadMeshFile(writeFile(dir / "textured.gltf", triangleGltf(imageMaterial("textures/my%20wood.png"))));
    ASSERT_EQ(mesh.materials.size(), 1u);
    ASSERT_TRUE(mesh.materials[0].baseColorTexture);
    EXPECT_EQ(mesh.materials[0].baseColorTexture->file, dir / "textures" / "my wood.png");
}

// ---------------------------------------------------------------------------
// OBJ material libraries

const std::string kObjTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";

TEST(MeshReferences, ObjMtllibEscapingTheFolderIsRefusedBeforeItIsOpened)
{
    const Tree tree;
    writeFile(tree.root / "x.mtl", "newmtl red\nKd 1 0 0\n");
    const fs::path file = writeFile(tree.model / "model.obj", "# a model\nmtllib ../../x.mtl\n" + kObjTriangle);
    const std::string message = loadError(file);
    // The refused path is named at the mtllib line: it never reached assimp's reader.
    EXPECT_EQ(message.rfind(file.string() + ":2: its mtllib line references '../../x.mtl' outside its folder (" +
                                fs::canonical(tree.model).string() + ")",
                            0),
              0u)
        << message;
    EXPECT_NE(message.find("resolves to " + (tree.root / "x.mtl").string()), std::string::npos) << message;
    EXPECT_EQ(loadMeshFile(file, kAllowOutside).triangles.size(), 1u);
}

TEST(MeshReferences, ObjMtllibClimbingFarAboveIsRefusedNotAFileReadError)
{
    // Assimp's fallback probes turned this into opening a folder ("File read error").
    const Tree tree;
    const fs::path file = writeFile(tree.model / "model.obj", "mtllib " + up(3) + "x.mtl\n" + kObjTriangle);
    const std::string message = loadError(file);
    EXPECT_NE(message.find(":1: its mtllib line references '" + up(3) + "x.mtl' outside its folder"), std::string::npos)
        << message;
    EXPECT_EQ(message.find("File read error"), std::string::npos) << message;
}

TEST(MeshReferences, MissingMtlIsNamedWithTheObjLine)
{
    const fs::path dir = testDir();
    const fs::path file = writeFile(dir / "model.obj", "# exported\nmtllib missing.mtl\n" + kObjTriangle);
    const std::string message = loadError(file);
    EXPECT_EQ(message, file.string() + ":2: the material library 'missing.mtl' cannot be read: " +
                           (dir / "missing.mtl").string() + ": no such file");
    // The option does not make a missing file acceptable.
    EXPECT_EQ(loadError(file, kAllowOutside), message);
}

TEST(MeshReferences, ObjMtllibThatIsAFolderIsNamed)
{
    const fs::path dir = testDir();
    fs::create_directories(dir / "folder.mtl");
    const fs::path file = writeFile(dir / "model.obj", "mtllib folder.mtl\n" + kObjTriangle);
    EXPECT_NE(loadError(file).find(":1: the material library 'folder.mtl' cannot be read: " +
                                   (dir / "folder.mtl").string() + ": is a directory"),
              std::string::npos);
}

TEST(MeshReferences, ObjWithItsMtlBesideItLoads)
{
    const fs::path dir = testDir();
    writeFile(dir / "mats" / "model.mtl", "newmtl red\nKd 1 0 0\n");
    const fs::path file = writeFile(dir / "model.obj", "mtllib mats/model.mtl\n" + kObjTriangle);
    EXPECT_EQ(loadMeshFile(file).triangles.size(), 1u);
}

// ---------------------------------------------------------------------------
// Node hierarchy and JSON nesting (assimp recurses on both)

TEST(MeshReferences, NodeChainDeeperThanTheLimitIsRefusedLocated)
{
    const fs::path file = writeFile(testDir() / "deep.gltf", gltf(kInlineBuffer, nodeChain(30000)));
    EXPECT_EQ(loadError(file), file.string() + ": node 1024 is nested 1025 levels deep in the node hierarchy; vkrt "
                                               "reads at most 1024 levels");
}

TEST(MeshReferences, NodeChainsUpToTheLimitLoad)
{
    for (int depth : {1000, int(kMaxGltfNodeDepth)}) {
        const MeshData mesh = loadMeshFile(writeFile(testDir() / "chain.gltf", gltf(kInlineBuffer, nodeChain(depth))));
        EXPECT_EQ(mesh.triangles.size(), 1u) << depth;
    }
    const fs::path over = writeFile(testDir() / "over.gltf", gltf(kInlineBuffer, nodeChain(kMaxGltfNodeDepth + 1)));
    EXPECT_NE(loadError(over).find("is nested 1025 levels deep"), std::string::npos);
}

TEST(MeshReferences, NodeCyclesAndSharedChildrenAreRefused)
{
    const fs::path dir = testDir();
    const auto error = [&](const std::string& nodes) {
        return loadError(writeFile(dir / "graph.gltf", gltf(kInlineBuffer, nodes)));
    };
    // Nodes 1 and 2 are each other's parent (each has one), apart from the scene's root 0.
    EXPECT_NE(error(R"([{"mesh": 0}, {"children": [2]}, {"children": [1]}])")
                  .find(": node 1 is its own ancestor (its children lists form a cycle)"),
              std::string::npos);
    EXPECT_NE(error(R"([{"children": [0], "mesh": 0}])").find(": node 0 lists itself among its children"),
              std::string::npos);
    EXPECT_NE(error(R"([{"children": [1, 2]}, {"children": [2]}, {"mesh": 0}])")
                  .find(": node 2 is a child of both node 0 and node 1"),
              std::string::npos);
    EXPECT_NE(error(R"([{"children": [1, 1]}, {"mesh": 0}])").find(": node 0 lists node 1 twice among its children"),
              std::string::npos);
}

TEST(MeshReferences, DeeplyNestedJsonIsRefusedWithItsByte)
{
    const std::string nested = std::string(200000, '[') + std::string(200000, ']');
    const std::string text = gltf(kInlineBuffer, R"([{"mesh": 0}])", R"(, "extras": )" + nested);
    const fs::path file = writeFile(testDir() / "nested.gltf", text);
    const size_t opening = text.find('[', text.find("\"extras\"")) + kMaxGltfJsonNesting - 1;
    EXPECT_EQ(loadError(file), file.string() +
                                   ": the glTF JSON nests arrays and objects more than 1024 levels deep "
                                   "(at byte " +
                                   std::to_string(opening) + " of the JSON)");
}

/// A .glb: the JSON chunk `json` (padded with spaces), then the binary chunk triangleBytes(1).
std::string glb(const std::string& json) { return glbBytes(json, triangleBytes(1.0f)); }

TEST(MeshReferences, GlbJsonChunkIsCheckedToo)
{
    const fs::path dir = testDir();
    EXPECT_NE(loadError(writeFile(dir / "deep.glb", glb(gltf("", nodeChain(30000)))))
                  .find("node 1024 is nested 1025 levels deep"),
              std::string::npos);
    EXPECT_NE(loadError(writeFile(dir / "escape.glb", glb(gltf("../escape.bin")))).find("outside its folder"),
              std::string::npos);
    EXPECT_EQ(loadMeshFile(writeFile(dir / "fine.glb", glb(gltf("", nodeChain(100))))).triangles.size(), 1u);
}

// ---------------------------------------------------------------------------
// Instancing: every node naming a mesh gets its own copy (PreTransformVertices)

/// Vertices (0,0,0) (1,0,0) (0,1,0), then `indexCount` uint16 indices 0 1 2 0 1 2 ...
std::string indexedMeshBytes(uint64_t indexCount)
{
    std::string bytes = triangleBytes(1.0f).substr(0, 36);
    for (uint64_t i = 0; i < indexCount; ++i) put(bytes, uint16_t(i % 3));
    return bytes;
}

/// A glTF whose mesh 0 is one primitive of `indexCount` indices in glTF
/// `mode`, read from mesh.bin (indexedMeshBytes) beside it; node 0 is the
/// scene's root (listed `rootListings` times) with `instances` children
/// naming the mesh, each moved 2 along x from the one before.
std::string instancedGltf(uint64_t indexCount, uint32_t instances, int mode = 4, uint32_t rootListings = 1)
{
    std::string children, nodes, roots;
    for (uint32_t i = 1; i <= instances; ++i) {
        children += (i > 1 ? "," : "") + std::to_string(i);
        nodes += R"(, {"mesh": 0, "translation": [)" + std::to_string(2 * i) + ", 0, 0]}";
    }
    for (uint32_t i = 0; i < rootListings; ++i) roots += i > 0 ? ",0" : "0";
    const uint64_t indexBytes = 2 * indexCount;
    return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [)" + roots +
           R"(]}], "nodes": [{"children": [)" + children + "]}" + nodes + R"(],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": )" +
           std::to_string(mode) + R"(}]}],
  "buffers": [{"uri": "mesh.bin", "byteLength": )" +
           std::to_string(36 + indexBytes) + R"(}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                  {"buffer": 0, "byteOffset": 36, "byteLength": )" +
           std::to_string(indexBytes) + R"(}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": )" +
           std::to_string(indexCount) + R"(, "type": "SCALAR"}]})";
}

/// An instanced file written into `dir` (instancedGltf's arguments), its mesh.bin beside it.
fs::path writeInstanced(const fs::path& dir, uint64_t indexCount, uint32_t instances, int mode = 4,
                        uint32_t rootListings = 1)
{
    writeFile(dir / "mesh.bin", indexedMeshBytes(indexCount));
    return writeFile(dir / "instanced.gltf", instancedGltf(indexCount, instances, mode, rootListings));
}

/// The message checkGltfBeforeImport throws for `file`, or "" when it accepts it (nothing is imported).
std::string preImportError(const fs::path& file)
{
    try {
        checkGltfBeforeImport(file, ReferencePolicy(file, {}));
    } catch (const InputError& error) {
        return error.what();
    }
    return "";
}

TEST(MeshInstancing, ManyNodesNamingALargeMeshAreRefusedAsOneMeshButAreInstancesInAScene)
{
    // 100,000 triangles (600 KB of indices) named by 5,000 nodes: 500 million triangles flattened into one
    // mesh object is refused before any copy is made; as a glTF scene they are 5,000 instances of one geometry.
    const fs::path file = writeInstanced(testDir(), 300000, 5000);
    EXPECT_EQ(loadError(file).rfind(file.string() + ": the node hierarchy instances meshes 5,000 times, 500,000,000 "
                                                    "triangles in all; vkrt reads at most 8,388,608 triangles after "
                                                    "instancing into one mesh",
                                    0),
              0u)
        << loadError(file);
    const Scene scene = parseGltfScene(file.string());
    ASSERT_EQ(scene.meshes.size(), 5000u);
    EXPECT_EQ(scene.meshes.front().geometry, scene.meshes.back().geometry);
    EXPECT_EQ(scene.meshes.front().geometry->data.triangles.size(), 100000u);
}

TEST(MeshInstancing, TheTriangleBoundIsExactForListsStripsAndFans)
{
    const fs::path dir = testDir();
    // 4,096 triangles a mesh, 2,049 nodes: 8 Mi + 4,096 triangles flattened, refused with the exact count.
    const fs::path over = writeInstanced(dir, 3 * 4096, 2049);
    EXPECT_NE(loadError(over).find(" 8,392,704 triangles in all"), std::string::npos) << loadError(over);
    for (int stripOrFan : {5, 6}) { // n indices make n - 2 triangles: 4,097 x 2,048 = 8,390,656
        const fs::path file = writeInstanced(dir, 4099, 2048, stripOrFan);
        EXPECT_NE(loadError(file).find(" 8,390,656 triangles in all"), std::string::npos) << stripOrFan;
    }
    // The unique triangles a scene places are bounded before anything is read: one mesh over the bound.
    EXPECT_EQ(preImportError(writeInstanced(dir, 3 * 4096, 2048)), ""); // 4,096 unique triangles
    // Points and lines make no triangles, however many.
    for (int pointsOrLines : {0, 1, 2, 3})
        EXPECT_EQ(preImportError(writeInstanced(dir, 3 * 4096, 4096, pointsOrLines)), "") << pointsOrLines;
}

TEST(MeshInstancing, RepeatedSceneRootsArePlacedOnce)
{
    // A root listed three times (glTF wants each once) places its subtree three times in the same
    // place: each placement after the first repeats one exactly and is drawn once (GltfReader's
    // PlacementSet). 1,024 instances of 4,096 triangles are 4 Mi triangles flattened, not 12 Mi.
    const fs::path dir = testDir();
    const fs::path file = writeInstanced(dir, 3 * 4096, 1024, 4, 3);
    EXPECT_EQ(loadMeshFile(file).triangles.size(), 1024u * 4096u);
    EXPECT_EQ(parseGltfScene(file.string()).meshes.size(), 1024u);
}

TEST(MeshInstancing, InstancedFileUnderTheBoundLoadsEveryCopy)
{
    const MeshData mesh = loadMeshFile(writeInstanced(testDir(), 3, 1000));
    ASSERT_EQ(mesh.triangles.size(), 1000u);
    const auto [lowest, highest] = std::minmax_element(mesh.positions.begin(), mesh.positions.end(),
                                                       [](const auto& a, const auto& b) { return a.x < b.x; });
    EXPECT_EQ(lowest->x, 2.0f);            // the first node's translation
    EXPECT_EQ(highest->x, 2000.0f + 1.0f); // the last node's, plus the triangle's width
}

TEST(MeshInstancing, NodeCountsAreBounded)
{
    const fs::path dir = testDir();
    // The nodes array, reachable nodes or not.
    const fs::path many = writeInstanced(dir, 3, uint32_t(kMaxGltfNodes));
    EXPECT_EQ(loadError(many), many.string() + ": the file has 65,537 nodes; vkrt reads at most 65,536");
    // One node listed as the scene's root 65,536 times loads (one instance: the listings repeat it
    // exactly); once more is refused, as the reach is counted before anything is read.
    const fs::path roots = writeFile(dir / "roots.gltf", gltf(kInlineBuffer));
    std::string text = fileText(roots);
    const std::string listing = R"("nodes": [0])";
    std::string repeated = R"("nodes": [0)";
    for (uint64_t i = 1; i < kMaxGltfNodes; ++i) repeated += ",0";
    text.replace(text.find(listing), listing.size(), repeated + "]");
    writeFile(roots, text);
    EXPECT_EQ(loadMeshFile(roots).triangles.size(), 1u);
    text.replace(text.find(repeated), repeated.size(), repeated + ",0");
    writeFile(roots, text);
    EXPECT_EQ(loadError(roots), roots.string() + ": the scene reaches 65,537 nodes (a node listed more than once "
                                                 "among its roots is reached each time, with its children); vkrt "
                                                 "reads at most 65,536");
}

TEST(MeshInstancing, AccessorDataWithoutABufferIsBounded)
{
    // A morph target of 100 million zeros (a sparse accessor with no bufferView): 600 bytes of JSON that
    // made assimp allocate 2.4 GB.
    std::string text = gltf(kInlineBuffer);
    const std::string accessorsEnd = R"("type": "SCALAR"}])";
    text.replace(text.find(accessorsEnd), accessorsEnd.size(),
                 R"("type": "SCALAR"}, {"componentType": 5126, "count": 100000000, "type": "VEC3",
                    "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5123},
                               "values": {"bufferView": 0}}}])");
    const std::string attributes = R"("attributes": {"POSITION": 0})";
    text.replace(text.find(attributes), attributes.size(), attributes + R"(, "targets": [{"POSITION": 2}])");
    const fs::path file = writeFile(testDir() / "sparse.gltf", text);
    EXPECT_EQ(loadError(file), file.string() + ": the meshes, morph targets, skins and animations use "
                                               "2,400,000,042 bytes of accessor data (each use counted, an "
                                               "accessor without a bufferView twice); vkrt reads at most "
                                               "1,073,741,824");
}

// ---------------------------------------------------------------------------
// Through the vkrt executable: a bad mesh is exit code 2, located, in bounded memory.

TEST(MeshReferences, VkrtRefusesHostileMeshReferencesWithExitCode2)
{
    // The sanitizer build (preset asan-ubsan-cpu) builds vkrt_cpu_tests alone; vkrt parses the scene before any
    // Vulkan call, so where vkrt is built this test needs no device.
    if (!fs::exists(VKRT_BINARY)) GTEST_SKIP() << VKRT_BINARY << " is not built";
    const Tree tree;
    writeFile(tree.model / "deep.gltf", gltf(kInlineBuffer, nodeChain(30000)));
    writeFile(tree.model / "escape.gltf", gltf("../../secret/tri2.bin"));
    const std::string header = "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 40\n"
                               "[materials.clay]\ntype = \"lambert\"\n[[objects]]\nshape = \"mesh\"\n"
                               "material = \"clay\"\n";
    for (const std::string mesh : {"deep.gltf", "escape.gltf"}) {
        const fs::path scene = tree.root / "scene" / (mesh + ".toml");
        writeText(scene, header + "file = \"model/" + mesh + "\"\n");
        const ProcessResult result = runVkrt({"render", scene.string(), "-o", (tree.root / "out.exr").string()});
        EXPECT_EQ(result.exitCode, 2) << result.output;
        EXPECT_NE(result.output.find(scene.string() + ":10:"), std::string::npos) << result.output;
        EXPECT_NE(result.output.find(mesh == "deep.gltf" ? "levels deep" : "outside its folder"), std::string::npos)
            << result.output;
        EXPECT_LT(result.peakResidentBytes, kBadInputMemoryLimit);
        EXPECT_FALSE(fs::exists(tree.root / "out.exr"));
    }
}

TEST(MeshInstancing, VkrtRefusesAMeshInstancedPastTheBoundWithExitCode2InBoundedMemory)
{
    if (!fs::exists(VKRT_BINARY)) GTEST_SKIP() << VKRT_BINARY << " is not built";
    const fs::path dir = testDir();
    const fs::path mesh = writeInstanced(dir, 300000, 5000); // 500 million triangles after instancing
    const fs::path scene = dir / "scene.toml";
    writeText(scene, "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 40\n[materials.clay]\ntype = \"lambert\"\n"
                     "[[objects]]\nshape = \"mesh\"\nmaterial = \"clay\"\nfile = \"instanced.gltf\"\n");
    const ProcessResult result = runVkrt({"render", scene.string(), "-o", (dir / "out.exr").string()});
    EXPECT_EQ(result.exitCode, 2) << result.output;
    EXPECT_NE(result.output.find(scene.string() + ":10:8: objects[0].file: cannot load the mesh: " + mesh.string() +
                                 ": the node hierarchy instances meshes 5,000 times, 500,000,000 triangles"),
              std::string::npos)
        << result.output;
    EXPECT_LT(result.peakResidentBytes, kBadInputMemoryLimit);
    EXPECT_LT(result.peakResidentBytes, int64_t(256) << 20) << "refused from the JSON, before any copy is made";
    EXPECT_FALSE(fs::exists(dir / "out.exr"));
}

} // namespace
} // namespace vkrt::test
