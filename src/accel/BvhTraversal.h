#pragma once
// CPU reference traversal of the trees of Bvh.h over triangles, mirroring
// shaders/lib/bvh.glsl and intersect.glsl operation for operation in float:
// the same watertight ray/triangle test (Woop, Benthin & Wald, JCGT 2013),
// the same slab test widened by 2 gamma(3), a stack, near child first. Tests
// check the builder with it; benchmarks count the work a ray does.
#include "accel/Bvh.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <optional>
#include <span>

namespace vkrt {

/// A ray and its per-ray set-up for the triangle and box tests.
struct TraversalRay {
    glm::vec3 origin;
    glm::vec3 direction;
    int kx = 0, ky = 1, kz = 2; ///< kz: the dominant axis of `direction`
    glm::vec3 shear{0.0f};      ///< (Sx, Sy, Sz) of the watertight test
    glm::vec3 invDir{0.0f};     ///< 1 / direction, zero components made tiny
};

TraversalRay makeTraversalRay(const glm::vec3& origin, const glm::vec3& direction);

/// A triangle hit: distance, triangle index (original order) and barycentric weights of v0, v1, v2.
struct TriangleHit {
    float t = 0.0f;
    uint32_t primitive = 0;
    glm::vec3 barycentrics{0.0f};
};

/// The watertight test of intersect.glsl: a hit with t in (0, tMax), both faces; never a degenerate triangle.
std::optional<TriangleHit> intersectTriangle(const glm::vec3& v0, const glm::vec3& v1, const glm::vec3& v2,
                                             const TraversalRay& ray, float tMax);

/// The slab test of bvh.glsl: whether the ray enters the box before tMax, and where (0 when it starts inside).
bool entersBox(const glm::vec3& lower, const glm::vec3& upper, const TraversalRay& ray, float tMax, float& tEntry);

/// The mesh a BVH was built over: triangles in their original order, indexed through bvh.order.
struct TriangleSet {
    std::span<const glm::vec3> positions;
    std::span<const glm::uvec3> triangles;
};

/// The closest hit before tMax. Of hits at exactly the same t, the first one found wins, as in the GLSL.
std::optional<TriangleHit> closestHit(const Bvh& bvh, const TriangleSet& mesh, const glm::vec3& origin,
                                      const glm::vec3& direction, float tMax);

/// Whether anything is hit before tMax.
bool anyHit(const Bvh& bvh, const TriangleSet& mesh, const glm::vec3& origin, const glm::vec3& direction, float tMax);

/// The work of one closest-hit query.
struct TraversalStats {
    uint32_t nodesVisited = 0; ///< nodes whose box was entered and which were then processed
    uint32_t trianglesTested = 0;
};

TraversalStats traversalStats(const Bvh& bvh, const TriangleSet& mesh, const glm::vec3& origin,
                              const glm::vec3& direction, float tMax);

/// The closest hit by testing every triangle in index order (what closestHit must find).
std::optional<TriangleHit> bruteForceClosestHit(const TriangleSet& mesh, const glm::vec3& origin,
                                                const glm::vec3& direction, float tMax);

} // namespace vkrt
