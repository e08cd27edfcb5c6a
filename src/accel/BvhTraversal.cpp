#include "accel/BvhTraversal.h"

#include <algorithm>
#include <vector>

namespace vkrt {

namespace {

/// gamma(n) = n u / (1 - n u) in float, as shaders/lib/ray.glsl computes it.
float gammaBound(int n)
{
    const float unitRoundoff = 5.96046448e-8f;
    return float(n) * unitRoundoff / (1.0f - float(n) * unitRoundoff);
}

} // namespace

TraversalRay makeTraversalRay(const glm::vec3& origin, const glm::vec3& direction)
{
    TraversalRay r;
    r.origin = origin;
    r.direction = direction;
    // triangleRaySetup (intersect.glsl)
    const glm::vec3 a = glm::abs(direction);
    r.kz = (a.x > a.y) ? ((a.x > a.z) ? 0 : 2) : ((a.y > a.z) ? 1 : 2);
    r.kx = (r.kz + 1) % 3;
    r.ky = (r.kx + 1) % 3;
    if (direction[r.kz] < 0.0f) std::swap(r.kx, r.ky);
    r.shear = glm::vec3(direction[r.kx] / direction[r.kz], direction[r.ky] / direction[r.kz], 1.0f / direction[r.kz]);
    // bvhRaySetup (bvh.glsl): a zero component becomes a tiny one, so that no
    // 0 * inf = NaN arises for an origin on a slab's plane.
    glm::vec3 d = direction;
    for (int k = 0; k < 3; ++k) d[k] = d[k] == 0.0f ? 1e-30f : d[k];
    r.invDir = 1.0f / d;
    return r;
}

std::optional<TriangleHit> intersectTriangle(const glm::vec3& v0, const glm::vec3& v1, const glm::vec3& v2,
                                             const TraversalRay& r, float tMax)
{
    const glm::vec3 A = v0 - r.origin;
    const glm::vec3 B = v1 - r.origin;
    const glm::vec3 C = v2 - r.origin;
    const float Ax = A[r.kx] - r.shear.x * A[r.kz];
    const float Ay = A[r.ky] - r.shear.y * A[r.kz];
    const float Bx = B[r.kx] - r.shear.x * B[r.kz];
    const float By = B[r.ky] - r.shear.y * B[r.kz];
    const float Cx = C[r.kx] - r.shear.x * C[r.kz];
    const float Cy = C[r.ky] - r.shear.y * C[r.kz];
    const float U = Cx * By - Cy * Bx;
    const float V = Ax * Cy - Ay * Cx;
    const float W = Bx * Ay - By * Ax;
    if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return std::nullopt;
    const float det = U + V + W;
    if (det == 0.0f) return std::nullopt;
    const float T = U * (r.shear.z * A[r.kz]) + V * (r.shear.z * B[r.kz]) + W * (r.shear.z * C[r.kz]);
    // t = T / det must lie in (0, tMax); compared before dividing to keep signs exact.
    const float signedT = det < 0.0f ? -T : T;
    const float absDet = std::abs(det);
    if (signedT <= 0.0f || signedT >= tMax * absDet) return std::nullopt;
    // Exactly collinear vertices can still give a tiny nonzero sheared area.
    if (glm::cross(v1 - v0, v2 - v0) == glm::vec3(0.0f)) return std::nullopt;
    TriangleHit hit;
    hit.t = T / det;
    hit.barycentrics = glm::vec3(U, V, W) / det;
    if (!(hit.t > 0.0f && hit.t < tMax)) return std::nullopt;
    return hit;
}

bool entersBox(const glm::vec3& lower, const glm::vec3& upper, const TraversalRay& r, float tMax, float& tEntry)
{
    const glm::vec3 t0 = (lower - r.origin) * r.invDir;
    const glm::vec3 t1 = (upper - r.origin) * r.invDir;
    const glm::vec3 tNear = glm::min(t0, t1);
    const glm::vec3 tFar = glm::max(t0, t1);
    tEntry = std::max(std::max(tNear.x, tNear.y), std::max(tNear.z, 0.0f));
    const float tExit = std::min(std::min(tFar.x, tFar.y), std::min(tFar.z, tMax)) * (1.0f + 2.0f * gammaBound(3));
    return tEntry <= tExit;
}

namespace {

/// What one traversal looks for and what it found.
struct Query {
    bool anyHit = false;
    float tMax = 0.0f;
    std::optional<TriangleHit> best;
    TraversalStats stats;
    float limit() const { return anyHit || !best ? tMax : best->t; }
};

/// Tests a leaf's triangles; returns true when an any-hit query is answered.
bool testLeaf(const gpu::BvhNode& n, const Bvh& bvh, const TriangleSet& mesh, const TraversalRay& r, Query& q)
{
    for (uint32_t k = 0; k < n.count; ++k) {
        ++q.stats.trianglesTested;
        const uint32_t primitive = bvh.order[n.first + k];
        const glm::uvec3& tri = mesh.triangles[primitive];
        auto hit = intersectTriangle(mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z], r, q.limit());
        if (!hit) continue;
        hit->primitive = primitive;
        q.best = hit;
        if (q.anyHit) return true;
    }
    return false;
}

/// traverseMesh of scene.glsl: a stack of far children with their entry
/// distances, near child first, nodes beyond the closest hit skipped.
void traverse(const Bvh& bvh, const TriangleSet& mesh, const TraversalRay& r, Query& q)
{
    std::vector<std::pair<uint32_t, float>> stack;
    stack.reserve(bvh.depth + 1);
    uint32_t node = 0;
    float tEntry = 0.0f;
    bool visiting = entersBox(bvh.nodes[0].lower, bvh.nodes[0].upper, r, q.limit(), tEntry);
    while (visiting) {
        ++q.stats.nodesVisited;
        const gpu::BvhNode& n = bvh.nodes[node];
        bool descend = false;
        if (n.count > 0) {
            if (testLeaf(n, bvh, mesh, r, q)) return;
        } else {
            const gpu::BvhNode& a = bvh.nodes[n.first];
            const gpu::BvhNode& b = bvh.nodes[n.first + 1];
            float ta = 0.0f, tb = 0.0f;
            const bool ha = entersBox(a.lower, a.upper, r, q.limit(), ta);
            const bool hb = entersBox(b.lower, b.upper, r, q.limit(), tb);
            if (ha && hb) {
                const bool aFirst = ta <= tb;
                stack.emplace_back(aFirst ? n.first + 1 : n.first, aFirst ? tb : ta);
                node = aFirst ? n.first : n.first + 1;
                descend = true;
            } else if (ha || hb) {
                node = ha ? n.first : n.first + 1;
                descend = true;
            }
        }
        if (descend) continue;
        visiting = false;
        while (!stack.empty()) {
            const auto [next, entry] = stack.back();
            stack.pop_back();
            if (entry <= q.limit()) {
                node = next;
                visiting = true;
                break;
            }
        }
    }
}

Query run(const Bvh& bvh, const TriangleSet& mesh, const glm::vec3& origin, const glm::vec3& direction, float tMax,
          bool anyHit)
{
    Query q;
    q.anyHit = anyHit;
    q.tMax = tMax;
    if (!bvh.nodes.empty()) traverse(bvh, mesh, makeTraversalRay(origin, direction), q);
    return q;
}

} // namespace

