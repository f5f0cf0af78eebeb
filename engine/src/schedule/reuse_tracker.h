// Verified reuse's per-tile state (reuse.h tests it): which tiles keep a history, since which
// frame, how many samples of it the scheduler may count, and the rejections the last read-back
// found. The RenderSession plans each frame's history operations with it and hands it the sums
// it reads back; the renderer applies the operations. Kept apart from the session so that every
// transition is tested without a GPU.
//
// Pure CPU, no Vulkan; owned by the RenderSession and called from its (the render) thread only.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "schedule/reuse.h"
#include "schedule/scheduler.h"
#include "schedule/tile_grid.h"

namespace retile {

// What the renderer does to the history of a rectangle before the frame's samples accumulate
// (FrameOptions::Reuse): Start keeps the pixels' sums as their history and counts fresh samples
// from zero beside it, Reject drops the history from the sums.
struct ReuseOp {
  enum Kind : std::uint8_t { Start, Reject };
  int tile = 0;
  TileRect rect;  // Start: the chunk that restarts the tile (maybe a strip of it); Reject: the tile
  Kind kind = Start;
};

class ReuseTracker {
 public:
  // Fills a tile's pixels, row by row over `rect` (sized rect.pixels(), zeroed): the sums of the
  // samples accumulated since its history started (fresh) and of the history.
  using TileSums = std::function<void(const TileRect& rect, std::vector<LuminanceSums>& fresh, std::vector<LuminanceSums>& history)>;

  // Every history dropped. The session calls it with the scheduler's grid whenever that changes:
  // the tiles' indices mean other pixels.
  void reset(const TileGrid& grid);
  // A pass started: the stale tiles of its smooth transition may start a history once more.
  void startPass() { ++pass_; }

  // Before frame `frameNumber` is traced: rewrites the plan's restarts (and, with a smooth
  // transition, its capped stale chunks) into history starts, applies the rejections the last
  // test() found, and returns the operations for the renderer. A global update drops every
  // history. `before`: the scheduler's samples per tile before the plan (a restart resets them).
  // The caller then gives credit() to the scheduler.
  std::vector<ReuseOp> planFrame(FramePlan& plan, const std::vector<double>& before, std::uint64_t frameNumber);

  // Tests every reusing tile against an image read back after frame `imageFrame`, pooling the
  // tiles it keeps with their neighbours and all together; the rejections apply with the next
  // planFrame(). `sums` is asked only for the tiles tested.
  void test(std::uint64_t imageFrame, double falseRejectRate, const TileSums& sums);

  const std::vector<TileReuse>& states() const { return state_; }
  // Per tile: the frame that rejected its history; 0 while it has one or never had.
  const std::vector<std::uint64_t>& rejectedAt() const { return rejectedAt_; }
  // Per tile: samples per pixel of history it keeps (TileScheduler::setCredit).
  const std::vector<double>& credit() const { return credit_; }
  bool anyReusing() const;
  // Tiles the last test() rejected, not yet applied.
  const std::vector<int>& pendingRejects() const { return pendingRejects_; }

 private:
  TileGrid grid_;
  std::vector<TileReuse> state_;
  // The frame of the tile's last history start: a test of an image read back before it is about
  // the previous edit's samples and is ignored.
  std::vector<std::uint64_t> started_;
  std::vector<std::uint64_t> rejectedAt_;
  std::vector<std::uint64_t> startedInPass_;  // the pass that last started the tile's history
  std::vector<double> credit_;
  std::vector<int> pendingRejects_;
  std::uint64_t pass_ = 0;  // passes started; 0 in startedInPass_ names none
};

}  // namespace retile
