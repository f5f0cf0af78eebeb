// The tile grid over an image: ceil(W/T) x ceil(H/T) square tiles, edge tiles partial, so every
// pixel belongs to exactly one tile (the prototype rounded down and never rendered the bottom
// rows). A plain value; any thread.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "retile/math.h"

namespace retile {

struct TileRect {
  int x = 0, y = 0, width = 0, height = 0;
  std::int64_t pixels() const { return static_cast<std::int64_t>(width) * height; }
};

class TileGrid {
 public:
  TileGrid() = default;
  TileGrid(int width, int height, int tileSize)
      : width_(std::max(width, 1)),
        height_(std::max(height, 1)),
        tile_(std::max(tileSize, 1)),
        cols_((width_ + tile_ - 1) / tile_),
        rows_((height_ + tile_ - 1) / tile_) {}

  int width() const { return width_; }
  int height() const { return height_; }
  int tileSize() const { return tile_; }
  int cols() const { return cols_; }
  int rows() const { return rows_; }
  int count() const { return cols_ * rows_; }
  std::int64_t pixels() const { return static_cast<std::int64_t>(width_) * height_; }

  int index(int col, int row) const { return row * cols_ + col; }
  int col(int tile) const { return tile % cols_; }
  int row(int tile) const { return tile / cols_; }
  bool contains(int col, int row) const { return col >= 0 && row >= 0 && col < cols_ && row < rows_; }

  TileRect rect(int tile) const {
    int x = col(tile) * tile_, y = row(tile) * tile_;
    return {x, y, std::min(tile_, width_ - x), std::min(tile_, height_ - y)};
  }
  // The tile holding an image position, clamped into the grid (positions off screen map to the
  // nearest edge tile, so a point of change behind the camera still orders the queue).
  int tileAt(Vec2 p) const {
    int c = std::clamp(static_cast<int>(std::floor(p.x / static_cast<float>(tile_))), 0, cols_ - 1);
    int r = std::clamp(static_cast<int>(std::floor(p.y / static_cast<float>(tile_))), 0, rows_ - 1);
    if (!(p.x == p.x) || !(p.y == p.y)) return index(cols_ / 2, rows_ / 2);  // NaN: the centre
    return index(c, r);
  }
  // Chebyshev distance in tiles: max(|dx|, |dy|).
  int chebyshev(int a, int b) const { return std::max(std::abs(col(a) - col(b)), std::abs(row(a) - row(b))); }

  bool operator==(const TileGrid& o) const { return width_ == o.width_ && height_ == o.height_ && tile_ == o.tile_; }

 private:
  int width_ = 1, height_ = 1, tile_ = 16, cols_ = 1, rows_ = 1;
};

}  // namespace retile
