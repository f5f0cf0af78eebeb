#include "schedule/denoise_regions.h"

#include <algorithm>

namespace retile {

void DenoiseRegions::reset(const TileGrid& grid) {
  grid_ = grid;
  layerValid_.assign(static_cast<std::size_t>(grid_.count()), 0);
  restart();
}

void DenoiseRegions::restart() {
  stack_.clear();
  regionOf_.assign(static_cast<std::size_t>(grid_.count()), -1);
  started_.assign(static_cast<std::size_t>(grid_.count()), 0);
  written_.assign(static_cast<std::size_t>(grid_.count()), 0);
  whole_ = false;
}

DenoiseFrame DenoiseRegions::describe(bool filter, const TileRect& domain, const std::vector<char>& started) const {
  const auto n = static_cast<std::size_t>(grid_.count());
  DenoiseFrame f;
  f.filter = filter;
  f.domain = domain;
  f.regions = stack_;
  f.wholeFrame = whole_;
  f.source.assign(n, TileSource::Stale);
  f.region = regionOf_;
  f.write = written_;
  f.filtered.assign(n, 0);
  for (std::size_t t = 0; t < n; ++t) {
    if (regionOf_[t] >= 0) f.source[t] = TileSource::Region;
    else if (t < started.size() && started[t]) f.source[t] = TileSource::Fresh;
    else if (layerValid_[t]) f.source[t] = TileSource::Previous;
    f.filtered[t] = filter && (whole_ || (t < started.size() && started[t]));
  }
  return f;
}

DenoiseFrame DenoiseRegions::wholeFrame(std::uint64_t frame) {
  const auto n = static_cast<std::size_t>(grid_.count());
  stack_ = {DenoiseRegion{TileRect{0, 0, grid_.width(), grid_.height()}, frame}};
  regionOf_.assign(n, 0);
  started_.assign(n, 1);
  written_.assign(n, 1);
  layerValid_.assign(n, 1);
  whole_ = true;
  return describe(true, stack_.front().rect, started_);
}

DenoiseFrame DenoiseRegions::incremental(const std::vector<char>& started, const std::vector<char>& grows, double threshold,
                                         bool passComplete, std::uint64_t frame) {
  const auto n = static_cast<std::size_t>(grid_.count());
  if (whole_) restart();  // the first incremental frame after refinement: a pass began
  started_.assign(n, 0);
  for (std::size_t t = 0; t < n && t < started.size(); ++t) started_[t] = started[t];
  written_.assign(n, 0);
  // A re-rendered tile's samples changed: its old denoised result no longer describes them.
  for (std::size_t t = 0; t < n; ++t)
    if (started_[t] && regionOf_[t] < 0) layerValid_[t] = 0;

  // The bounding rectangle of the re-rendered tiles that grow the region.
  int x0 = grid_.width(), y0 = grid_.height(), x1 = 0, y1 = 0;
  bool uncovered = false;  // a re-rendered tile that grows the region is in no region yet
  for (std::size_t t = 0; t < n; ++t) {
    if (!started_[t] || !(t < grows.size() && grows[t])) continue;
    uncovered = uncovered || regionOf_[t] < 0;
    TileRect r = grid_.rect(static_cast<int>(t));
    x0 = std::min(x0, r.x);
    y0 = std::min(y0, r.y);
    x1 = std::max(x1, r.x + r.width);
    y1 = std::max(y1, r.y + r.height);
  }
  if (x1 <= x0 || y1 <= y0) return describe(false, {}, started_);
  TileRect box{x0, y0, x1 - x0, y1 - y0};

  bool push = stack_.empty();
  if (!push) {
    const TileRect& top = stack_.back().rect;
    const double share = std::max(threshold, 0.0);
    bool grew = box.width - top.width > share * grid_.width() || box.height - top.height > share * grid_.height();
    push = grew || (passComplete && uncovered);
  }
  if (!push) return describe(false, {}, started_);

  const int index = static_cast<int>(stack_.size());
  stack_.push_back({box, frame});
  for (std::size_t t = 0; t < n; ++t) {
    if (!started_[t] || regionOf_[t] >= 0) continue;
    TileRect r = grid_.rect(static_cast<int>(t));
    if (r.x >= box.x && r.y >= box.y && r.x + r.width <= box.x + box.width && r.y + r.height <= box.y + box.height) {
      regionOf_[t] = index;
      written_[t] = 1;
      layerValid_[t] = 1;
    }
  }
  return describe(true, box, started_);
}

DenoiseFrame DenoiseRegions::unchanged() const {
  DenoiseFrame f = describe(false, {}, started_);
  std::fill(f.write.begin(), f.write.end(), 0);
  return f;
}

}  // namespace retile
