#include "retile/session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <map>

#include "retile/log.h"
#include "schedule/denoise_regions.h"
#include "schedule/planner.h"
#include "schedule/policies.h"
#include "schedule/reuse.h"
#include "schedule/reuse_tracker.h"
#include "schedule/scheduler.h"

namespace retile {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

struct CameraFrame {
  Vec3 forward, right, up;
  float tanHalf, aspect;
};

CameraFrame cameraFrame(const Camera& c, int width, int height) {
  CameraFrame f;
  f.forward = normalize(c.target - c.position);
  f.right = normalize(cross(f.forward, c.up));
  if (!(length(f.right) > 0)) f.right = normalize(cross(f.forward, std::abs(f.forward.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 0, 1}));
  f.up = cross(f.right, f.forward);
  f.tanHalf = std::tan(0.5f * c.verticalFov);
  f.aspect = static_cast<float>(width) / static_cast<float>(std::max(height, 1));
  return f;
}

}  // namespace

// Inverse of the trace kernel's camera ray: pixel = ((ndc + 1) / 2) * size, ndc.y pointing down.
std::optional<Vec2> projectToImage(const Camera& camera, int width, int height, Vec3 p) {
  CameraFrame f = cameraFrame(camera, width, height);
  Vec3 d = p - camera.position;
  float z = dot(d, f.forward);
  if (!(z > 1e-6f)) return std::nullopt;
  float nx = dot(d, f.right) / (z * f.tanHalf * f.aspect);
  float ny = -dot(d, f.up) / (z * f.tanHalf);
  return Vec2{(nx + 1.0f) * 0.5f * static_cast<float>(width), (ny + 1.0f) * 0.5f * static_cast<float>(height)};
}

struct RenderSession::Impl {
  Renderer renderer;
  TileScheduler scheduler;
  Planner planner;
  int width = 0, height = 0;
  std::uint64_t frame = 0;
  std::uint64_t documentVersion = 0;
  std::map<NodeId, Bounds3> meshBounds;  // object-space bounds, so an edit never walks a mesh
  std::vector<EditFacts> batch;          // edits applied since the last frame, planned together
  DenoiseRegions denoise;
  bool newPass = false;               // a plan started a pass (or a global update) since the last frame
  std::vector<char> leading;          // per tile: ranked first by the pass's policy
  NodeId counting = kNoNode;          // the object the renderer's counters describe
  NodeId countingMaterial = kNoNode;  // its material when counting began: the group's
  // Frames submitted and not yet finished, oldest first (at most two: one read back while the
  // next traces). Their records are filled at submission and completed when they finish.
  struct Pending {
    FrameTicket ticket;
    FrameRecord rec;
    AccumMode mode = AccumMode::Refinement;
    bool counting = false;
    bool readImage = false;
    bool completed = false;  // the device is done and counters and probe are taken
    FrameStats stats;
    Clock::time_point start;
    std::size_t kernels = 0;  // trace kernels compiled before it was submitted
  };
  std::deque<Pending> pending;
  std::shared_ptr<const RenderImage> lastImage;
  std::uint64_t lastImageFrame = 0;  // the frame lastImage shows the accumulation after
  RegionRect region;                 // the render region in pixels (empty: the whole image)
  ReuseTracker reuse;                // verified reuse's per-tile state, on the scheduler's grid
  int previewBlock = 1;              // setPreview
  bool previewed = false;            // the last frame was a preview: the next full one plans the edit again
  Clock::time_point lastEdit{};

  // The block size of the next frame: the preview's while edits come (or came a moment ago) and
  // it has something to show; else 1, and the first full frame after a preview plans the last
  // edit again (a probe pending is the change policy's next step instead).
  int frameBlock(bool edited, bool reusing) {
    if (previewBlock <= 1 || reusing) return 1;
    if (edited) lastEdit = Clock::now();
    if ((edited || msSince(lastEdit) < kPreviewLingerMs) && !scheduler.previewDone()) {
      previewed = true;
      return previewBlock;
    }
    if (previewed && scheduler.mode() != AccumMode::Probe) {
      execute(planner.lastEditPlan());
      // Its preview is shown: armed again, it would restart coarse on the next frame the tiles
      // this one renders sharp.
      scheduler.setPreviewTiles({});
    }
    previewed = false;
    return 1;
  }

