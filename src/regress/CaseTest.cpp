#include "regress/CaseTest.h"

#include "io/ExrFile.h"
#include "io/PngFile.h"
#include "render/ErrorMetrics.h"
#include "render/Tally.h"
#include "util/Error.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <thread>

#include <sys/resource.h>

namespace fs = std::filesystem;

namespace vkrt {

namespace {

// ---------------------------------------------------------------- references

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

} // namespace

/// The case's scene at the case's size, checked with the scene parser's limits.
Scene caseScene(const RegressionSuite& suite, const RegressionCase& c)
{
    std::string where = suite.path.string() + ": case " + c.name + ": ";
    return loadScene(c.scene.string(), {c.width, c.height, where + "width", where + "height"});
}

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

namespace {

// ---------------------------------------------------------------- rendering

/// Every session of a case: its seed, the variance the test needs, and the
/// run's --accel and test-hook defines.
SessionConfig caseConfig(uint32_t seed, const RegressOptions& options, uint32_t firstFrame, uint32_t frames)
{
    SessionConfig config;
    config.seed = seed;
    config.variance.layer = true;
    config.accel = options.accel;
    config.extraDefines = options.kernelDefines;
    config.firstFrame = firstFrame;
    config.stop = {frames, std::nullopt, std::nullopt, &interruptFlag()};
    return config;
}

/// As renderCase, but as `shards` sessions over the contiguous sample ranges
/// `vkrt render --shard i/n` renders, their tallies added as `vkrt merge`
/// adds them (render/Tally.h): the farm's path through the same test.
std::optional<Rendered> renderCaseInShards(const VulkanContext& context, const Scene& scene, uint32_t spp,
                                           uint32_t shards, uint32_t seed, const RegressOptions& options)
{
    std::vector<Tally> tallies;
    Rendered merged;
    for (uint32_t i = 0; i < shards; ++i) {
        const auto begin = uint32_t(uint64_t(i) * spp / shards), end = uint32_t(uint64_t(i + 1) * spp / shards);
        RenderSession session(context, scene, caseConfig(seed, options, begin, end - begin));
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

} // namespace

std::optional<Rendered> renderCase(const VulkanContext& context, const Scene& scene, uint32_t spp, uint32_t seed,
                                   const RegressOptions& options)
{
    RenderSession session(context, scene, caseConfig(seed, options, 0, spp));
    LoopResult loop = session.run();
    if (loop.reason == StopReason::Interrupted) return std::nullopt;
    Film film = session.film();
    Metadata metadata = session.metadata(film);
    return Rendered{std::move(film.mean), std::move(*film.variance), loop.renderSeconds,
                    session.renderer().counters().rejectedSamples, std::move(metadata)};
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

std::string safeName(std::string name)
{
    for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '_') ch = '_';
    return name;
}

void writeFailureImages(const fs::path& dir, const std::string& base, const Rendered& r, const Reference& ref,
                        const ReferenceTestResult& t)
{
    writePng(dir / (base + "-reference.png"), ref.mean, 0.0f);
    writePng(dir / (base + "-result.png"), r.mean, 0.0f);
    writePng(dir / (base + "-difference.png"), differenceImage(r.mean, ref.mean), 0.0f);
    writePng(dir / (base + "-significance.png"), significanceImage(t), 0.0f);
    writeExr(dir / (base + "-result.exr"), r.mean, r.metadata, {{"variance", r.variance}});
    writeExr(dir / (base + "-pvalues.exr"), t.pValues, {});
}

// ---------------------------------------------------------------- test hooks

namespace {

/// Whether the environment variable `hook` names this case (docs/regress.md, "Test hooks").
bool hookNames(const char* hook, const std::string& name)
{
    const char* value = std::getenv(hook);
    return value && name == value;
}

/// VKRT_TEST_CRASH_CASE: die of SIGSEGV as a crashing driver would (without a
/// core file: the crash is deliberate). VKRT_TEST_HANG_CASE: never finish, as a
/// driver in an endless loop; only Ctrl-C (in this process) or the runner's
/// timeout ends it. False when Ctrl-C ended the hang.
bool crashOrHangIfAsked(const std::string& name)
{
    if (hookNames("VKRT_TEST_CRASH_CASE", name)) {
        const rlimit noCore{0, 0};
        setrlimit(RLIMIT_CORE, &noCore);
        std::signal(SIGSEGV, SIG_DFL);
        std::raise(SIGSEGV);
    }
    if (hookNames("VKRT_TEST_HANG_CASE", name)) {
        while (!interrupted()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
        return false;
    }
    return true;
}

/// VKRT_TEST_FLAKY_CASE: the case fails its first attempt whatever the image.
void failFirstAttemptIfAsked(const std::string& name, const AttemptPlan& plan, CaseAttempt& attempt)
{
    if (!hookNames("VKRT_TEST_FLAKY_CASE", name) || plan.number != 1) return;
    attempt.status = CaseStatus::Fail;
    attempt.note = "VKRT_TEST_FLAKY_CASE: failed on purpose on its first attempt";
}

} // namespace

// ---------------------------------------------------------------- one attempt

namespace {

/// Renders and tests; fills `attempt` and returns the render (nullopt on Ctrl-C).
std::optional<Rendered> renderAndTest(const VulkanContext& context, const RegressionSuite& suite,
                                      const PreparedCase& pc, const RegressOptions& options, CaseAttempt& attempt)
{
    const RegressionCase& c = pc.spec;
    std::optional<Rendered> r = c.shards > 1
                                    ? renderCaseInShards(context, pc.scene, c.spp, c.shards, attempt.seed, options)
                                    : renderCase(context, pc.scene, c.spp, attempt.seed, options);
    if (!r) return std::nullopt;
    attempt.test = testRender(*r, c.spp, pc.reference, c.referenceSpp, suite);
    attempt.relMse = measureError(r->mean, pc.reference.mean).relMse;
    attempt.seconds = r->seconds;
    attempt.rejectedSamples = r->rejectedSamples;
    attempt.slow = c.baselineSeconds > 0 && r->seconds > c.baselineSeconds * suite.maxSlowdown;
    const bool passed = attempt.test.passedRule(suite.minPass) && r->rejectedSamples <= c.maxRejected &&
                        !(options.failOnSlowdown && attempt.slow);
    attempt.status = passed ? CaseStatus::Pass : CaseStatus::Fail;
    return r;
}

} // namespace

std::optional<CaseAttempt> runAttempt(const VulkanContext& context, const RegressionSuite& suite,
                                      const PreparedCase& pc, const RegressOptions& options, const AttemptPlan& plan)
{
    CaseAttempt attempt;
    attempt.number = plan.number;
    attempt.seed = suite.seed + plan.seedOffset;
    attempt.device = context.deviceInfo().name;
    attempt.driver = context.deviceInfo().driver;
    if (!crashOrHangIfAsked(pc.spec.name)) return std::nullopt;
    try {
        std::optional<Rendered> r = renderAndTest(context, suite, pc, options, attempt);
        if (!r) return std::nullopt;
        failFirstAttemptIfAsked(pc.spec.name, plan, attempt);
        if (attempt.status == CaseStatus::Fail && !plan.failureImageDir.empty()) {
            writeFailureImages(plan.failureImageDir, safeName(pc.spec.name), *r, pc.reference, attempt.test);
            attempt.wroteImages = true;
        }
        if (!plan.imageOut.empty()) writeExr(plan.imageOut, r->mean, r->metadata, {{"variance", r->variance}});
    } catch (const std::exception& e) {
        attempt.status = CaseStatus::Fail;
        attempt.problem = e.what();
    }
    return attempt;
}

} // namespace vkrt
