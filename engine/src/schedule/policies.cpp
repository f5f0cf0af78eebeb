#include "schedule/policies.h"

#include <algorithm>
#include <numeric>

namespace retile {

std::vector<int> spiralOrder(const TileGrid& grid, int center) {
  std::vector<int> order;
  order.reserve(static_cast<std::size_t>(grid.count()));
  int cx = grid.col(center), cy = grid.row(center);
  int maxRing = std::max({cx, cy, grid.cols() - 1 - cx, grid.rows() - 1 - cy});
  auto visit = [&](int c, int r) {
    if (grid.contains(c, r)) order.push_back(grid.index(c, r));
  };
  visit(cx, cy);
  for (int ring = 1; ring <= maxRing; ++ring) {
    int x0 = cx - ring, x1 = cx + ring, y0 = cy - ring, y1 = cy + ring;
    for (int c = x0; c <= x1; ++c) visit(c, y0);      // top, left to right
    for (int r = y0 + 1; r <= y1; ++r) visit(x1, r);  // right, downwards
    for (int c = x1 - 1; c >= x0; --c) visit(c, y1);  // bottom, right to left
    for (int r = y1 - 1; r > y0; --r) visit(x0, r);   // left, upwards
  }
  return order;
}

std::vector<int> interleavedSpirals(const TileGrid& grid, const std::vector<int>& centers) {
  if (centers.empty()) return spiralOrder(grid, grid.index(grid.cols() / 2, grid.rows() / 2));
  std::vector<std::vector<int>> spirals;
  for (int c : centers) spirals.push_back(spiralOrder(grid, c));
  std::vector<char> taken(static_cast<std::size_t>(grid.count()), 0);
  std::vector<std::size_t> next(spirals.size(), 0);
  std::vector<int> order;
  order.reserve(static_cast<std::size_t>(grid.count()));
  while (order.size() < static_cast<std::size_t>(grid.count())) {
    for (std::size_t s = 0; s < spirals.size(); ++s) {
      auto& i = next[s];
      while (i < spirals[s].size() && taken[static_cast<std::size_t>(spirals[s][i])]) ++i;
      if (i == spirals[s].size()) continue;
      int t = spirals[s][i++];
      taken[static_cast<std::size_t>(t)] = 1;
      order.push_back(t);
    }
  }
  return order;
}

IndirectionPlan indirectionPlan(const TileGrid& grid, const IndirectionCounts& counts, int center, const std::vector<int>& restOrder) {
  auto n = static_cast<std::size_t>(grid.count());
  IndirectionPlan plan;
  plan.classes.assign(n, TileClass::Rest);
  auto at = [](const std::vector<std::uint32_t>& v, std::size_t i) { return i < v.size() ? v[i] : 0u; };
  std::uint32_t m = 0;
  for (std::size_t t = 0; t < n; ++t) m = std::max({m, at(counts.reflection, t), at(counts.shadow, t)});
  const double third = m / 3.0, sixth = m / 6.0, twelfth = m / 12.0;
  for (std::size_t t = 0; t < n; ++t) {
    double refl = at(counts.reflection, t), sh = at(counts.shadow, t);
    double c = std::max(refl, sh);
    TileClass k = TileClass::Rest;
    if (at(counts.direct, t) > 0 || c > third) k = TileClass::High;
    else if (c > sixth || sh > twelfth) k = TileClass::Middle;
    else if (c > twelfth) k = TileClass::Low;
    plan.classes[t] = k;
  }
  for (TileClass k : {TileClass::High, TileClass::Middle, TileClass::Low})
    for (int t : spiralOrder(grid, center))
      if (plan.classes[static_cast<std::size_t>(t)] == k) {
        plan.order.push_back(t);
        if (k == TileClass::High) plan.high.push_back(t);
      }
  plan.prioritized = static_cast<int>(plan.order.size());
  for (int t : restOrder)
    if (plan.classes[static_cast<std::size_t>(t)] == TileClass::Rest) plan.order.push_back(t);
  return plan;
}

int automaticQuality(const TileGrid& grid, const std::vector<int>& tiles, int maxQ) {
  std::int64_t pixels = 0;
  for (int t : tiles) pixels += grid.rect(t).pixels();
  if (pixels <= 0) return std::max(1, maxQ);
  return static_cast<int>(std::clamp<std::int64_t>(grid.pixels() / pixels, 1, std::max(1, maxQ)));
}

std::vector<int> followMotion(const TileGrid& grid, const std::vector<int>& tiles, Vec2 motion) {
  std::vector<int> out;
  out.reserve(tiles.size());
  for (int t : tiles) {
    TileRect r = grid.rect(t);
    Vec2 c{static_cast<float>(r.x) + r.width * 0.5f + motion.x, static_cast<float>(r.y) + r.height * 0.5f + motion.y};
    if (c.x < 0 || c.y < 0 || c.x >= static_cast<float>(grid.width()) || c.y >= static_cast<float>(grid.height())) continue;
    int landed = grid.tileAt(c);
    if (std::find(out.begin(), out.end(), landed) == out.end()) out.push_back(landed);
  }
  return out;
}

std::vector<int> changeOrder(const TileGrid& grid, const std::vector<float>& difference, int center) {
  // NaN would break the sort's ordering: a tile without a usable difference ranks as unchanged.
  std::vector<float> d(static_cast<std::size_t>(grid.count()), 0.0f);
  for (std::size_t i = 0; i < d.size() && i < difference.size(); ++i) d[i] = difference[i] == difference[i] ? difference[i] : 0.0f;
  std::vector<int> order = spiralOrder(grid, center);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return d[static_cast<std::size_t>(a)] > d[static_cast<std::size_t>(b)]; });
  return order;
}

}  // namespace retile
