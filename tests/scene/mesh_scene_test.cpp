// `[[objects]] shape = "mesh"`: keys, transforms, normals and emission, and
// the errors a mistyped or broken mesh object gets (CPU only).
#include "mesh/MeshGeometry.h"
#include "mesh/Procedural.h"
#include "scene/SceneParser.h"
#include "support/GltfTestFiles.h"
#include "support/TestSupport.h"

#include <gtest/gtest.h>

namespace vkrt::test {
namespace {

const char* kHeader = R"(
[camera]
eye = [0, 0, 5]
target = [0, 0, 0]
fov = 40
[materials.clay]
type = "lambert"
)";

class SceneParserMesh : public ::testing::Test {
protected:
    void SetUp() override
    {
        m_dir = freshTempDir("scene-mesh");
        MeshData triangle;
        triangle.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
        triangle.triangles = {{0, 1, 2}};
        writeObj(triangle, m_dir / "tri.obj");
    }

    Scene parse(const std::string& object) const
    {
        return parseSceneString(std::string(kHeader) + "[[objects]]\nshape = \"mesh\"\nmaterial = \"clay\"\n" + object,
                                (m_dir / "scene.toml").string());
    }

    /// The message of the SceneError parsing `object` gives (empty if none).
    std::string errorOf(const std::string& object) const
    {
        try {
            parse(object);
        } catch (const SceneError& e) {
            return e.what();
        }
        return "";
    }

