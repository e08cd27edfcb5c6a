// The path integrator against closed forms: furnaces, pbrt-v4's analytic
// sphere, and direct light from a triangle emitter (MIS of light and BSDF
// sampling), with statistical tests where the estimate is noisy.
#include "io/ExrFile.h"
#include "render/CubeFaces.h"
#include "render/Renderer.h"
#include "scene/SceneParser.h"
#include "support/TestSupport.h"

#include <cmath>
#include <cstdio>
#include <fstream>

namespace vkrt::test {
namespace {

RenderOptions options(uint32_t seed = 1, bool jitter = false)
{
    RenderOptions o;
    o.seed = seed;
    o.jitter = jitter;
    o.cacheDirectory = testCacheDir();
    return o;
}

/// Per-pixel mean and the renderer's own estimate of its variance.
struct Estimate {
    Image mean;
    std::vector<double> varianceOfMean; ///< per float of mean.rgb
};

Estimate estimate(const Scene& scene, uint32_t frames)
{
    RenderOptions o = options(7);
    o.variance = true;
    Renderer renderer(gpu(), scene, o);
    renderer.renderFrames(frames);
    EXPECT_EQ(renderer.counters().rejectedSamples, 0u);
    Image variance = renderer.varianceOfMean();
    return {renderer.mean(), std::vector<double>(variance.rgb.begin(), variance.rgb.end())};
}

/// Fraction of values whose |z| stays under the Sidak-corrected threshold
/// for alpha = 0.01 over all tested values.
double fractionPassingZTest(const Estimate& e, const std::vector<double>& expected)
{
    size_t n = expected.size(), pass = 0;
    double alpha = 1.0 - std::pow(1.0 - 0.01, 1.0 / double(n));
    // Two-sided normal quantile for alpha by bisection on erfc.
    double lo = 0.0, hi = 40.0;
    for (int i = 0; i < 200; ++i) {
        double mid = 0.5 * (lo + hi);
        (std::erfc(mid / std::sqrt(2.0)) > alpha ? lo : hi) = mid;
    }
    double threshold = lo;
    for (size_t i = 0; i < n; ++i) {
        double sigma = std::sqrt(e.varianceOfMean[i]);
        double diff = std::abs(e.mean.rgb[i] - expected[i]);
        // Where every sample has the same value (e.g. a diffuse sphere lit
        // from its centre, k <= 2 bounces), the spread left is float rounding:
        // then sigma says nothing about the mean's error, and a difference
        // within float32 rounding passes. (Mesa 26 rounds such samples a few
        // ulps apart where Mesa 25 gave them bit for bit equal: sigma 1e-9.)
        bool withinRounding = diff <= 1e-5 * std::abs(expected[i]) + 1e-7;
        if (withinRounding || (sigma > 0.0 && diff / sigma < threshold)) ++pass;
    }
    return double(pass) / double(n);
}

/// z-score of the summed difference over all values: far more sensitive to a
/// small bias everywhere than the per-value test.
double pooledZ(const Estimate& e, const std::vector<double>& expected)
{
    double diff = 0.0, variance = 0.0;
    for (size_t i = 0; i < expected.size(); ++i) diff += e.mean.rgb[i] - expected[i], variance += e.varianceOfMean[i];
    return variance > 0.0 ? diff / std::sqrt(variance) : (std::abs(diff) < 1e-6 * expected.size() ? 0.0 : 1e30);
}

class PathTest : public GpuTest {};

std::string furnace(const std::string& material, int maxDepth)
{
    // Appended piece by piece: GCC 14 reports a false -Warray-bounds at -O2 in
    // the inlined `std::string&& + "..."`.
    std::string text = "[render]\nintegrator = \"path\"\nmax_depth = ";
    text += std::to_string(maxDepth);
    text += R"(
[camera]
eye = [0, 0, 3]
target = [0, 0, 0]
fov = 40
width = 24
height = 24
[background]
color = 1
[materials.m]
)";
    text += material;
    text += R"(
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1
material = "m"
)";
    return text;
}

