// The BVH builder's invariants, determinism and depth budget, and the CPU
// reference traversal against brute force (src/accel/Bvh.h, BvhTraversal.h).
#include "accel/Bvh.h"
#include "accel/BvhTraversal.h"
#include "mesh/Procedural.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace vkrt {
namespace {

bool contains(const gpu::BvhNode& outer, const glm::vec3& lower, const glm::vec3& upper)
{
    return glm::all(glm::lessThanEqual(outer.lower, lower)) && glm::all(glm::lessThanEqual(upper, outer.upper));
}

bool containsExactly(const gpu::BvhNode& outer, const Aabb& box)
{
    return glm::all(glm::lessThanEqual(glm::dvec3(outer.lower), box.lower)) &&
           glm::all(glm::lessThanEqual(box.upper, glm::dvec3(outer.upper)));
}

/// Every promise of Bvh.h, checked by walking the tree from the root.
::testing::AssertionResult wellFormed(const Bvh& bvh, std::span<const Aabb> boxes, uint32_t maxLeafSize)
{
    const size_t n = boxes.size();
    std::vector<uint32_t> sorted = bvh.order;
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 0; i < n; ++i)
        if (sorted.size() != n || sorted[i] != i) return ::testing::AssertionFailure() << "order is no permutation";
    std::vector<int> slotSeen(n, 0), nodeSeen(bvh.nodes.size(), 0);
    std::vector<std::pair<uint32_t, uint32_t>> stack{{0, 1}}; // node, depth
    uint32_t depth = 0;
    while (!stack.empty()) {
        const auto [index, level] = stack.back();
        stack.pop_back();
        if (index >= bvh.nodes.size() || nodeSeen[index]++)
            return ::testing::AssertionFailure() << "node " << index << " out of range or reached twice";
        const gpu::BvhNode& node = bvh.nodes[index];
        if (node.count == 0) {
            if (node.first <= index || node.first + 1 >= bvh.nodes.size())
                return ::testing::AssertionFailure() << "node " << index << " has children " << node.first;
            for (uint32_t c = node.first; c <= node.first + 1; ++c) {
                if (!contains(node, bvh.nodes[c].lower, bvh.nodes[c].upper) && boxes.size() > 0 &&
                    bvh.nodes[c].lower.x != std::numeric_limits<float>::infinity())
                    return ::testing::AssertionFailure() << "node " << index << " does not contain child " << c;
                stack.push_back({c, level + 1});
            }
            continue;
        }
        depth = std::max(depth, level);
        if (node.count > maxLeafSize)
            return ::testing::AssertionFailure() << "leaf " << index << " holds " << node.count;
        if (uint64_t(node.first) + node.count > n) return ::testing::AssertionFailure() << "leaf range past order";
        for (uint32_t s = node.first; s < node.first + node.count; ++s) {
            ++slotSeen[s];
            const Aabb& box = boxes[bvh.order[s]];
            if (!box.empty() && !containsExactly(node, box))
                return ::testing::AssertionFailure() << "leaf " << index << " misses primitive " << bvh.order[s];
        }
    }
    for (size_t s = 0; s < n; ++s)
        if (slotSeen[s] != 1)
            return ::testing::AssertionFailure() << "slot " << s << " in " << slotSeen[s] << " leaves";
    for (size_t i = 0; i < nodeSeen.size(); ++i)
        if (!nodeSeen[i]) return ::testing::AssertionFailure() << "node " << i << " unreachable";
    if (n > 0 && depth != bvh.depth)
        return ::testing::AssertionFailure() << "depth " << bvh.depth << ", longest path " << depth;
    return ::testing::AssertionSuccess();
}

std::vector<Aabb> boxesOf(const MeshData& mesh) { return triangleBoxes(mesh.positions, mesh.triangles); }

