#pragma once
// The render kernel variant: a scene's FeatureSet plus the render options that
// change the kernel (variance estimation, the sampler, where scene arrays
// live), turned into preprocessor defines and descriptor bindings.
// Data flow: Scene -> FeatureSet -> KernelVariant -> defines -> SPIR-V (cached)
// -> pipeline. The shape and light arrays' defines, bindings and uniform
// capacities all come from the registry (shared/Kinds.h).
#include "scene/FeatureSet.h"

#include <string>
#include <utility>
#include <vector>

namespace vkrt {

/// One scene array of the GPU scene: its binding and its uniform-block capacity.
struct SceneArrayBinding {
    uint32_t binding;
    uint32_t uniformCapacity;
};

/// The materials array, then every shape and light array in registry order.
const std::vector<SceneArrayBinding>& sceneArrayBindings();

struct KernelVariant {
    explicit KernelVariant(const FeatureSet& sceneFeatures = {}) : features(sceneFeatures) {}

    FeatureSet features;
    bool variance = false;     ///< per-pixel variance estimation (a render option)
    bool aov = false;          ///< arbitrary output values: albedo, normal, depth, position (a render option)
    bool sobolSampler = false; ///< Owen-scrambled Sobol' points instead of independent ones (a render option)
    bool uniformScene = false; ///< scene arrays in uniform buffers: every array fits (shared/SceneTypes.h)
    /// Count loop passes per subgroup (the unit a capping driver counts in),
    /// for mesh scenes on a device that caps loops: their traversal has no
    /// useful static bound, so a group that reaches the cap is detected at run time.
    bool groupLoopCount = false;
    /// The driver traversal backend (VK_KHR_ray_query; render/DriverAccel.h)
    /// instead of vkrt's own BVH walk: a different kernel, so part of the
    /// defines and the SPIR-V cache key.
    bool driverAccel = false;
    /// The path integrator in two kernels, trace and shade (lib/stages.glsl;
    /// render --staged): the same defines, each stage compiled with VKRT_STAGE.
    bool staged = false;
    /// The scene's read-only buffers read through their device addresses
    /// (VKRT_SCENE_ADDRESSES, lib/scene_buffers.glsl), wherever the device
    /// has them: lavapipe compiles such loads many times faster than
    /// divergent storage-buffer loads. The same arithmetic either way.
    bool sceneAddresses = false;
    /// Storage buffers the texel words are split into (texture/TextureAtlas.h:
    /// TextureChunking). 1 (every scene whose texels fit one buffer) adds
    /// nothing, so those kernels are what they were; more adds
    /// VKRT_TEXTURE_CHUNKS and VKRT_TEXTURE_CHUNK_SHIFT (lib/texture_bindings.glsl).
    uint32_t textureChunks = 1;
    uint32_t textureChunkShift = 0; ///< log2 of the words of each chunk, with several

    /// Preprocessor defines selecting this variant, in a stable order.
    std::vector<std::pair<std::string, std::string>> defines() const;
    /// Descriptor binding indices (shaders/shared/Bindings.h) this variant declares.
    std::vector<uint32_t> bindings() const;
    /// Whether this variant declares `binding` as a uniform buffer.
    bool isUniformBinding(uint32_t binding) const;
    /// Whether the texels are an array of several buffers (textureChunks > 1 in a textured variant).
    bool multiChunkTextures() const;
    /// Descriptors `binding` holds: textureChunks for the texels' array, else 1.
    uint32_t descriptorCount(uint32_t binding) const;
    /// One line for people, e.g. "whitted; spheres planes point-lights; lambert; uniform-scene".
    std::string describe() const;

    bool operator==(const KernelVariant&) const = default;
};

/// Whether every scene array of the scene fits the uniform-buffer capacities.
bool sceneFitsUniformBuffers(const Scene& scene);

} // namespace vkrt