TEST_F(PathTest, WhiteFurnaceLambertMirrorAndGlassAreInvisible)
{
    struct Case {
        const char* material;
        double expected;
    } cases[] = {
        {"type = \"lambert\"\nalbedo = 1", 1.0},
        {"type = \"lambert\"\nalbedo = 0.5", 0.5},
        {"type = \"mirror\"\nreflectance = 1", 1.0},
        {"type = \"dielectric\"\nior = 1.5", 1.0},
        {"type = \"dielectric\"\nior = 1.33\nfresnel = \"exact\"", 1.0},
    };
    for (const Case& c : cases) {
        Scene scene = sceneFromText(furnace(c.material, 32));
        Estimate e = estimate(scene, 64);
        std::vector<double> expected(e.mean.rgb.size(), c.expected);
        // Pixels off the sphere see the environment (1): expected there too for albedo 1.
        for (uint32_t y = 0; y < 24; ++y)
            for (uint32_t x = 0; x < 24; ++x) {
                double sx = (2.0 * (x + 0.5) / 24 - 1) * std::tan(M_PI / 9),
                       sy = (1 - 2.0 * (y + 0.5) / 24) * std::tan(M_PI / 9);
                double b = 3.0 / std::sqrt(1 + sx * sx + sy * sy); // distance of closest approach test
                bool hits = 9.0 - b * b < 1.0;
                for (int k = 0; k < 3; ++k) expected[(y * 24 + x) * 3 + k] = hits ? c.expected : 1.0;
            }
        EXPECT_GE(fractionPassingZTest(e, expected), 0.9975) << c.material;
        EXPECT_LT(std::abs(pooledZ(e, expected)), 4.0) << c.material;
    }
}

// pbrt-v4's analytic test: camera inside a diffuse sphere (Kd = 0.5) with a
// point light of intensity pi at its centre sees L = 1 - 0.5^k with k
// bounces: direct light 0.5 / r^2 = 0.5, each interreflection half the last.
TEST_F(PathTest, InsideDiffuseSphereWithCentralPointLight)
{
    for (int k : {1, 2, 3, 6, 40}) {
        std::string text = "[render]\nintegrator = \"path\"\nmax_depth = " + std::to_string(k) + R"(
[camera]
eye = [0, 0, 0]
target = [0, 0, -1]
fov = 60
width = 16
height = 16
[materials.m]
type = "lambert"
albedo = 0.5
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1
material = "m"
[[lights]]
type = "point"
position = [0, 0, 0]
intensity = 3.14159265358979
)";
        Estimate e = estimate(sceneFromText(text), 128);
        double expected = 1.0 - std::pow(0.5, k);
        // Every pixel has the same expectation: pool them for a tight check.
        double sum = 0, var = 0;
        for (size_t i = 0; i < e.mean.rgb.size(); ++i) sum += e.mean.rgb[i], var += e.varianceOfMean[i];
        double n = double(e.mean.rgb.size());
        double mean = sum / n, standardError = std::sqrt(var) / n;
        EXPECT_NEAR(mean, expected, 4.0 * standardError + 1e-5 * expected) << "k = " << k;
        // From the fourth vertex on, Russian roulette makes each pixel's
        // samples strongly skewed (most paths end at 0.9375, a few far above),
        // so a per-pixel normal test is only valid before it.
        if (k <= 3) {
            EXPECT_GE(fractionPassingZTest(e, std::vector<double>(e.mean.rgb.size(), expected)), 0.9975) << "k = " << k;
        }
    }
}

/// Irradiance at p (normal n) from a uniformly emitting polygon of radiance 1
/// (Lambert's formula): E = 1/2 |sum_i angle(u_i, u_i+1) n . unit(u_i x u_i+1)|.
double polygonIrradiance(const glm::dvec3& p, const glm::dvec3& n, const std::vector<glm::dvec3>& vertices)
{
    double sum = 0.0;
    for (size_t i = 0; i < vertices.size(); ++i) {
        glm::dvec3 a = glm::normalize(vertices[i] - p), b = glm::normalize(vertices[(i + 1) % vertices.size()] - p);
        glm::dvec3 c = glm::cross(a, b);
        sum += std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)) * glm::dot(n, c / glm::length(c));
    }
    return 0.5 * std::abs(sum);
}

