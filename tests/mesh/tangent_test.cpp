// Per-vertex tangents: computeTangents against frames known in closed form
// (planar grids, a UV sphere), the normal modes keeping them perpendicular,
// MeshGeometry's load path, and the Cube glTF asset's own TANGENT data.
#include "mesh/MeshData.h"
#include "mesh/MeshGeometry.h"
#include "mesh/MeshLoader.h"

#include "texture/TextureTestFiles.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <numbers>

namespace fs = std::filesystem;
using namespace vkrt;

using vkrt::test::assetsDir;

namespace {

/// An n x n grid of unit quads on z = 0 over [0, n]^2 with normals +z and uv = uvOf(x, y).
template <typename UvOf>
MeshData planarGrid(uint32_t n, UvOf uvOf, bool normals = true)
{
    MeshData mesh;
    for (uint32_t y = 0; y <= n; ++y) {
        for (uint32_t x = 0; x <= n; ++x) {
            mesh.positions.emplace_back(float(x), float(y), 0.0f);
            if (normals) mesh.normals.emplace_back(0.0f, 0.0f, 1.0f);
            mesh.uvs.push_back(uvOf(float(x), float(y)));
        }
    }
    const auto index = [n](uint32_t x, uint32_t y) { return y * (n + 1) + x; };
    for (uint32_t y = 0; y < n; ++y) {
        for (uint32_t x = 0; x < n; ++x) {
            mesh.triangles.emplace_back(index(x, y), index(x + 1, y), index(x + 1, y + 1));
            mesh.triangles.emplace_back(index(x, y), index(x + 1, y + 1), index(x, y + 1));
        }
    }
    return mesh;
}

void expectAllTangents(const MeshData& mesh, glm::vec4 expected)
{
    ASSERT_EQ(mesh.tangents.size(), mesh.positions.size());
    for (size_t v = 0; v < mesh.tangents.size(); ++v) EXPECT_EQ(mesh.tangents[v], expected) << "vertex " << v;
}

void expectUnitAndFinite(const MeshData& mesh)
{
    ASSERT_EQ(mesh.tangents.size(), mesh.positions.size());
    for (size_t v = 0; v < mesh.tangents.size(); ++v) {
        const glm::vec4 t = mesh.tangents[v];
        ASSERT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z)) << "vertex " << v;
        EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-6f) << "vertex " << v;
        EXPECT_TRUE(t.w == 1.0f || t.w == -1.0f) << "vertex " << v;
    }
}

/// A UV sphere with a seam: `slices` + 1 columns (u = 0 and u = 1 share
/// positions), one pole vertex per slice; u = phi / 2pi runs east, v = 1 -
/// theta / pi runs north; normals radial.
MeshData seamedUvSphere(uint32_t stacks, uint32_t slices)
{
    MeshData mesh;
    const double pi = std::numbers::pi;
    for (uint32_t i = 0; i <= stacks; ++i) {
        for (uint32_t j = 0; j <= slices; ++j) {
            const bool pole = i == 0 || i == stacks;
            const double u = (j + (pole ? 0.5 : 0.0)) / slices;
            const double theta = pi * i / stacks, phi = 2.0 * pi * u;
            const glm::dvec3 dir(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
            mesh.positions.emplace_back(dir);
            mesh.normals.emplace_back(glm::normalize(dir));
            mesh.uvs.emplace_back(float(u), float(1.0 - double(i) / stacks));
        }
    }
    const auto index = [slices](uint32_t i, uint32_t j) { return i * (slices + 1) + j; };
    for (uint32_t i = 0; i < stacks; ++i) {
        for (uint32_t j = 0; j < slices; ++j) {
            // Counter-clockwise seen from outside; none at the poles' degenerate corners.
            if (i != 0) mesh.triangles.emplace_back(index(i, j), index(i + 1, j), index(i, j + 1));
            if (i + 1 != stacks) mesh.triangles.emplace_back(index(i, j + 1), index(i + 1, j), index(i + 1, j + 1));
        }
    }
    return mesh;
}

} // namespace

// ---------------------------------------------------------------------------
// Closed-form frames

