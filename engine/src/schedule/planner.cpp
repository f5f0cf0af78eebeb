#include "schedule/planner.h"

#include <algorithm>
#include <cmath>

namespace retile {

Planner::Planner(const TileGrid& grid, const MethodSettings& method) : grid_(grid), method_(method) {}

bool Planner::indirection() const { return method_.kind == MethodKind::Indirection || method_.kind == MethodKind::IndirectionFocus; }

bool Planner::focusPolicy() const { return method_.kind == MethodKind::Focus || method_.kind == MethodKind::IndirectionFocus; }

void Planner::dropCounts(bool gatherAgain) {
  counts_ = {};
  countsFor_ = kNoNode;
  groupCounts_ = {};
  groupMaterial_ = kNoNode;
  countedCentre_.reset();
  classes_.clear();
  countFramesLeft_ = gatherAgain && countTarget_ != kNoNode ? method_.indirectionFrames : 0;
}

void Planner::setGrid(const TileGrid& grid) {
  grid_ = grid;
  lastEditPlan_ = {};
  pointsOfChange_.clear();
  lastTouched_.clear();
  passFromEdit_ = false;
  probePending_ = false;
  dropCounts(true);
}

void Planner::setMethod(const MethodSettings& method) {
  method_ = method;
  lastEditPlan_ = {};
  passFromEdit_ = false;
  probePending_ = false;
  dropCounts(true);
}

void Planner::setFocus(std::vector<FocusPoint> focus) {
  if (focus.size() > 3) focus.resize(3);
  method_.focus = std::move(focus);
}

void Planner::select(NodeId object) {
  countTarget_ = object;
  dropCounts(true);
}

bool Planner::countThisFrame(AccumMode mode) const {
  return indirection() && countTarget_ != kNoNode && countFramesLeft_ > 0 &&
         (mode == AccumMode::GlobalUpdate || mode == AccumMode::Refinement);
}

bool Planner::frameCounted() { return countFramesLeft_ > 0 && --countFramesLeft_ == 0; }

void Planner::setCounts(NodeId object, const IndirectionCounts& counts, std::optional<Vec2> centre, NodeId groupMaterial,
                        const IndirectionCounts& group) {
  if (object != countTarget_) return;  // gathered for an object no longer of interest
  counts_ = counts;
  countsFor_ = object;
  groupMaterial_ = group.empty() ? kNoNode : groupMaterial;
  groupCounts_ = group;
  countedCentre_ = centre;
  classes_ = indirectionPlan(grid_, counts_, grid_.tileAt(centre.value_or(this->centre())), {}).classes;
}

std::vector<int> Planner::centres() const {
  std::vector<int> c;
  for (Vec2 p : pointsOfChange_) c.push_back(grid_.tileAt(p));
  if (c.empty()) c.push_back(grid_.tileAt(centre()));
  if (focusPolicy())
    for (const FocusPoint& f : method_.focus) c.push_back(grid_.tileAt(f.pixel));
  return c;
}

std::vector<char> Planner::touchedTiles(const std::vector<EditFacts>& batch) const {
  std::vector<char> touched(static_cast<std::size_t>(grid_.count()), 0);
  for (const EditFacts& f : batch)
    for (const TileRect& r : f.screen) {
      if (r.pixels() <= 0) continue;
      int c0 = std::clamp(r.x / grid_.tileSize(), 0, grid_.cols() - 1);
      int r0 = std::clamp(r.y / grid_.tileSize(), 0, grid_.rows() - 1);
      int c1 = std::clamp((r.x + r.width - 1) / grid_.tileSize(), 0, grid_.cols() - 1);
      int r1 = std::clamp((r.y + r.height - 1) / grid_.tileSize(), 0, grid_.rows() - 1);
      for (int row = r0; row <= r1; ++row)
        for (int col = c0; col <= c1; ++col) touched[static_cast<std::size_t>(grid_.index(col, row))] = 1;
    }
  return touched;
}

// The tiles an indirection pass takes as touched. An edit that leaves its objects where they were
// counted (a material, a visibility) changes them where the counters saw them, and only there
// directly: their screen rectangles also cover what a large, thin or partly hidden object does
// not show (a backdrop's rectangle fills the image), which made every such tile high and
// automatic Q small. The counters' few samples a pixel can miss a silhouette's sliver of a tile,
// so the tiles around a seen one count too, within the rectangles. A move needs the rectangles:
// the object's old and new places. So does an object the counters did not see (shown again after
// it was hidden).
std::vector<char> Planner::seenWhereCounted(const std::vector<char>& touched, bool moved, const IndirectionCounts& counts) const {
  if (moved) return touched;
  std::vector<char> seen(touched.size(), 0);
  bool any = false;
  for (int row = 0; row < grid_.rows(); ++row)
    for (int col = 0; col < grid_.cols(); ++col) {
      const auto t = static_cast<std::size_t>(grid_.index(col, row));
      if (t >= counts.direct.size() || counts.direct[t] <= 0) continue;
      any = true;
      seen[t] = 1;
      for (int r = std::max(0, row - 1); r <= std::min(grid_.rows() - 1, row + 1); ++r)
        for (int c = std::max(0, col - 1); c <= std::min(grid_.cols() - 1, col + 1); ++c) {
          const auto n = static_cast<std::size_t>(grid_.index(c, r));
          if (touched[n]) seen[n] = 1;
        }
    }
  return any ? seen : touched;
}

void Planner::withPreview(Plan& plan, const std::vector<char>& touched) {
  plan.preview.clear();
  for (int t : plan.order)
    if (static_cast<std::size_t>(t) < touched.size() && touched[static_cast<std::size_t>(t)]) plan.preview.push_back(t);
  // An edit with nothing on screen (a light, the sky, an object out of view) may change any tile:
  // the preview covers what the pass restarts.
  if (plan.preview.empty())
    plan.preview.assign(plan.order.begin(), plan.order.begin() + std::clamp<std::ptrdiff_t>(plan.prioritized, 0, std::ssize(plan.order)));
}

Plan Planner::pass(std::vector<int> order, int leading, int quality) const {
  Plan p;
  p.kind = PlanKind::Pass;
  p.quality = std::max(1, quality);
  p.smooth = method_.smooth;
  p.staleCap = method_.staleCap;
  p.leading = leading;
  // Without the smooth transition every tile of the pass restarts.
  p.prioritized = method_.smooth ? leading : static_cast<int>(order.size());
  p.order = std::move(order);
  return p;
}

// Spiral and focus (and change and indirection before their probe or counters): one spiral per
// point of change (and focus point) taking turns. With the smooth transition the tiles the edit
// touched go first and restart, and the rest keep capped stale sums; without it the order is the
// spirals' (METHOD.md: by Chebyshev distance).
Plan Planner::spiralPass(const std::vector<char>& touched) const {
  std::vector<int> spiral = interleavedSpirals(grid_, centres());
  int q = method_.quality > 0 ? method_.quality : kDefaultAutomaticQuality;
  if (!method_.smooth) return pass(spiral, 0, q);
  std::vector<int> order;
  order.reserve(spiral.size());
  for (int t : spiral)
    if (touched[static_cast<std::size_t>(t)]) order.push_back(t);
  int prioritized = static_cast<int>(order.size());
  for (int t : spiral)
    if (!touched[static_cast<std::size_t>(t)]) order.push_back(t);
  return pass(std::move(order), prioritized, q);
}

// Indirection with counters of the edited object. The tiles where the object itself was seen
// (direct hits) move with its screen motion since counting, by replacement; tiles it shadows or
// reflects into are features of other surfaces that do not move like the object on screen, so
// they stay. First the moved direct tiles and every tile the edit touched, then the other high,
// middle and low tiles (all prioritized), then the rest. Automatic Q fits all high and touched
// tiles into one frame, so the object's old and new places are refreshed together (no ghosting).
Plan Planner::indirectionPass(const std::vector<char>& touched, Vec2 motion, const IndirectionCounts& counts) {
  const auto n = static_cast<std::size_t>(grid_.count());
  std::vector<int> spiral = interleavedSpirals(grid_, centres());
  IndirectionPlan classes = indirectionPlan(grid_, counts, spiral.front(), spiral);
  std::vector<int> direct;
  for (std::size_t t = 0; t < n && t < counts.direct.size(); ++t)
    if (counts.direct[t] > 0) direct.push_back(static_cast<int>(t));
  std::vector<int> moved = followMotion(grid_, direct, motion);

  std::vector<TileClass> cls(n, TileClass::Rest);
  for (std::size_t t = 0; t < n; ++t)
    if (!(counts.direct.size() > t && counts.direct[t] > 0)) cls[t] = classes.classes[t];
  std::vector<char> first(n, 0);
  for (int t : moved) first[static_cast<std::size_t>(t)] = 1;
  for (std::size_t t = 0; t < n; ++t)
    if (touched[t]) first[t] = 1;
  for (std::size_t t = 0; t < n; ++t)
    if (first[t]) cls[t] = TileClass::High;

  std::vector<int> order, mustFit;
  for (int t : spiral)
    if (first[static_cast<std::size_t>(t)]) order.push_back(t);
  for (TileClass k : {TileClass::High, TileClass::Middle, TileClass::Low})
    for (int t : spiral)
      if (!first[static_cast<std::size_t>(t)] && cls[static_cast<std::size_t>(t)] == k) order.push_back(t);
  for (int t : order)
    if (cls[static_cast<std::size_t>(t)] == TileClass::High) mustFit.push_back(t);
  int prioritized = static_cast<int>(order.size());
  for (int t : spiral)
    if (cls[static_cast<std::size_t>(t)] == TileClass::Rest) order.push_back(t);
  classes_ = std::move(cls);

  int q = method_.quality;
  if (q == 0) q = mustFit.empty() ? kDefaultAutomaticQuality : automaticQuality(grid_, mustFit, kMaxAutomaticQuality);
  return pass(std::move(order), prioritized, q);
}

Plan Planner::planBatch(const std::vector<EditFacts>& batch) {
  if (batch.empty()) return {};
  pointsOfChange_.clear();
  for (const EditFacts& f : batch) pointsOfChange_.push_back(f.pointOfChange);

  bool global = method_.kind == MethodKind::Global;
  for (const EditFacts& f : batch) global = global || f.global;
  if (global) {
    // A camera or settings change moves every tile's content: counters and the motion they are
    // measured from no longer hold, and following focus points have nothing to follow.
    pointsOfChange_ = {centre()};
    lastTouched_.clear();
    passFromEdit_ = false;
    probePending_ = false;
    bool cameraLike = std::any_of(batch.begin(), batch.end(), [](const EditFacts& f) { return f.global; });
    if (cameraLike) dropCounts(true);
    lastEditPlan_ = Plan{PlanKind::GlobalUpdate};
    return lastEditPlan_;
  }

  // The edited object: the last one the batch changed alone. Its motion within the batch moves
  // the focus points that follow it.
  NodeId object = kNoNode;
  for (const EditFacts& f : batch)
    if (f.object != kNoNode) object = f.object;
  Vec2 batchMotion{0.0f};
  std::optional<Vec2> centreNow;
  for (const EditFacts& f : batch)
    if (f.object == object && object != kNoNode && f.centreAfter) {
      centreNow = f.centreAfter;
      if (f.moved && f.centreBefore)
        batchMotion = Vec2{batchMotion.x + f.centreAfter->x - f.centreBefore->x, batchMotion.y + f.centreAfter->y - f.centreBefore->y};
    }
  for (FocusPoint& fp : method_.focus)
    if (fp.follows) fp.pixel = Vec2{fp.pixel.x + batchMotion.x, fp.pixel.y + batchMotion.y};

  // The counters describe the edit's own object, or nothing: an edit of another object makes
  // that object the one to count once the edit settles (a light or a shared material has none).
  if (object != kNoNode && object != countTarget_) {
    countTarget_ = object;
    dropCounts(false);
  }

  std::vector<char> touched = touchedTiles(batch);
  lastTouched_ = touched;
  passFromEdit_ = true;
  // A material edit: the material, when the batch changed one.
  NodeId material = kNoNode;
  for (const EditFacts& f : batch)
    if (f.material != kNoNode) material = f.material;
  const bool moved = std::any_of(batch.begin(), batch.end(), [](const EditFacts& f) { return f.moved; });
  Plan plan;
  if (indirection() && haveCounts() && object == countsFor_ && object != kNoNode) {
    Vec2 motion{0.0f};
    if (centreNow && countedCentre_) motion = Vec2{centreNow->x - countedCentre_->x, centreNow->y - countedCentre_->y};
    touched = seenWhereCounted(touched, moved || motion.x != 0.0f || motion.y != 0.0f, counts_);
    plan = indirectionPass(touched, motion, counts_);
  } else if (indirection() && material != kNoNode && material == groupMaterial_ && !groupCounts_.empty()) {
    // Every object of the material changed where it stands: its direct, reflected and shadow
    // tiles first, as for a move.
    touched = seenWhereCounted(touched, moved, groupCounts_);
    plan = indirectionPass(touched, Vec2{0.0f}, groupCounts_);
  } else {
    if (indirection() && haveCounts() && object != countsFor_) classes_.clear();  // they do not apply
    plan = spiralPass(touched);
  }
  withPreview(plan, touched);
  // Change: the spiral (or indirection) order while edits keep coming; one probe when they stop.
  probePending_ = method_.kind == MethodKind::Change;
  lastEditPlan_ = plan;
  return plan;
}

Plan Planner::planQuiet(bool passActive) {
  if (probePending_) {
    probePending_ = false;
    return Plan{PlanKind::Probe};
  }
  if (passFromEdit_ && !passActive) {
    // The edit has settled: gather fresh counters for the next one.
    passFromEdit_ = false;
    if (indirection() && countTarget_ != kNoNode) countFramesLeft_ = method_.indirectionFrames;
  }
  return {};
}

Plan Planner::planFromProbe(const std::vector<float>& tileDifference) {
  const auto n = static_cast<std::size_t>(grid_.count());
  std::vector<float> d(n, 0.0f);
  for (std::size_t i = 0; i < n && i < tileDifference.size(); ++i) d[i] = std::isfinite(tileDifference[i]) ? tileDifference[i] : 0.0f;
  std::vector<float> sorted = d;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2), sorted.end());
  const float threshold = kChangedOverMedian * sorted[n / 2];
  std::vector<int> byChange = changeOrder(grid_, d, grid_.tileAt(pointOfChange()));
  // Changed tiles and those the edit touched restart first; the rest follow by difference
  // (with the smooth transition they keep capped stale sums).
  std::vector<char> first(n, 0);
  for (std::size_t t = 0; t < n; ++t) first[t] = d[t] > threshold || (t < lastTouched_.size() && lastTouched_[t]);
  std::vector<int> order;
  for (int t : byChange)
    if (first[static_cast<std::size_t>(t)]) order.push_back(t);
  int prioritized = static_cast<int>(order.size());
  for (int t : byChange)
    if (!first[static_cast<std::size_t>(t)]) order.push_back(t);
  passFromEdit_ = true;
  lastEditPlan_ = pass(std::move(order), prioritized, method_.quality > 0 ? method_.quality : kDefaultAutomaticQuality);
  withPreview(lastEditPlan_, lastTouched_);
  return lastEditPlan_;
}

}  // namespace retile
