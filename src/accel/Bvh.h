#pragma once
// Bounding volume hierarchy over primitives given by their boxes: binned SAH
// (surface area heuristic) build on the host, using every core, producing
// the flat gpu::BvhNode array that shaders/lib/bvh.glsl traverses.
// Node 0 is the root. An inner node's children are nodes `first` and
// `first + 1`; a leaf (count > 0) holds primitives order[first ...
// first + count - 1]. Node boxes are rounded outwards to float32, so they
// contain their primitives' double-precision boxes.
#include "shared/SceneTypes.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace vkrt {

struct Aabb {
    glm::dvec3 lower{std::numeric_limits<double>::infinity()};
    glm::dvec3 upper{-std::numeric_limits<double>::infinity()};
    void extend(const glm::dvec3& p);
    void extend(const Aabb& b);
    bool empty() const { return !(lower.x <= upper.x); }
    glm::dvec3 centre() const { return 0.5 * (lower + upper); }
    double surfaceArea() const;
};

struct BvhOptions {
    uint32_t maxLeafSize = 4;   ///< never more primitives in a leaf
    uint32_t bins = 16;         ///< SAH bins per axis
    double traversalCost = 1.0; ///< SAH cost of one node visit, per primitive test
    uint32_t threads = 0;       ///< 0: std::thread::hardware_concurrency(); the tree is the same for any count
    /// Never deeper (in nodes, root to leaf) than this: the GPU's traversal
    /// stack (BVH_STACK_SIZE). SAH splits too lopsided to stay within it
    /// give way to median splits.
    uint32_t maxDepth = 64;
};

struct Bvh {
    std::vector<gpu::BvhNode> nodes;
    std::vector<uint32_t> order; ///< leaf order -> primitive index (a permutation)
    uint32_t depth = 0;          ///< longest root-to-leaf path, in nodes
    double buildSeconds = 0.0;
};

/// Builds over `boxes` (one per primitive; empty boxes are allowed and end
/// up in leaves of a subtree of their own, never entered). Every leaf holds
/// 1 ... maxLeafSize primitives; primitives whose centroids coincide are
/// split at the middle of their range. Zero primitives give a single node
/// (count 0) whose box no ray enters.
Bvh buildBvh(std::span<const Aabb> boxes, const BvhOptions& options = {});

/// The boxes of float32 triangles (vertex positions, index triples).
std::vector<Aabb> triangleBoxes(std::span<const glm::vec3> positions, std::span<const glm::uvec3> triangles);

/// Rounds a double box outwards to float32 (used for node boxes): the float
/// box contains the double one. An empty box becomes the point at +infinity,
/// which the slab test never enters.
void roundOutwards(const Aabb& box, glm::vec3& lower, glm::vec3& upper);

} // namespace vkrt
