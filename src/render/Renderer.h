#pragma once
// Progressive renderer: owns the kernel variant for a scene, its GPU buffers
// and the accumulation buffer; each frame adds one sample per pixel.
// A dispatch runs several frames per invocation (RenderOptions::samplesPerInvocation).
#include "gpu/Buffer.h"
#include "gpu/ComputeKernel.h"
#include "gpu/EnvironmentTexture.h"
#include "gpu/ShaderCompiler.h"
#include "io/Image.h"
#include "render/DriverAccel.h"
#include "render/GpuScene.h"
#include "render/ImageBands.h"
#include "render/KernelVariant.h"
#include "render/Tally.h"
#include "shared/Bindings.h"

#include <array>
#include <filesystem>
#include <optional>

namespace vkrt {

/// Through the buffers' device addresses, through their descriptors, or as
/// measured fastest to compile on the device (sceneAddressesPay).
enum class SceneReads { Auto, Address, Descriptor };

/// Whether reading the scene's buffers through device addresses pays on
/// this device: on lavapipe before Mesa 26, whose compiler turns every
/// divergent storage-buffer load into a loop over the lanes (cold start-up
/// 0.25-0.85x, docs/performance.md "Staged kernels"); Mesa 26 compiles
/// descriptor reads as fast or faster (0.97-1.22x the other way), and other
/// devices are not measured. Needs the bufferDeviceAddress feature.
bool sceneAddressesPay(const DeviceInfo& device);

struct RenderOptions {
    uint32_t seed = 0;
    bool jitter = true;
    bool uber = false;         ///< all-features kernel instead of the scene's variant
    bool variance = false;     ///< also estimate per-pixel variance (a kernel-variant flag)
    bool aov = false;          ///< also average the AOVs (albedo, normal, depth, position; a kernel-variant flag)
    bool sobol = false;        ///< Owen-scrambled Sobol' sampler (variance, if asked for, from batches)
    bool storageScene = false; ///< scene arrays in storage buffers even when they fit uniform ones
    bool driverAccel =
        false; ///< the driver's traversal (VK_KHR_ray_query) instead of vkrt's BVH (a kernel-variant flag)
    /// The path integrator as two kernels (trace, shade) that take turns
    /// (KernelVariant::staged); the same image bit for bit.
    bool staged = false;
    /// How the kernels read the scene's buffers (KernelVariant::sceneAddresses);
    /// the same image either way. Auto: sceneAddressesPay on the device.
    SceneReads sceneReads = SceneReads::Auto;
    uint32_t firstFrame = 0; ///< index of the first frame (sample) rendered: a shard's start
    /// Frames one invocation runs back to back per dispatch (path
    /// regeneration); 0: the device's default (samplesPerInvocationFor).
    /// The image does not depend on it (up to float rounding where a cubemap
    /// is sampled: lavapipe's lookup depends on which lanes share a vector).
    uint32_t samplesPerInvocation = 0;
    std::vector<Define> extraDefines; ///< test hooks (e.g. VKRT_TEST_INJECT_NONFINITE)
    /// Largest per-pixel buffer of one band of the image (ImageBands.h); 0:
    /// the device's maxStorageBufferRange. Tests set it to render small
    /// images in several bands.
    uint64_t maxBandBytes = 0;
    /// Largest storage buffer of texels (texture/TextureAtlas.h: texels
    /// beyond it are split into several); 0: the device's limit. A test hook:
    /// tests set it to split small scenes' textures.
    uint64_t maxTextureChunkBytes = 0;
    /// Host memory the render may use (RenderMemory.h); nullopt: what this
    /// process can still get. Tests set it to check the refusal.
    std::optional<uint64_t> availableMemory;
    std::filesystem::path shaderRoot = defaultShaderRoot();
    std::filesystem::path cacheDirectory = SpirvCache::defaultDirectory();
};

/// The arbitrary output values (RenderOptions::aov), per pixel: the means of
/// shared/SceneTypes.h's AovPixel, positions in world space (the eye added in
/// double); depth is +inf and position 0 where no camera ray hit anything.
struct AovImages {
    Image albedo;
    Image normal;
    Image position;
    std::vector<float> depth;
};

struct RenderCounters {
    uint64_t rejectedSamples = 0; ///< non-finite samples dropped (all pixels)
    /// Pixels whose accumulated sum is not finite although every sample was:
    /// radiance so large that its sum overflowed float32. Their mean is inf.
    uint64_t overflowedPixels = 0;
    /// Pixels that counted more samples than frames were rendered: only a
    /// faulty device (or an injected fault, `--inject neighbour-load`) does
    /// that. They add nothing to rejectedSamples (which once wrapped to 1.8e11).
    uint64_t miscountedPixels = 0;
    uint32_t maxLoopIterations = 0; ///< largest loop count of one sample seen
    uint32_t budgetExceeded = 0;    ///< invocations that reached lavapipe's loop budget
};

class Renderer {
public:
    Renderer(const VulkanContext& context, const Scene& scene, RenderOptions options);