TEST(BvhBuild, InvariantsOnRandomSoups)
{
    for (uint32_t n : {1u, 2u, 3u, 4u, 5u, 7u, 16u, 33u, 100u, 1000u, 5000u}) {
        const std::vector<Aabb> boxes = boxesOf(makeRandomSoup(n, n));
        const Bvh bvh = buildBvh(boxes);
        EXPECT_TRUE(wellFormed(bvh, boxes, 4)) << n << " triangles";
        EXPECT_GE(bvh.buildSeconds, 0.0);
    }
}

TEST(BvhBuild, InvariantsOnGridsAndSpheres)
{
    for (const MeshData& mesh :
         {makeGrid(30), makeUvSphere(2000, glm::vec3(1.0f, 2.0f, 3.0f), 0.5f),
          makeIcosphere(3, glm::vec3(0.0f), 100.0f), makeQuad({0, 0, 0}, {1, 0, 0}, {0, 1, 0})}) {
        const std::vector<Aabb> boxes = boxesOf(mesh);
        for (uint32_t leaf : {1u, 2u, 4u, 8u}) {
            EXPECT_TRUE(wellFormed(buildBvh(boxes, BvhOptions{.maxLeafSize = leaf}), boxes, leaf))
                << mesh.triangles.size() << " triangles, leaves of " << leaf;
        }
    }
}

TEST(BvhBuild, DepthWithinGpuStackFor1e5RandomTriangles)
{
    const std::vector<Aabb> boxes = boxesOf(makeRandomSoup(100000, 7));
    const Bvh bvh = buildBvh(boxes);
    EXPECT_TRUE(wellFormed(bvh, boxes, 4));
    EXPECT_LE(bvh.depth, 64u);
    EXPECT_GE(bvh.depth, 15u); // at least log2(1e5 / 4) + 1
}

TEST(BvhBuild, LopsidedInputStaysWithinTheDepthBudget)
{
    // Boxes at x = 2^i: SAH keeps peeling off the largest one, a chain as
    // deep as there are primitives, unless the depth budget steps in.
    std::vector<Aabb> boxes;
    for (int i = 0; i < 300; ++i) {
        const double x = std::ldexp(1.0, i);
        boxes.push_back(Aabb{{x, 0.0, 0.0}, {x * 1.5, 1.0, 1.0}});
    }
    for (uint32_t maxDepth : {10u, 20u, 64u}) {
        const Bvh bvh = buildBvh(boxes, BvhOptions{.maxDepth = maxDepth});
        EXPECT_TRUE(wellFormed(bvh, boxes, 4));
        EXPECT_LE(bvh.depth, maxDepth);
    }
}

TEST(BvhBuild, ThreadCountDoesNotChangeTheTree)
{
    // 2e5 triangles: dozens of parallel subtree tasks.
    const std::vector<Aabb> boxes = boxesOf(makeRandomSoup(200000, 3));
    const Bvh one = buildBvh(boxes, BvhOptions{.threads = 1});
    for (uint32_t threads : {2u, 3u, 0u}) {
        const Bvh many = buildBvh(boxes, BvhOptions{.threads = threads});
        ASSERT_EQ(one.nodes.size(), many.nodes.size()) << threads << " threads";
        EXPECT_EQ(0, std::memcmp(one.nodes.data(), many.nodes.data(), one.nodes.size() * sizeof(gpu::BvhNode)))
            << threads << " threads";
        EXPECT_EQ(one.order, many.order) << threads << " threads";
        EXPECT_EQ(one.depth, many.depth);
    }
}

TEST(BvhBuild, ZeroPrimitivesGiveOneNodeNoRayEnters)
{
    const Bvh bvh = buildBvh({});
    ASSERT_EQ(bvh.nodes.size(), 1u);
    EXPECT_EQ(bvh.nodes[0].count, 0u);
    EXPECT_TRUE(bvh.order.empty());
    const TraversalRay ray = makeTraversalRay({0, 0, 0}, glm::normalize(glm::vec3(1, 1, 1)));
    float entry = 0.0f;
    EXPECT_FALSE(entersBox(bvh.nodes[0].lower, bvh.nodes[0].upper, ray, 1e30f, entry));
    const TriangleSet none{};
    EXPECT_FALSE(closestHit(bvh, none, {0, 0, 0}, {0, 0, 1}, 1e30f));
}

