// What a new user expects of the command line (issue "what a new user trips
// over"), end to end: the output's format from its extension, one image side
// keeping the aspect ratio, the PNG's tone curve, the summary naming why the
// render stopped and every file it wrote, warnings for a scene that cannot
// show anything and for a lat-long map that is not 2:1, "did you mean" for a
// misspelt command or option, the start-up line on a terminal, and
// docs/machine-output.md's keys in the JSON documents.
#include "io/ExrFile.h"
#include "io/PngFile.h"
#include "support/TestSupport.h"

#include <nlohmann/json.hpp>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

class NewUserCli : public ::testing::Test {
protected:
    void SetUp() override
    {
        m_dir = freshTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
        setenv("VKRT_CACHE_DIR", testCacheDir().c_str(), 1);
    }
    fs::path m_dir;

    std::vector<std::string> withDevice(std::vector<std::string> args) const
    {
        if (const char* device = std::getenv("VKRT_TEST_DEVICE")) args.insert(args.end(), {"--device", device});
        return args;
    }

    ProcessResult render(const std::string& scene, std::vector<std::string> extra)
    {
        std::vector<std::string> args = {"render", scene, "--spp", "2"};
        args.insert(args.end(), extra.begin(), extra.end());
        return runVkrt(withDevice(args));
    }

    fs::path writeScene(const std::string& name, const std::string& text) const
    {
        const fs::path path = m_dir / name;
        writeText(path, text);
        return path;
    }
};

std::string readAll(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    std::stringstream buffer;
    buffer << in.rdbuf();
    return buffer.str();
}

