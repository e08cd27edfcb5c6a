#include "gpu/ComputeKernel.h"

#include "shared/Bindings.h"
#include "util/Error.h"

#include <algorithm>

namespace vkrt {

vk::DescriptorType descriptorTypeOf(uint32_t binding)
{
    VKRT_CHECK(binding < gpu::BINDING_COUNT);
    if (binding == gpu::BINDING_UNIFORMS) return vk::DescriptorType::eUniformBuffer;
    if (binding == gpu::BINDING_ENVIRONMENT) return vk::DescriptorType::eCombinedImageSampler;
    return vk::DescriptorType::eStorageBuffer;
}

ComputeKernel::ComputeKernel(const VulkanContext& context, std::span<const uint32_t> spirv,
                             std::vector<uint32_t> bindings, uint32_t pushConstantSize)
    : m_context(context), m_bindings(std::move(bindings)), m_pushConstantSize(pushConstantSize)
{
    const auto& device = context.device();
    m_module = vk::raii::ShaderModule(device, vk::ShaderModuleCreateInfo({}, spirv.size_bytes(), spirv.data()));

    std::vector<vk::DescriptorSetLayoutBinding> layoutBindings;
    std::vector<vk::DescriptorPoolSize> poolSizes;
    for (uint32_t binding : m_bindings) {
        layoutBindings.emplace_back(binding, descriptorTypeOf(binding), 1, vk::ShaderStageFlagBits::eCompute);
        poolSizes.emplace_back(descriptorTypeOf(binding), 1);
    }
    m_setLayout = vk::raii::DescriptorSetLayout(device, vk::DescriptorSetLayoutCreateInfo({}, layoutBindings));

    vk::PushConstantRange pushRange(vk::ShaderStageFlagBits::eCompute, 0, pushConstantSize);
    vk::DescriptorSetLayout setLayout = *m_setLayout;
    m_pipelineLayout = vk::raii::PipelineLayout(device, vk::PipelineLayoutCreateInfo({}, setLayout, pushRange));

    vk::PipelineShaderStageCreateInfo stage({}, vk::ShaderStageFlagBits::eCompute, *m_module, "main");
    m_pipeline = vk::raii::Pipeline(device, nullptr, vk::ComputePipelineCreateInfo({}, stage, *m_pipelineLayout));

    m_pool = vk::raii::DescriptorPool(
        device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, poolSizes));
    vk::raii::DescriptorSets sets(device, vk::DescriptorSetAllocateInfo(*m_pool, setLayout));
    m_set = std::move(sets[0]);
}

void ComputeKernel::bind(uint32_t binding, const Buffer& buffer)
{
    VKRT_CHECK(std::find(m_bindings.begin(), m_bindings.end(), binding) != m_bindings.end());
    vk::DescriptorBufferInfo info(buffer.handle(), 0, VK_WHOLE_SIZE);
    vk::WriteDescriptorSet write(*m_set, binding, 0, descriptorTypeOf(binding), nullptr, info);
    m_context.device().updateDescriptorSets(write, nullptr);
}

void ComputeKernel::bind(uint32_t binding, vk::ImageView view, vk::Sampler sampler)
{
    VKRT_CHECK(std::find(m_bindings.begin(), m_bindings.end(), binding) != m_bindings.end());
    vk::DescriptorImageInfo info(sampler, view, vk::ImageLayout::eShaderReadOnlyOptimal);
    vk::WriteDescriptorSet write(*m_set, binding, 0, descriptorTypeOf(binding), info);
    m_context.device().updateDescriptorSets(write, nullptr);
}

void ComputeKernel::recordDispatch(vk::CommandBuffer cmd, std::span<const std::byte> pushConstants,
                                   vk::Extent2D groups) const
{
    VKRT_CHECK(pushConstants.size() == m_pushConstantSize);
    cmd.bindPipeline(vk::PipelineBindPoint::eCompute, *m_pipeline);
    cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *m_pipelineLayout, 0, *m_set, nullptr);
    cmd.pushConstants(*m_pipelineLayout, vk::ShaderStageFlagBits::eCompute, 0, uint32_t(pushConstants.size()),
                      pushConstants.data());
    cmd.dispatch(groups.width, groups.height, 1);
}

} // namespace vkrt
