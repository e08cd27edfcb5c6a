#include "render/Renderer.h"

#include "gpu/SpirvFault.h"
#include "gpu/VectorWidth.h"

#include "render/LightTable.h"
#include "render/RenderMemory.h"

#include "render/Environment.h"
#include "render/EnvironmentSampling.h"
#include "shared/Bindings.h"
#include "shared/TextureTypes.h"
#include "util/Error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <type_traits>

namespace vkrt {

namespace {

constexpr vk::BufferUsageFlags kStorage = vk::BufferUsageFlagBits::eStorageBuffer;

/// Several samples per invocation would share one loop budget on a device
/// that caps an invocation's loop passes in total: refused there.
void checkSamplesPerInvocation(const LoopCap& cap, uint32_t samplesPerInvocation)
{
    if (samplesPerInvocation > 1 && cap.capped())
        throw InputError("--samples-per-invocation " + std::to_string(samplesPerInvocation) +
                         ": this device ends every invocation's loops after " + std::to_string(*cap.budget) +
                         " passes in total (" + cap.evidence +
                         "), which several samples would share; use 1 (its default) or Mesa 25's lavapipe");
}

/// The uber kernel's features: every feature, except that the glTF alpha
/// test, emission textures, second uv set and pbr layers (transmission, iridescence, anisotropy) come only with a scene
/// that uses them. Measured on Mesa 26.1's lavapipe (LLVM 19.1): an uber kernel with either, rendering a scene without
/// them, crashed the driver (SIGSEGV in the dispatch; Mesa 25.0 ran it), while their own variants render right on both.
/// Until the cause is found the uber kernel does not carry code for data the scene lacks.
FeatureSet uberFeatures(const Scene& scene)
{
    FeatureSet features = FeatureSet::everything(scene.render.integrator);
    const FeatureSet own = featuresOf(scene);
    features.alpha = own.alpha;
    features.emissionTextures = own.emissionTextures;
    features.secondUvs = own.secondUvs;
    features.pbrLayers = own.pbrLayers;
    features.pbrLobes = own.pbrLobes;
    features.lightTable = own.lightTable; // the scene's lights decide how they are sampled
    return features;
}

/// The largest device-local memory heap (where the per-pixel buffers go).
uint64_t deviceLocalHeapBytes(const VulkanContext& context)
{
    const vk::PhysicalDeviceMemoryProperties memory = context.physicalDevice().getMemoryProperties();
    uint64_t largest = 0;
    for (uint32_t i = 0; i < memory.memoryHeapCount; ++i)
        if (memory.memoryHeaps[i].flags & vk::MemoryHeapFlagBits::eDeviceLocal)
            largest = std::max<uint64_t>(largest, memory.memoryHeaps[i].size);
    return largest;
}

/// What the device leaves a variant's texel buffers: each within one storage
/// buffer's range and one allocation, as many as the storage-buffer
/// descriptors its other bindings leave, and device memory.
TextureStorageLimits textureStorageLimits(const VulkanContext& context, const KernelVariant& variant,
                                          const RenderOptions& options)
{
    const auto properties =
        context.physicalDevice()
            .getProperties2<vk::PhysicalDeviceProperties2, vk::PhysicalDeviceMaintenance3Properties>();
    const vk::PhysicalDeviceLimits& limits = properties.get<vk::PhysicalDeviceProperties2>().properties.limits;
    TextureStorageLimits storage;
    storage.maxBufferBytes =
        std::min<uint64_t>(limits.maxStorageBufferRange,
                           properties.get<vk::PhysicalDeviceMaintenance3Properties>().maxMemoryAllocationSize);
    if (options.maxTextureChunkBytes > 0)
        storage.maxBufferBytes = std::min(storage.maxBufferBytes, options.maxTextureChunkBytes);
    const std::vector<uint32_t> bindings = variant.bindings();
    const auto others = uint32_t(std::count_if(bindings.begin(), bindings.end(), [&](uint32_t binding) {
        return binding != gpu::BINDING_TEXTURE_TEXELS && !variant.isUniformBinding(binding) &&
               descriptorTypeOf(binding) == vk::DescriptorType::eStorageBuffer;
    }));
    const uint32_t descriptors =
        std::min(limits.maxPerStageDescriptorStorageBuffers, limits.maxDescriptorSetStorageBuffers);
    storage.maxBuffers = descriptors > others ? descriptors - others : 0;
    if (const uint64_t heap = deviceLocalHeapBytes(context)) storage.memoryBytes = heap;
    return storage;
}

/// Splits the variant's texels as the device needs (TextureAtlas::chunking);
/// several buffers need the device to index arrays of them.
void chooseTextureChunks(const VulkanContext& context, const Scene& scene, const RenderOptions& options,
                         KernelVariant& variant)
{
    if (!variant.features.textures || !scene.textures) return;
    const TextureStorageLimits limits = textureStorageLimits(context, variant, options);
    const TextureChunking chunks = scene.textures->chunking(limits);
    const DeviceInfo& device = context.deviceInfo();
    if (chunks.count > 1 && !device.bufferArraysMissing.empty())
        throw InputError(scene.path + ": the scene's textures need " + formatBytes(scene.textures->texelBytes()) +
                         ", more than one storage buffer of " + device.name + " holds (" +
                         formatBytes(limits.maxBufferBytes) + "), and splitting them needs " +
                         device.bufferArraysMissing + ", which it lacks");
    variant.textureChunks = chunks.count;
    variant.textureChunkShift = chunks.shift;
}

} // namespace

bool sceneAddressesPay(const DeviceInfo& device)
{
    if (!device.bufferDeviceAddress || device.driverId != vk::DriverId::eMesaLlvmpipe) return false;
    const std::optional<std::pair<int, int>> mesa = mesaVersion(device);
    return mesa && mesa->first < 26;
}

namespace {

KernelVariant chooseVariant(const VulkanContext& context, const Scene& scene, const RenderOptions& options)
{
    checkSamplesPerInvocation(context.loopCap(), options.samplesPerInvocation); // before any compilation
    checkLoopBudget(scene, context.loopCap());                                  // or allocation
    KernelVariant variant;
    variant.features = options.uber ? uberFeatures(scene) : featuresOf(scene);
    variant.variance = options.variance;
    variant.aov = options.aov;
    variant.sobolSampler = options.sobol;
    variant.driverAccel = options.driverAccel;
    // The batch sums are laid out for VARIANCE_BATCHES batches; a different
    // sampler batch count would make the estimate describe other batches.
    bool batchOverride = std::any_of(options.extraDefines.begin(), options.extraDefines.end(),
                                     [](const Define& d) { return d.first == "VKRT_SOBOL_BATCHES"; });
    if (options.variance && options.sobol && batchOverride)
        throw InputError("VKRT_SOBOL_BATCHES cannot be overridden when the Sobol' sampler estimates variance "
                         "(its batch count is VARIANCE_BATCHES)");
    variant.uniformScene = sceneFitsUniformBuffers(scene) && !options.storageScene;
    variant.groupLoopCount = context.loopCap().capped() && !scene.meshes.empty();
    if (options.staged && variant.features.integrator != Integrator::Path)
        throw InputError(scene.path + ": --staged runs the path integrator only; the scene's integrator is " +
                         integratorName(variant.features.integrator));
    variant.staged = options.staged;
    // An injected neighbour-load fault (--inject) changes storage-buffer loads
    // only: auto reads the scene through descriptors then, so that the fault
    // reaches every scene array as docs/regress.md says.
    const std::optional<SpirvFault> fault = spirvFaultFromEnvironment();
    const bool faultOnDescriptorLoads = fault && fault->kind == SpirvFaultKind::NeighbourLoad;
    variant.sceneAddresses = options.sceneReads == SceneReads::Auto
                                 ? sceneAddressesPay(context.deviceInfo()) && !faultOnDescriptorLoads
                                 : options.sceneReads == SceneReads::Address;
    if (variant.sceneAddresses && !context.deviceInfo().bufferDeviceAddress)
        throw InputError("--scene-reads address needs the bufferDeviceAddress feature, which " +
                         context.deviceInfo().name + " lacks; use --scene-reads descriptor or auto");
    chooseTextureChunks(context, scene, options, variant);
    return variant;
}

/// The variant's bindings with their descriptor types (scene arrays are
/// uniform buffers in the uniform-scene variant).
std::vector<KernelBinding> kernelBindingsOf(const KernelVariant& variant)
{
    std::vector<KernelBinding> bindings = renderKernelBindings(variant.bindings());
    for (KernelBinding& binding : bindings) {
        if (variant.isUniformBinding(binding.index)) binding.type = vk::DescriptorType::eUniformBuffer;
        binding.count = variant.descriptorCount(binding.index);
    }
    return bindings;
}

/// Refuses a variant that binds more buffers of a type than the device allows
/// one shader stage (textures add one, or their chunks: a few).
std::vector<KernelBinding> checkedKernelBindings(const VulkanContext& context, const Scene& scene,
                                                 const KernelVariant& variant)
{
    std::vector<KernelBinding> bindings = kernelBindingsOf(variant);
    const vk::PhysicalDeviceLimits limits = context.physicalDevice().getProperties().limits;
    auto count = [&](vk::DescriptorType type) {
        uint32_t descriptors = 0;
        for (const KernelBinding& b : bindings) descriptors += b.type == type ? b.count : 0;
        return descriptors;
    };
    auto check = [&](vk::DescriptorType type, uint32_t limit, const char* what) {
        if (count(type) > limit)
            throw InputError(scene.path + ": the scene's kernel needs " + std::to_string(count(type)) + " " + what +
                             ", more than the device's limit of " + std::to_string(limit) + " per shader stage (" +
                             variant.describe() + ")");
    };
    check(vk::DescriptorType::eStorageBuffer, limits.maxPerStageDescriptorStorageBuffers, "storage buffers");
    check(vk::DescriptorType::eUniformBuffer, limits.maxPerStageDescriptorUniformBuffers, "uniform buffers");
    return bindings;
}

/// A scene array's GPU buffer: padded to the block's fixed capacity when it
/// is a uniform buffer, so the bound range covers the whole declared block.
template <typename T>
Buffer makeSceneArrayBuffer(const VulkanContext& context, std::vector<T> records, bool uniform, uint32_t capacity,
                            vk::BufferUsageFlags storageUsage)
{
    if (!uniform) return makeBufferFrom(context, records, storageUsage);
    VKRT_CHECK(records.size() <= capacity);
    records.resize(capacity);
    return makeBufferFrom(context, records, vk::BufferUsageFlagBits::eUniformBuffer);
}

/// The staged kernels' pipelines in ComputeKernel (kernelStages' order).
constexpr uint32_t kTraceStage = 0;
constexpr uint32_t kShadeStage = 1;

/// The variant's kernel; with staged kernels, stage `stage` (1 trace, 2 shade; lib/stages.glsl).
CompiledKernel compileVariant(const KernelVariant& variant, const RenderOptions& options, int stage = 2)
{
    KernelSource source{options.shaderRoot, "kernels/render.comp", variant.defines()};
    if (variant.staged) source.defines.emplace_back("VKRT_STAGE", std::to_string(stage));
    source.defines.insert(source.defines.end(), options.extraDefines.begin(), options.extraDefines.end());
    return compileKernelCached(source, SpirvCache(options.cacheDirectory));
}

Image constantFace(const glm::vec3& colour)
{
    Image face(1, 1);
    face.rgb = {colour.x, colour.y, colour.z};
    return face;
}

template <typename T>
std::span<const std::byte> bytesOf(const T& value)
{
    return std::as_bytes(std::span(&value, 1));
}

/// Mean of a compensated sum's samples (one channel); it must have a sample.
double compensatedMean(const gpu::AccumPixel& p, int channel)
{
    return (double(p.sum[channel]) - double(p.compensation[channel])) / double(p.count);
}

/// Bytes per pixel of the largest per-pixel buffer the options ask for.
uint64_t largestBytesPerPixel(const RenderOptions& options)
{
    uint64_t bytes = sizeof(gpu::AccumPixel);
    if (options.variance) bytes = std::max<uint64_t>(bytes, varianceBytesPerPixel(options.sobol));
    if (options.aov) bytes = std::max<uint64_t>(bytes, sizeof(gpu::AovPixel));
    return bytes;
}

} // namespace

size_t varianceBytesPerPixel(bool sobol)
{
    return sobol ? sizeof(gpu::AccumPixel) * gpu::VARIANCE_BATCHES : sizeof(gpu::MomentPixel);
}

namespace {

/// The image's bands, once it is known that the render's memory is there to have.
ImageBands checkedImageBands(const VulkanContext& context, const Scene& scene, const RenderOptions& options)
{
    const vk::PhysicalDeviceType type = context.physicalDevice().getProperties().deviceType;
    // lavapipe's and an integrated GPU's buffers are the host's memory.
    const bool deviceIsHostMemory =
        type == vk::PhysicalDeviceType::eCpu || type == vk::PhysicalDeviceType::eIntegratedGpu;
    checkRenderMemory(scene, renderMemoryOf(scene, options), deviceIsHostMemory, deviceLocalHeapBytes(context),
                      options.availableMemory ? options.availableMemory : availableHostMemory());
    return imageBandsOf(scene, options, context.physicalDevice().getProperties().limits.maxStorageBufferRange);
}

} // namespace

ImageBands imageBandsOf(const Scene& scene, const RenderOptions& options, uint64_t maxBytes)
{
    if (options.maxBandBytes > 0) maxBytes = std::min(maxBytes, options.maxBandBytes);
    return imageBandsFor(scene.camera.width, scene.camera.height, largestBytesPerPixel(options), maxBytes, scene.path);
}

namespace {

/// The light samples one shading point draws: one per record of every light
/// kind, except that all emitters (triangle lights, emissive meshes) are one
/// sample together; with the light table, its candidates (lib/lights.glsl).
uint64_t sampledLightCount(const Scene& scene)
{
    if (usesLightTable(scene)) return kLightTableCandidates;
    return (featuresOf(scene).emitters ? 1 : 0) + enumeratedLightCount(scene);
}

} // namespace

uint64_t worstCaseLoopIterations(const Scene& scene)
{
    // Per depth: one depth-loop step, a closest-hit query over every hittable
    // (primitives and triangle lights), and per point light one light-loop
    // step plus a shadow query, and as much for the one sample of all
    // emitters (triangle lights, emissive meshes). Whitted shadow queries pass through glass, repeating once
    // per interface crossed; the path integrator's stop at glass but its
    // paths take one more closest-hit step after the last vertex.
    uint64_t hittables = scene.primitiveCount() + emittingTriangleLights(scene).size();
    bool whitted = scene.render.integrator == Integrator::Whitted;
    bool glassShadows = whitted && featuresOf(scene).has(MaterialType::Dielectric);
    uint64_t shadowQuery = glassShadows ? gpu::MAX_SHADOW_CROSSINGS * (1 + hittables) : hittables;
    uint64_t lights = sampledLightCount(scene);
    // A ray that escapes looks for every soft sun (lib/lights/directional.glsl).
    uint64_t escape = 0;
    for (const DirectionalLight& light : scene.directionalLights) escape += light.angle > 0.0 ? 1 : 0;
    // A textured hit reads its material's slots in a loop (lib/material_textures.glsl).
    uint64_t textureSlots = featuresOf(scene).textures ? gpu::TEXTURE_SLOT_COUNT : 0;
    uint64_t perDepth = 1 + hittables + lights * (1 + shadowQuery) + escape + textureSlots;
    uint64_t depth = uint64_t(scene.render.maxDepth);
    // Sampling the map (featuresOf: a lat-long map in both integrators, a
    // cubemap in the path integrator): binary searches over at most 2^32
    // entries in all and a shadow query (through glass for Whitted).
    uint64_t environment = featuresOf(scene).environmentSampling ? 1 + 32 + shadowQuery : 0;
    if (whitted) return depth * (perDepth + environment);
    return depth * (perDepth + environment) + 1 + hittables;
}

void checkLoopBudget(const Scene& scene, const LoopCap& cap)
{
    if (!cap.capped()) return; // the device runs every loop to completion
    // BVH traversal has no useful static bound: a mesh scene's kernel counts
    // every subgroup's passes and renderFrames fails if one reached the cap.
    if (!scene.meshes.empty()) return;
    uint64_t worst = worstCaseLoopIterations(scene);
    if (worst >= *cap.budget)
        throw InputError(scene.path + ": scene too large for this device: one pixel sample may need " +
                         std::to_string(worst) + " loop iterations, but it silently stops every shader invocation at " +
                         std::to_string(*cap.budget) + " (" + cap.evidence +
                         "); reduce primitives or lights, or use Mesa 25's lavapipe, which has no such cap");
}

Renderer::Renderer(const VulkanContext& context, const Scene& scene, RenderOptions options)
    : m_context(context),
      m_scene(scene),
      m_options(std::move(options)),
      m_variant(chooseVariant(context, scene, m_options)),
      m_bands(checkedImageBands(context, scene, m_options)),
      m_static(prepareStaticScene(scene, context.physicalDevice().getProperties().limits.maxStorageBufferRange,
                                  TextureChunking{m_variant.textureChunks, m_variant.textureChunkShift})),
      m_data(convertScene(scene, frameSettings(), m_static)),
      m_compiled(compileVariant(m_variant, m_options)),
      m_traceCompiled(m_variant.staged ? compileVariant(m_variant, m_options, 1) : CompiledKernel{}),
      m_accumulation(context, m_bands, sizeof(gpu::AccumPixel), scene.path, "the accumulation buffer"),
      m_stats(context, sizeof(gpu::RenderStats),
              kStorage | vk::BufferUsageFlagBits::eTransferDst | vk::BufferUsageFlagBits::eTransferSrc,
              MemoryUse::Device),
      m_frameRun(context, sizeof(gpu::FrameRun), kStorage | vk::BufferUsageFlagBits::eTransferDst, MemoryUse::Device),
      m_kernel(context, kernelStages(), checkedKernelBindings(context, scene, m_variant), sizeof(gpu::FrameConstants),
               m_bands.count)
{
    if (m_variant.staged) {
        if (m_bands.count > 1)
            throw InputError(scene.path + ": --staged renders images of one band only (" +
                             std::to_string(m_bands.count) + " bands here)");
        m_lanes.emplace(context, 16 * (1 + vk::DeviceSize(gpu::STAGED_LANE_VEC4S) * width() * height()),
                        kStorage | vk::BufferUsageFlagBits::eTransferDst, MemoryUse::Readback);
        m_lanes->clear(context);
        m_kernel.bind(gpu::BINDING_STAGED_LANES, *m_lanes);
    }
    m_accumulation.clear(context);
    m_stats.clear(context);
    if (m_variant.variance) {
        if (batchedVariance())
            m_moments.emplace(context, m_bands, varianceBytesPerPixel(true), scene.path,
                              "the error estimate's " + std::to_string(gpu::VARIANCE_BATCHES) +
                                  " batch sums (Sobol' sampler)",
                              ", or estimate the error with --sampler independent (one sum per pixel)");
        else m_moments.emplace(context, m_bands, varianceBytesPerPixel(false), scene.path, "the variance estimate");
        m_moments->clear(context);
    }
    if (m_variant.aov) {
        m_aovs.emplace(context, m_bands, sizeof(gpu::AovPixel), scene.path, "the AOVs");
        m_aovs->clear(context);
    }
    bindPerPixelBuffers();
    m_kernel.bind(gpu::BINDING_STATS, m_stats);
    m_kernel.bind(gpu::BINDING_FRAME_RUN, m_frameRun);
    if (m_options.samplesPerInvocation == 0)
        m_options.samplesPerInvocation = samplesPerInvocationFor(context.loopCap());
    bindEnvironment();
    uploadMeshBuffers();
    uploadSceneBuffers();
    if (m_variant.driverAccel) {
        m_driverAccel.emplace(context, m_static, m_meshTriangles, m_scene, m_data);
        m_kernel.bind(gpu::BINDING_TOP_LEVEL, m_driverAccel->topLevel());
    }
}

// Descriptor set b of the kernel holds band b's per-pixel buffers; every
// other binding is the same in all of them.
void Renderer::bindPerPixelBuffers()
{
    for (uint32_t b = 0; b < m_bands.count; ++b) {
        m_kernel.bindInSet(b, gpu::BINDING_ACCUMULATION, m_accumulation.band(b));
        if (m_moments) m_kernel.bindInSet(b, gpu::BINDING_MOMENTS, m_moments->band(b));
        if (m_aovs) m_kernel.bindInSet(b, gpu::BINDING_AOVS, m_aovs->band(b));
    }
}

void Renderer::uploadMeshBuffers()
{
    auto addBuffer = [&](uint32_t binding, const auto& records, vk::BufferUsageFlags extra = {}) {
        if (!m_kernel.uses(binding)) return;
        VKRT_CHECK(m_meshBuffers.size() < m_meshBuffers.capacity()); // a reallocation would move bound buffers
        m_meshBuffers.push_back(makeBufferFrom(m_context, records, sceneReadUsage() | extra));
        bindSceneRead(binding, m_meshBuffers.back());
    };
    m_meshBuffers.reserve(11); // bind() keeps references: no reallocation (one per addBuffer below)
    addBuffer(gpu::BINDING_MESH_NODES, m_static.meshNodes);
    // The driver backend builds its triangle structures from this same buffer.
    addBuffer(gpu::BINDING_MESH_TRIANGLES, m_static.meshTriangles,
              m_variant.driverAccel ? DriverAccel::kBuildInputUsage : vk::BufferUsageFlags{});
    if (m_variant.driverAccel && m_kernel.uses(gpu::BINDING_MESH_TRIANGLES)) m_meshTriangles = &m_meshBuffers.back();
    addBuffer(gpu::BINDING_MESH_NORMALS, m_static.meshNormals);
    addBuffer(gpu::BINDING_MESH_UVS, m_static.meshUvs);
    addBuffer(gpu::BINDING_MESH_UVS1, m_static.meshUvs1);
    addBuffer(gpu::BINDING_MESH_TANGENTS, m_static.meshTangents);
    addBuffer(gpu::BINDING_MESH_MATERIALS, m_static.meshMaterials);
    addBuffer(gpu::BINDING_MESH_COLORS, m_static.meshColors);
    // Textures never change with the camera either: uploaded once, here.
    uploadTextureChunks();
    addBuffer(gpu::BINDING_TEXTURE_RECORDS, m_static.textures.records);
    addBuffer(gpu::BINDING_MATERIAL_TEXTURES, m_static.materialTextures);
    addBuffer(gpu::BINDING_MATERIAL_ALPHA, m_static.materialAlpha);
}

// The texel words, one buffer per chunk: a plain binding for one, an array for several.
void Renderer::uploadTextureChunks()
{
    if (!m_kernel.uses(gpu::BINDING_TEXTURE_TEXELS)) return;
    const TextureBuffers& textures = m_static.textures;
    VKRT_CHECK(textures.chunking.count == m_kernel.countOf(gpu::BINDING_TEXTURE_TEXELS));
    m_textureChunks.reserve(textures.chunking.count); // bind() keeps references: no reallocation
    for (uint32_t chunk = 0; chunk < textures.chunking.count; ++chunk)
        m_textureChunks.push_back(makeBufferFrom(m_context, textures.chunk(chunk), sceneReadUsage()));
    if (m_textureChunks.size() == 1) bindSceneRead(gpu::BINDING_TEXTURE_TEXELS, m_textureChunks.front());
    else m_kernel.bind(gpu::BINDING_TEXTURE_TEXELS, std::span<const Buffer>(m_textureChunks));
}

void Renderer::bindEnvironment()
{
    if (!m_kernel.uses(gpu::BINDING_ENVIRONMENT)) return;
    if (m_variant.features.latLong) bindLatLongMap();
    else bindCubemap();
}

void Renderer::bindCubemap()
{
    // The uber kernel samples a cubemap even for a constant background:
    // give it a 1x1 cube of that colour.
    std::array<Image, 6> faces;
    if (m_scene.background.cubemap) faces = loadCubemapFaces(*m_scene.background.cubemap);
    else faces.fill(constantFace(m_data.uniforms.backgroundColor));
    m_environment.emplace(m_context, faces);
    m_kernel.bind(gpu::BINDING_ENVIRONMENT, m_environment->view(), m_environment->sampler());
    m_environmentSizes.cubeSize = faces[0].width;
    m_environmentSizes.constant = isConstantEnvironment(faces);
    if (m_kernel.uses(gpu::BINDING_ENVIRONMENT_CDF)) {
        m_environmentCdf.emplace(makeBufferFrom(m_context, environmentCdf(faces), sceneReadUsage()));
        bindSceneRead(gpu::BINDING_ENVIRONMENT_CDF, *m_environmentCdf);
    }
}

void Renderer::bindLatLongMap()
{
    const Image map = loadEnvironmentMap(*m_scene.background.environment);
    m_environment.emplace(m_context, map);
    m_kernel.bind(gpu::BINDING_ENVIRONMENT, m_environment->view(), m_environment->sampler());
    m_environmentSizes.latLongExtent = {map.width, map.height};
    m_environmentSizes.constant = isConstantEnvironment(std::span(&map, 1));
    if (!m_kernel.uses(gpu::BINDING_ENVIRONMENT_CDF)) return;
    const LatLongDistribution distribution = latLongDistribution(map);
    m_environmentSizes.latLongGrid = {distribution.columns, distribution.rows};
    m_environmentSizes.latLongBlock = distribution.block;
    m_environmentCdf.emplace(makeBufferFrom(m_context, distribution.cdf, sceneReadUsage()));
    bindSceneRead(gpu::BINDING_ENVIRONMENT_CDF, *m_environmentCdf);
}

void Renderer::uploadSceneBuffers()
{
    auto addBuffer = [&](uint32_t binding, auto&& records, uint32_t uniformCapacity) {
        if (!m_kernel.uses(binding)) return;
        bool uniform = m_variant.isUniformBinding(binding);
        m_sceneBuffers.push_back(makeSceneArrayBuffer(m_context, records, uniform, uniformCapacity, sceneReadUsage()));
        if (uniform) m_kernel.bind(binding, m_sceneBuffers.back());
        else bindSceneRead(binding, m_sceneBuffers.back());
    };
    m_sceneBuffers.clear();
    m_sceneBuffers.reserve(gpu::BINDING_COUNT); // bind() keeps references: no reallocation
    m_data.uniforms.environmentSize = m_environmentSizes.cubeSize;
    m_data.uniforms.environmentExtent = m_environmentSizes.latLongExtent;
    m_data.uniforms.environmentGrid = m_environmentSizes.latLongGrid;
    m_data.uniforms.environmentBlock = m_environmentSizes.latLongBlock;
    if (m_environmentSizes.constant) m_data.uniforms.flags |= gpu::RENDER_FLAG_CONSTANT_ENVIRONMENT;
    addBuffer(gpu::BINDING_MATERIALS, m_data.materials, gpu::UNIFORM_MATERIALS);
#define VKRT_UPLOAD_ARRAY(KIND, Type, name, value, field, array, ARRAY, capacity, bounded) \
    addBuffer(gpu::BINDING_##ARRAY, m_data.array, gpu::UNIFORM_##ARRAY);
    VKRT_SHAPE_KINDS(VKRT_UPLOAD_ARRAY)
    VKRT_LIGHT_KINDS(VKRT_UPLOAD_ARRAY)
#undef VKRT_UPLOAD_ARRAY
    auto addStorage = [&](uint32_t binding, const auto& records) {
        if (!m_kernel.uses(binding)) return;
        m_sceneBuffers.push_back(makeBufferFrom(m_context, records, sceneReadUsage()));
        bindSceneRead(binding, m_sceneBuffers.back());
    };
    addStorage(gpu::BINDING_TOP_NODES, m_data.topNodes);
    addStorage(gpu::BINDING_TOP_REFS, m_data.topRefs);
    addStorage(gpu::BINDING_EMITTERS, m_data.emitters);
    addStorage(gpu::BINDING_LIGHT_TABLE, m_data.lightTable);
    addStorage(gpu::BINDING_MATERIAL_TABLES, m_static.materialTables);
    // Last: the uniforms carry the addresses of every buffer above.
    std::copy(m_bufferAddresses.begin(), m_bufferAddresses.end(), m_data.uniforms.bufferAddresses);
    addBuffer(gpu::BINDING_UNIFORMS, std::vector{m_data.uniforms}, 1);
}

vk::BufferUsageFlags Renderer::sceneReadUsage() const
{
    return m_variant.sceneAddresses ? kStorage | vk::BufferUsageFlagBits::eShaderDeviceAddress : kStorage;
}

void Renderer::bindSceneRead(uint32_t binding, const Buffer& buffer)
{
    VKRT_CHECK(binding < m_bufferAddresses.size());
    m_kernel.bind(binding, buffer);
    if (!m_variant.sceneAddresses) return;
    const vk::DeviceAddress address = buffer.address(m_context);
    m_bufferAddresses[binding] = glm::uvec2(uint32_t(address), uint32_t(address >> 32));
}

std::vector<std::span<const uint32_t>> Renderer::kernelStages() const
{
    if (!m_variant.staged) return {m_compiled.spirv};
    return {m_traceCompiled.spirv, m_compiled.spirv};
}

void Renderer::reset()
{
    m_frames = 0;
    if (m_lanes) m_lanes->clear(m_context);
    m_accumulation.clear(m_context);
    m_stats.clear(m_context);
    if (m_moments) m_moments->clear(m_context);
    if (m_aovs) m_aovs->clear(m_context);
}

void Renderer::moveCamera(const Camera& camera)
{
    VKRT_CHECK(camera.width == width() && camera.height == height());
    m_scene.camera = camera;
    m_data = convertScene(m_scene, frameSettings(), m_static);
    uploadSceneBuffers();
    if (m_driverAccel) {
        m_driverAccel->moveCamera(m_scene, m_data);
        m_kernel.bind(gpu::BINDING_TOP_LEVEL, m_driverAccel->topLevel());
    }
    reset();
}

uint32_t samplesPerInvocationFor(const LoopCap& cap)
{
    // Of 1, 4, 8, 16 and 32, 16 measured best on the validation scenes
    // (docs/performance.md, "Path regeneration").
    return cap.capped() ? 1 : 16;
}

// Makes the next dispatches add `run`'s frames (shared/SceneTypes.h: FrameRun).
void Renderer::recordFrameRun(vk::CommandBuffer cmd, const gpu::FrameRun& run) const
{
    // The previous run's dispatches read what this update overwrites.
    vk::MemoryBarrier before(vk::AccessFlagBits::eShaderRead, vk::AccessFlagBits::eTransferWrite);
    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eTransfer, {}, before,
                        nullptr, nullptr);
    cmd.updateBuffer(m_frameRun.handle(), 0, sizeof run, &run);
    vk::MemoryBarrier after(vk::AccessFlagBits::eTransferWrite, vk::AccessFlagBits::eShaderRead);
    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eComputeShader, {}, after,
                        nullptr, nullptr);
}

