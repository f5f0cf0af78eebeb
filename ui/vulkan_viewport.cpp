#include "vulkan_viewport.h"

#include <QCoreApplication>
#include <QGuiApplication>
#include <QVulkanDeviceFunctions>
#include <QVulkanFunctions>
#include <QWidget>

#include <array>
#include <cstring>

#include "present_frag.h"
#include "present_vert.h"

namespace retile::ui {

namespace {

struct Push {
  std::int32_t pictureW, pictureH;
  float targetW, targetH;
  std::int32_t srgbTarget;
};

// Draws the picture with one full-screen triangle reading a storage buffer: no image layouts,
// samplers or staging copies, and the swapchain needs no usage beyond colour attachment.
class PresentRenderer : public QVulkanWindowRenderer {
 public:
  explicit PresentRenderer(VulkanViewport* w) : w_(w) {}

  void initResources() override {
    ok_ = true;
    dev_ = w_->device();
    f_ = w_->vulkanInstance()->deviceFunctions(dev_);
    VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO, nullptr, 0, 1, &b};
    if (!check(f_->vkCreateDescriptorSetLayout(dev_, &dl, nullptr, &setLayout_), "vkCreateDescriptorSetLayout")) return;
    VkPushConstantRange pr{VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(Push)};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO, nullptr, 0, 1, &setLayout_, 1, &pr};
    if (!check(f_->vkCreatePipelineLayout(dev_, &pl, nullptr, &layout_), "vkCreatePipelineLayout")) return;
    VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, QVulkanWindow::MAX_CONCURRENT_FRAME_COUNT};
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO, nullptr, 0,
                                  QVulkanWindow::MAX_CONCURRENT_FRAME_COUNT,     1,       &ps};
    if (!check(f_->vkCreateDescriptorPool(dev_, &dp, nullptr, &pool_), "vkCreateDescriptorPool")) return;
    for (int i = 0; i < w_->concurrentFrameCount(); ++i) {
      VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO, nullptr, pool_, 1, &setLayout_};
      if (!check(f_->vkAllocateDescriptorSets(dev_, &ai, &frames_[static_cast<std::size_t>(i)].set), "vkAllocateDescriptorSets")) return;
    }
    createPipeline();
  }

  // Qt releases everything and tries a new device by itself; the editor draws as a widget instead,
  // which cannot fail this way.
  void logicalDeviceLost() override { w_->fail(QStringLiteral("the Vulkan device was lost")); }

  void releaseResources() override {
    for (auto& fr : frames_) releaseBuffer(fr);
    f_->vkDestroyPipeline(dev_, pipeline_, nullptr);
    f_->vkDestroyDescriptorPool(dev_, pool_, nullptr);
    f_->vkDestroyPipelineLayout(dev_, layout_, nullptr);
    f_->vkDestroyDescriptorSetLayout(dev_, setLayout_, nullptr);
    pipeline_ = VK_NULL_HANDLE;
    pool_ = VK_NULL_HANDLE;
    layout_ = VK_NULL_HANDLE;
    setLayout_ = VK_NULL_HANDLE;
    frames_ = {};
  }

  void startNextFrame() override {
    Frame& fr = frames_[static_cast<std::size_t>(w_->currentFrame())];
    // The window waited on this slot's fence before calling us: its buffer is free to rewrite.
    const QImage& pic = w_->picture();
    // After a failed call of ours, frames only clear (the window is about to be replaced).
    const bool have = ok_ && !pic.isNull() && pic.format() == QImage::Format_RGB32 && upload(fr, pic);
    const QSize target = w_->swapChainImageSize();
    VkClearValue clear[3]{};
    clear[0].color = {{0.125f, 0.125f, 0.14f, 1.0f}};
    clear[1].depthStencil = {1.0f, 0};
    clear[2].color = clear[0].color;
    VkRenderPassBeginInfo rb{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rb.renderPass = w_->defaultRenderPass();
    rb.framebuffer = w_->currentFramebuffer();
    rb.renderArea.extent = {static_cast<std::uint32_t>(target.width()), static_cast<std::uint32_t>(target.height())};
    rb.clearValueCount = w_->sampleCountFlagBits() > VK_SAMPLE_COUNT_1_BIT ? 3 : 2;
    rb.pClearValues = clear;
    VkCommandBuffer cb = w_->currentCommandBuffer();
    f_->vkCmdBeginRenderPass(cb, &rb, VK_SUBPASS_CONTENTS_INLINE);
    if (have) {
      VkViewport vp{0, 0, static_cast<float>(target.width()), static_cast<float>(target.height()), 0, 1};
      VkRect2D sc{{0, 0}, rb.renderArea.extent};
      f_->vkCmdSetViewport(cb, 0, 1, &vp);
      f_->vkCmdSetScissor(cb, 0, 1, &sc);
      f_->vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_);
      f_->vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &fr.set, 0, nullptr);
      Push push{pic.width(), pic.height(), static_cast<float>(target.width()), static_cast<float>(target.height()),
                isSrgb(w_->colorFormat()) ? 1 : 0};
      f_->vkCmdPushConstants(cb, layout_, VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof push, &push);
      f_->vkCmdDraw(cb, 3, 1, 0, 0);
    }
    f_->vkCmdEndRenderPass(cb);
    if (have) w_->framePresented();
    w_->frameReady();
  }

 private:
  struct Frame {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
    VkDeviceSize capacity = 0;
    VkDescriptorSet set = VK_NULL_HANDLE;
  };

  // A failed call (out of device memory, a lost device) stops drawing and hands the viewport
  // back to the widget; it never ends the program.
  bool check(VkResult r, const char* what) {
    if (r == VK_SUCCESS) return true;
    ok_ = false;
    w_->fail(QStringLiteral("%1 failed (VkResult %2)").arg(QLatin1String(what)).arg(static_cast<int>(r)));
    return false;
  }
  static bool isSrgb(VkFormat f) {
    return f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_A8B8G8R8_SRGB_PACK32;
  }

  VkShaderModule module(const std::uint32_t* code, std::size_t bytes) {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO, nullptr, 0, bytes, code};
    VkShaderModule m = VK_NULL_HANDLE;
    check(f_->vkCreateShaderModule(dev_, &ci, nullptr, &m), "vkCreateShaderModule");
    return m;  // VK_NULL_HANDLE after a failure, which createPipeline checks
  }

  void createPipeline() {
    VkShaderModule vs = module(kPresentVert, sizeof kPresentVert), fs = module(kPresentFrag, sizeof kPresentFrag);
    if (!vs || !fs) {
      f_->vkDestroyShaderModule(dev_, vs, nullptr);
      f_->vkDestroyShaderModule(dev_, fs, nullptr);
      return;
    }
    std::array<VkPipelineShaderStageCreateInfo, 2> stages{};
    stages[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT, vs, "main", nullptr};
    stages[1] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_FRAGMENT_BIT, fs, "main", nullptr};
    VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo vps{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    vps.viewportCount = 1;
    vps.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.cullMode = VK_CULL_MODE_NONE;
    rs.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = w_->sampleCountFlagBits();
    VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    VkPipelineColorBlendAttachmentState att{};
    att.colorWriteMask = 0xf;
    VkPipelineColorBlendStateCreateInfo cbs{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    cbs.attachmentCount = 1;
    cbs.pAttachments = &att;
    std::array<VkDynamicState, 2> dyn{VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dys{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO, nullptr, 0,
                                         static_cast<std::uint32_t>(dyn.size()), dyn.data()};
    VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    ci.stageCount = static_cast<std::uint32_t>(stages.size());
    ci.pStages = stages.data();
    ci.pVertexInputState = &vi;
    ci.pInputAssemblyState = &ia;
    ci.pViewportState = &vps;
    ci.pRasterizationState = &rs;
    ci.pMultisampleState = &ms;
    ci.pDepthStencilState = &ds;
    ci.pColorBlendState = &cbs;
    ci.pDynamicState = &dys;
    ci.layout = layout_;
    ci.renderPass = w_->defaultRenderPass();
    check(f_->vkCreateGraphicsPipelines(dev_, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline_), "vkCreateGraphicsPipelines");
    f_->vkDestroyShaderModule(dev_, vs, nullptr);
    f_->vkDestroyShaderModule(dev_, fs, nullptr);
  }

  void releaseBuffer(Frame& fr) {
    if (fr.memory) f_->vkUnmapMemory(dev_, fr.memory);
    f_->vkDestroyBuffer(dev_, fr.buffer, nullptr);
    f_->vkFreeMemory(dev_, fr.memory, nullptr);
    fr.buffer = VK_NULL_HANDLE;
    fr.memory = VK_NULL_HANDLE;
    fr.mapped = nullptr;
    fr.capacity = 0;
  }

  // Copies the picture into the slot's host-visible buffer, growing it when needed. A failed
  // allocation skips the picture for this frame rather than ending the program.
  bool upload(Frame& fr, const QImage& pic) {
    const VkDeviceSize bytes = static_cast<VkDeviceSize>(pic.width()) * static_cast<VkDeviceSize>(pic.height()) * 4;
    if (bytes > fr.capacity) {
      releaseBuffer(fr);
      VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
      bi.size = bytes;
      bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
      if (f_->vkCreateBuffer(dev_, &bi, nullptr, &fr.buffer) != VK_SUCCESS) return false;
      VkMemoryRequirements req;
      f_->vkGetBufferMemoryRequirements(dev_, fr.buffer, &req);
      VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, req.size, w_->hostVisibleMemoryIndex()};
      if (f_->vkAllocateMemory(dev_, &ai, nullptr, &fr.memory) != VK_SUCCESS ||
          f_->vkBindBufferMemory(dev_, fr.buffer, fr.memory, 0) != VK_SUCCESS ||
          f_->vkMapMemory(dev_, fr.memory, 0, bytes, 0, &fr.mapped) != VK_SUCCESS) {
        releaseBuffer(fr);
        return false;
      }
      fr.capacity = bytes;
      VkDescriptorBufferInfo info{fr.buffer, 0, VK_WHOLE_SIZE};
      VkWriteDescriptorSet wr{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      wr.dstSet = fr.set;
      wr.descriptorCount = 1;
      wr.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      wr.pBufferInfo = &info;
      f_->vkUpdateDescriptorSets(dev_, 1, &wr, 0, nullptr);
    }
    const std::size_t row = static_cast<std::size_t>(pic.width()) * 4;
    auto* dst = static_cast<std::uint8_t*>(fr.mapped);
    for (int y = 0; y < pic.height(); ++y) std::memcpy(dst + row * static_cast<std::size_t>(y), pic.constScanLine(y), row);
    // The window's host-visible memory index is host-coherent (QVulkanWindow picks it so), so no flush.
    return true;
  }

  VulkanViewport* w_;
  bool ok_ = false;
  VkDevice dev_ = VK_NULL_HANDLE;
  QVulkanDeviceFunctions* f_ = nullptr;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  std::array<Frame, QVulkanWindow::MAX_CONCURRENT_FRAME_COUNT> frames_{};
};

}  // namespace