  // The tracker turns the plan's restarts into history starts (a global update drops every
  // history) and applies the last read-back's rejections; the scheduler counts the kept samples.
  // `before`: the scheduler's samples per tile before this frame's plan (a restart resets them).
  void planReuse(FramePlan& plan, FrameOptions& options, std::uint64_t frameNumber, const std::vector<double>& before) {
    for (const ReuseOp& op : reuse.planFrame(plan, before, frameNumber))
      options.reuse.push_back({op.rect.x, op.rect.y, op.rect.width, op.rect.height,
                               op.kind == ReuseOp::Start ? FrameOptions::Reuse::Start : FrameOptions::Reuse::Reject});
    scheduler.setCredit(reuse.credit());
  }

  // Tests every tile that reuses its history against the fresh samples the image holds: the
  // image keeps the history beside the accumulation, so the fresh sums are the difference.
  void testReuse(const RenderImage& img, std::uint64_t imageFrame, double falseRejectRate) {
    if (img.history.empty() || img.width != width || img.height != height) return;
    reuse.test(imageFrame, falseRejectRate, [&](const TileRect& r, std::vector<LuminanceSums>& fresh, std::vector<LuminanceSums>& hist) {
      for (int y = 0; y < r.height; ++y)
        for (int x = 0; x < r.width; ++x) {
          const std::size_t p = static_cast<std::size_t>(r.y + y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(r.x + x);
          const std::size_t k = static_cast<std::size_t>(y * r.width + x);
          constexpr std::size_t kh = RenderImage::kHistoryFloats;
          const float* hp = &img.history[p * kh];
          const float* c = &img.color[p * 3];
          const double n = img.sampleCount[p], m = hp[0];
          LuminanceSums& H = hist[k];
          LuminanceSums& F = fresh[k];
          H.count = m;
          H.sum = (0.2126 * hp[1] + 0.7152 * hp[2] + 0.0722 * hp[3]) * m;
          H.squares = hp[4] * m;
          F.count = n - m;
          F.sum = (0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]) * n - H.sum;
          F.squares = img.moment2[p] * n - H.squares;
          for (int ch = 0; ch < 3; ++ch) {
            H.rgb[ch] = hp[1 + ch] * m;
            F.rgb[ch] = c[ch] * n - H.rgb[ch];
          }
        }
    });
  }

  explicit Impl(const RendererOptions& o) : renderer(o) {}

  // Marks the tiles the region touches (the scheduler forgets it on a new grid).
  void applyRegion() {
    const TileGrid& g = scheduler.grid();
    std::vector<char> mask;
    if (!region.empty()) {
      mask.assign(static_cast<std::size_t>(g.count()), 0);
      for (int t = 0; t < g.count(); ++t) {
        TileRect r = g.rect(t);
        mask[static_cast<std::size_t>(t)] = region.overlaps(r.x, r.y, r.width, r.height);
      }
    }
    scheduler.setRegion(std::move(mask));
  }

  void newGrid(int tileSize) {
    TileGrid grid(width, height, tileSize);
    scheduler.reset(grid);
    planner.setGrid(grid);
    denoise.reset(grid);
    batch.clear();  // measured on the old grid; the reset restarts everything anyway
    reuse.reset(grid);
  }

  void execute(const Plan& p) {
    switch (p.kind) {
      case PlanKind::None: break;
      case PlanKind::GlobalUpdate: scheduler.globalUpdate(); break;
      case PlanKind::Probe: scheduler.probe(); break;
      case PlanKind::Pass:
        scheduler.startPass(p.order, p.quality, p.prioritized, p.smooth, p.staleCap);
        scheduler.setPreviewTiles(p.preview);
        reuse.startPass();
        leading.assign(static_cast<std::size_t>(scheduler.grid().count()), 0);
        for (int i = 0; i < p.leading && i < static_cast<int>(p.order.size()); ++i)
          leading[static_cast<std::size_t>(p.order[static_cast<std::size_t>(i)])] = 1;
        newPass = true;
        break;
    }
  }