// One bind and push per run of frames and band; dispatch i of the run (base
// workgroup z = i) adds frames firstFrame + i * S onwards, S per invocation
// (shared/SceneTypes.h: FrameConstants, FrameRun), to band b's rows (base
// workgroup y = b * the band's workgroup rows; render.comp).
void Renderer::recordFrames(vk::CommandBuffer cmd, uint32_t firstFrame, uint32_t count) const
{
    uint32_t perInvocation = m_options.samplesPerInvocation;
    recordFrameRun(cmd, gpu::FrameRun{perInvocation, firstFrame + count});
    gpu::FrameConstants constants{firstFrame, m_options.seed};
    uint32_t tilesX = (width() + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X;
    uint32_t bandTileRows = m_bands.tileRowsPerBand();
    uint32_t dispatches = (count + perInvocation - 1) / perInvocation;
    for (uint32_t band = 0; band < m_bands.count; ++band) {
        m_kernel.recordBind(cmd, bytesOf(constants), band);
        for (uint32_t i = 0; i < dispatches; ++i) {
            m_kernel.recordDispatchAt(cmd, vk::Offset2D(0, int32_t(band * bandTileRows)), i,
                                      vk::Extent2D(tilesX, bandTileRows));
            // The next dispatch reads and writes the same accumulation pixels.
            vk::MemoryBarrier barrier(vk::AccessFlagBits::eShaderWrite,
                                      vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite);
            cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eComputeShader,
                                {}, barrier, nullptr, nullptr);
        }
    }
}

