#include "regress/RegressionRun.h"

#include "io/AtomicFile.h"
#include "io/ExrFile.h"
#include "io/PngFile.h"
#include "regress/Suite.h"
#include "render/ErrorMetrics.h"
#include "render/RenderSession.h"
#include "render/Tally.h"
#include "util/Error.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

constexpr uint32_t kReferenceSeed = 0x5eed5eed; // never a test seed

/// Ctrl-C (runRegression holds an InterruptGuard): renders stop between submissions.
bool interrupted() { return interruptFlag().load(); }

// ---------------------------------------------------------------- references

struct Reference {
    Image mean, variance;
};

std::string makeHint(const RegressionCase& c)
{
    if (c.source == ReferenceSource::Vkrt) return "make it with: vkrt regress --update --filter " + c.name;
    return "make it with tools/make_reference.py (scenes/validation/README.md)";
}

/// `read()`, its InputError prefixed with the case.
template <typename Read>
auto forCase(const RegressionCase& c, Read read)
{
    try {
        return read();
    } catch (const InputError& e) {
        throw InputError("case " + c.name + ": " + e.what());
    }
}

/// One reference image, checked for size and for values a reference cannot have.
Image readReferenceImage(const RegressionCase& c, const fs::path& path, uint32_t width, uint32_t height,
                         bool isVariance)
{
    if (!fs::exists(path))
        throw InputError("case " + c.name + ": missing reference " + path.string() + "; " + makeHint(c));
    // The header must say the case's size before any pixel is read: a
    // reference that claims gigabytes costs only its header.
    const ExrHeader header = forCase(c, [&] { return readExrHeader(path); });
    if (header.width != width || header.height != height)
        throw InputError("case " + c.name + ": reference " + path.string() + " is " + std::to_string(header.width) +
                         "x" + std::to_string(header.height) + " but the case renders " + std::to_string(width) + "x" +
                         std::to_string(height) + " (match width/height in the manifest, or regenerate it)");
    const Image image = forCase(c, [&] {
        return readExr(path, ExpectedSize{width, height, "the case renders"}).image;
    });
    size_t invalid = std::count_if(image.rgb.begin(), image.rgb.end(),
                                   [&](float v) { return !std::isfinite(v) || (isVariance && v < 0.0f); });
    if (invalid)
        throw InputError("case " + c.name + ": reference " + path.string() + " has " + std::to_string(invalid) +
                         (isVariance ? " negative or non-finite values" : " non-finite values"));
    return image;
}

/// The case's scene at the case's size, checked with the scene parser's limits.
Scene caseScene(const RegressionSuite& suite, const RegressionCase& c)
{
    std::string where = suite.path.string() + ": case " + c.name + ": ";
    return loadScene(c.scene.string(), {c.width, c.height, where + "width", where + "height"});
}

/// A case with its scene parsed and its reference loaded and checked.
struct PreparedCase {
    RegressionCase spec;
    Scene scene;
    Reference reference;
};

/// Checks every selected case before anything renders; one InputError lists all problems.
std::vector<PreparedCase> prepareCases(const RegressionSuite& suite, const std::vector<RegressionCase>& cases)
{
    std::vector<PreparedCase> prepared;
    std::string problems;
    for (const RegressionCase& c : cases) {
        try {
            Scene scene = caseScene(suite, c);
            uint32_t w = scene.camera.width, h = scene.camera.height;
            Reference ref{readReferenceImage(c, c.referenceDir / "mean.exr", w, h, false),
                          readReferenceImage(c, c.referenceDir / "variance.exr", w, h, true)};
            prepared.push_back({c, std::move(scene), std::move(ref)});
        } catch (const InputError& e) {
            problems += std::string("\n  ") + e.what();
        }
    }
    if (!problems.empty())
        throw InputError(std::to_string(cases.size() - prepared.size()) + " case(s) cannot run:" + problems);
    return prepared;
}

// ---------------------------------------------------------------- rendering

struct Rendered {
    Image mean, variance;
    double seconds = 0.0;
    uint64_t rejectedSamples = 0;
    Metadata metadata; ///< the session's, for the images written from it
};