    /// Adds `frames` samples per pixel (in one submission) and waits.
    void renderFrames(uint32_t frames);
    /// Renders and discards one frame, so that the driver's own shader
    /// compilation (lavapipe compiles at the first dispatch) happens now and
    /// not inside timed rendering. The image and counters start afresh.
    void warmUp();
    uint32_t completedFrames() const { return m_frames; }

    /// Discards everything accumulated so far (the next frame is frame 0).
    void reset();
    /// Moves the camera (same image size) and resets: the scene is re-made
    /// camera-relative and re-uploaded; the kernel and environment stay.
    void moveCamera(const Camera& camera);
    const Scene& scene() const { return m_scene; }
    const VulkanContext& context() const { return m_context; }
    /// The accumulation buffer (AccumPixel per pixel, in bands), for display kernels.
    const BandedBuffer& accumulation() const { return m_accumulation; }
    /// How the image's per-pixel buffers are split (one band unless they
    /// would exceed maxStorageBufferRange).
    const ImageBands& bands() const { return m_bands; }

    /// Per-pixel mean of the accepted samples, resolved in double precision
    /// (with batched variance: the mean of the batch means, see Renderer.cpp).
    Image mean() const;
    /// Per-pixel variance of that mean; needs RenderOptions::variance. With
    /// independent samples: sample variance / count (+inf below 2 samples).
    /// With the Sobol' sampler: from the gpu::VARIANCE_BATCHES independently
    /// scrambled batch means, VARIANCE_BATCHES - 1 degrees of freedom (+inf
    /// until every batch has a sample).
    Image varianceOfMean() const;
    /// Degrees of freedom of each pixel's variance estimate (0: none made yet).
    uint64_t varianceDegreesOfFreedom() const;
    RenderCounters counters() const;
    /// The AOVs; needs RenderOptions::aov.
    AovImages aovs() const;
    /// The per-pixel sums a merge adds up (render/Tally.h).
    Tally tally() const;