void Renderer::renderFrames(uint32_t frames)
{
    if (frames == 0) return;
    // Base z + 1 stays within maxComputeWorkGroupCount[2], which Vulkan
    // guarantees to be at least 65,535.
    constexpr uint32_t maxRun = 4096;
    if (m_variant.staged) {
        for (uint32_t done = 0; done < frames; done += maxRun)
            renderStagedRun(m_options.firstFrame + m_frames + done, std::min(maxRun, frames - done));
    } else
        m_context.submitAndWait([&](vk::CommandBuffer cmd) {
            for (uint32_t done = 0; done < frames; done += maxRun)
                recordFrames(cmd, m_options.firstFrame + m_frames + done, std::min(maxRun, frames - done));
        });
    m_frames += frames;
    if (m_variant.groupLoopCount && counters().budgetExceeded)
        throw InputError(m_scene.path + ": " + std::to_string(counters().budgetExceeded) +
                         " shader invocations reached this device's loop cap of " +
                         std::to_string(*m_context.loopCap().budget) + " passes per subgroup (" +
                         m_context.loopCap().evidence +
                         ") while traversing the scene's meshes, so their samples may be cut short; the image is "
                         "not written. Use Mesa 25's lavapipe, which has no such cap, or simpler meshes");
}

// The staged kernels take turns, shade then trace, a few rounds per
// submission, until the last shade leaves no lane work (lib/stages.glsl).
void Renderer::renderStagedRun(uint32_t firstFrame, uint32_t count)
{
    constexpr uint32_t roundsPerSubmit = 8;
    const gpu::FrameConstants constants{firstFrame, m_options.seed};
    const uint32_t tilesX = (width() + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X;
    const vk::Extent2D groups(tilesX, m_bands.tileRowsPerBand());
    auto* header = static_cast<volatile uint32_t*>(m_lanes->mapped());
    VKRT_CHECK(header != nullptr);
    // A round advances every lane by one segment or its last shadow ray: a
    // sample takes at most max_depth + 3 rounds (start, segments, shadow), so
    // a lane still busy after that many is a fault, not a long path.
    const uint64_t roundLimit = uint64_t(count) * (m_data.uniforms.maxDepth + 3) + roundsPerSubmit;
    bool first = true;
    for (uint64_t rounds = 0;; rounds += roundsPerSubmit) {
        if (rounds > roundLimit)
            throw GpuError("the staged kernels' lanes still had work after " + std::to_string(rounds) + " rounds for " +
                           std::to_string(count) + " samples: the device lost track of them");
        m_context.submitAndWait([&](vk::CommandBuffer cmd) {
            if (first) recordFrameRun(cmd, gpu::FrameRun{count, firstFrame + count});
            m_kernel.recordBind(cmd, bytesOf(constants), 0, kShadeStage);
            vk::MemoryBarrier shaderToShader(vk::AccessFlagBits::eShaderWrite,
                                             vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite);
            vk::MemoryBarrier transferToShader(vk::AccessFlagBits::eTransferWrite,
                                               vk::AccessFlagBits::eShaderRead | vk::AccessFlagBits::eShaderWrite);
            for (uint32_t round = 0; round < roundsPerSubmit; ++round) {
                if (round + 1 == roundsPerSubmit) {
                    // Only the last shade's verdict counts.
                    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eTransfer,
                                        {},
                                        vk::MemoryBarrier(vk::AccessFlagBits::eShaderWrite,
                                                          vk::AccessFlagBits::eTransferWrite),
                                        nullptr, nullptr);
                    cmd.fillBuffer(m_lanes->handle(), 0, 4, 0);
                    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eTransfer, vk::PipelineStageFlagBits::eComputeShader,
                                        {}, transferToShader, nullptr, nullptr);
                }
                for (uint32_t stage : {kShadeStage, kTraceStage}) {
                    m_kernel.recordBindStage(cmd, stage);
                    m_kernel.recordDispatchAt(cmd, vk::Offset2D(0, 0), 0, groups);
                    cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader,
                                        vk::PipelineStageFlagBits::eComputeShader, {}, shaderToShader, nullptr,
                                        nullptr);
                }
            }
            cmd.pipelineBarrier(vk::PipelineStageFlagBits::eComputeShader, vk::PipelineStageFlagBits::eHost, {},
                                vk::MemoryBarrier(vk::AccessFlagBits::eShaderWrite, vk::AccessFlagBits::eHostRead),
                                nullptr, nullptr);
        });
        first = false;
        if (header[0] == 0) return;
    }
}