  // What the denoiser does this frame, and how the displayed image is composed.
  DenoiseWork denoiseWork(AccumMode mode, std::uint64_t frameNumber, const MethodSettings& m) {
    const TileGrid& grid = scheduler.grid();
    DenoiseFrame f;
    if (mode == AccumMode::GlobalUpdate || mode == AccumMode::Refinement) {
      f = denoise.wholeFrame(frameNumber);
    } else if (mode == AccumMode::Incremental) {
      if (newPass) denoise.restart();
      // The region grows over the tiles the policy ranked first (indirection: the prioritized
      // classes), or over every re-rendered tile when it ranked none above its order.
      bool indirection = m.kind == MethodKind::Indirection || m.kind == MethodKind::IndirectionFocus;
      bool anyLeading = std::find(leading.begin(), leading.end(), 1) != leading.end();
      std::vector<char> grows = indirection && anyLeading ? leading : std::vector<char>(static_cast<std::size_t>(grid.count()), 1);
      f = denoise.incremental(scheduler.startedTiles(), grows, m.denoiseThreshold, scheduler.queueServed() + 1 >= scheduler.queueLength(),
                              frameNumber);
    } else {
      f = denoise.unchanged();
    }
    newPass = false;
    DenoiseWork w;
    w.compose = true;
    w.filter = f.filter;
    w.x = f.domain.x;
    w.y = f.domain.y;
    w.width = f.domain.width;
    w.height = f.domain.height;
    w.tileSize = grid.tileSize();
    w.featherPixels = m.softBorders ? MethodSettings::kFeatherPixels : 0;
    w.tileCodes.resize(f.source.size());
    for (std::size_t t = 0; t < f.source.size(); ++t) {
      std::uint32_t code = kShowStale;
      switch (f.source[t]) {
        case TileSource::Stale: code = kShowStale; break;
        case TileSource::Previous: code = kShowPreviousLayer; break;
        case TileSource::Fresh: code = kShowFresh; break;
        case TileSource::Region: code = kShowLayer + static_cast<std::uint32_t>(f.region[t]); break;
      }
      if (f.write[t]) code |= kShowWriteLayer;
      if (f.filtered[t]) code |= kShowFiltered;
      w.tileCodes[t] = code;
    }
    lastRegions = std::move(f.regions);
    return w;
  }
  std::vector<DenoiseRegion> lastRegions;  // the stack as of the last planned frame

  // The renderer counts what the planner wants counted, and beside it the objects that share its
  // material (what a material edit changes); a new target starts from zero.
  void syncCounting(const Scene& scene) {
    if (planner.countTarget() == counting) return;
    counting = planner.countTarget();
    const Object* o = scene.object(counting);
    countingMaterial = o ? o->material : kNoNode;
    std::vector<NodeId> group;
    if (countingMaterial != kNoNode)
      for (const Object& x : scene.objects)
        if (x.material == countingMaterial) group.push_back(x.id);
    renderer.setSelection(counting, std::move(group));
    renderer.takeSelectionCounts();
  }
};

RenderSession::RenderSession(Scene scene, MethodSettings method, const RendererOptions& options)
    : impl_(std::make_unique<Impl>(options)), scene_(std::move(scene)) {
  if (std::string bad = validateMethodSettings(method); !bad.empty()) {
    logWarning("method settings: ", bad, "; using the defaults");
    method = MethodSettings{};
  }
  impl_->planner.setMethod(method);
  for (const Mesh& m : scene_.meshes)
    if (m.geometry) impl_->meshBounds[m.id] = m.geometry->bounds();
  sceneWarnings_ = impl_->renderer.setScene(scene_);
  impl_->renderer.setMaxBounces(scene_.settings.maxBounces);
  impl_->renderer.setSeed(scene_.settings.seed);
  resize(scene_.settings.width, scene_.settings.height);
}

RenderSession::~RenderSession() = default;

std::string RenderSession::deviceName() const { return impl_->renderer.deviceName(); }
const MethodSettings& RenderSession::method() const { return impl_->planner.method(); }

void RenderSession::resize(int width, int height) {
  completeGpu();  // the frame in flight's counters and probe belong to the state it was planned in
  width = std::clamp(width, 1, kMaxImageSide);
  height = std::clamp(height, 1, kMaxImageSide);
  impl_->width = width;
  impl_->height = height;
  scene_.settings.width = width;
  scene_.settings.height = height;
  impl_->renderer.resize(width, height);
  impl_->newGrid(method().tileSize);
  impl_->lastImage.reset();
  impl_->region = {};  // its pixels meant another image size
}

