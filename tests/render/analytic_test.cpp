// Deterministic renders checked against closed-form radiance computed here in
// double precision, independently of the renderer's own camera code.
#include "render/Renderer.h"
#include "support/TestSupport.h"

#include <cmath>

namespace vkrt::test {
namespace {

/// Direction of the ray through the centre of pixel (x, y) for a pinhole camera.
glm::dvec3 pixelCentreRay(const Camera& c, uint32_t x, uint32_t y)
{
    glm::dvec3 forward = glm::normalize(c.target - c.eye);
    glm::dvec3 right = glm::normalize(glm::cross(forward, c.up));
    glm::dvec3 up = glm::cross(right, forward);
    double tanHalf = std::tan(c.fovY * M_PI / 360.0);
    double sx = (2.0 * (x + 0.5) / c.width - 1.0) * tanHalf * c.width / c.height;
    double sy = (1.0 - 2.0 * (y + 0.5) / c.height) * tanHalf;
    return glm::normalize(sx * right + sy * up + forward);
}

// max_depth = 1: direct light only, so the closed forms below hold exactly.
const char* kLambertPlaneScene = R"(
[render]
max_depth = 1
[camera]
eye = [0.3, 2.0, 3.0]
target = [0.0, 0.0, -0.5]
fov = 50
width = 48
height = 36
[materials.grey]
type = "lambert"
albedo = [0.5, 0.25, 0.8]
[[objects]]
shape = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "grey"
[[lights]]
type = "point"
position = [0.5, 1.5, -1.0]
intensity = [10, 20, 5]
)";

class AnalyticTest : public GpuTest {};

// L = rho * I * cos(theta) / (pi * d^2) for a point light over a Lambert plane.
TEST_F(AnalyticTest, PointLightOverLambertPlaneMatchesClosedForm)
{
    Scene scene = sceneFromText(kLambertPlaneScene);
    Renderer renderer(gpu(), scene, pixelCentreOptions());
    renderer.renderFrames(1);
    Image image = renderer.mean();
    const glm::dvec3 rho(0.5, 0.25, 0.8), intensity(10, 20, 5), light(0.5, 1.5, -1.0);
    int checked = 0;
    double worst = 0.0;
    for (uint32_t y = 0; y < image.height; ++y) {
        for (uint32_t x = 0; x < image.width; ++x) {
            glm::dvec3 dir = pixelCentreRay(scene.camera, x, y);
            ASSERT_LT(dir.y, 0.0) << "every pixel must see the plane";
            glm::dvec3 p = scene.camera.eye + (-scene.camera.eye.y / dir.y) * dir;
            glm::dvec3 toLight = light - p;
            double d2 = glm::dot(toLight, toLight);
            double cosTheta = toLight.y / std::sqrt(d2);
            for (int c = 0; c < 3; ++c) {
                double expected = rho[c] * intensity[c] * cosTheta / (M_PI * d2);
                double relative = std::abs(image.at(x, y)[c] - expected) / expected;
                worst = std::max(worst, relative);
                ++checked;
            }
        }
    }
    EXPECT_EQ(checked, 48 * 36 * 3);
    EXPECT_LT(worst, 1e-4) << "worst relative error over all pixels";
}

// A light below the plane lights only its underside: the camera above sees black.
TEST_F(AnalyticTest, LightBehindSurfaceGivesNoRadiance)
{
    std::string text = kLambertPlaneScene;
    text.replace(text.find("position = [0.5, 1.5, -1.0]"), 27, "position = [0.5, -1.5, -1.0]");
    Renderer renderer(gpu(), sceneFromText(text), pixelCentreOptions());
    renderer.renderFrames(1);
    Image image = renderer.mean();
    for (float v : image.rgb) ASSERT_EQ(v, 0.0f);
}

// A sphere between the light and the plane casts a shadow exactly where the
// segment from the surface point to the light passes through the sphere.
TEST_F(AnalyticTest, HardShadowFollowsGeometry)
{
    // Appended rather than `std::string(...) + "..."`: GCC 14 reports a false
    // -Warray-bounds in the inlined rvalue operator+ at -O2.
    std::string text = kLambertPlaneScene;
    text += R"(
[[objects]]
shape = "sphere"
center = [0.35, 0.75, -0.6]
radius = 0.3
material = "grey"
)";
    Scene scene = sceneFromText(text);
    Renderer renderer(gpu(), scene, pixelCentreOptions());
    renderer.renderFrames(1);
    Image image = renderer.mean();
    const glm::dvec3 light(0.5, 1.5, -1.0), centre(0.35, 0.75, -0.6);
    int shadowed = 0, lit = 0;
    for (uint32_t y = 0; y < image.height; ++y) {
        for (uint32_t x = 0; x < image.width; ++x) {
            glm::dvec3 dir = pixelCentreRay(scene.camera, x, y);
            // Skip pixels that see the sphere itself.
            glm::dvec3 oc = scene.camera.eye - centre;
            double b = glm::dot(oc, dir), c = glm::dot(oc, oc) - 0.09;
            if (b * b - c > -1e-3) continue;
            glm::dvec3 p = scene.camera.eye + (-scene.camera.eye.y / dir.y) * dir;
            glm::dvec3 seg = glm::normalize(light - p);
            glm::dvec3 pc = p - centre;
            double bb = glm::dot(pc, seg), cc = glm::dot(pc, pc) - 0.09;
            double disc = bb * bb - cc;
            if (std::abs(disc) < 2e-3) continue; // penumbra-free but keep clear of the exact edge
            bool blocked = disc > 0 && -bb - std::sqrt(disc) > 0;
            if (blocked) {
                ++shadowed;
                EXPECT_EQ(image.at(x, y)[0], 0.0f) << x << "," << y;
            } else {
                ++lit;
                EXPECT_GT(image.at(x, y)[0], 0.0f) << x << "," << y;
            }
        }
    }
    EXPECT_GT(shadowed, 10);
    EXPECT_GT(lit, 100);
}

} // namespace
} // namespace vkrt::test