void Renderer::warmUp()
{
    VKRT_CHECK(m_frames == 0);
    if (m_variant.staged) {
        // One workgroup of each stage: lavapipe compiles each at its first dispatch.
        m_context.submitAndWait([&](vk::CommandBuffer cmd) {
            recordFrameRun(cmd, gpu::FrameRun{1, 1});
            for (uint32_t stage : {kShadeStage, kTraceStage}) {
                m_kernel.recordBind(cmd, bytesOf(gpu::FrameConstants{0, m_options.seed}), 0, stage);
                m_kernel.recordDispatchAt(cmd, vk::Offset2D(0, 0), 0, vk::Extent2D(1, 1));
            }
        });
        reset();
        return;
    }
    // One workgroup is enough to make lavapipe compile the kernel.
    m_context.submitAndWait([&](vk::CommandBuffer cmd) {
        recordFrameRun(cmd, gpu::FrameRun{1, 1});
        m_kernel.recordBind(cmd, bytesOf(gpu::FrameConstants{0, m_options.seed}));
        m_kernel.recordDispatchAt(cmd, vk::Offset2D(0, 0), 0, vk::Extent2D(1, 1));
    });
    reset();
}

AovImages Renderer::aovs() const
{
    VKRT_CHECK(m_aovs.has_value());
    auto bytes = m_aovs->download(m_context);
    const auto* pixels = reinterpret_cast<const gpu::AovPixel*>(bytes.data());
    AovImages out{Image(width(), height()), Image(width(), height()), Image(width(), height()),
                  std::vector<float>(size_t(width()) * height(), std::numeric_limits<float>::infinity())};
    const glm::dvec3 eye = m_scene.camera.eye;
    for (size_t i = 0; i < out.albedo.pixelCount(); ++i) {
        const gpu::AovPixel& p = pixels[i];
        std::copy_n(&p.albedo.x, 3, &out.albedo.rgb[i * 3]);
        std::copy_n(&p.normal.x, 3, &out.normal.rgb[i * 3]);
        if (p.hits == 0) continue;
        const glm::dvec3 world = glm::dvec3(p.position) + eye;
        for (int c = 0; c < 3; ++c) out.position.rgb[i * 3 + c] = float(world[c]);
        out.depth[i] = p.depth;
    }
    return out;
}

