#include "schedule/scheduler.h"

#include <algorithm>
#include <cmath>

namespace retile {

const char* accumModeName(AccumMode m) {
  switch (m) {
    case AccumMode::GlobalUpdate: return "global-update";
    case AccumMode::Incremental: return "incremental";
    case AccumMode::Refinement: return "refinement";
    case AccumMode::Probe: return "probe";
  }
  return "?";
}

void TileScheduler::reset(const TileGrid& grid) {
  grid_ = grid;
  region_.clear();
  auto n = static_cast<std::size_t>(grid.count());
  samples_.assign(n, 0.0);
  nextIndex_.assign(n, 0);
  dropPass();
  finished_.clear();
  refineCursor_ = 0;
  pendingGlobal_ = true;
  pendingProbe_ = false;
}

void TileScheduler::regrid(const TileGrid& grid) {
  const TileGrid old = grid_;
  const std::vector<double> oldSamples = samples_;
  const std::vector<std::uint32_t> oldNext = nextIndex_;
  const bool global = pendingGlobal_;
  reset(grid);
  pendingGlobal_ = global;
  if (old.width() != grid.width() || old.height() != grid.height() || old.count() == 0) {
    pendingGlobal_ = true;  // other pixels: nothing carries over
    return;
  }
  // A new tile holds the mean of the samples its pixels hold (area-weighted over the old tiles it
  // overlaps), and its sample indices continue past the largest any of its pixels has seen.
  const int t0 = old.tileSize();
  for (int t = 0; t < grid_.count(); ++t) {
    const TileRect r = grid_.rect(t);
    double sum = 0;
    std::uint32_t next = 0;
    for (int row = r.y / t0; row <= (r.y + r.height - 1) / t0; ++row)
      for (int col = r.x / t0; col <= (r.x + r.width - 1) / t0; ++col) {
        const int o = old.index(col, row);
        const TileRect q = old.rect(o);
        const int w = std::min(r.x + r.width, q.x + q.width) - std::max(r.x, q.x);
        const int h = std::min(r.y + r.height, q.y + q.height) - std::max(r.y, q.y);
        sum += oldSamples[static_cast<std::size_t>(o)] * w * h;
        next = std::max(next, oldNext[static_cast<std::size_t>(o)]);
      }
    samples_[static_cast<std::size_t>(t)] = sum / static_cast<double>(r.pixels());
    nextIndex_[static_cast<std::size_t>(t)] = next;
  }
}

void TileScheduler::globalUpdate() {
  pendingGlobal_ = true;
  pendingProbe_ = false;
  dropPass();
}

void TileScheduler::dropPass() {
  queue_.clear();
  pass_.clear();
  pos_ = 0;
  preview_.clear();
  previewPos_ = 0;
  previewed_.assign(static_cast<std::size_t>(grid_.count()), 0);
}

std::vector<int> TileScheduler::uniqueInRegion(const std::vector<int>& tiles) const {
  std::vector<char> seen(static_cast<std::size_t>(grid_.count()), 0);
  std::vector<int> kept;
  for (int t : tiles)
    if (t >= 0 && t < grid_.count() && !seen[static_cast<std::size_t>(t)] && inRegion(t)) {
      seen[static_cast<std::size_t>(t)] = 1;
      kept.push_back(t);
    }
  return kept;
}

void TileScheduler::probe() { pendingProbe_ = true; }

void TileScheduler::setRegion(std::vector<char> tiles) {
  if (static_cast<int>(tiles.size()) != grid_.count() || std::none_of(tiles.begin(), tiles.end(), [](char c) { return c; })) tiles.clear();
  region_ = std::move(tiles);
  // A pass keeps its order; tiles outside the region drop out of it.
  if (!region_.empty() && pos_ < queue_.size()) {
    std::vector<int> q(queue_.begin(), queue_.begin() + static_cast<std::ptrdiff_t>(pos_));
    std::vector<PassTile> p(pass_.begin(), pass_.begin() + static_cast<std::ptrdiff_t>(pos_));
    for (std::size_t i = pos_; i < queue_.size(); ++i)
      if (inRegion(queue_[i])) {
        q.push_back(queue_[i]);
        p.push_back(pass_[i]);
      }
    queue_ = std::move(q);
    pass_ = std::move(p);
  }
  // Nor does a preview trace outside it; a tile left outside is no longer the preview's.
  if (!region_.empty()) {
    preview_ = uniqueInRegion({preview_.begin() + static_cast<std::ptrdiff_t>(previewPos_), preview_.end()});
    previewPos_ = 0;
    for (std::size_t t = 0; t < previewed_.size(); ++t)
      if (!inRegion(static_cast<int>(t))) previewed_[t] = 0;
  }
}

void TileScheduler::startPass(std::vector<int> order, int quality, int prioritized, bool smooth, int staleCap) {
  queue_ = uniqueInRegion(order);
  quality_ = std::max(1, quality);
  pass_.assign(queue_.size(), PassTile{quality_, false});
  pos_ = 0;
  prioritized_ = std::clamp(prioritized, 0, static_cast<int>(queue_.size()));
  smooth_ = smooth;
  staleCap_ = std::max(1, staleCap);
  finished_.clear();
  pendingProbe_ = false;
  setPreviewTiles({});
}

void TileScheduler::setPreviewTiles(const std::vector<int>& tiles) {
  preview_ = uniqueInRegion(tiles);
  previewPos_ = 0;
}

AccumMode TileScheduler::mode() const {
  if (pendingGlobal_) return AccumMode::GlobalUpdate;
  if (pendingProbe_) return AccumMode::Probe;
  return passActive() ? AccumMode::Incremental : AccumMode::Refinement;
}

std::vector<float> TileScheduler::priorities() const {
  std::vector<float> p(static_cast<std::size_t>(grid_.count()), -1.0f);
  float last = queue_.size() > 1 ? static_cast<float>(queue_.size() - 1) : 1.0f;
  for (std::size_t i = 0; i < queue_.size(); ++i) p[static_cast<std::size_t>(queue_[i])] = 1.0f - static_cast<float>(i) / last;
  return p;
}

std::vector<char> TileScheduler::startedTiles() const {
  std::vector<char> started(static_cast<std::size_t>(grid_.count()), 0);
  for (std::size_t i = 0; i < queue_.size(); ++i)
    if (pass_[i].started) started[static_cast<std::size_t>(queue_[i])] = 1;
  for (std::size_t t = 0; t < started.size(); ++t) started[t] = started[t] || previewed_[t];
  return started;
}

void TileScheduler::emit(FramePlan& plan, int tile, TileRect rect, int quality, bool restart, int cap, bool wholeTile) {
  auto t = static_cast<std::size_t>(tile);
  TileChunk c;
  c.tile = tile;
  c.rect = rect;
  c.quality = quality;
  c.sampleBase = nextIndex_[t];
  c.restart = restart;
  c.capStale = cap;
  // Sample indices only grow per tile, so no pixel ever sees the same index twice.
  nextIndex_[t] += static_cast<std::uint32_t>(quality);
  double share = wholeTile ? 1.0 : static_cast<double>(rect.pixels()) / static_cast<double>(grid_.rect(tile).pixels());
  if (restart) samples_[t] = quality * share;
  else if (cap > 0) samples_[t] = std::min(samples_[t], static_cast<double>(cap)) + quality * share;
  else samples_[t] += quality * share;
  if (plan.servedTiles.empty() || std::find(plan.servedTiles.begin(), plan.servedTiles.end(), tile) == plan.servedTiles.end())
    plan.servedTiles.push_back(tile);
  plan.chunks.push_back(c);
  plan.samples += rect.pixels() * quality;
}

// The budget left after whole tiles is smaller than the next tile: spend it as 1-spp strips
// (whole rows, then part of a row) on tiles this frame has not touched, fresh ones first, so the
// frame traces exactly W x H samples and no pixel is served twice.
void TileScheduler::fillRemainder(FramePlan& plan, std::int64_t remainder, const std::vector<char>& served) {
  std::vector<char> used = served;
  auto strip = [&](int t, bool restart, int cap) {
    TileRect r = grid_.rect(t);
    std::int64_t m = std::min(remainder, r.pixels());
    int rows = static_cast<int>(m / r.width);
    int rest = static_cast<int>(m - static_cast<std::int64_t>(rows) * r.width);
    if (rows > 0) emit(plan, t, {r.x, r.y, r.width, rows}, 1, restart, cap, rows == r.height);
    if (rest > 0) emit(plan, t, {r.x, r.y + rows, rest, 1}, 1, restart, cap, false);
    remainder -= m;
    used[static_cast<std::size_t>(t)] = 1;
  };
  // 1. Tiles the pass has finished: their sums are fresh, extra samples only help.
  for (int t = 0; t < grid_.count(); ++t)
    if (!inRegion(t)) used[static_cast<std::size_t>(t)] = 1;  // outside the render region
  for (auto it = finished_.rbegin(); it != finished_.rend() && remainder > 0; ++it)
    if (!used[static_cast<std::size_t>(*it)]) strip(*it, false, 0);
  // 2. Tiles still queued. One not yet started restarts its strip pixels (its whole-tile chunk
  //    restarts them again later: those samples are spent, never biased).
  for (std::size_t i = pos_; i < queue_.size() && remainder > 0; ++i) {
    int t = queue_[i];
    if (used[static_cast<std::size_t>(t)]) continue;
    bool prior = static_cast<int>(i) < prioritized_ || !smooth_;
    bool started = pass_[i].started;
    strip(t, !started && prior, !started && !prior ? staleCap_ : 0);
  }
  // 3. Refinement: the tiles the cursor reaches next.
  for (int i = 0; i < grid_.count() && remainder > 0; ++i) {
    int t = static_cast<int>((refineCursor_ + static_cast<std::size_t>(i)) % static_cast<std::size_t>(grid_.count()));
    if (!used[static_cast<std::size_t>(t)]) strip(t, false, 0);
  }
}

// Raises the candidates with the fewest samples in all (history credit counted) to a common level
// L, each by whole samples per pixel, as far as `budget` goes (L at least the lowest + 1, so
// something is served when one sample of the lowest fits). Returns the samples spent.
std::int64_t TileScheduler::waterFill(FramePlan& plan, std::vector<int> order, std::int64_t budget, std::vector<char>& served) {
  if (order.empty() || budget <= 0) return 0;
  std::vector<double> have(static_cast<std::size_t>(grid_.count()));
  for (int t : order) have[static_cast<std::size_t>(t)] = held(t);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return have[static_cast<std::size_t>(a)] < have[static_cast<std::size_t>(b)]; });
  auto cost = [&](double level) {
    std::int64_t c = 0;
    for (int t : order) {
      const double need = std::ceil(level - have[static_cast<std::size_t>(t)]);
      if (need > 0) c += static_cast<std::int64_t>(need) * grid_.rect(t).pixels();
    }
    return c;
  };
  double lo = have[static_cast<std::size_t>(order.front())], hi = lo + 1e6;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (cost(mid) <= budget) lo = mid;
    else hi = mid;
  }
  std::int64_t spent = 0;
  for (int t : order) {
    const int k = static_cast<int>(std::min<double>(std::ceil(lo - have[static_cast<std::size_t>(t)]), 1e6));
    const std::int64_t pixels = grid_.rect(t).pixels();
    if (k <= 0 || spent + pixels * k > budget) continue;
    emit(plan, t, grid_.rect(t), k, false, 0, true);
    served[static_cast<std::size_t>(t)] = 1;
    spent += pixels * k;
  }
  return spent;
}