SessionConfig caseConfig(uint32_t seed, const std::vector<Define>& defines, uint32_t firstFrame, uint32_t frames)
{
    SessionConfig config;
    config.seed = seed;
    config.variance.layer = true;
    config.extraDefines = defines;
    config.firstFrame = firstFrame;
    config.stop = {frames, std::nullopt, std::nullopt, &interruptFlag()};
    return config;
}

/// Renders `spp` frames after a warm-up frame, with a per-pixel variance (the
/// per-value test needs it); nullopt when Ctrl-C stopped it.
std::optional<Rendered> renderCase(const VulkanContext& context, const Scene& scene, uint32_t spp, uint32_t seed,
                                   const std::vector<Define>& defines)
{
    RenderSession session(context, scene, caseConfig(seed, defines, 0, spp));
    LoopResult loop = session.run();
    if (loop.reason == StopReason::Interrupted) return std::nullopt;
    Film film = session.film();
    Metadata metadata = session.metadata(film);
    return Rendered{std::move(film.mean), std::move(*film.variance), loop.renderSeconds,
                    session.renderer().counters().rejectedSamples, std::move(metadata)};
}

/// As renderCase, but as `shards` sessions over the contiguous sample ranges
/// `vkrt render --shard i/n` renders, their tallies added as `vkrt merge`
/// adds them (render/Tally.h): the farm's path through the same test.
std::optional<Rendered> renderCaseInShards(const VulkanContext& context, const Scene& scene, uint32_t spp,
                                           uint32_t shards, uint32_t seed, const std::vector<Define>& defines)
{
    std::vector<Tally> tallies;
    Rendered merged;
    for (uint32_t i = 0; i < shards; ++i) {
        const auto begin = uint32_t(uint64_t(i) * spp / shards), end = uint32_t(uint64_t(i + 1) * spp / shards);
        RenderSession session(context, scene, caseConfig(seed, defines, begin, end - begin));
        LoopResult loop = session.run();
        if (loop.reason == StopReason::Interrupted) return std::nullopt;
        tallies.push_back(session.renderer().tally());
        merged.seconds += loop.renderSeconds;
        merged.rejectedSamples += session.renderer().counters().rejectedSamples;
        if (i == 0) merged.metadata = session.metadata(session.film());
    }
    const Tally tally = mergeTallies(tallies);
    merged.mean = tallyMean(tally);
    merged.variance = *tallyVarianceOfMean(tally);
    merged.metadata["spp"] = int64_t(spp);
    merged.metadata["shard"] = "merged from " + std::to_string(shards);
    return merged;
}

/// The pooled test per channel: z_c = sum (x - r) / sqrt(sum sigma^2) over the
/// pixels, with testAgainstReference's per-value sigma^2. The case's pooled z
/// is the channel with the largest |z_c|; its limit is the two-sided quantile
/// of pooledAlpha, Sidak-corrected over the 3 channels. (One sum over all
/// values, as ErrorMetrics.cpp forms it, treats a pixel's channels as
/// independent, but they come from the same paths: in a grey scene they are
/// equal, and that sum's standard deviation is sqrt(3), not 1.)
void poolByChannel(ReferenceTestResult& t, const Rendered& r, uint32_t spp, const Reference& ref, uint64_t refSpp,
                   double pooledAlpha)
{
    double scale = double(refSpp) / double(std::max(spp, 1u));
    std::array<double, 3> sumDiff{}, sumVariance{};
    for (size_t i = 0; i < r.mean.rgb.size(); ++i) {
        double x = r.mean.rgb[i], m = ref.mean.rgb[i], vr = ref.variance.rgb[i];
        double vx = std::isfinite(r.variance.rgb[i]) ? double(r.variance.rgb[i]) : INFINITY;
        double variance = std::max(vx, vr * scale) + vr + std::pow(1e-6 * m, 2);
        if (!std::isfinite(x) || !std::isfinite(variance)) continue; // the per-value test fails x
        sumDiff[i % 3] += x - m;
        sumVariance[i % 3] += variance;
    }
    t.pooledZ = 0.0;
    for (int c = 0; c < 3; ++c) {
        double z = sumVariance[c] > 0.0 ? sumDiff[c] / std::sqrt(sumVariance[c]) : (sumDiff[c] == 0.0 ? 0.0 : INFINITY);
        if (std::abs(z) > std::abs(t.pooledZ)) t.pooledZ = z;
    }
    t.pooledThreshold = normalQuantileTwoSided(1.0 - std::pow(1.0 - pooledAlpha, 1.0 / 3.0));
}

