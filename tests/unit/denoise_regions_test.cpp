// The denoised regions' growth on hand-made tile sequences, without a GPU.
#include <gtest/gtest.h>

#include <algorithm>

#include "schedule/denoise_regions.h"
#include "schedule/policies.h"

namespace retile {
namespace {

// Plays a spiral pass from `centre`, `perFrame` tiles a frame, and returns every frame's decision.
std::vector<DenoiseFrame> playSpiral(DenoiseRegions& r, const TileGrid& g, int centre, int perFrame, double threshold) {
  std::vector<int> order = spiralOrder(g, centre);
  std::vector<char> started(static_cast<std::size_t>(g.count()), 0), grows(static_cast<std::size_t>(g.count()), 1);
  std::vector<DenoiseFrame> frames;
  r.restart();
  std::uint64_t frame = 0;
  for (std::size_t i = 0; i < order.size();) {
    for (int k = 0; k < perFrame && i < order.size(); ++k) started[static_cast<std::size_t>(order[i++])] = 1;
    frames.push_back(r.incremental(started, grows, threshold, i == order.size(), ++frame));
  }
  return frames;
}

TEST(DenoiseRegions, GrowsOnlyPastTheThresholdOnEitherAxisAndCoversTheFrameAtTheEnd) {
  TileGrid g(320, 96, 16);  // 20 x 6 tiles: the height reaches the frame long before the width
  DenoiseRegions r;
  r.reset(g);
  auto frames = playSpiral(r, g, g.index(10, 3), 3, 0.125);  // 40 px of the width, 12 of the height
  std::vector<TileRect> pushed;
  for (const DenoiseFrame& f : frames)
    if (f.filter) pushed.push_back(f.domain);
  ASSERT_GE(pushed.size(), 3u) << "the region grew several times";
  for (std::size_t i = 1; i < pushed.size(); ++i) {
    bool grewW = pushed[i].width - pushed[i - 1].width > 40, grewH = pushed[i].height - pushed[i - 1].height > 12;
    bool last = i + 1 == pushed.size();  // when the pass re-rendered its last tile
    EXPECT_TRUE(grewW || grewH || last) << "resize " << i << ": " << pushed[i - 1].width << "x" << pushed[i - 1].height << " -> "
                                        << pushed[i].width << "x" << pushed[i].height;
  }
  EXPECT_EQ(pushed.back().width, 320);
  EXPECT_EQ(pushed.back().height, 96) << "the last region is the whole frame";
  EXPECT_EQ(frames.back().regions.size(), pushed.size()) << "every resize stacks";
}

TEST(DenoiseRegions, OlderResultsStayOnTopAndOnlyTheNewRingTakesTheNewResult) {
  TileGrid g(160, 160, 16);
  DenoiseRegions r;
  r.reset(g);
  auto frames = playSpiral(r, g, g.index(5, 5), 4, 0.1);
  std::vector<int> firstRegion(static_cast<std::size_t>(g.count()), -1);
  for (const DenoiseFrame& f : frames) {
    for (int t = 0; t < g.count(); ++t) {
      auto i = static_cast<std::size_t>(t);
      if (f.source[i] != TileSource::Region) continue;
      if (firstRegion[i] < 0) {
        firstRegion[i] = f.region[i];
        EXPECT_TRUE(f.write[i]) << "a tile takes a result when a region first covers it";
        EXPECT_EQ(f.region[i], static_cast<int>(f.regions.size()) - 1) << "the newest region";
      } else {
        EXPECT_EQ(f.region[i], firstRegion[i]) << "tile " << t << " keeps its older result";
        EXPECT_FALSE(f.write[i]);
      }
      TileRect tr = g.rect(t);
      const TileRect& rr = f.regions[static_cast<std::size_t>(f.region[i])].rect;
      EXPECT_TRUE(tr.x >= rr.x && tr.y >= rr.y && tr.x + tr.width <= rr.x + rr.width && tr.y + tr.height <= rr.y + rr.height);
    }
  }
  // Every tile ended in some region (the pass covered the frame).
  for (int t = 0; t < g.count(); ++t) EXPECT_GE(firstRegion[static_cast<std::size_t>(t)], 0) << t;
}

TEST(DenoiseRegions, TilesNotYetReRenderedTakeNoPartAndShowTheirPreviousResult) {
  TileGrid g(64, 64, 16);
  DenoiseRegions r;
  r.reset(g);
  r.wholeFrame(1);  // refinement: every tile denoised
  r.restart();      // an edit
  std::vector<char> started(16, 0), grows(16, 1);
  started[static_cast<std::size_t>(g.index(0, 0))] = 1;
  started[static_cast<std::size_t>(g.index(2, 0))] = 1;  // a second seed two tiles away
  DenoiseFrame f = r.incremental(started, grows, 1.0, false, 2);
  ASSERT_TRUE(f.filter);
  EXPECT_EQ(f.domain.width, 48) << "one rectangle spans both seeds";
  int between = g.index(1, 0);
  EXPECT_FALSE(f.filtered[static_cast<std::size_t>(between)]) << "inside the domain but not re-rendered";
  EXPECT_EQ(f.source[static_cast<std::size_t>(between)], TileSource::Previous) << "its denoised result from before the edit";
  EXPECT_TRUE(f.filtered[static_cast<std::size_t>(g.index(2, 0))]);
  EXPECT_EQ(f.source[static_cast<std::size_t>(g.index(0, 1))], TileSource::Previous);
  // Once re-rendered outside any region, it shows its fresh samples.
  started[static_cast<std::size_t>(g.index(3, 3))] = 1;
  DenoiseFrame next = r.incremental(started, grows, 1.0, false, 3);
  EXPECT_EQ(next.source[static_cast<std::size_t>(g.index(3, 3))], TileSource::Fresh);
}

TEST(DenoiseRegions, ANewPointOfChangeRestartsTheStack) {
  TileGrid g(128, 128, 16);
  DenoiseRegions r;
  r.reset(g);
  auto a = playSpiral(r, g, g.index(1, 1), 6, 0.125);
  ASSERT_GT(a.back().regions.size(), 1u);
  auto b = playSpiral(r, g, g.index(6, 6), 1, 0.125);
  EXPECT_EQ(b.front().regions.size(), 1u) << "restart: one region, around the new point";
  EXPECT_EQ(b.front().domain.x, 96);
  EXPECT_EQ(b.front().domain.width, 16);
}

TEST(DenoiseRegions, ThresholdZeroGrowsEveryFrameAndAFullFrameThresholdOnlyAtTheEnd) {
  TileGrid g(128, 128, 16);
  DenoiseRegions r;
  r.reset(g);
  // Threshold 0: a re-size on every frame the re-rendered tiles' box grew, and at the end.
  std::vector<int> order = spiralOrder(g, g.index(4, 4));
  auto zero = playSpiral(r, g, g.index(4, 4), 2, 0);
  TileRect box{};
  int expected = 0, got = 0;
  for (std::size_t f = 0; f < zero.size(); ++f) {
    int x0 = 1 << 20, y0 = 1 << 20, x1 = 0, y1 = 0;
    for (std::size_t i = 0; i < std::min(order.size(), 2 * (f + 1)); ++i) {
      TileRect t = g.rect(order[i]);
      x0 = std::min(x0, t.x), y0 = std::min(y0, t.y), x1 = std::max(x1, t.x + t.width), y1 = std::max(y1, t.y + t.height);
    }
    bool grew = x1 - x0 > box.width || y1 - y0 > box.height;
    if (grew) box = {x0, y0, x1 - x0, y1 - y0};
    expected += grew || f + 1 == zero.size();
    got += zero[f].filter;
    if (grew) {
      EXPECT_TRUE(zero[f].filter) << "frame " << f;
    }
  }
  EXPECT_EQ(got, expected);
  auto full = playSpiral(r, g, g.index(4, 4), 2, 1.0);
  int pushes = 0;
  for (const DenoiseFrame& f : full) pushes += f.filter;
  EXPECT_EQ(pushes, 2) << "the first region, then the whole frame when the pass ends";
  EXPECT_EQ(full.back().regions.back().rect.width, 128);
}

TEST(DenoiseRegions, RegionsAtTheBorderAndTinyAndHugeFrames) {
  for (auto [w, h] : {std::pair{1, 1}, std::pair{3840, 2160}, std::pair{100, 7}}) {
    SCOPED_TRACE(testing::Message() << w << "x" << h);
    TileGrid g(w, h, 32);
    DenoiseRegions r;
    r.reset(g);
    auto frames = playSpiral(r, g, g.count() - 1, std::max(1, g.count() / 7), 0.1);  // from the corner
    const DenoiseFrame& last = frames.back();
    ASSERT_FALSE(last.regions.empty());
    const TileRect& outer = last.regions.back().rect;
    EXPECT_EQ(outer.width, w);
    EXPECT_EQ(outer.height, h);
    for (const DenoiseRegion& reg : last.regions) {
      EXPECT_GE(reg.rect.x, 0);
      EXPECT_GE(reg.rect.y, 0);
      EXPECT_LE(reg.rect.x + reg.rect.width, w);
      EXPECT_LE(reg.rect.y + reg.rect.height, h);
    }
    DenoiseFrame whole = r.wholeFrame(99);
    EXPECT_TRUE(whole.wholeFrame);
    EXPECT_EQ(whole.domain.width, w);
    EXPECT_TRUE(std::all_of(whole.write.begin(), whole.write.end(), [](char c) { return c; }));
  }
}

TEST(DenoiseRegions, GrowsOnlyOverTheTilesItIsToldTo) {
  // Indirection: the prioritized tiles span the region, not every re-rendered tile.
  TileGrid g(128, 64, 16);
  DenoiseRegions r;
  r.reset(g);
  r.restart();
  std::vector<char> started(static_cast<std::size_t>(g.count()), 1), grows(static_cast<std::size_t>(g.count()), 0);
  grows[static_cast<std::size_t>(g.index(2, 1))] = grows[static_cast<std::size_t>(g.index(3, 2))] = 1;
  DenoiseFrame f = r.incremental(started, grows, 1.0, false, 1);
  EXPECT_EQ(f.domain.x, 32);
  EXPECT_EQ(f.domain.y, 16);
  EXPECT_EQ(f.domain.width, 32);
  EXPECT_EQ(f.domain.height, 32);
}

}  // namespace
}  // namespace retile
