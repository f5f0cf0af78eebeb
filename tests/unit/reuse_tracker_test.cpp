// Verified reuse's per-tile state machine (schedule/reuse_tracker.h) without a GPU: which plans
// start a history and with how much credit, what drops it, and which tiles a read-back rejects.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "schedule/reuse_tracker.h"

namespace retile {
namespace {

constexpr int kTile = 16;

TileChunk wholeTile(const TileGrid& g, int tile, bool restart, int capStale = 0) {
  TileChunk c;
  c.tile = tile;
  c.rect = g.rect(tile);
  c.quality = 4;
  c.restart = restart;
  c.capStale = capStale;
  return c;
}

FramePlan incrementalFrame(std::vector<TileChunk> chunks) {
  FramePlan p;
  p.mode = AccumMode::Incremental;
  p.chunks = std::move(chunks);
  return p;
}

// Every tile of the grid restarted (and so reusing) at frame `frame`, holding `spp` before.
void startEveryTile(ReuseTracker& r, const TileGrid& g, std::uint64_t frame, double spp) {
  r.startPass();
  std::vector<TileChunk> chunks;
  for (int t = 0; t < g.count(); ++t) chunks.push_back(wholeTile(g, t, true));
  FramePlan p = incrementalFrame(std::move(chunks));
  r.planFrame(p, std::vector<double>(static_cast<std::size_t>(g.count()), spp), frame);
}

// `n` grey samples per pixel, normal with the given mean and standard deviation, added to `px`.
void addGreySamples(std::mt19937& rng, std::vector<LuminanceSums>& px, double mean, double sd, int n) {
  std::normal_distribution<double> N(mean, sd);
  for (LuminanceSums& p : px)
    for (int i = 0; i < n; ++i) {
      const double x = N(rng);
      p.count += 1;
      p.sum += x;
      p.squares += x * x;
      for (double& c : p.rgb) c += x;
    }
}

// Sums for test(): each tile's history 64 samples per pixel of mean 1 and sd 0.5 (a lit surface
// after a few bounces), its fresh ones 16 per pixel of mean freshMean[tile]. A 16 x 16 tile's
// summed difference then has an sd of 0.5 sqrt(256 (1/16 + 1/64)) = 2.2.
struct NoisyTiles {
  NoisyTiles(const TileGrid& g, std::vector<double> mean) : grid(g), freshMean(std::move(mean)) {}

  TileGrid grid;
  std::vector<double> freshMean;
  std::mt19937 rng{7};
  std::vector<int> asked;

