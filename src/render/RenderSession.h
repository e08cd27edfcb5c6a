#pragma once
// One render session: a validated scene (overrides applied) -> a Renderer
// (kernel variant) -> batched frames until a stop rule fires -> the film read
// back -> the EXR metadata. `vkrt render`, `view`, `regress` and `info`
// configure a session instead of each owning a loop, a sampler policy and a
// metadata list, so a new stop rule or metadata field is one edit here.
#include "io/ExrFile.h"
#include "render/Accel.h"
#include "render/ErrorMetrics.h"
#include "render/Outcome.h"
#include "render/RenderLoop.h"
#include "render/Renderer.h"
#include "scene/GltfScene.h"
#include "scene/SceneOverrides.h"
#include "util/Signals.h"

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace vkrt {

// ---------------------------------------------------------------- sampler

enum class SamplerChoice { Auto, Independent, Sobol };
enum class Sampler { Independent, Sobol };

/// "auto", "independent" or "sobol" (the --sampler values); nullopt otherwise.
std::optional<SamplerChoice> samplerChoiceNamed(const std::string& name);
std::string samplerName(Sampler sampler);

/// What a session estimates besides the mean.
struct VarianceNeeds {
    bool layer = false;         ///< a per-pixel variance (EXR layer, regression test, viewer --variance)
    bool errorEstimate = false; ///< only the image's error (--report, --target-error)
    bool any() const { return layer || errorEstimate; }
};

/// The one sampler policy. A given choice is kept; "auto" picks Sobol'
/// (lower error; error estimates come from its independently scrambled
/// batches) except for a per-pixel variance, which independent samples give
/// with spp - 1 degrees of freedom instead of VARIANCE_BATCHES - 1, and except
/// where the batch sums would pass the storage-buffer range the device
/// guarantees (lavapipe: 0.6 M pixels), where independent samples need about
/// a sixth of that.
Sampler resolveSampler(SamplerChoice choice, VarianceNeeds needs, uint64_t pixels, uint64_t storageBufferRange);

// ---------------------------------------------------------------- scene

/// Parses and validates a scene file, then applies and checks `resolution`
/// with the parser's limits. Throws SceneError / InputError.
/// A TOML scene, or a glTF file as a scene (scene/GltfScene.h, with `gltf`'s
/// choices); prints the scene's warnings.
Scene loadScene(const std::string& path, const ResolutionOverride& resolution = {}, const GltfSceneOptions& gltf = {});

// ---------------------------------------------------------------- session

/// Everything a command chooses about a session.
struct SessionConfig {
    uint32_t seed = 0;
    uint32_t firstFrame = 0;           ///< the first sample index rendered (a shard's start; docs/farm.md)
    uint32_t samplesPerInvocation = 0; ///< RenderOptions::samplesPerInvocation
    bool jitter = true;
    bool uber = false;
    bool staged = false;                      ///< RenderOptions::staged
    SceneReads sceneReads = SceneReads::Auto; ///< RenderOptions::sceneReads
    bool warmUp = true; ///< render and discard a frame first, so timing excludes the driver's shader compile
    SamplerChoice sampler = SamplerChoice::Auto;
    VarianceNeeds variance;
    bool aov = false;                      ///< average the AOVs too (RenderOptions::aov)
    AccelChoice accel = AccelChoice::Auto; ///< the traversal backend (resolveAccel decides Auto)
    std::vector<Define> extraDefines;      ///< test hooks
    uint64_t maxBandBytes = 0;             ///< RenderOptions::maxBandBytes (a test hook; 0: the device's limit)
    uint64_t maxTextureChunkBytes = 0;     ///< RenderOptions::maxTextureChunkBytes (a test hook; 0: the device's)
    std::filesystem::path cacheDirectory = SpirvCache::defaultDirectory();
    StopRules stop; ///< of run(); its interrupt is usually &interruptFlag() (InterruptGuard)
};

/// What the accumulation holds, read back to the host.
struct Film {
    Image mean;
    std::optional<Image> variance;           ///< of each pixel's mean, when the kernel estimates it
    std::optional<EstimatedError> estimated; ///< the image's error, from that variance
};

/// Callbacks of run(): progress after every submission, and the film at every
/// checkpoint (1, 2, 4, ... spp and the last one) when asked for.
struct RunHooks {
    std::function<void(uint32_t framesDone)> onProgress;
    std::function<void(uint32_t spp, double renderSeconds, const Film& film)> onCheckpoint;
};

class RenderSession {
public:
    RenderSession(const VulkanContext& context, Scene scene, SessionConfig config);

    /// Renders until a stop rule fires (spp, time budget, target error, interrupt).
    LoopResult run(const RunHooks& hooks = {});
    /// Renders `frames` more outside the stop rules (the viewer paces frames by its display).
    void renderFrames(uint32_t frames);
    /// Renders `frames` more in paced submissions, stopping early only on the
    /// stop rules' interrupt (a batch of the Python module's progressive loop).
    LoopResult runFrames(uint32_t frames, const RunHooks& hooks = {});

    /// Starts the accumulation afresh.
    void reset();
    /// Moves the camera if the scene parser would accept it; otherwise leaves
    /// everything as it was and returns why ("fov: must be ...").
    [[nodiscard]] std::optional<std::string> moveCamera(const Camera& camera);
    /// Switches the integrator (a new kernel variant) and starts afresh.
    void setIntegrator(Integrator integrator);

    /// Reads back the mean, and the variance and error estimate if the kernel makes them.
    Film film() const;
    /// The EXR metadata of every image vkrt writes from a session; `savedBy`
    /// names an interactive save ("vkrt view").
    Metadata metadata(const Film& film, const std::string& savedBy = {}) const;
    /// Passed, or Interrupted when the interrupt stopped run().
    Outcome outcome() const;

    const Scene& scene() const { return m_scene; }
    const SessionConfig& config() const { return m_config; }
    const RenderOptions& renderOptions() const { return m_renderOptions; }
    const Renderer& renderer() const { return *m_renderer; }
    const VulkanContext& context() const { return m_context; }
    Sampler sampler() const;
    /// The traversal backend that runs (resolveAccel's choice).
    Accel accel() const { return m_renderOptions.driverAccel ? Accel::Driver : Accel::Own; }
    uint32_t spp() const { return m_renderer->completedFrames(); }
    double renderSeconds() const { return m_renderSeconds; }
    std::optional<StopReason> stoppedBy() const { return m_stoppedBy; }

private:
    const VulkanContext& m_context;
    Scene m_scene;
    SessionConfig m_config;
    RenderOptions m_renderOptions;
    std::unique_ptr<Renderer> m_renderer;
    double m_renderSeconds = 0.0;
    std::optional<StopReason> m_stoppedBy;

    void createRenderer();
    void startAfresh();
    CheckpointDecision atCheckpoint(const RunHooks& hooks, uint32_t spp, double seconds) const;
};

// ---------------------------------------------------------------- Ctrl-C

/// While alive, the first SIGINT only sets interruptFlag() (cleared on
/// construction), so that a session stops between submissions and keeps what
/// it has; a second SIGINT removes any temporary output and exits at once
/// (util/Signals.h). The previous handler comes back on destruction.
class InterruptGuard {
private:
    StopOnInterrupt m_stopOnInterrupt;
};

/// The flag InterruptGuard's handler sets; pass its address as
/// SessionConfig::stop.interrupt (StopRules::interrupt), which run() polls
/// between submissions.
const std::atomic<bool>& interruptFlag();

/// Whether Ctrl-C has asked the running command to stop (interruptFlag()).
inline bool interrupted() { return interruptFlag().load(); }

} // namespace vkrt