TEST(BvhBuild, EmptyBoxesEndInLeavesNoRayEnters)
{
    std::vector<Aabb> boxes = boxesOf(makeRandomSoup(50, 1));
    for (int i = 0; i < 13; ++i) boxes.insert(boxes.begin() + 4 * i, Aabb{});
    const Bvh bvh = buildBvh(boxes);
    EXPECT_TRUE(wellFormed(bvh, boxes, 4));
    // Every leaf holds only empty or only real boxes; empty-only leaves have the never-entered box.
    uint32_t emptyLeaves = 0;
    for (const gpu::BvhNode& node : bvh.nodes) {
        if (node.count == 0) continue;
        const bool empty = boxes[bvh.order[node.first]].empty();
        for (uint32_t s = node.first; s < node.first + node.count; ++s) EXPECT_EQ(boxes[bvh.order[s]].empty(), empty);
        if (!empty) continue;
        ++emptyLeaves;
        for (const glm::vec3& corner : {glm::vec3(-1, -1, -1), glm::vec3(2, 0.5f, 0.5f)}) {
            float entry = 0.0f;
            EXPECT_FALSE(entersBox(node.lower, node.upper, makeTraversalRay(corner, glm::vec3(1, 0, 0)), 1e30f, entry));
        }
    }
    EXPECT_GE(emptyLeaves, 4u); // 13 boxes, at most 4 a leaf
}

TEST(BvhBuild, CoincidentCentroidsSplitInTheMiddle)
{
    const std::vector<Aabb> boxes(100, Aabb{{0, 0, 0}, {1, 1, 1}});
    const Bvh bvh = buildBvh(boxes);
    EXPECT_TRUE(wellFormed(bvh, boxes, 4));
    EXPECT_EQ(bvh.depth, 6u); // 100 -> 50 -> 25 -> 13 -> 7 -> 4
}

TEST(BvhBuild, SahSeparatesDistantClusters)
{
    MeshData a = makeRandomSoup(60, 1), b = makeRandomSoup(40, 2);
    for (glm::vec3& p : b.positions) p += glm::vec3(10.0f, 0.0f, 0.0f);
    std::vector<Aabb> boxes = boxesOf(a);
    const std::vector<Aabb> more = boxesOf(b);
    boxes.insert(boxes.end(), more.begin(), more.end());
    const Bvh bvh = buildBvh(boxes);
    ASSERT_EQ(bvh.nodes[0].count, 0u);
    const gpu::BvhNode& left = bvh.nodes[bvh.nodes[0].first];
    const gpu::BvhNode& right = bvh.nodes[bvh.nodes[0].first + 1];
    EXPECT_LE(left.upper.x, 1.0f);
    EXPECT_GE(right.lower.x, 10.0f);
}

TEST(BvhBuild, NodeBoxesRoundOutwards)
{
    std::mt19937_64 random(5);
    std::uniform_real_distribution<double> coordinate(-1e3, 1e3);
    for (int i = 0; i < 1000; ++i) {
        Aabb box;
        box.extend(glm::dvec3(coordinate(random), coordinate(random), coordinate(random)));
        box.extend(glm::dvec3(coordinate(random), coordinate(random), coordinate(random)));
        gpu::BvhNode node{};
        roundOutwards(box, node.lower, node.upper);
        ASSERT_TRUE(containsExactly(node, box));
        for (int k = 0; k < 3; ++k) { // and as tight as float allows
            EXPECT_GT(double(std::nextafter(node.lower[k], INFINITY)), box.lower[k]);
            EXPECT_LT(double(std::nextafter(node.upper[k], -INFINITY)), box.upper[k]);
        }
    }
    gpu::BvhNode exact{};
    roundOutwards(Aabb{{0.5, -2.0, 3.0}, {1.0, 4.0, 8.0}}, exact.lower, exact.upper);
    EXPECT_EQ(exact.lower, glm::vec3(0.5f, -2.0f, 3.0f));
    EXPECT_EQ(exact.upper, glm::vec3(1.0f, 4.0f, 8.0f));
}

