// The denoiser and the compositor as compute passes (shaders/denoise_*.comp, compose.comp): an
// edge-avoiding a-trous wavelet filter over a domain of the accumulated image, demodulated by the
// guides' albedo and steered by normals, depths and the per-pixel variance, written into a
// denoised layer tile by tile; then the displayed image, composed per tile from the raw
// accumulation or the layer, with soft borders. The accumulation is only read: the denoiser is a
// view. Owned by the Renderer; used on the thread that owns its Context.
#pragma once

#include <memory>

#include "retile/render.h"
#include "vk/buffer.h"
#include "vk/context.h"
#include "vk/pipeline.h"

namespace retile {

class Denoiser {
 public:
  explicit Denoiser(vk::Context& ctx);
  ~Denoiser();

  // A new image size (the layer restarts empty) or new accumulation buffers. Buffers are made on
  // the first frame that composes, so a renderer without denoising pays nothing.
  void resize(int width, int height, vk::Buffer& accum, vk::Buffer& accumAux);
  // Before the command buffer is recorded (no submission in flight): uploads the tile codes.
  void prepare(const DenoiseWork& work);
  // Records the passes, after the accumulate pass.
  void record(VkCommandBuffer cb, const DenoiseWork& work);
  // The composed image (RGBA32F per pixel), valid once a frame has composed: the layer itself
  // when the last frame was denoised whole (every tile shows it, so nothing is composed).
  vk::Buffer& display() { return layerShown_ ? layer_ : display_; }
  // After a frame recorded with work.timePasses has completed (and before the next is recorded):
  // each pass's device time.
  std::vector<FrameStats::PassTime> passTimes();

 private:
  void allocate();

  vk::Context& ctx_;
  int width_ = 0, height_ = 0;
  vk::Buffer* accum_ = nullptr;
  vk::Buffer* accumAux_ = nullptr;
  bool allocated_ = false;
  std::unique_ptr<vk::ComputePipeline> prepare_, variance_, atrousAB_, atrousBA_, finish_, compose_;
  VkQueryPool timestamps_ = VK_NULL_HANDLE;
  std::vector<const char*> timedPasses_;  // the passes the last timed frame recorded
  bool layerShown_ = false;               // the last frame recorded shows the layer whole
  vk::Buffer a_, b_, surface_, gradient_, moments_, layer_, display_, tiles_;
};

}  // namespace retile