bool TileScheduler::previewDone() const {
  if (pendingGlobal_) return false;
  return pendingProbe_ || previewPos_ >= preview_.size();
}

FramePlan TileScheduler::previewFrame(int block) {
  FramePlan plan;
  const std::int64_t area = static_cast<std::int64_t>(block) * block;
  auto blocks = [&](int t) {
    const TileRect r = grid_.rect(t);
    return static_cast<std::int64_t>((r.width + block - 1) / block) * ((r.height + block - 1) / block);
  };
  auto serve = [&](int t, int q) {
    const auto i = static_cast<std::size_t>(t);
    TileChunk c;
    c.tile = t;
    c.rect = grid_.rect(t);
    c.quality = q;
    c.sampleBase = nextIndex_[i];
    c.restart = true;
    c.block = block;
    nextIndex_[i] += static_cast<std::uint32_t>(q);
    samples_[i] = q;
    plan.servedTiles.push_back(t);
    plan.chunks.push_back(c);
    plan.samples += blocks(t) * q;
  };
  if (pendingGlobal_) {
    plan.mode = AccumMode::GlobalUpdate;
    for (int t = 0; t < grid_.count(); ++t)
      if (inRegion(t)) serve(t, 1);
    dropPass();
    refineCursor_ = 0;
    pendingGlobal_ = false;
    return plan;
  }
  plan.mode = passActive() ? AccumMode::Incremental : AccumMode::Refinement;
  std::int64_t remaining = (grid_.pixels() + area - 1) / area;
  const int q = std::max<int>(1, static_cast<int>(quality_ / area));
  while (previewPos_ < preview_.size()) {
    const int t = preview_[previewPos_];
    if (blocks(t) * q > remaining && !plan.chunks.empty()) break;
    remaining -= blocks(t) * q;
    serve(t, q);
    previewed_[static_cast<std::size_t>(t)] = 1;
    ++previewPos_;
  }
  return plan;
}

