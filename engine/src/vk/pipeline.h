// A compute pipeline with one descriptor set. Owned by a render pass object; used on the
// thread that owns the Context. Its program (layouts and pipeline) is the device's, compiled by
// the first pipeline of the same shader, defines and bindings (Context::program); the descriptor
// set, which binds this pass's buffers, is its own.
#pragma once

#include <vulkan/vulkan.h>

#include <string>
#include <vector>

#include "vk/buffer.h"
#include "vk/context.h"
#include "vk/shader_compiler.h"

namespace retile::vk {

enum class Binding { Uniform, Storage, UniformTexel, StorageTexel };

class ComputePipeline {
 public:
  ComputePipeline(Context& ctx, const std::string& entry, const std::vector<Binding>& bindings, std::uint32_t pushConstantBytes,
                  const std::vector<ShaderDefine>& defines = {});
  ~ComputePipeline();
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;

  // Points binding `index` at a buffer (Uniform/Storage) or at its texel view (`format`).
  void bind(std::uint32_t index, Buffer& buffer, VkFormat format = VK_FORMAT_UNDEFINED);
  // Records bind + push constants + dispatch of `groups` workgroups along x (split over y when
  // it exceeds the device limit; shaders fold gl_WorkGroupID.y back in).
  void dispatch(VkCommandBuffer cb, std::uint32_t groupsX, std::uint32_t groupsY, const void* push, std::uint32_t pushBytes);

  const std::string& name() const { return entry_; }

 private:
  Context& ctx_;
  std::string entry_;
  std::vector<Binding> bindings_;
  std::uint32_t pushBytes_;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
};

// A full compute-to-compute (and transfer) barrier; passes run in sequence on one queue.
void computeBarrier(VkCommandBuffer cb);

}  // namespace retile::vk