TEST_F(NewUserCli, TheOutputsFormatComesFromItsExtension)
{
    const fs::path png = m_dir / "out.png";
    ProcessResult r = render(kDefaultScene, {"-o", png.string(), "--width", "32", "--height", "24"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const std::string bytes = readAll(png);
    ASSERT_GE(bytes.size(), 8u);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << "not a PNG";
    const Image image = readPng(png);
    EXPECT_EQ(image.width, 32u);
    EXPECT_EQ(image.height, 24u);
    // Upper case is the same format.
    ASSERT_EQ(render(kDefaultScene, {"-o", (m_dir / "OUT.EXR").string(), "--width", "8", "--height", "8"}).exitCode, 0);
    EXPECT_EQ(readExr(m_dir / "OUT.EXR").image.width, 8u);
    // Anything else is refused before any work, with the formats listed.
    for (const std::string name : {"out.jpg", "out", "out.tiff"}) {
        ProcessResult bad = render(kDefaultScene, {"-o", (m_dir / name).string()});
        EXPECT_EQ(bad.exitCode, 2) << name << ": " << bad.output;
        EXPECT_NE(bad.output.find(".exr (OpenEXR"), std::string::npos) << bad.output;
        EXPECT_NE(bad.output.find("-o " + (m_dir / name).string()), std::string::npos) << bad.output;
        EXPECT_FALSE(fs::exists(m_dir / name));
    }
    // A PNG cannot hold layers: refused, not written without them.
    ProcessResult layered = render(kDefaultScene, {"-o", (m_dir / "v.png").string(), "--variance"});
    EXPECT_EQ(layered.exitCode, 2) << layered.output;
    EXPECT_NE(layered.output.find("--variance"), std::string::npos) << layered.output;
    ProcessResult preview =
        render(kDefaultScene, {"-o", (m_dir / "a.exr").string(), "--png", (m_dir / "a.exr2").string()});
    EXPECT_EQ(preview.exitCode, 2) << preview.output;
    EXPECT_NE(preview.output.find("--png"), std::string::npos) << preview.output;
}

TEST_F(NewUserCli, OneImageSideKeepsTheAspectRatio)
{
    // The default scene is 640 x 480.
    ASSERT_EQ(render(kDefaultScene, {"-o", (m_dir / "w.exr").string(), "--width", "160"}).exitCode, 0);
    ExrContents w = readExr(m_dir / "w.exr");
    EXPECT_EQ(w.image.width, 160u);
    EXPECT_EQ(w.image.height, 120u);
    ASSERT_EQ(render(kDefaultScene, {"-o", (m_dir / "h.exr").string(), "--height", "33"}).exitCode, 0);
    ExrContents h = readExr(m_dir / "h.exr");
    EXPECT_EQ(h.image.width, 44u);
    EXPECT_EQ(h.image.height, 33u);
    // Both given: both taken.
    ASSERT_EQ(render(kDefaultScene, {"-o", (m_dir / "b.exr").string(), "--width", "20", "--height", "30"}).exitCode, 0);
    ExrContents both = readExr(m_dir / "b.exr");
    EXPECT_EQ(both.image.width, 20u);
    EXPECT_EQ(both.image.height, 30u);
}

TEST_F(NewUserCli, FilmicTonesThePngAsTheViewerDoes)
{
    // The curve: Narkowicz's ACES fit, the viewer's (shaders/kernels/display.comp).
    auto aces = [](double x) { return std::clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0); };
    auto srgb = [](double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; };
    for (float x : {0.01f, 0.18f, 0.5f, 1.0f, 4.0f, 100.0f}) {
        EXPECT_EQ(toneMapToSrgb8(x, 0.0f, ToneCurve::Filmic), uint8_t(std::lround(srgb(aces(x)) * 255.0))) << x;
        EXPECT_EQ(toneMapToSrgb8(x, 1.0f, ToneCurve::Filmic), uint8_t(std::lround(srgb(aces(2.0 * x)) * 255.0))) << x;
    }
    EXPECT_EQ(toneMapToSrgb8(std::numeric_limits<float>::infinity(), 0.0f, ToneCurve::Filmic), 255);
    EXPECT_EQ(toneMapToSrgb8(std::nanf(""), 0.0f, ToneCurve::Filmic), 0);
    // The command line: the same render, clamped and filmic, differ where the curve does.
    const std::vector<std::string> size{"--width", "16", "--height", "12", "--seed", "3"};
    auto args = [&](const std::string& png, bool filmic) {
        std::vector<std::string> a{"-o", (m_dir / "x.exr").string(), "--png", (m_dir / png).string()};
        a.insert(a.end(), size.begin(), size.end());
        if (filmic) a.push_back("--filmic");
        return a;
    };
    ASSERT_EQ(render(kDefaultScene, args("clamp.png", false)).exitCode, 0);
    const Image hdr = readExr(m_dir / "x.exr").image;
    ASSERT_EQ(render(kDefaultScene, args("filmic.png", true)).exitCode, 0);
    const std::vector<uint8_t> expected = toneMapImage(hdr, 0.0f, ToneCurve::Filmic);
    const Image filmic = readPng(m_dir / "filmic.png");
    ASSERT_EQ(filmic.rgb.size(), hdr.rgb.size());
    for (size_t i = 0; i < hdr.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(filmic.rgb[i * 3 + c], srgb8ToLinear(expected[i * 4 + c]), 1e-6) << "pixel " << i;
}

TEST_F(NewUserCli, TheSummarySaysWhyItStoppedAndNamesEveryFileWritten)
{
    const fs::path exr = m_dir / "s.exr", png = m_dir / "s.png", json = m_dir / "s.json";
    ProcessResult r = render(kDefaultScene, {"-o", exr.string(), "--png", png.string(), "--json", json.string(),
                                             "--width", "16", "--height", "12"});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("stopped: spp  -> " + exr.string() + ", " + png.string() + ", " + json.string()),
              std::string::npos)
        << r.output;
    const nlohmann::json doc = nlohmann::json::parse(readAll(json));
    EXPECT_EQ(doc["outputs"]["written"], (std::vector<std::string>{exr.string(), png.string(), json.string()}));
    EXPECT_EQ(doc["outputs"]["previewPng"], png.string());
    // A target error says it was reached, with the estimate.
    ProcessResult target = runVkrt(withDevice(
        {"render", kDefaultScene, "-o", exr.string(), "--width", "16", "--height", "12", "--target-error", "1e6"}));
    ASSERT_EQ(target.exitCode, 0) << target.output;
    EXPECT_TRUE(std::regex_search(
        target.output,
        std::regex("stopped: target error reached: estimated relMSE [0-9.e+-]+, upper bound [0-9.e+-]+ < 1e\\+06")))
        << target.output;
}

TEST_F(NewUserCli, AScenesThatGivesNoLightIsWarnedAbout)
{
    const std::string camera = "[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\nwidth = 8\nheight = 8\n"
                               "[materials.m]\ntype = \"lambert\"\n"
                               "[[objects]]\nshape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n";
    const fs::path dark = writeScene("dark.toml", camera);
    ProcessResult r = render(dark.string(), {"-o", (m_dir / "dark.exr").string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("dark.toml: nothing in the scene gives light"), std::string::npos) << r.output;
    for (const std::string light :
         {"[background]\ncolor = 0.5\n", "[[lights]]\ntype = \"point\"\nposition = [0, 3, 0]\nintensity = 1\n"}) {
        const fs::path lit = writeScene("lit.toml", camera + light);
        ProcessResult ok = render(lit.string(), {"-o", (m_dir / "lit.exr").string()});
        EXPECT_EQ(ok.exitCode, 0) << ok.output;
        EXPECT_EQ(ok.output.find("gives light"), std::string::npos) << ok.output;
    }
}

TEST_F(NewUserCli, ALatLongMapThatIsNot2To1IsWarnedAbout)
{
    auto writeMap = [&](const std::string& name, uint32_t w, uint32_t h) {
        Image map(w, h);
        map.rgb.assign(size_t(w) * h * 3, 0.5f);
        writeExr(m_dir / name, map, {});
    };
    writeMap("square.exr", 16, 16);
    writeMap("wide.exr", 32, 16);
    writeMap("wide-plus-row.exr", 32, 17);
    const std::string head = "[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\nwidth = 8\nheight = 8\n"
                             "[background.environment]\nfile = \"";
    for (const auto& [file, warned] : std::vector<std::pair<std::string, bool>>{{"square.exr", true},
                                                                                {"wide.exr", false},
                                                                                {"wide-plus-row.exr", false}}) {
        const fs::path scene = writeScene("env.toml", head + file + "\"\n");
        ProcessResult r = render(scene.string(), {"-o", (m_dir / "env.exr").string()});
        EXPECT_EQ(r.exitCode, 0) << r.output;
        EXPECT_EQ(r.output.find("not 2:1") != std::string::npos, warned) << file << ": " << r.output;
    }
}

TEST_F(NewUserCli, AMisspeltCommandOrOptionGetsTheNearestName)
{
    struct Case {
        std::vector<std::string> args;
        std::string hint;
    } cases[] = {
        {{"rendr", kDefaultScene}, "did you mean `vkrt render`?"},
        {{"regres"}, "did you mean `vkrt regress`?"},
        {{"render", kDefaultScene, "--samples", "16"}, "did you mean --spp?"},
        {{"render", kDefaultScene, "--sed", "3"}, "did you mean --seed?"},
        {{"render", kDefaultScene, "--out", "x.exr"}, "did you mean -o?"},
        {{"render", kDefaultScene, "--exposre=1"}, "did you mean --exposure?"},
        {{"view", kDefaultScene, "--filmc"}, "did you mean --filmic?"},
    };
    for (const Case& c : cases) {
        ProcessResult r = runVkrt(c.args);
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find(c.hint), std::string::npos) << c.args[0] << ": " << r.output;
    }
    // Nothing close: no guess.
    ProcessResult far = runVkrt({"render", kDefaultScene, "--zzzzzzzz"});
    EXPECT_EQ(far.exitCode, 2);
    EXPECT_EQ(far.output.find("did you mean"), std::string::npos) << far.output;
}

TEST_F(NewUserCli, MakeSkyHelpShowsTheDefaults)
{
    const ProcessResult r = runShell(shellQuote(fs::path(VKRT_BINARY).parent_path() / "vkrt-make-sky") + " --help");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(std::regex_search(r.output, std::regex(R"(--size[^\n]*128)"))) << r.output;
    EXPECT_TRUE(std::regex_search(r.output, std::regex(R"(--sun-elevation[^\n]*\d)"))) << r.output;
}

TEST_F(NewUserCli, OnATerminalTheStartUpSaysWhatItIsDoing)
{
    // script(1) gives the command a terminal; its output is what the terminal showed.
    if (runShell("command -v script >/dev/null").exitCode != 0) GTEST_SKIP() << "no script(1)";
    std::string command = shellQuote(VKRT_BINARY) + " render " + shellQuote(kDefaultScene) + " --spp 1 --width 8 -o " +
                          shellQuote((m_dir / "t.exr").string());
    if (const char* device = std::getenv("VKRT_TEST_DEVICE")) command += " --device " + shellQuote(device);
    const ProcessResult r = runShell("script -qec " + shellQuote(command) + " /dev/null");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("setting up " + kDefaultScene), std::string::npos) << r.output;
    // Not on a pipe: there the summary line is all.
    const ProcessResult piped = render(kDefaultScene, {"--width", "8", "-o", (m_dir / "p.exr").string()});
    EXPECT_EQ(piped.output.find("setting up"), std::string::npos) << piped.output;
}

