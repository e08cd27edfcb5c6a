#include "gpu/VulkanContext.h"

#include "util/Error.h"
#include "util/Signals.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <thread>

namespace vkrt {

namespace {

constexpr uint32_t kRequiredApiVersion = VK_API_VERSION_1_2;
constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::string lowercase(std::string text)
{
    std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
    return text;
}

VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void* user)
{
    std::string level = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning";
    std::string message = data->pMessage ? data->pMessage : "";
    // Newer layers (Debian 13's) keep the message's ID (VUID-..., SYNC-HAZARD-...)
    // out of its text: it is named here, so that logs and tests can look for it.
    if (data->pMessageIdName && *data->pMessageIdName && message.find(data->pMessageIdName) == std::string::npos)
        message = "[" + std::string(data->pMessageIdName) + "] " + message;
    static_cast<ValidationLog*>(user)->add("validation " + level + ": " + message);
    return VK_FALSE;
}

bool hasLayer(const vk::raii::Context& context, const char* name)
{
    for (const auto& layer : context.enumerateInstanceLayerProperties())
        if (std::string(layer.layerName.data()) == name) return true;
    return false;
}

/// A family with graphics, compute and presentation to `surface`.
std::optional<uint32_t> findPresentQueueFamily(const vk::raii::PhysicalDevice& device, vk::SurfaceKHR surface)
{
    auto families = device.getQueueFamilyProperties();
    auto needed = vk::QueueFlagBits::eGraphics | vk::QueueFlagBits::eCompute;
    for (uint32_t i = 0; i < families.size(); ++i)
        if ((families[i].queueFlags & needed) == needed && device.getSurfaceSupportKHR(i, surface)) return i;
    return std::nullopt;
}

std::optional<uint32_t> findComputeQueueFamily(const vk::raii::PhysicalDevice& device, vk::SurfaceKHR surface)
{
    if (surface) return findPresentQueueFamily(device, surface);
    auto families = device.getQueueFamilyProperties();
    // Prefer a compute family without graphics: on GPUs it is the async queue.
    std::optional<uint32_t> any;
    for (uint32_t i = 0; i < families.size(); ++i) {
        if (!(families[i].queueFlags & vk::QueueFlagBits::eCompute)) continue;
        if (!(families[i].queueFlags & vk::QueueFlagBits::eGraphics)) return i;
        if (!any) any = i;
    }
    return any;
}

std::string unsuitableReason(const vk::raii::PhysicalDevice& device, const DeviceInfo& info, vk::SurfaceKHR surface)
{
    if (info.apiVersion < kRequiredApiVersion) return "supports Vulkan " + info.apiVersionString() + ", vkrt needs 1.2";
    if (!info.computeQueueFamily)
        return surface ? "has no queue that can compute, blit and present to this window" : "has no compute queue";
    auto features = device.getFeatures2<vk::PhysicalDeviceFeatures2, vk::PhysicalDeviceVulkan12Features>();
    if (!features.get<vk::PhysicalDeviceVulkan12Features>().scalarBlockLayout)
        return "lacks the scalarBlockLayout feature (GPU structs use the scalar layout)";
    return {};
}

const std::vector<const char*> kRayQueryExtensions = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                                      VK_KHR_RAY_QUERY_EXTENSION_NAME,
                                                      VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};

/// What the device lacks for the driver traversal backend (empty: nothing).
std::string rayQueryMissing(const vk::raii::PhysicalDevice& device)
{
    const auto available = device.enumerateDeviceExtensionProperties();
    for (const char* name : kRayQueryExtensions) {
        bool found = std::any_of(available.begin(), available.end(), [&](const vk::ExtensionProperties& p) {
            return std::strcmp(p.extensionName, name) == 0;
        });
        if (!found) return std::string("the extension ") + name;
    }
    auto features =
        device
            .getFeatures2<vk::PhysicalDeviceFeatures2, vk::PhysicalDeviceVulkan12Features,
                          vk::PhysicalDeviceAccelerationStructureFeaturesKHR, vk::PhysicalDeviceRayQueryFeaturesKHR>();
    if (!features.get<vk::PhysicalDeviceVulkan12Features>().bufferDeviceAddress)
        return "the bufferDeviceAddress feature";
    if (!features.get<vk::PhysicalDeviceAccelerationStructureFeaturesKHR>().accelerationStructure)
        return "the accelerationStructure feature";
    if (!features.get<vk::PhysicalDeviceRayQueryFeaturesKHR>().rayQuery) return "the rayQuery feature";
    return {};
}

