#include "gpu/ComputeKernel.h"

#include "gpu/SpirvFault.h"
#include "shared/Bindings.h"
#include "util/Error.h"

#include <algorithm>
#include <optional>

namespace vkrt {

vk::DescriptorType descriptorTypeOf(uint32_t binding)
{
    VKRT_CHECK(binding < gpu::BINDING_COUNT);
    if (binding == gpu::BINDING_UNIFORMS) return vk::DescriptorType::eUniformBuffer;
    if (binding == gpu::BINDING_ENVIRONMENT) return vk::DescriptorType::eCombinedImageSampler;
    if (binding == gpu::BINDING_TOP_LEVEL) return vk::DescriptorType::eAccelerationStructureKHR;
    return vk::DescriptorType::eStorageBuffer;
}

std::vector<KernelBinding> renderKernelBindings(const std::vector<uint32_t>& indices)
{
    std::vector<KernelBinding> bindings;
    for (uint32_t index : indices) bindings.push_back({index, descriptorTypeOf(index)});
    return bindings;
}

ComputeKernel::ComputeKernel(const VulkanContext& context, std::span<const uint32_t> spirv,
                             std::vector<KernelBinding> bindings, uint32_t pushConstantSize, uint32_t setCount)
    : ComputeKernel(context, std::vector<std::span<const uint32_t>>{spirv}, std::move(bindings), pushConstantSize,
                    setCount)
{
}

ComputeKernel::ComputeKernel(const VulkanContext& context, const std::vector<std::span<const uint32_t>>& stages,
                             std::vector<KernelBinding> bindings, uint32_t pushConstantSize, uint32_t setCount)
    : m_context(context),
      m_bindings(std::move(bindings)),
      m_pushConstantSize(pushConstantSize)
{
    const auto& device = context.device();
    std::vector<vk::DescriptorSetLayoutBinding> layoutBindings;
    std::vector<vk::DescriptorPoolSize> poolSizes;
    for (const KernelBinding& binding : m_bindings) {
        layoutBindings.emplace_back(binding.index, binding.type, binding.count, vk::ShaderStageFlagBits::eCompute);
        poolSizes.emplace_back(binding.type, setCount * binding.count);
    }
    m_setLayout = vk::raii::DescriptorSetLayout(device, vk::DescriptorSetLayoutCreateInfo({}, layoutBindings));

    vk::PushConstantRange pushRange(vk::ShaderStageFlagBits::eCompute, 0, pushConstantSize);
    vk::DescriptorSetLayout setLayout = *m_setLayout;
    vk::PipelineLayoutCreateInfo layoutInfo({}, setLayout, pushRange);
    if (pushConstantSize == 0) layoutInfo.setPushConstantRanges({});
    m_pipelineLayout = vk::raii::PipelineLayout(device, layoutInfo);

    VKRT_CHECK(!stages.empty());
    for (std::span<const uint32_t> spirv : stages) {
        // The fault injector (gpu/SpirvFault.h) changes only what the driver
        // runs: the SPIR-V cache keeps the kernel as compiled.
        std::vector<uint32_t> faulty;
        if (std::optional<SpirvFault> fault = spirvFaultFromEnvironment()) {
            faulty = injectSpirvFault(spirv, *fault);
            spirv = faulty;
        }
        vk::raii::ShaderModule module(device, vk::ShaderModuleCreateInfo({}, spirv.size_bytes(), spirv.data()));
        vk::PipelineShaderStageCreateInfo stage({}, vk::ShaderStageFlagBits::eCompute, *module, "main");
        m_pipelines.emplace_back(device, nullptr,
                                 vk::ComputePipelineCreateInfo(vk::PipelineCreateFlagBits::eDispatchBase, stage,
                                                               *m_pipelineLayout));
    }

    VKRT_CHECK(setCount > 0);
    m_pool = vk::raii::DescriptorPool(device,
                                      vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet,
                                                                   setCount, poolSizes));
    std::vector<vk::DescriptorSetLayout> layouts(setCount, setLayout);
    vk::raii::DescriptorSets sets(device, vk::DescriptorSetAllocateInfo(*m_pool, layouts));
    for (auto& set : sets) m_sets.push_back(std::move(set));
}

bool ComputeKernel::uses(uint32_t binding) const
{
    return std::any_of(m_bindings.begin(), m_bindings.end(),
                       [&](const KernelBinding& b) { return b.index == binding; });
}