TEST_F(NewUserCli, VersionNamesTheCommitAndTheDevice)
{
    const ProcessResult r = runVkrt({"--version"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(
        std::regex_search(r.output, std::regex("vkrt " VKRT_VERSION R"( \(commit ([0-9a-f]{7,}(-dirty)?|unknown)\))")))
        << r.output;
    EXPECT_TRUE(std::regex_search(r.output, std::regex(R"(Vulkan device: [^\n]+, Vulkan \d)"))) << r.output;
}

TEST_F(NewUserCli, TheManPageListsEveryOptionOfEveryCommand)
{
    const ProcessResult page = runVkrt({"man"});
    ASSERT_EQ(page.exitCode, 0) << page.output;
    EXPECT_EQ(page.output.rfind(".TH VKRT 1", 0), 0u) << page.output.substr(0, 200);
    // Every option each command's --help shows is on the page (both come from one definition).
    for (const std::string command : {"render", "view", "info", "compare", "merge", "regress", "devices"}) {
        EXPECT_NE(page.output.find(".SS " + command + "\n"), std::string::npos) << command;
        const ProcessResult help = runVkrt({command, "--help"});
        const std::regex option(R"((^|[\s,])(--[a-z][a-z0-9-]*))");
        int seen = 0;
        for (std::sregex_iterator it(help.output.begin(), help.output.end(), option), end; it != end; ++it) {
            std::string escaped;
            for (char c : (*it)[2].str()) escaped += c == '-' ? std::string("\\-") : std::string(1, c);
            EXPECT_NE(page.output.find(escaped), std::string::npos) << command << " " << (*it)[2];
            ++seen;
        }
        EXPECT_GT(seen, 0) << command;
    }
    // The build writes it beside the binary.
    EXPECT_TRUE(fs::exists(fs::path(VKRT_BINARY).parent_path() / "vkrt.1"));
}

/// The backticked keys of the first column of the table under `heading` in docs/machine-output.md.
std::set<std::string> documentedKeys(const std::string& heading)
{
    std::ifstream doc(std::string(VKRT_TEST_SOURCE_DIR) + "/docs/machine-output.md");
    std::string line;
    bool inSection = false;
    std::set<std::string> keys;
    const std::regex key("`([A-Za-z]+)`");
    while (std::getline(doc, line)) {
        if (line.starts_with("## ")) inSection = line == "## " + heading;
        if (!inSection || !line.starts_with("| `")) continue;
        const std::string first = line.substr(0, line.find('|', 1));
        for (std::sregex_iterator it(first.begin(), first.end(), key), end; it != end; ++it) keys.insert((*it)[1]);
    }
    return keys;
}

TEST_F(NewUserCli, EveryDocumentedJsonKeyIsThere)
{
    const fs::path json = m_dir / "r.json";
    ASSERT_EQ(
        render(kDefaultScene, {"-o", (m_dir / "r.exr").string(), "--width", "8", "--json", json.string()}).exitCode, 0);
    const nlohmann::json renderDoc = nlohmann::json::parse(readAll(json));
    const std::set<std::string> renderKeys = documentedKeys("`vkrt render --json`");
    ASSERT_GT(renderKeys.size(), 20u);
    for (const std::string& key : renderKeys) EXPECT_TRUE(renderDoc.contains(key)) << "render: " << key;
    for (const char* key : {"schema", "command", "vkrtVersion"}) EXPECT_TRUE(renderDoc.contains(key)) << key;

    const fs::path infoJson = m_dir / "i.json";
    ASSERT_EQ(runVkrt(withDevice({"info", kDefaultScene, "--json", infoJson.string()})).exitCode, 0);
    const nlohmann::json infoDoc = nlohmann::json::parse(readAll(infoJson));
    const std::set<std::string> infoKeys = documentedKeys("`vkrt info --json`");
    ASSERT_GT(infoKeys.size(), 10u);
    for (const std::string& key : infoKeys) EXPECT_TRUE(infoDoc.contains(key)) << "info: " << key;
}

} // namespace
} // namespace vkrt::test
