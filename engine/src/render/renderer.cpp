#include "retile/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <tuple>

#include "core/process.h"
#include "render/denoiser.h"
#include "render/passes.h"
#include "render/render_scene.h"
#include "retile/log.h"
#include "shared/layouts.h"
#include "vk/buffer.h"
#include "vk/check.h"
#include "vk/context.h"
#include "vk/pipeline.h"

namespace retile {

using vk::Buffer;

namespace {

constexpr VkBufferUsageFlags kTexelUsage = VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
// What the trace kernel reads of the scene: storage texel buffers, read with imageLoad, which
// lavapipe inlines (a texelFetch is a call, scene.glsl).
constexpr VkBufferUsageFlags kSceneUsage = VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT;
constexpr VkBufferUsageFlags kStorageUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;

std::uint32_t groupsFor(std::uint64_t invocations, std::uint32_t local, std::uint32_t* groupsY) {
  std::uint64_t groups = (invocations + local - 1) / local;
  auto x = static_cast<std::uint32_t>(std::min<std::uint64_t>(groups, 65535));
  *groupsY = x ? static_cast<std::uint32_t>((groups + x - 1) / x) : 0;
  return x;
}

// Each trace invocation runs several paths one after another (trace.comp), so the lock-stepped
// lanes of its subgroup rarely wait for the longest path: on the Cornell box 128 paths per
// invocation trace about 1.5 times as many samples per second as one. The count is chosen from
// the last frame's mean loop iterations per path, to stay clear of lavapipe's loop limit: the
// mean invocation aims at 0.4 of the budget, because the busiest ran 1.2 to 1.3 times the mean
// in the Cornell box and the living room and 1.8 times on the bunny (an invocation traces a column
// of the image, some through the bunny and some past it). It also leaves enough invocations for
// every thread of the device. (Aiming the busiest invocation at half the budget instead was 10 to
// 20 % slower on the bunny, for reasons not found.) Those ratios were measured in frames of one
// sample per pixel; in an offline render's frames of 64 on a 32x32 image (a pixel's samples side
// by side, so an invocation traces whole pixels) the busiest ran 1.31 times the mean in the
// living room, 15634 loop iterations against the budget's 30000.
static_assert(kTraceLoopBudget == gpu::kLoopBudget, "render.h and shaders/shared/layouts.h disagree");
static_assert(gpu::kStatsPathEnds + FrameStats::kPathEnds <= gpu::kStatsCount, "the path ends' counters lie past the buffer");

// `fixedPaths` > 0 overrides the choice (FrameOptions::pathsPerInvocation).
std::uint64_t traceInvocations(std::uint64_t slots, double iterationsPerPath, int fixedPaths) {
  if (fixedPaths > 0) return (slots + static_cast<std::uint64_t>(fixedPaths) - 1) / static_cast<std::uint64_t>(fixedPaths);
  constexpr double kIterationTarget = gpu::kLoopBudget * 0.4;
  constexpr std::uint64_t kMaxPathsPerInvocation = 128, kMinInvocations = 512;
  auto paths = static_cast<std::uint64_t>(
      std::clamp(kIterationTarget / std::max(iterationsPerPath, 1.0), 1.0, static_cast<double>(kMaxPathsPerInvocation)));
  return std::max(std::min(slots, kMinInvocations), (slots + paths - 1) / paths);
}

}  // namespace

struct Renderer::Impl {
  vk::Context ctx;
  // By (alpha-tested geometry, material types, features): each scene runs a kernel without the
  // code it lacks.
  std::map<std::tuple<bool, std::uint32_t, std::uint32_t>, std::unique_ptr<vk::ComputePipeline>> traceVariants;
  vk::ComputePipeline* trace = nullptr;
  // The same with the selection's counting (kFeatureSelectionCounts), for the frames that count
  // (FrameOptions::selectionTileSize): looked up at the first of them after selectTrace.
  vk::ComputePipeline* traceCounting = nullptr;
  std::tuple<bool, std::uint32_t, std::uint32_t> traceKey{false, 0u, 0u};  // trace's
  std::unique_ptr<vk::ComputePipeline> accumulate;
  std::unique_ptr<vk::ComputePipeline> reusePass;  // created with the history, on first use
  Denoiser denoiser{ctx};
  bool displayCurrent = false;  // the denoiser's display matches the accumulation (readback takes it)
  RenderSceneBuilder builder;
  bool directReferences = true;  // RendererOptions::directReferences, for each scene's builder

  Buffer frameUbo, work, stats, selection;
  Buffer traversal, triShade, instances, materials, texInfo, texels, emitters, alias, delta, envCdf;
  Buffer filterWarp;  // FrameUniforms::filterWarp's values again, for the trace kernel (trace.comp warpSlot)
  Buffer samples, aux, accum, accumAux;
  Buffer history, reuseItems;  // verified reuse: allocated on first use, dropped on resize

  Camera camera;
  // The media around the camera (mediaAround), for the position they were found at; found again
  // when the camera moves or the scene changes (mediaKnown false).
  MediaAround media;
  Vec3 mediaAt{0.0f};
  bool mediaKnown = false;
  int width = 0, height = 0;
  // Loop iterations per path in the last frame (see traceInvocations); a cautious guess until a
  // frame of the current scene has been traced.
  static constexpr double kUnknownIterationsPerPath = 2000;
  double iterationsPerPath = kUnknownIterationsPerPath;
  int maxBounces = 8;
  // Longer paths cost more loop iterations than the last frame's figure says: guess again.
  void setMaxBounces(int bounces) {
    if (bounces > maxBounces) iterationsPerPath = kUnknownIterationsPerPath;
    maxBounces = bounces;
  }
  std::uint32_t seed = 0;
  RenderSettings sceneSettings;
  // The pixel filter's inverse CDF, recomputed when the scene's filter changes.
  std::vector<float> warp;
  PixelFilter warpFilter = PixelFilter::Box;
  float warpWidth = 0.0f;
  bool warpStepped = false;
  bool hasScene = false;
  NodeId selectedObject = kNoNode;
  std::vector<NodeId> countedGroup;      // counted beside the selection: every object of its material
  int countTileSize = 0;                 // tile size the selection buffer is laid out for
  std::size_t countTiles = 0;            // tiles it holds counters for
  std::vector<std::uint32_t> setWords;   // the sets' words on the device (layouts.h)
  std::vector<gpu::WorkItem> lastItems;  // the last frame's work, for readbackFrameLuminance