TEST(MeshTangents, GridWithUvEqualToXyHasTangentXAndRightHandedness)
{
    // dp/du = (1, 0, 0), dp/dv = (0, 1, 0) = cross((0, 0, 1), (1, 0, 0)): w = +1, exactly.
    MeshData mesh = planarGrid(4, [](float x, float y) { return glm::vec2(x, y); });
    computeTangents(mesh);
    expectAllTangents(mesh, {1.0f, 0.0f, 0.0f, 1.0f});
}

TEST(MeshTangents, GridWithoutNormalsUsesTheSmoothNormal)
{
    MeshData mesh = planarGrid(
        3, [](float x, float y) { return glm::vec2(x, y); }, /*normals=*/false);
    computeTangents(mesh);
    expectAllTangents(mesh, {1.0f, 0.0f, 0.0f, 1.0f});
    EXPECT_TRUE(mesh.normals.empty()); // it computes tangents, not normals
}

TEST(MeshTangents, MirroredUFlipsTheTangent)
{
    // dp/du = (-1, 0, 0); the bitangent (0, 1, 0) is -cross(n, t): w = -1.
    MeshData mesh = planarGrid(4, [](float x, float y) { return glm::vec2(-x, y); });
    computeTangents(mesh);
    expectAllTangents(mesh, {-1.0f, 0.0f, 0.0f, -1.0f});
}

TEST(MeshTangents, MirroredVFlipsTheHandedness)
{
    // dp/du = (1, 0, 0) still; dp/dv = (0, -1, 0) = -cross(n, t): w = -1.
    MeshData mesh = planarGrid(4, [](float x, float y) { return glm::vec2(x, -y); });
    computeTangents(mesh);
    expectAllTangents(mesh, {1.0f, 0.0f, 0.0f, -1.0f});
}

TEST(MeshTangents, ScaledAndRotatedUvsGiveTheirDirection)
{
    // uv = 3 * (x cos a + y sin a, -x sin a + y cos a): u increases along (cos a, sin a).
    const float a = 0.5f;
    MeshData mesh = planarGrid(3, [a](float x, float y) {
        return 3.0f * glm::vec2(x * std::cos(a) + y * std::sin(a), -x * std::sin(a) + y * std::cos(a));
    });
    computeTangents(mesh);
    expectUnitAndFinite(mesh);
    for (const glm::vec4& t : mesh.tangents) {
        EXPECT_NEAR(t.x, std::cos(a), 1e-5f);
        EXPECT_NEAR(t.y, std::sin(a), 1e-5f);
        EXPECT_EQ(t.z, 0.0f);
        EXPECT_EQ(t.w, 1.0f);
    }
}

TEST(MeshTangents, UvSphereTangentsRunEastAndArePerpendicular)
{
    const uint32_t slices = 32;
    MeshData mesh = seamedUvSphere(16, slices);
    computeTangents(mesh);
    expectUnitAndFinite(mesh);
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
        const glm::vec3 n = mesh.normals[v], t = glm::vec3(mesh.tangents[v]);
        EXPECT_NEAR(glm::dot(n, t), 0.0f, 1e-6f) << "vertex " << v;
        const glm::vec2 horizontal(n.x, n.y);
        if (glm::length(horizontal) < 1e-3f) continue; // the poles: east is undefined there
        // East, the direction of increasing phi: (-sin phi, cos phi, 0).
        const glm::vec3 east = glm::normalize(glm::vec3(-n.y, n.x, 0.0f));
        // A triangle's dp/du is its chord, up to half a slice (pi / slices) off
        // east at its corners; inside a row the chords on either side cancel
        // that, at the seam (u = 0 or 1) a vertex sees only one side.
        const bool seam = mesh.uvs[v].x == 0.0f || mesh.uvs[v].x == 1.0f;
        const float atLeast = seam ? float(std::cos(std::numbers::pi / slices)) - 1e-5f : 0.9999f;
        EXPECT_GT(glm::dot(t, east), atLeast) << "vertex " << v << ", uv " << mesh.uvs[v].x << ", " << mesh.uvs[v].y;
        // v runs north, and cross(radial, east) points north: right-handed.
        EXPECT_EQ(mesh.tangents[v].w, 1.0f) << "vertex " << v;
    }
}

