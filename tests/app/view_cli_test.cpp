// The progressive viewer under a real X display (Xvfb): its screenshot
// matches `vkrt render`, scripted camera moves reset the accumulation, and a
// missing display gives a clear message.
#include "io/ExrFile.h"
#include "io/PngFile.h"
#include "support/TestSupport.h"
#include "view/CameraControl.h"
#include "view/ViewerScript.h"

#include <stb/stb_image.h>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

const std::string kScene = std::string(VKRT_TEST_SOURCE_DIR) + "/scenes/seed/glass-area-light.toml";

bool haveXvfb() { return runShell("command -v xvfb-run").exitCode == 0; }

/// Runs `vkrt view ARGS` under a private Xvfb display.
ProcessResult runViewer(const std::vector<std::string>& args)
{
    std::string command = "xvfb-run -a -s '-screen 0 800x600x24' " + shellQuote(VKRT_BINARY) + " view";
    for (const auto& arg : args) command += " " + shellQuote(arg);
    return runShell(command);
}

std::vector<uint8_t> readPngPixels(const fs::path& path, int& width, int& height)
{
    int channels = 0;
    stbi_uc* data = stbi_load(path.c_str(), &width, &height, &channels, 4);
    if (!data) return {};
    std::vector<uint8_t> pixels(data, data + size_t(width) * height * 4);
    stbi_image_free(data);
    return pixels;
}

class ViewCli : public ::testing::Test {
protected:
    void SetUp() override
    {
        if (!haveXvfb()) GTEST_SKIP() << "xvfb-run is not installed (tools/install-deps.sh installs it)";
        m_dir = freshTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
        setenv("VKRT_CACHE_DIR", testCacheDir().c_str(), 1);
    }
    fs::path m_dir;
};

// --screenshot alone renders 64 frames first (docs/viewer.md), and says what it saved.
TEST_F(ViewCli, AScreenshotAloneIsTakenAfter64Frames)
{
    ProcessResult view =
        runViewer({kScene, "--screenshot", (m_dir / "alone.png").string(), "--width", "32", "--height", "24"});
    ASSERT_EQ(view.exitCode, 0) << view.output;
    EXPECT_NE(view.output.find("saved " + (m_dir / "alone.png").string() + " (64 spp)"), std::string::npos)
        << view.output;
    int w = 0, h = 0;
    EXPECT_EQ(readPngPixels(m_dir / "alone.png", w, h).size(), size_t(32 * 24 * 4));
}

// 16 frames in the viewer and `vkrt render --spp 16` accumulate the same
// samples (same seed); their 8-bit images may differ only by the rounding of
// the tone map (GPU float vs host double mean): at most 1 step, on few values.
TEST_F(ViewCli, ScreenshotMatchesRenderAfterToneMapping)
{
    ProcessResult view = runViewer({kScene, "--frames", "16", "--screenshot", (m_dir / "view.png").string(), "--width",
                                    "160", "--height", "120", "--seed", "4", "--validation"});
    ASSERT_EQ(view.exitCode, 0) << view.output;
    EXPECT_NE(view.output.find("saved " + (m_dir / "view.png").string() + " (16 spp)"), std::string::npos)
        << view.output;
    ProcessResult render = runVkrt({"render", kScene, "--spp", "16", "--width", "160", "--height", "120", "--seed", "4",
                                    "-o", (m_dir / "r.exr").string(), "--png", (m_dir / "render.png").string()});
    ASSERT_EQ(render.exitCode, 0) << render.output;
    int w1 = 0, h1 = 0, w2 = 0, h2 = 0;
    auto a = readPngPixels(m_dir / "view.png", w1, h1), b = readPngPixels(m_dir / "render.png", w2, h2);
    ASSERT_EQ(w1, 160);
    ASSERT_EQ(h1, 120);
    ASSERT_EQ(a.size(), b.size());
    size_t differing = 0;
    int worst = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        int d = std::abs(int(a[i]) - int(b[i]));
        worst = std::max(worst, d);
        differing += d != 0;
    }
    EXPECT_LE(worst, 1);
    EXPECT_LT(differing, a.size() / 100);
}

// An image in bands (render/ImageBands.h; forced here with the hidden
// --max-band-bytes: 160 x 16 rows of 28 bytes a band, so 8 bands) is
// tone-mapped band by band into the same picture as one band, pixel for pixel.
TEST_F(ViewCli, BandedImageDisplaysExactlyAsOneBand)
{
    auto screenshot = [&](const std::string& name, std::vector<std::string> extra) {
        std::vector<std::string> args = {kScene,    "--frames",    "4",        "--screenshot", (m_dir / name).string(),
                                         "--width", "160",         "--height", "120",          "--seed",
                                         "4",       "--validation"};
        args.insert(args.end(), extra.begin(), extra.end());
        ProcessResult view = runViewer(args);
        EXPECT_EQ(view.exitCode, 0) << view.output;
        int width = 0, height = 0;
        std::vector<uint8_t> pixels = readPngPixels(m_dir / name, width, height);
        EXPECT_EQ(width, 160);
        EXPECT_EQ(height, 120);
        return pixels;
    };
    std::vector<uint8_t> whole = screenshot("whole.png", {});
    std::vector<uint8_t> banded = screenshot("banded.png", {"--max-band-bytes", std::to_string(160 * 16 * 28)});
    ASSERT_FALSE(whole.empty());
    EXPECT_TRUE(whole == banded) << "the banded screenshot differs from the one-band screenshot";
}