/// testAgainstReference with two corrections (docs/regress.md): a value passes
/// exactly when its p-value reaches the per-value level (ErrorMetrics.cpp
/// computes z = 0/0 = NaN, a failure, where render, reference and both
/// variances are 0, e.g. a black background; its p-value there is correctly
/// 1), and the pooled test is per channel (poolByChannel).
ReferenceTestResult testRender(const Rendered& r, uint32_t spp, const Reference& ref, uint64_t refSpp,
                               const RegressionSuite& suite)
{
    ReferenceTestSettings settings{suite.alpha, suite.pooledAlpha, suite.minPass};
    ReferenceTestResult t = testAgainstReference(r.mean, r.variance, spp, ref.mean, ref.variance, refSpp, settings);
    float level = float(std::erfc(t.threshold / std::sqrt(2.0)));
    t.passed = size_t(std::count_if(t.pValues.rgb.begin(), t.pValues.rgb.end(), [&](float p) { return p >= level; }));
    poolByChannel(t, r, spp, ref, refSpp, suite.pooledAlpha);
    return t;
}

// ---------------------------------------------------------------- results

struct CaseResult {
    std::string name;
    bool passed = false;
    bool slow = false;
    std::string error;                           ///< set when the case could not run
    OutcomeKind errorKind = OutcomeKind::Passed; ///< what that error was
    ReferenceTestResult test;
    MeasuredError measured;
    double seconds = 0.0;
    double baseline = 0.0;
    uint64_t rejectedSamples = 0;
    uint64_t maxRejected = 0;
    std::string reference; ///< "mitsuba, 65536 spp"
};

std::string referenceLabel(const RegressionCase& c)
{
    return std::string(c.source == ReferenceSource::Mitsuba ? "mitsuba" : "vkrt") + ", " +
           std::to_string(c.referenceSpp) + " spp";
}

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
    writeExr(dir / (base + "-result.exr"), r.mean, r.metadata, {{"variance", r.variance}});
    writeExr(dir / (base + "-pvalues.exr"), t.pValues, {});
}

/// nullopt when Ctrl-C stopped the render.
std::optional<CaseResult> runCase(const VulkanContext& context, const RegressionSuite& suite, const PreparedCase& pc,
                                  const RegressOptions& options)
{
    const RegressionCase& c = pc.spec;
    CaseResult result{c.name};
    result.baseline = c.baselineSeconds;
    result.reference = referenceLabel(c);
    try {
        const uint32_t seed = suite.seed + options.seedOffset;
        std::optional<Rendered> r =
            c.shards > 1 ? renderCaseInShards(context, pc.scene, c.spp, c.shards, seed, options.kernelDefines)
                         : renderCase(context, pc.scene, c.spp, seed, options.kernelDefines);
        if (!r) return std::nullopt;
        result.test = testRender(*r, c.spp, pc.reference, c.referenceSpp, suite);
        result.measured = measureError(r->mean, pc.reference.mean);
        result.seconds = r->seconds;
        result.rejectedSamples = r->rejectedSamples;
        result.slow = c.baselineSeconds > 0 && r->seconds > c.baselineSeconds * suite.maxSlowdown;
        result.maxRejected = c.maxRejected;
        result.passed = result.test.passedRule(suite.minPass) && r->rejectedSamples <= c.maxRejected &&
                        !(options.failOnSlowdown && result.slow);
        if (!result.passed && !options.reportDir.empty())
            writeFailureImages(options.reportDir, c.name, *r, pc.reference, result.test);
    } catch (const InputError& e) {
        result.error = e.what();
        result.errorKind = OutcomeKind::BadInput;
    } catch (const std::exception& e) {
        result.error = e.what();
        result.errorKind = OutcomeKind::DeviceFailure;
    }
    return result;
}

// ---------------------------------------------------------------- reports

/// Where the run stands: "12 of 24 cases", plus "interrupted" when it ended early.
struct RunStatus {
    size_t total = 0;
    bool interrupted = false;
};