/// What the device lacks to index arrays of storage buffers per invocation (empty: nothing).
std::string bufferArraysMissing(const vk::raii::PhysicalDevice& device)
{
    auto features = device.getFeatures2<vk::PhysicalDeviceFeatures2, vk::PhysicalDeviceVulkan12Features>();
    if (!features.get<vk::PhysicalDeviceFeatures2>().features.shaderStorageBufferArrayDynamicIndexing)
        return "the shaderStorageBufferArrayDynamicIndexing feature";
    if (!features.get<vk::PhysicalDeviceVulkan12Features>().shaderStorageBufferArrayNonUniformIndexing)
        return "the shaderStorageBufferArrayNonUniformIndexing feature";
    return {};
}

DeviceInfo describeDevice(const vk::raii::PhysicalDevice& device, uint32_t index, vk::SurfaceKHR surface = {})
{
    auto chain = device.getProperties2<vk::PhysicalDeviceProperties2, vk::PhysicalDeviceDriverProperties>();
    const auto& props = chain.get<vk::PhysicalDeviceProperties2>().properties;
    const auto& driver = chain.get<vk::PhysicalDeviceDriverProperties>();
    DeviceInfo info;
    info.index = index;
    info.name = props.deviceName.data();
    info.type = props.deviceType;
    info.driver = std::string(driver.driverName.data()) + ": " + driver.driverInfo.data();
    info.driverId = driver.driverID;
    info.apiVersion = props.apiVersion;
    info.computeQueueFamily = findComputeQueueFamily(device, surface);
    info.unsuitableReason = unsuitableReason(device, info, surface);
    if (info.suitable()) info.rayQueryMissing = rayQueryMissing(device);
    if (info.suitable()) info.bufferArraysMissing = bufferArraysMissing(device);
    if (info.suitable())
        info.bufferDeviceAddress =
            device.getFeatures2<vk::PhysicalDeviceFeatures2, vk::PhysicalDeviceVulkan12Features>()
                .get<vk::PhysicalDeviceVulkan12Features>()
                .bufferDeviceAddress;
    return info;
}

std::string deviceList(const std::vector<DeviceInfo>& devices)
{
    std::string text;
    for (const auto& d : devices) text += "\n  " + std::to_string(d.index) + ": " + d.name;
    return text.empty() ? "\n  (none)" : text;
}

} // namespace

std::string DeviceInfo::typeName() const
{
    switch (type) {
    case vk::PhysicalDeviceType::eDiscreteGpu: return "discrete GPU";
    case vk::PhysicalDeviceType::eIntegratedGpu: return "integrated GPU";
    case vk::PhysicalDeviceType::eVirtualGpu: return "virtual GPU";
    case vk::PhysicalDeviceType::eCpu: return "CPU";
    default: return "other";
    }
}

std::string DeviceInfo::apiVersionString() const
{
    return std::to_string(VK_API_VERSION_MAJOR(apiVersion)) + "." + std::to_string(VK_API_VERSION_MINOR(apiVersion)) +
           "." + std::to_string(VK_API_VERSION_PATCH(apiVersion));
}

void ValidationLog::add(std::string message)
{
    std::lock_guard lock(m_mutex);
    m_messages.push_back(std::move(message));
}

std::vector<std::string> ValidationLog::messages() const
{
    std::lock_guard lock(m_mutex);
    return m_messages;
}

void tuneSoftwareRasterizerThreads()
{
    unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    setenv("LP_NUM_THREADS", std::to_string(4 * cores).c_str(), /*overwrite=*/0);
}

VulkanContext::VulkanContext(const ContextOptions& options)
{
    tuneSoftwareRasterizerThreads();
    // The loader first calls into drivers here: a broken one crashes or hangs right away.
    {
        DriverCrashGuard crash("creating the Vulkan instance");
        createInstance(options.validation, options.presentation);
    }
    {
        DriverCrashGuard crash("choosing a Vulkan device");
        chooseDevice(options.deviceSelector);
    }
    DriverCrashGuard crash("creating the Vulkan device");
    createDevice();
}

