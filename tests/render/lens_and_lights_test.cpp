// The thin-lens camera and the directional and spot lights against closed
// forms computed here on the CPU, independently of the kernels:
// - a delta sun and a spot light on a Lambert plane (Whitted, pixel centres:
//   deterministic, every pixel compared);
// - a soft sun: a cone of uniform radiance above a plane gives the same
//   irradiance E cos(theta0) as a delta sun (the cap's first moment), in
//   both integrators (the path integrator's MIS between cone and BSDF);
// - the thin lens: an emitting half-plane x > 0 seen out of focus has, at
//   each pixel centre, the fraction of the lens disk that sees it (a
//   circular segment), and in focus the pinhole's sharp edge.
#include "render/Renderer.h"
#include "support/TestSupport.h"

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace vkrt::test {
namespace {

class LensAndLights : public GpuTest {};

/// The camera ray through a pixel centre (the conventions of convertCamera).
glm::dvec3 pixelDirection(const Camera& c, uint32_t x, uint32_t y)
{
    const glm::dvec3 forward = glm::normalize(c.target - c.eye);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, c.up));
    const glm::dvec3 up = glm::cross(right, forward);
    const double halfHeight = std::tan(glm::radians(c.fovY) / 2.0);
    const double halfWidth = halfHeight * c.width / c.height;
    const double ndcX = 2.0 * (x + 0.5) / c.width - 1.0, ndcY = 1.0 - 2.0 * (y + 0.5) / c.height;
    return glm::normalize(ndcX * halfWidth * right + ndcY * halfHeight * up + forward);
}

constexpr double kAlbedo = 0.5;

std::string planeScene(const std::string& integrator, const std::string& light)
{
    return "[render]\nintegrator = \"" + integrator +
           "\"\nmax_depth = 1\n"
           "[camera]\neye = [0, 2, 3]\ntarget = [0, 0, 0]\nfov = 50\nwidth = 32\nheight = 24\n"
           "[materials.white]\ntype = \"lambert\"\nalbedo = 0.5\n"
           "[[objects]]\nshape = \"plane\"\nmaterial = \"white\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\n"
           "[[lights]]\n" +
           light;
}

/// Every pixel's expected radiance from the plane y = 0 it sees (nullopt where
/// it sees the sky, or where `expected` declines the point).
template <class Expected>
void expectPlaneRadiance(const std::string& text, Expected expected, double relative)
{
    const Scene scene = sceneFromText(text);
    Renderer renderer(gpu(), scene, pixelCentreOptions());
    renderer.renderFrames(1);
    const Image image = renderer.mean();
    int compared = 0;
    for (uint32_t y = 0; y < image.height; ++y) {
        for (uint32_t x = 0; x < image.width; ++x) {
            const glm::dvec3 d = pixelDirection(scene.camera, x, y);
            if (d.y >= 0.0) continue;
            const glm::dvec3 point = scene.camera.eye + d * (-scene.camera.eye.y / d.y);
            const std::optional<glm::dvec3> want = expected(point);
            if (!want) continue;
            for (int c = 0; c < 3; ++c) {
                const double got = image.at(x, y)[c];
                EXPECT_NEAR(got, (*want)[c], relative * std::abs((*want)[c]) + 1e-7)
                    << "pixel " << x << "," << y << " channel " << c;
            }
            ++compared;
        }
    }
    EXPECT_GT(compared, 300);
}

TEST_F(LensAndLights, DeltaSunLightsAPlaneAsEPerPiTimesCosine)
{
    const glm::dvec3 travel = glm::normalize(glm::dvec3(1, -2, 0.5));
    const glm::dvec3 irradiance(1.0, 2.0, 3.0);
    const std::string light = "type = \"directional\"\ndirection = [1, -2, 0.5]\nirradiance = [1, 2, 3]\n";
    expectPlaneRadiance(planeScene("whitted", light),
                        [&](const glm::dvec3&) -> std::optional<glm::dvec3> {
                            return kAlbedo / glm::pi<double>() * irradiance * -travel.y;
                        },
                        1e-5);
}

