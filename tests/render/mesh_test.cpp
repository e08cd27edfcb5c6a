// Meshes on the GPU: BVH traversal, instancing, transforms and their
// precision, shading normals and emissive meshes, each checked against an
// answer that does not come from the mesh code itself (the analytic
// sphere, the analytic triangle lights, the same scene elsewhere in space).
#include "mesh/MeshGeometry.h"
#include "mesh/Procedural.h"
#include "render/ErrorMetrics.h"
#include "render/Renderer.h"
#include "support/TestSupport.h"

#include <cmath>
#include <sstream>

namespace vkrt::test {
namespace {

class MeshRender : public GpuTest {};

struct Estimate {
    Image mean;
    Image variance;
};

Estimate renderWithVariance(const Scene& scene, uint32_t frames, uint32_t seed)
{
    RenderOptions o;
    o.seed = seed;
    o.variance = true;
    o.cacheDirectory = testCacheDir();
    Renderer renderer(gpu(), scene, o);
    renderer.renderFrames(frames);
    return {renderer.mean(), renderer.varianceOfMean()};
}

/// Both estimates agree pixel by pixel (Sidak-corrected Z-test at 1%).
void expectSameMeans(const Estimate& a, const Estimate& b, size_t allowedFailures, const std::string& what)
{
    PixelTestSummary z = pixelZTest(a.mean, a.variance, b.mean, b.variance, 0.01);
    reportStat(what + " failing values", double(z.tested - z.passed));
    EXPECT_GE(z.passed + allowedFailures, z.tested) << what << ": " << z.tested - z.passed << " of " << z.tested
                                                   << " values differ (smallest p " << z.minPValue << ")";
    double sumA = 0, sumB = 0;
    for (size_t i = 0; i < a.mean.rgb.size(); ++i) sumA += a.mean.rgb[i], sumB += b.mean.rgb[i];
    EXPECT_GT(sumA, 0.0) << what << ": the image is black, nothing was tested";
}

std::string sphereSceneText(const std::string& sphere)
{
    return R"(
[render]
integrator = "path"
max_depth = 3
[camera]
eye = [0, 0.4, 3]
target = [0, 0, 0]
fov = 40
width = 48
height = 40
[materials.clay]
type = "lambert"
albedo = [0.7, 0.5, 0.3]
[materials.floor]
type = "lambert"
albedo = [0.5, 0.5, 0.5]
[[objects]]
shape = "box"
min = [-3, -1.2, -3]
max = [3, -1, 3]
material = "floor"
[[lights]]
type = "triangle"
vertices = [[-1, 2.5, -1], [1, 2.5, -1], [0, 2.5, 1.5]]
radiance = [6, 6, 6]
[background]
color = [0.1, 0.12, 0.15]
)" + sphere;
}

// A finely tessellated sphere with its exact radial vertex normals renders
// like the analytic sphere: the same shading and shadow, statistically.
TEST_F(MeshRender, TessellatedSphereMatchesAnalyticSphere)
{
    const auto dir = freshTempDir("mesh-sphere");
    writePly(makeUvSphere(80000, glm::vec3(0.0f), 1.0f), dir / "sphere.ply", true);
    const Scene analytic = sceneFromText(sphereSceneText(R"(
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1
material = "clay"
)"),
                                         (dir / "analytic.toml").string());
    const Scene mesh = sceneFromText(sphereSceneText(R"(
[[objects]]
shape = "mesh"
file = "sphere.ply"
material = "clay"
)"),
                                     (dir / "mesh.toml").string());
    ASSERT_EQ(mesh.meshes.size(), 1u);
    ASSERT_GE(mesh.meshes[0].geometry->data.triangles.size(), 80000u);
    ASSERT_FALSE(mesh.meshes[0].geometry->data.normals.empty()) << "the PLY's vertex normals were dropped";
    // A few silhouette pixels may see the polygon's chord instead of the circle.
    expectSameMeans(renderWithVariance(analytic, 192, 1), renderWithVariance(mesh, 192, 2), 3, "sphere");
}

// The same sphere shaded with face normals is visibly faceted: the test
// above would notice if shading normals were ignored.
TEST_F(MeshRender, FaceNormalsOfACoarseSphereDifferFromTheAnalyticSphere)
{
    const auto dir = freshTempDir("mesh-coarse");
    writePly(makeUvSphere(60, glm::vec3(0.0f), 1.0f), dir / "coarse.ply", true);
    const Scene analytic = sceneFromText(sphereSceneText(R"(
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1
material = "clay"
)"),
                                         (dir / "analytic.toml").string());
    const Scene faceted = sceneFromText(sphereSceneText(R"(
[[objects]]
shape = "mesh"
file = "coarse.ply"
normals = "face"
material = "clay"
)"),
                                        (dir / "faceted.toml").string());
    const Estimate round = renderWithVariance(analytic, 64, 1), flat = renderWithVariance(faceted, 64, 2);
    PixelTestSummary z = pixelZTest(round.mean, round.variance, flat.mean, flat.variance);
    EXPECT_GT(z.tested - z.passed, 100u) << "a 60-triangle faceted sphere should differ from the round one";
}

// Two emissive mesh triangles light the scene exactly as the same two
// triangles given as [[lights]]: power-proportional emitter choice and its
// MIS weights against BSDF sampling are unbiased.
TEST_F(MeshRender, EmissiveMeshMatchesTriangleLights)
{
    const auto dir = freshTempDir("mesh-emitter");
    MeshData quad;
    quad.positions = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {2, 0.5, -1}, {2.5, 0.5, -1}, {2.2, 0.5, 0}};
    // Facing down (-y): clockwise seen from above. The small third triangle is brighter per area.
    quad.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}};
    writeObj(quad, dir / "quad.obj");
    const std::string common = R"(