vk::DescriptorType ComputeKernel::typeOf(uint32_t binding) const
{
    for (const KernelBinding& b : m_bindings)
        if (b.index == binding) return b.type;
    throw InternalError("kernel has no binding " + std::to_string(binding));
}

uint32_t ComputeKernel::countOf(uint32_t binding) const
{
    for (const KernelBinding& b : m_bindings)
        if (b.index == binding) return b.count;
    throw InternalError("kernel has no binding " + std::to_string(binding));
}

void ComputeKernel::bind(uint32_t binding, const Buffer& buffer)
{
    for (uint32_t set = 0; set < m_sets.size(); ++set) bindInSet(set, binding, buffer);
}

void ComputeKernel::bindInSet(uint32_t set, uint32_t binding, const Buffer& buffer)
{
    vk::DescriptorBufferInfo info(buffer.handle(), 0, VK_WHOLE_SIZE);
    vk::WriteDescriptorSet write(*m_sets.at(set), binding, 0, typeOf(binding), nullptr, info);
    m_context.device().updateDescriptorSets(write, nullptr);
}

void ComputeKernel::bind(uint32_t binding, std::span<const Buffer> buffers)
{
    VKRT_CHECK(buffers.size() == countOf(binding)); // an element left unwritten would be invalid
    std::vector<vk::DescriptorBufferInfo> infos;
    for (const Buffer& buffer : buffers) infos.emplace_back(buffer.handle(), 0, VK_WHOLE_SIZE);
    for (const auto& set : m_sets) {
        vk::WriteDescriptorSet write(*set, binding, 0, typeOf(binding), nullptr, infos);
        m_context.device().updateDescriptorSets(write, nullptr);
    }
}

void ComputeKernel::bind(uint32_t binding, vk::ImageView view, vk::Sampler sampler)
{
    vk::DescriptorImageInfo info(sampler, view, vk::ImageLayout::eShaderReadOnlyOptimal);
    for (const auto& set : m_sets) {
        vk::WriteDescriptorSet write(*set, binding, 0, typeOf(binding), info);
        m_context.device().updateDescriptorSets(write, nullptr);
    }
}

void ComputeKernel::bind(uint32_t binding, vk::AccelerationStructureKHR structure)
{
    vk::WriteDescriptorSetAccelerationStructureKHR info(structure);
    for (const auto& set : m_sets) {
        vk::WriteDescriptorSet write(*set, binding, 0, 1, typeOf(binding), nullptr, nullptr, nullptr, &info);
        m_context.device().updateDescriptorSets(write, nullptr);
    }
}

void ComputeKernel::bindStorageImage(uint32_t binding, vk::ImageView view)
{
    vk::DescriptorImageInfo info(nullptr, view, vk::ImageLayout::eGeneral);
    for (const auto& set : m_sets) {
        vk::WriteDescriptorSet write(*set, binding, 0, typeOf(binding), info);
        m_context.device().updateDescriptorSets(write, nullptr);
    }
}

void ComputeKernel::recordBind(vk::CommandBuffer cmd, std::span<const std::byte> pushConstants, uint32_t set,
                               uint32_t stage) const
{
    VKRT_CHECK(pushConstants.size() == m_pushConstantSize);
    recordBindStage(cmd, stage);
    cmd.bindDescriptorSets(vk::PipelineBindPoint::eCompute, *m_pipelineLayout, 0, *m_sets.at(set), nullptr);
    if (!pushConstants.empty())
        cmd.pushConstants(*m_pipelineLayout, vk::ShaderStageFlagBits::eCompute, 0, uint32_t(pushConstants.size()),
                          pushConstants.data());
}

void ComputeKernel::recordBindStage(vk::CommandBuffer cmd, uint32_t stage) const
{
    cmd.bindPipeline(vk::PipelineBindPoint::eCompute, *m_pipelines.at(stage));
}

void ComputeKernel::recordDispatch(vk::CommandBuffer cmd, std::span<const std::byte> pushConstants,
                                   vk::Extent2D groups) const
{
    recordBind(cmd, pushConstants);
    cmd.dispatch(groups.width, groups.height, 1);
}

void ComputeKernel::recordDispatchAt(vk::CommandBuffer cmd, vk::Offset2D base, uint32_t baseZ,
                                     vk::Extent2D groups) const
{
    cmd.dispatchBase(uint32_t(base.x), uint32_t(base.y), baseZ, groups.width, groups.height, 1);
}

} // namespace vkrt