TEST(MeshTangents, SeamVerticesWithDifferentUvsAreNotMerged)
{
    // Two grids side by side, sharing the positions along x = 2 but not the
    // uvs there (u = 2 on the left, u = 8 - 2 = 6 on the right, mirrored).
    MeshData left = planarGrid(2, [](float x, float y) { return glm::vec2(x, y); });
    MeshData right = planarGrid(2, [](float x, float y) { return glm::vec2(8.0f - (x + 2.0f), y); });
    MeshData mesh = left;
    const auto base = uint32_t(mesh.positions.size());
    for (size_t v = 0; v < right.positions.size(); ++v) {
        mesh.positions.push_back(right.positions[v] + glm::vec3(2.0f, 0.0f, 0.0f));
        mesh.normals.push_back(right.normals[v]);
        mesh.uvs.push_back(right.uvs[v]);
    }
    for (const glm::uvec3& t : right.triangles) mesh.triangles.push_back(t + glm::uvec3(base));
    computeTangents(mesh);
    for (uint32_t v = 0; v < base; ++v) EXPECT_EQ(mesh.tangents[v], glm::vec4(1, 0, 0, 1)) << "left vertex " << v;
    for (uint32_t v = base; v < mesh.positions.size(); ++v)
        EXPECT_EQ(mesh.tangents[v], glm::vec4(-1, 0, 0, -1)) << "right vertex " << v;
}

TEST(MeshTangents, DegenerateUvTrianglesContributeNothing)
{
    MeshData mesh = planarGrid(2, [](float x, float y) { return glm::vec2(x, y); });
    // A triangle at vertex 0 whose uvs all coincide (a collapsed uv island), pointing its edges elsewhere.
    const auto first = uint32_t(mesh.positions.size());
    for (const glm::vec3& p : {glm::vec3(0, 0, 0), glm::vec3(-1, 1, 0), glm::vec3(-1, -1, 0)}) {
        mesh.positions.push_back(p);
        mesh.normals.emplace_back(0.0f, 0.0f, 1.0f);
        mesh.uvs.emplace_back(0.0f, 0.0f);
    }
    mesh.triangles.emplace_back(first, first + 1, first + 2);
    computeTangents(mesh);
    // Vertex `first` welds with vertex 0 (same position, normal, uv): the grid's frame, undisturbed.
    EXPECT_EQ(mesh.tangents[0], glm::vec4(1, 0, 0, 1));
    EXPECT_EQ(mesh.tangents[first], glm::vec4(1, 0, 0, 1));
    // The other two got nothing: the fixed frame around +z, w = +1.
    EXPECT_EQ(mesh.tangents[first + 1], glm::vec4(perpendicularTo({0, 0, 1}), 1.0f));
}

TEST(MeshTangents, VertexWithoutUvFrameGetsAPerpendicularFallback)
{
    MeshData mesh;
    const glm::vec3 n = glm::normalize(glm::vec3(1, 2, 3));
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.normals = {n, n, n};
    mesh.uvs = {{0.5f, 0.5f}, {0.5f, 0.5f}, {0.5f, 0.5f}};
    mesh.triangles = {{0, 1, 2}};
    computeTangents(mesh);
    expectUnitAndFinite(mesh);
    for (const glm::vec4& t : mesh.tangents) EXPECT_NEAR(glm::dot(glm::vec3(t), n), 0.0f, 1e-6f);
}

TEST(MeshTangents, PerpendicularToIsUnitAndPerpendicularEverywhere)
{
    for (const glm::vec3& d : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(0, -1, 0),
                               glm::vec3(1, 2, 3), glm::vec3(-1e-8f, 0, -1), glm::vec3(3, -2, -1e-3f)}) {
        const glm::vec3 n = glm::normalize(d);
        const glm::vec3 t = perpendicularTo(n);
        EXPECT_NEAR(glm::length(t), 1.0f, 1e-6f) << d.x << " " << d.y << " " << d.z;
        EXPECT_NEAR(glm::dot(t, n), 0.0f, 1e-6f) << d.x << " " << d.y << " " << d.z;
    }
}

TEST(MeshTangents, NoUvsNoTangents)
{
    MeshData mesh = planarGrid(2, [](float x, float y) { return glm::vec2(x, y); });
    mesh.uvs.clear();
    computeTangents(mesh);
    EXPECT_TRUE(mesh.tangents.empty());
}