  // Pipelined frames: the submitted frame's results land in one of two slots, so that the frame
  // before it can still be read back (converted) while the device traces.
  struct Slot {
    std::uint64_t ticket = 0;
    bool completed = false;
    bool hasImage = false;
    bool hasDisplay = false;
    bool hasHistory = false;
    int width = 0, height = 0;
    Buffer image;                 // host-visible copies: accumulation, its auxiliary part, the display
    std::vector<NodeId> objects;  // instance -> object when submitted (edits may follow)
    FrameStats stats;
    std::uint64_t invocations = 0;
    std::chrono::steady_clock::time_point submitted;
  };
  Slot slots_[2];
  std::uint64_t nextTicket = 1;
  std::uint64_t inFlight = 0;  // ticket of the submitted frame not yet completed (0: none)

  explicit Impl(const RendererOptions& o) : ctx(vk::DeviceChoice{o.device, o.validation || kDebugValidation}) {
    accumulate = makePass(ctx, Pass::Accumulate, static_cast<std::uint32_t>(sizeof(gpu::AccumulatePush)));
    directReferences = o.directReferences;
    builder.setDirectReferences(directReferences);
    frameUbo = Buffer(ctx, sizeof(gpu::FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true,
                      "frame constants");
    stats = Buffer(ctx, gpu::kStatsCount * sizeof(std::uint32_t), kStorageUsage, true, "ray statistics");
    selection = Buffer(ctx, 16, kStorageUsage, true, "selection counters");
    work = Buffer(ctx, sizeof(gpu::WorkItem) * 64, kStorageUsage, true, "work items");
    filterWarp = Buffer(ctx, sizeof(gpu::FrameUniforms::filterWarp), kSceneUsage, true, "pixel filter table");
  }

#ifdef RETILE_VULKAN_VALIDATION
  static constexpr bool kDebugValidation = true;
#else
  static constexpr bool kDebugValidation = false;
#endif

  template <class T>
  void uploadArray(Buffer& b, const std::vector<T>& data, const char* what) {
    VkDeviceSize bytes = data.size() * sizeof(T);
    if (!b.valid() || b.size() < bytes || (b.size() > 2 * bytes + 65536)) b = Buffer(ctx, bytes, kSceneUsage, false, what);
    b.upload(data.data(), bytes);
  }

  void upload(std::uint32_t dirty) {
    completeInFlight();  // the frame in flight uses what this touches
    const RenderSceneData& d = builder.data();
    if (dirty & (kDirtyGeometry | kDirtyInstances | kDirtyTriangleNames)) {
      VkDeviceSize meshBytes = d.meshTraversal.size() * sizeof(gpu::vec4);
      VkDeviceSize need = meshBytes + d.topTraversal.size() * sizeof(gpu::vec4);
      if (dirty & (kDirtyGeometry | kDirtyTriangleNames) || !traversal.valid() || traversal.size() < need) {
        // Room for the top part to grow, so that adding objects does not re-upload the meshes.
        // The two parts are copied in place: a joined copy on the host would add the size of
        // every mesh to the peak memory of loading a scene.
        const VkDeviceSize room = std::min<VkDeviceSize>(meshBytes + (2 * d.topTraversal.size() + 256) * sizeof(gpu::vec4),
                                                         gpu::kMaxTraversalTexels * sizeof(gpu::vec4));
        if (!traversal.valid() || traversal.size() < need || traversal.size() > 2 * room + 65536)
          traversal = Buffer(ctx, std::max(room, need), kSceneUsage, false, "BVH and triangles");
        traversal.upload(d.meshTraversal.data(), meshBytes, 0);
        traversal.upload(d.topTraversal.data(), need - meshBytes, meshBytes);
      } else {
        // Only the top level changed: copy it alone, after the meshes. The cost of moving an
        // object does not depend on the size of any mesh.
        traversal.upload(d.topTraversal.data(), d.topTraversal.size() * sizeof(gpu::vec4), meshBytes);
      }
    }
    if (dirty & kDirtyGeometry) {
      iterationsPerPath = kUnknownIterationsPerPath;  // another scene may cost far more per path
      uploadArray(triShade, d.triangleShading, "triangle shading data");
    }
    if (dirty & kDirtyInstances) uploadArray(instances, d.instances, "instances");
    if (dirty & kDirtyMaterials) uploadArray(materials, d.materials, "materials");
    if (dirty & kDirtyTextures) {
      uploadArray(texInfo, d.textureInfo, "texture table");
      uploadArray(texels, d.texels, "texels");
    }
    if (dirty & kDirtyEnvironment) uploadArray(envCdf, d.environmentCdf, "environment distribution");
    if (dirty & kDirtyEmitters) {
      uploadArray(emitters, d.emitters, "emitters");
      uploadArray(alias, d.emitterAlias, "emitter alias table");
      uploadArray(delta, d.deltaLights, "delta lights");
    }
    selectTrace(d.alphaTested(), d.materialTypes, d.features());
    bindAll();
  }

  // Picks the trace kernel the scene needs.
  void selectTrace(bool alpha, std::uint32_t materialTypes, std::uint32_t features) {
    traceKey = {alpha, materialTypes, features};
    trace = traceVariant(alpha, materialTypes, features);
    traceCounting = nullptr;
  }

  // The kernel a frame runs: the scene's, or the one that also counts the selection.
  vk::ComputePipeline* frameTrace(bool counting) {
    if (!counting) return trace;
    if (!traceCounting) {
      auto [alpha, types, features] = traceKey;
      traceCounting = traceVariant(alpha, types, features | static_cast<std::uint32_t>(gpu::kFeatureSelectionCounts));
      ctx.wait();  // a frame in flight may have run this variant before selectTrace and still hold its descriptors
      bindTrace(*traceCounting);
    }
    return traceCounting;
  }

  // A trace kernel variant, compiled on first use (about 0.3 s on lavapipe, on the render thread;
  // the SPIR-V is cached on disk).
  vk::ComputePipeline* traceVariant(bool alpha, std::uint32_t materialTypes, std::uint32_t features) {
    auto& slot = traceVariants[{alpha, materialTypes, features}];
    if (!slot) {
      slot = makePass(ctx, Pass::Trace, static_cast<std::uint32_t>(sizeof(gpu::TracePush)),
                      {{"RETILE_ALPHA_TEST", alpha ? "1" : "0"},
                       {"RETILE_MATERIALS", std::to_string(materialTypes)},
                       {"RETILE_FEATURES", std::to_string(features)}});
    }
    return slot.get();
  }

  void bindAll() {
    if (trace) bindTrace(*trace);
    if (traceCounting) bindTrace(*traceCounting);
    bindAccumulate(*accumulate);
  }

  void bindTrace(vk::ComputePipeline& t) {
    t.bind(gpu::kBindTraceFrame, frameUbo);
    t.bind(gpu::kBindTraceWork, work);
    t.bind(gpu::kBindTraceTraversal, traversal, VK_FORMAT_R32G32B32A32_SFLOAT);
    t.bind(gpu::kBindTraceTriShade, triShade, VK_FORMAT_R32G32B32A32_SFLOAT);
    t.bind(gpu::kBindTraceInstances, instances, VK_FORMAT_R32G32B32A32_SFLOAT);
    t.bind(gpu::kBindTraceMaterials, materials, VK_FORMAT_R32G32B32A32_SFLOAT);
    t.bind(gpu::kBindTraceTexInfo, texInfo, VK_FORMAT_R32G32B32A32_SFLOAT);
    t.bind(gpu::kBindTraceTexels, texels, VK_FORMAT_R32G32_UINT);  // pairs of words (layouts.h kTexEightBit)
    t.bind(gpu::kBindTraceEmitters, emitters, VK_FORMAT_R32G32B32A32_SFLOAT);
    t.bind(gpu::kBindTraceAlias, alias, VK_FORMAT_R32G32B32A32_SFLOAT);
    t.bind(gpu::kBindTraceDelta, delta, VK_FORMAT_R32G32B32A32_SFLOAT);
    t.bind(gpu::kBindTraceEnvCdf, envCdf, VK_FORMAT_R32_SFLOAT);
    t.bind(gpu::kBindTraceStats, stats);
    t.bind(gpu::kBindTraceSelection, selection);
    t.bind(gpu::kBindTraceFilterWarp, filterWarp, VK_FORMAT_R32_SFLOAT);
    if (samples.valid()) {
      t.bind(gpu::kBindTraceSamples, samples);
      t.bind(gpu::kBindTraceAux, aux);
    }
  }

  void bindAccumulate(vk::ComputePipeline& a) {
    a.bind(gpu::kBindAccumulateFrame, frameUbo);
    a.bind(gpu::kBindAccumulateWork, work);
    if (samples.valid()) {
      a.bind(gpu::kBindAccumulateSamples, samples);
      a.bind(gpu::kBindAccumulateAux, aux);
    }
    if (accum.valid()) {
      a.bind(gpu::kBindAccumulateAccum, accum);
      a.bind(gpu::kBindAccumulateAccumAux, accumAux);
      // Without a history the shader never reads it; it still needs a buffer.
      a.bind(gpu::kBindAccumulateHistory, history.valid() ? history : accum);
    }
    if (reusePass && history.valid()) {
      reusePass->bind(gpu::kBindReuseFrame, frameUbo);
      reusePass->bind(gpu::kBindReuseItems, reuseItems);
      reusePass->bind(gpu::kBindReuseAccum, accum);
      reusePass->bind(gpu::kBindReuseHistory, history);
      reusePass->bind(gpu::kBindReuseAccumAux, accumAux);
    }
  }

  // The reuse pass's items for this frame (clipped to the image); allocates the history on first
  // use. Returns the number of pixels they cover.
  std::uint64_t prepareReuse(const std::vector<FrameOptions::Reuse>& ops, std::vector<gpu::ReuseItem>& items) {
    std::uint64_t pixels = 0;
    for (const auto& r : ops) {
      int x0 = std::max(r.x, 0), y0 = std::max(r.y, 0);
      int x1 = std::min(r.x + r.width, width), y1 = std::min(r.y + r.height, height);
      if (x1 <= x0 || y1 <= y0) continue;
      gpu::ReuseItem it{};
      it.rect = {x0, y0, x1 - x0, y1 - y0};
      it.info = {static_cast<std::uint32_t>(r.op), static_cast<std::uint32_t>(pixels), 0, 0};
      pixels += static_cast<std::uint64_t>(x1 - x0) * static_cast<std::uint64_t>(y1 - y0);
      items.push_back(it);
    }
    if (items.empty()) return 0;
    bool rebind = false;
    if (!history.valid()) {
      const VkDeviceSize bytes = static_cast<VkDeviceSize>(width) * static_cast<VkDeviceSize>(height) * 2 * sizeof(gpu::vec4);
      history = Buffer(ctx, bytes, kStorageUsage, false, "reuse history");
      ctx.submitAndWait([&](VkCommandBuffer cb) { vkCmdFillBuffer(cb, history.handle(), 0, VK_WHOLE_SIZE, 0); });
      if (!reusePass) reusePass = makePass(ctx, Pass::Reuse, static_cast<std::uint32_t>(sizeof(gpu::ReusePush)));
      rebind = true;
    }
    const VkDeviceSize bytes = items.size() * sizeof(gpu::ReuseItem);
    if (reuseItems.size() < bytes) {
      reuseItems = Buffer(ctx, bytes * 2, kStorageUsage, true, "reuse items");
      rebind = true;
    }
    if (rebind) bindAll();
    reuseItems.upload(items.data(), bytes);
    return pixels;
  }

  void ensureSampleCapacity(std::uint64_t slots) {
    VkDeviceSize need = std::max<std::uint64_t>(slots, 1) * 16;
    if (samples.valid() && samples.size() >= need) return;
    samples = Buffer(ctx, need, kStorageUsage, false, "samples");
    aux = Buffer(ctx, need * gpu::kAuxVec4s, kStorageUsage, false, "auxiliary samples");
    bindAll();
  }

  void resize(int w, int h) {
    completeInFlight();  // the frame in flight uses what this touches
    RETILE_ASSERT(w > 0 && h > 0 && w <= kMaxImageSide && h <= kMaxImageSide, cat("size ", w, "x", h));
    width = w;
    height = h;
    countTileSize = 0;  // the counters' layout follows the image
    const VkDeviceSize pixels = static_cast<VkDeviceSize>(w) * static_cast<VkDeviceSize>(h);
    // Written by the accumulate pass, read by the denoiser through texel views.
    constexpr VkBufferUsageFlags kAccumUsage = kStorageUsage | kTexelUsage;
    accum = Buffer(ctx, pixels * 2 * sizeof(gpu::vec4), kAccumUsage, false, "accumulation");
    history = Buffer();  // a resize keeps no samples, so no history either
    accumAux = Buffer(ctx, pixels * gpu::kAuxVec4s * sizeof(gpu::vec4), kAccumUsage, false, "auxiliary accumulation");
    ctx.submitAndWait([&](VkCommandBuffer cb) {
      vkCmdFillBuffer(cb, accum.handle(), 0, VK_WHOLE_SIZE, 0);
      vkCmdFillBuffer(cb, accumAux.handle(), 0, VK_WHOLE_SIZE, 0);
    });
    ensureSampleCapacity(static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h));
    bindAll();
    denoiser.resize(w, h, accum, accumAux);
    displayCurrent = false;
  }

