#include "mesh/MeshData.h"

#include "util/Hash.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <unordered_map>

namespace vkrt {

namespace {

/// Bit pattern of a position: equal keys are exactly equal coordinates
/// (after folding -0 into +0, which compares equal).
struct PositionKey {
    uint32_t bits[3];
    bool operator==(const PositionKey&) const = default;
};

struct PositionHash {
    size_t operator()(const PositionKey& k) const
    {
        return (size_t(k.bits[0]) * 73856093u) ^ (size_t(k.bits[1]) * 19349663u) ^ (size_t(k.bits[2]) * 83492791u);
    }
};

PositionKey keyOf(glm::vec3 p)
{
    PositionKey key;
    for (int i = 0; i < 3; ++i) {
        const float v = p[i] == 0.0f ? 0.0f : p[i];
        std::memcpy(&key.bits[i], &v, sizeof v);
    }
    return key;
}

/// For every vertex, the first vertex at exactly its position: mesh files
/// (and assimp's OBJ importer, which gives each face corner its own vertex)
/// often split a surface's vertices, and smoothing must join them again.
std::vector<uint32_t> weldByPosition(const std::vector<glm::vec3>& positions)
{
    std::unordered_map<PositionKey, uint32_t, PositionHash> first;
    first.reserve(positions.size());
    std::vector<uint32_t> weld(positions.size());
    for (uint32_t v = 0; v < positions.size(); ++v) weld[v] = first.try_emplace(keyOf(positions[v]), v).first->second;
    return weld;
}

/// Area-weighted vertex normals, (0, 0, 0) where a vertex's faces are all degenerate.
std::vector<glm::vec3> smoothNormals(const MeshData& mesh)
{
    // The unnormalised cross product of two edges is the face normal scaled by
    // twice the area, so summing it weights each face by its area. Doubles:
    // float cross products of large coordinates can overflow. Vertices at the
    // same position share one sum.
    const std::vector<uint32_t> weld = weldByPosition(mesh.positions);
    std::vector<glm::dvec3> sums(mesh.positions.size(), glm::dvec3(0.0));
    for (const glm::uvec3& triangle : mesh.triangles) {
        const glm::dvec3 p0 = mesh.positions[triangle.x];
        const glm::dvec3 areaNormal = glm::cross(glm::dvec3(mesh.positions[triangle.y]) - p0,
                                                 glm::dvec3(mesh.positions[triangle.z]) - p0);
        for (int corner = 0; corner < 3; ++corner) sums[weld[triangle[corner]]] += areaNormal;
    }
    std::vector<glm::vec3> normals(mesh.positions.size());
    for (size_t vertex = 0; vertex < sums.size(); ++vertex) {
        const double length = glm::length(sums[weld[vertex]]);
        // (0, 0, 0) tells the renderer to use the face normal (MeshData.h).
        normals[vertex] =
            length > 0.0 && std::isfinite(length) ? glm::vec3(sums[weld[vertex]] / length) : glm::vec3(0.0f);
    }
    return normals;
}

// ---------------------------------------------------------------------------
// Tangents.

/// The normal each vertex's tangent is made perpendicular to: its own where
/// it has one, else the smooth normal; (0, 0, 0) where neither exists.
std::vector<glm::vec3> tangentReferenceNormals(const MeshData& mesh)
{
    const auto isZero = [](const glm::vec3& n) { return n == glm::vec3(0.0f); };
    const bool complete = !mesh.normals.empty() && std::none_of(mesh.normals.begin(), mesh.normals.end(), isZero);
    if (complete) return mesh.normals;
    std::vector<glm::vec3> reference = smoothNormals(mesh);
    if (!mesh.normals.empty())
        for (size_t v = 0; v < reference.size(); ++v)
            if (!isZero(mesh.normals[v])) reference[v] = mesh.normals[v];
    return reference;
}

/// Bit patterns of a vertex's position, normal and uv (-0 folded into +0).
struct AttributeKey {
    std::array<uint32_t, 8> bits{};
    bool operator==(const AttributeKey&) const = default;
};

struct AttributeHash {
    size_t operator()(const AttributeKey& k) const
    {
        return Fnv1a64().add({reinterpret_cast<const char*>(k.bits.data()), sizeof k.bits}).value();
    }
};

AttributeKey attributeKey(const MeshData& mesh, uint32_t vertex)
{
    std::array<float, 8> values{};
    for (int i = 0; i < 3; ++i) values[i] = mesh.positions[vertex][i];
    if (!mesh.normals.empty())
        for (int i = 0; i < 3; ++i) values[3 + i] = mesh.normals[vertex][i];
    for (int i = 0; i < 2; ++i) values[6 + i] = tangentUvs(mesh)[vertex][i];
    AttributeKey key;
    for (size_t i = 0; i < values.size(); ++i) {
        const float v = values[i] == 0.0f ? 0.0f : values[i];
        std::memcpy(&key.bits[i], &v, sizeof v);
    }
    return key;
}

/// For every vertex, the first vertex with exactly its position, normal and
/// uv: MikkTSpace's welding, which keeps uv seams (same position, other uv) apart.
std::vector<uint32_t> weldByAttributes(const MeshData& mesh)
{
    std::unordered_map<AttributeKey, uint32_t, AttributeHash> first;
    first.reserve(mesh.positions.size());
    std::vector<uint32_t> weld(mesh.positions.size());
    for (uint32_t v = 0; v < mesh.positions.size(); ++v) weld[v] = first.try_emplace(attributeKey(mesh, v), v).first->second;
    return weld;
}

/// `v` without its component along the unit (or zero) `n`.
glm::dvec3 withoutNormal(const glm::dvec3& v, const glm::dvec3& n) { return v - n * glm::dot(n, v); }

/// Angle-weighted sums of one welded vertex's per-triangle tangent frames.
struct TangentSum {
    glm::dvec3 tangent{0.0};
    glm::dvec3 bitangent{0.0};
    double weight = 0.0;
};

/// The angle at corner `k` of the triangle (0 for a degenerate corner).
double cornerAngle(const std::array<glm::dvec3, 3>& p, int k)
{
    const glm::dvec3 a = p[(k + 1) % 3] - p[k];
    const glm::dvec3 b = p[(k + 2) % 3] - p[k];
    const double angle = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
    return std::isfinite(angle) ? angle : 0.0;
}

/// Adds one triangle's frame to its corners' sums; nothing when its uvs are degenerate.
void accumulateTriangle(const MeshData& mesh, const glm::uvec3& triangle, const std::vector<glm::vec3>& reference,
                        const std::vector<uint32_t>& weld, std::vector<TangentSum>& sums)
{
    std::array<glm::dvec3, 3> p;
    std::array<glm::dvec2, 3> uv;
    for (int k = 0; k < 3; ++k) {
        p[k] = mesh.positions[triangle[k]];
        uv[k] = tangentUvs(mesh)[triangle[k]];
    }
    // p - p0 = (u - u0) dp/du + (v - v0) dp/dv, solved for dp/du and dp/dv over two edges.
    const glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const glm::dvec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
    const double det = d1.x * d2.y - d2.x * d1.y;
    if (det == 0.0 || !std::isfinite(det)) return;
    const glm::dvec3 dpdu = (e1 * d2.y - e2 * d1.y) / det;
    const glm::dvec3 dpdv = (e2 * d1.x - e1 * d2.x) / det;
    for (int k = 0; k < 3; ++k) {
        const double angle = cornerAngle(p, k);
        const glm::dvec3 n = reference[triangle[k]];
        const glm::dvec3 t = withoutNormal(dpdu, n), b = withoutNormal(dpdv, n);
        const double tLength = glm::length(t), bLength = glm::length(b);
        if (angle <= 0.0 || !(tLength > 0.0) || !std::isfinite(tLength)) continue;
        TangentSum& sum = sums[weld[triangle[k]]];
        sum.tangent += t / tLength * angle;
        if (bLength > 0.0 && std::isfinite(bLength)) sum.bitangent += b / bLength * angle;
        sum.weight += angle;
    }
}

/// A vertex's tangent from its sum: perpendicular to `n`, unit, w from the bitangent's side.
glm::vec4 finishTangent(const TangentSum& sum, const glm::vec3& normal)
{
    const glm::dvec3 n = normal;
    const glm::dvec3 t = withoutNormal(sum.tangent, n);
    const double length = glm::length(t);
    // Sums that cancel (to a millionth of their weight) have no direction worth keeping.
    if (!(length > 1e-6 * sum.weight) || !std::isfinite(length)) {
        const glm::vec3 fallback = normal == glm::vec3(0.0f) ? glm::vec3(1.0f, 0.0f, 0.0f) : perpendicularTo(normal);
        return glm::vec4(fallback, 1.0f);
    }
    const glm::dvec3 unit = t / length;
    const double side = glm::dot(glm::cross(n, unit), sum.bitangent);
    return glm::vec4(glm::vec3(unit), side < 0.0 ? -1.0f : 1.0f);
}

/// Makes the tangents perpendicular to the (new) normals again, keeping w.
void reorthogonaliseTangents(MeshData& mesh)
{
    if (mesh.tangents.empty()) return;
    const std::vector<glm::vec3> reference = tangentReferenceNormals(mesh);
    for (size_t v = 0; v < mesh.tangents.size(); ++v) {
        const glm::dvec3 n = reference[v];
        const glm::dvec3 t = withoutNormal(glm::dvec3(mesh.tangents[v]), n);
        const double length = glm::length(t);
        glm::vec3 tangent = glm::vec3(mesh.tangents[v]);
        if (length > 1e-6 && std::isfinite(length))
            tangent = glm::vec3(t / length);
        else if (reference[v] != glm::vec3(0.0f))
            tangent = perpendicularTo(reference[v]);
        mesh.tangents[v] = glm::vec4(tangent, mesh.tangents[v].w);
    }
}

} // namespace

void computeSmoothNormals(MeshData& mesh) { mesh.normals = smoothNormals(mesh); }

void applyNormalMode(MeshData& mesh, NormalMode mode)
{
    switch (mode) {
    case NormalMode::File:
        return;
    case NormalMode::Smooth:
        computeSmoothNormals(mesh);
        break;
    case NormalMode::Face:
        mesh.normals.clear();
        break;
    }
    reorthogonaliseTangents(mesh);
}

glm::vec3 perpendicularTo(glm::vec3 n)
{
    // Duff et al. 2017, listing 3: the first vector of their branchless frame.
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    return glm::normalize(glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x));
}

void computeTangents(MeshData& mesh)
{
    mesh.tangents.clear();
    if (tangentUvs(mesh).empty()) return;
    const std::vector<glm::vec3> reference = tangentReferenceNormals(mesh);
    const std::vector<uint32_t> weld = weldByAttributes(mesh);
    std::vector<TangentSum> sums(mesh.positions.size());
    for (const glm::uvec3& triangle : mesh.triangles) accumulateTriangle(mesh, triangle, reference, weld, sums);
    mesh.tangents.resize(mesh.positions.size());
    for (size_t v = 0; v < mesh.positions.size(); ++v) mesh.tangents[v] = finishTangent(sums[weld[v]], reference[v]);
}

} // namespace vkrt
