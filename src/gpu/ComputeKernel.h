#pragma once
// A compute pipeline with its descriptor sets. The layout is derived from the
// list of binding indices the kernel variant uses (shaders/shared/Bindings.h),
// so no pipeline set-up is ever written twice. There are several sets of that
// one layout when an image is rendered in bands (render/ImageBands.h): they
// differ only in the per-pixel buffers, bound with bindInSet.
#include "gpu/Buffer.h"

#include <cstdint>
#include <span>
#include <vector>

namespace vkrt {

/// One binding of a kernel's set 0: `count` descriptors (an array when more than one).
struct KernelBinding {
    uint32_t index;
    vk::DescriptorType type;
    uint32_t count = 1;
};

/// The render kernels' bindings: indices from shaders/shared/Bindings.h with their types.
std::vector<KernelBinding> renderKernelBindings(const std::vector<uint32_t>& indices);

class ComputeKernel {
public:
    /// `pushConstantSize` in bytes (0: no push constants); `setCount` descriptor sets.
    ComputeKernel(const VulkanContext& context, std::span<const uint32_t> spirv, std::vector<KernelBinding> bindings,
                  uint32_t pushConstantSize, uint32_t setCount = 1);
    /// Several pipelines (stages) of one layout and one set of descriptors:
    /// recordBind's `stage` picks one; a binding made once serves them all.
    ComputeKernel(const VulkanContext& context, const std::vector<std::span<const uint32_t>>& stages,
                  std::vector<KernelBinding> bindings, uint32_t pushConstantSize, uint32_t setCount = 1);

    /// Points `binding` at `buffer` (the whole buffer) in every set.
    void bind(uint32_t binding, const Buffer& buffer);
    /// Points `binding` of set `set` alone at `buffer`.
    void bindInSet(uint32_t set, uint32_t binding, const Buffer& buffer);
    /// Points the elements of an array `binding` at `buffers` (one each, whole) in every set.
    void bind(uint32_t binding, std::span<const Buffer> buffers);
    /// Points a combined image-sampler `binding` at an image view.
    void bind(uint32_t binding, vk::ImageView view, vk::Sampler sampler);
    /// Points an acceleration-structure `binding` at `structure` in every set.
    void bind(uint32_t binding, vk::AccelerationStructureKHR structure);
    /// Points a storage-image `binding` at an image view in GENERAL layout.
    void bindStorageImage(uint32_t binding, vk::ImageView view);
    /// Records bind + push constants + dispatch of `groups`.
    void recordDispatch(vk::CommandBuffer cmd, std::span<const std::byte> pushConstants, vk::Extent2D groups) const;
    /// Binds the pipeline, descriptor set and push constants once, for a run
    /// of recordDispatchAt calls (lavapipe re-specializes the kernel each time
    /// push constants or bindings change).
    void recordBind(vk::CommandBuffer cmd, std::span<const std::byte> pushConstants, uint32_t set = 0,
                    uint32_t stage = 0) const;
    /// Binds stage `stage`'s pipeline alone (the set and push constants stay bound).
    void recordBindStage(vk::CommandBuffer cmd, uint32_t stage) const;
    /// A dispatch of `groups` workgroups whose ids start at (base.x, base.y, baseZ).
    void recordDispatchAt(vk::CommandBuffer cmd, vk::Offset2D base, uint32_t baseZ, vk::Extent2D groups) const;
    bool uses(uint32_t binding) const;
    vk::DescriptorType typeOf(uint32_t binding) const;
    /// Descriptors `binding` holds (KernelBinding::count).
    uint32_t countOf(uint32_t binding) const;

private:
    const VulkanContext& m_context;
    std::vector<KernelBinding> m_bindings;
    uint32_t m_pushConstantSize;
    vk::raii::DescriptorSetLayout m_setLayout = nullptr;
    vk::raii::PipelineLayout m_pipelineLayout = nullptr;
    std::vector<vk::raii::Pipeline> m_pipelines; ///< one per stage
    vk::raii::DescriptorPool m_pool = nullptr;
    std::vector<vk::raii::DescriptorSet> m_sets;
};

/// The descriptor type each binding index has in the render kernels.
vk::DescriptorType descriptorTypeOf(uint32_t binding);

} // namespace vkrt
