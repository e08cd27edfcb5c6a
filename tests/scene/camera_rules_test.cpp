// The scene parser and the checks on overrides (--width, a suite case's size,
// the viewer's camera moves) apply one set of camera rules. The parser ends
// with cameraProblem(), so it never accepts a camera the overrides refuse;
// this test checks the other direction: over a grid of valid and invalid
// cameras, cameraProblem() refuses every camera the parser's own field checks
// refuse, so an override can never make a camera a scene file could not.
#include "scene/SceneOverrides.h"
#include "scene/SceneParser.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <limits>

namespace vkrt {
namespace {

std::string number(double value)
{
    if (std::isnan(value)) return "nan";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    char text[64];
    auto result = std::to_chars(text, text + sizeof text, value);
    std::string out(text, result.ptr);
    // TOML needs a fraction or exponent for a float; plain integers read as integers.
    return out.find_first_of(".en") == std::string::npos ? out + ".0" : out;
}

std::string vector(const glm::dvec3& v) { return "[" + number(v.x) + ", " + number(v.y) + ", " + number(v.z) + "]"; }

std::string cameraScene(const Camera& c)
{
    return "[camera]\neye = " + vector(c.eye) + "\ntarget = " + vector(c.target) + "\nup = " + vector(c.up) +
           "\nfov = " + number(c.fovY) + "\nwidth = " + std::to_string(c.width) +
           "\nheight = " + std::to_string(c.height) + "\n";
}

TEST(CameraRules, ParserAcceptsExactlyTheCamerasOverridesAccept)
{
    const double inf = std::numeric_limits<double>::infinity();
    const glm::dvec3 eyes[] = {{0, 0, 0}, {1e300, 0, 0}, {0, 0, 1e-300}, {inf, 0, 0}};
    const glm::dvec3 targets[] = {{0, 0, -1}, {0, 0, 0}, {-1e300, 0, 0}, {0, 1, 0}};
    const glm::dvec3 ups[] = {{0, 1, 0}, {0, 0, 0}, {0, 0, 1}, {1e-7, 1, 0}, {0, 1e-300, 0}};
    const double fovs[] = {45, 0, 180, 1e-9, 179.999, -3};
    const std::pair<uint32_t, uint32_t> sizes[] = {{64, 48}, {0, 8}, {16384, 4096}, {16385, 1}, {16384, 4097}};
    int accepted = 0, refused = 0;
    for (const auto& eye : eyes)
        for (const auto& target : targets)
            for (const auto& up : ups)
                for (double fov : fovs)
                    for (auto [width, height] : sizes) {
                        Camera camera{eye, target, up, fov, width, height};
                        std::optional<std::string> problem = cameraProblem(camera);
                        std::string text = cameraScene(camera);
                        bool parsed = true;
                        std::string message;
                        try {
                            parseSceneString(text, "camera.toml");
                        } catch (const SceneError& e) {
                            parsed = false;
                            message = e.what();
                        }
                        ASSERT_EQ(parsed, !problem.has_value()) << text << "parser: " << (parsed ? "accepted" : message)
                                                                << "\ncameraProblem: " << problem.value_or("none");
                        (parsed ? accepted : refused)++;
                    }
    EXPECT_GT(accepted, 50);
    EXPECT_GT(refused, 1000);
}

} // namespace
} // namespace vkrt