void VulkanContext::createInstance(bool validation, const std::optional<PresentationSupport>& presentation)
{
    if (validation && !hasLayer(m_context, kValidationLayer))
        throw GpuError("validation requested but VK_LAYER_KHRONOS_validation is not installed "
                       "(Debian package vulkan-validationlayers)");
    vk::ApplicationInfo app("vkrt", 1, "vkrt", 1, kRequiredApiVersion);
    std::vector<const char*> layers, extensions;
    if (validation) {
        layers.push_back(kValidationLayer);
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME); // the layer provides it
    }
    if (presentation)
        for (const auto& e : presentation->instanceExtensions) extensions.push_back(e.c_str());
    vk::InstanceCreateInfo instanceInfo({}, &app, layers, extensions);
    // With validation, synchronization validation too: a missing barrier
    // between dispatches is invisible on lavapipe (it runs them in order) but
    // a race on a GPU, which none has run here (docs/platform.md).
    const std::array enabledFeatures{vk::ValidationFeatureEnableEXT::eSynchronizationValidation};
    vk::ValidationFeaturesEXT features(enabledFeatures, {});
    if (validation) instanceInfo.pNext = &features;
    m_instance = vk::raii::Instance(m_context, instanceInfo);
    if (presentation) m_surface = vk::raii::SurfaceKHR(m_instance, presentation->createSurface(*m_instance));
    if (!validation) return;
    using Severity = vk::DebugUtilsMessageSeverityFlagBitsEXT;
    using Type = vk::DebugUtilsMessageTypeFlagBitsEXT;
    // Built as the C struct and converted: Vulkan-Hpp 1.4 deprecates the
    // constructor taking a C callback, and 1.3 has none taking a C++ one.
    VkDebugUtilsMessengerCreateInfoEXT info{};
    info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    info.messageSeverity = VkDebugUtilsMessageSeverityFlagsEXT(Severity::eWarning | Severity::eError);
    info.messageType = VkDebugUtilsMessageTypeFlagsEXT(Type::eGeneral | Type::eValidation | Type::ePerformance);
    info.pfnUserCallback = &onValidationMessage;
    info.pUserData = m_validationLog.get();
    m_messenger = vk::raii::DebugUtilsMessengerEXT(m_instance, vk::DebugUtilsMessengerCreateInfoEXT(info));
}

const LoopCap& VulkanContext::loopCap() const
{
    if (!m_loopCap) m_loopCap = detectLoopCap(*this);
    return *m_loopCap;
}

void VulkanContext::chooseDevice(const std::string& selector)
{
    vk::raii::PhysicalDevices physical(m_instance);
    for (uint32_t i = 0; i < physical.size(); ++i) m_devices.push_back(describeDevice(physical[i], i, *m_surface));
    if (m_devices.empty())
        throw GpuError("no Vulkan device found; install mesa-vulkan-drivers for lavapipe (software Vulkan)");
    m_deviceIndex = selector.empty() ? defaultDeviceIndex(m_devices) : selectDevice(m_devices, selector);
    const DeviceInfo& chosen = m_devices[m_deviceIndex];
    if (!chosen.suitable())
        throw GpuError("device " + std::to_string(chosen.index) + " (" + chosen.name + ") cannot run vkrt: it " +
                       chosen.unsuitableReason);
    m_physicalDevice = std::move(physical[m_deviceIndex]);
}

void VulkanContext::createDevice()
{
    float priority = 1.0f;
    vk::DeviceQueueCreateInfo queueInfo({}, queueFamily(), 1, &priority);
    vk::StructureChain<vk::DeviceCreateInfo, vk::PhysicalDeviceVulkan12Features,
                       vk::PhysicalDeviceAccelerationStructureFeaturesKHR, vk::PhysicalDeviceRayQueryFeaturesKHR>
        chain;
    chain.get<vk::DeviceCreateInfo>().setQueueCreateInfos(queueInfo);
    std::vector<const char*> extensions;
    if (*m_surface) extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    chain.get<vk::PhysicalDeviceVulkan12Features>().setScalarBlockLayout(true);
    // Several texture buffers, indexed per texel, for scenes whose texels
    // exceed one buffer: enabled wherever they exist, as the driver backend's.
    vk::PhysicalDeviceFeatures core;
    if (deviceInfo().bufferArraysMissing.empty()) {
        core.setShaderStorageBufferArrayDynamicIndexing(true);
        chain.get<vk::PhysicalDeviceVulkan12Features>().setShaderStorageBufferArrayNonUniformIndexing(true);
    }
    chain.get<vk::DeviceCreateInfo>().setPEnabledFeatures(&core);
    if (deviceInfo().bufferDeviceAddress) chain.get<vk::PhysicalDeviceVulkan12Features>().setBufferDeviceAddress(true);
    // The driver backend's extensions are enabled wherever they exist, so
    // that one context serves either backend (they cost nothing unused).
    const bool rayQuery = deviceInfo().rayQuery();
    if (rayQuery) {
        extensions.insert(extensions.end(), kRayQueryExtensions.begin(), kRayQueryExtensions.end());
        chain.get<vk::PhysicalDeviceAccelerationStructureFeaturesKHR>().setAccelerationStructure(true);
        chain.get<vk::PhysicalDeviceRayQueryFeaturesKHR>().setRayQuery(true);
    } else {
        chain.unlink<vk::PhysicalDeviceAccelerationStructureFeaturesKHR>();
        chain.unlink<vk::PhysicalDeviceRayQueryFeaturesKHR>();
    }
    chain.get<vk::DeviceCreateInfo>().setPEnabledExtensionNames(extensions);
    m_device = vk::raii::Device(m_physicalDevice, chain.get<vk::DeviceCreateInfo>());
    m_queue = vk::raii::Queue(m_device, queueFamily(), 0);
    m_commandPool =
        vk::raii::CommandPool(m_device, vk::CommandPoolCreateInfo(vk::CommandPoolCreateFlagBits::eResetCommandBuffer,
                                                                  queueFamily()));
}

