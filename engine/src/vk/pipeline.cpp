#include "vk/pipeline.h"

#include "retile/log.h"
#include "vk/check.h"

namespace retile::vk {
namespace {

VkDescriptorType descriptorType(Binding b) {
  switch (b) {
    case Binding::Uniform: return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    case Binding::Storage: return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    case Binding::UniformTexel: return VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
    case Binding::StorageTexel: return VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER;
  }
  return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
}

}  // namespace

ComputePipeline::ComputePipeline(Context& ctx, const std::string& entry, const std::vector<Binding>& bindings,
                                 std::uint32_t pushConstantBytes, const std::vector<ShaderDefine>& defines)
    : ctx_(ctx), entry_(entry), bindings_(bindings), pushBytes_(pushConstantBytes) {
  VkDevice d = ctx.device();
  std::vector<VkDescriptorSetLayoutBinding> lb;
  std::vector<VkDescriptorPoolSize> sizes;
  std::string key = cat(entry, " push ", pushConstantBytes, " bindings");
  for (std::uint32_t i = 0; i < bindings.size(); ++i) {
    VkDescriptorSetLayoutBinding b{};
    b.binding = i;
    b.descriptorType = descriptorType(bindings[i]);
    b.descriptorCount = 1;
    b.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    lb.push_back(b);
    sizes.push_back({b.descriptorType, 1});
    key += cat(" ", static_cast<int>(b.descriptorType));
  }
  for (const ShaderDefine& def : defines) key += cat(" -D", def.name, "=", def.value);

  const Context::Program& program = ctx.program(key, [&] {
    Context::Program p;
    VkDescriptorSetLayoutCreateInfo dlci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dlci.bindingCount = static_cast<std::uint32_t>(lb.size());
    dlci.pBindings = lb.data();
    checkVk(vkCreateDescriptorSetLayout(d, &dlci, nullptr, &p.setLayout), "creating a descriptor set layout");

    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes};
    VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &p.setLayout;
    plci.pushConstantRangeCount = pushConstantBytes ? 1 : 0;
    plci.pPushConstantRanges = &range;
    checkVk(vkCreatePipelineLayout(d, &plci, nullptr, &p.layout), "creating a pipeline layout");

    std::vector<std::uint32_t> spirv = compileComputeShader(entry, defines);
    VkShaderModuleCreateInfo smci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    smci.codeSize = spirv.size() * 4;
    smci.pCode = spirv.data();
    VkShaderModule module;
    checkVk(vkCreateShaderModule(d, &smci, nullptr, &module), cat("creating shader module ", entry).c_str());
    VkComputePipelineCreateInfo cpci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    cpci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpci.stage.module = module;
    cpci.stage.pName = "main";
    cpci.layout = p.layout;
    VkResult r = vkCreateComputePipelines(d, VK_NULL_HANDLE, 1, &cpci, nullptr, &p.pipeline);
    vkDestroyShaderModule(d, module, nullptr);
    if (r != VK_SUCCESS) {
      vkDestroyPipelineLayout(d, p.layout, nullptr);
      vkDestroyDescriptorSetLayout(d, p.setLayout, nullptr);
    }
    checkVk(r, cat("creating compute pipeline ", entry).c_str());
    return p;
  });
  setLayout_ = program.setLayout;
  layout_ = program.layout;
  pipeline_ = program.pipeline;

  VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpci.maxSets = 1;
  dpci.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
  dpci.pPoolSizes = sizes.data();
  checkVk(vkCreateDescriptorPool(d, &dpci, nullptr, &pool_), "creating a descriptor pool");
  VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dsai.descriptorPool = pool_;
  dsai.descriptorSetCount = 1;
  dsai.pSetLayouts = &setLayout_;
  checkVk(vkAllocateDescriptorSets(d, &dsai, &set_), "allocating a descriptor set");
}

ComputePipeline::~ComputePipeline() {
  if (pool_) vkDestroyDescriptorPool(ctx_.device(), pool_, nullptr);  // the program is the device's
}

void ComputePipeline::bind(std::uint32_t index, Buffer& buffer, VkFormat format) {
  RETILE_ASSERT(index < bindings_.size(), cat(entry_, ": binding ", index, " of ", bindings_.size()));
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = set_;
  w.dstBinding = index;
  w.descriptorCount = 1;
  w.descriptorType = descriptorType(bindings_[index]);
  VkDescriptorBufferInfo info{buffer.handle(), 0, VK_WHOLE_SIZE};
  VkBufferView view = VK_NULL_HANDLE;
  if (bindings_[index] == Binding::UniformTexel || bindings_[index] == Binding::StorageTexel) {
    view = buffer.view(format);
    w.pTexelBufferView = &view;
  } else {
    w.pBufferInfo = &info;
  }
  vkUpdateDescriptorSets(ctx_.device(), 1, &w, 0, nullptr);
}

void ComputePipeline::dispatch(VkCommandBuffer cb, std::uint32_t groupsX, std::uint32_t groupsY, const void* push,
                               std::uint32_t pushBytes) {
  RETILE_ASSERT(pushBytes == pushBytes_, cat(entry_, ": push constants of ", pushBytes, " bytes, expected ", pushBytes_));
  if (groupsX == 0 || groupsY == 0) return;
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 0, nullptr);
  if (pushBytes) vkCmdPushConstants(cb, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes, push);
  vkCmdDispatch(cb, groupsX, groupsY, 1);
}

void computeBarrier(VkCommandBuffer cb) {
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, nullptr, 0, nullptr);
}

}  // namespace retile::vk