std::string markdownHeader(const RegressionSuite& suite, const std::vector<CaseResult>& results, RunStatus status,
                           const VulkanContext& context, const RegressOptions& options)
{
    std::ostringstream md;
    size_t passed = std::count_if(results.begin(), results.end(), [](const CaseResult& r) { return r.passed; });
    md << "# vkrt regression report\n\n"
       << "- suite: `" << suite.path.string() << "`\n- device: " << context.deviceInfo().name << " ("
       << context.deviceInfo().driver << ")\n"
       << "- driver manifest: " << (options.driver.empty() ? "system default" : "`" + options.driver + "`") << "\n"
       << "- seed: " << suite.seed + options.seedOffset << "\n";
    for (const Define& d : options.kernelDefines)
        md << "- kernel define (test hook): `" << d.first << "=" << d.second << "`\n";
    md << "- rule: at least " << 100.0 * suite.minPass << " % of values pass a Sidak-corrected z-test at alpha "
       << suite.alpha << ", |pooled z| within alpha " << suite.pooledAlpha
       << " (per channel, Sidak over 3), no more rejected (non-finite) samples than the case's max_rejected (default 0)"
       << " (docs/regress.md); slow = more than " << suite.maxSlowdown << " x baseline\n- result: **" << passed
       << " passed, " << results.size() - passed << " failed**";
    if (results.size() < status.total)
        md << " (" << results.size() << " of " << status.total << " cases"
           << (status.interrupted ? ": **interrupted**" : " so far") << ")";
    md << "\n\n";
    return md.str();
}

std::string markdownRow(const CaseResult& r)
{
    if (!r.error.empty()) {
        std::string message = r.error;
        std::replace(message.begin(), message.end(), '\n', ' ');
        std::replace(message.begin(), message.end(), '|', '/');
        return "| " + r.name + " | **error** | " + message + " | | | | | | | | |\n";
    }
    char line[640];
    std::string baseline = r.baseline > 0 ? std::to_string(r.baseline).substr(0, 5) : "-";
    std::string ratio = r.baseline > 0 ? std::to_string(r.seconds / r.baseline).substr(0, 4) : "-";
    std::string rejected = std::to_string(r.rejectedSamples);
    if (r.maxRejected) rejected += " (max " + std::to_string(r.maxRejected) + ")";
    std::snprintf(line, sizeof line, "| %s | %s%s | %.3f %% | %+.2f | %.3g | %.3g | %s | %.2f | %s | %s | %s |\n",
                  r.name.c_str(), r.passed ? "pass" : "**FAIL**", r.slow ? " (slow)" : "",
                  100.0 * r.test.fractionPassed(), r.test.pooledZ, r.test.minPValue, r.measured.relMse,
                  rejected.c_str(), r.seconds, baseline.c_str(), ratio.c_str(), r.reference.c_str());
    return line;
}

std::string markdownReport(const RegressionSuite& suite, const std::vector<CaseResult>& results, RunStatus status,
                           const VulkanContext& context, const RegressOptions& options)
{
    std::ostringstream md;
    md << markdownHeader(suite, results, status, context, options)
       << "| case | result | values passing | pooled z | smallest p | relMSE | rejected | seconds | baseline | ratio "
          "| reference |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    for (const CaseResult& r : results) md << markdownRow(r);
    for (const CaseResult& r : results) {
        if (r.passed || !r.error.empty() || r.test.tested == 0) continue;
        std::string base = safeName(r.name);
        md << "\n## " << r.name << "\n\n"
           << r.test.tested - r.test.passed << " of " << r.test.tested << " values beyond |z| = " << r.test.threshold
           << "; pooled z " << r.test.pooledZ << " (limit " << r.test.pooledThreshold << "); " << r.rejectedSamples
           << " rejected samples. Result with variance: `" << base << "-result.exr`, p-values: `" << base
           << "-pvalues.exr`.\n\n"
           << "| reference | result | difference | significance |\n| --- | --- | --- | --- |\n"
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
        else if (ch == '\n') out += "&#10;";
        else out += ch;
    }
    return out;
}

std::string failureMessage(const CaseResult& r)
{
    std::ostringstream m;
    m << 100.0 * r.test.fractionPassed() << "% of values pass; pooled z " << r.test.pooledZ << "; smallest p "
      << r.test.minPValue << "; " << r.rejectedSamples << " rejected samples"
      << (r.slow ? "; slower than baseline" : "");
    return m.str();
}