/// Moller-Trumbore in double, for deciding which pixels see the light.
bool hitsTriangle(const glm::dvec3& o, const glm::dvec3& d, const std::vector<glm::dvec3>& v)
{
    glm::dvec3 e1 = v[1] - v[0], e2 = v[2] - v[0], p = glm::cross(d, e2);
    double det = glm::dot(e1, p);
    glm::dvec3 s = o - v[0];
    double a = glm::dot(s, p) / det;
    glm::dvec3 q = glm::cross(s, e1);
    double b = glm::dot(d, q) / det, t = glm::dot(e2, q) / det;
    return a >= 0 && b >= 0 && a + b <= 1 && t > 0;
}

// A Lambert floor lit by one triangle light, direct light only: each pixel's
// estimate (light sampling and BSDF sampling combined by MIS in the path
// integrator, light sampling alone in Whitted) must match rho/pi * Le * E.
TEST_F(PathTest, TriangleLightOverLambertFloorMatchesPolygonFormula)
{
    for (const char* integrator : {"path", "whitted"}) {
        std::string text = std::string("[render]\nintegrator = \"") + integrator + R"("
max_depth = 1
[camera]
eye = [0, 3, 3]
target = [0, 0, 0]
fov = 50
width = 24
height = 18
[materials.floor]
type = "lambert"
albedo = 0.6
[[objects]]
shape = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"
[[lights]]
type = "triangle"
vertices = [[-0.5, 1.2, 0.3], [0.3, 1.0, 0.8], [0.6, 1.4, -0.4]]
radiance = [4, 2, 1]
two_sided = true
)";
        Scene scene = sceneFromText(text);
        Estimate e = estimate(scene, 256);
        std::vector<glm::dvec3> light = {{-0.5, 1.2, 0.3}, {0.3, 1.0, 0.8}, {0.6, 1.4, -0.4}};
        std::vector<double> expected(e.mean.rgb.size());
        const Camera& c = scene.camera;
        glm::dvec3 forward = glm::normalize(c.target - c.eye), right = glm::normalize(glm::cross(forward, c.up));
        glm::dvec3 up = glm::cross(right, forward);
        double t = std::tan(c.fovY * M_PI / 360.0);
        for (uint32_t y = 0; y < c.height; ++y)
            for (uint32_t x = 0; x < c.width; ++x) {
                double sx = (2.0 * (x + 0.5) / c.width - 1) * t * c.width / c.height,
                       sy = (1 - 2.0 * (y + 0.5) / c.height) * t;
                glm::dvec3 d = glm::normalize(sx * right + sy * up + forward);
                glm::dvec3 p = c.eye + (-c.eye.y / d.y) * d;
                // Pixels whose centre ray meets the (two-sided) light see its radiance.
                double factor =
                    hitsTriangle(c.eye, d, light) ? 1.0 : 0.6 / M_PI * polygonIrradiance(p, {0, 1, 0}, light);
                for (int k = 0; k < 3; ++k) expected[(y * c.width + x) * 3 + k] = factor * glm::dvec3(4, 2, 1)[k];
            }
        EXPECT_GE(fractionPassingZTest(e, expected), 0.9975) << integrator;
        EXPECT_LT(std::abs(pooledZ(e, expected)), 4.0) << integrator;
    }
}