void RenderSession::setRegion(RegionRect region) {
  completeGpu();  // the frame in flight's counters and probe belong to the state it was planned in
  // Clamped to the image; nothing left means no region.
  int x0 = std::clamp(region.x, 0, impl_->width), y0 = std::clamp(region.y, 0, impl_->height);
  int x1 = std::clamp(region.x + std::max(0, region.width), 0, impl_->width);
  int y1 = std::clamp(region.y + std::max(0, region.height), 0, impl_->height);
  impl_->region = RegionRect{x0, y0, x1 - x0, y1 - y0};
  if (impl_->region.empty()) impl_->region = {};
  impl_->applyRegion();
}

void RenderSession::setMaxBounces(int maxBounces) {
  completeGpu();  // the frame in flight's counters and probe belong to the state it was planned in
  scene_.settings.maxBounces = std::clamp(maxBounces, 0, 1024);
  impl_->renderer.setMaxBounces(scene_.settings.maxBounces);
  impl_->scheduler.globalUpdate();
}

std::string RenderSession::setMethod(const MethodSettings& method) {
  completeGpu();  // the frame in flight's counters and probe belong to the state it was planned in
  if (std::string bad = validateMethodSettings(method); !bad.empty()) return bad;
  // No setting of the method changes what a sample is: the accumulation stays, and the next edit
  // is planned the new way. A pass under way goes on, but for a new T, whose tiles take over the
  // samples their pixels hold (TileScheduler::regrid).
  const bool newGrid = method.tileSize != this->method().tileSize;
  impl_->planner.setMethod(method);
  if (newGrid) {
    const TileGrid grid(impl_->width, impl_->height, method.tileSize);
    impl_->scheduler.regrid(grid);
    impl_->planner.setGrid(grid);
    impl_->denoise.reset(grid);
    impl_->batch.clear();
    impl_->reuse.reset(grid);
    impl_->applyRegion();
  }
  return {};
}

void RenderSession::select(NodeId object) {
  completeGpu();  // the frame in flight's counters and probe belong to the state it was planned in
  if (object != kNoNode && !scene_.object(object)) object = kNoNode;
  selection_ = object;
  impl_->planner.select(object);
}

void RenderSession::setFocus(std::vector<FocusPoint> focus) {
  completeGpu();
  impl_->planner.setFocus(std::move(focus));
}

