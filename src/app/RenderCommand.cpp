// `vkrt render SCENE`: renders a scene progressively and writes an EXR (and
// optionally a PNG preview). Ctrl-C stops early and still writes what was
// accumulated, with its true spp in the metadata.
#include "app/Commands.h"
#include "io/ExrFile.h"
#include "io/PngFile.h"
#include "render/ConvergenceReport.h"
#include "render/Progress.h"
#include "render/RenderLoop.h"
#include "scene/SceneParser.h"
#include "util/Error.h"
#include "util/Hash.h"

#include <CLI/CLI.hpp>

#include <atomic>
#include <cmath>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <unistd.h>

namespace vkrt {

namespace {

struct RenderCommandOptions {
    std::string scenePath;
    std::string output;
    uint32_t spp = 64;
    std::optional<uint32_t> width;
    std::optional<uint32_t> height;
    uint32_t seed = 0;
    std::string device;
    std::string png;
    float exposure = 0.0f;
    bool validation = false;
    bool uber = false;
    bool pixelCenters = false;
    bool variance = false;
    std::optional<double> timeBudget;
    std::optional<double> targetError;
    std::string report;
    std::string reference;
    bool sppGiven = false;
    std::string sampler = "auto";

    /// Variance is needed for the layer, the report and the target-error rule.
    bool needsVariance() const { return variance || targetError || !report.empty(); }
    /// "auto": Sobol' (lower error; --report and --target-error estimate the
    /// image's error from its independently scrambled batches), except for a
    /// per-pixel variance layer, which independent samples give with
    /// spp - 1 degrees of freedom instead of 7, and except where the batch
    /// sums (VARIANCE_BATCHES per pixel) would pass the storage-buffer range
    /// the device guarantees (lavapipe: 0.6 M pixels), where independent
    /// samples need about a sixth of that.
    std::string resolvedSampler(uint64_t pixels, uint64_t storageBufferRange) const
    {
        if (sampler != "auto") return sampler;
        if (variance) return "independent";
        bool batchesFit = pixels * varianceBytesPerPixel(true) <= storageBufferRange;
        return needsVariance() && !batchesFit ? "independent" : "sobol";
    }
    /// --spp caps the render; without it a time or error rule may run long.
    uint32_t maxSpp() const { return sppGiven || !(timeBudget || targetError) ? spp : (1u << 30); }
};

std::atomic<bool> g_interrupted{false};

extern "C" void onInterrupt(int) { g_interrupted.store(true); }

bool environmentFlag(const char* name)
{
    const char* value = std::getenv(name);
    return value && *value && std::string(value) != "0";
}

std::string defaultOutputFor(const std::string& scenePath)
{
    return std::filesystem::path(scenePath).stem().string() + ".exr";
}

void applyResolution(Scene& scene, const RenderCommandOptions& options)
{
    if (options.width) scene.camera.width = *options.width;
    if (options.height) scene.camera.height = *options.height;
    uint64_t pixels = uint64_t(scene.camera.width) * scene.camera.height;
    if (pixels > SceneLimits::maxImagePixels)
        throw InputError("--width/--height: " + std::to_string(pixels) + " pixels exceeds the limit of " +
                         std::to_string(SceneLimits::maxImagePixels));
}

Metadata describeRender(const Scene& scene, const VulkanContext& context, const Renderer& renderer,
                        const RenderCommandOptions& options, const LoopResult& loop, const RenderCounters& counters,
                        const std::optional<EstimatedError>& estimated)
{
    bool sobol = renderer.variant().sobolSampler;
    Metadata metadata{
        {"vkrtVersion", std::string(VKRT_VERSION)},
        {"spp", int64_t(renderer.completedFrames())},
        {"seed", int64_t(options.seed)},
        {"renderSeconds", loop.renderSeconds},
        {"stoppedBy", stopReasonName(loop.reason)},
        {"device", context.deviceInfo().name},
        {"driver", context.deviceInfo().driver},
        {"scene", scene.path},
        {"sceneHash", "fnv1a64:" + toHex(scene.fileHash)},
        {"integrator", integratorName(scene.render.integrator)},
        {"kernelVariant", renderer.variant().describe() + (options.uber ? " (uber)" : "")},
        {"sampler", std::string(sobol ? "sobol" : "independent")},
        {"rejectedSamples", int64_t(counters.rejectedSamples)},
    };
    if (options.variance) {
        // The variance layer's degrees of freedom: per-pixel tests on it
        // (vkrt compare) need Student's t rather than a normal when few.
        metadata["varianceDegreesOfFreedom"] = int64_t(renderer.varianceDegreesOfFreedom());
        metadata["varianceEstimator"] = sobol
                                            ? std::to_string(gpu::VARIANCE_BATCHES) + " independently scrambled batches"
                                            : std::string("independent samples");
    }
    if (estimated) {
        metadata["estimatedRmse"] = estimated->rmse;
        metadata["estimatedRelMse"] = estimated->relMse;
    }
    if (options.timeBudget) metadata["timeBudgetSeconds"] = *options.timeBudget;
    if (options.targetError) metadata["targetRelMse"] = *options.targetError;
    return metadata;
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

void printSummary(const Renderer& renderer, const VulkanContext& context, const LoopResult& loop,
                  const RenderCounters& counters, double startupSeconds, const std::string& output)
{
    double samples = double(renderer.completedFrames()) * renderer.width() * renderer.height();
    std::fprintf(stderr, "%u spp  %.2f s  %ssamples/s  %s  (start-up %.2f s%s)  -> %s\n", renderer.completedFrames(),
                 loop.renderSeconds, humanCount(loop.renderSeconds > 0 ? samples / loop.renderSeconds : 0).c_str(),
                 context.deviceInfo().name.c_str(), startupSeconds,
                 renderer.kernel().fromCache ? ", kernel cached" : ", kernel compiled", output.c_str());
    if (counters.rejectedSamples)
        std::fprintf(stderr, "warning: %llu non-finite samples were rejected\n",
                     static_cast<unsigned long long>(counters.rejectedSamples));
    if (counters.budgetExceeded)
        std::fprintf(stderr, "warning: %u invocations reached lavapipe's loop budget; the image may be wrong\n",
                     counters.budgetExceeded);
}

int reportValidation(const VulkanContext& context)
{
    auto messages = context.validationMessages();
    for (const auto& m : messages) std::fprintf(stderr, "%s\n", m.c_str());
    return messages.empty() ? kExitOk : kExitValidation;
}

int runRender(const RenderCommandOptions& options)
{
    auto start = std::chrono::steady_clock::now();
    Scene scene = parseSceneFile(options.scenePath);
    applyResolution(scene, options);
    std::string output = options.output.empty() ? defaultOutputFor(options.scenePath) : options.output;

    VulkanContext context({options.device, options.validation || environmentFlag("VKRT_VALIDATION")});
    RenderOptions renderOptions;
    renderOptions.seed = options.seed;
    renderOptions.jitter = !options.pixelCenters;
    renderOptions.uber = options.uber;
    renderOptions.variance = options.needsVariance();
    uint64_t pixels = uint64_t(scene.camera.width) * scene.camera.height;
    renderOptions.sobol =
        options.resolvedSampler(pixels, context.physicalDevice().getProperties().limits.maxStorageBufferRange) == "sobol";
    std::optional<Image> reference = loadReference(options, scene);
    Renderer renderer(context, scene, renderOptions);
    renderer.warmUp();
    double startupSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    std::optional<ConvergenceReport> report;
    if (!options.report.empty())
        report.emplace(options.report, reportHeader(scene, context, startupSeconds), std::move(reference));
    uint32_t lastCheckpoint = 0;
    auto onCheckpoint = [&](uint32_t spp, double seconds) {
        if (!report && !options.targetError) return false;
        Image mean = renderer.mean(), variance = renderer.varianceOfMean();
        if (report) report->add(spp, seconds, mean, variance);
        lastCheckpoint = spp;
        return options.targetError && estimateError(mean, variance).relMse < *options.targetError;
    };

    g_interrupted.store(false);
    std::signal(SIGINT, onInterrupt);
    StopRules rules{options.maxSpp(), options.timeBudget, &g_interrupted};
    Progress progress(rules.maxSpp, uint64_t(scene.camera.width) * scene.camera.height, isatty(STDERR_FILENO));
    LoopResult loop = runRenderLoop(
        renderer, rules, [&](uint32_t done) { progress.update(done); }, onCheckpoint);
    progress.finish();
    std::signal(SIGINT, SIG_DFL);

    if (renderer.completedFrames() == 0) {
        std::fprintf(stderr, "vkrt: interrupted before the first frame finished; nothing written\n");
        return kExitInterrupted;
    }
    RenderCounters counters = renderer.counters();
    Image image = renderer.mean();
    std::map<std::string, Image> layers;
    std::optional<EstimatedError> estimated;
    if (options.needsVariance()) {
        Image variance = renderer.varianceOfMean();
        estimated = estimateError(image, variance);
        if (renderer.varianceDegreesOfFreedom() == 0)
            std::fprintf(stderr,
                         "vkrt: warning: %u spp are too few for an error estimate (it needs 2, or %u with the "
                         "Sobol' sampler's batches): the estimate and any variance layer are +inf\n",
                         renderer.completedFrames(), gpu::VARIANCE_BATCHES);
        if (report && lastCheckpoint != renderer.completedFrames())
            report->add(renderer.completedFrames(), loop.renderSeconds, image, variance); // the last row
        if (options.variance) layers["variance"] = std::move(variance);
    }
    writeExr(output, image, describeRender(scene, context, renderer, options, loop, counters, estimated), layers);
    if (!options.png.empty()) writePng(options.png, image, options.exposure);
    printSummary(renderer, context, loop, counters, startupSeconds, output);
    if (int status = reportValidation(context); status != kExitOk) return status;
    return loop.reason == StopReason::Interrupted ? kExitInterrupted : kExitOk;
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
    cmd->add_option("scene", options->scenePath, "Scene file (TOML, see docs/scene-format.md)")->required();
    cmd->add_option("-o,--output", options->output, "Output EXR (default: SCENE's name with .exr, here)");
    cmd->add_option("--spp", options->spp, "Samples per pixel (default 64; with --time-budget or --target-error: no limit)")
        ->check(CLI::Range(1u, 1u << 30))
        ->each([options](const std::string&) { options->sppGiven = true; });
    cmd->add_option("--width", options->width, "Image width (overrides the scene)")
        ->check(CLI::Range(1u, SceneLimits::maxImageSide));
    cmd->add_option("--height", options->height, "Image height (overrides the scene)")
        ->check(CLI::Range(1u, SceneLimits::maxImageSide));
    cmd->add_option("--seed", options->seed, "Random seed (same seed, same image)");
    cmd->add_option("--device", options->device, "Vulkan device index or name (see `vkrt devices`)");
    cmd->add_option("--png", options->png, "Also write a tone-mapped 8-bit sRGB PNG preview");
    cmd->add_option("--exposure", options->exposure, "PNG exposure in stops (x 2^E)")->check(finiteNumber)->check(CLI::Range(-64.0, 64.0));
    cmd->add_flag("--validation", options->validation,
                  "Enable Vulkan validation; any message makes the exit status 3 (also VKRT_VALIDATION=1)");
    cmd->add_flag("--uber", options->uber, "Use the all-features kernel instead of the scene's variant");
    cmd->add_flag("--pixel-centers", options->pixelCenters, "Sample pixel centres only (no anti-aliasing jitter)");
    cmd->add_option("--time-budget", options->timeBudget, "Stop after this many seconds of rendering")
        ->check(finiteNumber)
        ->check(CLI::PositiveNumber);
    cmd->add_option("--target-error", options->targetError,
                    "Stop once the estimated relMSE falls below this (checked at 1, 2, 4, ... spp)")
        ->check(finiteNumber)
        ->check(CLI::PositiveNumber);
    cmd->add_option("--report", options->report, "Write a convergence CSV (error against time, docs/convergence.md)");
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
    return [options] { return runRender(*options); };
}

} // namespace vkrt
