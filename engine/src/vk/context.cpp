#include "vk/context.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

#include "core/process.h"
#include "retile/log.h"
#include "vk/check.h"

namespace retile::vk {

const char* resultName(VkResult r) {
  switch (r) {
#define RETILE_VK_CASE(x) \
  case x: return #x;
    RETILE_VK_CASE(VK_SUCCESS)
    RETILE_VK_CASE(VK_NOT_READY)
    RETILE_VK_CASE(VK_TIMEOUT)
    RETILE_VK_CASE(VK_EVENT_SET)
    RETILE_VK_CASE(VK_EVENT_RESET)
    RETILE_VK_CASE(VK_INCOMPLETE)
    RETILE_VK_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    RETILE_VK_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    RETILE_VK_CASE(VK_ERROR_INITIALIZATION_FAILED)
    RETILE_VK_CASE(VK_ERROR_DEVICE_LOST)
    RETILE_VK_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    RETILE_VK_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    RETILE_VK_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    RETILE_VK_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    RETILE_VK_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    RETILE_VK_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    RETILE_VK_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    RETILE_VK_CASE(VK_ERROR_FRAGMENTED_POOL)
    RETILE_VK_CASE(VK_ERROR_UNKNOWN)
    RETILE_VK_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    RETILE_VK_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    RETILE_VK_CASE(VK_ERROR_FRAGMENTATION)
#undef RETILE_VK_CASE
    default: return "VK_ERROR_(unnamed)";
  }
}

void throwVk(VkResult r, const char* what) {
  std::string message = cat("Vulkan: ", what, " failed: ", resultName(r), " (", static_cast<int>(r), ")");
  if (r == VK_ERROR_DEVICE_LOST) throw DeviceLost(message);
  throw Error(message);
}

namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  LogLevel level = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? LogLevel::Error : LogLevel::Warning;
  logMessage(level, cat("Vulkan validation: ", data && data->pMessage ? data->pMessage : "?"));
  return VK_FALSE;
}

int typeRank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

bool hasLayer(const char* name) {
  std::uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  return std::any_of(layers.begin(), layers.end(), [&](const auto& l) { return std::strcmp(l.layerName, name) == 0; });
}

}  // namespace

// The instance and device every Context of the process shares, and the programs compiled on it.
class Device {
 public:
  explicit Device(const DeviceChoice& choice);
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queueFamily_ = 0;
  VkPhysicalDeviceProperties props_{};
  std::uint32_t subgroupSize_ = 1;
  VkPhysicalDeviceMemoryProperties memProps_{};
  std::string name_;

  std::mutex queueLock;  // vkQueueSubmit's queue is externally synchronised
  std::mutex programsLock;
  std::map<std::string, Context::Program> programs_;
  std::atomic<bool> lost{false};
};

namespace {

// The devices made so far, by the choice they were made for; never destroyed (see context.h),
// as a process that rendered once renders again, and a lavapipe device torn down by static
// destructors at exit may outlive the driver's own state.
std::shared_ptr<Device> sharedDevice(const DeviceChoice& choice) {
  static std::mutex lock;
  static auto* devices = new std::map<std::pair<std::string, bool>, std::shared_ptr<Device>>;
  std::lock_guard<std::mutex> guard(lock);
  std::shared_ptr<Device>& d = (*devices)[{choice.preferred, choice.validation}];
  if (!d || d->lost) d = std::make_shared<Device>(choice);
  return d;
}

}  // namespace