// Glass that is not closed, seen at normal incidence against a light behind
// it (R = ((n - 1) / (n + 1))^2, T = 1 - R, n = 1.5). The path integrator
// decides each crossing by the side it meets (a mesh's front is always
// entered from outside, as in Mitsuba) and scales radiance by
// (n_incident / n_transmitted)^2 at each refraction:
// - one open sheet: entered, never left, T / n^2;
// - two parallel sheets of one mesh facing the camera: the ray enters the
//   first, leaves through the open side between them without a crossing and
//   enters the second from outside: T^2 / (n^4 (1 - R^2)) with the
//   reflections between them. A stale medium-stack entry would see glass on
//   both sides of the second sheet (no reflection, no bending: T) and no
//   scaling would give T^2 / (1 - R^2): both far outside the noise.
TEST_F(PathTest, OpenGlassIsCrossedByItsSidesAndScalesRadiance)
{
    const std::filesystem::path dir = freshTempDir("open-glass");
    const double n = 1.5, r = (n - 1) * (n - 1) / ((n + 1) * (n + 1)), t = 1 - r;
    auto writeSheets = [&](const std::string& name, std::initializer_list<const char*> depths) {
        std::string obj;
        int base = 1;
        for (const char* z : depths) {
            for (const char* corner : {"-50 -50", "50 -50", "50 50", "-50 50"})
                obj += std::string("v ") + corner + " " + z + "\n";
            // Counter-clockwise seen from +z: the front faces the camera.
            obj += "f " + std::to_string(base) + " " + std::to_string(base + 1) + " " + std::to_string(base + 2) + "\n";
            obj += "f " + std::to_string(base) + " " + std::to_string(base + 2) + " " + std::to_string(base + 3) + "\n";
            base += 4;
        }
        std::ofstream(dir / name) << obj;
    };
    writeSheets("one.obj", {"0"});
    writeSheets("two.obj", {"0", "-1"});
    struct Case {
        const char* file;
        double expected;
    };
    for (Case c : {Case{"one.obj", t / (n * n)}, Case{"two.obj", t * t / (n * n * n * n * (1 - r * r))}}) {
        std::string text = R"([render]
integrator = "path"
max_depth = 12
[camera]
eye = [0, 0, 5]
target = [0, 0, 0]
fov = 1
width = 4
height = 3
[materials.glass]
type = "dielectric"
ior = 1.5
[[objects]]
shape = "mesh"
material = "glass"
file = ")";
        text += c.file;
        text += R"("
[[lights]]
type = "triangle"
vertices = [[-100, -100, -2], [100, -100, -2], [0, 100, -2]]
radiance = 1
)";
        Scene scene = parseSceneString(text, (dir / "scene.toml").string());
        Estimate e = estimate(scene, 2048);
        std::vector<double> expected(e.mean.rgb.size(), c.expected);
        double mean = 0;
        for (float v : e.mean.rgb) mean += v / double(e.mean.rgb.size());
        std::printf("[ measured ] open glass %s: mean %.5f, expected %.5f, pooled z %+.2f\n", c.file, mean, c.expected,
                    pooledZ(e, expected));
        EXPECT_LT(std::abs(pooledZ(e, expected)), 4.0) << c.file;
        EXPECT_NEAR(mean, c.expected, 0.02 * c.expected) << c.file;
    }
}

// A Lambert sphere in a cubemap whose faces are six constant colours, one
// bounce: each pixel on the sphere sees rho/pi times the irradiance of that
// environment at its normal (integrated here over fine face grids), which
// tests cubemap importance sampling, its pdf and MIS with BSDF sampling.
TEST_F(PathTest, LambertSphereInFaceColouredCubemapMatchesIrradiance)
{
    const std::array<glm::dvec3, 6> colours = {glm::dvec3{2.0, 0.1, 0.1}, {0.1, 1.5, 0.1}, {4.0, 4.0, 3.5},
                                               {0.05, 0.05, 0.05},        {0.3, 0.3, 1.2}, {1.0, 0.6, 0.2}};
    std::filesystem::path dir = freshTempDir("env-irradiance");
    const char* names[6] = {"px", "nx", "py", "ny", "pz", "nz"};
    std::string text = R"([render]
integrator = "path"
max_depth = 1
[camera]
eye = [0.3, 0.8, 3]
target = [0, 0, 0]
fov = 45
width = 20
height = 20
[materials.m]
type = "lambert"
albedo = 0.8
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1
material = "m"
[background.cubemap]
)";
    for (int f = 0; f < 6; ++f) {
        Image face(4, 4);
        for (size_t i = 0; i < face.pixelCount(); ++i)
            for (int c = 0; c < 3; ++c) face.rgb[i * 3 + c] = float(colours[f][c]);
        writeExr(dir / (std::string(names[f]) + ".exr"), face, {});
        text += std::string(names[f]) + " = \"" + names[f] + ".exr\"\n";
    }
    Scene scene = parseSceneString(text, (dir / "scene.toml").string());
    Estimate e = estimate(scene, 256);

    auto irradiance = [&](const glm::dvec3& n) {
        constexpr int kGrid = 200;
        glm::dvec3 sum(0.0);
        for (int f = 0; f < 6; ++f)
            for (int j = 0; j < kGrid; ++j)
                for (int i = 0; i < kGrid; ++i) {
                    double s = (i + 0.5) / kGrid, t = (j + 0.5) / kGrid;
                    double sc = 2 * s - 1, tc = 2 * t - 1, r = std::sqrt(sc * sc + tc * tc + 1);
                    double solidAngle = 4.0 / (kGrid * kGrid) / (r * r * r);
                    sum += colours[f] * std::max(0.0, glm::dot(n, cubeFaceDirection(f, s, t))) * solidAngle;
                }
        return sum;
    };
    const Camera& c = scene.camera;
    glm::dvec3 forward = glm::normalize(c.target - c.eye), right = glm::normalize(glm::cross(forward, c.up));
    glm::dvec3 up = glm::cross(right, forward);
    double tanHalf = std::tan(c.fovY * M_PI / 360.0);
    std::vector<double> expected;
    std::vector<double> values, variances;
    for (uint32_t y = 0; y < c.height; ++y)
        for (uint32_t x = 0; x < c.width; ++x) {
            glm::dvec3 d = glm::normalize((2.0 * (x + 0.5) / c.width - 1) * tanHalf * right +
                                          (1 - 2.0 * (y + 0.5) / c.height) * tanHalf * up + forward);
            double b = glm::dot(c.eye, d), disc = b * b - (glm::dot(c.eye, c.eye) - 1.0);
            if (disc < 0.05) continue; // off the sphere or too close to its silhouette
            glm::dvec3 n = glm::normalize(c.eye + (-b - std::sqrt(disc)) * d);
            glm::dvec3 radiance = 0.8 / M_PI * irradiance(n);
            for (int k = 0; k < 3; ++k) {
                size_t i = (y * c.width + x) * 3 + k;
                expected.push_back(radiance[k]);
                values.push_back(e.mean.rgb[i]);
                variances.push_back(e.varianceOfMean[i]);
            }
        }
    ASSERT_GT(expected.size(), 300u);
    Estimate onSphere{Image(uint32_t(values.size()), 1), variances};
    for (size_t i = 0; i < values.size(); ++i) onSphere.mean.rgb[i] = float(values[i]);
    EXPECT_GE(fractionPassingZTest(onSphere, expected), 0.9975);
    EXPECT_LT(std::abs(pooledZ(onSphere, expected)), 4.0);
}

} // namespace
} // namespace vkrt::test

