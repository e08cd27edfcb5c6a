#include "render/RenderSession.h"

#include "gpu/VectorWidth.h"

#include "scene/GltfScene.h"
#include "scene/SceneParser.h"
#include "util/Hash.h"

#include <chrono>
#include <cstdio>

namespace vkrt {

// ---------------------------------------------------------------- sampler

std::optional<SamplerChoice> samplerChoiceNamed(const std::string& name)
{
    if (name == "auto") return SamplerChoice::Auto;
    if (name == "independent") return SamplerChoice::Independent;
    if (name == "sobol") return SamplerChoice::Sobol;
    return std::nullopt;
}

std::string samplerName(Sampler sampler) { return sampler == Sampler::Sobol ? "sobol" : "independent"; }

std::optional<AccelChoice> accelChoiceNamed(const std::string& name)
{
    if (name == "own") return AccelChoice::Own;
    if (name == "driver") return AccelChoice::Driver;
    if (name == "auto") return AccelChoice::Auto;
    return std::nullopt;
}

std::string accelName(Accel accel) { return accel == Accel::Driver ? "driver" : "own"; }

std::string accelChoiceName(AccelChoice choice)
{
    switch (choice) {
    case AccelChoice::Own: return "own";
    case AccelChoice::Driver: return "driver";
    case AccelChoice::Auto: break;
    }
    return "auto";
}

Accel resolveAccel(AccelChoice choice, const DeviceInfo& device, uint64_t meshTriangles)
{
    if (choice == AccelChoice::Own) return Accel::Own;
    if (choice == AccelChoice::Driver) {
        if (!device.rayQuery())
            throw InputError("--accel driver: " + device.name + " (" + device.driver + ") lacks " +
                             device.rayQueryMissing + "; use --accel own or auto");
        return Accel::Driver;
    }
    if (!device.rayQuery()) return Accel::Own;
    // On a GPU the driver's traversal is the one that uses its ray-tracing
    // hardware. On lavapipe (Mesa 25.0 and 26.1, whole renders, same paths)
    // it measured 1.25-1.32x the own backend's samples/s on a 36-triangle
    // scene, 0.8-1.4x around 500-1000 triangles, 0.58-0.87x on 69,000 and
    // 0.45-0.62x without meshes (docs/performance.md).
    if (device.type != vk::PhysicalDeviceType::eCpu) return Accel::Driver;
    return meshTriangles > 0 && meshTriangles <= kDriverAccelMaxCpuTriangles ? Accel::Driver : Accel::Own;
}

Sampler resolveSampler(SamplerChoice choice, VarianceNeeds needs, uint64_t pixels, uint64_t storageBufferRange)
{
    if (choice == SamplerChoice::Independent) return Sampler::Independent;
    if (choice == SamplerChoice::Sobol) return Sampler::Sobol;
    if (needs.layer) return Sampler::Independent;
    bool batchesFit = pixels * varianceBytesPerPixel(true) <= storageBufferRange;
    return needs.errorEstimate && !batchesFit ? Sampler::Independent : Sampler::Sobol;
}

// ---------------------------------------------------------------- scene

Scene loadScene(const std::string& path, const ResolutionOverride& resolution, const GltfSceneOptions& gltf)
{
    if (!isGltfPath(path) && (gltf.camera || gltf.environment || gltf.scene || gltf.variant))
        throw InputError(std::string(gltf.camera    ? "--camera"
                                     : gltf.scene   ? "--scene"
                                     : gltf.variant ? "--variant"
                                                    : "--environment") +
                         " applies to a glTF scene (.gltf, .glb); " + path + " is a TOML scene");
    Scene scene = isGltfPath(path) ? parseGltfScene(path, gltf) : parseSceneFile(path);
    applyResolution(scene.camera, resolution);
    // What the scene asks for that vkrt cannot honour exactly (glTF extensions, ...): said, never silent.
    for (const std::string& warning : scene.warnings) std::fprintf(stderr, "vkrt: warning: %s\n", warning.c_str());
    return scene;
}

// ---------------------------------------------------------------- session

namespace {

using Clock = std::chrono::steady_clock;

RenderOptions renderOptionsFor(const VulkanContext& context, const Scene& scene, const SessionConfig& config)
{
    RenderOptions options;
    options.seed = config.seed;
    options.firstFrame = config.firstFrame;
    options.samplesPerInvocation = config.samplesPerInvocation;
    options.jitter = config.jitter;
    options.uber = config.uber;
    options.staged = config.staged;
    options.sceneReads = config.sceneReads;
    options.variance = config.variance.any();
    options.aov = config.aov;
    options.extraDefines = config.extraDefines;
    options.maxBandBytes = config.maxBandBytes;
    options.maxTextureChunkBytes = config.maxTextureChunkBytes;
    options.cacheDirectory = config.cacheDirectory;
    uint64_t pixels = uint64_t(scene.camera.width) * scene.camera.height;
    uint64_t range = context.physicalDevice().getProperties().limits.maxStorageBufferRange;
    options.sobol = resolveSampler(config.sampler, config.variance, pixels, range) == Sampler::Sobol;
    options.driverAccel = resolveAccel(config.accel, context.deviceInfo(), meshTriangleCount(scene)) == Accel::Driver;
    return options;
}

} // namespace

RenderSession::RenderSession(const VulkanContext& context, Scene scene, SessionConfig config)
    : m_context(context),
      m_scene(std::move(scene)),
      m_config(std::move(config)),
      m_renderOptions(renderOptionsFor(context, m_scene, m_config))
{
    createRenderer();
    if (m_config.warmUp) m_renderer->warmUp();
}

void RenderSession::createRenderer()
{
    m_renderer.reset(); // its buffers go before the new ones are made
    m_renderer = std::make_unique<Renderer>(m_context, m_scene, m_renderOptions);
    startAfresh();
}

void RenderSession::startAfresh()
{
    m_renderSeconds = 0.0;
    m_stoppedBy.reset();
}

CheckpointDecision RenderSession::atCheckpoint(const RunHooks& hooks, uint32_t spp, double seconds) const
{
    const std::optional<double>& target = m_config.stop.targetRelMse;
    if (!hooks.onCheckpoint && !target) return {}; // no read-back needed
    Film current = film();
    if (hooks.onCheckpoint) hooks.onCheckpoint(spp, seconds, current);
    if (!target || !current.estimated) return {};
    // The bound, not the point estimate: the estimate at few samples is
    // noisy, and stopping on it broke the target in most runs (docs/convergence.md).
    const double bound = current.estimated->relMseUpper;
    if (bound < *target) return {true, std::nullopt};
    // Look again where the bound should meet the target, not only at the
    // next doubling (which would cost up to twice the samples needed).
    const uint32_t granularity = sampler() == Sampler::Sobol ? gpu::VARIANCE_BATCHES : 1;
    return {false, sppExpectedToMeet(spp, bound, *target, granularity)};
}

LoopResult RenderSession::run(const RunHooks& hooks)
{
    LoopResult loop = runRenderLoop(*m_renderer, m_config.stop, hooks.onProgress,
                                    [&](uint32_t spp, double seconds) { return atCheckpoint(hooks, spp, seconds); });
    m_renderSeconds += loop.renderSeconds;
    m_stoppedBy = loop.reason;
    return loop;
}

LoopResult RenderSession::runFrames(uint32_t frames, const RunHooks& hooks)
{
    StopRules rules;
    rules.maxSpp = spp() + frames;
    rules.interrupt = m_config.stop.interrupt;
    LoopResult loop = runRenderLoop(*m_renderer, rules, hooks.onProgress, {});
    m_renderSeconds += loop.renderSeconds;
    m_stoppedBy = loop.reason;
    return loop;
}

void RenderSession::renderFrames(uint32_t frames)
{
    auto start = Clock::now();
    m_renderer->renderFrames(frames);
    m_renderSeconds += std::chrono::duration<double>(Clock::now() - start).count();
}

void RenderSession::reset()
{
    m_renderer->reset();
    startAfresh();
}

std::optional<std::string> RenderSession::moveCamera(const Camera& camera)
{
    if (auto problem = cameraProblem(camera)) return problem;
    if (camera.width != m_scene.camera.width || camera.height != m_scene.camera.height)
        return std::string("a camera move cannot change the image size");
    m_renderer->moveCamera(camera);
    m_scene.camera = camera;
    startAfresh();
    return std::nullopt;
}

void RenderSession::setIntegrator(Integrator integrator)
{
    m_scene.render.integrator = integrator;
    createRenderer();
}

Sampler RenderSession::sampler() const
{
    return m_renderer->variant().sobolSampler ? Sampler::Sobol : Sampler::Independent;
}

Film RenderSession::film() const
{
    Film film{m_renderer->mean(), std::nullopt, std::nullopt};
    if (m_renderer->variant().variance) {
        film.variance = m_renderer->varianceOfMean();
        film.estimated = estimateError(film.mean, *film.variance, double(m_renderer->varianceDegreesOfFreedom()));
    }
    return film;
}

Metadata RenderSession::metadata(const Film& film, const std::string& savedBy) const
{
    const Renderer& renderer = *m_renderer;
    const RenderCounters counters = renderer.counters();
    Metadata metadata{
        {"vkrtVersion", std::string(VKRT_VERSION)},
        {"spp", int64_t(renderer.completedFrames())},
        {"seed", int64_t(m_config.seed)},
        {"renderSeconds", m_renderSeconds},
        {"device", m_context.deviceInfo().name},
        {"driver", m_context.deviceInfo().driver},
        {"scene", m_scene.path},
        {"sceneHash", "fnv1a64:" + toHex(m_scene.fileHash)},
        {"integrator", integratorName(m_scene.render.integrator)},
        {"kernelVariant", renderer.variant().describe() + (m_config.uber ? " (uber)" : "")},
        {"sampler", samplerName(sampler())},
        {"accel", accelName(accel())},
        {"rejectedSamples", int64_t(counters.rejectedSamples)},
    };
    // Said wherever the image goes: an inf pixel is never written without it.
    if (counters.overflowedPixels) metadata["overflowedPixels"] = int64_t(counters.overflowedPixels);
    if (counters.miscountedPixels) metadata["miscountedPixels"] = int64_t(counters.miscountedPixels);
    // lavapipe's SIMD width (vkrt render --vector-width).
    if (std::optional<int> bits = lavapipeVectorBits(m_context.deviceInfo())) metadata["vectorWidth"] = int64_t(*bits);
    // Whether the device may have cut loops short (docs/platform.md).
    metadata["loopCap"] = m_context.loopCap().describe();
    if (m_stoppedBy) metadata["stoppedBy"] = stopReasonName(*m_stoppedBy);
    if (renderer.variant().variance) {
        // The variance's degrees of freedom: per-pixel tests on it (vkrt
        // compare) need Student's t rather than a normal when few.
        metadata["varianceDegreesOfFreedom"] = int64_t(renderer.varianceDegreesOfFreedom());
        metadata["varianceEstimator"] = sampler() == Sampler::Sobol
                                            ? std::to_string(gpu::VARIANCE_BATCHES) + " independently scrambled batches"
                                            : std::string("independent samples");
    }
    if (film.estimated) {
        metadata["estimatedRmse"] = film.estimated->rmse;
        metadata["estimatedRelMse"] = film.estimated->relMse;
        metadata["estimatedRelMseUpper"] = film.estimated->relMseUpper;
    }
    if (m_config.stop.timeBudgetSeconds) metadata["timeBudgetSeconds"] = *m_config.stop.timeBudgetSeconds;
    if (m_config.stop.targetRelMse) metadata["targetRelMse"] = *m_config.stop.targetRelMse;
    if (!savedBy.empty()) metadata["savedBy"] = savedBy;
    return metadata;
}

Outcome RenderSession::outcome() const
{
    if (m_stoppedBy == StopReason::Interrupted) return Outcome::of(OutcomeKind::Interrupted);
    return Outcome::passed();
}

// ---------------------------------------------------------------- Ctrl-C

const std::atomic<bool>& interruptFlag() { return StopOnInterrupt::stopRequested(); }

} // namespace vkrt