/// glTF KHR_lights_punctual's falloff, written from the specification.
double gltfSpotFalloff(double cosAngle, double innerDeg, double outerDeg)
{
    const double cosOuter = std::cos(glm::radians(outerDeg)), cosInner = std::cos(glm::radians(innerDeg));
    const double t = std::clamp((cosAngle - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
    return t * t;
}

TEST_F(LensAndLights, SpotLightFallsOffAsGltfSpecifies)
{
    const glm::dvec3 position(0.3, 1.5, -0.2), axis = glm::normalize(glm::dvec3(-0.2, -1, 0.1));
    const glm::dvec3 intensity(5.0, 6.0, 7.0);
    const std::string light = "type = \"spot\"\nposition = [0.3, 1.5, -0.2]\ndirection = [-0.2, -1, 0.1]\n"
                              "intensity = [5, 6, 7]\ninner_cone_angle = 15\nouter_cone_angle = 40\n";
    int inPenumbra = 0;
    expectPlaneRadiance(planeScene("whitted", light),
                        [&](const glm::dvec3& p) -> std::optional<glm::dvec3> {
                            const glm::dvec3 toPoint = p - position;
                            const double d2 = glm::dot(toPoint, toPoint);
                            const glm::dvec3 dir = toPoint / std::sqrt(d2);
                            const double falloff = gltfSpotFalloff(glm::dot(dir, axis), 15.0, 40.0);
                            inPenumbra += falloff > 0.05 && falloff < 0.95;
                            return kAlbedo / glm::pi<double>() * intensity * falloff * -dir.y / d2;
                        },
                        1e-4);
    EXPECT_GT(inPenumbra, 50) << "the test should see the falloff, not only its ends";
}

TEST_F(LensAndLights, SpotLightWithEqualConesHasAHardEdge)
{
    const glm::dvec3 position(0.0, 1.0, 0.0), axis(0, -1, 0);
    const std::string light = "type = \"spot\"\nposition = [0, 1, 0]\ndirection = [0, -1, 0]\n"
                              "intensity = 2\ninner_cone_angle = 30\nouter_cone_angle = 30\n";
    int lit = 0, dark = 0;
    expectPlaneRadiance(planeScene("whitted", light),
                        [&](const glm::dvec3& p) -> std::optional<glm::dvec3> {
                            const glm::dvec3 toPoint = p - position;
                            const double d2 = glm::dot(toPoint, toPoint);
                            const double cosAngle = glm::dot(toPoint / std::sqrt(d2), axis);
                            const double cosOuter = std::cos(glm::radians(30.0));
                            if (std::abs(cosAngle - cosOuter) < 1e-5) return std::nullopt; // float's edge
                            const bool inside = cosAngle >= cosOuter;
                            (inside ? lit : dark)++;
                            return glm::dvec3(inside ? kAlbedo / glm::pi<double>() * 2.0 * cosAngle / d2 : 0.0);
                        },
                        1e-4);
    EXPECT_GT(lit, 20);
    EXPECT_GT(dark, 20);
}

TEST_F(LensAndLights, SoftSunGivesTheIrradianceOfADeltaSunInBothIntegrators)
{
    // theta0 = 40 degrees from the plane's normal, a 5-degree-wide sun: the
    // cone stays above the horizon, so E cos(theta0) exactly.
    const double c = 0.766, s = 0.643; // about 40 degrees
    const std::string light = "type = \"directional\"\ndirection = [0, -0.766, -0.643]\nirradiance = 2\nangle = 5\n";
    const double cosTheta0 = c / std::hypot(c, s);
    const double expected = kAlbedo / glm::pi<double>() * 2.0 * cosTheta0;
    for (const char* integrator : {"whitted", "path"}) {
        // The camera looks straight down: every pixel sees the plane.
        std::string text = planeScene(integrator, light);
        text.replace(text.find("eye = [0, 2, 3]"), 15, "eye = [0, 2, 0]");
        text.replace(text.find("fov = 50"), 8, "fov = 20\nup = [0, 0, -1]");
        const Scene scene = sceneFromText(text);
        RenderOptions options = statisticalOptions(11);
        Renderer renderer(gpu(), scene, options);
        renderer.renderFrames(256);
        const double z = pooledZ(renderer.mean(), renderer.varianceOfMean(), 0, expected);
        reportStat(std::string("soft_sun_pooled_z_") + integrator, z);
        EXPECT_LT(std::abs(z), 4.0) << integrator << ": mean " << channelMean(renderer.mean(), 0) << ", expected "
                                    << expected;
    }
}

// ---------------------------------------------------------------- thin lens

/// The fraction of a disk of radius r left of the line x = c (the circular
/// segment's area over the disk's).
double diskFractionLeftOf(double c, double r)
{
    const double t = std::clamp(c / r, -1.0, 1.0);
    return (t * std::sqrt(1.0 - t * t) + std::asin(t)) / glm::pi<double>() + 0.5;
}

constexpr double kFocus = 2.0, kAperture = 0.2;

/// A camera at the origin looking down -z at an emitting half-plane x > 0 at
/// depth `depth` (two triangle lights), focused at kFocus.
std::string halfPlaneScene(double depth)
{
    const std::string z = std::to_string(-depth);
    return "[render]\nintegrator = \"whitted\"\nmax_depth = 1\n"
           "[camera]\neye = [0, 0, 0]\ntarget = [0, 0, -1]\nfov = 2\nwidth = 64\nheight = 4\n"
           "aperture_radius = 0.2\nfocus_distance = 2\n"
           "[[lights]]\ntype = \"triangle\"\ntwo_sided = true\nradiance = 1\nvertices = [[0, -100, " +
           z + "], [100, -100, " + z + "], [100, 100, " + z +
           "]]\n"
           "[[lights]]\ntype = \"triangle\"\ntwo_sided = true\nradiance = 1\nvertices = [[0, -100, " +
           z + "], [100, 100, " + z + "], [0, 100, " + z + "]]\n";
}

/// The x of pixel column `x`'s centre on the plane in focus.
double focusPlaneX(const Camera& c, uint32_t x)
{
    const double halfWidth = std::tan(glm::radians(c.fovY) / 2.0) * c.width / c.height;
    return (2.0 * (x + 0.5) / c.width - 1.0) * halfWidth * kFocus;
}

TEST_F(LensAndLights, ThinLensBlursAnEdgeIntoACircularSegment)
{
    // A lens point o sees the point p of the focus plane through the emitter
    // plane at depth Z at x = p.x Z / f + o.x (1 - Z / f): lit where
    // o.x < c = p.x Z / (Z - f), a fraction F(c) of the lens disk.
    const double depth = 6.0;
    const Scene scene = sceneFromText(halfPlaneScene(depth));
    RenderOptions options = pixelCentreOptions();
    options.seed = 3;
    Renderer renderer(gpu(), scene, options);
    const uint32_t spp = 2048;
    renderer.renderFrames(spp);
    const Image image = renderer.mean();
    const double zLimit = 4.5; // two-sided, Sidak over 256 values at alpha = 0.01 is 3.9
    int partial = 0;
    for (uint32_t y = 0; y < image.height; ++y) {
        for (uint32_t x = 0; x < image.width; ++x) {
            const double c = focusPlaneX(scene.camera, x) * depth / (depth - kFocus);
            const double f = diskFractionLeftOf(c, kAperture);
            const double got = image.at(x, y)[0];
            partial += f > 0.02 && f < 0.98;
            const double sigma = std::sqrt(std::max(f * (1.0 - f), 1e-12) / spp);
            if (f == 0.0 || f == 1.0) EXPECT_EQ(got, f) << "pixel " << x;
            else EXPECT_LT(std::abs(got - f) / sigma, zLimit) << "pixel " << x << ": " << got << " vs " << f;
        }
    }
    EXPECT_GT(partial, 4 * 8) << "the blur should span several columns";
}

TEST_F(LensAndLights, ThinLensKeepsThePlaneInFocusSharp)
{
    const Scene scene = sceneFromText(halfPlaneScene(kFocus));
    RenderOptions options = pixelCentreOptions();
    Renderer renderer(gpu(), scene, options);
    renderer.renderFrames(64);
    const Image image = renderer.mean();
    for (uint32_t y = 0; y < image.height; ++y) {
        for (uint32_t x = 0; x < image.width; ++x) {
            const double px = focusPlaneX(scene.camera, x);
            if (std::abs(px) < 1e-4) continue;
            EXPECT_NEAR(image.at(x, y)[0], px > 0 ? 1.0 : 0.0, 1e-6) << "pixel " << x;
        }
    }
}

} // namespace
} // namespace vkrt::test