  // Per instance, two bits: the selected object (bit 0) and its group (bit 1); a removed or hidden
  // object is in no instance the tracer reaches.
  std::vector<std::uint32_t> countedSetWords() const {
    const auto& objects = builder.data().instanceObject;
    std::vector<std::uint32_t> words((objects.size() + gpu::kInstancesPerSetWord - 1) / gpu::kInstancesPerSetWord + 1, 0u);
    for (std::size_t i = 0; i < objects.size(); ++i) {
      const bool selected = objects[i] == selectedObject && selectedObject != kNoNode;
      const bool grouped = std::find(countedGroup.begin(), countedGroup.end(), objects[i]) != countedGroup.end();
      const std::uint32_t bits = (selected ? 1u : 0u) | (grouped ? 2u : 0u);
      words[i / gpu::kInstancesPerSetWord] |= bits << ((i % gpu::kInstancesPerSetWord) * 2);
    }
    return words;
  }

  // Lays the counters out for `tileSize` after the sets' words (clearing them when either
  // changes). Returns where the counters start, in words.
  std::uint32_t prepareSelection(int tileSize) {
    if (tileSize <= 0) return 0;
    const std::size_t tiles =
        static_cast<std::size_t>((width + tileSize - 1) / tileSize) * static_cast<std::size_t>((height + tileSize - 1) / tileSize);
    std::vector<std::uint32_t> words = countedSetWords();
    const VkDeviceSize bytes = (words.size() + tiles * gpu::kSelectionCounters) * sizeof(std::uint32_t);
    if (tileSize != countTileSize || tiles != countTiles || words.size() != setWords.size() || selection.size() < bytes) {
      selection = Buffer(ctx, std::max<VkDeviceSize>(bytes, 16), kStorageUsage, true, "selection counters");
      std::vector<std::uint32_t> zero(selection.size() / sizeof(std::uint32_t), 0);
      std::copy(words.begin(), words.end(), zero.begin());
      selection.upload(zero.data(), zero.size() * sizeof(std::uint32_t));
      countTileSize = tileSize;
      countTiles = tiles;
      setWords = std::move(words);
      bindAll();
    } else if (words != setWords) {
      selection.upload(words.data(), words.size() * sizeof(std::uint32_t));  // a new selection: the counts start again
      std::vector<std::uint32_t> zero(tiles * gpu::kSelectionCounters, 0);
      selection.upload(zero.data(), zero.size() * sizeof(std::uint32_t), words.size() * sizeof(std::uint32_t));
      setWords = std::move(words);
    }
    return static_cast<std::uint32_t>(setWords.size());
  }

