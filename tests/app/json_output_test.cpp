// `vkrt render --json` and `vkrt info --json` (docs/machine-output.md): the
// documents parse, their facts agree with what was rendered and with the
// lines printed for people, and a bad --json path is refused before any work.
#include "io/ExrFile.h"
#include "mesh/Procedural.h"
#include "support/TestSupport.h"
#include "texture/TextureTestFiles.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <regex>

namespace fs = std::filesystem;
using nlohmann::json;

namespace vkrt::test {
namespace {

std::string readText(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The document, or a test failure naming the text that did not parse.
json parseJson(const std::string& text)
{
    json document = json::parse(text, nullptr, false);
    EXPECT_FALSE(document.is_discarded()) << "not JSON:\n" << text;
    return document;
}

template <class T>
T attribute(const Metadata& metadata, const std::string& name)
{
    auto it = metadata.find(name);
    if (it == metadata.end() || !std::holds_alternative<T>(it->second)) {
        ADD_FAILURE() << "no " << name << " attribute of that type";
        return T{};
    }
    return std::get<T>(it->second);
}

class Json : public ::testing::Test {
protected:
    void SetUp() override
    {
        m_dir = freshTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
        setenv("VKRT_CACHE_DIR", testCacheDir().c_str(), 1);
    }

    static std::vector<std::string> withDevice(std::vector<std::string> args)
    {
        if (const char* device = std::getenv("VKRT_TEST_DEVICE")) args.insert(args.end(), {"--device", device});
        return args;
    }

    /// `vkrt render` of the default scene at 64x48 into m_dir/NAME.
    ProcessResult render(const std::string& output, const std::vector<std::string>& extra)
    {
        std::vector<std::string> args = {"render",      kDefaultScene, "-o",       (m_dir / output).string(),
                                         "--width",     "64",          "--height", "48",
                                         "--validation"};
        args.insert(args.end(), extra.begin(), extra.end());
        return runVkrt(withDevice(args));
    }

    /// Runs vkrt with one of its streams redirected ("2>/dev/null": stdout
    /// alone). The subshell keeps runShell's own 2>&1 from undoing that.
    static ProcessResult runRedirected(const std::vector<std::string>& args, const std::string& redirect)
    {
        std::string line = shellQuote(VKRT_BINARY);
        for (const std::string& arg : withDevice(args)) line += " " + shellQuote(arg);
        return runShell("(" + line + " " + redirect + ")");
    }

    /// A scene of known counts: two instances of an 80-triangle icosphere,
    /// an 18-triangle grid, an analytic sphere, one point light, one material.
    fs::path meshScene()
    {
        writePly(makeIcosphere(1, glm::vec3(0.0f), 0.5f), m_dir / "ico.ply", true);
        writePly(makeGrid(3), m_dir / "grid.ply", true);
        writeText(m_dir / "meshes.toml", R"([camera]
eye = [0, 1, 4]
target = [0, 0, 0]
fov = 40
width = 40
height = 30
[materials.clay]
type = "lambert"
albedo = [0.7, 0.6, 0.5]
[[objects]]
shape = "mesh"
file = "ico.ply"
material = "clay"
translate = [-1, 0, 0]
[[objects]]
shape = "mesh"
file = "ico.ply"
material = "clay"
translate = [1, 0, 0]
[[objects]]
shape = "mesh"
file = "grid.ply"
material = "clay"
rotate = { axis = [1, 0, 0], angle = -90 }
translate = [0, -0.5, 0]
[[objects]]
shape = "sphere"
center = [0, 0.5, -1]
radius = 0.3
material = "clay"
[[lights]]
type = "point"
position = [2, 3, 2]
intensity = 30
)");
        return m_dir / "meshes.toml";
    }

    std::vector<std::string> filesInDir() const
    {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(m_dir)) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

    fs::path m_dir;
};

// ---------------------------------------------------------------- render

// A device that miscounts (here an injected fault: every storage-buffer load
// reads the next element) gave pixels more samples than frames; the
// difference wrapped, and 1,536 samples reported about 1.8e11 rejected ones.
TEST_F(Json, APixelCountingMoreSamplesThanRenderedIsReportedNotWrapped)
{
    const fs::path file = m_dir / "faulty.json";
    const ProcessResult r =
        runVkrt(withDevice({"render", kDefaultScene, "-o", (m_dir / "f.exr").string(), "--width", "32", "--height",
                            "24", "--spp", "2", "--inject", "neighbour-load", "--json", file.string()}));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const json doc = parseJson(readText(file));
    EXPECT_LE(doc["rejectedSamples"].get<uint64_t>(), 32u * 24u * 2u); // 180,388,626,391 before, on Mesa 25
    // How many pixels miscount depends on the order the driver runs the invocations in (most do, on Mesa 25).
    const uint64_t miscounted = doc["miscountedPixels"].get<uint64_t>();
    EXPECT_LE(miscounted, 32u * 24u);
    EXPECT_EQ(r.output.find("pixels counted more samples than were rendered") != std::string::npos, miscounted > 0)
        << r.output;
    if (miscounted > 0) { // the EXR names it only then
        EXPECT_EQ(int64_t(miscounted), attribute<int64_t>(readExr(m_dir / "f.exr").metadata, "miscountedPixels"));
    }
}

TEST_F(Json, RenderWritesTheFactsOfTheRenderItDid)
{
    const fs::path file = m_dir / "run.json";
    ProcessResult r = render("a.exr", {"--spp", "5", "--seed", "3", "--json", file.string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const json doc = parseJson(readText(file));
    const ExrContents exr = readExr(m_dir / "a.exr");

    EXPECT_EQ(doc["schema"], 1);
    EXPECT_EQ(doc["command"], "render");
    EXPECT_EQ(doc["vkrtVersion"], VKRT_VERSION);
    EXPECT_EQ(doc["scene"], kDefaultScene);
    EXPECT_EQ(doc["sceneHash"], attribute<std::string>(exr.metadata, "sceneHash"));
    EXPECT_FALSE(doc["device"]["name"].get<std::string>().empty());
    EXPECT_EQ(doc["device"]["name"], attribute<std::string>(exr.metadata, "device"));
    EXPECT_EQ(doc["device"]["driver"], attribute<std::string>(exr.metadata, "driver"));
    EXPECT_EQ(doc["integrator"], attribute<std::string>(exr.metadata, "integrator"));
    EXPECT_EQ(doc["sampler"], attribute<std::string>(exr.metadata, "sampler"));
    EXPECT_EQ(doc["seed"], 3);
    EXPECT_EQ(doc["spp"], 5);
    EXPECT_EQ(doc["width"], exr.image.width);
    EXPECT_EQ(doc["height"], exr.image.height);
    EXPECT_EQ(doc["renderSeconds"].get<double>(), attribute<double>(exr.metadata, "renderSeconds"));
    const double seconds = doc["renderSeconds"];
    ASSERT_GT(seconds, 0.0);
    EXPECT_NEAR(doc["samplesPerSecond"].get<double>(), 5.0 * 64 * 48 / seconds, 1e-9 * 5.0 * 64 * 48 / seconds);
    EXPECT_GT(doc["startupSeconds"].get<double>(), 0.0);
    EXPECT_TRUE(doc["firstFrameSeconds"].is_null());
    EXPECT_EQ(doc["rejectedSamples"], attribute<int64_t>(exr.metadata, "rejectedSamples"));
    EXPECT_EQ(doc["loopCap"]["capped"], gpu().loopCap().capped());
    EXPECT_EQ(doc["loopCap"]["invocationsAtCap"], 0);
    EXPECT_EQ(doc["stoppedBy"], "spp");
    EXPECT_TRUE(doc["errorEstimate"].is_null()) << "no estimate was made";
    EXPECT_TRUE(doc["shard"].is_null());
    EXPECT_EQ(doc["outputs"]["exr"], (m_dir / "a.exr").string());
    EXPECT_TRUE(doc["outputs"]["png"].is_null());
    EXPECT_EQ(doc["validationMessages"], 0);
    EXPECT_FALSE(doc["kernel"]["cacheKey"].get<std::string>().empty());

    // The line for people says the same.
    std::smatch line;
    ASSERT_TRUE(std::regex_search(r.output, line, std::regex(R"((\d+) spp  ([\d.]+) s  .*\(start-up ([\d.]+) s)")))
        << r.output;
    EXPECT_EQ(std::stoi(line[1]), 5);
    EXPECT_NEAR(std::stod(line[2]), seconds, 0.005 + 1e-12);
    EXPECT_NEAR(std::stod(line[3]), doc["startupSeconds"].get<double>(), 0.005 + 1e-12);
    EXPECT_NE(r.output.find(doc["device"]["name"].get<std::string>()), std::string::npos);
}

TEST_F(Json, RenderToStandardOutputWritesOnlyTheDocumentThere)
{
    std::vector<std::string> args = {"render",  kDefaultScene, "-o",       (m_dir / "a.exr").string(),
                                     "--width", "32",          "--height", "24",
                                     "--spp",   "2",           "--json",   "-"};
    ProcessResult r = runRedirected(args, "2>/dev/null");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const json doc = parseJson(r.output);
    EXPECT_EQ(doc["spp"], 2);
    EXPECT_EQ(doc["width"], 32);
    EXPECT_EQ(filesInDir(), std::vector<std::string>{"a.exr"});
}

TEST_F(Json, RenderReportsTheErrorEstimateTheExrRecords)
{
    const fs::path file = m_dir / "run.json";
    ProcessResult r =
        render("a.exr", {"--spp", "8", "--variance", "--png", (m_dir / "a.png").string(), "--json", file.string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const json doc = parseJson(readText(file));
    const ExrContents exr = readExr(m_dir / "a.exr");
    ASSERT_TRUE(doc["errorEstimate"].is_object()) << doc.dump(2);
    EXPECT_EQ(doc["errorEstimate"]["rmse"].get<double>(), attribute<double>(exr.metadata, "estimatedRmse"));
    EXPECT_EQ(doc["errorEstimate"]["relMse"].get<double>(), attribute<double>(exr.metadata, "estimatedRelMse"));
    EXPECT_EQ(doc["errorEstimate"]["degreesOfFreedom"], attribute<int64_t>(exr.metadata, "varianceDegreesOfFreedom"));
    EXPECT_EQ(doc["errorEstimate"]["estimator"], "independent-samples");
    EXPECT_EQ(doc["errorEstimate"]["relMseUpper"].get<double>(),
              attribute<double>(exr.metadata, "estimatedRelMseUpper"));
    EXPECT_GT(doc["errorEstimate"]["relMseUpper"].get<double>(), doc["errorEstimate"]["relMse"].get<double>());
    EXPECT_EQ(doc["errorEstimate"]["relMseConfidence"], 0.95);
    EXPECT_GT(doc["errorEstimate"]["relMseDegreesOfFreedom"].get<double>(), 0.0);
    EXPECT_EQ(doc["outputs"]["exrLayers"], json::array({"variance"}));
    EXPECT_EQ(doc["outputs"]["png"], (m_dir / "a.png").string());
}

TEST_F(Json, RenderOfAShardGivesItsSampleRange)
{
    const fs::path file = m_dir / "run.json";
    ProcessResult r = render("s.exr", {"--spp", "4", "--shard", "1/2", "--json", file.string()});
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const json doc = parseJson(readText(file));
    EXPECT_EQ(doc["spp"], 2);
    EXPECT_EQ(doc["shard"], json({{"index", 1}, {"count", 2}, {"sampleBegin", 2}, {"sampleEnd", 4}, {"totalSpp", 4}}));
}

TEST_F(Json, RenderRefusesABadJsonPathBeforeAnyWork)
{
    for (const fs::path& bad : {m_dir / "no-such-dir" / "run.json", m_dir}) {
        ProcessResult r = render("a.exr", {"--spp", "1", "--json", bad.string()});
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find(bad.string()), std::string::npos) << r.output;
        EXPECT_EQ(r.output.find(" spp "), std::string::npos) << "it rendered:\n" << r.output;
        EXPECT_TRUE(filesInDir().empty()) << "something was written";
    }
}

TEST_F(Json, RenderRefusesJsonOverAnotherOutputOrTheScene)
{
    const fs::path exr = m_dir / "a.exr";
    ProcessResult same = render("a.exr", {"--spp", "1", "--json", exr.string()});
    EXPECT_EQ(same.exitCode, 2) << same.output;
    EXPECT_NE(same.output.find("--json is the same file as -o"), std::string::npos) << same.output;
    EXPECT_FALSE(fs::exists(exr));

    const fs::path scene = m_dir / "scene.toml";
    fs::copy_file(kDefaultScene, scene);
    ProcessResult input = runVkrt(withDevice({"render", scene.string(), "-o", exr.string(), "--width", "16", "--height",
                                              "16", "--spp", "1", "--json", scene.string()}));
    EXPECT_EQ(input.exitCode, 2) << input.output;
    EXPECT_NE(input.output.find("--json is the same file as the scene file"), std::string::npos) << input.output;
    EXPECT_EQ(readText(scene), readText(kDefaultScene));
}

// ---------------------------------------------------------------- info

TEST_F(Json, InfoCountsWhatTheSceneHolds)
{
    const fs::path scene = meshScene(), file = m_dir / "info.json";
    ProcessResult r = runVkrt(withDevice({"info", scene.string(), "--json", file.string()}));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const json doc = parseJson(readText(file));
    EXPECT_EQ(doc["schema"], 1);
    EXPECT_EQ(doc["command"], "info");
    EXPECT_EQ(doc["width"], 40);
    EXPECT_EQ(doc["height"], 30);
    EXPECT_FALSE(doc["device"]["name"].get<std::string>().empty());
    EXPECT_EQ(doc["counts"]["shapes"]["mesh"], 3);
    EXPECT_EQ(doc["counts"]["shapes"]["sphere"], 1);
    EXPECT_EQ(doc["counts"]["shapes"]["box"], 0);
    EXPECT_EQ(doc["counts"]["lights"]["point"], 1);
    EXPECT_EQ(doc["counts"]["lights"]["triangle"], 0);
    EXPECT_EQ(doc["counts"]["materials"]["lambert"], 1);
    EXPECT_EQ(doc["features"]["shapes"], json::array({"sphere", "mesh"}));
    EXPECT_EQ(doc["features"]["lights"], json::array({"point"}));
    EXPECT_EQ(doc["features"]["materials"], json::array({"lambert"}));

    const json& meshes = doc["meshes"];
    EXPECT_EQ(meshes["instances"], 3);
    EXPECT_EQ(meshes["geometries"], 2);
    EXPECT_EQ(meshes["triangles"], 80 + 18);
    EXPECT_EQ(meshes["renderedTriangles"], 2 * 80 + 18);
    EXPECT_EQ(meshes["emissiveTriangles"], 0);
    EXPECT_GT(meshes["bvhNodes"].get<int>(), 0);
    EXPECT_EQ(meshes["topLevelRecords"], 4) << "three instances and the sphere";
    EXPECT_GT(meshes["gpuBytes"].get<int64_t>(), 0);
    EXPECT_TRUE(doc["textures"].is_null());
    EXPECT_TRUE(doc["loopPassesWorstCase"].is_null()) << "meshes have no static bound";

    EXPECT_GT(doc["kernel"]["spirvBytes"].get<int64_t>(), 0);
    EXPECT_EQ(doc["kernel"]["defines"]["VKRT_HAS_MESHES"], "1");
    EXPECT_GE(doc["firstFrameSeconds"].get<double>(), doc["setupSeconds"].get<double>());

    // The lines for people say the same.
    EXPECT_NE(r.output.find("spirv bytes:    " + std::to_string(doc["kernel"]["spirvBytes"].get<int64_t>())),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("3 instances of 2 files; 98 triangles (178 rendered)"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("variant:        " + doc["kernel"]["cacheKey"].get<std::string>()), std::string::npos);
}

// With --staged the kernel is the shade stage and traceStage the other
// (null without); a Whitted scene is refused, naming the option.
TEST_F(Json, InfoDescribesBothStagedKernels)
{
    const fs::path scene = fs::path(VKRT_TEST_SOURCE_DIR) / "scenes" / "validation" / "diffuse-box.toml";
    const fs::path file = m_dir / "staged.json";
    ProcessResult plain = runVkrt(withDevice({"info", scene.string(), "--json", file.string()}));
    ASSERT_EQ(plain.exitCode, 0) << plain.output;
    const json megakernel = parseJson(readText(file));
    EXPECT_EQ(megakernel["kernel"]["staged"], false);
    EXPECT_TRUE(megakernel["kernel"]["traceStage"].is_null());

    ProcessResult staged = runVkrt(withDevice({"info", scene.string(), "--staged", "--json", file.string()}));
    ASSERT_EQ(staged.exitCode, 0) << staged.output;
    const json doc = parseJson(readText(file));
    EXPECT_EQ(doc["kernel"]["staged"], true);
    const json& trace = doc["kernel"]["traceStage"];
    ASSERT_TRUE(trace.is_object()) << doc["kernel"].dump();
    EXPECT_GT(trace["spirvBytes"].get<int64_t>(), 0);
    EXPECT_NE(trace["cacheKey"], doc["kernel"]["cacheKey"]);
    EXPECT_NE(doc["kernel"]["cacheKey"], megakernel["kernel"]["cacheKey"]);

    ProcessResult whitted =
        runVkrt(withDevice({"render", kDefaultScene, "--staged", "--spp", "1", "-o", (m_dir / "w.exr").string()}));
    EXPECT_EQ(whitted.exitCode, 2) << whitted.output;
    EXPECT_NE(whitted.output.find("--staged runs the path integrator only"), std::string::npos) << whitted.output;
    EXPECT_FALSE(fs::exists(m_dir / "w.exr"));
}

// --scene-reads picks how the kernel reads the scene (a different kernel:
// another cache key), and a name it does not know is refused naming it.
TEST_F(Json, InfoReportsHowTheKernelReadsTheScene)
{
    const fs::path scene = fs::path(VKRT_TEST_SOURCE_DIR) / "scenes" / "validation" / "diffuse-box.toml";
    const fs::path file = m_dir / "reads.json";
    ProcessResult descriptor =
        runVkrt(withDevice({"info", scene.string(), "--scene-reads", "descriptor", "--json", file.string()}));
    ASSERT_EQ(descriptor.exitCode, 0) << descriptor.output;
    const json byDescriptor = parseJson(readText(file));
    EXPECT_EQ(byDescriptor["kernel"]["sceneAddresses"], false);
    EXPECT_FALSE(byDescriptor["kernel"]["defines"].contains("VKRT_SCENE_ADDRESSES"));

    ProcessResult address =
        runVkrt(withDevice({"info", scene.string(), "--scene-reads", "address", "--json", file.string()}));
    if (address.exitCode == 0) {
        const json byAddress = parseJson(readText(file));
        EXPECT_EQ(byAddress["kernel"]["sceneAddresses"], true);
        EXPECT_TRUE(byAddress["kernel"]["defines"].contains("VKRT_SCENE_ADDRESSES"));
        EXPECT_NE(byAddress["kernel"]["cacheKey"], byDescriptor["kernel"]["cacheKey"]);
    } else {
        EXPECT_NE(address.output.find("bufferDeviceAddress"), std::string::npos) << address.output;
    }

    // An injected neighbour-load fault changes descriptor loads only: auto then reads through descriptors.
    setenv("VKRT_INJECT_FAULT", "neighbour-load", 1);
    ProcessResult faulty = runVkrt(withDevice({"info", scene.string(), "--json", file.string()}));
    unsetenv("VKRT_INJECT_FAULT");
    ASSERT_EQ(faulty.exitCode, 0) << faulty.output;
    EXPECT_EQ(parseJson(readText(file))["kernel"]["sceneAddresses"], false);

    ProcessResult unknown = runVkrt(withDevice({"info", scene.string(), "--scene-reads", "pointer"}));
    EXPECT_EQ(unknown.exitCode, 2) << unknown.output;
    EXPECT_NE(unknown.output.find("--scene-reads pointer"), std::string::npos) << unknown.output;
}

// Texture memory: its bytes and the storage buffers they take, one unless
// they exceed a buffer (here forced by the hidden --max-texture-chunk-bytes).
TEST_F(Json, InfoReportsTextureMemoryAndItsBuffers)
{
    write8BitPng(m_dir / "grey.png", 16, 16, 3, std::vector<uint8_t>(16 * 16 * 3, 128));
    const fs::path scene = m_dir / "textured.toml";
    std::ofstream(scene) << "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nfov = 45\nwidth = 16\nheight = 16\n"
                            "[materials.m]\ntype = \"lambert\"\nalbedo = { texture = \"grey.png\" }\n"
                            "[[objects]]\nshape = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\nmaterial = \"m\"\n"
                            "[[lights]]\ntype = \"point\"\nposition = [0, 3, 3]\nintensity = [5, 5, 5]\n";
    auto info = [&](const std::vector<std::string>& extra) {
        const fs::path file = m_dir / "info.json";
        std::vector<std::string> args = {"info", scene.string(), "--json", file.string()};
        args.insert(args.end(), extra.begin(), extra.end());
        const ProcessResult r = runVkrt(withDevice(args));
        EXPECT_EQ(r.exitCode, 0) << r.output;
        return std::make_pair(parseJson(readText(file)), r.output);
    };
    const auto [one, oneText] = info({});
    const uint64_t bytes = 4 * (256 + 64 + 16 + 4 + 1); // 8-bit sRGB, every mip level
    EXPECT_EQ(one["textures"]["texelBytes"], bytes);
    EXPECT_EQ(one["textures"]["buffers"], 1);
    EXPECT_EQ(one["textures"]["bufferBytes"], bytes);
    EXPECT_FALSE(one["kernel"]["defines"].contains("VKRT_TEXTURE_CHUNKS"));
    EXPECT_NE(oneText.find("in 1 buffer\n"), std::string::npos) << oneText;
    const auto [split, splitText] = info({"--max-texture-chunk-bytes", "256"});
    EXPECT_EQ(split["textures"]["texelBytes"], bytes);
    EXPECT_EQ(split["textures"]["buffers"], 6); // 341 words in chunks of 64
    EXPECT_EQ(split["textures"]["bufferBytes"], 256);
    EXPECT_EQ(split["kernel"]["defines"]["VKRT_TEXTURE_CHUNKS"], "6");
    EXPECT_EQ(split["kernel"]["defines"]["VKRT_TEXTURE_CHUNK_SHIFT"], "6");
    EXPECT_NE(splitText.find("in 6 buffers\n"), std::string::npos) << splitText;
    // The start-up split: the image was decoded by the first run (or an
    // earlier one) and read from the texture cache by the second; the parts
    // add up to the total.
    const json& first = one["startup"];
    EXPECT_EQ(first["texturesDecoded"].get<int>() + first["texturesFromCache"].get<int>(), 1);
    EXPECT_EQ(split["startup"]["texturesFromCache"], 1);
    EXPECT_EQ(split["startup"]["texturesDecoded"], 0);
    double parts = 0.0;
    for (const char* key : {"parseSeconds", "texturesSeconds", "meshFilesSeconds", "bvhSeconds", "glslangSeconds",
                            "setupSeconds", "firstFrameSeconds"}) {
        EXPECT_GE(first[key].get<double>(), 0.0) << key;
        parts += first[key].get<double>();
    }
    EXPECT_NEAR(parts, first["totalSeconds"].get<double>(), 1e-9);
    EXPECT_NE(oneText.find("start-up:       "), std::string::npos) << oneText;
}

TEST_F(Json, InfoToStandardOutputMovesTheLinesForPeopleToStderr)
{
    const fs::path scene = meshScene();
    ProcessResult out = runRedirected({"info", scene.string(), "--json", "-"}, "2>/dev/null");
    ASSERT_EQ(out.exitCode, 0) << out.output;
    const json doc = parseJson(out.output);
    EXPECT_EQ(doc["meshes"]["triangles"], 98);
    EXPECT_TRUE(doc["loopPassesWorstCase"].is_null());

    ProcessResult err = runRedirected({"info", scene.string(), "--json", "-"}, ">/dev/null");
    ASSERT_EQ(err.exitCode, 0) << err.output;
    EXPECT_NE(err.output.find("first frame:"), std::string::npos) << err.output;
}

TEST_F(Json, InfoWithoutMeshesGivesTheStaticLoopBound)
{
    const fs::path file = m_dir / "info.json";
    ProcessResult r = runVkrt(withDevice({"info", kDefaultScene, "--json", file.string()}));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const json doc = parseJson(readText(file));
    EXPECT_TRUE(doc["meshes"].is_null());
    ASSERT_TRUE(doc["loopPassesWorstCase"].is_number_integer()) << doc.dump(2);
    EXPECT_NE(r.output.find("worst case " + std::to_string(doc["loopPassesWorstCase"].get<int64_t>())),
              std::string::npos)
        << r.output;
}

TEST_F(Json, InfoRefusesABadJsonPathAndTheScenesOwnFiles)
{
    const fs::path scene = meshScene();
    const fs::path bad = m_dir / "no-such-dir" / "info.json";
    ProcessResult r = runVkrt(withDevice({"info", scene.string(), "--json", bad.string()}));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find(bad.string()), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("first frame"), std::string::npos) << "it ran:\n" << r.output;

    const std::string mesh = readText(m_dir / "ico.ply");
    ProcessResult overMesh = runVkrt(withDevice({"info", scene.string(), "--json", (m_dir / "ico.ply").string()}));
    EXPECT_EQ(overMesh.exitCode, 2) << overMesh.output;
    EXPECT_NE(overMesh.output.find("--json is the same file as a mesh the scene loads"), std::string::npos)
        << overMesh.output;
    EXPECT_EQ(readText(m_dir / "ico.ply"), mesh);
}

} // namespace
} // namespace vkrt::test
