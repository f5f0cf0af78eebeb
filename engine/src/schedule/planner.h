// The planner: everything the method of ../shared/METHOD.md decides about what to trace next and
// what to keep. Given an edit's facts on screen (rectangles before and after, points of change,
// the edited object's projected motion), the method, the focus points, the indirection counters
// and the change probe's differences, it returns a Plan: a global update, a probe frame, or a pass
// (tile order, prioritized prefix, Q, smooth transition). The RenderSession measures the facts,
// executes plans through the TileScheduler and feeds measurements back; no decision is made
// there, so every policy is tested here without a GPU.
//
// Pure CPU, no Vulkan; owned by the render thread (the RenderSession's).
#pragma once

#include <optional>
#include <vector>

#include "retile/method.h"
#include "retile/scene.h"
#include "schedule/policies.h"
#include "schedule/scheduler.h"
#include "schedule/tile_grid.h"

namespace retile {

// What one edit changed on screen, measured by the session right after applying it.
struct EditFacts {
  bool global = false;                            // camera or render settings: every sample is stale
  Vec2 pointOfChange{0.0f};                       // projected centre of the targets' bounds (light position; else centre)
  std::vector<TileRect> screen;                   // image rectangles the targets cover, before and after the edit
  NodeId object = kNoNode;                        // the one object the edit changed (a move; a material only it uses)
  NodeId material = kNoNode;                      // a material edit: the material (the batch holds a fact per object using it)
  bool moved = false;                             // that object's transform changed
  std::optional<Vec2> centreBefore, centreAfter;  // its projected bounds centre
};

enum class PlanKind {
  None,          // nothing new: the scheduler goes on with its pass or refinement
  GlobalUpdate,  // every tile at 1 spp, sums restarted
  Probe,         // every tile at 1 spp, traced and compared, not accumulated (change policy)
  Pass,          // an incremental pass
};

struct Plan {
  PlanKind kind = PlanKind::None;
  std::vector<int> order;  // Pass: tiles in serving order
  int quality = 1;         // Pass: Q
  int leading = 0;         // Pass: how many tiles the policy ranked first (touched with smooth,
                           //       indirection classes, changed tiles)
  int prioritized = 0;     // Pass: the first `prioritized` tiles restart: all without smooth, else
  bool smooth = false;     //       the leading ones; the rest keep capped stale sums (staleCap)
  int staleCap = 1;
  // Pass: what a preview re-renders, in order: the tiles the edit touched (with none on screen,
  // the ones the pass restarts)
  std::vector<int> preview;
};

class Planner {
 public:
  // Q when automatic Q has nothing to fit (no high tiles: the object is out of view), and its cap.
  static constexpr int kDefaultAutomaticQuality = 64;
  static constexpr int kMaxAutomaticQuality = 256;

  Planner() = default;
  Planner(const TileGrid& grid, const MethodSettings& method);

  // A new grid (resize, new T), new settings or new focus points. The grid and the settings drop
  // the counters (their tiles or their meaning changed) and gather them again.
  void setGrid(const TileGrid& grid);
  void setMethod(const MethodSettings& method);
  void setFocus(std::vector<FocusPoint> focus);
  // The selection is what the counters describe until an edit changes another object.
  void select(NodeId object);

  // Indirection counters, gathered over full frames (global update, refinement) so that no tile
  // is favoured. The session counts the object countTarget() names in the frames
  // countThisFrame() allows, tells frameCounted() after each, and gives the sums to setCounts()
  // once frameCounted() returns true.
  NodeId countTarget() const { return countTarget_; }
  bool countThisFrame(AccumMode mode) const;
  bool frameCounted();
  // `centre`: the object's projected centre now, from which its later motion is measured.
  // `group`: the counts of every object using `groupMaterial` (the object's material), which a
  // material edit of it plans by as a move plans by the object's.
  void setCounts(NodeId object, const IndirectionCounts& counts, std::optional<Vec2> centre, NodeId groupMaterial = kNoNode,
                 const IndirectionCounts& group = {});
  bool haveCounts() const { return !counts_.empty() && countsFor_ != kNoNode; }

  // One plan for all edits applied since the last frame (a batch), with all their points of change.
  Plan planBatch(const std::vector<EditFacts>& batch);
  // A frame without an edit: the change policy probes on the first one; a pass that drained
  // settles the edit (the counters are gathered again).
  Plan planQuiet(bool passActive);
  // The change policy's pass from the probe: per tile, how much the probe's estimate differs from
  // the image before it (relative; NaN: unknown).
  Plan planFromProbe(const std::vector<float>& tileDifference);
  // The plan of the last edit (planBatch or planFromProbe), to run again at full resolution after
  // a preview of it (RenderSession); None when the grid or method changed since.
  const Plan& lastEditPlan() const { return lastEditPlan_; }

  const MethodSettings& method() const { return method_; }
  const TileGrid& grid() const { return grid_; }
  Vec2 pointOfChange() const { return pointsOfChange_.empty() ? centre() : pointsOfChange_.back(); }
  const std::vector<Vec2>& pointsOfChange() const { return pointsOfChange_; }
  const std::vector<FocusPoint>& focus() const { return method_.focus; }
  // Per tile, the indirection classes of the last plan (or of the counters); empty without counters.
  const std::vector<TileClass>& classes() const { return classes_; }
  bool probePending() const { return probePending_; }

  // The change policy's threshold: a tile counts as changed when its probe difference exceeds
  // this many times the median difference (most tiles of a local edit are unchanged, so the
  // median measures the 1-spp probe's noise).
  static constexpr float kChangedOverMedian = 3.0f;

 private:
  bool indirection() const;
  bool focusPolicy() const;
  Vec2 centre() const { return {grid_.width() * 0.5f, grid_.height() * 0.5f}; }
  std::vector<int> centres() const;  // tiles of the points of change, then (focus policies) of the focus points
  std::vector<char> touchedTiles(const std::vector<EditFacts>& batch) const;
  std::vector<char> seenWhereCounted(const std::vector<char>& touched, bool moved, const IndirectionCounts& counts) const;
  Plan spiralPass(const std::vector<char>& touched) const;
  Plan indirectionPass(const std::vector<char>& touched, Vec2 motion, const IndirectionCounts& counts);
  Plan pass(std::vector<int> order, int leading, int quality) const;
  static void withPreview(Plan& plan, const std::vector<char>& touched);
  void dropCounts(bool gatherAgain);

  TileGrid grid_;
  MethodSettings method_;
  std::vector<Vec2> pointsOfChange_;
  std::vector<char> lastTouched_;  // the last batch's touched tiles, for the change policy's pass

  NodeId countTarget_ = kNoNode;
  int countFramesLeft_ = 0;
  NodeId countsFor_ = kNoNode;
  IndirectionCounts counts_;
  NodeId groupMaterial_ = kNoNode;  // what groupCounts_ describe: the objects of this material
  IndirectionCounts groupCounts_;
  std::optional<Vec2> countedCentre_;
  std::vector<TileClass> classes_;

  Plan lastEditPlan_;
  bool passFromEdit_ = false;  // a pass runs because of an edit: gather counters when it drains
  bool probePending_ = false;  // change policy: probe on the first frame without an edit
};

}  // namespace retile