FramePlan TileScheduler::nextFrame(int block) {
  if (block > 1) return previewFrame(block);
  FramePlan plan;
  const std::int64_t budget = grid_.pixels();
  const int n = grid_.count();
  std::vector<char> served(static_cast<std::size_t>(n), 0);

  // With a render region, the region's share of the budget per tile and frame.
  std::int64_t regionPixels = 0;
  for (int t = 0; t < n && !region_.empty(); ++t)
    if (inRegion(t)) regionPixels += grid_.rect(t).pixels();
  const int regionQuality = regionPixels > 0 ? static_cast<int>(std::max<std::int64_t>(1, budget / regionPixels)) : 1;

  if (pendingGlobal_ || pendingProbe_) {
    plan.mode = pendingGlobal_ ? AccumMode::GlobalUpdate : AccumMode::Probe;
    for (int t = 0; t < n; ++t) {
      if (!inRegion(t)) continue;
      if (plan.mode == AccumMode::Probe) {
        // Traced and compared, never accumulated: the tile's sums and indices stay as they are.
        TileChunk c;
        c.tile = t;
        c.rect = grid_.rect(t);
        c.sampleBase = nextIndex_[static_cast<std::size_t>(t)];
        plan.chunks.push_back(c);
        plan.servedTiles.push_back(t);
        plan.samples += c.rect.pixels();
      } else {
        emit(plan, t, grid_.rect(t), regionQuality, true, 0, true);
      }
    }
    if (pendingGlobal_) {
      dropPass();
      refineCursor_ = 0;
    }
    pendingGlobal_ = pendingProbe_ = false;
    return plan;
  }

  std::int64_t remaining = budget;
  plan.mode = passActive() ? AccumMode::Incremental : AccumMode::Refinement;
  if (passActive() && credit_.size() == static_cast<std::size_t>(n) && !finished_.empty()) {
    // Catch-up (verified reuse): tiles this pass finished that hold far fewer samples than the
    // others it finished (their history was rejected: the edit changed them, the others kept
    // theirs) get up to half the budget, raised together from the lowest, so the changed part of
    // the picture converges while the pass goes on testing the other histories instead of
    // waiting for the pass to end. When the edit changed everything (a light), every finished
    // tile is equally fresh and the pass keeps the whole budget to restart the stale rest.
    std::vector<double> have;
    for (int t : finished_) have.push_back(held(t));
    std::nth_element(have.begin(), have.begin() + static_cast<std::ptrdiff_t>(have.size() / 2), have.end());
    const double median = have[have.size() / 2];
    std::vector<int> behind;
    for (int t : finished_)
      if (held(t) < kCatchUpFraction * median) behind.push_back(t);
    remaining -= waterFill(plan, behind, remaining / 2, served);
  }
  while (pos_ < queue_.size()) {
    int t = queue_[pos_];
    PassTile& pt = pass_[pos_];
    std::int64_t pixels = grid_.rect(t).pixels();
    int k = static_cast<int>(std::min<std::int64_t>(pt.need, remaining / pixels));
    if (k <= 0) break;
    bool prior = static_cast<int>(pos_) < prioritized_ || !smooth_;
    emit(plan, t, grid_.rect(t), k, !pt.started && prior, !pt.started && !prior ? staleCap_ : 0, true);
    served[static_cast<std::size_t>(t)] = 1;
    previewed_[static_cast<std::size_t>(t)] = 0;
    pt.started = true;
    pt.need -= k;
    remaining -= pixels * k;
    if (pt.need > 0) break;  // the budget ran out inside this tile; it continues next frame
    finished_.push_back(t);
    ++pos_;
  }
  if (!passActive() && !region_.empty()) {
    // Refinement inside a render region: every region tile once, at the region's share.
    for (int t = 0; t < n; ++t) {
      if (!inRegion(t) || served[static_cast<std::size_t>(t)]) continue;
      std::int64_t pixels = grid_.rect(t).pixels();
      int k = static_cast<int>(std::min<std::int64_t>(regionQuality, remaining / pixels));
      if (k <= 0) break;
      emit(plan, t, grid_.rect(t), k, false, 0, true);
      served[static_cast<std::size_t>(t)] = 1;
      remaining -= pixels * k;
    }
  } else if (!passActive() && credit_.size() == static_cast<std::size_t>(n)) {
    // Refinement with credits: the whole budget raises the tiles with the fewest samples in all.
    std::vector<int> candidates;
    for (int t = 0; t < n; ++t)
      if (!served[static_cast<std::size_t>(t)]) candidates.push_back(t);
    remaining -= waterFill(plan, candidates, remaining, served);
  } else if (!passActive()) {
    // Continuous refinement: every tile at 1 spp, round robin, so that a full frame is exactly
    // one pass over the image.
    int visited = 0;
    for (; visited < n; ++visited) {
      int t = static_cast<int>((refineCursor_ + static_cast<std::size_t>(visited)) % static_cast<std::size_t>(n));
      if (served[static_cast<std::size_t>(t)]) continue;
      std::int64_t pixels = grid_.rect(t).pixels();
      if (pixels > remaining) break;
      emit(plan, t, grid_.rect(t), 1, false, 0, true);
      served[static_cast<std::size_t>(t)] = 1;
      remaining -= pixels;
    }
    refineCursor_ = (refineCursor_ + static_cast<std::size_t>(visited)) % static_cast<std::size_t>(n);
  }
  if (remaining > 0) fillRemainder(plan, remaining, served);
  return plan;
}

}  // namespace retile
