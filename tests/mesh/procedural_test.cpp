// Procedural meshes (src/mesh/Procedural.h): counts, shapes, orientation,
// determinism, and the bytes the OBJ and PLY writers produce.
#include "mesh/Procedural.h"

#include "support/TestSupport.h"
#include "util/Error.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

namespace vkrt {
namespace {

double areaOf(const MeshData& m)
{
    double area = 0.0;
    for (const glm::uvec3& t : m.triangles) {
        const glm::dvec3 a(m.positions[t.x]), b(m.positions[t.y]), c(m.positions[t.z]);
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    return area;
}

/// Every directed edge appears once and its reverse once: a closed, consistently oriented surface.
::testing::AssertionResult closedAndOriented(const MeshData& m)
{
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (const glm::uvec3& t : m.triangles)
        for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
    for (const auto& [edge, count] : edges) {
        const auto reverse = edges.find({edge.second, edge.first});
        if (count != 1 || reverse == edges.end() || reverse->second != 1)
            return ::testing::AssertionFailure() << "edge " << edge.first << "-" << edge.second << " x" << count;
    }
    return ::testing::AssertionSuccess();
}

/// Vertices at the radius (relative 1e-6), normals unit and radial, faces turned outwards.
void expectSphere(const MeshData& m, glm::vec3 centre, float radius)
{
    ASSERT_EQ(m.normals.size(), m.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i) {
        const glm::dvec3 offset = glm::dvec3(m.positions[i]) - glm::dvec3(centre);
        ASSERT_NEAR(glm::length(offset), radius, 1e-6 * radius) << "vertex " << i;
        ASSERT_NEAR(glm::length(glm::dvec3(m.normals[i])), 1.0, 1e-6);
        ASSERT_GT(glm::dot(glm::dvec3(m.normals[i]), glm::normalize(offset)), 1.0 - 1e-6);
    }
    for (const glm::uvec3& t : m.triangles) {
        const glm::dvec3 a(m.positions[t.x]), b(m.positions[t.y]), c(m.positions[t.z]);
        ASSERT_GT(glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0 - glm::dvec3(centre)), 0.0);
    }
    EXPECT_TRUE(closedAndOriented(m));
}

TEST(Procedural, UvSphereHasAtLeastTheRequestedTriangles)
{
    for (uint32_t wanted : {0u, 1u, 6u, 7u, 100u, 999u, 12345u, 80000u, 1000000u}) {
        const MeshData m = makeUvSphere(wanted, glm::vec3(0.0f), 1.0f);
        EXPECT_GE(m.triangles.size(), std::max(wanted, 6u)) << wanted;
        // Slices are chosen for the count: at most one more ring of triangles than needed.
        EXPECT_LT(double(m.triangles.size()), wanted + std::sqrt(double(wanted)) + 8.0) << wanted;
        EXPECT_EQ(m.positions.size(), m.triangles.size() / 2 + 2); // Euler: V = F / 2 + 2 for a closed sphere
    }
}

TEST(Procedural, UvSphereShape)
{
    expectSphere(makeUvSphere(5000, glm::vec3(0.0f), 1.0f), glm::vec3(0.0f), 1.0f);
    expectSphere(makeUvSphere(300, glm::vec3(0.5f, -1.0f, 2.0f), 2.5f), glm::vec3(0.5f, -1.0f, 2.0f), 2.5f);
}

TEST(Procedural, IcosphereCountsAndShape)
{
    for (int n = 0; n <= 4; ++n) {
        const MeshData m = makeIcosphere(n, glm::vec3(0.0f, 0.0f, 1.0f), 3.0f);
        EXPECT_EQ(m.triangles.size(), size_t(20) << (2 * n));
        EXPECT_EQ(m.positions.size(), (size_t(10) << (2 * n)) + 2);
        expectSphere(m, glm::vec3(0.0f, 0.0f, 1.0f), 3.0f);
    }
}

TEST(Procedural, SphereAreaConvergesTo4PiR2)
{
    const double radius = 2.0, exact = 4.0 * std::numbers::pi * radius * radius;
    double previous = INFINITY;
    for (int n = 0; n <= 6; ++n) {
        const double error = exact - areaOf(makeIcosphere(n, glm::vec3(0.0f), float(radius)));
        EXPECT_GT(error, 0.0);                 // inscribed
        EXPECT_LT(error, previous / 3.0) << n; // about 4x smaller per level
        previous = error;
    }
    EXPECT_LT(previous / exact, 1e-3);
    const double uvError = exact - areaOf(makeUvSphere(100000, glm::vec3(0.0f), float(radius)));
    EXPECT_GT(uvError, 0.0);
    EXPECT_LT(uvError / exact, 1e-3);
}

TEST(Procedural, GridLayout)
{
    const uint32_t n = 5;
    const MeshData g = makeGrid(n);
    EXPECT_EQ(g.triangles.size(), 2u * n * n);
    EXPECT_EQ(g.positions.size(), (n + 1u) * (n + 1u));
    EXPECT_EQ(g.normals.size(), g.positions.size());
    EXPECT_EQ(g.uvs.size(), g.positions.size());
    EXPECT_NEAR(areaOf(g), 4.0, 1e-6);
    glm::vec3 lower(INFINITY), upper(-INFINITY);
    for (const glm::vec3& p : g.positions) lower = glm::min(lower, p), upper = glm::max(upper, p);
    EXPECT_EQ(lower, glm::vec3(-1.0f, -1.0f, 0.0f));
    EXPECT_EQ(upper, glm::vec3(1.0f, 1.0f, 0.0f));
    for (const glm::uvec3& t : g.triangles) {
        const glm::vec3 a = g.positions[t.x], b = g.positions[t.y], c = g.positions[t.z];
        EXPECT_GT(glm::cross(b - a, c - a).z, 0.0f); // counter-clockwise seen from +z, where the normals face
    }
}

TEST(Procedural, RandomSoupIsDeterministicAndInTheUnitCube)
{
    const MeshData a = makeRandomSoup(1000, 5), b = makeRandomSoup(1000, 5), c = makeRandomSoup(1000, 6);
    ASSERT_EQ(a.triangles.size(), 1000u);
    ASSERT_EQ(a.positions.size(), 3000u);
    EXPECT_EQ(0, std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(glm::vec3)));
    EXPECT_NE(0, std::memcmp(a.positions.data(), c.positions.data(), a.positions.size() * sizeof(glm::vec3)));
    for (const glm::vec3& p : a.positions) {
        EXPECT_TRUE(glm::all(glm::greaterThanEqual(p, glm::vec3(0.0f))) &&
                    glm::all(glm::lessThanEqual(p, glm::vec3(1.0f))));
    }
    EXPECT_GT(areaOf(a), 0.0);
    // SplitMix64 and plain arithmetic: the same first vertex on every platform.
    EXPECT_EQ(makeRandomSoup(1, 1).positions[0], glm::vec3(0.554341316f, 0.715630054f, 0.950191915f));
}

TEST(Procedural, BadArgumentsAreInputErrors)
{
    EXPECT_THROW(makeGrid(0), InputError);
    EXPECT_THROW(makeIcosphere(-1, glm::vec3(0.0f), 1.0f), InputError);
    EXPECT_THROW(makeIcosphere(11, glm::vec3(0.0f), 1.0f), InputError);
    EXPECT_THROW(makeRandomSoup(0, 1), InputError);
}

std::string readFile(const std::filesystem::path& path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::vector<std::string> linesOf(const std::string& text)
{
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

TEST(Procedural, ObjWriterLines)
{
    const auto dir = test::freshTempDir("procedural-obj");
    const MeshData g = makeGrid(2);
    writeObj(g, dir / "grid.obj");
    std::map<std::string, int> tags;
    std::vector<glm::vec3> positions;
    std::vector<std::string> faces;
    for (const std::string& line : linesOf(readFile(dir / "grid.obj"))) {
        std::istringstream words(line);
        std::string tag;
        words >> tag;
        ++tags[tag];
        if (tag == "v") {
            std::string x, y, z;
            words >> x >> y >> z;
            positions.emplace_back(std::strtof(x.c_str(), nullptr), std::strtof(y.c_str(), nullptr),
                                   std::strtof(z.c_str(), nullptr));
        }
        if (tag == "f") faces.push_back(line);
    }
    EXPECT_EQ(tags["v"], 9);
    EXPECT_EQ(tags["vn"], 9);
    EXPECT_EQ(tags["vt"], 9);
    EXPECT_EQ(tags["f"], 8);
    EXPECT_EQ(tags["#"], 1);
    EXPECT_EQ(positions, g.positions); // the text reads back exactly
    EXPECT_EQ(faces[0], "f 1/1/1 2/2/2 5/5/5");
    // Without normals and uvs the corners are plain indices.
    writeObj(makeRandomSoup(2, 1), dir / "soup.obj");
    const std::vector<std::string> soup = linesOf(readFile(dir / "soup.obj"));
    EXPECT_EQ(soup.back(), "f 4 5 6");
    EXPECT_EQ(soup.size(), 1u + 6u + 2u);
}

const char* gridPlyHeader(const char* format)
{
    static std::string h;
    h = std::string("ply\nformat ") + format +
        " 1.0\ncomment vkrt procedural mesh\nelement vertex 9\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "property float s\nproperty float t\n"
        "element face 8\nproperty list uchar uint vertex_indices\nend_header\n";
    return h.c_str();
}

uint32_t littleEndianAt(const std::string& bytes, size_t offset)
{
    uint32_t x = 0;
    for (int k = 3; k >= 0; --k) x = (x << 8) | uint8_t(bytes[offset + k]);
    return x;
}

TEST(Procedural, BinaryPlyBytes)
{
    const auto dir = test::freshTempDir("procedural-ply-binary");
    const MeshData g = makeGrid(2);
    writePly(g, dir / "grid.ply", true);
    const std::string bytes = readFile(dir / "grid.ply");
    const std::string header = gridPlyHeader("binary_little_endian");
    ASSERT_EQ(bytes.substr(0, header.size()), header);
    ASSERT_EQ(bytes.size(), header.size() + 9 * 8 * 4 + 8 * (1 + 3 * 4));
    const size_t vertex4 = header.size() + 4 * 8 * 4; // x, y, z, nx, ny, nz, s, t of vertex 4
    EXPECT_EQ(std::bit_cast<float>(littleEndianAt(bytes, vertex4)), g.positions[4].x);
    EXPECT_EQ(std::bit_cast<float>(littleEndianAt(bytes, vertex4 + 5 * 4)), 1.0f);       // nz
    EXPECT_EQ(std::bit_cast<float>(littleEndianAt(bytes, vertex4 + 7 * 4)), g.uvs[4].y); // t
    const size_t face1 = header.size() + 9 * 8 * 4 + 13;
    EXPECT_EQ(uint8_t(bytes[face1]), 3);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(littleEndianAt(bytes, face1 + 1 + 4 * k), g.triangles[1][k]);
}

TEST(Procedural, AsciiPlyLines)
{
    const auto dir = test::freshTempDir("procedural-ply-ascii");
    const MeshData g = makeGrid(2);
    writePly(g, dir / "grid.ply", false);
    const std::string text = readFile(dir / "grid.ply");
    const std::string header = gridPlyHeader("ascii");
    ASSERT_EQ(text.substr(0, header.size()), header);
    const std::vector<std::string> lines = linesOf(text.substr(header.size()));
    ASSERT_EQ(lines.size(), 9u + 8u);
    EXPECT_EQ(lines[0], "-1 -1 0 0 0 1 0 0");
    EXPECT_EQ(lines[9], "3 0 1 4");
    EXPECT_EQ(lines[16], "3 4 8 7");
}

TEST(Procedural, WriterFailureNamesTheFile)
{
    const auto missing = test::freshTempDir("procedural-missing") / "no-such-dir" / "x.ply";
    try {
        writePly(makeGrid(1), missing, true);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
    }
    EXPECT_THROW(writeObj(makeGrid(1), missing), InputError);
}

} // namespace
} // namespace vkrt