namespace vkrt::test {
namespace {

/// Mean squared error of an image against a reference, and the relative
/// difference of their image means.
std::pair<double, double> errorAgainst(const Image& image, const Image& reference)
{
    double squared = 0, sum = 0, refSum = 0;
    for (size_t i = 0; i < image.rgb.size(); ++i) {
        double d = double(image.rgb[i]) - reference.rgb[i];
        squared += d * d, sum += image.rgb[i], refSum += reference.rgb[i];
    }
    return {squared / double(image.rgb.size()), sum / refSum - 1.0};
}

// The Sobol' sampler (`--sampler sobol`) must stay unbiased and, on these
// smooth-lit scenes, give a clearly lower error than independent samples at
// equal spp, measured against the committed Mitsuba references.
TEST_F(PathTest, SobolSamplerIsUnbiasedAndLowersTheError)
{
    for (const char* name : {"diffuse-box", "lights"}) {
        std::string root = std::string(VKRT_TEST_SOURCE_DIR);
        Scene scene = parseSceneFile(root + "/scenes/validation/" + name + ".toml");
        Image reference = readExr(root + "/tests/references/validation/" + name + "/mean.exr").image;
        RenderOptions sobol = options(3, true), independent = options(3, true);
        sobol.sobol = true;
        Renderer a(gpu(), scene, sobol), b(gpu(), scene, independent);
        a.renderFrames(64);
        b.renderFrames(64);
        auto [mseSobol, biasSobol] = errorAgainst(a.mean(), reference);
        auto [mseIndependent, biasIndependent] = errorAgainst(b.mean(), reference);
        std::printf("[ measured ] %s, 64 spp: MSE sobol %.4g, independent %.4g (ratio %.2f); image mean vs "
                    "Mitsuba %+.4f%% / %+.4f%%\n",
                    name, mseSobol, mseIndependent, mseIndependent / mseSobol, 100 * biasSobol, 100 * biasIndependent);
        EXPECT_LT(mseSobol, 0.5 * mseIndependent) << name;
        EXPECT_LT(std::abs(biasSobol), 0.005) << name << ": the image mean must match Mitsuba's";
        EXPECT_TRUE(a.variant().sobolSampler && !b.variant().sobolSampler);
    }
}

} // namespace
} // namespace vkrt::test