    std::filesystem::path m_dir;
};

glm::dvec3 apply(const glm::dmat4& m, glm::dvec3 p) { return glm::dvec3(m * glm::dvec4(p, 1.0)); }

TEST_F(SceneParserMesh, FileIsRelativeToTheSceneAndLoaded)
{
    const Scene scene = parse("file = \"tri.obj\"\n");
    ASSERT_EQ(scene.meshes.size(), 1u);
    EXPECT_EQ(scene.meshes[0].geometry->data.triangles.size(), 1u);
    EXPECT_EQ(scene.meshes[0].material, 0u);
    EXPECT_EQ(scene.meshes[0].emission, Color(0.0));
    EXPECT_EQ(scene.meshes[0].where.line, 8);
}

TEST_F(SceneParserMesh, ScaleThenRotateThenTranslate)
{
    const Scene scene = parse("file = \"tri.obj\"\nscale = [2, 3, 4]\nrotate = { axis = [0, 0, 1], angle = 90 }\n"
                              "translate = [10, 20, 30]\n");
    const glm::dmat4& m = scene.meshes[0].objectToWorld;
    // (1, 1, 1) -> scaled (2, 3, 4) -> rotated 90 degrees about z (-3, 2, 4) -> (7, 22, 34).
    const glm::dvec3 p = apply(m, {1, 1, 1});
    EXPECT_NEAR(p.x, 7.0, 1e-12);
    EXPECT_NEAR(p.y, 22.0, 1e-12);
    EXPECT_NEAR(p.z, 34.0, 1e-12);
}

TEST_F(SceneParserMesh, MatrixRowsAreRows)
{
    const Scene scene =
        parse("file = \"tri.obj\"\nmatrix = [[0, -1, 0, 5], [1, 0, 0, 6], [0, 0, 2, 7], [0, 0, 0, 1]]\n");
    const glm::dvec3 p = apply(scene.meshes[0].objectToWorld, {1, 2, 3});
    EXPECT_EQ(p, glm::dvec3(-2 + 5, 1 + 6, 6 + 7));
}

TEST_F(SceneParserMesh, InstancesOfOneFileShareGeometryPerNormalMode)
{
    const Scene scene =
        parseSceneString(std::string(kHeader) +
                             "[[objects]]\nshape = \"mesh\"\nmaterial = \"clay\"\nfile = \"tri.obj\"\n"
                             "[[objects]]\nshape = \"mesh\"\nmaterial = \"clay\"\nfile = \"./tri.obj\"\n"
                             "[[objects]]\nshape = \"mesh\"\nmaterial = \"clay\"\nfile = \"tri.obj\"\n"
                             "normals = \"smooth\"\n",
                         (m_dir / "scene.toml").string());
    ASSERT_EQ(scene.meshes.size(), 3u);
    EXPECT_EQ(scene.meshes[0].geometry, scene.meshes[1].geometry);
    EXPECT_NE(scene.meshes[0].geometry, scene.meshes[2].geometry);
    EXPECT_EQ(scene.meshes[2].geometry->normals, NormalMode::Smooth);
    EXPECT_EQ(scene.meshes[2].geometry->data.normals.size(), 3u);
}

TEST_F(SceneParserMesh, EmissionAndTwoSided)
{
    const Scene scene = parse("file = \"tri.obj\"\nemission = [1, 2, 3]\ntwo_sided = true\n");
    EXPECT_EQ(scene.meshes[0].emission, Color(1, 2, 3));
    EXPECT_TRUE(scene.meshes[0].twoSided);
}

TEST_F(SceneParserMesh, ErrorsNameFileLineAndColumn)
{
    struct Case {
        std::string object;
        std::string expected;
    };
    const std::vector<Case> cases = {
        {"", "'file'"},
        {"file = \"missing.obj\"\n", "does not exist"},
        {"file = \"tri.xyz\"\n", "unsupported mesh file"},
        {"file = \"tri.obj\"\nnormal = \"face\"\n", "not used by shape 'mesh'"},
        {"file = \"tri.obj\"\nnormls = \"face\"\n", "normals"}, // did you mean
        {"file = \"tri.obj\"\nnormals = \"flat\"\n", "expected one of"},
        {"file = \"tri.obj\"\nscale = 0\n", "must not be zero"},
        {"file = \"tri.obj\"\nscale = [1, 0, 1]\n", "must not be zero"},
        {"file = \"tri.obj\"\nrotate = { axis = [0, 0, 0], angle = 3 }\n", "zero-length"},
        {"file = \"tri.obj\"\nrotate = { axis = [0, 0, 1], angel = 3 }\n", "angle"},
        {"file = \"tri.obj\"\nmatrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]\n", "4 rows"},
        {"file = \"tri.obj\"\nmatrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 1]]\n", "singular"},
        {"file = \"tri.obj\"\nmatrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]\n", "affine"},
        {"file = \"tri.obj\"\nmatrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\ntranslate = [1, 1, "
         "1]\n",
         "cannot be combined with matrix"},
        {"file = \"tri.obj\"\ntwo_sided = true\n", "only applies to an emissive mesh"},
        {"file = \"tri.obj\"\nemission = [-1, 0, 0]\n", "emission"},
        {"file = \"tri.obj\"\nradius = 1\n", "radius"},
    };
    for (const Case& c : cases) {
        const std::string message = errorOf(c.object);
        EXPECT_NE(message.find("scene.toml:"), std::string::npos) << c.object << " -> " << message;
        EXPECT_NE(message.find(c.expected), std::string::npos) << c.object << " -> " << message;
    }
}

TEST_F(SceneParserMesh, BrokenMeshFileIsASceneErrorNamingBoth)
{
    writeText(m_dir / "broken.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
    const std::string message = errorOf("file = \"broken.obj\"\n");
    EXPECT_NE(message.find("scene.toml:11:"), std::string::npos) << message;
    EXPECT_NE(message.find("broken.obj"), std::string::npos) << message;
}

/// A one-triangle glTF in m_dir/model whose buffer is m_dir/tri.bin, outside its folder.
void writeGltfReadingAboveItsFolder(const std::filesystem::path& dir)
{
    std::string bytes;
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(bytes, v);
    for (uint16_t i : {0, 1, 2}) put(bytes, i);
    bytes.append(2, '\0');
    writeText(dir / "tri.bin", bytes);
    writeText(dir / "model" / "up.gltf",
              R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "buffers": [{"uri": "../tri.bin", "byteLength": 44}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]})");
}

TEST_F(SceneParserMesh, ReferencesOutsideTheMeshFolderNeedTheScenesPermission)
{
    writeGltfReadingAboveItsFolder(m_dir);
    const std::string message = errorOf("file = \"model/up.gltf\"\n");
    EXPECT_NE(message.find("scene.toml:11:"), std::string::npos) << message;
    EXPECT_NE(message.find("cannot load the mesh: " + (m_dir / "model" / "up.gltf").string() +
                           ": buffer 0 references '../tri.bin' outside its folder"),
              std::string::npos)
        << message;
    const Scene scene = parse("file = \"model/up.gltf\"\nallow_outside_references = true\n");
    ASSERT_EQ(scene.meshes.size(), 1u);
    EXPECT_EQ(scene.meshes[0].geometry->data.triangles.size(), 1u);
    EXPECT_NE(errorOf("file = \"tri.obj\"\nallow_outside_references = \"yes\"\n").find("allow_outside_references"),
              std::string::npos);
}

TEST_F(SceneParserMesh, PermissionIsPartOfTheSharedGeometrysKey)
{
    // The first instance may read outside; the second, of the same file, may not, and must not reuse the first's.
    writeGltfReadingAboveItsFolder(m_dir);
    const std::string message =
        errorOf("file = \"model/up.gltf\"\nallow_outside_references = true\n"
                "[[objects]]\nshape = \"mesh\"\nmaterial = \"clay\"\nfile = \"model/up.gltf\"\n");
    EXPECT_NE(message.find("scene.toml:16:"), std::string::npos) << message;
    EXPECT_NE(message.find("outside its folder"), std::string::npos) << message;
}

} // namespace
} // namespace vkrt::test