  SelectionCounts takeSelectionCounts() {
    completeInFlight();  // the frame in flight uses what this touches
    SelectionCounts c;
    c.tileSize = countTileSize;
    if (countTileSize <= 0 || width <= 0 || countTiles == 0) return c;
    const std::size_t tiles = countTiles;
    const VkDeviceSize offset = setWords.size() * sizeof(std::uint32_t);
    std::vector<std::uint32_t> raw(tiles * gpu::kSelectionCounters);
    selection.download(raw.data(), raw.size() * sizeof(std::uint32_t), offset);
    std::vector<std::uint32_t> zero(raw.size(), 0);
    selection.upload(zero.data(), zero.size() * sizeof(std::uint32_t), offset);
    for (auto* set : {&c.object, &c.group}) {
      set->direct.resize(tiles);
      set->reflection.resize(tiles);
      set->shadow.resize(tiles);
    }
    for (std::size_t t = 0; t < tiles; ++t) {
      const std::uint32_t* r = &raw[t * gpu::kSelectionCounters];
      c.object.direct[t] = r[0];
      c.object.reflection[t] = r[1];
      c.object.shadow[t] = r[2];
      c.group.direct[t] = r[3];
      c.group.reflection[t] = r[4];
      c.group.shadow[t] = r[5];
    }
    return c;
  }

  // The sample slots a work item takes: one per pixel, or per block of a coarse item, q each.
  static std::uint64_t itemSlots(const gpu::WorkItem& w) {
    const std::uint64_t b = std::max(w.pixels.z, 1u);
    return ((static_cast<std::uint64_t>(w.rect.z) + b - 1) / b) * ((static_cast<std::uint64_t>(w.rect.w) + b - 1) / b) * w.info.x;
  }