std::string junitReport(const std::vector<CaseResult>& results)
{
    std::ostringstream xml;
    size_t failures = 0, errors = 0;
    double total = 0;
    for (const auto& r : results)
        failures += !r.passed && r.error.empty(), errors += !r.error.empty(), total += r.seconds;
    xml << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuite name=\"vkrt-regress\" tests=\"" << results.size()
        << "\" failures=\"" << failures << "\" errors=\"" << errors << "\" time=\"" << total << "\">\n";
    for (const auto& r : results) {
        xml << "  <testcase classname=\"vkrt.regress\" name=\"" << xmlEscape(r.name) << "\" time=\"" << r.seconds
            << "\"";
        if (r.passed) {
            xml << "/>\n";
            continue;
        }
        xml << ">\n";
        if (!r.error.empty()) xml << "    <error message=\"" << xmlEscape(r.error) << "\"/>\n";
        else xml << "    <failure message=\"" << xmlEscape(failureMessage(r)) << "\"/>\n";
        xml << "  </testcase>\n";
    }
    xml << "</testsuite>\n";
    return xml.str();
}

void writeText(const fs::path& path, const std::string& text)
{
    writeBytesAtomically(path, text); // every write checked: an unchecked ofstream's last flush can fail silently
}

/// Rewritten after every case, so an interrupted run keeps what finished.
void writeReports(const RegressionSuite& suite, const std::vector<CaseResult>& results, RunStatus status,
                  const VulkanContext& context, const RegressOptions& options)
{
    if (!options.reportDir.empty())
        writeText(options.reportDir / "report.md", markdownReport(suite, results, status, context, options));
    if (!options.junit.empty()) writeText(options.junit, junitReport(results));
}

void printResult(const CaseResult& r)
{
    if (!r.error.empty()) std::printf("%-34s ERROR\n    %s\n", r.name.c_str(), r.error.c_str());
    else
        std::printf("%-34s %s  %.3f%% pass  pooled z %+.2f  %.2f s%s%s\n", r.name.c_str(), r.passed ? "pass" : "FAIL",
                    100.0 * r.test.fractionPassed(), r.test.pooledZ, r.seconds,
                    r.rejectedSamples ? ("  " + std::to_string(r.rejectedSamples) + " rejected samples").c_str() : "",
                    r.slow ? "  (slower than baseline)" : "");
    std::fflush(stdout);
}

/// Passed, or the kind of the first case that could not run, else Failed on a failure.
Outcome outcomeOf(const std::vector<CaseResult>& results)
{
    for (const CaseResult& r : results)
        if (!r.error.empty()) return Outcome::of(r.errorKind);
    bool allPassed = std::all_of(results.begin(), results.end(), [](const CaseResult& r) { return r.passed; });
    return allPassed ? Outcome::passed() : Outcome::of(OutcomeKind::Failed);
}

Outcome runCases(const VulkanContext& context, const RegressionSuite& suite, const std::vector<PreparedCase>& cases,
                 const RegressOptions& options)
{
    std::vector<CaseResult> results;
    RunStatus status{cases.size(), false};
    for (const PreparedCase& c : cases) {
        std::optional<CaseResult> r = interrupted() ? std::nullopt : runCase(context, suite, c, options);
        if (!r) {
            status.interrupted = true;
            break;
        }
        results.push_back(std::move(*r));
        printResult(results.back());
        writeReports(suite, results, status, context, options);
    }
    size_t passed = std::count_if(results.begin(), results.end(), [](const CaseResult& r) { return r.passed; });
    std::printf("%zu passed, %zu failed", passed, results.size() - passed);
    if (status.interrupted) {
        writeReports(suite, results, status, context, options);
        std::printf(" (interrupted after %zu of %zu cases)\n", results.size(), cases.size());
        return Outcome::of(OutcomeKind::Interrupted);
    }
    std::printf("\n");
    return outcomeOf(results);
}

// ---------------------------------------------------------------- --update