TEST(BvhBuild, TriangleBoxesAndSurfaceArea)
{
    const std::vector<glm::vec3> p{{0.1f, 0.2f, 0.3f}, {-1.0f, 5.0f, 0.3f}, {2.0f, 0.0f, -7.0f}};
    const std::vector<glm::uvec3> t{{0, 1, 2}};
    const Aabb box = triangleBoxes(p, t)[0];
    EXPECT_EQ(box.lower, glm::dvec3(-1.0, double(0.0f), -7.0));
    EXPECT_EQ(box.upper, glm::dvec3(2.0, 5.0, double(0.3f)));
    EXPECT_DOUBLE_EQ((Aabb{{0, 0, 0}, {1, 2, 3}}).surfaceArea(), 22.0);
    EXPECT_EQ(Aabb{}.surfaceArea(), 0.0);
}

// ---------------------------------------------------------------- traversal

glm::vec3 randomDirection(std::mt19937& random)
{
    std::normal_distribution<float> normal;
    for (;;) {
        const glm::vec3 d(normal(random), normal(random), normal(random));
        if (glm::length(d) > 1e-3f) return glm::normalize(d);
    }
}

TEST(BvhTraversal, ClosestHitEqualsBruteForce)
{
    const MeshData soup = makeRandomSoup(2000, 11);
    const Bvh bvh = buildBvh(boxesOf(soup));
    const TriangleSet mesh{soup.positions, soup.triangles};
    std::mt19937 random(42);
    std::uniform_real_distribution<float> inCube(-0.5f, 1.5f);
    int hits = 0;
    for (int i = 0; i < 10000; ++i) {
        const glm::vec3 origin(inCube(random), inCube(random), inCube(random));
        // Half the rays aim at a triangle's centroid, so that most rays hit something.
        const glm::uvec3 aim = soup.triangles[random() % soup.triangles.size()];
        const glm::vec3 towards = (soup.positions[aim.x] + soup.positions[aim.y] + soup.positions[aim.z]) / 3.0f;
        const glm::vec3 dir = i % 2 ? glm::normalize(towards - origin) : randomDirection(random);
        const float tMax = i % 4 == 0 ? 0.3f : 1e30f;
        const auto expected = bruteForceClosestHit(mesh, origin, dir, tMax);
        const auto found = closestHit(bvh, mesh, origin, dir, tMax);
        ASSERT_EQ(found.has_value(), expected.has_value()) << "ray " << i;
        EXPECT_EQ(anyHit(bvh, mesh, origin, dir, tMax), expected.has_value()) << "ray " << i;
        if (!expected) continue;
        ++hits;
        ASSERT_EQ(std::bit_cast<uint32_t>(found->t), std::bit_cast<uint32_t>(expected->t)) << "ray " << i;
        if (found->primitive != expected->primitive) {
            // Only a tie at exactly the same t may pick another triangle.
            const glm::uvec3 tri = soup.triangles[found->primitive];
            const auto again = intersectTriangle(soup.positions[tri.x], soup.positions[tri.y], soup.positions[tri.z],
                                                 makeTraversalRay(origin, dir), tMax);
            ASSERT_TRUE(again && again->t == expected->t) << "ray " << i;
        } else {
            EXPECT_EQ(found->barycentrics, expected->barycentrics);
        }
    }
    EXPECT_GT(hits, 4000); // the comparison saw many hits
}