Image Renderer::mean() const
{
    if (batchedVariance()) return meanOfBatchMeans();
    auto bytes = m_accumulation.download(m_context);
    const auto* pixels = reinterpret_cast<const gpu::AccumPixel*>(bytes.data());
    Image image(width(), height());
    for (size_t i = 0; i < image.pixelCount(); ++i) {
        const gpu::AccumPixel& p = pixels[i];
        if (p.count == 0) continue; // every sample was non-finite: black, and counted
        for (int c = 0; c < 3; ++c) image.rgb[i * 3 + c] = float(compensatedMean(p, c));
    }
    return image;
}

namespace {

/// Variance of a pixel's mean from K independent batch means (one channel):
/// sum_b (m_b - mean)^2 / (K (K - 1)); +inf when a batch has no sample yet.
float varianceFromBatches(const gpu::AccumPixel* batches, uint32_t count, int channel)
{
    std::vector<double> means(count);
    for (uint32_t b = 0; b < count; ++b) {
        if (batches[b].count == 0) return std::numeric_limits<float>::infinity();
        means[b] = compensatedMean(batches[b], channel);
    }
    double mean = std::accumulate(means.begin(), means.end(), 0.0) / count;
    double squares = 0.0;
    for (double m : means) squares += (m - mean) * (m - mean);
    double variance = squares / (double(count) * (count - 1));
    return std::isfinite(variance) ? float(variance) : std::numeric_limits<float>::infinity();
}

} // namespace