TEST(MeshTangents, BadGeometryNeverGivesNaN)
{
    // Collapsed triangles, repeated vertices, huge and tiny coordinates, zero normals.
    MeshData mesh;
    mesh.positions = {{0, 0, 0}, {0, 0, 0}, {1e30f, 0, 0}, {0, 1e30f, 0}, {1e-30f, 0, 0}, {0, 1e-30f, 0}, {1, 1, 1}};
    mesh.normals = {{0, 0, 0}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    mesh.uvs = {{0, 0}, {1e30f, 0}, {0, 1}, {1, 0}, {0, 0}, {1e-30f, 1e-30f}, {-1e30f, 1e30f}};
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 4, 5}, {1, 1, 1}, {4, 5, 6}, {2, 3, 6}};
    computeTangents(mesh);
    expectUnitAndFinite(mesh);
}

// ---------------------------------------------------------------------------
// Normal modes and the load path

TEST(MeshTangents, NormalModesMakeTangentsPerpendicularToTheNewNormals)
{
    // File normals tilted towards +x: the tangent is x without its part along them.
    const glm::vec3 tilted(0.6f, 0.0f, 0.8f);
    MeshData mesh = planarGrid(2, [](float x, float y) { return glm::vec2(x, -y); });
    for (glm::vec3& n : mesh.normals) n = tilted;
    computeTangents(mesh);
    for (const glm::vec4& t : mesh.tangents) {
        EXPECT_NEAR(t.x, 0.8f, 1e-6f);
        EXPECT_NEAR(t.z, -0.6f, 1e-6f);
        EXPECT_EQ(t.w, -1.0f);
    }
    for (NormalMode mode : {NormalMode::Smooth, NormalMode::Face}) {
        MeshData copy = mesh;
        applyNormalMode(copy, mode);
        // The grid's smooth (and face) normal is +z: the tangent becomes x again, w kept.
        for (const glm::vec4& t : copy.tangents) {
            EXPECT_NEAR(t.x, 1.0f, 1e-6f);
            EXPECT_NEAR(t.z, 0.0f, 1e-6f);
            EXPECT_EQ(t.w, -1.0f);
        }
    }
}

TEST(MeshTangents, GeometryComputesTangentsOnlyWhereTheFileHasNone)
{
    const MeshData grid = planarGrid(4, [](float x, float y) { return glm::vec2(x, y); });
    const auto computed = makeMeshGeometry(grid, NormalMode::File, "grid");
    expectAllTangents(computed->data, {1.0f, 0.0f, 0.0f, 1.0f});

    MeshData given = grid;
    given.tangents.assign(given.positions.size(), glm::vec4(0.0f, 1.0f, 0.0f, -1.0f));
    expectAllTangents(makeMeshGeometry(given, NormalMode::File, "given")->data, {0.0f, 1.0f, 0.0f, -1.0f});

    MeshData noUvs = grid;
    noUvs.uvs.clear();
    EXPECT_TRUE(makeMeshGeometry(noUvs, NormalMode::File, "plain")->data.tangents.empty());
}

TEST(MeshTangents, GeometryReordersTriangleMaterialsWithTheTriangles)
{
    MeshData mesh = planarGrid(8, [](float x, float y) { return glm::vec2(x, y); });
    const MeshData original = mesh;
    mesh.materials.resize(3);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) mesh.triangleMaterials.push_back(uint32_t(t % 3));
    const auto geometry = makeMeshGeometry(mesh, NormalMode::File, "grid");
    const MeshData& data = geometry->data;
    ASSERT_EQ(data.triangleMaterials.size(), data.triangles.size());
    for (size_t slot = 0; slot < data.triangles.size(); ++slot) {
        const uint32_t source = geometry->bvh.order[slot];
        EXPECT_EQ(data.triangles[slot], original.triangles[source]);
        EXPECT_EQ(data.triangleMaterials[slot], source % 3) << "slot " << slot;
    }
}

TEST(MeshTangents, GpuBytesCountUvsTangentsAndMaterials)
{
    MeshData mesh = planarGrid(4, [](float x, float y) { return glm::vec2(x, y); });
    MeshData plain = mesh;
    plain.uvs.clear();
    const size_t triangles = mesh.triangles.size();
    const size_t base = makeMeshGeometry(plain, NormalMode::File, "plain")->gpuBytes();
    // uvs: 3 corners x 8 bytes; tangents: 3 corners x 16 bytes (computed, the grid has uvs).
    EXPECT_EQ(makeMeshGeometry(mesh, NormalMode::File, "uvs")->gpuBytes(), base + triangles * (24 + 48));
    mesh.materials.resize(1);
    mesh.triangleMaterials.assign(triangles, 0);
    EXPECT_EQ(makeMeshGeometry(mesh, NormalMode::File, "materials")->gpuBytes(), base + triangles * (24 + 48 + 4));
}