  std::vector<float> readbackFrameLuminance() {
    completeInFlight();  // the frame in flight uses what this touches
    std::vector<float> lum(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), std::numeric_limits<float>::quiet_NaN());
    std::uint64_t slots = 0;
    for (const auto& w : lastItems) slots = std::max(slots, w.info.y + itemSlots(w));
    if (slots == 0) return lum;
    std::vector<gpu::vec4> s(slots);
    samples.download(s.data(), slots * sizeof(gpu::vec4));
    for (const auto& w : lastItems) {
      if (w.pixels.z > 1) continue;  // a preview's block: no pixel of its own (probes are never coarse)
      std::uint64_t pixels = static_cast<std::uint64_t>(w.rect.z) * static_cast<std::uint64_t>(w.rect.w);
      for (std::uint64_t p = 0; p < pixels; ++p) {
        double sum = 0, n = 0;
        for (std::uint32_t r = 0; r < w.info.x; ++r) {
          const gpu::vec4& v = s[w.info.y + p * w.info.x + r];
          sum += 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
          n += v.w;
        }
        int x = w.rect.x + static_cast<int>(p % static_cast<std::uint64_t>(w.rect.z));
        int y = w.rect.y + static_cast<int>(p / static_cast<std::uint64_t>(w.rect.z));
        if (n > 0)
          lum[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)] = static_cast<float>(sum / n);
      }
    }
    return lum;
  }

  // `counters`: where the selection buffer's counters start (0: not counting).
  void writeFrameUniforms(std::uint32_t itemCount, std::uint64_t slots, int countTile, std::uint32_t counters) {
    const RenderSceneData& d = builder.data();
    gpu::FrameUniforms u{};
    Vec3 forward = normalize(camera.target - camera.position);
    Vec3 right = normalize(cross(forward, camera.up));
    if (length(right) == 0) right = normalize(cross(forward, std::abs(forward.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 0, 1}));
    Vec3 up = cross(right, forward);
    float tanHalf = std::tan(0.5f * camera.verticalFov);
    u.cameraPosition = {camera.position.x, camera.position.y, camera.position.z, tanHalf};
    u.cameraRight = {right.x, right.y, right.z, static_cast<float>(width) / static_cast<float>(height)};
    u.cameraUp = {up.x, up.y, up.z, camera.apertureRadius};
    u.cameraForward = {forward.x, forward.y, forward.z, camera.focusDistance};
    u.image = {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height), seed,
               static_cast<std::uint32_t>(std::max(maxBounces, 0))};
    u.scene = {d.tlasRoot, static_cast<std::int32_t>(d.instanceReferences),
               static_cast<std::int32_t>(d.emitters.size() / gpu::kEmitterTexels),
               static_cast<std::int32_t>(d.deltaLights.size() / gpu::kDeltaLightTexels)};
    u.lightPick = {d.lightPick[0], d.lightPick[1], d.lightPick[2], static_cast<float>(d.suns)};
    u.environment = {d.environmentType, d.environmentMap, d.environmentWidth, d.environmentHeight};
    u.environmentTint = {d.environmentTint.x, d.environmentTint.y, d.environmentTint.z, 0};
    for (int r = 0; r < 3; ++r)
      u.environmentToMap[r] = {d.environmentToMap.m[r][0], d.environmentToMap.m[r][1], d.environmentToMap.m[r][2], 0};
    Vec3 c = d.bounds.empty() ? Vec3{0.0f} : d.bounds.center();
    u.sceneSphere = {c.x, c.y, c.z, d.bounds.empty() ? 1.0f : 0.5f * length(d.bounds.extent())};
    if (!mediaKnown || mediaAt != camera.position) {
      media = mediaAround(d, camera.position);
      mediaAt = camera.position;
      mediaKnown = true;
    }
    const MediumAt &in = media.in, &around = media.around;
    u.cameraAbsorption = {in.absorption.x, in.absorption.y, in.absorption.z, in.glass ? 1.0f : 0.0f};
    u.cameraScattering = {in.scattering.x, in.scattering.y, in.scattering.z, in.anisotropy};
    u.cameraOuterAbsorption = {around.absorption.x, around.absorption.y, around.absorption.z, around.glass ? 1.0f : 0.0f};
    u.cameraOuterScattering = {around.scattering.x, around.scattering.y, around.scattering.z, around.anisotropy};
    const MediumAt& world = d.worldMedium;
    u.worldAbsorption = {world.absorption.x, world.absorption.y, world.absorption.z, d.lightInScatteringGlass ? 0.0f : 1.0f};
    u.worldScattering = {world.scattering.x, world.scattering.y, world.scattering.z, world.anisotropy};
    u.bounces = {d.minBounces, d.lightGroups, 0, 0};
    std::copy_n(d.lightGroupShapes.begin(), std::min<std::size_t>(d.lightGroupShapes.size(), std::size(u.lightGroups)), u.lightGroups);
    const bool counting = countTile > 0 && counters > 0;
    u.work = {itemCount, static_cast<std::uint32_t>(slots), counting ? counters + 1 : 0u,
              counting ? static_cast<std::uint32_t>(countTile) : 0u};
    // The stepped table is drawn for a tent and a Gaussian only; a box is drawn exactly either way.
    const int drawn = d.filterFeature;  // the compiled kernel's
    const bool stepped = drawn == gpu::kFeatureFilterStepped || drawn == gpu::kFeatureFilterSteppedTent;
    if (warpFilter != sceneSettings.pixelFilter || warpWidth != sceneSettings.filterWidth || warpStepped != stepped || warp.empty()) {
      warpFilter = sceneSettings.pixelFilter;
      warpWidth = sceneSettings.filterWidth;
      warpStepped = stepped;
      warp = stepped ? steppedFilterCdf(warpFilter) : pixelFilterWarp(warpFilter, warpWidth, gpu::kFilterWarpSegments);
    }
    for (std::size_t i = 0; i < warp.size(); ++i) {
      gpu::vec4& v = u.filterWarp[i / 4];
      (i % 4 == 0 ? v.x : i % 4 == 1 ? v.y : i % 4 == 2 ? v.z : v.w) = warp[i];
    }
    // The tent's inverse CDF has an infinite slope at its ends, where the table's straight pieces
    // put too many samples: the shader inverts it exactly when this (its radius) is set.
    const float radius = 0.5f * std::clamp(warpWidth, 0.01f, 16.0f);
    u.filterWarp[8].w = stepped ? -radius : drawn == gpu::kFeatureFilterTent ? radius : 0.0f;
    // Which of the two stepped ones (a kernel compiled with every feature has the code for both).
    u.filterWarp[8].z = drawn == gpu::kFeatureFilterSteppedTent ? 1.0f : 0.0f;
    frameUbo.upload(&u, sizeof u);
    filterWarp.upload(u.filterWarp, sizeof u.filterWarp);  // host-visible: a copy of 144 bytes
  }

  std::uint64_t submitFrame(const std::vector<TileWork>& tiles, const FrameOptions& options, bool copyImage) {
    RETILE_ASSERT(hasScene, "renderFrame before setScene");
    RETILE_ASSERT(width > 0, "renderFrame before resize");
    completeInFlight();
    std::vector<gpu::WorkItem> items;
    items.reserve(tiles.size());
    std::uint64_t slots = 0, pixels = 0;
    for (const TileWork& t : tiles) {
      // Clip to the image; an empty tile is skipped rather than an error.
      int x0 = std::max(t.x, 0), y0 = std::max(t.y, 0);
      int x1 = std::min(t.x + t.width, width), y1 = std::min(t.y + t.height, height);
      if (x1 <= x0 || y1 <= y0 || t.quality < 1) continue;
      gpu::WorkItem w{};
      w.rect = {x0, y0, x1 - x0, y1 - y0};
      std::uint32_t flags = t.restart ? gpu::kWorkRestart : (t.capStale > 0 ? gpu::kWorkCapStale : 0u);
      w.info = {static_cast<std::uint32_t>(t.quality), static_cast<std::uint32_t>(slots), t.sampleBase, flags};
      w.pixels = {static_cast<std::uint32_t>(pixels), static_cast<std::uint32_t>(std::max(t.capStale, 0)),
                  static_cast<std::uint32_t>(std::clamp(t.block, 1, 64)), 0};
      slots += itemSlots(w);
      pixels += static_cast<std::uint64_t>(x1 - x0) * static_cast<std::uint64_t>(y1 - y0);
      items.push_back(w);
    }
    // The trace kernel divides by its invocations, at most the slots, in floats (integer.glsl quotient).
    RETILE_ASSERT(slots < (1ull << 30), cat("a frame of ", slots, " samples"));
    std::uint64_t invocations = 0;
    vk::ComputePipeline* tracer = nullptr;
    if (!items.empty()) {
      ensureSampleCapacity(slots + 1);  // the trace pass's spare slot (trace.comp)
      VkDeviceSize workBytes = items.size() * sizeof(gpu::WorkItem);
      if (work.size() < workBytes) {
        work = Buffer(ctx, workBytes * 2, kStorageUsage, true, "work items");
        bindAll();
      }
      work.upload(items.data(), workBytes);
      const std::uint32_t counters = prepareSelection(options.selectionTileSize);
      writeFrameUniforms(static_cast<std::uint32_t>(items.size()), slots, options.selectionTileSize, counters);
      std::uint32_t zero[gpu::kStatsCount] = {};
      stats.upload(zero, sizeof zero);
      invocations = traceInvocations(slots, iterationsPerPath, options.pathsPerInvocation);
      tracer = frameTrace(options.selectionTileSize > 0);
    }
    std::vector<gpu::ReuseItem> reuse;
    const std::uint64_t reusePixels = options.accumulate ? prepareReuse(options.reuse, reuse) : 0;
    lastItems = items;
    const bool compose = options.denoise.compose && options.accumulate;
    if (compose) denoiser.prepare(options.denoise);
    if (options.accumulate && !items.empty()) displayCurrent = compose;
    else if (compose) displayCurrent = true;

    const std::uint64_t ticket = nextTicket++;
    Slot& slot = slots_[ticket % 2];
    slot.ticket = ticket;
    slot.completed = false;
    slot.hasImage = copyImage;
    slot.hasDisplay = copyImage && displayCurrent;
    slot.hasHistory = copyImage && history.valid();
    slot.width = width;
    slot.height = height;
    slot.stats = FrameStats{};
    slot.stats.samples = slots;
    slot.invocations = invocations;
    const VkDeviceSize pixelCount = static_cast<VkDeviceSize>(width) * static_cast<VkDeviceSize>(height);
    const VkDeviceSize imageBytes = pixelCount * 2 * sizeof(gpu::vec4);
    const VkDeviceSize auxBytes = pixelCount * gpu::kAuxVec4s * sizeof(gpu::vec4);
    const VkDeviceSize displayBytes = pixelCount * sizeof(gpu::vec4);
    const VkDeviceSize historyBytes = slot.hasHistory ? imageBytes : 0;
    if (copyImage) {
      const VkDeviceSize total = imageBytes + auxBytes + displayBytes + historyBytes;
      if (!slot.image.valid() || slot.image.size() != total)
        slot.image = Buffer(ctx, total, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, "image read-back");
      slot.objects = builder.data().instanceObject;
    }
    slot.submitted = std::chrono::steady_clock::now();
    ctx.submit([&](VkCommandBuffer cb) {
      if (reusePixels > 0) {
        gpu::ReusePush rp{static_cast<std::uint32_t>(reusePixels), static_cast<std::uint32_t>(reuse.size()), 0, 0};
        std::uint32_t gy;
        std::uint32_t gx = groupsFor(reusePixels, gpu::kAccumulateWorkgroup, &gy);
        reusePass->dispatch(cb, gx, gy, &rp, sizeof rp);
        vk::computeBarrier(cb);
      }
      if (!items.empty()) {
        // A slot the trace pass does not reach (its invocation ran out of loop budget) must read
        // as weight 0, not as the last frame's sample.
        vkCmdFillBuffer(cb, samples.handle(), 0, static_cast<VkDeviceSize>(slots) * sizeof(gpu::vec4), 0);
        vk::computeBarrier(cb);
        gpu::TracePush tp{0, static_cast<std::uint32_t>(slots), static_cast<std::uint32_t>(invocations), 0};
        std::uint32_t gy;
        std::uint32_t gx = groupsFor(invocations, gpu::kTraceWorkgroup, &gy);
        tracer->dispatch(cb, gx, gy, &tp, sizeof tp);
        vk::computeBarrier(cb);
        gpu::AccumulatePush ap{0, static_cast<std::uint32_t>(pixels), static_cast<std::uint32_t>(items.size()), history.valid() ? 1u : 0u};
        gx = groupsFor(pixels, gpu::kAccumulateWorkgroup, &gy);
        if (options.accumulate) accumulate->dispatch(cb, gx, gy, &ap, sizeof ap);
      }
      if (compose) denoiser.record(cb, options.denoise);
      if (copyImage) {
        // The accumulated image, copied while the device is at it: the CPU converts it later,
        // while the device traces the next frame.
        vk::computeBarrier(cb);
        VkBufferCopy c{0, 0, imageBytes};
        vkCmdCopyBuffer(cb, accum.handle(), slot.image.handle(), 1, &c);
        VkBufferCopy a{0, imageBytes, auxBytes};
        vkCmdCopyBuffer(cb, accumAux.handle(), slot.image.handle(), 1, &a);
        if (slot.hasDisplay) {
          VkBufferCopy d{0, imageBytes + auxBytes, displayBytes};
          vkCmdCopyBuffer(cb, denoiser.display().handle(), slot.image.handle(), 1, &d);
        }
        if (slot.hasHistory) {
          VkBufferCopy h{0, imageBytes + auxBytes + displayBytes, historyBytes};
          vkCmdCopyBuffer(cb, history.handle(), slot.image.handle(), 1, &h);
        }
      }
    });
    inFlight = ticket;
    return ticket;
  }

  // Waits for the frame in flight and takes its statistics.
  void completeInFlight() {
    if (!inFlight) return;
    Slot& slot = slots_[inFlight % 2];
    inFlight = 0;
    ctx.wait();
    FrameStats& fs = slot.stats;
    fs.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - slot.submitted).count();
    slot.completed = true;
    fs.denoisePasses = denoiser.passTimes();
    if (fs.samples == 0) return;
    std::uint32_t counts[gpu::kStatsCount];
    stats.download(counts, sizeof counts);
    fs.primaryRays = counts[0];
    fs.bounceRays = counts[1];
    fs.shadowRays = counts[2];
    fs.maxLoopIterations = counts[3];
    fs.cutPaths = counts[4];
    fs.maxSegmentIterations = counts[6];
    for (std::size_t i = 0; i < fs.pathEnds.size(); ++i) fs.pathEnds[i] = counts[gpu::kStatsPathEnds + i];
    fs.loopIterations = static_cast<std::uint64_t>(counts[5]) * gpu::kLoopIterationUnit;
    fs.pathsPerInvocation = static_cast<double>(fs.samples) / static_cast<double>(std::max<std::uint64_t>(slot.invocations, 1));
    iterationsPerPath = static_cast<double>(fs.loopIterations) / static_cast<double>(fs.samples);
  }

  Slot& completedSlot(std::uint64_t ticket) {
    Slot& slot = slots_[ticket % 2];
    RETILE_ASSERT(slot.ticket == ticket, cat("frame ", ticket, " was overwritten by frame ", slot.ticket));
    if (ticket == inFlight) completeInFlight();
    return slot;
  }

  RenderImage frameImage(std::uint64_t ticket) {
    Slot& slot = completedSlot(ticket);
    RETILE_ASSERT(slot.hasImage, cat("frame ", ticket, " was submitted without its image"));
    auto n = static_cast<std::size_t>(slot.width) * static_cast<std::size_t>(slot.height);
    // Read through the mapping: the slot is not touched by the frame now in flight.
    const auto* acc = static_cast<const gpu::vec4*>(slot.image.mapped());
    RenderImage img =
        convert(acc, acc + n * 2, slot.hasDisplay ? acc + n * (2 + gpu::kAuxVec4s) : nullptr, slot.width, slot.height, slot.objects);
    if (slot.hasHistory) img.history = convertHistory(acc + n * (3 + gpu::kAuxVec4s), n);
    return img;
  }

  RenderImage readback() {
    completeInFlight();  // the frame in flight uses what this touches
    auto n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    std::vector<gpu::vec4> acc(n * 2), ax(n * gpu::kAuxVec4s);
    accum.download(acc.data(), acc.size() * sizeof(gpu::vec4));
    accumAux.download(ax.data(), ax.size() * sizeof(gpu::vec4));
    std::vector<gpu::vec4> shown;
    if (displayCurrent) {
      shown.resize(n);
      denoiser.display().download(shown.data(), n * sizeof(gpu::vec4));
    }
    RenderImage img = convert(acc.data(), ax.data(), displayCurrent ? shown.data() : nullptr, width, height, builder.data().instanceObject);
    if (history.valid()) {
      std::vector<gpu::vec4> h(n * 2);
      history.download(h.data(), h.size() * sizeof(gpu::vec4));
      img.history = convertHistory(h.data(), n);
    }
    return img;
  }

  // Per pixel [sum.rgb count, compensation.rgb squares] to count, mean RGB, mean square.
  static std::vector<float> convertHistory(const gpu::vec4* h, std::size_t n) {
    constexpr std::size_t k = RenderImage::kHistoryFloats;
    std::vector<float> out(n * k);
    for (std::size_t i = 0; i < n; ++i) {
      const gpu::vec4& s = h[i * 2];
      const gpu::vec4& c = h[i * 2 + 1];
      const double inv = s.w > 0 ? 1.0 / s.w : 0.0;
      out[i * k] = s.w;
      for (int ch = 0; ch < 3; ++ch)
        out[i * k + 1 + static_cast<std::size_t>(ch)] = static_cast<float>((double((&s.x)[ch]) - (&c.x)[ch]) * inv);
      out[i * k + 4] = static_cast<float>(c.w * inv);
    }
    return out;
  }

  // Per pixel: accumulation [sum.rgb count, compensation.rgb squares] and auxiliary [albedo.rgb
  // depth, normal.xyz instance, emission.rgb -] to means.
  // `shown`: the composed display per pixel, or null.
  static RenderImage convert(const gpu::vec4* acc, const gpu::vec4* ax, const gpu::vec4* shown, int w, int h,
                             const std::vector<NodeId>& objects) {
    RenderImage img;
    img.width = w;
    img.height = h;
    auto n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    img.color.resize(n * 3);
    img.albedo.resize(n * 3);
    img.normal.resize(n * 3);
    img.depth.resize(n);
    img.objectId.resize(n);
    img.sampleCount.resize(n);
    img.moment2.resize(n);
    if (shown) img.display.resize(n * 3);
    for (std::size_t i = 0; i < n; ++i) {
      const gpu::vec4& s = acc[i * 2];
      const gpu::vec4& comp = acc[i * 2 + 1];
      float count = s.w;
      double invD = count > 0 ? 1.0 / count : 0.0;
      float inv = static_cast<float>(invD);
      // The compensation holds what the last additions lost: take it back out.
      img.color[i * 3 + 0] = static_cast<float>((double(s.x) - comp.x) * invD);
      img.color[i * 3 + 1] = static_cast<float>((double(s.y) - comp.y) * invD);
      img.color[i * 3 + 2] = static_cast<float>((double(s.z) - comp.z) * invD);
      img.sampleCount[i] = count;
      img.moment2[i] = comp.w * inv;
      if (shown)
        for (int c = 0; c < 3; ++c) img.display[i * 3 + static_cast<std::size_t>(c)] = (&shown[i].x)[c];
      const gpu::vec4& a = ax[i * gpu::kAuxVec4s];
      const gpu::vec4& b = ax[i * gpu::kAuxVec4s + 1];
      img.albedo[i * 3 + 0] = a.x * inv;
      img.albedo[i * 3 + 1] = a.y * inv;
      img.albedo[i * 3 + 2] = a.z * inv;
      Vec3 nrm = normalize(Vec3{b.x, b.y, b.z});
      img.normal[i * 3 + 0] = nrm.x;
      img.normal[i * 3 + 1] = nrm.y;
      img.normal[i * 3 + 2] = nrm.z;
      img.depth[i] = a.w >= 1e29f ? std::numeric_limits<float>::infinity() : a.w;
      std::int32_t inst;
      std::memcpy(&inst, &b.w, sizeof inst);
      img.objectId[i] =
          (inst > 0 && static_cast<std::size_t>(inst) <= objects.size()) ? objects[static_cast<std::size_t>(inst - 1)] : kNoNode;
    }
    return img;
  }
};