Device::Device(const DeviceChoice& choice) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "Retile";
  app.pEngineName = "Retile";
  app.apiVersion = VK_API_VERSION_1_2;

  std::vector<const char*> layers, extensions;
  const char* kValidation = "VK_LAYER_KHRONOS_validation";
  if (choice.validation) {
    if (hasLayer(kValidation)) {
      layers.push_back(kValidation);
      extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    } else {
      logWarning("Vulkan validation requested but ", kValidation, " is not installed (package vulkan-validationlayers)");
    }
  }
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  ici.ppEnabledExtensionNames = extensions.data();
  VkResult r = vkCreateInstance(&ici, nullptr, &instance_);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw NoDeviceError("Vulkan: no Vulkan 1.2 driver found (on Debian, install mesa-vulkan-drivers for the CPU driver lavapipe)");
  checkVk(r, "creating the Vulkan instance");

  if (!layers.empty()) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (create) {
      VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
      mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
      mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
      mci.pfnUserCallback = debugCallback;
      checkVk(create(instance_, &mci, nullptr, &messenger_), "creating the validation messenger");
    }
  }

  std::uint32_t count = 0;
  checkVk(vkEnumeratePhysicalDevices(instance_, &count, nullptr), "enumerating devices");
  std::vector<VkPhysicalDevice> devices(count);
  checkVk(vkEnumeratePhysicalDevices(instance_, &count, devices.data()), "enumerating devices");

  struct Candidate {
    VkPhysicalDevice dev;
    VkPhysicalDeviceProperties props;
    std::uint32_t family;
  };
  std::vector<Candidate> usable;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    if (p.apiVersion < VK_API_VERSION_1_2) continue;
    std::uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, nullptr);
    std::vector<VkQueueFamilyProperties> qs(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, qs.data());
    for (std::uint32_t i = 0; i < nq; ++i)
      if (qs[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
        usable.push_back({d, p, i});
        break;
      }
  }
  if (usable.empty())
    throw NoDeviceError("Vulkan: no device with Vulkan 1.2 compute found (on Debian, install mesa-vulkan-drivers for lavapipe)");
  std::stable_sort(usable.begin(), usable.end(),
                   [](const Candidate& a, const Candidate& b) { return typeRank(a.props.deviceType) < typeRank(b.props.deviceType); });
  const Candidate* chosen = &usable.front();
  if (!choice.preferred.empty()) {
    const Candidate* match = nullptr;
    char* end = nullptr;
    long index = std::strtol(choice.preferred.c_str(), &end, 10);
    if (end && *end == '\0' && index >= 0 && index < static_cast<long>(usable.size())) {
      match = &usable[static_cast<std::size_t>(index)];
    } else {
      for (const auto& c : usable)
        if (std::strstr(c.props.deviceName, choice.preferred.c_str())) match = &c;
    }
    if (match) {
      chosen = match;
    } else {
      logWarning("Vulkan: no device matches RETILE_DEVICE='", choice.preferred, "'; using ", chosen->props.deviceName);
    }
  }
  physical_ = chosen->dev;
  props_ = chosen->props;
  queueFamily_ = chosen->family;
  name_ = props_.deviceName;
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props2.pNext = &subgroup;
  vkGetPhysicalDeviceProperties2(physical_, &props2);
  subgroupSize_ = std::max(subgroup.subgroupSize, 1u);
  vkGetPhysicalDeviceMemoryProperties(physical_, &memProps_);

  float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = queueFamily_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  checkVk(vkCreateDevice(physical_, &dci, nullptr, &device_), "creating the device");
  vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);

  logInfo("Vulkan device: ", name_);
}

Device::~Device() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    for (auto& [key, p] : programs_) {
      vkDestroyPipeline(device_, p.pipeline, nullptr);
      vkDestroyPipelineLayout(device_, p.layout, nullptr);
      vkDestroyDescriptorSetLayout(device_, p.setLayout, nullptr);
    }
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy =
        reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

Context::Context(const DeviceChoice& choiceIn) {
  flushDenormals();  // lavapipe's threads, created with the device, inherit it (core/process.h)
  DeviceChoice choice = choiceIn;
  if (const char* env = std::getenv("RETILE_DEVICE"); env && *env) choice.preferred = env;
  if (const char* env = std::getenv("RETILE_VALIDATION"); env && *env) choice.validation = std::strcmp(env, "0") != 0;
  shared_ = sharedDevice(choice);
  VkDevice d = shared_->device_;
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = shared_->queueFamily_;
  checkVk(vkCreateCommandPool(d, &pci, nullptr, &pool_), "creating a command pool");
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  checkVk(vkCreateFence(d, &fci, nullptr, &fence_), "creating a fence");
}

