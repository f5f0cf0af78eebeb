#include "render/denoiser.h"

#include <algorithm>
#include <tuple>

#include "render/passes.h"
#include "retile/log.h"
#include "vk/check.h"
#include "shared/layouts.h"

namespace retile {

static_assert(kShowStale == gpu::kTileStale && kShowFresh == gpu::kTileFresh && kShowLayer == gpu::kTileLayer &&
                  kShowPreviousLayer == gpu::kTilePreviousLayer && kShowFiltered == gpu::kTileFiltered &&
                  kShowWriteLayer == gpu::kTileWrite,
              "render.h and shaders/shared/layouts.h disagree on the tile codes");

namespace {

constexpr VkBufferUsageFlags kReadWrite = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
constexpr VkFormat kRgba32 = VK_FORMAT_R32G32B32A32_SFLOAT;
constexpr VkFormat kHalf4 = VK_FORMAT_R16G16B16A16_SFLOAT;  // common/denoise.glsl packColor

// Workgroups of kDenoiseTile x kDenoiseTile pixels over a width x height domain.
std::uint32_t groups(int width, int height, std::uint32_t* groupsY) {
  *groupsY = static_cast<std::uint32_t>((height + gpu::kDenoiseTile - 1) / gpu::kDenoiseTile);
  return static_cast<std::uint32_t>((width + gpu::kDenoiseTile - 1) / gpu::kDenoiseTile);
}

constexpr std::uint32_t kMaxStamps = 5 + gpu::kDenoiseIterations;  // start, prepare, variance, the iterations, finish, compose
constexpr const char* kAtrousNames[] = {"a-trous 1", "a-trous 2", "a-trous 4", "a-trous 8", "a-trous 16", "a-trous 32"};
static_assert(gpu::kDenoiseIterations <= 6);

// Every tile shows the layer as this frame writes it, all alike (so no seam between them).
bool showsLayerWhole(const DenoiseWork& work) {
  if (work.tileCodes.empty()) return false;
  const std::uint32_t first = work.tileCodes.front();
  return (first & gpu::kTileWrite) != 0 && (first & gpu::kTileKindMask) >= gpu::kTileLayer &&
         std::all_of(work.tileCodes.begin(), work.tileCodes.end(), [&](std::uint32_t c) { return c == first; });
}

}  // namespace

Denoiser::Denoiser(vk::Context& ctx) : ctx_(ctx) {}
Denoiser::~Denoiser() {
  if (timestamps_ != VK_NULL_HANDLE) vkDestroyQueryPool(ctx_.device(), timestamps_, nullptr);
}

void Denoiser::resize(int width, int height, vk::Buffer& accum, vk::Buffer& accumAux) {
  width_ = width;
  height_ = height;
  accum_ = &accum;
  accumAux_ = &accumAux;
  allocated_ = false;
  for (vk::Buffer* b : {&a_, &b_, &surface_, &gradient_, &moments_, &layer_, &display_}) *b = vk::Buffer();
}

void Denoiser::allocate() {
  if (!prepare_) {
    auto push = static_cast<std::uint32_t>(sizeof(gpu::DenoisePush));
    prepare_ = makePass(ctx_, Pass::DenoisePrepare, push);
    variance_ = makePass(ctx_, Pass::DenoiseVariance, push);
    // The a-trous iterations ping-pong between two buffers: one pipeline (and descriptor set) each way.
    for (auto* p : {&atrousAB_, &atrousBA_}) *p = makePass(ctx_, Pass::DenoiseAtrous, push);
    finish_ = makePass(ctx_, Pass::DenoiseFinish, push);
    compose_ = makePass(ctx_, Pass::Compose, push);
  }
  const VkDeviceSize pixels = static_cast<VkDeviceSize>(width_) * static_cast<VkDeviceSize>(height_);
  const VkDeviceSize px = pixels * sizeof(gpu::vec4);
  a_ = vk::Buffer(ctx_, pixels * 8, kReadWrite, false, "denoiser ping");
  b_ = vk::Buffer(ctx_, pixels * 8, kReadWrite, false, "denoiser pong");
  surface_ = vk::Buffer(ctx_, px, kReadWrite, false, "denoiser surfaces");
  gradient_ = vk::Buffer(ctx_, pixels * sizeof(float), kReadWrite, false, "denoiser depth gradients");
  moments_ = vk::Buffer(ctx_, px, kReadWrite, false, "denoiser moments");
  layer_ = vk::Buffer(ctx_, px, kReadWrite, false, "denoised layer");
  display_ = vk::Buffer(ctx_, px, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false, "displayed image");
  ctx_.submitAndWait([&](VkCommandBuffer cb) { vkCmdFillBuffer(cb, layer_.handle(), 0, VK_WHOLE_SIZE, 0); });

  prepare_->bind(gpu::kBindDenoisePrepareAccum, *accum_, kRgba32);
  prepare_->bind(gpu::kBindDenoisePrepareAccumAux, *accumAux_, kRgba32);
  prepare_->bind(gpu::kBindDenoisePrepareColors, a_);
  prepare_->bind(gpu::kBindDenoisePrepareSurface, surface_);
  prepare_->bind(gpu::kBindDenoisePrepareMoments, moments_);
  variance_->bind(gpu::kBindDenoiseVarianceColors, a_, kHalf4);
  variance_->bind(gpu::kBindDenoiseVarianceSurface, surface_, kRgba32);
  variance_->bind(gpu::kBindDenoiseVarianceMoments, moments_, kRgba32);
  variance_->bind(gpu::kBindDenoiseVarianceOut, b_);
  variance_->bind(gpu::kBindDenoiseVarianceGradient, gradient_);
  for (auto [pipe, from, to] : {std::tuple{atrousBA_.get(), &b_, &a_}, std::tuple{atrousAB_.get(), &a_, &b_}}) {
    pipe->bind(gpu::kBindDenoiseAtrousIn, *from, kHalf4);
    pipe->bind(gpu::kBindDenoiseAtrousSurface, surface_, kRgba32);
    pipe->bind(gpu::kBindDenoiseAtrousGradient, gradient_, VK_FORMAT_R32_SFLOAT);
    pipe->bind(gpu::kBindDenoiseAtrousOut, *to);
  }
  // The variance pass writes b; the iterations go b->a, a->b, ...; the last one's output is finished.
  finish_->bind(gpu::kBindDenoiseFinishColors, gpu::kDenoiseIterations % 2 == 1 ? a_ : b_, kHalf4);
  finish_->bind(gpu::kBindDenoiseFinishAccum, *accum_, kRgba32);
  finish_->bind(gpu::kBindDenoiseFinishAccumAux, *accumAux_, kRgba32);
  finish_->bind(gpu::kBindDenoiseFinishLayer, layer_);
  compose_->bind(gpu::kBindComposeAccum, *accum_, kRgba32);
  compose_->bind(gpu::kBindComposeLayer, layer_, kRgba32);
  compose_->bind(gpu::kBindComposeDisplay, display_);
  allocated_ = true;
}

void Denoiser::prepare(const DenoiseWork& work) {
  if (!work.compose) return;
  if (!allocated_) allocate();
  int cols = (width_ + work.tileSize - 1) / work.tileSize, rows = (height_ + work.tileSize - 1) / work.tileSize;
  auto count = static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows);
  RETILE_ASSERT(work.tileSize > 0 && work.tileCodes.size() == count,
                cat(work.tileCodes.size(), " tile codes for ", cols, "x", rows, " tiles of ", work.tileSize));
  VkDeviceSize bytes = std::max<VkDeviceSize>(count * sizeof(std::uint32_t), 16);
  if (!tiles_.valid() || tiles_.size() < bytes) {
    tiles_ = vk::Buffer(ctx_, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, "tile codes");
    prepare_->bind(gpu::kBindDenoisePrepareTiles, tiles_);
    finish_->bind(gpu::kBindDenoiseFinishTiles, tiles_);
    compose_->bind(gpu::kBindComposeTiles, tiles_);
  }
  tiles_.upload(work.tileCodes.data(), count * sizeof(std::uint32_t));
}