Image Renderer::varianceOfMean() const
{
    VKRT_CHECK(m_moments.has_value());
    if (batchedVariance()) return varianceOfMeanFromBatches();
    auto accumBytes = m_accumulation.download(m_context);
    auto momentBytes = m_moments->download(m_context);
    const auto* pixels = reinterpret_cast<const gpu::AccumPixel*>(accumBytes.data());
    const auto* moments = reinterpret_cast<const gpu::MomentPixel*>(momentBytes.data());
    Image image(width(), height());
    for (size_t i = 0; i < image.pixelCount(); ++i) {
        double n = pixels[i].count;
        for (int c = 0; c < 3; ++c) {
            // An overflowed sum of squares (a radiance near float's limit) is an
            // unknown, huge variance: report +inf, never a reassuring 0.
            double m2 = double(moments[i].m2[c]) - double(moments[i].m2Compensation[c]);
            bool known = n >= 2 && std::isfinite(m2);
            image.rgb[i * 3 + c] =
                known ? float(std::max(0.0, m2) / (n - 1) / n) : std::numeric_limits<float>::infinity();
        }
    }
    return image;
}

// The estimate whose variance varianceOfMeanFromBatches() gives: batch means
// weighted equally. Frames that are not a multiple of the batch count, or
// rejected (non-finite) samples, leave batches with unequal counts; a mean
// weighted by count would then be a different estimator from the one the
// variance describes. A pixel with an empty batch (fewer frames than
// batches, or all of a batch's samples rejected) has no such estimate and
// falls back to the mean of all its samples (its variance is +inf).
Image Renderer::meanOfBatchMeans() const
{
    auto accumBytes = m_accumulation.download(m_context);
    auto batchBytes = m_moments->download(m_context);
    const auto* pixels = reinterpret_cast<const gpu::AccumPixel*>(accumBytes.data());
    const auto* batches = reinterpret_cast<const gpu::AccumPixel*>(batchBytes.data());
    Image image(width(), height());
    for (size_t i = 0; i < image.pixelCount(); ++i) {
        const gpu::AccumPixel* pixelBatches = batches + i * gpu::VARIANCE_BATCHES;
        bool everyBatch = std::all_of(pixelBatches, pixelBatches + gpu::VARIANCE_BATCHES,
                                      [](const gpu::AccumPixel& b) { return b.count > 0; });
        for (int c = 0; c < 3; ++c) {
            double value = 0.0;
            if (everyBatch) {
                for (uint32_t b = 0; b < gpu::VARIANCE_BATCHES; ++b) value += compensatedMean(pixelBatches[b], c);
                value /= gpu::VARIANCE_BATCHES;
            } else if (pixels[i].count > 0) {
                value = compensatedMean(pixels[i], c);
            }
            image.rgb[i * 3 + c] = float(value);
        }
    }
    return image;
}