Renderer::Renderer(const RendererOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Renderer::~Renderer() = default;

std::string Renderer::deviceName() const { return impl_->ctx.deviceName(); }
bool Renderer::cpuDevice() const { return impl_->ctx.isCpuDevice(); }
std::uint32_t Renderer::subgroupSize() const { return impl_->ctx.subgroupSize(); }

std::vector<std::string> Renderer::setScene(const Scene& scene) {
  impl_->builder = RenderSceneBuilder{};
  impl_->builder.setDirectReferences(impl_->directReferences);
  return updateScene(scene, kUpdateAll);
}

std::vector<std::string> Renderer::updateScene(const Scene& scene, std::uint32_t flags) {
  std::vector<std::string> warnings;
  std::uint32_t dirty = impl_->builder.update(scene, flags, &warnings);
  // Building BVHs frees as much as the meshes' packed data; handing it back before the upload
  // allocates the device copy keeps it out of the peak (`retile bench room --triangles 1M`:
  // 667 -> 626 MB).
  if (dirty & kDirtyGeometry) releaseFreedMemory();
  impl_->upload(dirty);
  if (dirty & kDirtyGeometry) releaseFreedMemory();
  impl_->camera = scene.camera;
  impl_->mediaKnown = false;
  impl_->sceneSettings = scene.settings;
  if (!impl_->hasScene || (flags & kUpdateSettings)) impl_->setMaxBounces(scene.settings.maxBounces);
  impl_->hasScene = true;
  return warnings;
}

void Renderer::resize(int width, int height) { impl_->resize(width, height); }
void Renderer::setMaxBounces(int maxBounces) { impl_->setMaxBounces(std::max(0, maxBounces)); }
void Renderer::setSeed(std::uint32_t seed) { impl_->seed = seed; }
FrameStats Renderer::renderFrame(const std::vector<TileWork>& tiles, const FrameOptions& options) {
  return completeFrame(submitFrame(tiles, options, false));
}
FrameTicket Renderer::submitFrame(const std::vector<TileWork>& tiles, const FrameOptions& options, bool copyImage) {
  return FrameTicket{impl_->submitFrame(tiles, options, copyImage)};
}
FrameStats Renderer::completeFrame(FrameTicket frame) { return impl_->completedSlot(frame.id).stats; }
RenderImage Renderer::frameImage(FrameTicket frame) { return impl_->frameImage(frame.id); }
std::vector<float> Renderer::readbackFrameLuminance() { return impl_->readbackFrameLuminance(); }
void Renderer::setSelection(NodeId object, std::vector<NodeId> group) {
  impl_->selectedObject = object;
  impl_->countedGroup = std::move(group);
}
SelectionCounts Renderer::takeSelectionCounts() { return impl_->takeSelectionCounts(); }
RenderImage Renderer::readback() { return impl_->readback(); }
std::uint64_t Renderer::sceneDeviceBytes() const { return impl_->builder.data().deviceBytes(); }
Renderer::SceneMemory Renderer::sceneMemory() const {
  const RenderSceneData& d = impl_->builder.data();
  auto bytes = [](const auto& x) { return static_cast<std::uint64_t>(x.size() * sizeof(x[0])); };
  SceneMemory m;
  // The traversal buffer holds every unique triangle first, then the meshes' BVH nodes.
  m.triangles = std::min(bytes(d.meshTraversal), d.triangleCount * gpu::kTriTexels * sizeof(gpu::vec4));
  m.bvh = bytes(d.meshTraversal) - m.triangles + bytes(d.topTraversal);
  m.shading = bytes(d.triangleShading);
  m.textures = bytes(d.textureInfo) + bytes(d.texels);
  m.other = d.deviceBytes() - m.triangles - m.bvh - m.shading - m.textures;
  return m;
}

std::uint64_t Renderer::sceneTriangles() const { return impl_->builder.data().triangleCount; }
std::uint64_t Renderer::sceneInstances() const { return impl_->builder.data().instanceObject.size(); }
std::uint64_t Renderer::sceneInstanceReferences() const { return impl_->builder.data().instanceReferences; }

void FrameStats::add(const FrameStats& later) {
  samples += later.samples;
  primaryRays += later.primaryRays;
  bounceRays += later.bounceRays;
  shadowRays += later.shadowRays;
  seconds += later.seconds;
  maxLoopIterations = std::max(maxLoopIterations, later.maxLoopIterations);
  cutPaths += later.cutPaths;
  loopIterations += later.loopIterations;
  maxSegmentIterations = std::max(maxSegmentIterations, later.maxSegmentIterations);
  pathsPerInvocation = later.pathsPerInvocation;
  for (std::size_t i = 0; i < pathEnds.size(); ++i) pathEnds[i] += later.pathEnds[i];
}

void Renderer::prepareMoves() {
  if (!impl_->hasScene) return;
  const RenderSceneData& d = impl_->builder.data();
  // A move gives an instance a transform, and then no reference is packed direct. An object
  // duplicated in place shares its mesh with the original: no transform, but not direct either.
  const auto direct = static_cast<std::uint32_t>(gpu::kFeatureDirectReferences);
  impl_->traceVariant(d.alphaTested(), d.materialTypes,
                      (d.features() | static_cast<std::uint32_t>(gpu::kFeatureInstanceTransforms)) & ~direct);
  if (d.features() & direct) impl_->traceVariant(d.alphaTested(), d.materialTypes, d.features() & ~direct);
}

std::size_t Renderer::kernelsCompiled() const { return impl_->traceVariants.size(); }

std::vector<std::string> Renderer::kernelFeatures() const {
  const RenderSceneData& d = impl_->builder.data();
  std::vector<std::string> out;
  for (int t = 0; t < kMaterialTypeCount; ++t)
    if (d.materialTypes & (1u << t)) out.push_back(materialTypeName(static_cast<MaterialType>(t)));
  if (d.materialTypes & (1u << gpu::kMaskBeckmann)) out.push_back("beckmann");
  if (d.materialTypes & (1u << gpu::kMaskCoat)) out.push_back("coat");
  if (d.materialTypes & (1u << gpu::kMaskMedium)) out.push_back("medium");
  if (d.materialTypes & (1u << gpu::kMaskScattering)) out.push_back("scattering medium");
  if (d.cutOuts) out.push_back("alpha test");
  if (d.sheetShadows) out.push_back("shadow rays through thin sheets");
  const std::uint32_t f = d.features();
  struct Named {
    std::uint32_t bit;
    const char* label;
  };
  static constexpr Named kNames[] = {
#define RETILE_KERNEL_FEATURE(name, bit, label) {1u << bit, label},
#include "shared/kernel_features.h"
#undef RETILE_KERNEL_FEATURE
  };
  for (const Named& n : kNames)
    if (f & n.bit) out.push_back(n.label);
  return out;
}
double Renderer::lastBlasSeconds() const { return impl_->builder.lastTiming().blas; }
double Renderer::lastTlasSeconds() const { return impl_->builder.lastTiming().tlas; }

RenderImage Renderer::render(const RenderRequest& request, const std::function<bool(int, int)>& progress, FrameStats* total) {
  const RenderSettings& s = impl_->sceneSettings;
  int w = request.width > 0 ? request.width : s.width;
  int h = request.height > 0 ? request.height : s.height;
  int spp = request.samplesPerPixel > 0 ? request.samplesPerPixel : s.samplesPerPixel;
  impl_->setMaxBounces(request.maxBounces >= 0 ? request.maxBounces : s.maxBounces);
  impl_->seed = request.seed;
  resize(w, h);
  FrameStats sum;
  const int perFrame = offlineSamplesPerFrame(w, h);
  for (int done = 0; done < spp;) {
    TileWork all;
    all.width = w;
    all.height = h;
    all.quality = std::min(perFrame, spp - done);
    all.sampleBase = static_cast<std::uint32_t>(done);
    all.restart = done == 0;
    FrameOptions o;
    o.pathsPerInvocation = request.pathsPerInvocation;
    sum.add(renderFrame({all}, o));
    done += all.quality;
    if (progress && !progress(done, spp)) break;
  }
  if (request.denoise) {
    FrameOptions o;
    o.denoise = wholeFrameDenoise(w, h);
    renderFrame({}, o);
  }
  if (total) *total = sum;
  return readback();
}

int offlineSamplesPerFrame(int width, int height) {
  constexpr std::int64_t kFrameSamples = 1 << 18, kMaxPerPixel = 64;
  const std::int64_t pixels = std::max<std::int64_t>(std::int64_t{width} * height, 1);
  return static_cast<int>(std::clamp<std::int64_t>(kFrameSamples / pixels, 1, kMaxPerPixel));
}

DenoiseWork wholeFrameDenoise(int width, int height, int tileSize) {
  DenoiseWork d;
  d.compose = d.filter = true;
  d.width = width;
  d.height = height;
  d.tileSize = tileSize;
  auto tiles = static_cast<std::size_t>((width + tileSize - 1) / tileSize) * static_cast<std::size_t>((height + tileSize - 1) / tileSize);
  d.tileCodes.assign(tiles, kShowLayer | kShowWriteLayer | kShowFiltered);
  return d;
}

}  // namespace retile