void Denoiser::record(VkCommandBuffer cb, const DenoiseWork& work) {
  timedPasses_.clear();
  layerShown_ = false;
  if (!work.compose) return;
  // Timestamps after each pass (the pass before them has finished: one queue, barriers between).
  if (work.timePasses && timestamps_ == VK_NULL_HANDLE) {
    VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = kMaxStamps;
    vk::checkVk(vkCreateQueryPool(ctx_.device(), &info, nullptr, &timestamps_), "creating the denoiser's timestamps");
  }
  if (work.timePasses) vkCmdResetQueryPool(cb, timestamps_, 0, kMaxStamps);
  auto stamp = [&](const char* name) {
    if (!work.timePasses) return;
    vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, timestamps_, static_cast<std::uint32_t>(timedPasses_.size()));
    timedPasses_.push_back(name);
  };
  gpu::DenoisePush push{};
  push.image = {static_cast<std::uint32_t>(width_), static_cast<std::uint32_t>(height_), 1,
                static_cast<std::uint32_t>(std::max(work.featherPixels, 0))};
  push.tiles = {static_cast<std::uint32_t>(work.tileSize), static_cast<std::uint32_t>((width_ + work.tileSize - 1) / work.tileSize), 0, 0};
  std::uint32_t gy;
  if (work.filter) {
    int x0 = std::clamp(work.x, 0, width_), y0 = std::clamp(work.y, 0, height_);
    int x1 = std::clamp(work.x + work.width, 0, width_), y1 = std::clamp(work.y + work.height, 0, height_);
    if (x1 > x0 && y1 > y0) {
      push.domain = {x0, y0, x1 - x0, y1 - y0};
      std::uint32_t gx = groups(x1 - x0, y1 - y0, &gy);
      vk::computeBarrier(cb);
      stamp("start");
      prepare_->dispatch(cb, gx, gy, &push, sizeof push);
      stamp("prepare");
      vk::computeBarrier(cb);
      variance_->dispatch(cb, gx, gy, &push, sizeof push);
      stamp("variance");
      for (int i = 0; i < gpu::kDenoiseIterations; ++i) {
        vk::computeBarrier(cb);
        push.image.z = 1u << i;
        (i % 2 == 0 ? atrousBA_ : atrousAB_)->dispatch(cb, gx, gy, &push, sizeof push);
        stamp(kAtrousNames[i]);
      }
      vk::computeBarrier(cb);
      finish_->dispatch(cb, gx, gy, &push, sizeof push);
      stamp("finish");
      // A frame denoised whole shows the layer everywhere, without seams: the layer is the
      // displayed image and there is nothing to compose.
      layerShown_ = x0 == 0 && y0 == 0 && x1 == width_ && y1 == height_ && showsLayerWhole(work);
      if (layerShown_) return;
    }
  }
  push.domain = {0, 0, width_, height_};
  push.image.z = 1;
  vk::computeBarrier(cb);
  std::uint32_t gx = groups(width_, height_, &gy);
  if (timedPasses_.empty()) stamp("start");
  compose_->dispatch(cb, gx, gy, &push, sizeof push);
  stamp("compose");
}

std::vector<FrameStats::PassTime> Denoiser::passTimes() {
  std::vector<FrameStats::PassTime> out;
  if (timedPasses_.size() < 2) return out;
  std::vector<std::uint64_t> ticks(timedPasses_.size());
  vk::checkVk(
      vkGetQueryPoolResults(ctx_.device(), timestamps_, 0, static_cast<std::uint32_t>(ticks.size()), ticks.size() * sizeof(std::uint64_t),
                            ticks.data(), sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
      "reading the denoiser's timestamps");
  const double msPerTick = static_cast<double>(ctx_.properties().limits.timestampPeriod) * 1e-6;
  for (std::size_t i = 1; i < ticks.size(); ++i) out.push_back({timedPasses_[i], static_cast<double>(ticks[i] - ticks[i - 1]) * msPerTick});
  timedPasses_.clear();
  return out;
}

}  // namespace retile
