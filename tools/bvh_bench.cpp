// vkrt-bvh-bench: BVH build time, peak memory and traversal work for
// procedural meshes (an optional target: `cmake --build build --target vkrt-bvh-bench`).
//   vkrt-bvh-bench soup|sphere TRIANGLES [THREADS [TRAVERSAL_COST]]
// Memory: the growth of the peak resident set during the build (Linux:
// /proc/self/clear_refs resets the peak first), i.e. the nodes, the order,
// the centroids and the build's transient arrays, not the mesh or its boxes.
#include "accel/Bvh.h"
#include "accel/BvhTraversal.h"
#include "mesh/Procedural.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>

namespace {

/// A field of /proc/self/status in KiB (VmRSS, VmHWM), or -1.
long statusKiB(const std::string& field)
{
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
        if (line.rfind(field + ":", 0) == 0) return std::atol(line.c_str() + field.size() + 1);
    return -1;
}

void resetPeak() { std::ofstream("/proc/self/clear_refs") << "5"; }

} // namespace

int main(int argc, char** argv)
{
    if (argc < 3) {
        std::fprintf(stderr, "usage: vkrt-bvh-bench soup|sphere TRIANGLES [THREADS]\n");
        return 2;
    }
    const std::string kind = argv[1];
    const uint32_t triangles = uint32_t(std::strtoul(argv[2], nullptr, 10));
    const uint32_t threads = argc > 3 ? uint32_t(std::strtoul(argv[3], nullptr, 10)) : 0;
    vkrt::BvhOptions options{.threads = threads};
    if (argc > 4) options.traversalCost = std::strtod(argv[4], nullptr);
    const vkrt::MeshData mesh =
        kind == "sphere" ? vkrt::makeUvSphere(triangles, glm::vec3(0.0f), 1.0f) : vkrt::makeRandomSoup(triangles, 1);
    const auto start = std::chrono::steady_clock::now();
    const std::vector<vkrt::Aabb> boxes = vkrt::triangleBoxes(mesh.positions, mesh.triangles);
    const double boxSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    resetPeak();
    const long before = statusKiB("VmRSS");
    const vkrt::Bvh bvh = vkrt::buildBvh(boxes, options);
    const long peak = statusKiB("VmHWM");

    // Traversal work: rays from a sphere of radius 3 towards points inside the mesh's cube.
    const vkrt::TriangleSet set{mesh.positions, mesh.triangles};
    std::mt19937 random(1);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    const glm::vec3 centre = kind == "sphere" ? glm::vec3(0.0f) : glm::vec3(0.5f);
    double nodes = 0, tests = 0;
    const int rays = 2000;
    for (int i = 0; i < rays; ++i) {
        const glm::vec3 from = centre + 3.0f * glm::normalize(glm::vec3(unit(random), unit(random), unit(random)));
        const glm::vec3 to = centre + 0.5f * glm::vec3(unit(random), unit(random), unit(random));
        const vkrt::TraversalStats s = vkrt::traversalStats(bvh, set, from, glm::normalize(to - from), 1e30f);
        nodes += s.nodesVisited;
        tests += s.trianglesTested;
    }
    std::printf("%s triangles=%zu threads=%u boxes_s=%.3f build_s=%.3f nodes=%zu depth=%u build_peak_MiB=%.1f "
                "(nodes+order %.1f MiB) nodes/ray=%.1f tests/ray=%.1f\n",
                kind.c_str(), mesh.triangles.size(), threads, boxSeconds, bvh.buildSeconds, bvh.nodes.size(), bvh.depth,
                (peak - before) / 1024.0,
                (bvh.nodes.size() * sizeof(vkrt::gpu::BvhNode) + bvh.order.size() * 4) / 1048576.0, nodes / rays,
                tests / rays);
    return 0;
}
