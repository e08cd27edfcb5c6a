#include "regress/RegressionRun.h"

#include "app/Commands.h"
#include "io/AtomicFile.h"
#include "io/ExrFile.h"
#include "io/PngFile.h"
#include "regress/Suite.h"
#include "render/ErrorMetrics.h"
#include "render/Renderer.h"
#include "scene/SceneParser.h"
#include "util/Error.h"

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

constexpr uint32_t kReferenceSeed = 0x5eed5eed; // never a test seed

std::atomic<bool> g_stop{false};
extern "C" void onRegressInterrupt(int) { g_stop.store(true); }

struct CaseResult {
    std::string name;
    bool passed = false;
    bool slow = false;
    std::string error; ///< set when the case could not run
    ReferenceTestResult test;
    MeasuredError measured;
    double seconds = 0.0;
    double baseline = 0.0;
};

struct Reference {
    Image mean, variance;
};

Reference loadReference(const RegressionCase& c, uint32_t width, uint32_t height)
{
    fs::path meanPath = c.referenceDir / "mean.exr", variancePath = c.referenceDir / "variance.exr";
    for (const fs::path& p : {meanPath, variancePath})
        if (!fs::exists(p))
            throw InputError("case " + c.name + ": missing reference " + p.string() +
                             (c.source == ReferenceSource::Vkrt ? " (make it with vkrt regress --update)"
                                                                : " (make it with tools/make_reference.py)"));
    Reference r{readExr(meanPath).image, readExr(variancePath).image};
    for (const Image* image : {&r.mean, &r.variance})
        if (image->width != width || image->height != height)
            throw InputError("case " + c.name + ": reference is " + std::to_string(image->width) + "x" +
                             std::to_string(image->height) + " but the case renders " + std::to_string(width) + "x" +
                             std::to_string(height) + " (" + c.referenceDir.string() + ")");
    return r;
}

Scene caseScene(const RegressionCase& c)
{
    Scene scene = parseSceneFile(c.scene.string());
    if (c.width) scene.camera.width = *c.width;
    if (c.height) scene.camera.height = *c.height;
    return scene;
}

struct Rendered {
    Image mean, variance;
    double seconds = 0.0;
};

Rendered renderCase(const VulkanContext& context, const Scene& scene, uint32_t spp, uint32_t seed,
                    const std::vector<Define>& defines)
{
    RenderOptions options;
    options.seed = seed;
    options.variance = true;
    options.extraDefines = defines;
    Renderer renderer(context, scene, options);
    renderer.warmUp();
    auto start = std::chrono::steady_clock::now();
    for (uint32_t done = 0; done < spp;) {
        uint32_t batch = std::min(spp - done, 32u);
        renderer.renderFrames(batch);
        done += batch;
    }
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return {renderer.mean(), renderer.varianceOfMean(), seconds};
}

// ---------------------------------------------------------------- reports

Image differenceImage(const Image& a, const Image& b)
{
    Image d(a.width, a.height);
    float largest = 0.0f;
    for (size_t i = 0; i < d.rgb.size(); ++i) largest = std::max(largest, std::abs(a.rgb[i] - b.rgb[i]));
    for (size_t i = 0; i < d.rgb.size(); ++i) d.rgb[i] = largest > 0 ? std::abs(a.rgb[i] - b.rgb[i]) / largest : 0.0f;
    return d;
}

/// White where a value is significant: -log10(p) relative to the per-value threshold.
Image significanceImage(const ReferenceTestResult& t)
{
    Image s(t.pValues.width, t.pValues.height);
    double limit = -std::log10(std::erfc(t.threshold / std::sqrt(2.0)));
    for (size_t i = 0; i < s.rgb.size(); ++i)
        s.rgb[i] = float(std::min(1.0, -std::log10(std::max(1e-300, double(t.pValues.rgb[i]))) / limit));
    return s;
}

std::string safeName(std::string name)
{
    for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '_') ch = '_';
    return name;
}

void writeFailureImages(const fs::path& dir, const std::string& name, const Rendered& r, const Reference& ref,
                        const ReferenceTestResult& t)
{
    std::string base = safeName(name);
    writePng(dir / (base + "-reference.png"), ref.mean, 0.0f);
    writePng(dir / (base + "-result.png"), r.mean, 0.0f);
    writePng(dir / (base + "-difference.png"), differenceImage(r.mean, ref.mean), 0.0f);
    writePng(dir / (base + "-significance.png"), significanceImage(t), 0.0f);
    writeExr(dir / (base + "-result.exr"), r.mean, {}, {{"variance", r.variance}});
}