VulkanViewport::VulkanViewport(QWidget* eventTarget) : target_(eventTarget) {
  setVulkanInstance(sharedInstance());
  // Qt reports a failed swapchain acquire or present only as a warning and keeps trying: a
  // picture that waits seconds for a frame, or a window exposed for seconds without valid
  // presentation, is taken as a failure.
  watchdog_.setInterval(1000);
  QObject::connect(&watchdog_, &QTimer::timeout, this, [this] { watch(); });
  watchdog_.start();
}

void VulkanViewport::fail(const QString& why) {
  if (failed_) return;
  failed_ = true;
  watchdog_.stop();
  if (auto handler = onFailure_)
    QMetaObject::invokeMethod(
        target_, [handler, why] { handler(why); }, Qt::QueuedConnection);
}

void VulkanViewport::framePresented() { waiting_.invalidate(); }

void VulkanViewport::watch() {
  constexpr qint64 kLimitMs = 5000;
  const bool visible = isExposed() && !size().isEmpty();
  if (!visible) {
    waiting_.invalidate();
    notStarted_.invalidate();
    return;
  }
  if (!isValid()) {
    if (!notStarted_.isValid()) notStarted_.start();
    if (notStarted_.elapsed() > kLimitMs) fail(QStringLiteral("Vulkan presentation did not start"));
    return;
  }
  notStarted_.invalidate();
  if (waiting_.isValid() && waiting_.elapsed() > kLimitMs) fail(QStringLiteral("the swapchain stopped presenting frames"));
}

