// The two traversal backends (`--accel own|driver`, render/DriverAccel.h,
// shaders/lib/ray_query.glsl) against each other, hit for hit: the same
// camera rays (same seed, one sample per pixel) through every scene below,
// each ray's closest hit recorded by the kernel's hit-probe hook
// (VKRT_TEST_HIT_PROBE in lib/aov.glsl: kind, record, primitive, t and the
// hit point's error bound). Both backends must agree on whether a ray hits,
// on the record and primitive it hits, and on t within the two error bounds.
// A driver whose traversal misses a triangle, reports a farther one or
// loses an instance fails here with the scene, the pixel and both hits.
// The third: vkrt's own traversal as a packet walk (VKRT_PACKET_TRAVERSAL,
// lib/shapes/mesh.glsl), a measurement hook since it does not pay on
// lavapipe, must give the own lane walk's hits exactly: the same primitive
// at the same t, ties at shared edges apart.
// Also: a camera move rebuilds the driver's camera-relative structures (the
// viewer's path), and --accel driver on a device without ray queries is
// refused with what it lacks.
#include "render/RenderSession.h"
#include "scene/SceneParser.h"
#include "support/TestSupport.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

namespace vkrt::test {
namespace {

class AccelBackends : public GpuTest {
protected:
    void SetUp() override
    {
        GpuTest::SetUp();
        if (!gpu().deviceInfo().rayQuery())
            GTEST_SKIP() << gpu().deviceInfo().name << " lacks " << gpu().deviceInfo().rayQueryMissing;
    }
};

constexpr double kFloatStep = 0x1p-24;
/// Float steps of t / |cos| the two backends' distances may differ by.
constexpr double kDistanceSteps = 16.0;

/// One camera ray's closest hit as the probe hook records it.
struct ProbedHit {
    bool hit = false;
    int kind = -1;
    uint32_t record = 0, primitive = 0;
    double t = 0.0, error = 0.0, cosine = 1.0;
};

enum class Walk { Own, Driver, OwnPackets };

std::vector<ProbedHit> probeHits(const Scene& scene, Walk walk)
{
    RenderOptions options;
    options.seed = 11;
    options.aov = true;
    options.driverAccel = walk == Walk::Driver;
    options.extraDefines = {{"VKRT_TEST_HIT_PROBE", "1"}};
    if (walk == Walk::OwnPackets) options.extraDefines.emplace_back("VKRT_PACKET_TRAVERSAL", "1");
    options.cacheDirectory = testCacheDir();
    Renderer renderer(gpu(), scene, options);
    renderer.renderFrames(1);
    const AovImages aovs = renderer.aovs();
    std::vector<ProbedHit> hits(aovs.depth.size());
    for (size_t i = 0; i < hits.size(); ++i) {
        ProbedHit& h = hits[i];
        h.hit = std::isfinite(aovs.depth[i]);
        if (!h.hit) continue;
        h.kind = int(aovs.albedo.rgb[3 * i]);
        h.record = uint32_t(aovs.albedo.rgb[3 * i + 1]);
        h.primitive = uint32_t(aovs.albedo.rgb[3 * i + 2]);
        h.t = aovs.normal.rgb[3 * i];
        h.error = aovs.normal.rgb[3 * i + 1];
        h.cosine = aovs.normal.rgb[3 * i + 2];
    }
    return hits;
}

std::string describe(const ProbedHit& h)
{
    if (!h.hit) return "no hit";
    std::ostringstream text;
    text << "kind " << h.kind << " record " << h.record << " primitive " << h.primitive << " t " << h.t << " (+-"
         << h.error << ")";
    return text.str();
}

struct Disagreements {
    uint64_t rays = 0, hits = 0;
    uint64_t hitOrMiss = 0;      ///< one backend hit, the other did not
    uint64_t otherPrimitive = 0; ///< different record or primitive at a distance outside both bounds
    uint64_t tie = 0;            ///< different primitive at the same distance (a shared edge or vertex)
    uint64_t distance = 0;       ///< same primitive, t outside both bounds
    std::string examples;
    double worstSteps = 0.0; ///< largest |t_own - t_driver| |cos| / (2^-24 t)
};

Disagreements compareHits(const std::string& name, uint32_t width, const std::vector<ProbedHit>& own,
                          const std::vector<ProbedHit>& driver)
{
    Disagreements d;
    auto note = [&](size_t i, const char* what) {
        if (d.examples.size() > 2000) return;
        d.examples += "  " + name + " pixel (" + std::to_string(i % width) + ", " + std::to_string(i / width) +
                      "): " + what + ": own " + describe(own[i]) + ", driver " + describe(driver[i]) + "\n";
    };
    for (size_t i = 0; i < own.size(); ++i) {
        ++d.rays;
        const ProbedHit &a = own[i], &b = driver[i];
        if (a.hit != b.hit) {
            ++d.hitOrMiss;
            note(i, "hit or miss");
            continue;
        }
        if (!a.hit) continue;
        ++d.hits;
        // Each backend's t is a ratio of rounded products whose relative error
        // grows as 1 / |cos| of the incidence (the watertight test's, and
        // whatever test the driver uses): a few float steps of t / |cos| each
        // (measured at most 5.5 on these scenes), besides the hit points'
        // own error bounds.
        const double cosine = std::max(a.cosine, 1e-3);
        d.worstSteps = std::max(d.worstSteps, std::abs(a.t - b.t) * cosine / (kFloatStep * a.t));
        const bool sameDistance = std::abs(a.t - b.t) <= a.error + b.error + kDistanceSteps * kFloatStep * a.t / cosine;
        const bool samePrimitive = a.kind == b.kind && a.record == b.record && a.primitive == b.primitive;
        if (samePrimitive && !sameDistance) {
            ++d.distance;
            note(i, "distance");
        } else if (!samePrimitive && sameDistance) {
            ++d.tie;
        } else if (!samePrimitive) {
            ++d.otherPrimitive;
            note(i, "closest primitive");
        }
    }
    return d;
}

TEST_F(AccelBackends, HitForHitOnOverOneHundredThousandCameraRays)
{
    const std::string root = VKRT_TEST_SOURCE_DIR;
    // Meshes (instances, an emissive mesh, vertex normals, textures and uvs,
    // a glTF node hierarchy) and analytic kinds (spheres, boxes, triangles,
    // triangle lights, planes).
    const char* scenes[] = {"scenes/validation/mesh-cornell.toml",
                            "scenes/validation/mesh-bunny-diffuse.toml",
                            "scenes/validation/mesh-smooth.toml",
                            "scenes/validation/textured.toml",
                            "scenes/gltf/lights-camera.gltf",
                            "scenes/validation/lights.toml",
                            "scenes/seed/glass.toml"};
    Disagreements total;
    for (const char* file : scenes) {
        Scene scene = loadScene(root + "/" + file, ResolutionOverride{160, 120});
        const Disagreements d =
            compareHits(file, scene.camera.width, probeHits(scene, Walk::Own), probeHits(scene, Walk::Driver));
        RecordProperty(std::string(file) + " rays/hits/hit-or-miss/other-primitive/ties/distance",
                       std::to_string(d.rays) + "/" + std::to_string(d.hits) + "/" + std::to_string(d.hitOrMiss) + "/" +
                           std::to_string(d.otherPrimitive) + "/" + std::to_string(d.tie) + "/" +
                           std::to_string(d.distance));
        std::printf("%s: %llu rays, %llu hits; disagreements: hit or miss %llu, closest primitive %llu, "
                    "distance %llu; ties at shared edges %llu; largest distance difference %.2f float steps "
                    "of t / |cos|\n",
                    file, (unsigned long long)d.rays, (unsigned long long)d.hits, (unsigned long long)d.hitOrMiss,
                    (unsigned long long)d.otherPrimitive, (unsigned long long)d.distance, (unsigned long long)d.tie,
                    d.worstSteps);
        total.rays += d.rays;
        total.hits += d.hits;
        total.hitOrMiss += d.hitOrMiss;
        total.otherPrimitive += d.otherPrimitive;
        total.tie += d.tie;
        total.distance += d.distance;
        total.examples += d.examples;
    }
    EXPECT_GE(total.rays, 100000u);
    EXPECT_GE(total.hits, 50000u);
    EXPECT_EQ(total.otherPrimitive, 0u) << "the backends found different closest primitives:\n" << total.examples;
    EXPECT_EQ(total.distance, 0u) << "the backends' distances to the same primitive differ beyond both error bounds:\n"
                                  << total.examples;
    EXPECT_EQ(total.hitOrMiss, 0u) << "one backend hit where the other missed:\n" << total.examples;
    // Rays through an edge or vertex two triangles share may take either.
    EXPECT_LE(total.tie, total.hits / 1000) << total.examples;
}

TEST_F(AccelBackends, ThePacketWalkFindsTheLaneWalksHitsExactly)
{
    const std::string root = VKRT_TEST_SOURCE_DIR;
    const char* scenes[] = {"scenes/validation/mesh-bunny-diffuse.toml", "scenes/validation/mesh-smooth.toml"};
    uint64_t rays = 0, hits = 0, ties = 0, packetWalked = 0;
    for (const char* file : scenes) {
        Scene scene = loadScene(root + "/" + file, ResolutionOverride{160, 120});
        ASSERT_FALSE(scene.meshes.empty()) << file;
        const std::vector<ProbedHit> lanes = probeHits(scene, Walk::Own);
        const std::vector<ProbedHit> packets = probeHits(scene, Walk::OwnPackets);
        for (size_t i = 0; i < lanes.size(); ++i) {
            const ProbedHit &a = lanes[i], &b = packets[i];
            ++rays;
            ASSERT_EQ(a.hit, b.hit) << file << " pixel " << i << ": " << describe(a) << " / " << describe(b);
            if (!a.hit) continue;
            ++hits;
            packetWalked += a.kind == b.kind && a.kind == int(ShapeKind::Mesh) ? 1 : 0;
            const bool samePrimitive = a.kind == b.kind && a.record == b.record && a.primitive == b.primitive;
            if (!samePrimitive && a.t == b.t) {
                ++ties;
                continue;
            }
            ASSERT_TRUE(samePrimitive) << file << " pixel " << i << ": " << describe(a) << " / " << describe(b);
            ASSERT_EQ(a.t, b.t) << file << " pixel " << i;
            ASSERT_EQ(a.error, b.error) << file << " pixel " << i;
        }
    }
    EXPECT_GE(hits, 30000u);
    EXPECT_GE(packetWalked, 10000u); // mesh hits: what the packet walk found
    EXPECT_LE(ties, hits / 1000);
}

// The driver's box structures and top level are camera-relative: a camera
// move must rebuild them (Renderer::moveCamera, the viewer's path). With
// analytic kinds only, both backends run the same intersection code on the
// same records, so their images are equal bit for bit before and after the
// move; structures left at the old camera would put every sphere and box in
// the wrong place. The rebuild's time is what the viewer pays per move.
TEST_F(AccelBackends, CameraMovesRebuildTheDriversStructures)
{
    Scene scene =
        loadScene(std::string(VKRT_TEST_SOURCE_DIR) + "/scenes/validation/lights.toml", ResolutionOverride{64, 48});
    Camera moved = scene.camera;
    moved.eye += glm::dvec3(0.7, 0.3, -0.5);
    auto render = [&](bool driver) {
        RenderOptions options = pixelCentreOptions();
        options.driverAccel = driver;
        Renderer renderer(gpu(), scene, options);
        renderer.renderFrames(2);
        Image before = renderer.mean();
        renderer.moveCamera(moved);
        renderer.renderFrames(2);
        if (driver) RecordProperty("rebuild seconds", std::to_string(renderer.driverAccel()->rebuildSeconds()));
        return std::make_pair(before, renderer.mean());
    };
    const auto own = render(false), driver = render(true);
    EXPECT_EQ(own.first.rgb, driver.first.rgb);
    EXPECT_EQ(own.second.rgb, driver.second.rgb);
    EXPECT_NE(own.first.rgb, own.second.rgb); // the move changed the view
}

} // namespace
} // namespace vkrt::test