std::string markdownReport(const RegressionSuite& suite, const std::vector<CaseResult>& results,
                           const VulkanContext& context, const RegressOptions& options)
{
    std::ostringstream md;
    size_t failed = std::count_if(results.begin(), results.end(), [](const CaseResult& r) { return !r.passed; });
    md << "# vkrt regression report\n\n"
       << "- suite: `" << suite.path.string() << "`\n- device: " << context.deviceInfo().name << " ("
       << context.deviceInfo().driver << ")\n"
       << "- driver manifest: " << (options.driver.empty() ? "system default" : "`" + options.driver + "`") << "\n"
       << "- seed: " << suite.seed + options.seedOffset << "\n- rule: at least " << 100.0 * suite.minPass
       << " % of values pass a Sidak-corrected z-test at alpha " << suite.alpha << ", and |pooled z| within alpha "
       << suite.pooledAlpha << " (docs/regress.md)\n- result: **" << results.size() - failed << " passed, " << failed
       << " failed**\n\n| case | result | values passing | pooled z | smallest p | relMSE | seconds | baseline |\n"
       << "| --- | --- | --- | --- | --- | --- | --- | --- |\n";
    char line[512];
    for (const CaseResult& r : results) {
        if (!r.error.empty()) {
            md << "| " << r.name << " | **error** | " << r.error << " | | | | | |\n";
            continue;
        }
        std::snprintf(line, sizeof line, "| %s | %s%s | %.3f %% | %+.2f | %.3g | %.3g | %.2f | %s |\n", r.name.c_str(),
                      r.passed ? "pass" : "**FAIL**", r.slow ? " (slow)" : "", 100.0 * r.test.fractionPassed(),
                      r.test.pooledZ, r.test.minPValue, r.measured.relMse, r.seconds,
                      r.baseline > 0 ? std::to_string(r.baseline).substr(0, 5).c_str() : "-");
        md << line;
    }
    for (const CaseResult& r : results) {
        if (r.passed || !r.error.empty()) continue;
        std::string base = safeName(r.name);
        md << "\n## " << r.name << "\n\n| reference | result | difference | significance |\n| --- | --- | --- | --- |\n"
           << "| ![](" << base << "-reference.png) | ![](" << base << "-result.png) | ![](" << base
           << "-difference.png) | ![](" << base << "-significance.png) |\n";
    }
    return md.str();
}

std::string xmlEscape(const std::string& text)
{
    std::string out;
    for (char ch : text) {
        if (ch == '<') out += "&lt;";
        else if (ch == '>') out += "&gt;";
        else if (ch == '&') out += "&amp;";
        else if (ch == '"') out += "&quot;";
        else out += ch;
    }
    return out;
}

std::string junitReport(const std::vector<CaseResult>& results)
{
    std::ostringstream xml;
    size_t failures = 0, errors = 0;
    double total = 0;
    for (const auto& r : results) failures += !r.passed && r.error.empty(), errors += !r.error.empty(), total += r.seconds;
    xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuite name=\"vkrt-regress\" tests=\"" << results.size()
        << "\" failures=\"" << failures << "\" errors=\"" << errors << "\" time=\"" << total << "\">\n";
    for (const auto& r : results) {
        xml << "  <testcase classname=\"vkrt.regress\" name=\"" << xmlEscape(r.name) << "\" time=\"" << r.seconds << "\"";
        if (r.passed) {
            xml << "/>\n";
            continue;
        }
        xml << ">\n";
        if (!r.error.empty()) xml << "    <error message=\"" << xmlEscape(r.error) << "\"/>\n";
        else
            xml << "    <failure message=\"" << 100.0 * r.test.fractionPassed() << "% of values pass; pooled z "
                << r.test.pooledZ << "\"/>\n";
        xml << "  </testcase>\n";
    }
    xml << "</testsuite>\n";
    return xml.str();
}

void writeText(const fs::path& path, const std::string& text)
{
    writeFileAtomically(path, [&](const fs::path& temporary) {
        std::ofstream out(temporary, std::ios::binary);
        out << text;
        if (!out) throw InputError(path.string() + ": cannot write");
    });
}

// ---------------------------------------------------------------- cases

CaseResult runCase(const VulkanContext& context, const RegressionSuite& suite, const RegressionCase& c,
                   const RegressOptions& options)
{
    CaseResult result{c.name};
    result.baseline = c.baselineSeconds;
    try {
        Scene scene = caseScene(c);
        Reference ref = loadReference(c, scene.camera.width, scene.camera.height);
        Rendered r = renderCase(context, scene, c.spp, suite.seed + options.seedOffset, options.kernelDefines);
        ReferenceTestSettings settings{suite.alpha, suite.pooledAlpha, suite.minPass};
        result.test = testAgainstReference(r.mean, r.variance, c.spp, ref.mean, ref.variance, c.referenceSpp, settings);
        result.measured = measureError(r.mean, ref.mean);
        result.seconds = r.seconds;
        result.slow = c.baselineSeconds > 0 && r.seconds > c.baselineSeconds * suite.maxSlowdown;
        result.passed = result.test.passedRule(suite.minPass) && !(options.failOnSlowdown && result.slow);
        if (!result.passed && !options.reportDir.empty()) writeFailureImages(options.reportDir, c.name, r, ref, result.test);
    } catch (const std::exception& e) {
        result.error = e.what();
    }
    return result;
}

