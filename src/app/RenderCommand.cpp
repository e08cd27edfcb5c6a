// `vkrt render SCENE`: renders a scene progressively and writes an EXR (and
// optionally a PNG preview). Ctrl-C stops early and still writes what was
// accumulated, with its true spp in the metadata.
#include "app/Commands.h"
#include "app/ExitCodes.h"
#include "app/InjectOption.h"
#include "app/JsonOutput.h"
#include "app/VectorWidthRelaunch.h"
#include "io/AtomicFile.h"
#include "io/ExrFile.h"
#include "io/OutputPaths.h"
#include "io/PngFile.h"
#include "render/ConvergenceReport.h"
#include "render/Progress.h"
#include "render/RenderOutput.h"
#include "render/RenderSession.h"
#include "scene/FeatureSet.h"
#include "scene/SceneInputs.h"
#include "scene/TomlReader.h"
#include "util/Error.h"
#include "util/Hash.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include <unistd.h>

namespace vkrt {

namespace {

struct RenderCommandOptions {
    std::string scenePath;
    std::string output;
    uint32_t spp = kDefaultSpp;
    std::optional<uint32_t> width;
    std::optional<uint32_t> height;
    uint32_t seed = 0;
    std::string device;
    std::string png;
    float exposure = 0.0f;
    bool filmic = false;
    bool validation = false;
    bool uber = false;
    bool staged = false;
    bool pixelCenters = false;
    bool variance = false;
    std::optional<double> timeBudget;
    std::optional<double> targetError;
    std::string report;
    std::string reference;
    std::string json; ///< --json FILE, or "-" for standard output (docs/machine-output.md)
    bool sppGiven = false;
    std::string sampler = "auto";
    AccelChoice accel = AccelChoice::Auto;
    SceneReads sceneReads = SceneReads::Auto;
    VectorWidthChoice vectorWidth = VectorWidthChoice::Auto;
    std::string shard;                      ///< "i/n" (docs/farm.md)
    uint32_t samplesPerInvocation = 0;      ///< 0: the device's default
    std::vector<std::string> kernelDefines; ///< NAME=VALUE (measurement hooks)
    std::string injectFault;                ///< --inject: a SPIR-V fault (gpu/SpirvFault.h)
    uint64_t maxBandBytes = 0;              ///< test hook: bands of at most this many bytes per buffer
    uint64_t maxTextureChunkBytes = 0;      ///< test hook: texel buffers of at most this many bytes
    std::vector<std::string> aovs;          ///< --aov albedo,normal,depth,position
    GltfSceneOptions gltf;                  ///< --camera, --scene, --environment (a glTF scene)