// ---------------------------------------------------------------------------
// The Cube glTF asset: TANGENT from the file

namespace {

/// `count` little-endian floats at `offset` of Cube.bin (offsets from Cube.gltf's bufferViews).
std::vector<float> cubeFloats(size_t offset, size_t count)
{
    std::ifstream in(assetsDir() / "gltf" / "Cube" / "Cube.bin", std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    EXPECT_EQ(bytes.size(), 1800u);
    std::vector<float> values(count);
    if (offset + count * 4 <= bytes.size()) std::memcpy(values.data(), bytes.data() + offset, count * 4);
    return values;
}

} // namespace

TEST(MeshTangents, GltfCubeKeepsTheFilesTangents)
{
    // Cube.gltf: 36 vertices; POSITION is bufferView 1 (offset 72), NORMAL
    // bufferView 2 (offset 504), TANGENT bufferView 3 (offset 936, VEC4),
    // TEXCOORD_0 bufferView 4 (offset 1512).
    const std::vector<float> positions = cubeFloats(72, 36 * 3);
    const std::vector<float> normals = cubeFloats(504, 36 * 3);
    const std::vector<float> tangents = cubeFloats(936, 36 * 4);
    const std::vector<float> uvs = cubeFloats(1512, 36 * 2);
    const MeshData cube = loadMeshFile(assetsDir() / "gltf" / "Cube" / "Cube.gltf");
    ASSERT_EQ(cube.tangents.size(), cube.positions.size());
    ASSERT_EQ(cube.positions.size(), 36u);
    for (size_t v = 0; v < 36; ++v) {
        // The same vertex of the file: its position, normal and uv (assimp flips v: v = 1 - v_file).
        size_t match = 36;
        for (size_t f = 0; f < 36 && match == 36; ++f) {
            const glm::vec3 p(positions[3 * f], positions[3 * f + 1], positions[3 * f + 2]);
            const glm::vec3 n(normals[3 * f], normals[3 * f + 1], normals[3 * f + 2]);
            const glm::vec2 uv(uvs[2 * f], 1.0f - uvs[2 * f + 1]);
            if (p == cube.positions[v] && n == cube.normals[v] && uv == cube.uvs[v]) match = f;
        }
        ASSERT_LT(match, 36u) << "vertex " << v;
        const glm::vec4 file(tangents[4 * match], tangents[4 * match + 1], tangents[4 * match + 2],
                             tangents[4 * match + 3]);
        EXPECT_EQ(glm::vec3(cube.tangents[v]), glm::vec3(file)) << "vertex " << v; // already unit in the file
        // glTF's bitangent cross(n, t) * w: MeshData keeps the file's sign
        // (the Khronos viewer's b = cross(n, t) * w; GltfReader.cpp says why).
        EXPECT_EQ(cube.tangents[v].w, file.w) << "vertex " << v;
    }
}

TEST(MeshTangents, GltfCubeFileTangentsAreKeptWhereTheirHandednessRunsAgainstItsUvs)
{
    // Cube.gltf's tangents lie along its increasing u, as computed ones do,
    // but its bitangents cross(n, t) w run along increasing file v (down the
    // image), where glTF's normal maps have +Y up the image (MikkTSpace over
    // the uvs before an exporter turns v down, as SheenCloth's 115,200
    // triangles have them). A file's TANGENT is used as written, as the
    // Khronos viewer uses it: here with the opposite handedness.
    const MeshData cube = loadMeshFile(assetsDir() / "gltf" / "Cube" / "Cube.gltf");
    MeshData computed = cube;
    computeTangents(computed);
    ASSERT_EQ(computed.tangents.size(), cube.tangents.size());
    for (size_t v = 0; v < cube.tangents.size(); ++v) {
        EXPECT_NEAR(glm::distance(glm::vec3(computed.tangents[v]), glm::vec3(cube.tangents[v])), 0.0f, 1e-5f)
            << "vertex " << v;
        EXPECT_EQ(computed.tangents[v].w, -cube.tangents[v].w) << "vertex " << v;
    }
}