std::string gitCommit(const fs::path& dir)
{
    std::string command = "git -C '" + dir.string() + "' rev-parse HEAD 2>/dev/null";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return "unknown";
    char buffer[64] = {};
    size_t n = fread(buffer, 1, sizeof buffer - 1, pipe);
    pclose(pipe);
    std::string commit(buffer, n);
    while (!commit.empty() && std::isspace(static_cast<unsigned char>(commit.back()))) commit.pop_back();
    return commit.empty() ? "unknown" : commit;
}

void updateReference(const VulkanContext& context, const RegressionCase& c)
{
    Scene scene = caseScene(c);
    auto start = std::chrono::steady_clock::now();
    Rendered r = renderCase(context, scene, uint32_t(c.referenceSpp), kReferenceSeed, {});
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    fs::create_directories(c.referenceDir);
    writeExr(c.referenceDir / "mean.exr", r.mean, {{"spp", int64_t(c.referenceSpp)}, {"seed", int64_t(kReferenceSeed)}});
    writeExr(c.referenceDir / "variance.exr", r.variance, {{"spp", int64_t(c.referenceSpp)}});
    std::time_t now = std::time(nullptr);
    char date[64];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    std::ostringstream readme;
    readme << "# vkrt reference: " << c.name << "\n\n- scene: `" << c.scene.string() << "`\n- made by: `vkrt regress --update`"
           << " (vkrt " << VKRT_VERSION << ", commit " << gitCommit(c.scene.parent_path()) << ")\n- device: "
           << context.deviceInfo().name << " (" << context.deviceInfo().driver << ")\n- spp: " << c.referenceSpp
           << ", seed " << kReferenceSeed << ", " << scene.camera.width << "x" << scene.camera.height << "\n- date: "
           << date << ", " << seconds << " s\n\n`mean.exr` is the per-pixel mean, `variance.exr` the variance of that mean.\n";
    writeText(c.referenceDir / "README.md", readme.str());
    std::printf("updated %s (%llu spp, %.1f s)\n", c.referenceDir.c_str(), static_cast<unsigned long long>(c.referenceSpp),
                seconds);
}

std::vector<RegressionCase> selectedCases(const RegressionSuite& suite, const std::string& filter)
{
    std::vector<RegressionCase> cases;
    for (const auto& c : suite.cases)
        if (filter.empty() || c.name.find(filter) != std::string::npos) cases.push_back(c);
    if (cases.empty()) throw InputError("--filter " + filter + ": no case of " + suite.path.string() + " matches");
    return cases;
}

} // namespace

void selectVulkanDriver(const fs::path& icdManifest)
{
    std::ifstream in(icdManifest);
    if (!in) throw InputError("--driver " + icdManifest.string() + ": no such file");
    std::stringstream text;
    text << in.rdbuf();
    if (text.str().find("\"ICD\"") == std::string::npos)
        throw InputError("--driver " + icdManifest.string() + ": not a Vulkan ICD manifest (no \"ICD\" object)");
    setenv("VK_DRIVER_FILES", icdManifest.c_str(), 1);
    setenv("VK_ICD_FILENAMES", icdManifest.c_str(), 1); // older loaders
}

int runRegression(const RegressOptions& options)
{
    RegressionSuite suite = readRegressionSuite(options.suite);
    std::vector<RegressionCase> cases = selectedCases(suite, options.filter);
    if (!options.driver.empty()) selectVulkanDriver(options.driver);
    if (!options.reportDir.empty()) fs::create_directories(options.reportDir);
    VulkanContext context({options.device, false});

    if (options.update) {
        for (const auto& c : cases) {
            if (c.source == ReferenceSource::Mitsuba) std::printf("kept %s (made by Mitsuba 3: tools/make_reference.py)\n", c.name.c_str());
            else updateReference(context, c);
        }
        return kExitOk;
    }

    g_stop.store(false);
    std::signal(SIGINT, onRegressInterrupt);
    std::vector<CaseResult> results;
    for (const auto& c : cases) {
        if (g_stop.load()) break;
        results.push_back(runCase(context, suite, c, options));
        const CaseResult& r = results.back();
        std::printf("%-34s %s  %.3f%% pass  pooled z %+.2f  %.2f s%s%s\n", r.name.c_str(),
                    !r.error.empty() ? "ERROR" : r.passed ? "pass" : "FAIL", 100.0 * r.test.fractionPassed(),
                    r.test.pooledZ, r.seconds, r.slow ? "  (slower than baseline)" : "",
                    r.error.empty() ? "" : ("\n    " + r.error).c_str());
        std::fflush(stdout);
        // Written after every case: an interrupted run keeps what finished.
        if (!options.reportDir.empty()) writeText(options.reportDir / "report.md", markdownReport(suite, results, context, options));
        if (!options.junit.empty()) writeText(options.junit, junitReport(results));
    }
    std::signal(SIGINT, SIG_DFL);
    size_t passed = std::count_if(results.begin(), results.end(), [](const CaseResult& r) { return r.passed; });
    std::printf("%zu passed, %zu failed\n", passed, results.size() - passed);
    if (g_stop.load()) return kExitInterrupted;
    return passed == cases.size() ? kExitOk : kExitCompareFailed;
}

} // namespace vkrt
