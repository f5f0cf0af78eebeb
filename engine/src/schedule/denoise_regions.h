// Where the denoiser runs and what each tile of the displayed image shows (../shared/METHOD.md,
// "spiral-denoised"). After an edit, the denoised region is the bounding rectangle of the tiles
// re-rendered since (for indirection: of the prioritized ones). Its domain is re-sized only when
// its width or its height has grown by more than a threshold since the last re-size, and once more
// when the pass has re-rendered its last tile (so its outer ring is denoised too); each re-size
// denoises the new domain once and stacks it. Older, smaller
// results stay on top: a tile shows the result of the first region that covered it after it was
// re-rendered, so only the new outer ring shows the new result. Tiles inside a domain that the
// pass has not re-rendered yet take no part in the filter (their old samples would bleed into the
// fresh ones) and keep showing what they showed until a later region covers them: their last
// denoised result, if the layer holds one for their samples, else their samples. This is also what
// several seeds (focus points) do: one rectangle spans every seed's re-rendered tiles, and only
// those are filtered and shown denoised. A new point of change restarts the stack; a global
// update and continuous refinement denoise the whole frame every frame.
//
// Pure CPU, no Vulkan; owned by the render thread (the RenderSession's).
#pragma once

#include <cstdint>
#include <vector>

#include "schedule/tile_grid.h"

namespace retile {

struct DenoiseRegion {
  TileRect rect;            // pixels
  std::uint64_t frame = 0;  // the frame that denoised it
};

// What a tile shows this frame.
enum class TileSource : std::uint8_t {
  Stale,     // the raw accumulation, not re-rendered by the current pass
  Previous,  // not re-rendered either: the denoised result its samples had before the pass
  Fresh,     // the raw accumulation, re-rendered, in no region yet
  Region,    // the denoised result of region `region[tile]`
};

struct DenoiseFrame {
  bool filter = false;  // run the denoiser over `domain` this frame
  TileRect domain;
  std::vector<TileSource> source;      // per tile
  std::vector<int> region;             // per tile: the region index for Region tiles, else -1
  std::vector<char> write;             // per tile: takes this frame's result (its region is the new one)
  std::vector<char> filtered;          // per tile: takes part in this frame's filter
  std::vector<DenoiseRegion> regions;  // the stack, oldest (innermost) first
  bool wholeFrame = false;
};

class DenoiseRegions {
 public:
  // A new grid (resize, new T): nothing is denoised yet (the layer starts empty).
  void reset(const TileGrid& grid);
  // A new pass (a new point of change): the stack restarts.
  void restart();
  // Global update or continuous refinement: the whole frame, denoised this frame.
  DenoiseFrame wholeFrame(std::uint64_t frame);
  // An incremental frame. `started`: per tile, re-rendered by the pass so far (or by a preview not
  // yet followed by a full-resolution pass: TileScheduler::startedTiles); `grows`: per tile,
  // counts for the region's rectangle (all tiles, or the prioritized ones). `threshold`: a share
  // of the image's width (for the region's width) and height (for its height).
  // `passComplete`: the pass has started every tile it will re-render.
  DenoiseFrame incremental(const std::vector<char>& started, const std::vector<char>& grows, double threshold, bool passComplete,
                           std::uint64_t frame);
  // A frame that accumulates nothing (the change probe): the display stays as it was.
  DenoiseFrame unchanged() const;

 private:
  DenoiseFrame describe(bool filter, const TileRect& domain, const std::vector<char>& started) const;

  TileGrid grid_;
  std::vector<DenoiseRegion> stack_;
  std::vector<int> regionOf_;     // per tile, -1: none
  std::vector<char> started_;     // the last incremental frame's
  std::vector<char> written_;     // tiles that took the newest region's result this frame
  std::vector<char> layerValid_;  // the layer holds a denoised result of the tile's samples as they are
  bool whole_ = false;
};

}  // namespace retile