std::optional<TriangleHit> closestHit(const Bvh& bvh, const TriangleSet& mesh, const glm::vec3& origin,
                                      const glm::vec3& direction, float tMax)
{
    return run(bvh, mesh, origin, direction, tMax, false).best;
}

bool anyHit(const Bvh& bvh, const TriangleSet& mesh, const glm::vec3& origin, const glm::vec3& direction, float tMax)
{
    return run(bvh, mesh, origin, direction, tMax, true).best.has_value();
}

TraversalStats traversalStats(const Bvh& bvh, const TriangleSet& mesh, const glm::vec3& origin,
                              const glm::vec3& direction, float tMax)
{
    return run(bvh, mesh, origin, direction, tMax, false).stats;
}

std::optional<TriangleHit> bruteForceClosestHit(const TriangleSet& mesh, const glm::vec3& origin,
                                                const glm::vec3& direction, float tMax)
{
    const TraversalRay r = makeTraversalRay(origin, direction);
    std::optional<TriangleHit> best;
    for (uint32_t i = 0; i < mesh.triangles.size(); ++i) {
        const glm::uvec3& tri = mesh.triangles[i];
        const float limit = best ? best->t : tMax;
        auto hit = intersectTriangle(mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z], r, limit);
        if (!hit) continue;
        hit->primitive = i;
        best = hit;
    }
    return best;
}

} // namespace vkrt