/// First line of a git command's output in `dir`, or nullopt.
std::optional<std::string> gitLine(const fs::path& dir, const std::string& arguments)
{
    std::string command = "git -C '" + dir.string() + "' " + arguments + " 2>/dev/null";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return std::nullopt;
    char buffer[4096] = {};
    size_t n = fread(buffer, 1, sizeof buffer - 1, pipe);
    int status = pclose(pipe);
    std::string line(buffer, n);
    line = line.substr(0, line.find('\n'));
    if (status != 0 || line.empty()) return std::nullopt;
    return line;
}

/// "commit abc… " plus a warning when shaders or sources differ from it.
std::string commitDescription(const fs::path& dir)
{
    std::optional<std::string> commit = gitLine(dir, "rev-parse HEAD");
    if (!commit) return "commit unknown";
    std::optional<std::string> dirty = gitLine(dir, "status --porcelain -- shaders src");
    return "commit " + *commit + (dirty ? " with uncommitted changes in shaders/ or src/" : "");
}

/// The path relative to the git checkout holding it, else absolute.
std::string repositoryPath(const fs::path& file)
{
    fs::path absolute = fs::weakly_canonical(file);
    std::optional<std::string> top = gitLine(absolute.parent_path(), "rev-parse --show-toplevel");
    fs::path relative = top ? absolute.lexically_relative(fs::path(*top)) : fs::path();
    bool inside = !relative.empty() && *relative.begin() != "..";
    return inside ? relative.string() : absolute.string();
}

void writeReferenceReadme(const VulkanContext& context, const RegressionSuite& suite, const RegressionCase& c,
                          const Scene& scene, double seconds)
{
    std::time_t now = std::time(nullptr);
    char date[64];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    std::ostringstream readme;
    readme << "# vkrt reference: " << c.name << "\n\n| | |\n|---|---|\n| scene | `" << repositoryPath(c.scene)
           << "` |\n| command | `vkrt regress --update --suite " << repositoryPath(suite.path) << " --filter " << c.name
           << "` |\n| vkrt | " << VKRT_VERSION << ", " << commitDescription(c.scene.parent_path()) << " |\n| device | "
           << context.deviceInfo().name << " (" << context.deviceInfo().driver << ") |\n| image | "
           << scene.camera.width << " x " << scene.camera.height << " |\n| spp | " << c.referenceSpp << " (seed "
           << kReferenceSeed << ") |\n| date | " << date << " |\n| render time | " << std::lround(seconds)
           << " s |\n\n`mean.exr` is the per-pixel mean, `variance.exr` the variance of that mean (sample variance / "
              "spp).\n";
    writeText(c.referenceDir / "README.md", readme.str());
}

/// Renders one vkrt reference; false when Ctrl-C stopped it (nothing written).
bool updateReference(const VulkanContext& context, const RegressionSuite& suite, const RegressionCase& c)
{
    std::printf("updating %s: %llu spp ...\n", c.name.c_str(), static_cast<unsigned long long>(c.referenceSpp));
    std::fflush(stdout);
    Scene scene = caseScene(suite, c);
    auto start = std::chrono::steady_clock::now();
    std::optional<Rendered> r = renderCase(context, scene, uint32_t(c.referenceSpp), kReferenceSeed, {});
    if (!r) return false;
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (r->rejectedSamples)
        std::printf("warning: %s: %llu non-finite samples were rejected\n", c.name.c_str(),
                    static_cast<unsigned long long>(r->rejectedSamples));
    fs::create_directories(c.referenceDir);
    writeExr(c.referenceDir / "mean.exr", r->mean, r->metadata);
    writeExr(c.referenceDir / "variance.exr", r->variance, r->metadata);
    writeReferenceReadme(context, suite, c, scene, seconds);
    std::printf("updated %s (%.1f s)\n", c.referenceDir.c_str(), seconds);
    return true;
}

Outcome updateReferences(const VulkanContext& context, const RegressionSuite& suite,
                         const std::vector<RegressionCase>& cases)
{
    std::set<fs::path> updated;
    for (const RegressionCase& c : cases) {
        if (c.source == ReferenceSource::Mitsuba) {
            std::printf("kept %s (made by Mitsuba 3: tools/make_reference.py)\n", c.name.c_str());
            continue;
        }
        if (!updated.insert(c.referenceDir).second) {
            std::printf("kept %s (its reference %s was just updated by another case)\n", c.name.c_str(),
                        c.referenceDir.c_str());
            continue;
        }
        if (interrupted() || !updateReference(context, suite, c)) {
            std::printf("interrupted: %s and later references not updated\n", c.name.c_str());
            return Outcome::of(OutcomeKind::Interrupted);
        }
    }
    return Outcome::passed();
}