QVulkanInstance* VulkanViewport::sharedInstance(QString* why) {
  static QVulkanInstance* instance = nullptr;
  static QString failure;
  if (!instance && failure.isEmpty()) {
    const QString platform = QGuiApplication::platformName();
    if (platform == "offscreen" || platform == "minimal" || platform == "vnc") {
      failure = QStringLiteral("the '%1' platform has no Vulkan surfaces").arg(platform);
    } else {
      auto* inst = new QVulkanInstance;
      inst->setApiVersion(QVersionNumber(1, 1));
      if (inst->create()) {
        instance = inst;
      } else {
        failure = QStringLiteral("no Vulkan instance for windows (VkResult %1)").arg(inst->errorCode());
        delete inst;
      }
    }
  }
  if (why) *why = failure;
  return instance;
}

void VulkanViewport::setPicture(QImage picture) {
  picture_ = std::move(picture);
  if (!waiting_.isValid()) waiting_.start();
  requestUpdate();
}

QVulkanWindowRenderer* VulkanViewport::createRenderer() { return new PresentRenderer(this); }

bool VulkanViewport::event(QEvent* e) {
  switch (e->type()) {
    case QEvent::MouseButtonPress:
    case QEvent::MouseButtonRelease:
    case QEvent::MouseButtonDblClick:
    case QEvent::MouseMove:
    case QEvent::Wheel:
    case QEvent::KeyPress:
    case QEvent::KeyRelease: QCoreApplication::sendEvent(target_, e); return true;
    default: return QVulkanWindow::event(e);
  }
}

}  // namespace retile::ui