Image Renderer::varianceOfMeanFromBatches() const
{
    auto bytes = m_moments->download(m_context);
    const auto* batches = reinterpret_cast<const gpu::AccumPixel*>(bytes.data());
    Image image(width(), height());
    for (size_t i = 0; i < image.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c)
            image.rgb[i * 3 + c] = varianceFromBatches(batches + i * gpu::VARIANCE_BATCHES, gpu::VARIANCE_BATCHES, c);
    return image;
}

uint64_t Renderer::varianceDegreesOfFreedom() const
{
    if (!m_variant.variance || m_frames == 0) return 0;
    if (batchedVariance()) return m_frames >= gpu::VARIANCE_BATCHES ? gpu::VARIANCE_BATCHES - 1 : 0;
    return m_frames - 1;
}

RenderCounters Renderer::counters() const
{
    auto accumBytes = m_accumulation.download(m_context);
    const auto* pixels = reinterpret_cast<const gpu::AccumPixel*>(accumBytes.data());
    RenderCounters counters;
    size_t pixelCount = size_t(width()) * height();
    for (size_t i = 0; i < pixelCount; ++i) {
        if (pixels[i].count <= m_frames) counters.rejectedSamples += m_frames - pixels[i].count;
        else ++counters.miscountedPixels;
        const glm::vec3 sum = pixels[i].sum;
        if (!std::isfinite(sum.x) || !std::isfinite(sum.y) || !std::isfinite(sum.z)) ++counters.overflowedPixels;
    }
    auto statsBytes = m_stats.download(m_context);
    const auto* stats = reinterpret_cast<const gpu::RenderStats*>(statsBytes.data());
    counters.maxLoopIterations = stats->maxLoopIterations;
    counters.budgetExceeded = stats->budgetExceeded;
    return counters;
}