uint32_t VulkanContext::findMemoryType(uint32_t typeBits, vk::MemoryPropertyFlags required,
                                       vk::MemoryPropertyFlags preferred) const
{
    auto memory = m_physicalDevice.getMemoryProperties();
    std::optional<uint32_t> fallback;
    for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
        if (!(typeBits & (1u << i))) continue;
        auto flags = memory.memoryTypes[i].propertyFlags;
        if ((flags & required) != required) continue;
        if ((flags & preferred) == preferred) return i;
        if (!fallback) fallback = i;
    }
    if (!fallback) throw GpuError("no Vulkan memory type with the required properties on " + deviceInfo().name);
    return *fallback;
}

vk::raii::CommandBuffer VulkanContext::beginOneShot() const
{
    vk::raii::CommandBuffers buffers(m_device, vk::CommandBufferAllocateInfo(*m_commandPool,
                                                                             vk::CommandBufferLevel::ePrimary, 1));
    vk::raii::CommandBuffer cmd = std::move(buffers[0]);
    cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
    return cmd;
}

void VulkanContext::endSubmitAndWait(const vk::raii::CommandBuffer& cmd) const
{
    cmd.end();
    DriverCrashGuard crash("running GPU work (a queue submission and its fence wait)");
    vk::raii::Fence fence(m_device, vk::FenceCreateInfo());
    vk::CommandBuffer handle = *cmd;
    m_queue.submit(vk::SubmitInfo({}, {}, handle), *fence);
    if (m_device.waitForFences(*fence, VK_TRUE, UINT64_MAX) != vk::Result::eSuccess)
        throw GpuError("vkWaitForFences did not complete");
}

std::vector<DeviceInfo> listVulkanDevices()
{
    vk::raii::Context context;
    DriverCrashGuard crash("listing the Vulkan devices");
    vk::ApplicationInfo app("vkrt", 1, "vkrt", 1, kRequiredApiVersion);
    vk::raii::Instance instance(context, vk::InstanceCreateInfo({}, &app));
    vk::raii::PhysicalDevices physical(instance);
    std::vector<DeviceInfo> devices;
    for (uint32_t i = 0; i < physical.size(); ++i) devices.push_back(describeDevice(physical[i], i));
    return devices;
}

uint32_t defaultDeviceIndex(const std::vector<DeviceInfo>& devices)
{
    for (auto type : {vk::PhysicalDeviceType::eDiscreteGpu, vk::PhysicalDeviceType::eCpu})
        for (const auto& d : devices)
            if (d.suitable() && d.type == type) return d.index;
    for (const auto& d : devices)
        if (d.suitable()) return d.index;
    std::string reasons;
    for (const auto& d : devices)
        reasons += "\n  " + std::to_string(d.index) + ": " + d.name + ": " + d.unsuitableReason;
    throw GpuError("no Vulkan device can run vkrt:" + reasons);
}

uint32_t selectDevice(const std::vector<DeviceInfo>& devices, const std::string& selector)
{
    bool numeric = !selector.empty() && std::all_of(selector.begin(), selector.end(), ::isdigit);
    if (numeric) {
        unsigned long index = std::stoul(selector);
        if (index < devices.size()) return static_cast<uint32_t>(index);
        throw InputError("--device " + selector + ": no device with that index; devices are:" + deviceList(devices));
    }
    std::vector<uint32_t> matches;
    for (const auto& d : devices)
        if (lowercase(d.name).find(lowercase(selector)) != std::string::npos) matches.push_back(d.index);
    if (matches.size() == 1) return matches[0];
    if (matches.empty())
        throw InputError("--device " + selector + ": no device name contains it; devices are:" + deviceList(devices));
    throw InputError("--device " + selector + ": matches several devices; use an index:" + deviceList(devices));
}

} // namespace vkrt
