// The engine's own headless Vulkan instance and device (no surface, no Qt). One Context per
// renderer. Threads: created and used by the thread that owns the renderer (the render thread
// in the editor); nothing here is thread-safe on its own.
#pragma once

#include <vulkan/vulkan.h>

#include <functional>
#include <string>

namespace retile::vk {

struct DeviceChoice {
  // Preferred device: a substring of its name or an index; empty means automatic (discrete,
  // then integrated, then virtual, then CPU). The RETILE_DEVICE environment variable overrides.
  std::string preferred;
  bool validation = false;  // request VK_LAYER_KHRONOS_validation if installed
};

class Context {
 public:
  explicit Context(const DeviceChoice& choice = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  std::uint32_t queueFamily() const { return queueFamily_; }
  const VkPhysicalDeviceProperties& properties() const { return props_; }
  const std::string& deviceName() const { return name_; }
  bool isCpuDevice() const { return props_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }

  // Memory type for `bits` with `wanted` flags; falls back to any type in `bits` with
  // `fallback` flags. Throws when none fits.
  std::uint32_t memoryType(std::uint32_t bits, VkMemoryPropertyFlags wanted, VkMemoryPropertyFlags fallback) const;

  // Records commands into a one-time command buffer and submits it; returns while the device
  // works. At most one submission is in flight: a second submit waits for the first.
  void submit(const std::function<void(VkCommandBuffer)>& record);
  // Waits for the submission in flight, if any. Any call that touches memory the device may be
  // using (uploads, downloads, reallocations) must wait first.
  void wait();
  bool busy() const { return pending_ != VK_NULL_HANDLE; }
  // submit, then wait.
  void submitAndWait(const std::function<void(VkCommandBuffer)>& record);

 private:
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queueFamily_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkCommandBuffer pending_ = VK_NULL_HANDLE;  // the submission in flight
  VkPhysicalDeviceProperties props_{};
  VkPhysicalDeviceMemoryProperties memProps_{};
  std::string name_;
};

}  // namespace retile::vk