    const KernelVariant& variant() const { return m_variant; }
    const CompiledKernel& kernel() const { return m_compiled; }
    /// Staged kernels: the trace stage (kernel() is then the shade stage).
    const CompiledKernel& traceStage() const { return m_traceCompiled; }
    /// The scene's mesh data as uploaded (empty for a scene without meshes).
    const GpuSceneStatic& meshData() const { return m_static; }
    /// The driver backend's structures (null with vkrt's own traversal).
    const DriverAccel* driverAccel() const { return m_driverAccel ? &*m_driverAccel : nullptr; }
    uint32_t width() const { return m_data.uniforms.width; }
    uint32_t height() const { return m_data.uniforms.height; }

private:
    const VulkanContext& m_context;
    Scene m_scene;
    RenderOptions m_options;
    KernelVariant m_variant;
    ImageBands m_bands;      ///< before m_data, whose tile count is per band
    GpuSceneStatic m_static; ///< mesh geometry and the top-level topology: uploaded once
    GpuSceneData m_data;
    CompiledKernel m_compiled;      ///< the kernel, or with staged kernels the shade stage
    CompiledKernel m_traceCompiled; ///< staged kernels: the trace stage (else empty)
    std::vector<Buffer> m_meshBuffers;
    std::vector<Buffer> m_textureChunks; ///< the texel words, one buffer per chunk (TextureChunking)
    std::vector<Buffer> m_sceneBuffers;
    /// SceneUniforms::bufferAddresses: each read-only scene buffer's, at its binding.
    std::array<glm::uvec2, gpu::ADDRESSED_BINDING_COUNT> m_bufferAddresses{};
    BandedBuffer m_accumulation;
    Buffer m_stats;
    Buffer m_frameRun; ///< gpu::FrameRun of the run being dispatched
    std::optional<BandedBuffer> m_moments;
    std::optional<BandedBuffer> m_aovs;
    ComputeKernel m_kernel;
    std::optional<Buffer> m_lanes;           ///< staged kernels: every pixel's path between stages
    const Buffer* m_meshTriangles = nullptr; ///< in m_meshBuffers, for the driver backend's builds
    std::optional<DriverAccel> m_driverAccel;
    std::optional<EnvironmentTexture> m_environment;
    std::optional<Buffer> m_environmentCdf;
    /// The map's sizes, which every upload of the uniforms carries.
    struct EnvironmentSizes {
        uint32_t cubeSize = 0;
        glm::uvec2 latLongExtent{0}, latLongGrid{0};
        uint32_t latLongBlock = 1;
        bool constant = false; ///< every texel equal: RENDER_FLAG_CONSTANT_ENVIRONMENT
    } m_environmentSizes;
    uint32_t m_frames = 0;

    FrameSettings frameSettings() const { return FrameSettings{m_options.jitter, m_bands.rowsPerBand}; }
    bool batchedVariance() const { return m_variant.variance && m_variant.sobolSampler; }
    Image varianceOfMeanFromBatches() const;
    Image meanOfBatchMeans() const;
    void bindEnvironment();
    void bindCubemap();
    void bindLatLongMap();
    void uploadSceneBuffers();
    void uploadMeshBuffers();
    void uploadTextureChunks();
    /// The usage of the scene's read-only buffers: with device addresses where the kernels read them so.
    vk::BufferUsageFlags sceneReadUsage() const;
    /// Binds one of the scene's read-only buffers and notes its device address for the uniforms.
    void bindSceneRead(uint32_t binding, const Buffer& buffer);
    void recordFrames(vk::CommandBuffer cmd, uint32_t firstFrame, uint32_t count) const;
    void renderStagedRun(uint32_t firstFrame, uint32_t count);
    std::vector<std::span<const uint32_t>> kernelStages() const;
    void bindPerPixelBuffers();
    void recordFrameRun(vk::CommandBuffer cmd, const gpu::FrameRun& run) const;
};

/// Bytes per pixel of the variance estimate's buffer: Welford moments, or
/// under the Sobol' sampler one compensated sum per batch.
size_t varianceBytesPerPixel(bool sobol);

/// The bands in which a scene's image is rendered with these options: its
/// largest per-pixel buffer (accumulation, variance moments or batch sums)
/// fits `maxBytes` per band.
ImageBands imageBandsOf(const Scene& scene, const RenderOptions& options, uint64_t maxBytes);

/// Samples per invocation and dispatch when RenderOptions leaves it at 0:
/// several, so that lanes whose paths end early start their next sample
/// (docs/performance.md), but one on a device that caps an invocation's loop
/// passes in total (Mesa 22 lavapipe), where several samples would share one
/// budget.
uint32_t samplesPerInvocationFor(const LoopCap& cap);

/// Worst-case loop iterations one invocation of the scene's kernel can run.
uint64_t worstCaseLoopIterations(const Scene& scene);

/// Throws InputError naming the scene if its kernel could be cut short by the
/// device's loop cap (Mesa < 25 lavapipe); a device without a cap refuses nothing.
void checkLoopBudget(const Scene& scene, const LoopCap& cap);

} // namespace vkrt
