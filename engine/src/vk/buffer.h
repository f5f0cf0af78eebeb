// A VkBuffer with its own memory, and optional texel-buffer view. Owned by whoever created it;
// used on the thread that owns the Context.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>

#include "vk/context.h"

namespace retile::vk {

class Buffer {
 public:
  Buffer() = default;
  // Device-local when `hostVisible` is false (uploads go through a staging copy); on unified
  // memory devices such as lavapipe every type is host-visible and writes are direct.
  Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, bool hostVisible, const char* what);
  ~Buffer();
  Buffer(Buffer&& o) noexcept { *this = std::move(o); }
  Buffer& operator=(Buffer&& o) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  bool valid() const { return buffer_ != VK_NULL_HANDLE; }
  void* mapped() const { return mapped_; }

  // Copies bytes into the buffer at `offset`, directly when mapped, else through staging. Either
  // way it first waits for the context's submission in flight, as does destroying the buffer.
  void upload(const void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);
  // Copies bytes out of the buffer, after waiting for the submission in flight. To read a buffer
  // the submission in flight does not touch, use mapped() instead.
  void download(void* data, VkDeviceSize bytes, VkDeviceSize offset = 0);
  // A texel view of the whole buffer in `format`, created on first use.
  VkBufferView view(VkFormat format);

 private:
  void release();
  Context* ctx_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkBufferView view_ = VK_NULL_HANDLE;
  VkFormat viewFormat_ = VK_FORMAT_UNDEFINED;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
};

}  // namespace retile::vk