  ReuseTracker::TileSums sums() {
    return [this](const TileRect& r, std::vector<LuminanceSums>& f, std::vector<LuminanceSums>& h) {
      const int t = grid.index(r.x / grid.tileSize(), r.y / grid.tileSize());
      asked.push_back(t);
      addGreySamples(rng, h, 1.0, 0.5, 64);
      addGreySamples(rng, f, freshMean[static_cast<std::size_t>(t)], 0.5, 16);
    };
  }
};

std::vector<int> sortedTiles(std::vector<int> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// Every tile of `g` reusing a 40-sample history, and the fresh samples of `tile` twice its
// history's mean tested: its rejection pending.
void rejectOneTile(ReuseTracker& r, const TileGrid& g, int tile) {
  r.reset(g);
  startEveryTile(r, g, 1, 40);
  NoisyTiles img{g, std::vector<double>(static_cast<std::size_t>(g.count()), 1.0)};
  img.freshMean[static_cast<std::size_t>(tile)] = 2.0;
  r.test(1, 1e-4, img.sums());
}

TEST(ReuseTracker, ARestartStartsAHistoryCreditedWithTheSamplesTheTileHad) {
  const TileGrid g(64, 32, kTile);  // 4 x 2 tiles
  ReuseTracker r;
  r.reset(g);
  r.startPass();
  TileChunk strip = wholeTile(g, 2, true);
  strip.rect.height = 4;  // a tile served in strips starts its history with the first
  FramePlan p = incrementalFrame({strip, wholeTile(g, 5, false)});
  const std::vector<double> before = {0, 0, 40, 0, 0, 30, 0, 0};
  const std::vector<ReuseOp> ops = r.planFrame(p, before, 7);

  ASSERT_EQ(ops.size(), 1u);
  EXPECT_EQ(ops[0].kind, ReuseOp::Start);
  EXPECT_EQ(ops[0].tile, 2);
  EXPECT_EQ(ops[0].rect.y, strip.rect.y);
  EXPECT_EQ(ops[0].rect.height, 4) << "the history starts where the restart would have";
  EXPECT_FALSE(p.chunks[0].restart) << "the sums stay, as history";
  EXPECT_FALSE(p.chunks[1].restart);
  EXPECT_EQ(r.states()[2], TileReuse::Reusing);
  EXPECT_EQ(r.states()[5], TileReuse::None) << "a tile added to is not restarted";
  EXPECT_EQ(r.credit()[2], 40.0);
  EXPECT_EQ(r.credit()[5], 0.0);
  EXPECT_TRUE(r.anyReusing());
}

TEST(ReuseTracker, ARestartOfAReusingTileGoesBackToItsHistoryAndKeepsItsCredit) {
  const TileGrid g(64, 32, kTile);
  ReuseTracker r;
  r.reset(g);
  startEveryTile(r, g, 1, 40);
  // The next edit restarts tile 3, whose fresh samples since are 12 spp: the history it goes
  // back to is still the 40 spp credited.
  r.startPass();
  FramePlan p = incrementalFrame({wholeTile(g, 3, true)});
  std::vector<double> before(8, 12.0);
  const std::vector<ReuseOp> ops = r.planFrame(p, before, 9);
  ASSERT_EQ(ops.size(), 1u);
  EXPECT_EQ(ops[0].kind, ReuseOp::Start);
  EXPECT_EQ(r.credit()[3], 40.0);
}

TEST(ReuseTracker, AStaleTileOfASmoothPassStartsItsHistoryOncePerPass) {
  const TileGrid g(64, 32, kTile);
  ReuseTracker r;
  r.reset(g);
  r.startPass();
  std::vector<double> before(8, 20.0);
  before[6] = 3.0;
  FramePlan first = incrementalFrame({wholeTile(g, 1, false, 8), wholeTile(g, 6, false, 8)});
  std::vector<ReuseOp> ops = r.planFrame(first, before, 2);
  ASSERT_EQ(ops.size(), 2u);
  EXPECT_EQ(ops[0].kind, ReuseOp::Start);
  EXPECT_EQ(ops[0].tile, 1);
  EXPECT_EQ(first.chunks[0].capStale, 0) << "the verified history replaces the capped one";
  EXPECT_EQ(r.credit()[1], 12.0) << "the scheduler counts the capped 8 spp as fresh";
  EXPECT_EQ(r.credit()[6], 0.0) << "fewer samples than the cap: none beyond it";
  EXPECT_EQ(r.states()[1], TileReuse::Reusing);

  // Served again in the same pass: the tile adds to the history it started.
  FramePlan again = incrementalFrame({wholeTile(g, 1, false, 8)});
  before[1] = 30.0;
  EXPECT_TRUE(r.planFrame(again, before, 3).empty());
  EXPECT_EQ(again.chunks[0].capStale, 0) << "nor is it capped";
  EXPECT_EQ(r.credit()[1], 12.0);

  // A new pass starts it again.
  r.startPass();
  FramePlan next = incrementalFrame({wholeTile(g, 1, false, 8)});
  ops = r.planFrame(next, before, 4);
  ASSERT_EQ(ops.size(), 1u);
  EXPECT_EQ(ops[0].kind, ReuseOp::Start);
}

TEST(ReuseTracker, AGlobalUpdateDropsEveryHistoryCreditAndVerdict) {
  const TileGrid g(64, 32, kTile);
  ReuseTracker r;
  rejectOneTile(r, g, 4);
  ASSERT_EQ(r.pendingRejects(), std::vector<int>{4});

  FramePlan global;
  global.mode = AccumMode::GlobalUpdate;
  for (int t = 0; t < g.count(); ++t) global.chunks.push_back(wholeTile(g, t, true));
  EXPECT_TRUE(r.planFrame(global, std::vector<double>(8, 40.0), 2).empty());
  for (int t = 0; t < g.count(); ++t) {
    EXPECT_EQ(r.states()[static_cast<std::size_t>(t)], TileReuse::None) << t;
    EXPECT_EQ(r.credit()[static_cast<std::size_t>(t)], 0.0) << t;
    EXPECT_TRUE(global.chunks[static_cast<std::size_t>(t)].restart) << "its restarts drop the sums, history and all";
  }
  EXPECT_FALSE(r.anyReusing());
  EXPECT_TRUE(r.pendingRejects().empty()) << "the verdict was about the dropped history";
}

TEST(ReuseTracker, APendingRejectionDropsTheHistoryAndItsCreditWithTheNextFrame) {
  const TileGrid g(64, 32, kTile);
  ReuseTracker r;
  rejectOneTile(r, g, 6);
  EXPECT_EQ(r.states()[6], TileReuse::Reusing) << "until the next frame";

  FramePlan p = incrementalFrame({wholeTile(g, 6, false)});
  const std::vector<ReuseOp> ops = r.planFrame(p, std::vector<double>(8, 5.0), 2);
  ASSERT_EQ(ops.size(), 1u);
  EXPECT_EQ(ops[0].kind, ReuseOp::Reject);
  EXPECT_EQ(ops[0].tile, 6);
  EXPECT_EQ(ops[0].rect.x, g.rect(6).x);
  EXPECT_EQ(ops[0].rect.width, kTile) << "the whole tile's history goes";
  EXPECT_EQ(r.states()[6], TileReuse::Rejected);
  EXPECT_EQ(r.credit()[6], 0.0);
  EXPECT_EQ(r.rejectedAt()[6], 2u);
  EXPECT_EQ(r.credit()[5], 40.0);
  EXPECT_TRUE(r.pendingRejects().empty());
  EXPECT_TRUE(r.planFrame(p, std::vector<double>(8, 6.0), 3).empty()) << "applied once";
}

TEST(ReuseTracker, ANewEditRestartingARejectedTileInTheSameFrameKeepsItsNewHistory) {
  const TileGrid g(64, 32, kTile);
  ReuseTracker r;
  rejectOneTile(r, g, 6);
  ASSERT_EQ(r.pendingRejects(), std::vector<int>{6});

  r.startPass();
  FramePlan p = incrementalFrame({wholeTile(g, 6, true)});
  const std::vector<ReuseOp> ops = r.planFrame(p, std::vector<double>(8, 5.0), 2);
  ASSERT_EQ(ops.size(), 1u);
  EXPECT_EQ(ops[0].kind, ReuseOp::Start);
  EXPECT_EQ(r.states()[6], TileReuse::Reusing);
  EXPECT_EQ(r.credit()[6], 40.0);
  EXPECT_EQ(r.rejectedAt()[6], 0u);
}

TEST(ReuseTracker, TestingRejectsATileManySigmaOffAndKeepsTheOnesWithinNoise) {
  const TileGrid g(64, 32, kTile);
  ReuseTracker r;
  r.reset(g);
  startEveryTile(r, g, 1, 40);
  NoisyTiles img{g, std::vector<double>(8, 1.0)};
  img.freshMean[3] = 1.3;  // z about (256 x 0.3 - margin) / 2.2 = 34 over the tile
  r.test(1, 1e-4, img.sums());
  EXPECT_EQ(sortedTiles(img.asked), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(r.pendingRejects(), std::vector<int>{3});
}

TEST(ReuseTracker, OnlyReusingTilesAreTestedAndOnlyOnImagesFromAfterTheirStart) {
  const TileGrid g(64, 32, kTile);
  ReuseTracker r;
  r.reset(g);
  startEveryTile(r, g, 1, 40);
  NoisyTiles img{g, std::vector<double>(8, 2.0)};
  r.test(1, 1e-4, img.sums());
  FramePlan none = incrementalFrame({});
  r.planFrame(none, std::vector<double>(8, 5.0), 2);  // every tile rejected
  ASSERT_FALSE(r.anyReusing());

  // A new edit restarts tiles 1 and 2 at frame 4; the image read back after frame 3, still in
  // flight when the edit came, holds samples of the old scene.
  r.startPass();
  FramePlan p = incrementalFrame({wholeTile(g, 1, true), wholeTile(g, 2, true)});
  r.planFrame(p, std::vector<double>(8, 5.0), 4);
  img.asked.clear();
  r.test(3, 1e-4, img.sums());
  EXPECT_TRUE(img.asked.empty());
  EXPECT_TRUE(r.pendingRejects().empty());
  r.test(4, 1e-4, img.sums());
  EXPECT_EQ(sortedTiles(img.asked), (std::vector<int>{1, 2}));
}

TEST(ReuseTracker, ASmallChangeOverANeighbourhoodOfTilesIsFoundByPoolingNeighbours) {
  const TileGrid g(128, 128, kTile);  // 8 x 8 tiles
  ReuseTracker r;
  r.reset(g);
  startEveryTile(r, g, 1, 40);
  // 3 x 3 tiles 3 % brighter: beyond the 0.5 % margin, z about 2.9 in each alone (the tile's
  // threshold is 4.8), 8.6 pooled; over the whole image the change is within the margin.
  NoisyTiles img{g, std::vector<double>(64, 1.0)};
  for (int y = 3; y <= 5; ++y)
    for (int x = 3; x <= 5; ++x) img.freshMean[static_cast<std::size_t>(g.index(x, y))] = 1.03;
  r.test(1, 1e-4, img.sums());
  const std::vector<int> found = r.pendingRejects();
  EXPECT_NE(std::find(found.begin(), found.end(), g.index(4, 4)), found.end()) << "the centre of the change";
  for (int t : found) EXPECT_LE(g.chebyshev(t, g.index(4, 4)), 2) << "tile " << t << " is far from the change";
}

TEST(ReuseTracker, ASmallChangeOverTheWholeImageIsFoundByPoolingEveryTile) {
  const TileGrid g(256, 256, kTile);  // 16 x 16 tiles
  ReuseTracker r;
  r.reset(g);
  startEveryTile(r, g, 1, 40);
  // Every tile 1 % brighter: z about 0.6 in each tile, 1.7 over a neighbourhood, 9 over all.
  NoisyTiles img{g, std::vector<double>(256, 1.01)};
  r.test(1, 1e-4, img.sums());
  EXPECT_EQ(r.pendingRejects().size(), 256u);
}

}  // namespace
}  // namespace retile
