// Arbitrary output values (`vkrt render --aov`): the albedo and normal of the
// first non-specular surface (through a mirror), the first hit's depth and
// position, what an escaping ray leaves, that asking for AOVs changes no
// pixel of the image, and the EXR layers the command writes.
#include "io/ExrFile.h"
#include "render/Renderer.h"
#include "support/TestSupport.h"

#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

namespace vkrt::test {
namespace {

namespace fs = std::filesystem;

class Aov : public GpuTest {};

RenderOptions aovOptions()
{
    RenderOptions options = pixelCentreOptions();
    options.aov = true;
    return options;
}

// A camera at z = 5 looking down -z at a green plane z = 0 that fills the
// left half of the view (a box), and nothing on the right.
const std::string kHalfPlane = "[render]\nintegrator = \"whitted\"\nmax_depth = 3\n"
                               "[camera]\neye = [0.2, 0.1, 5]\ntarget = [0.2, 0.1, 0]\nfov = 30\nwidth = 16\nheight = 12\n"
                               "[materials.green]\ntype = \"lambert\"\nalbedo = [0.1, 0.7, 0.2]\n"
                               "[[objects]]\nshape = \"box\"\nmaterial = \"green\"\nmin = [-10, -10, -1]\n"
                               "max = [0.2, 10, 0]\n"
                               "[[lights]]\ntype = \"point\"\nposition = [0, 0, 4]\nintensity = 10\n";

TEST_F(Aov, FirstSurfaceAlbedoNormalDepthAndPositionAndEscapes)
{
    const Scene scene = sceneFromText(kHalfPlane);
    Renderer renderer(gpu(), scene, aovOptions());
    renderer.renderFrames(4);
    const AovImages aovs = renderer.aovs();
    const Camera& c = scene.camera;
    const double halfHeight = std::tan(glm::radians(c.fovY) / 2.0), halfWidth = halfHeight * c.width / c.height;
    int onPlane = 0, escaped = 0;
    for (uint32_t y = 0; y < c.height; ++y) {
        for (uint32_t x = 0; x < c.width; ++x) {
            const size_t i = size_t(y) * c.width + x;
            const double ndcX = 2.0 * (x + 0.5) / c.width - 1.0, ndcY = 1.0 - 2.0 * (y + 0.5) / c.height;
            const glm::dvec3 point = c.eye + 5.0 * glm::dvec3(ndcX * halfWidth, ndcY * halfHeight, -1.0);
            if (point.x < 0.2) {
                ++onPlane;
                EXPECT_FLOAT_EQ(aovs.albedo.rgb[i * 3 + 1], 0.7f) << x << "," << y;
                EXPECT_FLOAT_EQ(aovs.normal.rgb[i * 3 + 2], 1.0f) << x << "," << y;
                EXPECT_NEAR(aovs.depth[i], 5.0, 1e-5) << x << "," << y;
                for (int k = 0; k < 3; ++k) EXPECT_NEAR(aovs.position.rgb[i * 3 + k], point[k], 1e-5) << x << "," << y;
            } else {
                ++escaped;
                EXPECT_EQ(aovs.albedo.rgb[i * 3 + 1], 0.0f);
                EXPECT_EQ(aovs.normal.rgb[i * 3 + 2], 0.0f);
                EXPECT_TRUE(std::isinf(aovs.depth[i]));
                EXPECT_EQ(aovs.position.rgb[i * 3], 0.0f);
            }
        }
    }
    EXPECT_GT(onPlane, 40);
    EXPECT_GT(escaped, 40);
}

TEST_F(Aov, AlbedoAndNormalAreThoseSeenThroughAMirror)
{
    // A mirror plane at z = 0 facing the camera reflects a red box behind the
    // camera's eye: the albedo is the box's, the normal the box's face (+z
    // seen from the mirror side, i.e. facing the mirror: -z), and the depth
    // the mirror's.
    const std::string text = "[render]\nintegrator = \"path\"\nmax_depth = 3\n"
                             "[camera]\neye = [0, 0, 2]\ntarget = [0, 0, 0]\nfov = 10\nwidth = 8\nheight = 8\n"
                             "[materials.mirror]\ntype = \"mirror\"\n"
                             "[materials.red]\ntype = \"lambert\"\nalbedo = [0.8, 0.1, 0.1]\n"
                             "[[objects]]\nshape = \"plane\"\nmaterial = \"mirror\"\npoint = [0, 0, 0]\n"
                             "normal = [0, 0, 1]\n"
                             "[[objects]]\nshape = \"box\"\nmaterial = \"red\"\nmin = [-5, -5, 6]\nmax = [5, 5, 7]\n";
    const Scene scene = sceneFromText(text);
    Renderer renderer(gpu(), scene, aovOptions());
    renderer.renderFrames(2);
    const AovImages aovs = renderer.aovs();
    for (size_t i = 0; i < aovs.albedo.pixelCount(); ++i) {
        EXPECT_FLOAT_EQ(aovs.albedo.rgb[i * 3], 0.8f) << i;
        EXPECT_FLOAT_EQ(aovs.normal.rgb[i * 3 + 2], -1.0f) << i;
        EXPECT_NEAR(aovs.depth[i], 2.0, 1e-5) << i;
    }
}

TEST_F(Aov, AskingForAovsChangesNoPixelOfTheImage)
{
    for (const char* integrator : {"whitted", "path"}) {
        std::string text = kHalfPlane;
        text.replace(text.find("whitted"), 7, integrator);
        const Scene scene = sceneFromText(text);
        RenderOptions plain = pixelCentreOptions();
        plain.jitter = true;
        plain.seed = 4;
        RenderOptions withAovs = plain;
        withAovs.aov = true;
        Renderer a(gpu(), scene, plain), b(gpu(), scene, withAovs);
        EXPECT_EQ(a.variant().describe().find("aov"), std::string::npos);
        EXPECT_NE(b.variant().describe().find("aov"), std::string::npos);
        a.renderFrames(16);
        b.renderFrames(16);
        const Image ia = a.mean(), ib = b.mean();
        ASSERT_EQ(ia.rgb.size(), ib.rgb.size());
        EXPECT_EQ(std::memcmp(ia.rgb.data(), ib.rgb.data(), ia.rgb.size() * sizeof(float)), 0) << integrator;
    }
}

TEST_F(Aov, RenderWritesCompositorLayersAndRefusesBadNames)
{
    const fs::path dir = freshTempDir("aov-cli");
    writeText(dir / "scene.toml", kHalfPlane);
    const std::string exr = (dir / "out.exr").string();
    const ProcessResult ok = runVkrt({"render", (dir / "scene.toml").string(), "-o", exr, "--spp", "2", "--aov",
                                      "albedo,normal,depth,position"});
    ASSERT_EQ(ok.exitCode, 0) << ok.output;
    Imf::InputFile file(exr.c_str());
    for (const char* name : {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B", "N.X", "N.Y", "N.Z", "Z", "P.X",
                             "P.Y", "P.Z"})
        EXPECT_NE(file.header().channels().findChannel(name), nullptr) << name;
    const ExrContents contents = readExr(exr); // vkrt's reader skips what is not R, G, B
    EXPECT_EQ(contents.layers.count("albedo"), 1u);
    EXPECT_EQ(std::get<std::string>(contents.metadata.at("aovs")), "albedo,normal,depth,position");

    const ProcessResult bad = runVkrt({"render", (dir / "scene.toml").string(), "-o", exr, "--aov", "albdeo"});
    EXPECT_EQ(bad.exitCode, 2);
    EXPECT_NE(bad.output.find("--aov: unknown AOV 'albdeo'; did you mean 'albedo'?"), std::string::npos) << bad.output;
    const ProcessResult shard =
        runVkrt({"render", (dir / "scene.toml").string(), "-o", exr, "--aov", "depth", "--shard", "0/2"});
    EXPECT_EQ(shard.exitCode, 2);
    EXPECT_NE(shard.output.find("--aov cannot be combined with --shard"), std::string::npos) << shard.output;
}

} // namespace
} // namespace vkrt::test