// ---------------------------------------------------------------- set-up

std::vector<RegressionCase> selectedCases(const RegressionSuite& suite, const std::vector<std::string>& filters)
{
    std::vector<RegressionCase> cases;
    auto matches = [&](const std::string& name) {
        return filters.empty() || std::any_of(filters.begin(), filters.end(),
                                              [&](const std::string& f) { return name.find(f) != std::string::npos; });
    };
    for (const auto& c : suite.cases)
        if (matches(c.name)) cases.push_back(c);
    if (cases.empty()) {
        std::string list;
        for (const auto& f : filters) list += (list.empty() ? "" : ", ") + f;
        throw InputError("--filter " + list + ": no case of " + suite.path.string() + " matches");
    }
    return cases;
}

/// The value of the first "key": "value" pair in JSON text ("" if absent).
std::string jsonString(const std::string& text, const std::string& key)
{
    size_t at = text.find("\"" + key + "\"");
    if (at == std::string::npos) return "";
    size_t colon = text.find(':', at), open = text.find('"', colon == std::string::npos ? at : colon);
    size_t close = open == std::string::npos ? open : text.find('"', open + 1);
    return close == std::string::npos ? "" : text.substr(open + 1, close - open - 1);
}

std::unique_ptr<VulkanContext> openContext(const RegressOptions& options)
{
    try {
        return std::make_unique<VulkanContext>(ContextOptions{options.device, false, std::nullopt});
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        if (options.driver.empty()) throw;
        throw GpuError("--driver " + options.driver + ": the Vulkan loader could not use this driver (" + e.what() +
                       "); is its library_path loadable, and does it list a device?");
    }
}

} // namespace

void createReportDir(const fs::path& dir)
{
    std::error_code error;
    fs::create_directories(dir, error);
    if (error || !fs::is_directory(dir))
        throw InputError("--report-dir " + dir.string() + ": cannot create it (" +
                         (error ? error.message() : "not a directory") + ")");
}

void selectVulkanDriver(const fs::path& icdManifest)
{
    std::string option = "--driver " + icdManifest.string();
    fs::path path = fs::absolute(icdManifest);
    if (!fs::is_regular_file(path)) throw InputError(option + ": no such file");
    std::ifstream in(path);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) throw InputError(option + ": cannot read it");
    if (text.find("\"ICD\"") == std::string::npos)
        throw InputError(option + ": not a Vulkan ICD manifest (no \"ICD\" object)");
    std::string library = jsonString(text, "library_path");
    if (library.empty()) throw InputError(option + ": the ICD manifest has no \"library_path\"");
    // A bare file name is looked up by the dynamic linker; a path is relative to the manifest.
    fs::path libraryPath =
        (fs::path(library).is_absolute() ? fs::path(library) : path.parent_path() / library).lexically_normal();
    if (library.find('/') != std::string::npos && !fs::exists(libraryPath))
        throw InputError(option + ": its library_path " + libraryPath.string() + " does not exist");
    setenv("VK_DRIVER_FILES", path.c_str(), 1);
    setenv("VK_ICD_FILENAMES", path.c_str(), 1); // older loaders
}

Outcome runRegression(const RegressOptions& options)
{
    RegressionSuite suite = readRegressionSuite(options.suite);
    if (options.update && !options.kernelDefines.empty())
        throw InputError(
            "--update cannot be combined with --kernel-define: references must come from unmodified kernels");
    std::vector<RegressionCase> cases = selectedCases(suite, options.filters);
    if (!options.driver.empty()) selectVulkanDriver(options.driver);
    std::vector<PreparedCase> prepared;
    if (!options.update) prepared = prepareCases(suite, cases);
    if (!options.reportDir.empty()) createReportDir(options.reportDir);

    InterruptGuard interrupt;
    std::unique_ptr<VulkanContext> context = openContext(options);
    if (options.update) return updateReferences(*context, suite, cases);
    return runCases(*context, suite, prepared, options);
}

} // namespace vkrt