    VarianceNeeds varianceNeeds() const { return {variance, targetError || !report.empty()}; }
    PngLook pngLook() const { return {exposure, filmic ? ToneCurve::Filmic : ToneCurve::Clamp}; }
    /// --spp caps the render; without it a time or error rule may run long.
    uint32_t maxSpp() const
    {
        return sppCap(sppGiven ? std::optional<uint32_t>(spp) : std::nullopt, timeBudget || targetError);
    }
};

bool environmentFlag(const char* name)
{
    const char* value = std::getenv(name);
    return value && *value && std::string(value) != "0";
}

std::string defaultOutputFor(const std::string& scenePath)
{
    return std::filesystem::path(scenePath).stem().string() + ".exr";
}

/// Shard i of n: the contiguous sample range [i S / n, (i + 1) S / n) of a render of S spp.
struct ShardRange {
    uint32_t index = 0, count = 1;
    uint32_t begin = 0, end = 0;
};

std::optional<ShardRange> shardRange(const RenderCommandOptions& options)
{
    if (options.shard.empty()) return std::nullopt;
    auto fail = [&](const std::string& why) -> ShardRange {
        throw InputError("--shard " + options.shard + ": " + why);
    };
    const size_t slash = options.shard.find('/');
    auto number = [&](const std::string& text) -> uint64_t {
        if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos)
            fail("expected i/n, two whole numbers with 0 <= i < n (shard i of n)");
        return std::stoull(text);
    };
    if (slash == std::string::npos) fail("expected i/n, two whole numbers with 0 <= i < n (shard i of n)");
    const uint64_t index = number(options.shard.substr(0, slash)), count = number(options.shard.substr(slash + 1));
    if (count == 0) fail("n must be at least 1");
    if (index >= count) fail("i must be below n (shards are numbered 0 ... n - 1)");
    if (count > options.spp)
        fail(std::to_string(count) + " shards of " + std::to_string(options.spp) +
             " spp would leave some without samples; use at most --spp shards");
    if (options.timeBudget || options.targetError || !options.report.empty())
        fail("a shard renders a fixed range of the samples; --time-budget, --target-error and --report apply to "
             "whole renders");
    ShardRange range{uint32_t(index), uint32_t(count)};
    range.begin = uint32_t(index * options.spp / count);
    range.end = uint32_t((index + 1) * options.spp / count);
    return range;
}

// ------------------------------------------------------------------- AOVs

/// --aov's names, checked (render/RenderOutput.h), and not with --shard (a
/// merge adds sums; AOVs are means).
std::vector<std::string> checkedAovs(const RenderCommandOptions& options)
{
    std::vector<std::string> names = checkedAovNames(options.aovs, "--aov");
    if (!names.empty() && !options.shard.empty())
        throw InputError("--aov cannot be combined with --shard: a merge adds the shards' sums, and AOVs are "
                         "means; render the AOVs in one run");
    return names;
}

SessionConfig sessionConfig(const RenderCommandOptions& options, const std::optional<ShardRange>& shard)
{
    SessionConfig config;
    config.seed = options.seed;
    config.samplesPerInvocation = options.samplesPerInvocation;
    config.extraDefines = parseKernelDefines(options.kernelDefines);
    config.maxBandBytes = options.maxBandBytes;
    config.maxTextureChunkBytes = options.maxTextureChunkBytes;
    if (shard) config.firstFrame = shard->begin;
    config.jitter = !options.pixelCenters;
    config.uber = options.uber;
    config.staged = options.staged;
    config.sampler = *samplerChoiceNamed(options.sampler); // CLI::IsMember checked it
    config.accel = options.accel;
    config.sceneReads = options.sceneReads;
    config.variance = options.varianceNeeds();
    config.aov = !options.aovs.empty();
    config.stop = {shard ? shard->end - shard->begin : options.maxSpp(), options.timeBudget, options.targetError,
                   &interruptFlag()};
    return config;
}

/// The reference for --report, checked before any rendering starts.
std::optional<Image> loadReference(const RenderCommandOptions& options, const Scene& scene)
{
    if (options.reference.empty()) return std::nullopt;
    Image reference = readExr(options.reference).image;
    if (reference.width != scene.camera.width || reference.height != scene.camera.height)
        throw InputError("--reference " + options.reference + ": image is " + std::to_string(reference.width) + "x" +
                         std::to_string(reference.height) + ", the render is " + std::to_string(scene.camera.width) +
                         "x" + std::to_string(scene.camera.height));
    return reference;
}

std::string reportHeader(const Scene& scene, const VulkanContext& context, double startupSeconds)
{
    char text[512];
    std::snprintf(text, sizeof text, "vkrt %s convergence report; scene=%s; device=%s; startup_seconds=%.4f",
                  VKRT_VERSION, scene.path.c_str(), context.deviceInfo().name.c_str(), startupSeconds);
    return text;
}

/// What a finished render reports. The summary line and --json are both
/// made from one of these, so the two cannot disagree.
struct RenderFacts {
    uint32_t spp = 0;
    uint32_t width = 0, height = 0;
    double renderSeconds = 0.0;
    double startupSeconds = 0.0;
    double samplesPerSecond = 0.0;
    std::string device;
    bool kernelFromCache = false;
    RenderCounters counters;
    bool loopCapped = false; ///< only then do loop-cap hits make a wrong image
    std::string output;
    std::vector<std::string> written; ///< every file the run wrote, in order (the summary names them)
    StopReason stoppedBy = StopReason::SppReached;
    std::optional<EstimatedError> estimated; ///< the error estimate at the stop, where one was made
    std::optional<double> targetError;
};

RenderFacts renderFacts(const RenderSession& session, const LoopResult& loop, double startupSeconds,
                        const std::string& output)
{
    const Renderer& renderer = session.renderer();
    RenderFacts facts;
    facts.spp = renderer.completedFrames();
    facts.width = renderer.width();
    facts.height = renderer.height();
    facts.renderSeconds = loop.renderSeconds;
    facts.startupSeconds = startupSeconds;
    const double samples = double(facts.spp) * facts.width * facts.height;
    facts.samplesPerSecond = loop.renderSeconds > 0 ? samples / loop.renderSeconds : 0.0;
    facts.device = session.context().deviceInfo().name;
    facts.kernelFromCache = renderer.kernel().fromCache;
    facts.counters = renderer.counters();
    facts.loopCapped = session.context().loopCap().capped();
    facts.output = output;
    facts.stoppedBy = session.stoppedBy().value_or(StopReason::SppReached);
    return facts;
}

/// Why the render stopped, in words: "spp", "time budget", "target error
/// reached: estimated relMSE X, upper bound Y < T", "interrupted".
std::string stopSentence(const RenderFacts& facts)
{
    switch (facts.stoppedBy) {
    case StopReason::TimeBudget: return "time budget";
    case StopReason::Interrupted: return "interrupted";
    case StopReason::TargetError: {
        std::string text = "target error reached";
        if (facts.estimated && facts.targetError) {
            char buffer[96];
            std::snprintf(buffer, sizeof buffer, ": estimated relMSE %.3g, upper bound %.3g < %.3g",
                          facts.estimated->relMse, facts.estimated->relMseUpper, *facts.targetError);
            text += buffer;
        }
        return text;
    }
    case StopReason::SppReached: break;
    }
    return "spp";
}

void printSummary(const RenderFacts& facts)
{
    std::string files;
    for (const std::string& file : facts.written) files += (files.empty() ? "" : ", ") + file;
    std::fprintf(stderr, "%u spp  %.2f s  %ssamples/s  %s  (start-up %.2f s%s)  stopped: %s  -> %s\n", facts.spp,
                 facts.renderSeconds, humanCount(facts.samplesPerSecond).c_str(), facts.device.c_str(),
                 facts.startupSeconds, facts.kernelFromCache ? ", kernel cached" : ", kernel compiled",
                 stopSentence(facts).c_str(), files.c_str());
    if (facts.counters.rejectedSamples)
        std::fprintf(stderr, "warning: %llu non-finite samples were rejected\n",
                     static_cast<unsigned long long>(facts.counters.rejectedSamples));
    if (facts.counters.overflowedPixels)
        std::fprintf(stderr,
                     "warning: %llu pixels overflowed float32 (radiance too large for its sum over the samples): "
                     "they are inf in the image\n",
                     static_cast<unsigned long long>(facts.counters.overflowedPixels));
    if (facts.counters.miscountedPixels)
        std::fprintf(stderr,
                     "warning: %llu pixels counted more samples than were rendered: the device miscounted (a driver "
                     "fault); the image cannot be trusted\n",
                     static_cast<unsigned long long>(facts.counters.miscountedPixels));
    if (facts.counters.budgetExceeded && facts.loopCapped)
        std::fprintf(stderr, "warning: %u invocations reached the device's loop cap; the image may be wrong\n",
                     facts.counters.budgetExceeded);
}

// ---------------------------------------------------------------- --json (docs/machine-output.md)

JsonObject errorEstimateJson(const RenderSession& session, const std::optional<EstimatedError>& estimated)
{
    if (!estimated) return nullptr;
    const Renderer& renderer = session.renderer();
    return {{"rmse", estimated->rmse},
            {"relMse", estimated->relMse},
            {"relMseUpper", estimated->relMseUpper},
            {"relMseConfidence", kRelMseConfidence},
            {"relMseDegreesOfFreedom", estimated->degreesOfFreedom},
            {"degreesOfFreedom", renderer.varianceDegreesOfFreedom()},
            {"estimator", session.sampler() == Sampler::Sobol ? "batches" : "independent-samples"}};
}

JsonObject shardJson(const std::optional<ShardRange>& shard, uint32_t totalSpp, uint32_t spp)
{
    if (!shard) return nullptr;
    return {{"index", shard->index},
            {"count", shard->count},
            {"sampleBegin", shard->begin},
            {"sampleEnd", shard->begin + spp},
            {"totalSpp", totalSpp}};
}

JsonObject outputsJson(const RenderCommandOptions& options, const RenderFacts& facts,
                       const std::map<std::string, Image>& layers)
{
    auto optionalPath = [](const std::string& path) { return path.empty() ? JsonObject(nullptr) : JsonObject(path); };
    JsonObject layerNames = JsonObject::array();
    for (const auto& [name, image] : layers) layerNames.push_back(name);
    const bool pngOutput = imageFormatOf(facts.output, "-o") == ImageFormat::Png;
    return {{"exr", pngOutput ? JsonObject(nullptr) : JsonObject(facts.output)},
            {"exrLayers", layerNames},
            {"png", pngOutput ? JsonObject(facts.output) : optionalPath(options.png)},
            {"previewPng", optionalPath(options.png)},
            {"report", optionalPath(options.report)},
            {"written", facts.written}};
}

JsonObject renderJson(const RenderCommandOptions& options, const RenderSession& session, const RenderFacts& facts,
                      const std::optional<EstimatedError>& estimated, const std::map<std::string, Image>& layers,
                      const std::optional<ShardRange>& shard, size_t validationMessages)
{
    const Scene& scene = session.scene();
    const Renderer& renderer = session.renderer();
    const DeviceInfo& device = session.context().deviceInfo();
    JsonObject json = jsonDocument("render");
    json["scene"] = scene.path;
    json["sceneHash"] = "fnv1a64:" + toHex(scene.fileHash);
    json["device"] = {{"name", facts.device}, {"driver", device.driver}};
    json["integrator"] = integratorName(scene.render.integrator);
    json["sampler"] = samplerName(session.sampler());
    json["accel"] = accelName(session.accel());
    json["vectorWidth"] = valueOrNull(lavapipeVectorBits(device)); // null: not lavapipe
    json["kernel"] = {{"variant", renderer.variant().describe()},
                      {"uber", options.uber},
                      {"cacheKey", renderer.kernel().cacheKey},
                      {"fromCache", facts.kernelFromCache},
                      {"compileSeconds", renderer.kernel().compileSeconds}};
    json["seed"] = options.seed;
    json["spp"] = facts.spp;
    json["width"] = facts.width;
    json["height"] = facts.height;
    json["renderSeconds"] = facts.renderSeconds;
    json["startupSeconds"] = facts.startupSeconds;
    json["firstFrameSeconds"] = nullptr; // render's warm-up frame is inside startupSeconds; `vkrt info` measures it
    json["samplesPerSecond"] = facts.samplesPerSecond;
    json["rejectedSamples"] = facts.counters.rejectedSamples;
    json["overflowedPixels"] = facts.counters.overflowedPixels;
    json["miscountedPixels"] = facts.counters.miscountedPixels;
    json["loopCap"] = {{"capped", facts.loopCapped},
                       {"budget", valueOrNull(session.context().loopCap().budget)},
                       {"invocationsAtCap", facts.counters.budgetExceeded}};
    json["stoppedBy"] = stopReasonName(session.stoppedBy().value_or(StopReason::SppReached));
    json["timeBudgetSeconds"] = valueOrNull(options.timeBudget);
    json["targetRelMse"] = valueOrNull(options.targetError);
    json["errorEstimate"] = errorEstimateJson(session, estimated);
    json["shard"] = shardJson(shard, options.spp, facts.spp);
    json["outputs"] = outputsJson(options, facts, layers);
    json["validationMessages"] = validationMessages;
    return json;
}

void warnIfTooFewForAnEstimate(const Renderer& renderer)
{
    if (renderer.varianceDegreesOfFreedom() != 0) return;
    const uint32_t spp = renderer.completedFrames();
    if (renderer.variant().sobolSampler) // its estimate comes from batches
        std::fprintf(stderr,
                     "vkrt: warning: %u spp are too few for an error estimate with the Sobol' sampler: it needs %u "
                     "(one per independently scrambled batch); the estimate and any variance layer are +inf\n",
                     spp, gpu::VARIANCE_BATCHES);
    else
        std::fprintf(stderr,
                     "vkrt: warning: %u spp %s too few for an error estimate: it needs at least 2; the estimate "
                     "and any variance layer are +inf\n",
                     spp, spp == 1 ? "is" : "are");
}

/// A shard's EXR carries its range and its tally, which `vkrt merge` adds up.
void addShard(const ShardRange& shard, uint32_t totalSpp, const Renderer& renderer, Metadata& metadata,
              std::map<std::string, Image>& layers)
{
    metadata["shard"] = std::to_string(shard.index) + "/" + std::to_string(shard.count);
    metadata["sampleBegin"] = int64_t(shard.begin);
    // Interrupted: the samples actually rendered (stoppedBy says so).
    metadata["sampleEnd"] = int64_t(shard.begin + renderer.completedFrames());
    metadata["totalSpp"] = int64_t(totalSpp);
    addTallyLayers(renderer.tally(), layers);
}

/// Runs the session's stop rules, feeding --report at every checkpoint.
LoopResult renderWithProgress(RenderSession& session, std::optional<ConvergenceReport>& report,
                              uint32_t& lastCheckpoint)
{
    const Camera& camera = session.scene().camera;
    Progress progress(session.config().stop.maxSpp, uint64_t(camera.width) * camera.height, isatty(STDERR_FILENO));
    RunHooks hooks;
    hooks.onProgress = [&](uint32_t done) { progress.update(done); };
    if (report)
        hooks.onCheckpoint = [&](uint32_t spp, double seconds, const Film& film) {
            report->add(spp, seconds, film.mean, *film.estimated);
            lastCheckpoint = spp;
        };
    LoopResult loop = session.run(hooks);
    progress.finish();
    return loop;
}

Outcome interruptedBeforeRendering()
{
    return Outcome::of(OutcomeKind::Interrupted, {"vkrt: interrupted before rendering started; nothing written"});
}

std::vector<NamedFile> renderOutputs(const RenderCommandOptions& options, const std::string& output)
{
    return {{"-o", output}, {"--png", options.png}, {"--report", options.report}, jsonOutputFile(options.json)};
}

/// Before any work: no output may destroy an input or another output, and each must be writable.
void checkRenderFiles(const RenderCommandOptions& options, const std::string& output)
{
    checkOutputs({{"the scene file", options.scenePath}, {"--reference", options.reference}},
                 renderOutputs(options, output));
    // The format comes from the extension: never EXR bytes under a .png name.
    if (imageFormatOf(output, "-o") == ImageFormat::Png) {
        const char* layerOption = options.variance ? "--variance" : !options.aovs.empty() ? "--aov" : nullptr;
        if (layerOption)
            throw InputError("-o " + output + ": " + layerOption +
                             " writes EXR layers, which a PNG cannot hold; write an .exr (with --png for a preview)");
        if (!options.shard.empty())
            throw InputError("-o " + output + ": a shard is an EXR of sums that `vkrt merge` adds; write an .exr");
    }
    const bool pngDiscarded =
        !options.png.empty() && resolveOutputTarget(options.png).kind == OutputTargetKind::Discarded;
    if (!options.png.empty() && !pngDiscarded && imageFormatOf(options.png, "--png") != ImageFormat::Png)
        throw InputError("--png " + options.png + ": names a PNG file, so it must end in .png");
}

/// Starts vkrt again with lavapipe at the width --vector-width chooses, before
/// anything is compiled or written; returns when the running width is it.
void startAtTheVectorWidth(const RenderCommandOptions& options, const VulkanContext& context, const Scene& scene)
{
    const bool driverAccel =
        resolveAccel(options.accel, context.deviceInfo(), meshTriangleCount(scene)) == Accel::Driver;
    const VectorWidthFacts facts = vectorWidthFacts(context, scene, driverAccel);
    if (std::optional<int> bits = chooseVectorBits(options.vectorWidth, facts)) relaunchAtVectorWidth(*bits, facts);
}

Outcome runRender(const RenderCommandOptions& options)
{
    // Ctrl-C asks to stop from the very start (even while a driver hangs creating the instance);
    // a second one ends the process at once.
    InterruptGuard interrupt;
    auto start = std::chrono::steady_clock::now();
    const std::optional<ShardRange> shard = shardRange(options);
    const std::vector<std::string> aovNames = checkedAovs(options);
    std::string output = options.output.empty() ? defaultOutputFor(options.scenePath) : options.output;
    checkRenderFiles(options, output);
    Scene scene = loadScene(options.scenePath, {options.width, options.height}, options.gltf);
    refuseOverlappingFiles(filesTheSceneRead(scene), renderOutputs(options, output));

    VulkanContext context({options.device, options.validation || environmentFlag("VKRT_VALIDATION")});
    startAtTheVectorWidth(options, context, scene);
    std::optional<Image> reference = loadReference(options, scene);
    if (interruptFlag()) return interruptedBeforeRendering();
    // On a terminal, say what the silent seconds of a cold start are.
    if (isatty(STDERR_FILENO))
        std::fprintf(stderr,
                     "vkrt: setting up %s: its buffers, and its kernel (compiled the first time a scene "
                     "needs it, seconds; cached after)...\n",
                     options.scenePath.c_str());
    RenderSession session(context, std::move(scene), sessionConfig(options, shard));
    double startupSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    std::optional<ConvergenceReport> report;
    if (!options.report.empty())
        report.emplace(options.report, reportHeader(session.scene(), context, startupSeconds), std::move(reference));
    uint32_t lastCheckpoint = 0;
    LoopResult loop = renderWithProgress(session, report, lastCheckpoint);
    const Renderer& renderer = session.renderer();
    if (renderer.completedFrames() == 0)
        return Outcome::of(OutcomeKind::Interrupted,
                           {"vkrt: interrupted before the first frame finished; nothing written"});

    Film film = session.film();
    if (film.variance) {
        warnIfTooFewForAnEstimate(renderer);
        if (report && lastCheckpoint != renderer.completedFrames())
            report->add(renderer.completedFrames(), loop.renderSeconds, film.mean, *film.estimated); // the last row
    }
    const std::optional<EstimatedError> estimated = film.estimated;
    RenderOutput out = renderOutput(session, std::move(film), options.variance, aovNames);
    if (shard) addShard(*shard, options.spp, renderer, out.metadata, out.layers);
    writeRenderImage(output, out, options.pngLook(), "-o");
    if (!options.png.empty()) writePng(options.png, out.mean, options.exposure, options.pngLook().curve);
    RenderFacts facts = renderFacts(session, loop, startupSeconds, output);
    facts.estimated = estimated;
    facts.targetError = options.targetError;
    for (const std::string& file : {output, options.png, options.report, jsonOutputFile(options.json).path.string()})
        if (!file.empty()) facts.written.push_back(file);
    printSummary(facts);
    if (!options.json.empty())
        writeJson(options.json, renderJson(options, session, facts, estimated, out.layers, shard,
                                           context.validationMessages().size()));
    return withValidation(session.outcome(), context.validationMessages());
}

/// "must be > 0 seconds, not 0": CLI::PositiveNumber's message printed its
/// bound, the largest double, in 310 digits. CLI11 prefixes the option's name.
CLI::Validator positiveFiniteNumber(const std::string& unit)
{
    return CLI::Validator(
        [unit](const std::string& text) -> std::string {
            char* end = nullptr;
            const double value = std::strtod(text.c_str(), &end);
            if (end == text.c_str() || *end != '\0') return "must be a number of " + unit + ", not " + text;
            if (!std::isfinite(value) || !(value > 0.0)) return "must be > 0 " + unit + " and finite, not " + text;
            return std::string();
        },
        "POSITIVE");
}

} // namespace

