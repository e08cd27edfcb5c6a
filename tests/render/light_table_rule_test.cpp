// The light table's rules on the host (render/LightTable.h), without a
// device: when a scene gets it, each entry's power against closed forms and
// numerical integration written here, the table's probabilities, the
// emitters' densities scaled for the candidates, the soft suns first, and a
// per-sample cost that no longer grows with the lights (the loop budget).
// The kernel's side is render/light_table_test.cpp.
#include "render/GpuScene.h"
#include "render/LightTable.h"
#include "render/Renderer.h"
#include "scene/FeatureSet.h"
#include "support/ManyLightsScene.h"
#include "support/TestSupport.h"

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <string>

namespace vkrt::test {
namespace {

constexpr double kPi = glm::pi<double>();

std::string litPlane(const std::string& lights)
{
    return "[render]\nintegrator = \"path\"\n[camera]\neye = [0, 2, 4]\ntarget = [0, 0, 0]\nfov = 40\n"
           "width = 8\nheight = 8\n[materials.m]\ntype = \"lambert\"\n"
           "[[objects]]\nshape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 3\nmaterial = \"m\"\n" +
           lights;
}

std::string pointLights(int count, double intensity)
{
    std::string text;
    for (int i = 0; i < count; ++i)
        text += "[[lights]]\ntype = \"point\"\nposition = [0, 4, " + std::to_string(i) +
                "]\nintensity = " + std::to_string(intensity) + "\n";
    return text;
}

TEST(LightTableRule, OnlyMoreLightsThanTheKernelTestsOneByOneGetTheTable)
{
    const Scene eight = sceneFromText(litPlane(pointLights(int(kMaxEnumeratedLights), 1.0)));
    const Scene nine = sceneFromText(litPlane(pointLights(int(kMaxEnumeratedLights) + 1, 1.0)));
    EXPECT_FALSE(featuresOf(eight).lightTable);
    EXPECT_TRUE(featuresOf(nine).lightTable);
    EXPECT_TRUE(convertScene(eight, {}, prepareStaticScene(eight)).lightTable.empty());
    const GpuSceneData data = convertScene(nine, {}, prepareStaticScene(nine));
    ASSERT_EQ(data.lightTable.size(), kMaxEnumeratedLights + 1);
    EXPECT_EQ(data.uniforms.lightTableCount, kMaxEnumeratedLights + 1);
    EXPECT_EQ(data.uniforms.lightCandidates, kLightTableCandidates);
    // Equal lights: equal probabilities, summing to one.
    for (const gpu::LightPick& pick : data.lightTable) EXPECT_NEAR(pick.pdf, 1.0 / 9.0, 1e-7);
}

TEST(LightTableRule, EntriesArePointsThenSunsThenSpotsThenTheEmittersInProportionToPower)
{
    // Registry order: point, (triangle: none), directional, spot; then all emitters.
    const std::string lights =
        pointLights(3, 2.0) +
        "[[lights]]\ntype = \"directional\"\ndirection = [0, -1, 0]\nirradiance = 1.5\n"
        "[[lights]]\ntype = \"directional\"\ndirection = [0, -1, 0.2]\nirradiance = [1, 2, 3]\nangle = 10\n"
        "[[lights]]\ntype = \"spot\"\nposition = [0, 4, 0]\ndirection = [0, -1, 0]\nintensity = 5\n"
        "inner_cone_angle = 30\nouter_cone_angle = 30\n"
        "[[lights]]\ntype = \"spot\"\nposition = [0, 4, 1]\ndirection = [0, -1, 0]\nintensity = 5\n"
        "inner_cone_angle = 10\nouter_cone_angle = 40\n"
        "[[lights]]\ntype = \"triangle\"\nvertices = [[0, 5, 0], [1, 5, 0], [0, 5, 1]]\nradiance = 4\n"
        "[[lights]]\ntype = \"point\"\nposition = [0, 4, 9]\nintensity = [0, 0, 0]\n"
        "[[lights]]\ntype = \"point\"\nposition = [0, 4, 9]\nintensity = [3, 0, 0]\n";
    const Scene scene = sceneFromText(litPlane(lights));
    ASSERT_TRUE(usesLightTable(scene));
    const GpuSceneStatic fixed = prepareStaticScene(scene);
    const GpuSceneData data = convertScene(scene, {}, fixed);
    const double radius = sceneBoundingRadius(scene);
    // The sphere of radius 3 at the origin, the eye at (0, 2, 4), the lights up to z = 9.
    EXPECT_GT(radius, 4.0);
    std::vector<double> expected;
    for (double intensity : {2.0, 2.0, 2.0, 0.0, 1.0}) expected.push_back(4.0 * kPi * intensity);
    expected.push_back(1.5 * kPi * radius * radius); // a delta sun: its irradiance on the disc
    expected.push_back(2.0 * kPi * radius * radius); // a soft sun: the mean irradiance it was given
    expected.push_back(2.0 * kPi * (1.0 - std::cos(glm::radians(30.0))) * 5.0); // a hard-edged cap
    // The falloff t^2 over the sphere, integrated numerically.
    const double cosOuter = std::cos(glm::radians(40.0)), cosInner = std::cos(glm::radians(10.0));
    double falloff = 0.0;
    const int steps = 200000;
    for (int k = 0; k < steps; ++k) {
        const double c = cosOuter + (1.0 - cosOuter) * (k + 0.5) / steps;
        const double t = std::clamp((c - cosOuter) / (cosInner - cosOuter), 0.0, 1.0);
        falloff += t * t * (1.0 - cosOuter) / steps;
    }
    expected.push_back(2.0 * kPi * falloff * 5.0);
    expected.push_back(4.0 * 0.5 * 1.0 * kPi); // the emitter: radiance x area x pi, one-sided
    // The scene's points go first, then the suns (soft first), then the spots.
    const std::vector<double> order{expected[0], expected[1], expected[2], expected[3], expected[4],
                                    expected[6], expected[5], expected[7], expected[8], expected[9]};
    const std::vector<double> powers = lightTablePowers(data, fixed.emitters.totalPower, radius);
    ASSERT_EQ(powers.size(), order.size());
    for (size_t i = 0; i < powers.size(); ++i) EXPECT_NEAR(powers[i], order[i], 1e-5 * order[i]) << "entry " << i;
    const double total = std::accumulate(order.begin(), order.end(), 0.0);
    ASSERT_EQ(data.lightTable.size(), order.size());
    double sum = 0.0;
    for (size_t i = 0; i < order.size(); ++i) {
        EXPECT_NEAR(data.lightTable[i].pdf, order[i] / total, 1e-6) << "entry " << i;
        sum += data.lightTable[i].pdf;
    }
    EXPECT_NEAR(sum, 1.0, 1e-6);
    // The emitter's density: the candidates times its entry's probability (it is the only emitter).
    ASSERT_EQ(data.emitters.size(), 1u);
    EXPECT_NEAR(data.emitters[0].pdf, kLightTableCandidates * order.back() / total, 1e-6);
}

TEST(LightTableRule, SoftSunsComeFirstInTheirOrder)
{
    std::string lights;
    const double angles[] = {0.0, 5.0, 0.0, 7.0, 0.0};
    for (int i = 0; i < 5; ++i)
        lights += "[[lights]]\ntype = \"directional\"\ndirection = [0, -1, 0]\nirradiance = " + std::to_string(i + 1) +
                  "\nangle = " + std::to_string(angles[i]) + "\n";
    const Scene scene = sceneFromText(litPlane(lights));
    const GpuSceneData data = convertScene(scene, {}, prepareStaticScene(scene));
    EXPECT_EQ(data.uniforms.softDirectionalLightCount, 2u);
    ASSERT_EQ(data.directionalLights.size(), 5u);
    // Soft suns 2 and 4 (irradiance 2 and 4), then delta suns 1, 3, 5.
    const float irradiance[] = {2.0f, 4.0f, 1.0f, 3.0f, 5.0f};
    for (int i = 0; i < 2; ++i) EXPECT_GT(data.directionalLights[i].oneMinusCos, 0.0f) << i;
    for (int i = 2; i < 5; ++i) {
        EXPECT_EQ(data.directionalLights[i].oneMinusCos, 0.0f) << i;
        EXPECT_FLOAT_EQ(data.directionalLights[i].radiance.r, irradiance[i]) << i;
    }
}

TEST(LightTableRule, ASampleCostsNoMoreLoopPassesWithThousandsOfLights)
{
    // One by one, each light is a loop pass and a shadow query over every
    // primitive; from the table, the candidates are, however many lights.
    const uint64_t eight = worstCaseLoopIterations(sceneFromText(manyLightsScene(300, 8, 1.0)));
    const uint64_t thousands = worstCaseLoopIterations(sceneFromText(manyLightsScene(300, 5000, 1.0)));
    EXPECT_LE(thousands, eight + uint64_t(kLightTableCandidates) * 302);
    EXPECT_LT(thousands, uint64_t(5000));
}

TEST(LightTableRule, LightsOfNoPowerAreNeverDrawn)
{
    const Scene scene = sceneFromText(litPlane(pointLights(12, 0.0)));
    const GpuSceneData data = convertScene(scene, {}, prepareStaticScene(scene));
    ASSERT_EQ(data.lightTable.size(), 12u);
    for (const gpu::LightPick& pick : data.lightTable) EXPECT_EQ(pick.pdf, 0.0f);
}

} // namespace
} // namespace vkrt::test