[render]
integrator = "path"
max_depth = 3
[camera]
eye = [0, 1, 5]
target = [0, -0.5, 0]
fov = 50
width = 40
height = 32
[materials.white]
type = "lambert"
albedo = [0.8, 0.8, 0.8]
[materials.black]
type = "lambert"
albedo = [0, 0, 0]
[[objects]]
shape = "box"
min = [-4, -2.2, -4]
max = [4, -2, 4]
material = "white"
[[objects]]
shape = "sphere"
center = [0.3, -1.3, 0.2]
radius = 0.7
material = "white"
)";
    const Scene lights = sceneFromText(common + R"(
[[lights]]
type = "triangle"
vertices = [[-1, 1.5, -1], [1, 1.5, -1], [1, 1.5, 1]]
radiance = [3, 2, 1]
[[lights]]
type = "triangle"
vertices = [[-1, 1.5, -1], [1, 1.5, 1], [-1, 1.5, 1]]
radiance = [3, 2, 1]
[[lights]]
type = "triangle"
vertices = [[2, 2, -1], [2.5, 2, -1], [2.2, 2, 0]]
radiance = [3, 2, 1]
)",
                                       (dir / "lights.toml").string());
    const Scene emissive = sceneFromText(common + R"(
[[objects]]
shape = "mesh"
file = "quad.obj"
material = "black"
translate = [0, 1.5, 0]
emission = [3, 2, 1]
)",
                                         (dir / "emissive.toml").string());
    // The mesh's third triangle sits 0.5 higher in the file: move it to y = 2 like the light.
    ASSERT_EQ(emissive.meshes.size(), 1u);
    expectSameMeans(renderWithVariance(lights, 256, 3), renderWithVariance(emissive, 256, 4), 0, "emitters");
}

// Instances of one file share its geometry (one copy of its triangles and
// BVH on the GPU), each placed by its own transform.
TEST_F(MeshRender, InstancesShareOneGeometry)
{
    const auto dir = freshTempDir("mesh-instances");
    writeObj(makeUvSphere(500, glm::vec3(0.0f), 0.4f), dir / "ball.obj");
    // Whitted, a point light at the eye, no background: balls are lit, the rest is black.
    std::string text = R"(
[render]
max_depth = 1
[camera]
eye = [0, 0, 4]
target = [0, 0, 0]
fov = 40
width = 48
height = 16
[materials.clay]
type = "lambert"
[[lights]]
type = "point"
position = [0, 0, 4]
intensity = 10
)";
    for (int i = 0; i < 3; ++i)
        text += "[[objects]]\nshape = \"mesh\"\nfile = \"ball.obj\"\nmaterial = \"clay\"\ntranslate = [" +
                std::to_string(i - 1.0) + ", 0, 0]\n";
    const Scene scene = sceneFromText(text, (dir / "scene.toml").string());
    ASSERT_EQ(scene.meshes.size(), 3u);
    EXPECT_EQ(scene.meshes[0].geometry, scene.meshes[2].geometry);
    Renderer renderer(gpu(), scene, pixelCentreOptions());
    const size_t triangles = scene.meshes[0].geometry->data.triangles.size();
    EXPECT_EQ(renderer.meshData().meshTriangles.size(), triangles);
    ASSERT_TRUE(renderer.meshData().top.has_value());
    EXPECT_EQ(renderer.meshData().top->refs.size(), 3u) << "one top-level leaf per instance";
    renderer.renderFrames(1);
    // Along the centre row: lit at the three centres (x = -1, 0, 1 project to
    // columns 24 -+ 24 / (12 tan 20deg) = 24 -+ 5.5, radius 2.2), black in the gaps.
    const Image image = renderer.mean();
    const uint32_t row = image.height / 2;
    for (uint32_t x : {18u, 24u, 29u}) EXPECT_GT(image.at(x, row)[0], 0.05f) << "ball at column " << x;
    for (uint32_t x : {0u, 21u, 26u, 47u}) EXPECT_EQ(image.at(x, row)[0], 0.0f) << "gap at column " << x;
}

