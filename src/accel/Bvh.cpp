#include "accel/Bvh.h"

#include "util/Error.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

namespace vkrt {

void Aabb::extend(const glm::dvec3& p)
{
    lower = glm::min(lower, p);
    upper = glm::max(upper, p);
}

void Aabb::extend(const Aabb& b)
{
    lower = glm::min(lower, b.lower);
    upper = glm::max(upper, b.upper);
}

double Aabb::surfaceArea() const
{
    if (empty()) return 0.0;
    const glm::dvec3 d = upper - lower;
    return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

std::vector<Aabb> triangleBoxes(std::span<const glm::vec3> positions, std::span<const glm::uvec3> triangles)
{
    std::vector<Aabb> boxes(triangles.size());
    for (size_t i = 0; i < triangles.size(); ++i) {
        const glm::uvec3& t = triangles[i];
        VKRT_CHECK(t.x < positions.size() && t.y < positions.size() && t.z < positions.size());
        // float -> double is exact, so the box is exactly the triangle's.
        for (int k = 0; k < 3; ++k) boxes[i].extend(glm::dvec3(positions[t[k]]));
    }
    return boxes;
}

namespace {

/// The nearest float not above (below) x.
float floatBelow(double x)
{
    const float f = float(x);
    return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}

float floatAbove(double x)
{
    const float f = float(x);
    return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

} // namespace

void roundOutwards(const Aabb& box, glm::vec3& lower, glm::vec3& upper)
{
    if (box.empty()) {
        // The point at +infinity: every slab gives +-inf, so the min/max slab
        // test of shaders/lib/bvh.glsl never enters it. An inverted box
        // (lower = +inf, upper = -inf) would be entered by every ray.
        lower = upper = glm::vec3(std::numeric_limits<float>::infinity());
        return;
    }
    for (int k = 0; k < 3; ++k) {
        lower[k] = floatBelow(box.lower[k]);
        upper[k] = floatAbove(box.upper[k]);
    }
}

namespace {

/// A box with nothing inverted and nothing NaN in any axis.
bool holdsSomething(const Aabb& b)
{
    return b.lower.x <= b.upper.x && b.lower.y <= b.upper.y && b.lower.z <= b.upper.z;
}

/// Depth (in nodes) of the tree that median splits make over `count`
/// primitives: what a subtree of that size needs at the least.
uint32_t medianDepth(uint64_t count, uint32_t maxLeafSize)
{
    uint32_t depth = 1;
    for (; count > maxLeafSize; count = (count + 1) / 2) ++depth;
    return depth;
}

/// A float box; rounding a double box outwards is monotonic, so the union of
/// rounded boxes is exactly the rounded union (the node box Bvh.h promises).
struct FloatBox {
    glm::vec3 lower{std::numeric_limits<float>::infinity()};
    glm::vec3 upper{-std::numeric_limits<float>::infinity()};
    void extend(const glm::vec3& p)
    {
        lower = glm::min(lower, p);
        upper = glm::max(upper, p);
    }
    void extend(const FloatBox& b)
    {
        lower = glm::min(lower, b.lower);
        upper = glm::max(upper, b.upper);
    }
    double surfaceArea() const
    {
        if (!(lower.x <= upper.x)) return 0.0;
        const glm::dvec3 d = glm::dvec3(upper) - glm::dvec3(lower);
        return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
    }
};

/// One primitive as the build moves it around: its box rounded outwards and
/// its index. The build permutes these (sequential memory, unlike an index
/// array into the boxes), and `order` is read off them at the end.
struct PrimRef {
    FloatBox box;
    uint32_t index;
    /// Halves first: no overflow to infinity near FLT_MAX.
    glm::vec3 centroid() const { return 0.5f * box.lower + 0.5f * box.upper; }
};

/// What every part of one build shares. Refs [0, firstEmpty) have boxes,
/// the rest (empty boxes) only need leaves.
struct BuildInput {
    std::vector<PrimRef> refs;
    uint32_t firstEmpty = 0;
    BvhOptions options;
};

/// A range of `order` waiting to become node `node` at depth `depth` (root = 1).
struct PendingNode {
    uint32_t node;
    uint32_t begin;
    uint32_t end;
    uint32_t depth;
};

/// Stores a node box; an empty one as roundOutwards stores it (never entered).
void setBox(gpu::BvhNode& node, const FloatBox& box)
{
    if (box.lower.x <= box.upper.x) {
        node.lower = box.lower;
        node.upper = box.upper;
    } else {
        roundOutwards(Aabb{}, node.lower, node.upper);
    }
}

/// The box of a range's primitives and the box of their centroids.
struct RangeBounds {
    FloatBox box;
    FloatBox centroids;
};

RangeBounds boundsOf(const BuildInput& in, uint32_t begin, uint32_t end)
{
    RangeBounds r;
    if (begin >= in.firstEmpty) return r;
    for (uint32_t i = begin; i < end; ++i) {
        r.box.extend(in.refs[i].box);
        r.centroids.extend(in.refs[i].centroid());
    }
    return r;
}

/// Maps a centroid coordinate to its bin; the same expression serves the
/// binning and the partition, so both agree on every primitive.
struct BinMapping {
    double lower = 0.0;
    double scale = 0.0;
    uint32_t bins = 0;
    uint32_t operator()(float c) const { return std::min(bins - 1, uint32_t((double(c) - lower) * scale)); }
};

struct Bin {
    FloatBox box;
    uint32_t count = 0;
};

/// Bins per axis and the sweep's running sums, reused from node to node.
struct Scratch {
    std::array<std::vector<Bin>, 3> bins;
    std::vector<double> rightArea;
    std::vector<uint32_t> rightCount;
};

/// The best SAH split plane: primitives in bins < plane go left. `cost` is
/// sum(area * count) over both sides, comparable between the planes of one node.
struct SahSplit {
    int axis = -1;
    uint32_t plane = 0;
    double cost = std::numeric_limits<double>::infinity();
    uint32_t leftCount = 0;
};

/// Whether `a` beats `b`: cheaper, or as cheap and more balanced (then the first found wins).
bool better(const SahSplit& a, const SahSplit& b, uint32_t count)
{
    const auto imbalance = [count](uint32_t left) { return std::max(left, count - left); };
    return a.cost < b.cost || (a.cost == b.cost && imbalance(a.leftCount) < imbalance(b.leftCount));
}

/// Tries a split after each bin of one axis.
void sweepAxis(const std::vector<Bin>& bins, int axis, uint32_t count, Scratch& s, SahSplit& best)
{
    const uint32_t n = uint32_t(bins.size());
    s.rightArea.resize(n);
    s.rightCount.resize(n);
    FloatBox box;
    uint32_t c = 0;
    for (uint32_t b = n; b-- > 1;) {
        box.extend(bins[b].box);
        c += bins[b].count;
        s.rightArea[b] = box.surfaceArea();
        s.rightCount[b] = c;
    }
    box = FloatBox{};
    c = 0;
    for (uint32_t plane = 1; plane < n; ++plane) {
        box.extend(bins[plane - 1].box);
        c += bins[plane - 1].count;
        if (c == 0 || c == count) continue;
        const SahSplit candidate{axis, plane, box.surfaceArea() * c + s.rightArea[plane] * s.rightCount[plane], c};
        if (better(candidate, best, count)) best = candidate;
    }
}

/// Bins the range's centroids (one pass, every axis they spread along) and sweeps the bins.
SahSplit bestSahSplit(const BuildInput& in, uint32_t begin, uint32_t end, const RangeBounds& r,
                      std::array<BinMapping, 3>& mappings, Scratch& s)
{
    // A node of few primitives needs no more bins than it has primitives:
    // the per-node sweep, not the binning, dominates deep in the tree.
    const uint32_t bins = std::clamp(end - begin, 2u, in.options.bins);
    std::array<bool, 3> spread{};
    for (int axis = 0; axis < 3; ++axis) {
        const double extent = double(r.centroids.upper[axis]) - double(r.centroids.lower[axis]);
        spread[axis] = extent > 0.0 && std::isfinite(bins / extent);
        mappings[axis] = BinMapping{r.centroids.lower[axis], spread[axis] ? bins / extent : 0.0, bins};
        s.bins[axis].assign(bins, Bin{});
    }
    for (uint32_t i = begin; i < end; ++i) {
        const PrimRef& ref = in.refs[i];
        const glm::vec3 c = ref.centroid();
        for (int axis = 0; axis < 3; ++axis) {
            if (!spread[axis]) continue;
            Bin& bin = s.bins[axis][mappings[axis](c[axis])];
            bin.box.extend(ref.box);
            ++bin.count;
        }
    }
    SahSplit best;
    for (int axis = 0; axis < 3; ++axis)
        if (spread[axis]) sweepAxis(s.bins[axis], axis, end - begin, s, best);
    return best;
}

/// Splits the range at its middle slot, after ordering it along the axis of
/// widest centroid spread (when the centroids spread at all).
uint32_t medianSplit(BuildInput& in, uint32_t begin, uint32_t end, const RangeBounds& r)
{
    const uint32_t middle = begin + (end - begin) / 2;
    const glm::vec3 extent = r.centroids.upper - r.centroids.lower;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    if (begin < in.firstEmpty && extent[axis] > 0.0f) {
        const auto less = [axis](const PrimRef& a, const PrimRef& b) {
            const float ca = a.centroid()[axis], cb = b.centroid()[axis];
            return ca < cb || (ca == cb && a.index < b.index);
        };
        std::nth_element(in.refs.begin() + begin, in.refs.begin() + middle, in.refs.begin() + end, less);
    }
    return middle;
}

/// Decides one node: 0 for a leaf, else the slot where its right child's range begins.
uint32_t splitPoint(BuildInput& in, const PendingNode& p, const RangeBounds& r, Scratch& scratch)
{
    const BvhOptions& o = in.options;
    const uint32_t count = p.end - p.begin;
    if (count == 1) return 0;
    if (p.begin >= in.firstEmpty) return count <= o.maxLeafSize ? 0 : medianSplit(in, p.begin, p.end, r);
    std::array<BinMapping, 3> mappings;
    const SahSplit sah = bestSahSplit(in, p.begin, p.end, r, mappings, scratch);
    // SAH: a split costs one traversal step plus each side's primitives
    // weighted by the chance (area ratio) of entering it; a leaf costs its count.
    const double area = r.box.surfaceArea();
    const double splitCost = o.traversalCost + (area > 0.0 ? sah.cost / area : 0.0);
    // A lopsided split is taken only while its larger side still fits in the
    // depth budget (the GPU's traversal stack) when built with median splits.
    const bool fits =
        sah.axis >= 0 &&
        p.depth + medianDepth(std::max(sah.leftCount, count - sah.leftCount), o.maxLeafSize) <= o.maxDepth;
    if (count <= o.maxLeafSize && !(fits && splitCost < double(count))) return 0;
    if (fits) {
        const BinMapping& map = mappings[sah.axis];
        const auto left = [&map, &sah](const PrimRef& ref) { return map(ref.centroid()[sah.axis]) < sah.plane; };
        const auto mid = std::partition(in.refs.begin() + p.begin, in.refs.begin() + p.end, left);
        return uint32_t(mid - in.refs.begin());
    }
    // Coincident centroids, or the budget is tight: halve the range.
    return medianSplit(in, p.begin, p.end, r);
}

/// Nodes of one subtree (or of the top of the tree), in the order they are made.
struct Subtree {
    std::vector<gpu::BvhNode> nodes;
    uint32_t depth = 0;
};

/// Builds the subtree of `root` (node 0 of `out`). With `deferBelow` > 0,
/// ranges of at most that many primitives are not built but appended to
/// `deferred` (their node stays a placeholder) for building in parallel.
void buildSubtree(BuildInput& in, PendingNode root, Subtree& out, uint32_t deferBelow,
                  std::vector<PendingNode>* deferred)
{
    std::vector<PendingNode> stack{root};
    Scratch scratch;
    while (!stack.empty()) {
        const PendingNode p = stack.back();
        stack.pop_back();
        if (deferred && p.end - p.begin <= deferBelow && p.node != root.node) {
            deferred->push_back(p);
            continue;
        }
        const RangeBounds r = boundsOf(in, p.begin, p.end);
        const uint32_t mid = splitPoint(in, p, r, scratch);
        const uint32_t left = uint32_t(out.nodes.size());
        gpu::BvhNode& node = out.nodes[p.node];
        setBox(node, r.box);
        node.first = mid == 0 ? p.begin : left;
        node.count = mid == 0 ? p.end - p.begin : 0;
        if (mid == 0) {
            out.depth = std::max(out.depth, p.depth);
            continue;
        }
        out.nodes.resize(out.nodes.size() + 2);
        // Right pushed first so the left subtree is built (and numbered) first.
        stack.push_back({left + 1, mid, p.end, p.depth + 1});
        stack.push_back({left, p.begin, mid, p.depth + 1});
    }
}

/// Runs `work(k)` for k in [0, count) on `threads` threads, each taking the next k.
template <class Work>
void runInParallel(uint32_t count, uint32_t threads, const Work& work)
{
    std::atomic<uint32_t> next{0};
    const auto worker = [&] {
        for (uint32_t k; (k = next.fetch_add(1)) < count;) work(k);
    };
    std::vector<std::jthread> pool;
    for (uint32_t t = 1; t < std::min(threads, count); ++t) pool.emplace_back(worker);
    worker();
}

/// Appends the subtree built for placeholder `slot` to `top`: its root
/// replaces the placeholder, the rest follows with child indices moved.
void attachSubtree(Subtree& top, uint32_t slot, const Subtree& sub)
{
    const uint32_t offset = uint32_t(top.nodes.size());
    const auto moved = [offset](gpu::BvhNode n) {
        if (n.count == 0) n.first = n.first - 1 + offset; // local node j >= 1 lands at offset + j - 1
        return n;
    };
    top.nodes[slot] = moved(sub.nodes[0]);
    for (size_t j = 1; j < sub.nodes.size(); ++j) top.nodes.push_back(moved(sub.nodes[j]));
    top.depth = std::max(top.depth, sub.depth);
}

/// Ranges of at most this many primitives are built as independent tasks.
/// It depends on the primitive count only, so the tree does not depend on
/// the thread count.
uint32_t taskSize(size_t primitives) { return uint32_t(std::max<size_t>(4096, primitives / 64)); }

void checkOptions(const BvhOptions& o, size_t primitives)
{
    VKRT_CHECK(o.maxLeafSize >= 1);
    VKRT_CHECK(o.bins >= 2);
    VKRT_CHECK(primitives < std::numeric_limits<uint32_t>::max() / 2);
    VKRT_CHECK(medianDepth(primitives, o.maxLeafSize) + 1 <= o.maxDepth);
}

/// Refs of the primitives with holdsSomething() boxes first, the others
/// (never hit) after them, each group in index order.
BuildInput prepare(std::span<const Aabb> boxes, const BvhOptions& options)
{
    BuildInput in;
    in.options = options;
    in.refs.resize(boxes.size());
    uint32_t front = 0;
    for (uint32_t i = 0; i < boxes.size(); ++i) {
        if (!holdsSomething(boxes[i])) continue;
        VKRT_CHECK(std::isfinite(boxes[i].lower.x + boxes[i].lower.y + boxes[i].lower.z + boxes[i].upper.x +
                                 boxes[i].upper.y + boxes[i].upper.z));
        PrimRef& ref = in.refs[front++];
        roundOutwards(boxes[i], ref.box.lower, ref.box.upper);
        ref.index = i;
    }
    in.firstEmpty = front;
    for (uint32_t i = 0, back = front; i < boxes.size(); ++i)
        if (!holdsSomething(boxes[i])) in.refs[back++] = PrimRef{FloatBox{}, i};
    return in;
}

} // namespace

Bvh buildBvh(std::span<const Aabb> boxes, const BvhOptions& options)
{
    const auto start = std::chrono::steady_clock::now();
    checkOptions(options, boxes.size());
    BuildInput in = prepare(boxes, options);
    const uint32_t n = uint32_t(boxes.size());
    const uint32_t emptyCount = n - in.firstEmpty;

    // ---- the top of the tree, serially, down to ranges of taskSize(n)
    Subtree top;
    top.nodes.resize(1);
    std::vector<PendingNode> roots;
    if (n == 0) {
        roundOutwards(Aabb{}, top.nodes[0].lower, top.nodes[0].upper);
        top.depth = 1;
    } else if (emptyCount > 0 && emptyCount < n) {
        // Empty boxes get a subtree of their own, beside the real ones.
        setBox(top.nodes[0], boundsOf(in, 0, in.firstEmpty).box);
        top.nodes[0].first = 1;
        top.nodes.resize(3);
        roots = {{1, 0, n - emptyCount, 2}, {2, n - emptyCount, n, 2}};
    } else {
        roots = {{0, 0, n, 1}};
    }
    std::vector<PendingNode> tasks;
    for (const PendingNode& root : roots) buildSubtree(in, root, top, taskSize(n), &tasks);

    // ---- the rest in parallel tasks (largest first), attached in discovery order
    std::vector<uint32_t> bySize(tasks.size());
    for (uint32_t k = 0; k < bySize.size(); ++k) bySize[k] = k;
    std::stable_sort(bySize.begin(), bySize.end(), [&tasks](uint32_t a, uint32_t b) {
        return tasks[a].end - tasks[a].begin > tasks[b].end - tasks[b].begin;
    });
    std::vector<Subtree> subtrees(tasks.size());
    // Small trees (the top level over a scene's objects) are not worth a thread.
    const uint32_t threads = n < 16384         ? 1
                             : options.threads ? options.threads
                                               : std::max(1u, std::thread::hardware_concurrency());
    runInParallel(uint32_t(tasks.size()), threads, [&](uint32_t k) {
        const PendingNode& t = tasks[bySize[k]];
        Subtree& sub = subtrees[bySize[k]];
        sub.nodes.resize(1);
        sub.nodes.reserve(2 * (t.end - t.begin) / options.maxLeafSize + 1);
        buildSubtree(in, PendingNode{0, t.begin, t.end, t.depth}, sub, 0, nullptr);
    });
    size_t total = top.nodes.size();
    for (const Subtree& s : subtrees) total += s.nodes.size() - 1;
    top.nodes.reserve(total);
    for (size_t k = 0; k < tasks.size(); ++k) attachSubtree(top, tasks[k].node, subtrees[k]);

    Bvh bvh;
    bvh.nodes = std::move(top.nodes);
    bvh.order.resize(n);
    for (uint32_t i = 0; i < n; ++i) bvh.order[i] = in.refs[i].index;
    bvh.depth = top.depth;
    bvh.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

} // namespace vkrt