CommandRunner addRenderCommand(CLI::App& app)
{
    // CLI::Range lets NaN through (every comparison with it is false).
    CLI::Validator finiteNumber(
        [](const std::string& text) {
            double value = std::strtod(text.c_str(), nullptr);
            return std::isfinite(value) ? std::string() : "must be a finite number, got " + text;
        },
        "FINITE");
    auto options = std::make_shared<RenderCommandOptions>();
    CLI::App* cmd = app.add_subcommand("render", "Render a scene file to an OpenEXR image");
    // "SCENE", not "scene": CLI11 2.4 (Debian 13) refuses a positional named like an option (--scene).
    cmd->add_option("SCENE", options->scenePath,
                    "Scene file (TOML, see docs/scene-format.md; or a glTF .gltf/.glb file as a scene)")
        ->required();
    cmd->add_option("-o,--output", options->output,
                    "Output image: .exr (linear HDR, every layer) or .png (8-bit sRGB, tone-mapped as --exposure and "
                    "--filmic say); default: SCENE's name with .exr, here");
    cmd->add_option("--spp", options->spp,
                    "Samples per pixel (default 64; with --time-budget or --target-error: no limit)")
        ->check(CLI::Range(1u, 1u << 30))
        ->each([options](const std::string&) { options->sppGiven = true; });
    // Checked with the scene parser's limits (SceneOverrides.h) once the scene is read.
    cmd->add_option("--width", options->width, "Image width (overrides the scene)");
    cmd->add_option("--height", options->height, "Image height (overrides the scene)");
    cmd->add_option("--seed", options->seed, "Random seed (same seed, same image)");
    cmd->add_option("--device", options->device, "Vulkan device index or name (see `vkrt devices`)");
    cmd->add_option("--png", options->png, "Also write a tone-mapped 8-bit sRGB PNG preview");
    cmd->add_option("--exposure", options->exposure, "PNG exposure in stops (x 2^E)")
        ->check(finiteNumber)
        ->check(CLI::Range(-64.0, 64.0));
    cmd->add_flag("--filmic", options->filmic,
                  "PNG tone curve: ACES filmic (highlights roll off) instead of clamping, as the viewer's --filmic");
    cmd->add_flag("--validation", options->validation,
                  "Enable Vulkan validation; any message makes the exit status 3 (also VKRT_VALIDATION=1)");
    cmd->add_flag("--uber", options->uber, "Use the all-features kernel instead of the scene's variant");
    cmd->add_flag("--staged", options->staged,
                  "Run the path integrator as two kernels, trace and shade, that take turns (the same image)");
    cmd->add_flag("--pixel-centers", options->pixelCenters, "Sample pixel centres only (no anti-aliasing jitter)");
    cmd->add_option("--time-budget", options->timeBudget, "Stop after this many seconds of rendering")
        ->check(positiveFiniteNumber("seconds"));
    cmd->add_option("--target-error", options->targetError,
                    "Stop once the estimated relMSE's 95 % upper bound falls below this (the true relMSE then "
                    "meets it in 95 % of runs: docs/convergence.md)")
        ->check(positiveFiniteNumber("relMSE"));
    cmd->add_option("--report", options->report, "Write a convergence CSV (error against time, docs/convergence.md)");
    cmd->add_option("--json", options->json,
                    "Also write the run's facts (spp, times, samples/s, device, outputs, ...) as one JSON object to "
                    "FILE, or to standard output for - (docs/machine-output.md)");
    cmd->add_option("--reference", options->reference, "Reference EXR for the report's true error")
        ->needs(cmd->get_option("--report"));
    cmd->add_flag("--variance", options->variance,
                  "Also estimate per-pixel variance and write the variance of each pixel's mean as layer 'variance'");
    cmd->add_option("--sampler", options->sampler,
                    "auto (default: sobol, except independent for --variance and for error estimates too large "
                    "for the Sobol' batch sums), independent, or sobol "
                    "(Owen-scrambled Sobol' points: lower error; any variance estimate comes from " +
                        std::to_string(gpu::VARIANCE_BATCHES) + " independently scrambled batches)")
        ->check(CLI::IsMember({"auto", "independent", "sobol"}));
    addAccelOption(*cmd, options->accel);
    addSceneReadsOption(*cmd, options->sceneReads);
    addVectorWidthOption(*cmd, options->vectorWidth);
    cmd->add_option("--camera", options->gltf.camera,
                    "A glTF scene's camera to render through: its or its node's name, or its index (default: the "
                    "first)");
    cmd->add_option("--scene", options->gltf.scene,
                    "Which of a glTF file's scenes to render: its name or index (default: the file's `scene`)");
    cmd->add_option("--variant", options->gltf.variant,
                    "A glTF file's KHR_materials_variants variant: its name or index (default: the default materials)");
    cmd->add_option("--environment", options->gltf.environment,
                    "A lat-long .exr or .hdr map lighting a glTF scene (default: a grey studio gradient for a file "
                    "without lights, else black; docs/scene-format.md)");
    cmd->add_option("--aov", options->aovs,
                    "Also write arbitrary output values as EXR layers, comma-separated: albedo (albedo.R/G/B), "
                    "normal (N.X/Y/Z, world space), depth (Z, camera space), position (P.X/Y/Z, world space); "
                    "albedo and normal of the first non-specular surface, as Open Image Denoise expects")
        ->delimiter(',');
    cmd->add_option("--shard", options->shard,
                    "Render only shard i of n (0 <= i < n): samples [i S/n, (i+1) S/n) of --spp S, seeded as in one "
                    "run; `vkrt merge` adds the shards (docs/farm.md)");
    cmd->add_option(
           "--samples-per-invocation", options->samplesPerInvocation,
           "Samples one shader invocation renders back to back per dispatch (default 16, 1 on Mesa 22's "
           "lavapipe); a tuning knob: the image does not depend on it, up to float rounding in cubemap lookups")
        ->check(CLI::Range(1u, 64u));
    cmd->add_option("--kernel-define", options->kernelDefines,
                    "NAME=VALUE define for the kernel (test and measurement hooks, e.g. tools/lane_occupancy.py)")
        ->group("");
    cmd->add_option("--max-band-bytes", options->maxBandBytes,
                    "Render in bands whose per-pixel buffers hold at most this many bytes (test hook; default: the "
                    "device's maxStorageBufferRange)")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 40))
        ->group("");
    addTextureChunkOption(*cmd, options->maxTextureChunkBytes);
    addInjectOption(*cmd, options->injectFault);
    return [options] {
        applyInjectOption(options->injectFault);
        return exitCodeFor(runRender(*options));
    };
}

} // namespace vkrt
