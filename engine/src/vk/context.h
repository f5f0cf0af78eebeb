// The engine's own headless Vulkan (no surface, no Qt). One Context per renderer, each with its
// own command pool and fence; the instance, the device and the compiled compute programs behind
// them are the process's (Device, context.cpp), made by the first Context that asks for a device
// and kept until the process exits, so that the next renderer starts without compiling anything
// again (lavapipe takes 0.3 to 0.7 s to create a trace kernel's pipeline even with its disk cache
// warm, and the eval and the tests make a renderer per method and case). A device that was lost is
// given to no new Context. Threads: a Context is created and used by the thread that owns its
// renderer (the render thread in the editor); Contexts on different threads may share the device
// (its queue and program cache are locked).
#pragma once

#include <vulkan/vulkan.h>

#include <functional>
#include <memory>
#include <string>

namespace retile::vk {

struct DeviceChoice {
  // Preferred device: a substring of its name or an index; empty means automatic (discrete,
  // then integrated, then virtual, then CPU). The RETILE_DEVICE environment variable overrides.
  std::string preferred;
  bool validation = false;  // request VK_LAYER_KHRONOS_validation if installed
};

class Device;

class Context {
 public:
  explicit Context(const DeviceChoice& choice = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const;
  VkPhysicalDevice physicalDevice() const;
  VkDevice device() const;
  std::uint32_t queueFamily() const;
  const VkPhysicalDeviceProperties& properties() const;
  const std::string& deviceName() const;
  // Invocations in lock-step: lavapipe's are 8 or, with 512-bit vectors, 16 (core/process.h).
  std::uint32_t subgroupSize() const;
  bool isCpuDevice() const { return properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }

  // Memory type for `bits` with `wanted` flags; falls back to any type in `bits` with
  // `fallback` flags. Throws when none fits.
  std::uint32_t memoryType(std::uint32_t bits, VkMemoryPropertyFlags wanted, VkMemoryPropertyFlags fallback) const;

  // A compute program: what every pipeline of one shader, defines and bindings shares.
  struct Program {
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
  };
  // The device's program for `key`, made by make() the first time any Context of the device asks
  // for it (while others wait) and destroyed with the device.
  const Program& program(const std::string& key, const std::function<Program()>& make);

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
  // Marks the device lost (no new Context gets it) when `call` throws DeviceLost.
  template <class F>
  void noticingLoss(F&& call);

  std::shared_ptr<Device> shared_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkCommandBuffer pending_ = VK_NULL_HANDLE;  // the submission in flight
};

}  // namespace retile::vk