Tally Renderer::tally() const
{
    auto accumBytes = m_accumulation.download(m_context);
    const auto* pixels = reinterpret_cast<const gpu::AccumPixel*>(accumBytes.data());
    Tally tally;
    tally.count = Image(width(), height());
    tally.mean = Image(width(), height());
    const size_t pixelCount = tally.count.pixelCount();
    for (size_t i = 0; i < pixelCount; ++i)
        for (int c = 0; c < 3; ++c) {
            tally.count.rgb[i * 3 + c] = float(pixels[i].count);
            if (pixels[i].count > 0) tally.mean.rgb[i * 3 + c] = float(compensatedMean(pixels[i], c));
        }
    if (!m_moments) return tally;
    auto bytes = m_moments->download(m_context);
    if (batchedVariance()) {
        const auto* batches = reinterpret_cast<const gpu::AccumPixel*>(bytes.data());
        for (uint32_t b = 0; b < gpu::VARIANCE_BATCHES; ++b) {
            Image count(width(), height()), mean(width(), height());
            for (size_t i = 0; i < pixelCount; ++i) {
                const gpu::AccumPixel& p = batches[i * gpu::VARIANCE_BATCHES + b];
                for (int c = 0; c < 3; ++c) {
                    count.rgb[i * 3 + c] = float(p.count);
                    if (p.count > 0) mean.rgb[i * 3 + c] = float(compensatedMean(p, c));
                }
            }
            tally.batchCount.push_back(std::move(count));
            tally.batchMean.push_back(std::move(mean));
        }
        return tally;
    }
    const auto* moments = reinterpret_cast<const gpu::MomentPixel*>(bytes.data());
    tally.m2 = Image(width(), height());
    for (size_t i = 0; i < pixelCount; ++i)
        for (int c = 0; c < 3; ++c)
            tally.m2->rgb[i * 3 + c] = float(double(moments[i].m2[c]) - double(moments[i].m2Compensation[c]));
    return tally;
}

} // namespace vkrt