std::string farSceneText(double offset, double scale)
{
    auto point = [&](double x, double y, double z) {
        std::ostringstream s;
        s.precision(17);
        s << "[" << x * scale + offset << ", " << y * scale + offset << ", " << z * scale + offset << "]";
        return s.str();
    };
    std::ostringstream s;
    s.precision(17);
    s << "[camera]\neye = " << point(0.3, 0.8, 3) << "\ntarget = " << point(0, 0, 0)
      << "\nfov = 40\nwidth = 40\nheight = 32\n"
      << "[materials.grey]\ntype = \"lambert\"\nalbedo = [0.6, 0.6, 0.6]\n"
      << "[[objects]]\nshape = \"mesh\"\nfile = \"ball.obj\"\nmaterial = \"grey\"\nnormals = \"face\"\nscale = "
      << scale << "\ntranslate = " << point(0, 0, 0) << "\n"
      << "[[objects]]\nshape = \"mesh\"\nfile = \"floor.obj\"\nmaterial = \"grey\"\nscale = " << scale
      << "\ntranslate = " << point(0, -1, 0) << "\n"
      << "[[lights]]\ntype = \"point\"\nposition = " << point(1, 3, 2) << "\nintensity = [" << 20 * scale * scale
      << ", " << 20 * scale * scale << ", " << 20 * scale * scale << "]\n";
    return s.str();
}

// Camera-relative conversion holds for meshes: the scene 1e5 away, or
// scaled by 1e-4, gives the image it gives at the origin. Shadow-ray
// self-intersection (acne) or lost hits would show as dark or black pixels.
TEST_F(MeshRender, FarAwayAndTinyMeshesRenderLikeAtTheOrigin)
{
    const auto dir = freshTempDir("mesh-far");
    writeObj(makeUvSphere(2000, glm::vec3(0.0f), 1.0f), dir / "ball.obj");
    MeshData floor = makeGrid(8);
    // makeGrid lies in z = 0: turn it into a y = 0 floor of half-size 3.
    for (glm::vec3& p : floor.positions) p = glm::vec3(3.0f * p.x, 0.0f, -3.0f * p.y);
    writeObj(floor, dir / "floor.obj");
    auto render = [&](double offset, double scale) {
        Renderer renderer(gpu(), sceneFromText(farSceneText(offset, scale), (dir / "s.toml").string()),
                          pixelCentreOptions());
        renderer.renderFrames(1);
        return renderer.mean();
    };
    const Image origin = render(0.0, 1.0);
    for (auto [offset, scale] : {std::pair{1e5, 1.0}, std::pair{0.0, 1e-4}, std::pair{-1e5, 1e-2}}) {
        const Image moved = render(offset, scale);
        double worst = 0.0;
        size_t lit = 0;
        for (size_t i = 0; i < origin.rgb.size(); ++i) {
            const double a = origin.rgb[i], b = moved.rgb[i];
            if (a > 1e-3) ++lit;
            worst = std::max(worst, std::abs(a - b) / std::max(a, 1e-3));
        }
        EXPECT_GT(lit, origin.rgb.size() / 4);
        // Silhouette pixels may flip between ball and floor: allow rare large
        // differences, but nothing systematic.
        size_t bad = 0;
        for (size_t i = 0; i < origin.rgb.size(); ++i)
            bad += std::abs(origin.rgb[i] - moved.rgb[i]) > 0.02 * std::max<double>(origin.rgb[i], 1e-2);
        EXPECT_LE(bad, origin.rgb.size() / 200) << "offset " << offset << " scale " << scale << " worst " << worst;
    }
}

// A camera move refits the top level and re-uploads only camera-relative
// data: the image equals a renderer made afresh at the new camera.
TEST_F(MeshRender, CameraMoveGivesTheImageOfAFreshRenderer)
{
    const auto dir = freshTempDir("mesh-move");
    writeObj(makeUvSphere(3000, glm::vec3(0.0f), 0.8f), dir / "ball.obj");
    const std::string text = sphereSceneText(R"(
[[objects]]
shape = "mesh"
file = "ball.obj"
material = "clay"
translate = [0.2, 0, 0]
)");
    Scene scene = sceneFromText(text, (dir / "scene.toml").string());
    Renderer moved(gpu(), scene, pixelCentreOptions());
    const size_t nodes = moved.meshData().meshNodes.size();
    Camera camera = scene.camera;
    camera.eye = glm::dvec3(1.5, 1.0, 2.0);
    moved.moveCamera(camera);
    EXPECT_EQ(moved.meshData().meshNodes.size(), nodes);
    moved.renderFrames(2);
    scene.camera = camera;
    Renderer fresh(gpu(), scene, pixelCentreOptions());
    fresh.renderFrames(2);
    const Image a = moved.mean(), b = fresh.mean();
    ASSERT_EQ(a.rgb.size(), b.rgb.size());
    size_t differing = 0;
    for (size_t i = 0; i < a.rgb.size(); ++i) differing += a.rgb[i] != b.rgb[i];
    EXPECT_EQ(differing, 0u);
}

} // namespace
} // namespace vkrt::test
