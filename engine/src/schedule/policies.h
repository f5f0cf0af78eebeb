// Tile orderings of the priority policies (../shared/METHOD.md). Pure functions of plain values:
// no GPU, no scene; the render session feeds them the point of change, focus points and counters.
#pragma once

#include <cstdint>
#include <vector>

#include "schedule/tile_grid.h"

namespace retile {

// Every tile once, ring by ring of Chebyshev distance from `center`; each ring walked clockwise
// from its top-left corner (a square spiral). Distances never decrease along the order.
std::vector<int> spiralOrder(const TileGrid& grid, int center);

// Several spirals (the point of change first, then focus points) take turns: each contributes
// its next tile not yet taken. A tile's position reflects min(distance to any centre).
std::vector<int> interleavedSpirals(const TileGrid& grid, const std::vector<int>& centers);

// What the tracer saw of the selected object, per tile, summed over the gathering frames.
struct IndirectionCounts {
  std::vector<std::uint32_t> direct;      // primary hits on the object
  std::vector<std::uint32_t> reflection;  // later path vertices on it, weighted (maxBounces+1)/d
  std::vector<std::uint32_t> shadow;      // shadow rays it blocked
  bool empty() const { return direct.empty(); }
};

enum class TileClass : std::uint8_t { High = 0, Middle = 1, Low = 2, Rest = 3 };

struct IndirectionPlan {
  std::vector<int> order;          // high, middle, low, then the rest
  std::vector<TileClass> classes;  // per tile
  std::vector<int> high;           // the high tiles (their count drives automatic Q)
  int prioritized = 0;             // tiles in the high, middle and low classes
};

// Classes: high = any direct hit, or reflection or shadow count > M/3 (M the largest per-tile
// reflection-or-shadow count); middle = above M/6, or any shadow above M/12 (shadows never fall
// to low: users missed them); low = above M/12; the rest after. Within a class, by spiral distance
// from `center`; the rest follows `restOrder` (a spiral, or focus spirals).
IndirectionPlan indirectionPlan(const TileGrid& grid, const IndirectionCounts& counts, int center, const std::vector<int>& restOrder);

// The largest Q at which all `tiles` fit into one frame's budget of grid.pixels() samples;
// never below 1 (a screen-filling object) and never above `maxQ`.
int automaticQuality(const TileGrid& grid, const std::vector<int>& tiles, int maxQ);

// High tiles follow the object's screen motion by replacement: each tile whose centre, moved by
// `motion` pixels (the total since the tiles were classified, so that a slow drag moves them
// too), lands in another tile is replaced by that tile. Duplicates merge, tiles moved
// off screen drop out; the set never grows.
std::vector<int> followMotion(const TileGrid& grid, const std::vector<int>& tiles, Vec2 motion);

// Tiles by decreasing `difference` (ties by spiral order from `center`).
std::vector<int> changeOrder(const TileGrid& grid, const std::vector<float>& difference, int center);

}  // namespace retile