namespace {

// World bounds of an object, from cached mesh bounds (empty when hidden or missing).
Bounds3 objectBounds(const Scene& s, const std::map<NodeId, Bounds3>& meshBounds, NodeId id) {
  const Object* o = s.object(id);
  if (!o || !o->visible) return {};
  auto it = meshBounds.find(o->mesh);
  if (it == meshBounds.end() || it->second.empty()) return {};
  return transformBounds(o->transform, it->second);
}

// The image rectangle a world box covers; the whole image when any corner is behind the camera.
TileRect screenRect(const Camera& cam, int w, int h, const Bounds3& b) {
  if (b.empty()) return {};
  float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
  for (int i = 0; i < 8; ++i) {
    Vec3 p{(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z};
    auto q = projectToImage(cam, w, h, p);
    if (!q) return {0, 0, w, h};
    x0 = std::min(x0, q->x);
    y0 = std::min(y0, q->y);
    x1 = std::max(x1, q->x);
    y1 = std::max(y1, q->y);
  }
  int ix0 = std::clamp(static_cast<int>(std::floor(x0)), 0, w), iy0 = std::clamp(static_cast<int>(std::floor(y0)), 0, h);
  int ix1 = std::clamp(static_cast<int>(std::ceil(x1)), 0, w), iy1 = std::clamp(static_cast<int>(std::ceil(y1)), 0, h);
  return {ix0, iy0, ix1 - ix0, iy1 - iy0};
}

std::optional<Vec2> projectedCentre(const Camera& cam, int w, int h, const Bounds3& b) {
  if (b.empty()) return std::nullopt;
  return projectToImage(cam, w, h, b.center());
}

}  // namespace

void RenderSession::setDocumentVersion(std::uint64_t version) { impl_->documentVersion = version; }

void RenderSession::setPreview(int block) {
  completeGpu();
  impl_->previewBlock = std::clamp(block, 1, 16);
}

Result<std::uint32_t> RenderSession::applyEdit(const Edit& edit, std::uint64_t documentVersion) {
  completeGpu();  // the frame in flight's counters and probe belong to the state it was planned in
  Impl& d = *impl_;
  // Where the edit's targets were, before: a pass prioritizes their old and new places.
  std::vector<NodeId> targets;
  NodeId target = editTarget(edit);
  if (const auto* m = std::get_if<SetMaterial>(&edit)) {
    for (const Object& o : scene_.objects)
      if (o.material == m->material.id) targets.push_back(o.id);
  } else if (target != kNoNode && scene_.object(target)) {
    targets.push_back(target);
  }
  Bounds3 before;
  for (NodeId t : targets) before.grow(objectBounds(scene_, d.meshBounds, t));

  const RenderSettings settingsBefore = scene_.settings;
  // An edit no pixel shows (a name, a node nothing visible uses) is applied and uploaded, but the
  // samples stay: nothing restarts.
  const bool visible = changesImage(scene_, edit);
  auto applied = retile::applyEdit(scene_, edit);
  if (!applied) return applied;
  // Settings the session renders as it did: the editor sends them when only what an offline
  // render stops at (the scene's own resolution, which it replaces by the viewport's, and its
  // samples per pixel) or the display-only view changed. Kept, but nothing to restart.
  if (std::holds_alternative<SetRenderSettings>(edit)) {
    RenderSettings same = settingsBefore;
    same.samplesPerPixel = scene_.settings.samplesPerPixel;
    same.view = scene_.settings.view;
    if (same == scene_.settings) {
      d.documentVersion = std::max(d.documentVersion, documentVersion);
      return 0u;
    }
  }
  std::uint32_t flags = applied.value();
  if (const auto* add = std::get_if<AddMesh>(&edit); add && add->mesh.geometry) d.meshBounds[add->mesh.id] = add->mesh.geometry->bounds();
  if (const auto* add = std::get_if<AddObject>(&edit)) targets.push_back(add->object.id);
  for (auto& w : d.renderer.updateScene(scene_, flags)) sceneWarnings_.push_back(std::move(w));
  // Coalesced commands may arrive out of version order: the record shows the newest applied.
  d.documentVersion = std::max(d.documentVersion, documentVersion);
  if (selection_ != kNoNode && !scene_.object(selection_)) select(kNoNode);
  if (d.planner.countTarget() != kNoNode && !scene_.object(d.planner.countTarget())) d.planner.select(selection_);
  if (!visible) return flags;

  EditFacts facts;
  if (flags & kUpdateSettings) {
    d.renderer.setMaxBounces(scene_.settings.maxBounces);
    d.renderer.setSeed(scene_.settings.seed);
    if (scene_.settings.width != d.width || scene_.settings.height != d.height) {
      resize(scene_.settings.width, scene_.settings.height);
      return flags;
    }
  }
  // Camera moves and settings discard everything (the global-update mode).
  facts.global = (flags & (kUpdateCamera | kUpdateSettings)) != 0;
  const Camera& cam = scene_.camera;
  const auto* material = std::get_if<SetMaterial>(&edit);
  if (material) facts.material = material->material.id;
  if (material && targets.size() > 1 && !facts.global) {
    // A material shared by several objects changes each where it is seen: a point of change and a
    // rectangle per object on screen, planned as a batch of edits is (the box around them all
    // would put the spiral's head between them, and every tile in the box first).
    const std::size_t planned = d.batch.size();
    for (NodeId t : targets) {
      const Bounds3 b = objectBounds(scene_, d.meshBounds, t);
      const TileRect r = screenRect(cam, d.width, d.height, b);
      if (r.pixels() <= 0) continue;
      EditFacts each = facts;
      each.pointOfChange = projectedCentre(cam, d.width, d.height, b).value_or(Vec2{r.x + r.width * 0.5f, r.y + r.height * 0.5f});
      each.screen = {r};
      d.batch.push_back(std::move(each));
    }
    if (d.batch.size() > planned) return flags;
  }

  // The point of change: the centre of the edited objects' bounds, a light's position, or
  // (environment, textures) the image centre.
  Bounds3 after;
  for (NodeId t : targets) after.grow(objectBounds(scene_, d.meshBounds, t));
  std::optional<Vec2> poc = projectedCentre(cam, d.width, d.height, after);
  if (!poc) poc = projectedCentre(cam, d.width, d.height, before);
  if (!poc)
    if (const auto* l = std::get_if<SetLight>(&edit); l && l->light.type != LightType::Directional)
      poc = projectToImage(cam, d.width, d.height, l->light.position);
  facts.pointOfChange = poc.value_or(Vec2{d.width * 0.5f, d.height * 0.5f});
  for (const Bounds3& b : {before, after})
    if (TileRect r = screenRect(cam, d.width, d.height, b); r.pixels() > 0) facts.screen.push_back(r);
  if (targets.size() == 1) {
    facts.object = targets.front();
    facts.moved = std::holds_alternative<SetObject>(edit);
    facts.centreBefore = projectedCentre(cam, d.width, d.height, before);
    facts.centreAfter = projectedCentre(cam, d.width, d.height, after);
  }
  d.batch.push_back(std::move(facts));
  return flags;
}

void RenderSession::completeGpu() {
  Impl& d = *impl_;
  if (d.pending.empty() || d.pending.back().completed) return;
  Impl::Pending& p = d.pending.back();
  p.stats = d.renderer.completeFrame(p.ticket);
  p.completed = true;
  const TileGrid& grid = d.scheduler.grid();

  if (p.counting && d.planner.frameCounted()) {
    SelectionCounts c = d.renderer.takeSelectionCounts();
    if (c.tileSize == grid.tileSize()) {
      // The object's own centre now is where its later motion is measured from.
      std::optional<Vec2> centre = projectedCentre(scene_.camera, d.width, d.height, objectBounds(scene_, d.meshBounds, d.counting));
      auto counts = [](const SelectionCounts::Set& s) { return IndirectionCounts{s.direct, s.reflection, s.shadow}; };
      d.planner.setCounts(d.counting, counts(c.object), centre, d.countingMaterial, counts(c.group));
    }
  }

  if (p.mode == AccumMode::Probe && p.rec.width == d.width && p.rec.height == d.height) {
    // Change-aware priority: per tile, how much the cheap new estimate differs from the image
    // accumulated before the probe (the probe itself accumulates nothing).
    std::vector<float> now = d.renderer.readbackFrameLuminance();
    std::shared_ptr<const RenderImage> old = d.lastImage;
    if (!old || d.lastImageFrame + 1 != p.rec.frame) old = std::make_shared<RenderImage>(d.renderer.readback());
    std::vector<float> diff(static_cast<std::size_t>(grid.count()), 0.0f);
    for (int t = 0; t < grid.count(); ++t) {
      TileRect r = grid.rect(t);
      double a = 0, b = 0;
      int n = 0;
      for (int y = r.y; y < r.y + r.height; ++y)
        for (int x = r.x; x < r.x + r.width; ++x) {
          std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(d.width) + static_cast<std::size_t>(x);
          if (!(now[i] == now[i])) continue;
          const float* c = &old->color[i * 3];
          a += now[i];
          b += 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
          ++n;
        }
      if (n) diff[static_cast<std::size_t>(t)] = static_cast<float>(std::abs(a - b) / n / (b / n + 0.05));
    }
    d.execute(d.planner.planFromProbe(diff));
  }
}

void RenderSession::submitFrame(bool readImage) {
  Impl& d = *impl_;
  completeGpu();
  RETILE_ASSERT(d.pending.size() < 2, cat(d.pending.size(), " frames unfinished: finish one before submitting"));
  auto start = Clock::now();
  const TileGrid& grid = d.scheduler.grid();
  // One plan for every edit since the last frame; without edits, whatever quiet brings.
  const bool edited = !d.batch.empty();
  d.execute(edited ? d.planner.planBatch(d.batch) : d.planner.planQuiet(d.scheduler.passActive() || d.previewed));
  d.batch.clear();
  const int block = d.frameBlock(edited, method().reuse);
  d.syncCounting(scene_);
  std::vector<double> samplesBefore;
  if (method().reuse) samplesBefore = d.scheduler.tileSamples();
  else d.scheduler.setCredit({});
  FramePlan plan = d.scheduler.nextFrame(block);
  FrameOptions options;
  options.accumulate = plan.mode != AccumMode::Probe;
  if (method().denoise) options.denoise = d.denoiseWork(plan.mode, d.frame + 1, method());
  if (method().reuse && options.accumulate) d.planReuse(plan, options, d.frame + 1, samplesBefore);
  std::vector<TileWork> work;
  work.reserve(plan.chunks.size());
  for (const TileChunk& c : plan.chunks)
    work.push_back({c.rect.x, c.rect.y, c.rect.width, c.rect.height, c.quality, c.sampleBase, c.restart, c.capStale, c.block});
  Impl::Pending p;
  p.mode = plan.mode;
  p.counting = d.planner.countThisFrame(plan.mode);
  if (p.counting) options.selectionTileSize = grid.tileSize();
  // Verified reuse tests the samples of every frame while a tile reuses its history.
  p.readImage = readImage || (method().reuse && d.reuse.anyReusing());
  p.start = start;

  FrameRecord& rec = p.rec;
  rec.frame = ++d.frame;
  rec.documentVersion = d.documentVersion;
  rec.method = methodLabel(method());
  rec.mode = accumModeName(plan.mode);
  rec.block = block;
  rec.smooth = method().smooth;
  rec.staleCap = method().staleCap;
  rec.width = d.width;
  rec.height = d.height;
  rec.tileSize = grid.tileSize();
  rec.cols = grid.cols();
  rec.rows = grid.rows();
  rec.quality = d.scheduler.quality();
  rec.pointOfChange = d.planner.pointOfChange();
  rec.pointsOfChange = d.planner.pointsOfChange();
  for (const auto& f : d.planner.focus()) rec.focus.push_back(f.pixel);
  rec.selection = selection_;
  rec.tilePriority = d.scheduler.priorities();
  for (TileClass c : d.planner.classes()) rec.tileClass.push_back(static_cast<std::uint8_t>(c));
  rec.tileSamples.assign(d.scheduler.tileSamples().begin(), d.scheduler.tileSamples().end());
  rec.servedTiles = std::move(plan.servedTiles);
  rec.region = d.region;
  if (method().denoise)
    for (const DenoiseRegion& r : d.lastRegions)
      rec.denoised.push_back({RegionRect{r.rect.x, r.rect.y, r.rect.width, r.rect.height}, rec.frame - r.frame});
  if (method().reuse) {
    rec.tileReuse.reserve(d.reuse.states().size());
    for (TileReuse r : d.reuse.states()) {
      rec.tileReuse.push_back(static_cast<std::uint8_t>(r));
      rec.reusedTiles += r == TileReuse::Reusing;
      rec.rejectedTiles += r == TileReuse::Rejected;
    }
    rec.tileRejectedAt = d.reuse.rejectedAt();
  }
  rec.queueLength = d.scheduler.queueLength();
  rec.queueServed = d.scheduler.queueServed();
  rec.scheduleMs = msSince(start);

  p.kernels = d.renderer.kernelsCompiled();
  p.ticket = d.renderer.submitFrame(work, options, p.readImage);
  d.pending.push_back(std::move(p));
}

FrameRecord RenderSession::finishFrame() {
  Impl& d = *impl_;
  RETILE_ASSERT(!d.pending.empty(), "finishFrame without a submitted frame");
  if (d.pending.size() == 1) completeGpu();  // else the oldest was completed when the next was submitted
  Impl::Pending p = std::move(d.pending.front());
  d.pending.pop_front();
  auto readStart = Clock::now();
  FrameRecord rec = std::move(p.rec);
  rec.samples = p.stats.samples;
  rec.traceMs = p.stats.seconds * 1e3;
  if (p.readImage) {
    d.lastImage = std::make_shared<RenderImage>(d.renderer.frameImage(p.ticket));
    d.lastImageFrame = rec.frame;
    rec.image = d.lastImage;
    if (method().reuse) d.testReuse(*d.lastImage, rec.frame, method().reuseFalseReject);
  }
  rec.readbackMs = msSince(readStart);
  rec.frameMs = msSince(p.start);
  // Compiled for it, or while it was in flight (prepareMoves): its time is mostly the compile's.
  rec.compiledKernel = d.renderer.kernelsCompiled() != p.kernels;
  return rec;
}

std::size_t RenderSession::framesInFlight() const { return impl_->pending.size(); }

void RenderSession::prepareMoves() { impl_->renderer.prepareMoves(); }

FrameRecord RenderSession::renderFrame(bool readImage) {
  RETILE_ASSERT(impl_->pending.empty(), "renderFrame while pipelined frames are unfinished");
  submitFrame(readImage);
  return finishFrame();
}

}  // namespace retile
