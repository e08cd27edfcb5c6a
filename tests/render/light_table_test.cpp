// The light table on the device (lib/lights.glsl, VKRT_LIGHT_TABLE): a scene
// with more lights than the kernel tests one by one must render what the
// same light, gathered into few lights that the kernel does test one by one,
// renders:
// - 250 point lights at one point against one of 250 times the intensity
//   (Whitted, pixel centres): equal to float rounding, since every candidate
//   of the resampling is the same light (each weighs in as 1 / its
//   density), and at a per-sample cost that does not grow with the lights;
// - in both integrators, each light kind (an emitting triangle, a soft and a
//   delta sun, a spot) beside 9 point lights at one place (the table) against
//   the same kind beside one point light of their sum (one by one): per-pixel
//   Welch z, Sidak-corrected, and the whole image's. The soft sun and the
//   emitter are also found by BSDF sampling in the path integrator, so their
//   MIS weights must use the table's density.
// The host's rules are in render/light_table_rule_test.cpp.
#include "render/ErrorMetrics.h"
#include "render/Renderer.h"
#include "support/ChiSquare.h"
#include "support/ManyLightsScene.h"
#include "support/TestSupport.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

namespace vkrt::test {
namespace {

class LightTable : public GpuTest {};

TEST_F(LightTable, ManyLightsAtOnePointLightAsOneOfTheirSum)
{
    Renderer many(gpu(), sceneFromText(manyLightsScene(2, 250, 1.0), "many.toml"), pixelCentreOptions());
    ASSERT_NE(many.variant().describe().find("light-table"), std::string::npos) << many.variant().describe();
    many.renderFrames(1);
    Renderer one(gpu(), sceneFromText(manyLightsScene(2, 1, 250.0), "one.toml"), pixelCentreOptions());
    ASSERT_EQ(one.variant().describe().find("light-table"), std::string::npos) << one.variant().describe();
    one.renderFrames(1);
    const Image image = many.mean(), expected = one.mean();
    ASSERT_GT(channelMean(expected, 0), 0.01);
    for (size_t i = 0; i < image.rgb.size(); ++i)
        ASSERT_NEAR(image.rgb[i], expected.rgb[i], 1e-5 * expected.rgb[i] + 1e-7) << "value " << i;
    // One by one, 250 lights would take 250 loop passes and shadow queries of
    // three primitives each; the table takes its candidates' and one query.
    EXPECT_LT(many.counters().maxLoopIterations, 250u);
    reportStat("light_table_loop_passes", many.counters().maxLoopIterations);
    reportStat("one_light_loop_passes", one.counters().maxLoopIterations);
}

/// One light of a kind (the one under test) and a point light of intensity
/// 2, around a Lambert box in the corner of two walls. `split` spreads the
/// point light over 9 at one place, which puts every light into the table.
/// The tested light gives most of the light, so a wrong density of its own
/// (or a wrong MIS weight where BSDF sampling finds it too) shows.
std::string oneKindScene(const std::string& integrator, const std::string& light, bool split)
{
    std::string text = "[render]\nintegrator = \"" + integrator +
                       "\"\nmax_depth = 3\n[camera]\neye = [0, 2.5, 5]\ntarget = [0, 0.5, 0]\nfov = 45\n"
                       "width = 20\nheight = 16\n[background]\ncolor = [0, 0, 0]\n"
                       "[materials.m]\ntype = \"lambert\"\nalbedo = [0.7, 0.6, 0.5]\n"
                       "[[objects]]\nshape = \"box\"\nmin = [-3, -0.1, -3]\nmax = [3, 0, 3]\nmaterial = \"m\"\n"
                       "[[objects]]\nshape = \"box\"\nmin = [-3, 0, -1.6]\nmax = [3, 3, -1.5]\nmaterial = \"m\"\n"
                       "[[objects]]\nshape = \"box\"\nmin = [-0.5, 0, -0.5]\nmax = [0.5, 1, 0.5]\nmaterial = \"m\"\n" +
                       light;
    const int points = split ? 9 : 1;
    for (int i = 0; i < points; ++i)
        text += "[[lights]]\ntype = \"point\"\nposition = [1.2, 1.8, -1]\nintensity = " + std::to_string(2.0 / points) +
                "\n";
    return text;
}

struct TestedLight {
    std::string name, toml;
};

const TestedLight kTestedLights[] = {
    // One emitter: the table's last entry, its density scaled by the host.
    {"emitter", "[[lights]]\ntype = \"triangle\"\nvertices = [[-1.5, 2.5, -1], [-1.5, 2.5, 0.5], [0, 2.5, -1]]\n"
                "radiance = 8\n"},
    // A wide cone, whose density is near the Lambert BSDF's: its MIS weights matter.
    // A delta sun before it, so that the soft one is moved first.
    {"soft-sun", "[[lights]]\ntype = \"directional\"\ndirection = [-0.5, -1, -0.3]\nirradiance = 0.2\n"
                 "[[lights]]\ntype = \"directional\"\ndirection = [0.6, -1, -0.5]\nirradiance = [1.2, 1, 0.8]\n"
                 "angle = 60\n"},
    {"delta-sun", "[[lights]]\ntype = \"directional\"\ndirection = [0.6, -1, -0.5]\nirradiance = [1.2, 1, 0.8]\n"},
    {"spot", "[[lights]]\ntype = \"spot\"\nposition = [0.5, 2.5, 1]\ndirection = [-0.3, -1, -0.4]\n"
             "intensity = [8, 6, 4]\ninner_cone_angle = 15\nouter_cone_angle = 35\n"},
};

TEST_F(LightTable, EachKindFromTheTableRendersAsItDoesOneByOne)
{
    uint32_t seed = 40;
    for (const std::string integrator : {"whitted", "path"}) {
        for (const TestedLight& light : kTestedLights) {
            SCOPED_TRACE(integrator + " " + light.name);
            Renderer table(gpu(), sceneFromText(oneKindScene(integrator, light.toml, true), "table.toml"),
                           statisticalOptions(++seed));
            Renderer direct(gpu(), sceneFromText(oneKindScene(integrator, light.toml, false), "direct.toml"),
                            statisticalOptions(++seed));
            ASSERT_NE(table.variant().describe().find("light-table"), std::string::npos);
            ASSERT_EQ(direct.variant().describe().find("light-table"), std::string::npos);
            table.renderFrames(512);
            direct.renderFrames(512);
            const Image ma = table.mean(), mb = direct.mean(), va = table.varianceOfMean(),
                        vb = direct.varianceOfMean();
            // The whole image's z per channel: a pixel's channels come from
            // one path and are correlated, so they are not summed together.
            std::array<double, 3> difference{}, variance{};
            double largest = 0.0;
            int tests = 0;
            for (size_t i = 0; i < ma.rgb.size(); ++i) {
                const double v = double(va.rgb[i]) + vb.rgb[i];
                difference[i % 3] += double(ma.rgb[i]) - mb.rgb[i];
                variance[i % 3] += v;
                if (v > 0.0) {
                    largest = std::max(largest, std::abs(double(ma.rgb[i]) - mb.rgb[i]) / std::sqrt(v));
                    ++tests;
                } else {
                    EXPECT_EQ(ma.rgb[i], mb.rgb[i]) << "value " << i << " has no variance in either";
                }
            }
            // Family-wise alpha 1e-3 over every pixel channel of every case.
            const double limit = normalQuantileTwoSided(sidakCorrectedAlpha(1e-3, tests * 8));
            reportStat("light_table_" + integrator + "_" + light.name + "_largest_z", largest);
            EXPECT_LT(largest, limit) << tests << " tests";
            for (int c = 0; c < 3; ++c) {
                const double whole = difference[c] / std::sqrt(variance[c]);
                reportStat("light_table_" + integrator + "_" + light.name + "_image_z" + std::to_string(c), whole);
                EXPECT_LT(std::abs(whole), normalQuantileTwoSided(sidakCorrectedAlpha(1e-3, 8 * 3))) << "channel " << c;
            }
        }
    }
}

} // namespace
} // namespace vkrt::test
