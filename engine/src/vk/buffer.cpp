#include "vk/buffer.h"

#include <cstring>
#include <utility>

#include "retile/log.h"
#include "vk/check.h"

namespace retile::vk {

Buffer::Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, bool hostVisible, const char* what) : ctx_(&ctx), size_(size) {
  // Zero-sized buffers are not allowed; keep a minimal one so descriptors stay valid.
  VkDeviceSize allocSize = size ? size : 16;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = allocSize;
  bci.usage = usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  checkVk(vkCreateBuffer(ctx.device(), &bci, nullptr, &buffer_), cat("creating buffer '", what, "'").c_str());
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(ctx.device(), buffer_, &req);
  VkMemoryPropertyFlags hostFlags = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  VkMemoryPropertyFlags wanted = hostVisible ? hostFlags : VkMemoryPropertyFlags{VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT};
  VkMemoryPropertyFlags fallback = hostVisible ? hostFlags : 0;
  std::uint32_t type = ctx.memoryType(req.memoryTypeBits, wanted, fallback);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = type;
  VkResult r = vkAllocateMemory(ctx.device(), &mai, nullptr, &memory_);
  if (r != VK_SUCCESS) {
    vkDestroyBuffer(ctx.device(), buffer_, nullptr);
    buffer_ = VK_NULL_HANDLE;
    throwVk(r, cat("allocating ", req.size >> 20, " MiB for '", what, "'").c_str());
  }
  checkVk(vkBindBufferMemory(ctx.device(), buffer_, memory_, 0), "binding buffer memory");
  VkMemoryPropertyFlags actual;
  {
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(ctx.physicalDevice(), &mp);
    actual = mp.memoryTypes[type].propertyFlags;
  }
  // Persistently map whatever is host-visible and coherent: on lavapipe that is everything,
  // which saves the staging copies.
  if ((actual & hostFlags) == hostFlags)
    checkVk(vkMapMemory(ctx.device(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "mapping buffer memory");
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    release();
    ctx_ = std::exchange(o.ctx_, nullptr);
    buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    view_ = std::exchange(o.view_, VK_NULL_HANDLE);
    viewFormat_ = o.viewFormat_;
    size_ = std::exchange(o.size_, 0);
    mapped_ = std::exchange(o.mapped_, nullptr);
  }
  return *this;
}

Buffer::~Buffer() { release(); }

void Buffer::release() {
  if (!ctx_) return;
  ctx_->wait();  // the submission in flight may still use it
  VkDevice d = ctx_->device();
  if (view_) vkDestroyBufferView(d, view_, nullptr);
  if (buffer_) vkDestroyBuffer(d, buffer_, nullptr);
  if (memory_) vkFreeMemory(d, memory_, nullptr);
  view_ = VK_NULL_HANDLE;
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
  ctx_ = nullptr;
}

void Buffer::upload(const void* data, VkDeviceSize bytes, VkDeviceSize offset) {
  RETILE_ASSERT(offset + bytes <= size_, cat("upload of ", bytes, " bytes at ", offset, " into a buffer of ", size_));
  if (!bytes) return;
  if (mapped_) {
    ctx_->wait();  // the submission in flight may be reading it
    std::memcpy(static_cast<char*>(mapped_) + offset, data, bytes);
    return;
  }
  Buffer staging(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, "staging");
  std::memcpy(staging.mapped(), data, bytes);
  ctx_->submitAndWait([&](VkCommandBuffer cb) {
    VkBufferCopy c{0, offset, bytes};
    vkCmdCopyBuffer(cb, staging.handle(), buffer_, 1, &c);
  });
}

void Buffer::download(void* data, VkDeviceSize bytes, VkDeviceSize offset) {
  RETILE_ASSERT(offset + bytes <= size_, cat("download of ", bytes, " bytes at ", offset, " from a buffer of ", size_));
  if (!bytes) return;
  if (mapped_) {
    ctx_->wait();  // the submission in flight may be writing it
    std::memcpy(data, static_cast<const char*>(mapped_) + offset, bytes);
    return;
  }
  Buffer staging(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, "staging");
  ctx_->submitAndWait([&](VkCommandBuffer cb) {
    VkBufferCopy c{offset, 0, bytes};
    vkCmdCopyBuffer(cb, buffer_, staging.handle(), 1, &c);
  });
  std::memcpy(data, staging.mapped(), bytes);
}

VkBufferView Buffer::view(VkFormat format) {
  if (view_ && viewFormat_ == format) return view_;
  if (view_) vkDestroyBufferView(ctx_->device(), view_, nullptr);
  VkBufferViewCreateInfo vci{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
  vci.buffer = buffer_;
  vci.format = format;
  vci.offset = 0;
  vci.range = VK_WHOLE_SIZE;
  checkVk(vkCreateBufferView(ctx_->device(), &vci, nullptr, &view_), "creating a texel buffer view");
  viewFormat_ = format;
  return view_;
}

}  // namespace retile::vk