Context::~Context() {
  VkDevice d = shared_->device_;
  if (pending_) {
    vkWaitForFences(d, 1, &fence_, VK_TRUE, UINT64_MAX);
    vkFreeCommandBuffers(d, pool_, 1, &pending_);
  }
  if (fence_) vkDestroyFence(d, fence_, nullptr);
  if (pool_) vkDestroyCommandPool(d, pool_, nullptr);
}

VkInstance Context::instance() const { return shared_->instance_; }
VkPhysicalDevice Context::physicalDevice() const { return shared_->physical_; }
VkDevice Context::device() const { return shared_->device_; }
std::uint32_t Context::queueFamily() const { return shared_->queueFamily_; }
const VkPhysicalDeviceProperties& Context::properties() const { return shared_->props_; }
const std::string& Context::deviceName() const { return shared_->name_; }
std::uint32_t Context::subgroupSize() const { return shared_->subgroupSize_; }

const Context::Program& Context::program(const std::string& key, const std::function<Program()>& make) {
  std::lock_guard<std::mutex> guard(shared_->programsLock);
  auto it = shared_->programs_.find(key);
  if (it == shared_->programs_.end()) it = shared_->programs_.emplace(key, make()).first;
  return it->second;
}

template <class F>
void Context::noticingLoss(F&& call) {
  try {
    call();
  } catch (const DeviceLost&) {
    shared_->lost = true;
    throw;
  }
}

std::uint32_t Context::memoryType(std::uint32_t bits, VkMemoryPropertyFlags wanted, VkMemoryPropertyFlags fallback) const {
  for (VkMemoryPropertyFlags flags : {wanted, fallback})
    for (std::uint32_t i = 0; i < shared_->memProps_.memoryTypeCount; ++i)
      if ((bits & (1u << i)) && (shared_->memProps_.memoryTypes[i].propertyFlags & flags) == flags) return i;
  throw Error("Vulkan: no suitable memory type for a buffer");
}

void Context::submit(const std::function<void(VkCommandBuffer)>& record) {
  wait();  // one submission in flight at a time: its fence and command buffer are reused
  VkDevice d = shared_->device_;
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb;
  checkVk(vkAllocateCommandBuffers(d, &ai, &cb), "allocating a command buffer");
  try {
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    checkVk(vkBeginCommandBuffer(cb, &bi), "beginning a command buffer");
    record(cb);
    checkVk(vkEndCommandBuffer(cb), "ending a command buffer");
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    checkVk(vkResetFences(d, 1, &fence_), "resetting a fence");
    noticingLoss([&] {
      std::lock_guard<std::mutex> guard(shared_->queueLock);
      checkVk(vkQueueSubmit(shared_->queue_, 1, &si, fence_), "submitting work");
    });
  } catch (...) {
    vkFreeCommandBuffers(d, pool_, 1, &cb);
    throw;
  }
  pending_ = cb;
}

void Context::wait() {
  if (pending_ == VK_NULL_HANDLE) return;
  VkDevice d = shared_->device_;
  VkCommandBuffer cb = std::exchange(pending_, VK_NULL_HANDLE);
  VkResult r = vkWaitForFences(d, 1, &fence_, VK_TRUE, UINT64_MAX);
  vkFreeCommandBuffers(d, pool_, 1, &cb);
  noticingLoss([&] { checkVk(r, "waiting for the device"); });
}

void Context::submitAndWait(const std::function<void(VkCommandBuffer)>& record) {
  submit(record);
  wait();
}

}  // namespace retile::vk