TEST_F(ViewCli, CameraMoveResetsAccumulationAndSaveRecordsTrueSpp)
{
    fs::path script = m_dir / "session.txt";
    writeText(script, "# a scripted session\nframes 4\nsave " + (m_dir / "before.exr").string() +
                          "\norbit 15 5\nframes 3\nsave " + (m_dir / "after.exr").string() +
                          "\nkey I\nframes 2\nsave " + (m_dir / "path.exr").string() + "\nkey R\nframes 1\nsave " +
                          (m_dir / "reset.exr").string() + "\n");
    ProcessResult r =
        runViewer({kScene, "--script", script.string(), "--width", "96", "--height", "72", "--validation"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    auto spp = [&](const char* name) { return std::get<int64_t>(readExr(m_dir / name).metadata.at("spp")); };
    EXPECT_EQ(spp("before.exr"), 4);
    EXPECT_EQ(spp("after.exr"), 3) << "a camera move must reset the accumulation";
    EXPECT_EQ(spp("path.exr"), 2) << "switching the integrator starts afresh";
    EXPECT_EQ(spp("reset.exr"), 1);
    EXPECT_EQ(std::get<std::string>(readExr(m_dir / "path.exr").metadata.at("integrator")), "path");
    EXPECT_TRUE(fs::exists(m_dir / "after.png"));
    EXPECT_NE(readExr(m_dir / "before.exr").image.rgb, readExr(m_dir / "after.exr").image.rgb);
}

// A move to a camera the scene file could not hold (here: flown to infinity)
// is ignored with a message; the accumulation and the camera stay.
TEST_F(ViewCli, InvalidCameraMoveIsIgnoredWithAMessage)
{
    fs::path script = m_dir / "session.txt";
    writeText(script, "frames 3\nfly 0 0 1e308\nframes 2\nsave " + (m_dir / "kept.exr").string() + "\n");
    ProcessResult r =
        runViewer({kScene, "--script", script.string(), "--width", "48", "--height", "36", "--validation"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("fly ignored: the camera would be invalid (eye: must be finite)"), std::string::npos)
        << r.output;
    EXPECT_EQ(std::get<int64_t>(readExr(m_dir / "kept.exr").metadata.at("spp")), 5) << "no reset for a refused move";
    EXPECT_EQ(std::get<std::string>(readExr(m_dir / "kept.exr").metadata.at("savedBy")), "vkrt view");
}

// A click (here the script's `focus`) focuses a thin lens on the surface it
// points at: a wall 7 units ahead of an eye focused at 2 is refocused at 7,
// the accumulation starts afresh, and a pinhole camera says why it cannot.
TEST_F(ViewCli, FocusSetsTheThinLensOnTheSurfaceUnderThePoint)
{
    const fs::path scene = m_dir / "lens.toml";
    writeText(scene, "[render]\nintegrator = \"path\"\nmax_depth = 2\n"
                     "[camera]\neye = [0, 0, 7]\ntarget = [0, 0, 0]\nfov = 30\nwidth = 48\nheight = 36\n"
                     "aperture_radius = 0.1\nfocus_distance = 2\n"
                     "[materials.white]\ntype = \"lambert\"\nalbedo = 0.5\n"
                     "[[objects]]\nshape = \"plane\"\nmaterial = \"white\"\npoint = [0, 0, 0]\nnormal = [0, 0, 1]\n"
                     "[background]\ncolor = 1\n");
    fs::path script = m_dir / "focus.txt";
    writeText(script, "frames 2\nfocus 0.5 0.5\nframes 3\nsave " + (m_dir / "focused.exr").string() + "\n");
    ProcessResult r = runViewer({scene.string(), "--script", script.string(), "--validation"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("vkrt view: focus distance 7 (pixel 24,18)"), std::string::npos) << r.output;
    EXPECT_EQ(std::get<int64_t>(readExr(m_dir / "focused.exr").metadata.at("spp")), 3) << "focusing restarts";

    writeText(script, "frames 1\nfocus 0.5 0.5\n");
    ProcessResult pinhole = runViewer({kScene, "--script", script.string(), "--width", "48", "--height", "36"});
    ASSERT_EQ(pinhole.exitCode, 0) << pinhole.output;
    EXPECT_NE(pinhole.output.find("focus ignored: the camera is a pinhole"), std::string::npos) << pinhole.output;
}

// Dropping a file on the window (here the script's `open`) opens it: a glTF
// file as a scene; a file vkrt refuses leaves the view with the reason.
TEST_F(ViewCli, OpeningAGltfFileReplacesTheScene)
{
    const std::string gltf = std::string(VKRT_TEST_SOURCE_DIR) + "/scenes/gltf/lights-camera.gltf";
    fs::path script = m_dir / "open.txt";
    writeText(script, "frames 1\nopen " + (m_dir / "missing.glb").string() + "\nopen " + gltf + "\nframes 2\nsave " +
                          (m_dir / "opened.exr").string() + "\n");
    ProcessResult r = runViewer({kScene, "--script", script.string(), "--width", "48", "--height", "36"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("cannot open " + (m_dir / "missing.glb").string()), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("vkrt view: opened " + gltf), std::string::npos) << r.output;
    const ExrContents saved = readExr(m_dir / "opened.exr");
    EXPECT_EQ(std::get<int64_t>(saved.metadata.at("spp")), 2);
    EXPECT_EQ(saved.image.width, 48u); // the window's size
    EXPECT_EQ(std::get<std::string>(saved.metadata.at("scene")), gltf);
}

TEST_F(ViewCli, BadScriptNamesFileLineAndColumn)
{
    fs::path script = m_dir / "bad.txt";
    writeText(script, "frames 2\norbit ten 5\n");
    ProcessResult r = runViewer({kScene, "--script", script.string()});
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find(script.string() + ":2:7"), std::string::npos) << r.output;
}

TEST(ViewNoDisplay, SuggestsRender)
{
    std::string command =
        "env -u DISPLAY -u WAYLAND_DISPLAY " + shellQuote(VKRT_BINARY) + " view " + shellQuote(kScene);
    ProcessResult r = runShell(command);
    EXPECT_NE(r.exitCode, 0);
    EXPECT_NE(r.output.find("vkrt render"), std::string::npos) << r.output;
}

// The size is checked with the scene parser's rules before any window opens,
// so this needs no display.
TEST(ViewNoDisplay, ResolutionOverridesAreValidatedLikeTheSceneFile)
{
    std::string command =
        "env -u DISPLAY -u WAYLAND_DISPLAY " + shellQuote(VKRT_BINARY) + " view " + shellQuote(kScene) + " --width 0";
    ProcessResult r = runShell(command);
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("--width: must be between 1 and 16384, got 0"), std::string::npos) << r.output;
}

TEST(ViewerScript, ParsesCommandsAndRejectsMistakes)
{
    auto commands = parseViewerScript("frames 3 # comment\n\norbit 1.5 -2\nkey +\nsave out.exr\n", "s.txt");
    ASSERT_EQ(commands.size(), 4u);
    EXPECT_EQ(commands[1].name, "orbit");
    EXPECT_EQ(commands[1].numbers, (std::vector<double>{1.5, -2}));
    EXPECT_EQ(commands[2].text, "+");
    EXPECT_EQ(commands[3].line, 5);
    for (auto [text, where] : {std::pair{"jump 3\n", "s.txt:1:1"},
                               {"frames -1\n", "s.txt:1:8"},
                               {"frames 2 3\n", "s.txt:1:1"},
                               {"zoom 0\n", "s.txt:1:6"},
                               {"key X\n", "s.txt:1:5"},
                               {"fly 1 nan 0\n", "s.txt:1:7"}}) {
        try {
            parseViewerScript(text, "s.txt");
            ADD_FAILURE() << "accepted: " << text;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(where), std::string::npos) << e.what();
        }
    }
}

TEST(CameraControl, OrbitKeepsDistanceAndStopsShortOfThePoles)
{
    Camera c;
    c.eye = {0, 1, 5};
    c.target = {0, 1, 0};
    Camera o = orbit(c, 90, 0);
    EXPECT_NEAR(glm::length(o.eye - o.target), 5.0, 1e-12);
    EXPECT_NEAR(o.eye.x, 5.0, 1e-9) << "yaw 90 about +y turns +z towards +x";
    Camera top = orbit(c, 0, 200);
    double polar = std::acos(glm::dot(glm::normalize(top.eye - top.target), glm::dvec3(0, 1, 0)));
    EXPECT_NEAR(glm::degrees(polar), 1.0, 1e-9);
    Camera moved = fly(c, 0, 0, 0.2);
    EXPECT_NEAR(moved.eye.z, 4.0, 1e-12);
    EXPECT_NEAR(moved.target.z, -1.0, 1e-12);
    EXPECT_EQ(zoom(c, 100).fovY, 170.0);
}

} // namespace
} // namespace vkrt::test
