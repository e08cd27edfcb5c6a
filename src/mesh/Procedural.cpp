#include "mesh/Procedural.h"

#include "io/AtomicFile.h"
#include "util/Error.h"

#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <fstream>
#include <numbers>
#include <string>
#include <unordered_map>

namespace vkrt {

namespace {

/// A vertex on the sphere in direction `dir` (unit, double): the position
/// rounded once to float, the normal the exact direction rounded to float.
void addSphereVertex(MeshData& mesh, const glm::dvec3& dir, glm::vec3 centre, float radius)
{
    mesh.positions.push_back(glm::vec3(glm::dvec3(centre) + double(radius) * dir));
    mesh.normals.push_back(glm::vec3(dir));
}

/// Stacks s and slices m of the smallest UV sphere with m <= 2 s and 2 m (s - 1) >= triangles.
std::pair<uint32_t, uint32_t> uvSphereShape(uint32_t triangles)
{
    uint64_t stacks = 2;
    while (4 * stacks * (stacks - 1) < triangles) ++stacks;
    const uint64_t perSlice = 2 * (stacks - 1);
    const uint64_t slices = std::max<uint64_t>(3, (triangles + perSlice - 1) / perSlice);
    return {uint32_t(stacks), uint32_t(slices)};
}

} // namespace

MeshData makeUvSphere(uint32_t trianglesAtLeast, glm::vec3 centre, float radius)
{
    const auto [stacks, slices] = uvSphereShape(trianglesAtLeast);
    MeshData mesh;
    // ---- vertices: north pole, rings 1 ... stacks - 1 from north to south, south pole
    addSphereVertex(mesh, {0.0, 0.0, 1.0}, centre, radius);
    for (uint32_t i = 1; i < stacks; ++i) {
        const double theta = std::numbers::pi * i / stacks;
        for (uint32_t j = 0; j < slices; ++j) {
            const double phi = 2.0 * std::numbers::pi * j / slices;
            const glm::dvec3 dir(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
            addSphereVertex(mesh, glm::normalize(dir), centre, radius);
        }
    }
    addSphereVertex(mesh, {0.0, 0.0, -1.0}, centre, radius);
    // ---- triangles, counter-clockwise seen from outside
    const auto ring = [slices](uint32_t i, uint32_t j) { return 1 + (i - 1) * slices + j % slices; };
    const uint32_t south = uint32_t(mesh.positions.size() - 1);
    mesh.triangles.reserve(size_t(2) * slices * (stacks - 1));
    for (uint32_t j = 0; j < slices; ++j) mesh.triangles.emplace_back(0, ring(1, j), ring(1, j + 1));
    for (uint32_t i = 1; i + 1 < stacks; ++i) {
        for (uint32_t j = 0; j < slices; ++j) {
            mesh.triangles.emplace_back(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1));
            mesh.triangles.emplace_back(ring(i, j), ring(i + 1, j + 1), ring(i, j + 1));
        }
    }
    for (uint32_t j = 0; j < slices; ++j)
        mesh.triangles.emplace_back(south, ring(stacks - 1, j + 1), ring(stacks - 1, j));
    return mesh;
}

namespace {

/// The icosahedron's unit vertices and outward (counter-clockwise) faces.
void icosahedron(std::vector<glm::dvec3>& dirs, std::vector<glm::uvec3>& faces)
{
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    dirs = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
            {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    for (glm::dvec3& d : dirs) d = glm::normalize(d);
    faces = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
             {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
             {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
}

/// Splits every face in four at its edges' midpoints (pushed onto the sphere, shared between neighbours).
void subdivide(std::vector<glm::dvec3>& dirs, std::vector<glm::uvec3>& faces)
{
    std::unordered_map<uint64_t, uint32_t> midpoints;
    const auto midpoint = [&](uint32_t a, uint32_t b) {
        const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
        auto [it, added] = midpoints.try_emplace(key, uint32_t(dirs.size()));
        if (added) dirs.push_back(glm::normalize(dirs[a] + dirs[b]));
        return it->second;
    };
    std::vector<glm::uvec3> finer;
    finer.reserve(faces.size() * 4);
    for (const glm::uvec3& f : faces) {
        const uint32_t ab = midpoint(f.x, f.y), bc = midpoint(f.y, f.z), ca = midpoint(f.z, f.x);
        finer.insert(finer.end(), {{f.x, ab, ca}, {f.y, bc, ab}, {f.z, ca, bc}, {ab, bc, ca}});
    }
    faces = std::move(finer);
}

} // namespace

MeshData makeIcosphere(int subdivisions, glm::vec3 centre, float radius)
{
    if (subdivisions < 0 || subdivisions > 10)
        throw InputError("icosphere: subdivisions must be 0 ... 10, not " + std::to_string(subdivisions));
    std::vector<glm::dvec3> dirs;
    MeshData mesh;
    icosahedron(dirs, mesh.triangles);
    for (int level = 0; level < subdivisions; ++level) subdivide(dirs, mesh.triangles);
    mesh.positions.reserve(dirs.size());
    mesh.normals.reserve(dirs.size());
    for (const glm::dvec3& d : dirs) addSphereVertex(mesh, d, centre, radius);
    return mesh;
}

MeshData makeGrid(uint32_t n)
{
    if (n < 1 || n > 16384) throw InputError("grid: n must be 1 ... 16384, not " + std::to_string(n));
    MeshData mesh;
    const uint32_t side = n + 1;
    for (uint32_t j = 0; j < side; ++j) {
        for (uint32_t i = 0; i < side; ++i) {
            const glm::dvec2 uv(double(i) / n, double(j) / n);
            mesh.positions.emplace_back(float(2.0 * uv.x - 1.0), float(2.0 * uv.y - 1.0), 0.0f);
            mesh.normals.emplace_back(0.0f, 0.0f, 1.0f);
            mesh.uvs.push_back(glm::vec2(uv));
        }
    }
    mesh.triangles.reserve(size_t(2) * n * n);
    for (uint32_t j = 0; j < n; ++j) {
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t a = j * side + i, b = a + 1, c = a + side + 1, d = a + side;
            mesh.triangles.emplace_back(a, b, c);
            mesh.triangles.emplace_back(a, c, d);
        }
    }
    return mesh;
}

namespace {

/// SplitMix64 (Steele, Lea & Flood 2014): a tiny generator whose output is
/// fixed by its definition, unlike <random>'s distributions.
class SplitMix64 {
public:
    explicit SplitMix64(uint64_t seed) : m_state(seed) {}
    uint64_t next()
    {
        uint64_t z = (m_state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    /// Uniform in [0, 1), 53 bits.
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }

private:
    uint64_t m_state;
};

} // namespace

MeshData makeRandomSoup(uint32_t n, uint32_t seed)
{
    if (n < 1) throw InputError("random soup: needs at least one triangle");
    // Triangles about as large as the spacing of n points in the cube (at most 0.1).
    const double halfSize = std::min(0.05, 0.5 / std::cbrt(double(n)));
    SplitMix64 random(seed);
    MeshData mesh;
    mesh.positions.reserve(size_t(3) * n);
    mesh.triangles.reserve(n);
    for (uint32_t i = 0; i < n; ++i) {
        glm::dvec3 centre;
        for (int k = 0; k < 3; ++k) centre[k] = halfSize + (1.0 - 2.0 * halfSize) * random.uniform();
        for (int v = 0; v < 3; ++v) {
            glm::dvec3 p;
            for (int k = 0; k < 3; ++k) p[k] = centre[k] + halfSize * (2.0 * random.uniform() - 1.0);
            mesh.positions.push_back(glm::vec3(p));
        }
        mesh.triangles.emplace_back(3 * i, 3 * i + 1, 3 * i + 2);
    }
    return mesh;
}

MeshData makeQuad(glm::vec3 corner, glm::vec3 edgeU, glm::vec3 edgeV)
{
    MeshData mesh;
    mesh.positions = {corner, corner + edgeU, corner + edgeU + edgeV, corner + edgeV};
    mesh.uvs = {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}};
    const glm::vec3 normal = glm::cross(edgeU, edgeV);
    if (glm::length(normal) > 0.0f) mesh.normals.assign(4, glm::normalize(normal));
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
    return mesh;
}

// ------------------------------------------------------------------ writers

namespace {

/// Buffered output to a file that reports failure as an InputError naming it.
class FileWriter {
public:
    FileWriter(const std::filesystem::path& file, const std::filesystem::path& shownAs)
        : m_stream(file, std::ios::binary),
          m_shownAs(shownAs)
    {
        if (!m_stream) fail();
        m_buffer.reserve(1 << 20);
    }
    void text(std::string_view s)
    {
        m_buffer.append(s);
        flushIfFull();
    }
    /// The shortest text that reads back as exactly `x`.
    void number(float x)
    {
        char digits[32];
        const auto end = std::to_chars(digits, digits + sizeof digits, x).ptr;
        text(std::string_view(digits, size_t(end - digits)));
    }
    void number(uint32_t x) { text(std::to_string(x)); }
    void littleEndian(uint32_t x)
    {
        for (int shift = 0; shift < 32; shift += 8) m_buffer.push_back(char((x >> shift) & 0xFF));
        flushIfFull();
    }
    void littleEndian(float x) { littleEndian(std::bit_cast<uint32_t>(x)); }
    void byte(uint8_t b) { m_buffer.push_back(char(b)); }
    void close()
    {
        flush();
        m_stream.close();
        if (!m_stream) fail();
    }

private:
    void flushIfFull()
    {
        if (m_buffer.size() >= (1 << 20)) flush();
    }
    void flush()
    {
        m_stream.write(m_buffer.data(), std::streamsize(m_buffer.size()));
        m_buffer.clear();
        if (!m_stream) fail();
    }
    [[noreturn]] void fail() { throw InputError(m_shownAs.string() + ": cannot write the mesh file"); }

    std::ofstream m_stream;
    std::filesystem::path m_shownAs;
    std::string m_buffer;
};

void writeObjVertices(FileWriter& out, const MeshData& mesh)
{
    const auto triple = [&out](const char* tag, const glm::vec3& v) {
        out.text(tag);
        for (int k = 0; k < 3; ++k) {
            out.text(" ");
            out.number(v[k]);
        }
        out.text("\n");
    };
    for (const glm::vec3& p : mesh.positions) triple("v", p);
    for (const glm::vec3& n : mesh.normals) triple("vn", n);
    for (const glm::vec2& uv : mesh.uvs) {
        out.text("vt ");
        out.number(uv.x);
        out.text(" ");
        out.number(uv.y);
        out.text("\n");
    }
}

/// "i", "i/i", "i//i" or "i/i/i": OBJ's 1-based position[/uv][/normal] reference.
void writeObjCorner(FileWriter& out, uint32_t index, bool uvs, bool normals)
{
    const std::string one = std::to_string(index + 1);
    out.text(one);
    if (!uvs && !normals) return;
    out.text("/");
    if (uvs) out.text(one);
    if (normals) {
        out.text("/");
        out.text(one);
    }
}

} // namespace

void writeObj(const MeshData& mesh, const std::filesystem::path& path)
{
    writeFileAtomically(path, [&](const std::filesystem::path& temporary) {
        FileWriter out(temporary, path);
        out.text("# vkrt procedural mesh: " + std::to_string(mesh.positions.size()) + " vertices, " +
                 std::to_string(mesh.triangles.size()) + " triangles\n");
        writeObjVertices(out, mesh);
        for (const glm::uvec3& t : mesh.triangles) {
            out.text("f");
            for (int k = 0; k < 3; ++k) {
                out.text(" ");
                writeObjCorner(out, t[k], !mesh.uvs.empty(), !mesh.normals.empty());
            }
            out.text("\n");
        }
        out.close();
    });
}

namespace {

std::string plyHeader(const MeshData& mesh, bool binary)
{
    std::string h = "ply\nformat ";
    h += binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
    h += "comment vkrt procedural mesh\n";
    h += "element vertex " + std::to_string(mesh.positions.size()) + "\n";
    h += "property float x\nproperty float y\nproperty float z\n";
    if (!mesh.normals.empty()) h += "property float nx\nproperty float ny\nproperty float nz\n";
    if (!mesh.uvs.empty()) h += "property float s\nproperty float t\n";
    h += "element face " + std::to_string(mesh.triangles.size()) + "\n";
    h += "property list uchar uint vertex_indices\nend_header\n";
    return h;
}

/// One vertex's floats in header order.
std::vector<float> plyVertex(const MeshData& mesh, size_t i)
{
    std::vector<float> v{mesh.positions[i].x, mesh.positions[i].y, mesh.positions[i].z};
    if (!mesh.normals.empty()) v.insert(v.end(), {mesh.normals[i].x, mesh.normals[i].y, mesh.normals[i].z});
    if (!mesh.uvs.empty()) v.insert(v.end(), {mesh.uvs[i].x, mesh.uvs[i].y});
    return v;
}

void writePlyBody(FileWriter& out, const MeshData& mesh, bool binary)
{
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        const std::vector<float> v = plyVertex(mesh, i);
        for (size_t k = 0; k < v.size(); ++k) {
            if (binary) {
                out.littleEndian(v[k]);
                continue;
            }
            if (k > 0) out.text(" ");
            out.number(v[k]);
        }
        if (!binary) out.text("\n");
    }
    for (const glm::uvec3& t : mesh.triangles) {
        if (binary) out.byte(3);
        else out.text("3");
        for (int k = 0; k < 3; ++k) {
            if (binary) {
                out.littleEndian(uint32_t(t[k]));
                continue;
            }
            out.text(" ");
            out.number(uint32_t(t[k]));
        }
        if (!binary) out.text("\n");
    }
}

} // namespace

void writePly(const MeshData& mesh, const std::filesystem::path& path, bool binary)
{
    writeFileAtomically(path, [&](const std::filesystem::path& temporary) {
        FileWriter out(temporary, path);
        out.text(plyHeader(mesh, binary));
        writePlyBody(out, mesh, binary);
        out.close();
    });
}

} // namespace vkrt
