#include "retile/session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "retile/log.h"
#include "schedule/policies.h"
#include "schedule/scheduler.h"

namespace retile {

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kMaxAutomaticQuality = 256;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

struct CameraFrame {
  Vec3 forward, right, up;
  float tanHalf, aspect;
};

CameraFrame cameraFrame(const Camera& c, int width, int height) {
  CameraFrame f;
  f.forward = normalize(c.target - c.position);
  f.right = normalize(cross(f.forward, c.up));
  if (!(length(f.right) > 0))
    f.right = normalize(cross(f.forward, std::abs(f.forward.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 0, 1}));
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
  int width = 0, height = 0;
  std::uint64_t frame = 0;
  std::uint64_t documentVersion = 0;
  std::map<NodeId, Bounds3> meshBounds;  // object-space bounds, so an edit never walks a mesh

  Vec2 poc{0.0f};
  // Indirection: counters gathered over a few full frames, the plan made from them, and the
  // point of change when it was made (for following the object's motion during a drag).
  int countFramesLeft = 0;
  SelectionCounts counts;
  bool haveCounts = false;
  IndirectionPlan plan;
  Vec2 planPoc{0.0f};
  bool passFromEdit = false;  // a pass is running because of an edit (recount when it drains)
  // Change policy: the probe frame's point of change.
  bool awaitingProbe = false;
  std::shared_ptr<const RenderImage> lastImage;
  RegionRect region;  // the render region in pixels (empty: the whole image)

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
};

RenderSession::RenderSession(Scene scene, MethodSettings method, const RendererOptions& options)
    : impl_(std::make_unique<Impl>(options)), scene_(std::move(scene)), method_(std::move(method)) {
  if (std::string bad = validateMethodSettings(method_); !bad.empty()) {
    logWarning("method settings: ", bad, "; using the defaults");
    method_ = MethodSettings{};
  }
  for (const Mesh& m : scene_.meshes)
    if (m.geometry) impl_->meshBounds[m.id] = m.geometry->bounds();
  sceneWarnings_ = impl_->renderer.setScene(scene_);
  impl_->renderer.setMaxBounces(scene_.settings.maxBounces);
  impl_->renderer.setSeed(scene_.settings.seed);
  resize(scene_.settings.width, scene_.settings.height);
}

RenderSession::~RenderSession() = default;

std::string RenderSession::deviceName() const { return impl_->renderer.deviceName(); }

void RenderSession::resize(int width, int height) {
  width = std::clamp(width, 1, 16384);
  height = std::clamp(height, 1, 16384);
  impl_->width = width;
  impl_->height = height;
  scene_.settings.width = width;
  scene_.settings.height = height;
  impl_->renderer.resize(width, height);
  impl_->scheduler.reset(TileGrid(width, height, method_.tileSize));
  impl_->poc = {width * 0.5f, height * 0.5f};
  impl_->haveCounts = false;
  impl_->countFramesLeft = selection_ != kNoNode ? method_.indirectionFrames : 0;
  impl_->awaitingProbe = false;
  impl_->lastImage.reset();
  impl_->region = {};  // its pixels meant another image size
}

void RenderSession::setRegion(RegionRect region) {
  // Clamped to the image; nothing left means no region.
  int x0 = std::clamp(region.x, 0, impl_->width), y0 = std::clamp(region.y, 0, impl_->height);
  int x1 = std::clamp(region.x + std::max(0, region.width), 0, impl_->width);
  int y1 = std::clamp(region.y + std::max(0, region.height), 0, impl_->height);
  impl_->region = RegionRect{x0, y0, x1 - x0, y1 - y0};
  if (impl_->region.empty()) impl_->region = {};
  impl_->applyRegion();
}

void RenderSession::setMaxBounces(int maxBounces) {
  scene_.settings.maxBounces = std::clamp(maxBounces, 0, 1024);
  impl_->renderer.setMaxBounces(scene_.settings.maxBounces);
  impl_->scheduler.globalUpdate();
}

std::string RenderSession::setMethod(const MethodSettings& method) {
  if (std::string bad = validateMethodSettings(method); !bad.empty()) return bad;
  bool newGrid = method.tileSize != method_.tileSize;
  method_ = method;
  if (newGrid) {
    // The accumulation stays valid; only the tiles change. Restart cleanly all the same, so
    // per-tile records describe the new grid.
    impl_->scheduler.reset(TileGrid(impl_->width, impl_->height, method_.tileSize));
    impl_->applyRegion();
    impl_->haveCounts = false;
  } else {
    impl_->scheduler.globalUpdate();
  }
  impl_->countFramesLeft = selection_ != kNoNode ? method_.indirectionFrames : 0;
  return {};
}

void RenderSession::select(NodeId object) {
  if (object != kNoNode && !scene_.object(object)) object = kNoNode;
  selection_ = object;
  impl_->renderer.setSelection(object);
  impl_->haveCounts = false;
  impl_->renderer.takeSelectionCounts();  // discard counts of the previous selection
  impl_->countFramesLeft = object != kNoNode ? method_.indirectionFrames : 0;
}

void RenderSession::setFocus(std::vector<FocusPoint> focus) {
  if (focus.size() > 3) focus.resize(3);
  method_.focus = std::move(focus);
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

}  // namespace

void RenderSession::setDocumentVersion(std::uint64_t version) { impl_->documentVersion = version; }

Result<std::uint32_t> RenderSession::applyEdit(const Edit& edit, std::uint64_t documentVersion) {
  Impl& d = *impl_;
  // Where the edit's target was, before: the smooth transition prioritizes old and new places.
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

  auto applied = retile::applyEdit(scene_, edit);
  if (!applied) return applied;
  std::uint32_t flags = applied.value();
  if (const auto* add = std::get_if<AddMesh>(&edit); add && add->mesh.geometry)
    d.meshBounds[add->mesh.id] = add->mesh.geometry->bounds();
  if (const auto* add = std::get_if<AddObject>(&edit)) targets.push_back(add->object.id);
  for (auto& w : d.renderer.updateScene(scene_, flags)) sceneWarnings_.push_back(std::move(w));
  // Coalesced commands may arrive out of version order: the record shows the newest applied.
  d.documentVersion = std::max(d.documentVersion, documentVersion);
  if (selection_ != kNoNode && !scene_.object(selection_)) select(kNoNode);

  if (flags & kUpdateSettings) {
    d.renderer.setMaxBounces(scene_.settings.maxBounces);
    d.renderer.setSeed(scene_.settings.seed);
    if (scene_.settings.width != d.width || scene_.settings.height != d.height) {
      resize(scene_.settings.width, scene_.settings.height);
      return flags;
    }
  }
  // Camera moves and global methods discard everything (the global-update mode).
  if ((flags & (kUpdateCamera | kUpdateSettings)) || method_.kind == MethodKind::Global) {
    d.scheduler.globalUpdate();
    d.poc = {d.width * 0.5f, d.height * 0.5f};
    d.passFromEdit = false;
    return flags;
  }

  // The point of change: the centre of the edited objects' bounds, a light's position, or
  // (environment, textures) the image centre.
  Bounds3 after;
  for (NodeId t : targets) after.grow(objectBounds(scene_, d.meshBounds, t));
  Vec2 centre{d.width * 0.5f, d.height * 0.5f};
  std::optional<Vec2> poc;
  if (!after.empty()) poc = projectToImage(scene_.camera, d.width, d.height, after.center());
  else if (!before.empty()) poc = projectToImage(scene_.camera, d.width, d.height, before.center());
  else if (const auto* l = std::get_if<SetLight>(&edit); l && l->light.type != LightType::Directional)
    poc = projectToImage(scene_.camera, d.width, d.height, l->light.position);
  Vec2 oldPoc = d.poc;
  d.poc = poc.value_or(centre);

  const TileGrid& grid = d.scheduler.grid();
  int pocTile = grid.tileAt(d.poc);
  // Tiles the edit touched directly (its target before and after): first in a smooth pass.
  std::vector<char> touched(static_cast<std::size_t>(grid.count()), 0);
  for (const Bounds3& b : {before, after}) {
    TileRect r = screenRect(scene_.camera, d.width, d.height, b);
    if (r.pixels() <= 0) continue;
    for (int t = 0; t < grid.count(); ++t) {
      TileRect tr = grid.rect(t);
      if (tr.x < r.x + r.width && r.x < tr.x + tr.width && tr.y < r.y + r.height && r.y < tr.y + tr.height)
        touched[static_cast<std::size_t>(t)] = 1;
    }
  }

  // Focus points: those following the object move with the point of change.
  std::vector<int> centers = {pocTile};
  for (FocusPoint& f : method_.focus) {
    if (f.follows && poc) f.pixel = Vec2{f.pixel.x + d.poc.x - oldPoc.x, f.pixel.y + d.poc.y - oldPoc.y};
    centers.push_back(grid.tileAt(f.pixel));
  }

  std::vector<int> order;
  int prioritized = 0;
  int quality = std::max(1, method_.quality);
  bool indirection = method_.kind == MethodKind::Indirection || method_.kind == MethodKind::IndirectionFocus;
  std::vector<int> rest = method_.kind == MethodKind::Focus || method_.kind == MethodKind::IndirectionFocus
                              ? interleavedSpirals(grid, centers)
                              : spiralOrder(grid, pocTile);
  if (method_.kind == MethodKind::Change) {
    d.scheduler.probe();
    d.awaitingProbe = true;
    d.passFromEdit = true;
    return flags;
  }
  if (indirection && d.haveCounts && d.counts.tileSize == grid.tileSize()) {
    IndirectionCounts c{d.counts.direct, d.counts.reflection, d.counts.shadow};
    IndirectionPlan plan = indirectionPlan(grid, c, grid.tileAt(d.planPoc), rest);
    bool movedSelection = std::find(targets.begin(), targets.end(), selection_) != targets.end() &&
                          std::holds_alternative<SetObject>(edit);
    if (movedSelection) {
      // During a drag the prioritized tiles follow the object's screen motion, by replacement.
      Vec2 motion{d.poc.x - d.planPoc.x, d.poc.y - d.planPoc.y};
      std::vector<int> moved = followMotion(grid, plan.high, motion);
      std::vector<char> inFront(static_cast<std::size_t>(grid.count()), 0);
      plan.order.clear();
      plan.high = moved;
      for (int t : moved) {
        plan.order.push_back(t);
        inFront[static_cast<std::size_t>(t)] = 1;
      }
      for (int t : rest)
        if (!inFront[static_cast<std::size_t>(t)] && touched[static_cast<std::size_t>(t)]) {
          plan.order.push_back(t);
          inFront[static_cast<std::size_t>(t)] = 1;
        }
      plan.prioritized = static_cast<int>(plan.order.size());
      for (int t : rest)
        if (!inFront[static_cast<std::size_t>(t)]) plan.order.push_back(t);
    }
    order = plan.order;
    prioritized = plan.prioritized;
    // Automatic Q; capped so that a tiny object does not stretch the pass over hundreds of
    // frames, and the default when the object is out of view (no high tiles at all).
    if (method_.quality == 0) quality = plan.high.empty() ? 64 : automaticQuality(grid, plan.high, kMaxAutomaticQuality);
    d.plan = std::move(plan);
  } else {
    // Spiral and focus (and indirection before its counters exist): with the smooth transition
    // the touched tiles go first, restarted; the rest keep capped stale sums.
    if (method_.smooth) {
      for (int t : rest)
        if (touched[static_cast<std::size_t>(t)]) order.push_back(t);
      prioritized = static_cast<int>(order.size());
      for (int t : rest)
        if (!touched[static_cast<std::size_t>(t)]) order.push_back(t);
    } else {
      order = rest;
      prioritized = static_cast<int>(order.size());
    }
    if (method_.quality == 0) quality = 64;
  }
  if (!method_.smooth) prioritized = static_cast<int>(order.size());
  d.scheduler.startPass(std::move(order), quality, prioritized, method_.smooth, method_.staleCap);
  d.passFromEdit = true;
  return flags;
}

FrameRecord RenderSession::renderFrame(bool readImage) {
  Impl& d = *impl_;
  auto start = Clock::now();
  const TileGrid& grid = d.scheduler.grid();
  FramePlan plan = d.scheduler.nextFrame();
  std::vector<TileWork> work;
  work.reserve(plan.chunks.size());
  for (const TileChunk& c : plan.chunks)
    work.push_back({c.rect.x, c.rect.y, c.rect.width, c.rect.height, c.quality, c.sampleBase, c.restart, c.capStale});
  FrameOptions options;
  options.accumulate = plan.mode != AccumMode::Probe;
  bool indirection = method_.kind == MethodKind::Indirection || method_.kind == MethodKind::IndirectionFocus;
  // Count over full frames only (every tile traced once), so that no tile is favoured.
  bool fullFrame = plan.mode == AccumMode::GlobalUpdate || plan.mode == AccumMode::Refinement;
  bool counting = indirection && selection_ != kNoNode && d.countFramesLeft > 0 && fullFrame;
  if (counting) options.selectionTileSize = grid.tileSize();
  double scheduleMs = msSince(start);

  FrameStats stats = d.renderer.renderFrame(work, options);

  if (counting && --d.countFramesLeft == 0) {
    d.counts = d.renderer.takeSelectionCounts();
    d.haveCounts = d.counts.tileSize == grid.tileSize();
    d.planPoc = d.poc;
    if (d.haveCounts) {
      IndirectionCounts c{d.counts.direct, d.counts.reflection, d.counts.shadow};
      d.plan = indirectionPlan(grid, c, grid.tileAt(d.poc), spiralOrder(grid, grid.tileAt(d.poc)));
      // The selected object's own centre is where its motion is measured from.
      if (selection_ != kNoNode) {
        Bounds3 b = objectBounds(scene_, d.meshBounds, selection_);
        if (!b.empty())
          if (auto p = projectToImage(scene_.camera, d.width, d.height, b.center())) d.planPoc = *p;
      }
    }
  }

  auto readStart = Clock::now();
  if (plan.mode == AccumMode::Probe && d.awaitingProbe) {
    // Change-aware priority: tiles whose cheap new estimate differs most from the old image.
    std::vector<float> now = d.renderer.readbackFrameLuminance();
    std::shared_ptr<const RenderImage> old = d.lastImage;
    if (!old) old = std::make_shared<RenderImage>(d.renderer.readback());
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
    std::vector<int> order = changeOrder(grid, diff, grid.tileAt(d.poc));
    d.scheduler.startPass(order, std::max(1, method_.quality), static_cast<int>(order.size()), method_.smooth,
                          method_.staleCap);
    d.awaitingProbe = false;
  }
  if (d.passFromEdit && !d.scheduler.passActive() && plan.mode != AccumMode::Probe) {
    // The edit has settled: gather fresh counters for the next edit.
    d.passFromEdit = false;
    if (indirection && selection_ != kNoNode) {
      d.renderer.takeSelectionCounts();
      d.countFramesLeft = method_.indirectionFrames;
    }
  }

  FrameRecord rec;
  rec.frame = ++d.frame;
  rec.documentVersion = d.documentVersion;
  rec.method = methodName(method_.kind);
  rec.mode = accumModeName(plan.mode);
  rec.smooth = method_.smooth;
  rec.staleCap = method_.staleCap;
  rec.width = d.width;
  rec.height = d.height;
  rec.tileSize = grid.tileSize();
  rec.cols = grid.cols();
  rec.rows = grid.rows();
  rec.quality = d.scheduler.quality();
  rec.pointOfChange = d.poc;
  for (const auto& f : method_.focus) rec.focus.push_back(f.pixel);
  rec.selection = selection_;
  rec.tilePriority = d.scheduler.priorities();
  if (indirection && d.haveCounts)
    for (TileClass c : d.plan.classes) rec.tileClass.push_back(static_cast<std::uint8_t>(c));
  rec.tileSamples.assign(d.scheduler.tileSamples().begin(), d.scheduler.tileSamples().end());
  rec.servedTiles = plan.servedTiles;
  rec.region = d.region;
  rec.queueLength = d.scheduler.queueLength();
  rec.queueServed = d.scheduler.queueServed();
  rec.samples = stats.samples;
  rec.scheduleMs = scheduleMs;
  rec.traceMs = stats.seconds * 1e3;
  if (readImage) {
    d.lastImage = std::make_shared<RenderImage>(d.renderer.readback());
    rec.image = d.lastImage;
  }
  rec.readbackMs = msSince(readStart);
  rec.frameMs = msSince(start);
  return rec;
}

}  // namespace retile