TEST(BvhTraversal, WatertightAtSharedEdgesAndVertices)
{
    // n = 64: every vertex coordinate and edge midpoint is exact in float.
    const uint32_t n = 64;
    const MeshData grid = makeGrid(n);
    const Bvh bvh = buildBvh(boxesOf(grid));
    const TriangleSet mesh{grid.positions, grid.triangles};
    std::mt19937 random(9);
    std::uniform_real_distribution<float> spread(-3.0f, 3.0f);
    std::uniform_int_distribution<uint32_t> interior(1, n - 1);
    const float step = 2.0f / n;
    int rays = 0, hits = 0, anyHits = 0;
    for (int i = 0; i < 6000; ++i) {
        // A vertex, the midpoint of a horizontal, vertical or diagonal edge.
        const glm::vec2 vertex(-1.0f + step * interior(random), -1.0f + step * interior(random));
        const glm::vec2 offsets[4] = {{0, 0}, {0.5f, 0}, {0, 0.5f}, {0.5f, 0.5f}};
        const glm::vec3 target(vertex + step * offsets[i % 4], 0.0f);
        const glm::vec3 origin(spread(random), spread(random), i % 2 ? 2.0f : -2.0f);
        const glm::vec3 dir = glm::normalize(target - origin);
        ++rays;
        hits += closestHit(bvh, mesh, origin, dir, 1e30f).has_value();
        anyHits += anyHit(bvh, mesh, origin, dir, 1e30f);
    }
    EXPECT_EQ(hits, rays);
    EXPECT_EQ(anyHits, rays);
}

TEST(BvhTraversal, StatsShowTheTreeSavesWork)
{
    const MeshData soup = makeRandomSoup(10000, 4);
    const Bvh bvh = buildBvh(boxesOf(soup));
    const TriangleSet mesh{soup.positions, soup.triangles};
    std::mt19937 random(1);
    uint64_t tested = 0, visited = 0;
    const int rays = 1000;
    for (int i = 0; i < rays; ++i) {
        const TraversalStats s = traversalStats(bvh, mesh, {0.5f, 0.5f, 0.5f}, randomDirection(random), 1e30f);
        EXPECT_GE(s.nodesVisited, 1u);
        tested += s.trianglesTested;
        visited += s.nodesVisited;
    }
    EXPECT_LT(double(tested) / rays, 0.02 * 10000); // a few dozen of 10,000 triangles
    EXPECT_LT(double(visited) / rays, 0.02 * bvh.nodes.size());
    const TraversalStats miss = traversalStats(bvh, mesh, {5.0f, 5.0f, 5.0f}, {1.0f, 0.0f, 0.0f}, 1e30f);
    EXPECT_EQ(miss.nodesVisited, 0u);
    EXPECT_EQ(miss.trianglesTested, 0u);
}

TEST(BvhTraversal, TriangleTestLimitsAndDegenerates)
{
    const glm::vec3 a(0, 0, 1), b(1, 0, 1), c(0, 1, 1);
    const TraversalRay up = makeTraversalRay({0.25f, 0.25f, 0.0f}, {0, 0, 1});
    const auto hit = intersectTriangle(a, b, c, up, 1e30f);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->t, 1.0f);
    EXPECT_FLOAT_EQ(hit->barycentrics.x, 0.5f);
    EXPECT_FLOAT_EQ(hit->barycentrics.y, 0.25f);
    EXPECT_TRUE(intersectTriangle(a, c, b, up, 1e30f)); // both faces
    EXPECT_FALSE(intersectTriangle(a, b, c, up, 1.0f)); // t must lie below tMax
    EXPECT_FALSE(intersectTriangle(a, b, c, makeTraversalRay({0.25f, 0.25f, 2.0f}, {0, 0, 1}), 1e30f)); // behind
    EXPECT_FALSE(intersectTriangle(a, b, glm::vec3(2, 0, 1), up, 1e30f)); // collinear: never hit
}

} // namespace
} // namespace vkrt
