#pragma once
// The Vulkan instance, the chosen physical device, its logical device and a
// compute queue. Members are declared in creation order, so RAII destroys
// them in the reverse order Vulkan requires.
#include "gpu/LoopCap.h"

#include <vulkan/vulkan_raii.hpp>

#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace vkrt {

/// A physical device as `vkrt devices` shows it, with the reason it cannot run vkrt.
struct DeviceInfo {
    uint32_t index = 0;
    std::string name;
    vk::PhysicalDeviceType type = vk::PhysicalDeviceType::eOther;
    std::string driver;      ///< driver name and info, e.g. "llvmpipe: Mesa 22.3.6 (LLVM 15.0.6)"
    vk::DriverId driverId{}; ///< e.g. eMesaLlvmpipe for lavapipe
    uint32_t apiVersion = 0;
    std::optional<uint32_t> computeQueueFamily;
    std::string unsuitableReason; ///< empty when vkrt can use the device
    /// The driver's own traversal (`--accel driver`): VK_KHR_ray_query and
    /// VK_KHR_acceleration_structure with their features and buffer device
    /// addresses. Empty when present; otherwise what is missing.
    std::string rayQueryMissing = "not checked";

    bool rayQuery() const { return rayQueryMissing.empty(); }
    /// Arrays of storage buffers indexed per invocation (the features
    /// shaderStorageBufferArrayDynamicIndexing and
    /// shaderStorageBufferArrayNonUniformIndexing), which a scene whose
    /// texels exceed one storage buffer needs (texture/TextureAtlas.h). Empty
    /// when present; otherwise what is missing.
    std::string bufferArraysMissing = "not checked";
    /// Loads through buffer device addresses (the Vulkan 1.2 feature
    /// bufferDeviceAddress, enabled wherever it exists): the render kernels
    /// read the scene's buffers through them (lib/scene_buffers.glsl).
    bool bufferDeviceAddress = false;

    bool suitable() const { return unsuitableReason.empty(); }
    std::string typeName() const;
    std::string apiVersionString() const;
};

/// What a window needs from the context: the instance extensions the window
/// system asks for, and a function that creates the window's surface.
struct PresentationSupport {
    std::vector<std::string> instanceExtensions;
    std::function<VkSurfaceKHR(VkInstance)> createSurface;
};

struct ContextOptions {
    /// Device index or case-insensitive name fragment; empty = default choice
    /// (a discrete GPU if one is suitable, else a CPU device such as lavapipe).
    std::string deviceSelector;
    /// Enable VK_LAYER_KHRONOS_validation and record every message it emits.
    bool validation = false;
    /// Set for the viewer: the device must present to this window's surface
    /// from a queue that also does graphics (blits) and compute.
    std::optional<PresentationSupport> presentation;
};

/// Collects validation-layer messages (thread-safe; the layer may call from any thread).
class ValidationLog {
public:
    void add(std::string message);
    std::vector<std::string> messages() const;

private:
    mutable std::mutex m_mutex;
    std::vector<std::string> m_messages;
};

class VulkanContext {
public:
    explicit VulkanContext(const ContextOptions& options = {});

    /// Every physical device the loader reports, with suitability.
    const std::vector<DeviceInfo>& devices() const { return m_devices; }
    const DeviceInfo& deviceInfo() const { return m_devices[m_deviceIndex]; }
    const vk::raii::PhysicalDevice& physicalDevice() const { return m_physicalDevice; }
    const vk::raii::Device& device() const { return m_device; }
    const vk::raii::Queue& queue() const { return m_queue; }
    uint32_t queueFamily() const { return *deviceInfo().computeQueueFamily; }
    /// The window surface (viewer only; null otherwise).
    const vk::raii::SurfaceKHR& surface() const { return m_surface; }

    /// Whether this device silently cuts long shader loops short (Mesa < 25
    /// lavapipe); decided once, on first use, by detectLoopCap.
    const LoopCap& loopCap() const;

    /// Messages the validation layer has emitted so far (empty when disabled).
    std::vector<std::string> validationMessages() const { return m_validationLog->messages(); }

    /// Index of a memory type with all `required` properties among `typeBits`,
    /// preferring one that also has `preferred`; throws GpuError if none.
    uint32_t findMemoryType(uint32_t typeBits, vk::MemoryPropertyFlags required,
                            vk::MemoryPropertyFlags preferred = {}) const;

    /// Records commands with `record`, submits them and waits for completion.
    template <typename Record>
    void submitAndWait(Record&& record) const
    {
        vk::raii::CommandBuffer cmd = beginOneShot();
        record(*cmd);
        endSubmitAndWait(cmd);
    }
    vk::raii::CommandBuffer beginOneShot() const;
    void endSubmitAndWait(const vk::raii::CommandBuffer& cmd) const;

private:
    std::unique_ptr<ValidationLog> m_validationLog = std::make_unique<ValidationLog>();
    vk::raii::Context m_context;
    vk::raii::Instance m_instance = nullptr;
    vk::raii::DebugUtilsMessengerEXT m_messenger = nullptr;
    vk::raii::SurfaceKHR m_surface = nullptr;
    std::vector<DeviceInfo> m_devices;
    uint32_t m_deviceIndex = 0;
    vk::raii::PhysicalDevice m_physicalDevice = nullptr;
    vk::raii::Device m_device = nullptr;
    vk::raii::Queue m_queue = nullptr;
    vk::raii::CommandPool m_commandPool = nullptr;
    mutable std::optional<LoopCap> m_loopCap;

    void createInstance(bool validation, const std::optional<PresentationSupport>& presentation);
    void chooseDevice(const std::string& selector);
    void createDevice();
};

/// The device vkrt picks when none is named: a suitable discrete GPU, else a
/// suitable CPU device (lavapipe), else any suitable device.
uint32_t defaultDeviceIndex(const std::vector<DeviceInfo>& devices);
/// Resolves `--device`: an index, or a case-insensitive fragment of one name.
uint32_t selectDevice(const std::vector<DeviceInfo>& devices, const std::string& selector);

/// Every physical device with its suitability, without creating a logical device.
std::vector<DeviceInfo> listVulkanDevices();

/// Lets lavapipe use more worker threads than cores (it splits each dispatch
/// into one equal run per thread; more runs balance better). Must run before
/// the Vulkan instance exists; never overrides a value the user set.
void tuneSoftwareRasterizerThreads();

} // namespace vkrt
