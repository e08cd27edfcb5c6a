// End-to-end tests of `vkrt regress` (docs/regress.md) as CI and a driver
// developer run it: a deliberately biased kernel fails the right cases,
// repeated seeds fail no more often than the suite's alpha allows, bad input
// gives clear errors (never exit 4, never a crash), --update makes references
// the suite then accepts, and Ctrl-C keeps the finished cases on disk. The
// runner in the manner of deqp-runner: a crashing or hanging case (test hooks
// in the environment) is a Crash or Timeout while the others still pass, a
// case failing once is a Flake, baseline files decide what is unexpected,
// results.csv says it all, and --compare-drivers compares a driver with itself.
#include "io/ExrFile.h"
#include "support/TestSupport.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace vkrt::test {
namespace {

const fs::path kSource = VKRT_TEST_SOURCE_DIR;

/// One [[case]] of a test manifest; scene and reference are absolute paths.
struct ManifestCase {
    std::string name;
    fs::path scene;
    fs::path reference;
    uint32_t referenceSpp = 4096;
    uint32_t spp = 32;
    std::string extra; ///< more TOML lines, e.g. "width = 64"
    std::string source = "vkrt";
};

std::string manifestText(const std::vector<ManifestCase>& cases, const std::string& suiteLines = "")
{
    std::ostringstream toml;
    toml << "[suite]\nseed = 1\n" << suiteLines << "\n";
    for (const ManifestCase& c : cases)
        toml << "[[case]]\nname = \"" << c.name << "\"\nscene = \"" << c.scene.string() << "\"\nreference = \""
             << c.reference.string() << "\"\nreference_source = \"" << c.source
             << "\"\nreference_spp = " << c.referenceSpp << "\nspp = " << c.spp << "\n"
             << c.extra << "\n";
    return toml.str();
}

/// A case of the default suite's seed and extreme references.
ManifestCase shipped(const std::string& name, uint32_t spp, const std::string& extra = "")
{
    std::string folder = name.substr(0, name.find('/')), file = name.substr(name.find('/') + 1);
    return {name, kSource / "scenes" / folder / (file + ".toml"), kSource / "tests/references" / name, 4096, spp,
            extra};
}

std::string readFile(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// Outcome per case of a JUnit file: "pass", "failure" or "error".
std::map<std::string, std::string> junitOutcomes(const fs::path& path)
{
    std::string xml = readFile(path);
    std::map<std::string, std::string> outcomes;
    std::regex testcase(R"re(<testcase [^>]*name="([^"]*)"[^>]*?(/?)>)re");
    for (auto it = std::sregex_iterator(xml.begin(), xml.end(), testcase); it != std::sregex_iterator(); ++it) {
        std::string name = (*it)[1], body;
        if ((*it)[2] != "/") body = xml.substr(size_t(it->position() + it->length()));
        body = body.substr(0, body.find("</testcase>"));
        outcomes[name] = body.find("<failure") != std::string::npos ? "failure"
                         : body.find("<error") != std::string::npos ? "error"
                                                                    : "pass";
    }
    return outcomes;
}

/// Pooled z per case from the summary lines `vkrt regress` prints.
std::map<std::string, double> pooledZ(const std::string& output)
{
    std::map<std::string, double> z;
    std::regex line(
        R"((\S+)\s+(Pass|Fail|Flake|KnownFlake|ExpectedFail|UnexpectedPass)\s+\S+% pass\s+pooled z ([-+0-9.]+))");
    for (auto it = std::sregex_iterator(output.begin(), output.end(), line); it != std::sregex_iterator(); ++it)
        z[(*it)[1]] = std::stod((*it)[3]);
    return z;
}

/// Status per case of a results.csv or failures.csv (deqp-runner's
/// `test,status,duration` lines, no header); every line must have that form.
std::map<std::string, std::string> csvStatuses(const fs::path& path)
{
    std::map<std::string, std::string> statuses;
    std::istringstream in(readFile(path));
    const std::regex form(
        R"(([^,]+),(Pass|Fail|Crash|Timeout|Flake|Skip|ExpectedFail|UnexpectedPass|KnownFlake),[0-9]+\.[0-9]{3})");
    std::smatch m;
    for (std::string line; std::getline(in, line);) {
        EXPECT_TRUE(std::regex_match(line, m, form)) << path << ": " << line;
        if (m.size() == 3) statuses[m[1]] = m[2];
    }
    return statuses;
}

/// Sets an environment variable (a test hook) for the lifetime of this object.
class ScopedEnvironment {
public:
    ScopedEnvironment(const char* name, const std::string& value) : m_name(name) { setenv(name, value.c_str(), 1); }
    ~ScopedEnvironment() { unsetenv(m_name); }
    ScopedEnvironment(const ScopedEnvironment&) = delete;
    ScopedEnvironment& operator=(const ScopedEnvironment&) = delete;

private:
    const char* m_name;
};

/// Smallest m with P(X > m) < tail for X ~ Binomial(n, p).
int binomialUpperBound(int n, double p, double tail)
{
    double cumulative = 0.0;
    for (int k = 0; k <= n; ++k) {
        cumulative += std::exp(std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0) +
                               k * std::log(p) + (n - k) * std::log1p(-p));
        if (1.0 - cumulative < tail) return k;
    }
    return n;
}

class RegressCli : public ::testing::Test {
protected:
    void SetUp() override
    {
        m_dir = freshTempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
        setenv("VKRT_CACHE_DIR", testCacheDir().c_str(), 1);
    }
    fs::path m_dir;

    static std::vector<std::string> deviceArgs()
    {
        const char* device = std::getenv("VKRT_TEST_DEVICE");
        return device ? std::vector<std::string>{"--device", device} : std::vector<std::string>{};
    }

    ProcessResult regress(std::vector<std::string> args)
    {
        args.insert(args.begin(), "regress");
        for (const std::string& a : deviceArgs()) args.push_back(a);
        return runVkrt(args);
    }

    fs::path writeManifest(const std::vector<ManifestCase>& cases, const std::string& suiteLines = "")
    {
        fs::path path = m_dir / "suite.toml";
        writeText(path, manifestText(cases, suiteLines));
        return path;
    }

    /// A copy of a shipped reference folder that a test may damage.
    fs::path copyReference(const std::string& name)
    {
        fs::path copy = m_dir / "references" / name;
        fs::create_directories(copy);
        for (const char* file : {"mean.exr", "variance.exr"})
            fs::copy_file(kSource / "tests/references" / name / file, copy / file);
        return copy;
    }
};

/// Bad input: exit 2 (never 0, never 4 = "a case failed", never a signal),
/// with every expected fragment in the message.
void expectInputError(const ProcessResult& r, const std::vector<std::string>& fragments)
{
    EXPECT_EQ(r.exitCode, 2) << r.output;
    for (const std::string& f : fragments) EXPECT_NE(r.output.find(f), std::string::npos) << f << "\n" << r.output;
}

// ------------------------------------------------------------ deliberate bias

// As ctest runs the suite on a clean build: --junit inside a --report-dir that
// does not exist yet. The output checks run before any case, so the report
// directory must be made before them (a clean clone failed here).
TEST_F(RegressCli, JunitInsideAReportDirThatDoesNotExistYet)
{
    const fs::path report = m_dir / "not" / "yet" / "there";
    ProcessResult r = regress(
        {"--filter", "seed/baseline", "--junit", (report / "junit.xml").string(), "--report-dir", report.string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(junitOutcomes(report / "junit.xml")["seed/baseline"], "pass") << r.output;
    EXPECT_TRUE(fs::exists(report / "report.md"));
}

// VKRT_TEST_FRESNEL_SCALE=1.02 (shaders/lib/fresnel.glsl) makes every dielectric
// reflect 2 % more. The cases whose image is dominated by a Fresnel term must
// fail: kappa-halfspace shows only the Fresnel reflection of an opaque glass
// half-space (green and blue are F itself), kappa-shadow lights a floor
// through a slab with (1 - F)^2. The cases without a dielectric must pass:
// they render the same kernels' other code bit for bit.
TEST_F(RegressCli, FresnelBiasFailsTheGlassCasesOnly)
{
    fs::path junit = m_dir / "junit.xml", report = m_dir / "report";
    ProcessResult r = regress({"--filter", "extreme/kappa-", "--filter", "seed/baseline", "--filter",
                               "extreme/degenerate-lights", "--kernel-define", "VKRT_TEST_FRESNEL_SCALE=1.02",
                               "--junit", junit.string(), "--report-dir", report.string()});
    EXPECT_EQ(r.exitCode, 4) << r.output;
    std::map<std::string, std::string> outcome = junitOutcomes(junit);
    EXPECT_EQ(outcome.size(), 4u) << r.output;
    EXPECT_EQ(outcome["extreme/kappa-halfspace"], "failure") << r.output;
    EXPECT_EQ(outcome["extreme/kappa-shadow"], "failure") << r.output;
    EXPECT_EQ(outcome["seed/baseline"], "pass") << r.output;
    EXPECT_EQ(outcome["extreme/degenerate-lights"], "pass") << r.output;
    // The report names the hook and shows the failures' images.
    std::string md = readFile(report / "report.md");
    EXPECT_NE(md.find("VKRT_TEST_FRESNEL_SCALE=1.02"), std::string::npos);
    for (const char* suffix : {"reference.png", "result.png", "difference.png", "significance.png", "result.exr"})
        EXPECT_TRUE(fs::exists(report / (std::string("extreme_kappa-halfspace-") + suffix))) << suffix;
    EXPECT_FALSE(fs::exists(report / "seed_baseline-result.png"));
}

// The suite's power in CI (docs/regress.md, "injected faults"): a 5 % error in
// every float multiply the driver runs is caught by both glass cases, and the
// legal variation `contract` (products fused into adds where SPIR-V allows it:
// what Mesa 26 does and Mesa 25 does not) passes them; a memory fault (loads
// that read the next element) fails both. The fault reaches the children, and
// report.md and the JUnit file record it.
TEST_F(RegressCli, AnInjectedFaultIsCaughtAndALegalContractionIsNot)
{
    fs::path junit = m_dir / "junit.xml", report = m_dir / "faulty";
    ProcessResult r = regress({"--filter", "extreme/kappa-", "--inject", "scale:FMul:0.05", "--junit", junit.string(),
                               "--report-dir", report.string()});
    EXPECT_EQ(r.exitCode, 4) << r.output;
    std::map<std::string, std::string> outcome = junitOutcomes(junit);
    EXPECT_EQ(outcome.size(), 2u) << r.output;
    EXPECT_EQ(outcome["extreme/kappa-halfspace"], "failure") << r.output;
    EXPECT_EQ(outcome["extreme/kappa-shadow"], "failure") << r.output;
    EXPECT_NE(readFile(report / "report.md").find("scale:FMul:0.05"), std::string::npos);
    EXPECT_NE(readFile(junit).find("scale:FMul:0.05"), std::string::npos);

    r = regress({"--filter", "extreme/kappa-", "--inject", "contract", "--report-dir", (m_dir / "legal").string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(readFile(m_dir / "legal" / "report.md").find("contract"), std::string::npos);

    // A memory fault: every storage-buffer element load reads the next element.
    fs::path memoryJunit = m_dir / "memory.xml";
    r = regress({"--filter", "extreme/kappa-", "--inject", "neighbour-load", "--junit", memoryJunit.string()});
    EXPECT_EQ(r.exitCode, 4) << r.output;
    outcome = junitOutcomes(memoryJunit);
    EXPECT_EQ(outcome["extreme/kappa-halfspace"], "failure") << r.output;
    EXPECT_EQ(outcome["extreme/kappa-shadow"], "failure") << r.output;
}

// ------------------------------------------------------------ seed consistency

// Ten runs of a small suite with seed offsets 1..10. Each case of a correct
// renderer fails with probability at most alpha = 0.01 (the pooled test's own
// alpha is 0.001; the per-value rule almost never fails), so the failures over
// all runs are at most Binomial(runs x cases, 0.01): allow the count that such
// a variable exceeds with probability below 1e-3. A failing case is re-run
// with a fresh seed, so a first attempt that failed shows as a Flake (or, if
// the re-run failed too, a Fail): both count. The seed must really change the
// noise: the pooled z of a case differs between runs.
TEST_F(RegressCli, RepeatedSeedsFailNoMoreOftenThanAlphaAllows)
{
    std::vector<ManifestCase> cases = {shipped("seed/baseline", 16, "width = 96\nheight = 72"),
                                       shipped("extreme/kappa-shadow", 32),
                                       shipped("seed/area-light", 16, "width = 96\nheight = 72"),
                                       shipped("extreme/ior-huge", 32)};
    fs::path suite = writeManifest(cases, "alpha = 0.01");
    constexpr int kRuns = 10;
    int failures = 0;
    std::map<std::string, std::vector<double>> zs;
    for (int offset = 1; offset <= kRuns; ++offset) {
        fs::path report = m_dir / ("run" + std::to_string(offset));
        ProcessResult r = regress(
            {"--suite", suite.string(), "--seed-offset", std::to_string(offset), "--report-dir", report.string()});
        ASSERT_TRUE(r.exitCode == 0 || r.exitCode == 4) << r.output;
        std::map<std::string, std::string> status = csvStatuses(report / "results.csv");
        ASSERT_EQ(status.size(), cases.size()) << r.output;
        for (const auto& [name, result] : status) {
            ASSERT_TRUE(result == "Pass" || result == "Fail" || result == "Flake") << name << " " << result << "\n"
                                                                                   << r.output;
            failures += result != "Pass";
        }
        EXPECT_EQ(r.exitCode == 4,
                  std::any_of(status.begin(), status.end(), [](auto& o) { return o.second == "Fail"; }));
        for (const auto& [name, z] : pooledZ(r.output)) zs[name].push_back(z);
    }
    int allowed = binomialUpperBound(kRuns * int(cases.size()), 0.01, 1e-3);
    std::printf("[ measured ] %d failing first attempts in %d runs x %zu cases (allowed %d)\n", failures, kRuns,
                cases.size(), allowed);
    EXPECT_LE(failures, allowed);
    for (const auto& [name, values] : zs) {
        ASSERT_EQ(values.size(), size_t(kRuns)) << name;
        EXPECT_NE(*std::min_element(values.begin(), values.end()), *std::max_element(values.begin(), values.end()))
            << name << ": the seed offset does not change the render";
    }
}

// ------------------------------------------------------------ bad input

TEST_F(RegressCli, MissingReferenceNamesTheFileAndHowToMakeIt)
{
    ManifestCase c = shipped("extreme/kappa-shadow", 8);
    c.reference = m_dir / "no-such-reference";
    fs::path suite = writeManifest({c});
    ProcessResult r = regress({"--suite", suite.string(), "--junit", (m_dir / "j.xml").string()});
    expectInputError(r, {"extreme/kappa-shadow", (c.reference / "mean.exr").string(),
                         "vkrt regress --update --filter extreme/kappa-shadow"});
    EXPECT_FALSE(fs::exists(m_dir / "j.xml")) << "nothing renders when a reference is missing";
}

TEST_F(RegressCli, CorruptReferenceNamesTheFile)
{
    ManifestCase c = shipped("extreme/kappa-shadow", 8);
    c.reference = copyReference("extreme/kappa-shadow");
    // EXR's magic number, then garbage: the header cannot be parsed.
    writeText(c.reference / "variance.exr", "\x76\x2f\x31\x01 this is not an EXR file \xff\xfe");
    ProcessResult r = regress({"--suite", writeManifest({c}).string()});
    expectInputError(r, {(c.reference / "variance.exr").string(), "not a readable EXR"});
    // A valid EXR holding impossible values is refused too.
    Image negative(64, 48);
    std::fill(negative.rgb.begin(), negative.rgb.end(), -1.0f);
    writeExr(c.reference / "variance.exr", negative, {});
    expectInputError(regress({"--suite", writeManifest({c}).string()}),
                     {(c.reference / "variance.exr").string(), "negative or non-finite"});
}

TEST_F(RegressCli, MismatchedResolutionNamesBothSizes)
{
    fs::path suite = writeManifest({shipped("extreme/kappa-shadow", 8, "width = 32\nheight = 24")});
    ProcessResult r = regress({"--suite", suite.string()});
    expectInputError(r, {"extreme/kappa-shadow", "mean.exr", "is 64x48 but the case renders 32x24"});
}

// A case's width/height pass the scene parser's checks, naming suite and case.
TEST_F(RegressCli, CaseResolutionIsValidatedLikeTheSceneFile)
{
    fs::path suite = writeManifest({shipped("extreme/kappa-shadow", 8, "width = 99999\nheight = 24")});
    ProcessResult r = regress({"--suite", suite.string()});
    expectInputError(r,
                     {suite.string() + ": case extreme/kappa-shadow: width: must be between 1 and 16384, got 99999"});
}

TEST_F(RegressCli, UnusableDriverManifestIsNamed)
{
    fs::path suite = writeManifest({shipped("extreme/kappa-shadow", 8)});
    expectInputError(regress({"--suite", suite.string(), "--driver", "/nonexistent.json"}),
                     {"--driver /nonexistent.json", "no such file"});
    writeText(m_dir / "not-icd.json", "{\"file_format_version\": \"1.0.0\"}\n");
    expectInputError(regress({"--suite", suite.string(), "--driver", (m_dir / "not-icd.json").string()}),
                     {"not-icd.json", "not a Vulkan ICD manifest"});
    writeText(m_dir / "lost.json", "{\"file_format_version\": \"1.0.0\", \"ICD\": {\"library_path\": "
                                   "\"./build/libvulkan_lvp.so\", \"api_version\": \"1.3.0\"}}\n");
    expectInputError(regress({"--suite", suite.string(), "--driver", (m_dir / "lost.json").string()}),
                     {"lost.json", (m_dir / "build/libvulkan_lvp.so").string(), "does not exist"});
    // A bare library name is the dynamic linker's to find; when it cannot, the
    // loader fails: a driver failure (exit 1) that still names the manifest.
    writeText(m_dir / "bare.json", "{\"file_format_version\": \"1.0.0\", \"ICD\": {\"library_path\": "
                                   "\"libvkrt_no_such_driver.so\", \"api_version\": \"1.3.0\"}}\n");
    ProcessResult bare = regress({"--suite", suite.string(), "--driver", (m_dir / "bare.json").string()});
    EXPECT_EQ(bare.exitCode, 1) << bare.output;
    EXPECT_NE(bare.output.find("--driver " + (m_dir / "bare.json").string() + ": the Vulkan loader could not use"),
              std::string::npos)
        << bare.output;
}

TEST_F(RegressCli, ManifestErrorsNameFileLineAndColumn)
{
    ManifestCase c = shipped("extreme/kappa-shadow", 8);
    fs::path suite = m_dir / "suite.toml";
    std::string good = manifestText({c});
    // A misspelt key: reported where it stands, with the key it resembles.
    writeText(suite, good + "[[case]]\nname = \"x\"\nscene = \"" + c.scene.string() +
                         "\"\nreference = \"r\"\n"
                         "reference_source = \"vkrt\"\nreference_spp = 16\nsp = 4\n");
    int line = int(std::count(good.begin(), good.end(), '\n')) + 7;
    expectInputError(regress({"--suite", suite.string()}),
                     {suite.string() + ":" + std::to_string(line) + ":1", "unknown key 'sp'", "did you mean 'spp'"});
    // A missing field: reported at its case's table.
    writeText(suite, "[[case]]\nname = \"x\"\nscene = \"" + c.scene.string() +
                         "\"\nreference_source = \"vkrt\"\n"
                         "reference_spp = 16\nspp = 4\n");
    expectInputError(regress({"--suite", suite.string()}), {suite.string() + ":", "missing required key 'reference'"});
    // A value out of range, and a TOML syntax error.
    writeManifest({c}, "alpha = 1.5");
    expectInputError(regress({"--suite", suite.string()}), {suite.string() + ":3:9", "suite.alpha", "(0, 1)"});
    writeText(suite, "[suite\n");
    expectInputError(regress({"--suite", suite.string()}), {suite.string() + ":1:", "invalid TOML"});
    expectInputError(regress({"--suite", (m_dir / "nope.toml").string()}), {"--suite", "nope.toml", "no such file"});
    expectInputError(regress({"--suite", writeManifest({c}).string(), "--filter", "no-such-case"}),
                     {"--filter no-such-case", "no case"});
}

// Case names are what a child is started with and what every report writes
// unescaped: an empty name once made a child take itself for the parent and
// start the suite again (hundreds of processes within seconds).
TEST_F(RegressCli, CaseNamesAreCheckedWhereTheyStand)
{
    ManifestCase c = shipped("extreme/kappa-shadow", 8);
    const fs::path suite = m_dir / "suite.toml";
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"", "a case name cannot be empty"},
        {"x\\u0001y", "not 0x01"},
        {"a,Fail", "not ','"},
        {"with space", "not ' '"},
        {std::string(97, 'n'), "at most 96 bytes, this one 97"},
    };
    for (const auto& [name, message] : bad) {
        c.name = name;
        writeText(suite, manifestText({c}));
        // The name's line: [suite], seed, blank, [[case]], name.
        const ProcessResult result = regress({"--suite", suite.string()});
        expectInputError(result, {suite.string() + ":5:", "case[0].name", message});
    }
    // A child is a child whatever its case name: it never runs the suite.
    c.name = "ok";
    writeText(suite, manifestText({c}));
    const ProcessResult child = regress({"--suite", suite.string(), "--run-case", ""});
    expectInputError(child, {"--run-case  needs --case-result FILE"});
}

// A manifest naming the Vulkan loader as the driver hung the parent in
// vkCreateInstance for good; now the driver is opened in a child first, under
// the case timeout, and the run ends as a device failure naming it.
TEST_F(RegressCli, ADriverThatHangsOpeningIsATimeoutNotAHang)
{
    writeText(m_dir / "loader.json", "{\"file_format_version\": \"1.0.0\", \"ICD\": {\"library_path\": "
                                     "\"libvulkan.so.1\", \"api_version\": \"1.3.0\"}}\n");
    const auto start = std::chrono::steady_clock::now();
    const ProcessResult r = regress({"--suite", writeManifest({shipped("extreme/kappa-shadow", 8)}).string(),
                                     "--driver", (m_dir / "loader.json").string(), "--case-timeout", "2"});
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("loader.json: opening the driver did not return within 2 s"), std::string::npos)
        << r.output;
}

TEST_F(RegressCli, CaseTimeoutMustBeAPositiveFiniteNumber)
{
    const fs::path suite = writeManifest({shipped("extreme/kappa-shadow", 8)});
    for (const std::string value : {"nan", "inf", "-1", "0", "1e999", "3s"}) {
        const ProcessResult result = regress({"--suite", suite.string(), "--case-timeout", value});
        EXPECT_NE(result.exitCode, 0) << value;
        EXPECT_NE(result.output.find("--case-timeout"), std::string::npos) << value << ": " << result.output;
        EXPECT_NE(result.output.find("positive finite number of seconds"), std::string::npos)
            << value << ": " << result.output;
    }
}

// ------------------------------------------------------------ --update

// --update renders the vkrt-made references (never a Mitsuba one, never with a
// test hook), records how, and the suite then passes against them.
TEST_F(RegressCli, UpdateMakesReferencesTheSuiteAccepts)
{
    ManifestCase made = shipped("extreme/kappa-shadow", 16, "width = 32\nheight = 24");
    made.reference = m_dir / "made";
    made.referenceSpp = 256;
    ManifestCase mitsuba = shipped("extreme/tir", 16);
    mitsuba.reference = copyReference("extreme/tir");
    mitsuba.source = "mitsuba";
    std::string before = readFile(mitsuba.reference / "mean.exr");
    fs::path suite = writeManifest({made, mitsuba});

    expectInputError(regress(
                         {"--suite", suite.string(), "--update", "--kernel-define", "VKRT_TEST_FRESNEL_SCALE=1.02"}),
                     {"--update", "--kernel-define"});
    EXPECT_FALSE(fs::exists(made.reference));

    ProcessResult update = regress({"--suite", suite.string(), "--update"});
    ASSERT_EQ(update.exitCode, 0) << update.output;
    ExrContents mean = readExr(made.reference / "mean.exr");
    EXPECT_EQ(mean.image.width, 32u);
    EXPECT_EQ(std::get<int64_t>(mean.metadata.at("spp")), 256);
    EXPECT_EQ(readExr(made.reference / "variance.exr").image.height, 24u);
    std::string readme = readFile(made.reference / "README.md");
    EXPECT_NE(readme.find("scenes/extreme/kappa-shadow.toml"), std::string::npos) << readme;
    EXPECT_NE(readme.find("--filter extreme/kappa-shadow"), std::string::npos) << readme;
    EXPECT_EQ(readFile(mitsuba.reference / "mean.exr"), before) << "a Mitsuba reference was overwritten";

    ProcessResult run = regress({"--suite", suite.string()});
    EXPECT_EQ(run.exitCode, 0) << run.output;
}

// A case whose scene reads a texture from its own reference folder: --update
// overwrote the texture with the new reference (exit 0). Refused now, naming
// both, before any case is rendered.
TEST_F(RegressCli, UpdateRefusesAReferenceThatIsAnInputOfItsCase)
{
    fs::create_directories(m_dir / "ref");
    Image texture(2, 2);
    for (float& v : texture.rgb) v = 0.5f;
    writeExr(m_dir / "ref" / "mean.exr", texture, {});
    const std::string before = readFile(m_dir / "ref" / "mean.exr");
    writeText(m_dir / "textured.toml", R"([camera]
eye = [0, 0, 4]
target = [0, 0, 0]
fov = 40
width = 16
height = 12
[materials.wood]
type = "lambert"
albedo = { texture = "ref/mean.exr" }
[[objects]]
shape = "sphere"
center = [0, 0, 0]
radius = 1
material = "wood"
[[lights]]
type = "point"
position = [0, 3, 3]
intensity = [10, 10, 10]
)");
    ManifestCase first = shipped("extreme/kappa-shadow", 16, "width = 32\nheight = 24");
    first.reference = m_dir / "made";
    const ManifestCase textured{"textured", m_dir / "textured.toml", m_dir / "ref", 16, 4};
    const fs::path suite = writeManifest({first, textured});
    expectInputError(regress({"--suite", suite.string(), "--update"}),
                     {(m_dir / "ref" / "mean.exr").string() + ": the reference of case textured (mean) is the same "
                                                              "file as a texture the scene loads"});
    EXPECT_EQ(readFile(m_dir / "ref" / "mean.exr"), before) << "the texture was overwritten";
    EXPECT_FALSE(fs::exists(first.reference)) << "a case was rendered before the refusal";
}

// ------------------------------------------------------------ Ctrl-C

/// Processes whose command line mentions `text` (the children of a run name its suite).
int processesMentioning(const std::string& text)
{
    int count = 0;
    std::error_code error; // processes come and go while this reads
    for (const auto& entry : fs::directory_iterator("/proc", error)) {
        std::string cmdline = readFile(entry.path() / "cmdline");
        std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
        count += cmdline.find(text) != std::string::npos;
    }
    return count;
}

// SIGINT once the first case has finished (its JUnit file appears): the run
// stops within a submission of the second case, exits 130, and the JUnit and
// report files keep the first case's result. The second case's child process
// is gone with it.
TEST_F(RegressCli, InterruptKeepsFinishedCasesOnDisk)
{
    ManifestCase quick = shipped("extreme/kappa-shadow", 8);
    ManifestCase endless = shipped("extreme/degenerate-lights", 1000000);
    fs::path suite = writeManifest({quick, endless}), junit = m_dir / "junit.xml", report = m_dir / "report";
    std::vector<std::string> args = {"vkrt",    "regress",      "--suite",      suite.string(),
                                     "--junit", junit.string(), "--report-dir", report.string()};
    for (const std::string& a : deviceArgs()) args.push_back(a);
    pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        std::vector<char*> argv;
        for (std::string& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        execv(VKRT_BINARY, argv.data());
        _exit(127);
    }
    auto start = std::chrono::steady_clock::now();
    while (!fs::exists(junit) && std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    bool firstFinished = fs::exists(junit);
    std::this_thread::sleep_for(std::chrono::milliseconds(500)); // into the second case
    auto interrupted = std::chrono::steady_clock::now();
    kill(child, SIGINT);
    int status = 0;
    waitpid(child, &status, 0);
    double stopSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - interrupted).count();
    ASSERT_TRUE(firstFinished) << "the first case never finished";
    ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
    EXPECT_EQ(WEXITSTATUS(status), 130);
    EXPECT_LT(stopSeconds, 10.0) << "Ctrl-C must stop the case in progress";
    std::map<std::string, std::string> outcome = junitOutcomes(junit);
    EXPECT_EQ(outcome, (std::map<std::string, std::string>{{"extreme/kappa-shadow", "pass"}}));
    std::string md = readFile(report / "report.md");
    EXPECT_NE(md.find("extreme/kappa-shadow"), std::string::npos);
    EXPECT_NE(md.find("1 of 2 cases: **interrupted**"), std::string::npos) << md;
    EXPECT_EQ(md.find("extreme/degenerate-lights |"), std::string::npos) << md;
    EXPECT_EQ(processesMentioning("--run-case extreme/degenerate-lights"), 0) << "a child outlived Ctrl-C";
}

// ------------------------------------------------------------ the runner (deqp-runner's shape)

/// Three quick cases at 64 x 48 (white furnaces and a camera inside glass: well under a second each).
std::vector<ManifestCase> quickCases()
{
    return {shipped("extreme/tir", 32), shipped("extreme/camera-in-glass", 32), shipped("extreme/ior-one", 32)};
}

double secondsSince(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// VKRT_TEST_CRASH_CASE makes the child for one case die of SIGSEGV: that case
// is a Crash (after its re-run crashed too), every other case still runs and
// passes, the run fails (exit 4), and the child's output is kept.
TEST_F(RegressCli, CrashingCaseIsACrashAndTheOthersStillPass)
{
    ScopedEnvironment crash("VKRT_TEST_CRASH_CASE", "extreme/camera-in-glass");
    const fs::path report = m_dir / "report", junit = m_dir / "junit.xml";
    ProcessResult r = regress({"--suite", writeManifest(quickCases()).string(), "--jobs", "2", "--report-dir",
                               report.string(), "--junit", junit.string()});
    EXPECT_EQ(r.exitCode, 4) << r.output;
    const std::map<std::string, std::string> expected{{"extreme/tir", "Pass"},
                                                      {"extreme/camera-in-glass", "Crash"},
                                                      {"extreme/ior-one", "Pass"}};
    EXPECT_EQ(csvStatuses(report / "results.csv"), expected) << r.output;
    EXPECT_EQ(csvStatuses(report / "failures.csv"),
              (std::map<std::string, std::string>{{"extreme/camera-in-glass", "Crash"}}));
    EXPECT_EQ(junitOutcomes(junit)["extreme/camera-in-glass"], "error");
    EXPECT_NE(r.output.find("seed 1: Crash (killed by SIGSEGV"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("re-run seed 65537: Crash (killed by SIGSEGV"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(report / "extreme_camera-in-glass-attempt1.log"));
    const std::string md = readFile(report / "report.md");
    EXPECT_NE(md.find("| extreme/camera-in-glass | **Crash** |"), std::string::npos) << md;
    EXPECT_NE(md.find("| extreme/tir | Pass |"), std::string::npos) << md;
}

// VKRT_TEST_HANG_CASE makes one case never finish: with --case-timeout 3 it is
// killed after 3 s (and its re-run after 3 more) and is a Timeout; the others pass.
TEST_F(RegressCli, HangingCaseIsATimeoutWithinTheCaseTimeout)
{
    ScopedEnvironment hang("VKRT_TEST_HANG_CASE", "extreme/tir");
    const fs::path report = m_dir / "report";
    const auto start = std::chrono::steady_clock::now();
    ProcessResult r = regress({"--suite", writeManifest(quickCases()).string(), "--jobs", "2", "--case-timeout", "3",
                               "--report-dir", report.string()});
    const double seconds = secondsSince(start);
    EXPECT_EQ(r.exitCode, 4) << r.output;
    const std::map<std::string, std::string> expected{{"extreme/tir", "Timeout"},
                                                      {"extreme/camera-in-glass", "Pass"},
                                                      {"extreme/ior-one", "Pass"}};
    EXPECT_EQ(csvStatuses(report / "results.csv"), expected) << r.output;
    EXPECT_NE(r.output.find("ran past its 3 s timeout and was killed"), std::string::npos) << r.output;
    // Two attempts of 3 s, and the other cases beside them: far below the default timeout (120 s and more).
    EXPECT_LT(seconds, 45.0) << r.output;
    EXPECT_GE(seconds, 6.0) << "the timeout did not wait for the case";
}

// VKRT_TEST_FLAKY_CASE fails one case's first attempt only: the re-run with a
// fresh seed passes, so the case is a Flake (both seeds reported) and the run
// passes; with the case in --flakes it is a KnownFlake. The second run is in
// this process (--jobs 0): the re-run rule does not depend on child processes.
TEST_F(RegressCli, FailThenPassIsAFlake)
{
    ScopedEnvironment flaky("VKRT_TEST_FLAKY_CASE", "extreme/tir");
    const fs::path suite = writeManifest(quickCases()), report = m_dir / "report";
    ProcessResult r = regress({"--suite", suite.string(), "--report-dir", report.string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(csvStatuses(report / "results.csv")["extreme/tir"], "Flake") << r.output;
    EXPECT_EQ(readFile(report / "failures.csv"), "") << "a flake is not a failure of the run";
    const std::string md = readFile(report / "report.md");
    EXPECT_NE(md.find("seed 1: Fail [VKRT_TEST_FLAKY_CASE"), std::string::npos) << md;
    EXPECT_NE(md.find("re-run seed 65537: Pass"), std::string::npos) << md;

    writeText(m_dir / "flakes.txt", "# white furnaces are never flaky, but this one is told to be\nextreme/t.r$\n");
    r = regress({"--suite", suite.string(), "--report-dir", report.string(), "--flakes",
                 (m_dir / "flakes.txt").string(), "--jobs", "0"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(csvStatuses(report / "results.csv")["extreme/tir"], "KnownFlake") << r.output;
}

// deqp-runner's baseline semantics: a case failing as the baseline says is an
// ExpectedFail (the run passes), a listed case that passes is an
// UnexpectedPass (the run fails), a skipped case is not run (its hang hook
// never fires), and failures.csv holds only what failed the run.
TEST_F(RegressCli, BaselineDecidesWhatIsUnexpected)
{
    ScopedEnvironment crash("VKRT_TEST_CRASH_CASE", "extreme/camera-in-glass");
    ScopedEnvironment hang("VKRT_TEST_HANG_CASE", "extreme/ior-one");
    const fs::path suite = writeManifest(quickCases()), report = m_dir / "report";
    const fs::path fails = m_dir / "fails.txt", skips = m_dir / "skips.txt";
    writeText(fails, "# the driver's known bugs\nextreme/camera-in-glass,Crash\nextreme/tir,Fail\n");
    writeText(skips, "ior-one\n");
    ProcessResult r = regress({"--suite", suite.string(), "--report-dir", report.string(), "--baseline", fails.string(),
                               "--skips", skips.string(), "--case-timeout", "30"});
    EXPECT_EQ(r.exitCode, 4) << r.output;
    const std::map<std::string, std::string> expected{{"extreme/tir", "UnexpectedPass"},
                                                      {"extreme/camera-in-glass", "ExpectedFail"},
                                                      {"extreme/ior-one", "Skip"}};
    EXPECT_EQ(csvStatuses(report / "results.csv"), expected) << r.output;
    EXPECT_EQ(csvStatuses(report / "failures.csv"),
              (std::map<std::string, std::string>{{"extreme/tir", "UnexpectedPass"}}));
    EXPECT_EQ(r.output.find("re-run"), std::string::npos) << "an expected crash is not re-run\n" << r.output;

    // The baseline without the case that passes now: nothing is unexpected.
    writeText(fails, "extreme/camera-in-glass,Crash\n");
    r = regress({"--suite", suite.string(), "--report-dir", report.string(), "--baseline", fails.string(), "--skips",
                 skips.string(), "--case-timeout", "30"});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(csvStatuses(report / "results.csv")["extreme/tir"], "Pass");
    EXPECT_EQ(csvStatuses(report / "results.csv")["extreme/camera-in-glass"], "ExpectedFail");
    EXPECT_EQ(readFile(report / "failures.csv"), "");
}

// Bad lines of the baseline files are input errors naming file:line, before
// anything renders; so are a bad --accel and a misplaced --jobs 0.
TEST_F(RegressCli, BadBaselineLinesNameFileAndLine)
{
    const fs::path suite = writeManifest(quickCases()), report = m_dir / "report";
    const fs::path fails = m_dir / "fails.txt", skips = m_dir / "skips.txt";
    writeText(fails, "# fine so far\nextreme/tir,Fail\nextreme/ior-one Fail\n");
    expectInputError(regress(
                         {"--suite", suite.string(), "--baseline", fails.string(), "--report-dir", report.string()}),
                     {fails.string() + ":3: expected 'case-name,Status'"});
    EXPECT_FALSE(fs::exists(report / "results.csv")) << "nothing runs on bad input";
    writeText(fails, "extreme/tir,Failed\n");
    expectInputError(regress({"--suite", suite.string(), "--baseline", fails.string()}),
                     {fails.string() + ":1: status 'Failed' cannot be expected"});
    writeText(skips, "\n\n[unclosed\n");
    expectInputError(regress({"--suite", suite.string(), "--skips", skips.string()}),
                     {skips.string() + ":3: not a regular expression"});
    expectInputError(regress({"--suite", suite.string(), "--flakes", (m_dir / "none.txt").string()}),
                     {"--flakes", "none.txt", "no such file"});
    expectInputError(regress({"--suite", suite.string(), "--accel", "bvh"}), {"--accel bvh", "own, driver or auto"});
}

// --accel reaches every case (the report says which) and the children.
TEST_F(RegressCli, AccelChoiceIsAcceptedAndReported)
{
    const fs::path report = m_dir / "report";
    ProcessResult r = regress({"--suite", writeManifest({shipped("extreme/tir", 16)}).string(), "--accel", "own",
                               "--report-dir", report.string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(readFile(report / "report.md").find("- accel: own"), std::string::npos);
}

/// The system's lavapipe ICD manifest, or empty if there is none.
fs::path systemLavapipeManifest()
{
    for (const char* dir : {"/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d"}) {
        std::error_code error;
        for (const auto& entry : fs::directory_iterator(dir, error))
            if (entry.path().filename().string().rfind("lvp_icd", 0) == 0) return entry.path();
    }
    return {};
}

// The same driver twice: every case passes on both, the two images agree (the
// same seed on the same driver gives the same image), and compare.csv has the
// render-time ratio B/A of each case.
TEST_F(RegressCli, CompareDriversWithTheSameDriverTwicePasses)
{
    const fs::path icd = systemLavapipeManifest();
    if (icd.empty()) GTEST_SKIP() << "no lavapipe ICD manifest in /usr/share/vulkan/icd.d";
    const fs::path report = m_dir / "report";
    ProcessResult r =
        regress({"--suite", writeManifest({shipped("extreme/tir", 16), shipped("extreme/ior-one", 32)}).string(),
                 "--compare-drivers", icd.string(), icd.string(), "--report-dir", report.string()});
    EXPECT_EQ(r.exitCode, 0) << r.output;
    std::istringstream csv(readFile(report / "compare.csv"));
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line, "case,statusA,statusB,agree,secondsA,secondsB,ratio");
    const std::regex row(R"(extreme/(tir|ior-one),Pass,Pass,yes,([0-9.]+),([0-9.]+),([0-9]+\.[0-9]{3}))");
    int rows = 0;
    for (std::smatch m; std::getline(csv, line); ++rows) {
        ASSERT_TRUE(std::regex_match(line, m, row)) << line;
        const double a = std::stod(m[2]), b = std::stod(m[3]), ratio = std::stod(m[4]);
        EXPECT_GT(a, 0.0);
        // The times are written to 0.1 ms, the ratio to 0.001: allow for that rounding.
        EXPECT_NEAR(ratio, b / a, 0.0006 + ratio * (0.0001 / a + 0.0001 / b)) << line;
    }
    EXPECT_EQ(rows, 2);
    EXPECT_EQ(csvStatuses(report / "results.csv"),
              (std::map<std::string, std::string>{{"extreme/tir", "Pass"}, {"extreme/ior-one", "Pass"}}));
    const std::string md = readFile(report / "report.md");
    EXPECT_NE(md.find("B/A"), std::string::npos);
    EXPECT_NE(md.find("- A: `" + icd.string() + "`"), std::string::npos) << md;
    // Timing is fair by default: one render at a time.
    EXPECT_NE(md.find("- jobs: 1 (the timed renders ran one at a time"), std::string::npos) << md;
    expectInputError(regress({"--suite", writeManifest({shipped("extreme/tir", 16)}).string(), "--compare-drivers",
                              icd.string(), (m_dir / "missing.json").string()}),
                     {"--compare-drivers", "missing.json", "no such file"});
}

} // namespace
} // namespace vkrt::test
