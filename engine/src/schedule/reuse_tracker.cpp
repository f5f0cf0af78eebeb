#include "schedule/reuse_tracker.h"

#include <algorithm>

namespace retile {

void ReuseTracker::reset(const TileGrid& grid) {
  grid_ = grid;
  const auto n = static_cast<std::size_t>(grid.count());
  state_.assign(n, TileReuse::None);
  started_.assign(n, 0);
  rejectedAt_.assign(n, 0);
  startedInPass_.assign(n, 0);
  credit_.assign(n, 0.0);
  pendingRejects_.clear();
}

bool ReuseTracker::anyReusing() const { return std::find(state_.begin(), state_.end(), TileReuse::Reusing) != state_.end(); }

std::vector<ReuseOp> ReuseTracker::planFrame(FramePlan& plan, const std::vector<double>& before, std::uint64_t frameNumber) {
  std::vector<ReuseOp> ops;
  if (plan.mode == AccumMode::GlobalUpdate) {
    // Its restarts drop every history, in the renderer's accumulate pass.
    reset(grid_);
    return ops;
  }
  std::vector<char> started(state_.size(), 0);
  for (TileChunk& c : plan.chunks) {
    auto t = static_cast<std::size_t>(c.tile);
    // The smooth transition's stale tiles keep their verified history instead of a capped one:
    // their first serve in the pass starts the history like a restart.
    const double had = t < before.size() ? before[t] : 0.0;
    double kept = had;  // spp the tile's history will hold
    if (c.capStale > 0 && !c.restart) {
      const int cap = c.capStale;
      c.capStale = 0;
      if (startedInPass_[t] == pass_) continue;
      kept = had - std::min(had, static_cast<double>(cap));  // the scheduler counts the cap as fresh
    } else if (!c.restart) {
      continue;
    }
    // A tile that keeps a history goes back to it: its credit stays.
    if (state_[t] != TileReuse::Reusing) credit_[t] = kept + credit_[t];
    c.restart = false;
    startedInPass_[t] = pass_;
    ops.push_back({c.tile, c.rect, ReuseOp::Start});
    started[t] = 1;
    state_[t] = TileReuse::Reusing;
    started_[t] = frameNumber;
    rejectedAt_[t] = 0;
  }
  for (int tile : pendingRejects_) {
    auto t = static_cast<std::size_t>(tile);
    if (started[t] || state_[t] != TileReuse::Reusing) continue;  // a new edit's history replaces the verdict
    ops.push_back({tile, grid_.rect(tile), ReuseOp::Reject});
    state_[t] = TileReuse::Rejected;
    rejectedAt_[t] = frameNumber;
    credit_[t] = 0.0;
  }
  pendingRejects_.clear();
  return ops;
}

void ReuseTracker::test(std::uint64_t imageFrame, double falseRejectRate, const TileSums& sums) {
  std::vector<LuminanceSums> fresh, hist;
  std::vector<ReuseTest> tested(static_cast<std::size_t>(grid_.count()));
  std::vector<int> kept;
  for (int t = 0; t < grid_.count(); ++t) {
    auto ti = static_cast<std::size_t>(t);
    if (ti >= state_.size() || state_[ti] != TileReuse::Reusing || started_[ti] >= imageFrame + 1) continue;
    TileRect r = grid_.rect(t);
    fresh.assign(static_cast<std::size_t>(r.pixels()), {});
    hist.assign(fresh.size(), {});
    sums(r, fresh, hist);
    tested[ti] = testReuse(fresh, hist, r.width, r.height, falseRejectRate);
    if (tested[ti].reject()) pendingRejects_.push_back(t);
    else kept.push_back(t);
  }
  // Changes too small for one tile: each kept tile pooled with its kept neighbours, then all the
  // kept tiles together (a light a few per cent brighter changes every lit tile a little).
  std::vector<int> more;
  for (int t : kept) {
    std::vector<const ReuseTest*> pool;
    const int cx = t % grid_.cols(), cy = t / grid_.cols();
    for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, grid_.rows() - 1); ++y)
      for (int x = std::max(cx - 1, 0); x <= std::min(cx + 1, grid_.cols() - 1); ++x) {
        const auto n = static_cast<std::size_t>(y * grid_.cols() + x);
        if (tested[n].pixels > 0 && !tested[n].reject()) pool.push_back(&tested[n]);
      }
    if (pool.size() > 1 && testPooled(pool, falseRejectRate).reject()) more.push_back(t);
  }
  std::vector<char> found(tested.size(), 0);
  for (int t : more) found[static_cast<std::size_t>(t)] = 1;
  std::vector<const ReuseTest*> all;
  for (int t : kept)
    if (!found[static_cast<std::size_t>(t)]) all.push_back(&tested[static_cast<std::size_t>(t)]);
  if (all.size() > 1 && testPooled(all, falseRejectRate).reject()) more = kept;
  pendingRejects_.insert(pendingRejects_.end(), more.begin(), more.end());
}

}  // namespace retile
