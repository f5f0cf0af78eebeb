// Plans each frame's tiles on the exact same-time budget: every frame traces exactly W x H
// samples, whatever the mode, T or Q. Owns the accumulator's three modes of METHOD.md:
//   global update  - every tile at 1 spp, sums restarted (camera change, resize, global method)
//   incremental    - the queued tiles at Q spp, restarted on their first chunk of the pass
//   refinement     - every tile at 1 spp added to its sum, once the queue ran empty
// plus the change policy's probe frame (every tile at 1 spp, traced but not accumulated).
// Pure CPU; owned by the render thread.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "schedule/tile_grid.h"

namespace retile {

enum class AccumMode { GlobalUpdate, Incremental, Refinement, Probe };
const char* accumModeName(AccumMode m);

// A rectangle (a whole tile, or a strip of one) and how it is traced and accumulated this frame.
struct TileChunk {
  int tile = 0;
  TileRect rect;
  int quality = 1;
  std::uint32_t sampleBase = 0;  // sample indices sampleBase .. sampleBase + quality - 1
  bool restart = false;          // replace the pixels' sums
  int capStale = 0;              // > 0: first scale the sums down to at most this many samples
  int block = 1;                 // > 1: a preview's chunk, a sample per block x block pixels (TileWork::block)
};

struct FramePlan {
  AccumMode mode = AccumMode::Refinement;
  std::vector<TileChunk> chunks;  // disjoint: no pixel appears twice in a frame
  std::int64_t samples = 0;       // always grid.pixels()
  std::vector<int> servedTiles;   // tiles with at least one chunk, in serving order
};

class TileScheduler {
 public:
  static constexpr double kCatchUpFraction = 0.5;

  TileScheduler() = default;
  explicit TileScheduler(const TileGrid& grid) { reset(grid); }

  // A new grid (resize, new T): everything restarts with a global update.
  void reset(const TileGrid& grid);
  // The same pixels cut into other tiles (a new T): the accumulation stays, each new tile taking
  // the samples its pixels hold and sample indices none of them has seen. A pass under way ends
  // (its order named the old tiles): refinement follows. Other pixels reset as reset() does.
  void regrid(const TileGrid& grid);
  // The next frame restarts every tile at 1 spp; refinement follows.
  void globalUpdate();
  // The next frame is a probe (traced, not accumulated); the caller then starts a pass.
  void probe();
  // Starts an incremental pass (a new edit restarts the queue from its point of change). Tiles
  // of `order` (each at most once; tiles left out are not served by the pass) get `quality` spp
  // each. The first `prioritized` restart their sums; with `smooth`, the others keep their stale
  // sums capped at `staleCap` samples per pixel and add fresh ones, else they restart too.
  void startPass(std::vector<int> order, int quality, int prioritized, bool smooth, int staleCap);

  // The tiles a preview of the pass just started re-renders, in order: those the edit touched
  // (where the object was and is). The rest keep what they show until the pass reaches them at
  // full resolution, as the method keeps them; a preview that restarted them too would throw the
  // converged image away for a coarse one. startPass clears it. A tile a preview restarted holds
  // samples of the edit (coarse ones): it counts as started (startedTiles, which the denoiser's
  // region grows over) in later passes too, until a pass re-renders it at full resolution, so
  // that the trail of a drag's previews is denoised rather than shown raw.
  void setPreviewTiles(const std::vector<int>& tiles);
  // `block` > 1: a preview while edits come (previewFrame); else a frame of the method.
  FramePlan nextFrame(int block = 1);
  // Whether a preview has anything left to show: a global update, or preview tiles (previews
  // restart tiles only: coarse samples added to a sum would blur it for good).
  bool previewDone() const;
  // A render region: only the marked tiles are traced (empty: every tile). Frames then spend the
  // budget on the region (about W x H / region pixels spp per tile, each tile once per frame,
  // so a frame traces at most W x H samples); passes skip tiles outside it.
  void setRegion(std::vector<char> tiles);
  // Samples per pixel a tile holds beyond those counted since its restart (verified reuse: the
  // history it keeps). With credits, continuous refinement serves the tiles with the fewest
  // samples in all first, up to a common level (water-filling), instead of one sample to each:
  // tiles whose history was rejected catch up with the ones that kept theirs. During a pass,
  // tiles it finished with fewer than kCatchUpFraction of the median samples in all of the tiles
  // it finished get up to half of each frame's budget the same way (catch-up). Empty: none.
  void setCredit(std::vector<double> credit) { credit_ = std::move(credit); }
  bool inRegion(int tile) const { return region_.empty() || region_[static_cast<std::size_t>(tile)]; }

  const TileGrid& grid() const { return grid_; }
  AccumMode mode() const;
  bool passActive() const { return pos_ < queue_.size(); }
  std::size_t queueLength() const { return queue_.size(); }
  std::size_t queueServed() const { return pos_; }  // tiles of the pass finished
  int quality() const { return quality_; }
  // Per tile: mean samples per pixel accumulated since its last restart.
  const std::vector<double>& tileSamples() const { return samples_; }
  // Per tile: 1 for the head of the queue falling linearly to 0 at its end; -1 when unqueued.
  std::vector<float> priorities() const;
  // Per tile: 1 when the current pass has started re-rendering it, or a preview (of this pass or
  // an earlier one) restarted it and no pass has served it at full resolution since.
  std::vector<char> startedTiles() const;

 private:
  struct PassTile {
    int need = 0;  // spp still to serve to the whole tile
    bool started = false;
  };
  void emit(FramePlan& plan, int tile, TileRect rect, int quality, bool restart, int cap, bool wholeTile);
  // A frame of at most W x H / block^2 samples, each standing for a block of pixels: the global update at
  // 1 sample per block, or the preview tiles restarted at Q / block^2 per block (the pass's queue
  // does not advance). The caller plans the same edit again at full resolution once the preview
  // ends.
  FramePlan previewFrame(int block);
  std::int64_t waterFill(FramePlan& plan, std::vector<int> order, std::int64_t budget, std::vector<char>& served);
  // Samples per pixel tile t holds, its kept history's credit counted.
  double held(int t) const {
    const auto i = static_cast<std::size_t>(t);
    return samples_[i] + (i < credit_.size() ? credit_[i] : 0.0);
  }
  std::vector<char> region_;
  // Ends the pass and forgets its previews and every preview mark (a global update, a new grid).
  void dropPass();
  // `tiles` in order, each once, those off the grid or outside the render region left out.
  std::vector<int> uniqueInRegion(const std::vector<int>& tiles) const;
  void fillRemainder(FramePlan& plan, std::int64_t remainder, const std::vector<char>& served);

  TileGrid grid_;
  bool pendingGlobal_ = true;
  bool pendingProbe_ = false;
  std::vector<int> queue_;
  std::vector<PassTile> pass_;  // per queue position
  std::size_t pos_ = 0;
  int quality_ = 1;
  int prioritized_ = 0;
  bool smooth_ = false;
  int staleCap_ = 0;
  std::size_t refineCursor_ = 0;
  std::vector<double> samples_;
  std::vector<double> credit_;
  std::vector<std::uint32_t> nextIndex_;
  std::vector<int> finished_;  // tiles of the pass already at quality, most recent last
  std::vector<int> preview_;   // setPreviewTiles
  std::size_t previewPos_ = 0;
  std::vector<char> previewed_;  // per tile: a preview restarted it since a full-resolution pass last served it
};

}  // namespace retile
