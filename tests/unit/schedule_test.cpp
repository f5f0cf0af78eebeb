// The tile scheduler and the policies, without a GPU: ordering properties and the exact budget.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "retile/method.h"
#include "schedule/policies.h"
#include "schedule/scheduler.h"

namespace retile {
namespace {

TEST(TileGrid, CoversOddSizesWithPartialEdgeTiles) {
  TileGrid g(333, 177, 16);
  EXPECT_EQ(g.cols(), 21);
  EXPECT_EQ(g.rows(), 12);
  std::int64_t sum = 0;
  for (int t = 0; t < g.count(); ++t) sum += g.rect(t).pixels();
  EXPECT_EQ(sum, 333 * 177) << "every pixel in exactly one tile, bottom rows included";
  EXPECT_EQ(g.rect(g.count() - 1).width, 333 - 20 * 16);
  EXPECT_EQ(g.rect(g.count() - 1).height, 177 - 11 * 16);
}

TEST(Spiral, EveryTileOnceAndChebyshevNeverDecreases) {
  for (auto [w, h, t] : {std::tuple{333, 177, 16}, std::tuple{64, 64, 8}, std::tuple{1920, 1080, 32}, std::tuple{5, 300, 8}}) {
    TileGrid g(w, h, t);
    for (int center : {0, g.count() - 1, g.index(g.cols() / 2, g.rows() / 2), g.index(g.cols() - 1, 0)}) {
      auto order = spiralOrder(g, center);
      ASSERT_EQ(order.size(), static_cast<std::size_t>(g.count()));
      EXPECT_EQ(std::set<int>(order.begin(), order.end()).size(), order.size()) << "each tile exactly once";
      EXPECT_EQ(order.front(), center);
      for (std::size_t i = 1; i < order.size(); ++i)
        ASSERT_LE(g.chebyshev(order[i - 1], center), g.chebyshev(order[i], center)) << "at " << i;
    }
  }
}

TEST(Focus, SpiralsAlternateAndCoverEverything) {
  TileGrid g(640, 360, 16);
  int a = g.index(2, 2), b = g.index(35, 19);
  auto order = interleavedSpirals(g, {a, b});
  ASSERT_EQ(std::set<int>(order.begin(), order.end()).size(), static_cast<std::size_t>(g.count()));
  auto sa = spiralOrder(g, a), sb = spiralOrder(g, b);
  // Far apart, the spirals do not meet for a while: the queue takes one tile of each in turn.
  for (std::size_t i = 0; i < 20; ++i) {
    EXPECT_EQ(order[2 * i], sa[i]);
    EXPECT_EQ(order[2 * i + 1], sb[i]);
  }
  // Three centres take turns too.
  int c = g.index(38, 1);
  auto three = interleavedSpirals(g, {a, b, c});
  EXPECT_EQ(three[0], a);
  EXPECT_EQ(three[1], b);
  EXPECT_EQ(three[2], c);
}

TEST(Indirection, ClassesFromCountsWithShadowsAboveLow) {
  TileGrid g(64, 32, 16);  // 4 x 2 tiles
  IndirectionCounts c;
  c.direct = {5, 0, 0, 0, 0, 0, 0, 0};
  c.reflection = {0, 120, 30, 15, 0, 0, 0, 0};
  c.shadow = {0, 0, 0, 0, 20, 0, 0, 0};
  auto plan = indirectionPlan(g, c, 0, spiralOrder(g, 0));
  EXPECT_EQ(plan.classes[0], TileClass::High) << "a direct hit";
  EXPECT_EQ(plan.classes[1], TileClass::High) << "reflection above M/3";
  EXPECT_EQ(plan.classes[2], TileClass::Middle) << "between M/6 and M/3";
  EXPECT_EQ(plan.classes[3], TileClass::Low) << "between M/12 and M/6";
  EXPECT_EQ(plan.classes[4], TileClass::Middle) << "a shadow tile never falls to low";
  EXPECT_EQ(plan.classes[5], TileClass::Rest);
  EXPECT_EQ(plan.prioritized, 5);
  EXPECT_EQ(plan.order.size(), static_cast<std::size_t>(g.count()));
  EXPECT_EQ(std::set<int>(plan.order.begin(), plan.order.begin() + 2), (std::set<int>{0, 1}));
}

TEST(Indirection, AutomaticQualityFitsOneFrameAndStaysAtLeastOne) {
  TileGrid g(333, 177, 16);
  std::vector<int> all(static_cast<std::size_t>(g.count()));
  for (int t = 0; t < g.count(); ++t) all[static_cast<std::size_t>(t)] = t;
  EXPECT_EQ(automaticQuality(g, all, 1024), 1) << "an object filling the screen";
  std::vector<int> some = {0, 1, 2, g.count() - 1};
  int q = automaticQuality(g, some, 1 << 20);
  std::int64_t px = 0;
  for (int t : some) px += g.rect(t).pixels();
  EXPECT_LE(q * px, g.pixels());
  EXPECT_GT((q + 1) * px, g.pixels()) << "the largest Q that fits";
  EXPECT_EQ(automaticQuality(g, some, 64), 64) << "clamped to the maximum";
  EXPECT_GE(automaticQuality(g, {}, 64), 1);
}

TEST(Indirection, MotionReplacesHighTilesAndNeverGrowsTheSet) {
  TileGrid g(320, 180, 16);
  std::vector<int> high = {g.index(5, 5), g.index(6, 5), g.index(5, 6), g.index(6, 6)};
  // A drag of 2 px a frame: the motion is the total since the tiles were classified, so slow
  // drags move the set too (a per-frame shift of 2 px would never leave a tile).
  std::vector<int> moved;
  for (int frame = 1; frame <= 100; ++frame) {
    moved = followMotion(g, high, {2.0f * static_cast<float>(frame), 0.0f});
    ASSERT_LE(moved.size(), high.size()) << "frame " << frame;
  }
  ASSERT_EQ(moved.size(), high.size());
  for (int t : moved) EXPECT_GE(g.col(t), 17) << "200 px to the right of columns 5 and 6";
  auto jumped = followMotion(g, high, {32.0f, 16.0f});
  EXPECT_EQ(std::set<int>(jumped.begin(), jumped.end()), (std::set<int>{g.index(7, 6), g.index(8, 6), g.index(7, 7), g.index(8, 7)}));
  EXPECT_TRUE(followMotion(g, high, {-1000.0f, 0.0f}).empty()) << "tiles moved off screen drop out";
}

// Runs frames until the pass is done (plus a few refinement frames) and checks each frame:
// exactly W x H samples, no pixel twice, and at the end every queued tile restarted with >= Q.
void checkBudget(int w, int h, int t, int q, bool smooth) {
  SCOPED_TRACE(testing::Message() << w << "x" << h << " T=" << t << " Q=" << q << (smooth ? " smooth" : ""));
  TileGrid g(w, h, t);
  TileScheduler s(g);
  auto check = [&](const FramePlan& p) {
    std::int64_t samples = 0;
    std::vector<unsigned char> hit(static_cast<std::size_t>(g.pixels()), 0);
    for (const auto& c : p.chunks) {
      ASSERT_GE(c.quality, 1);
      samples += c.rect.pixels() * c.quality;
      for (int y = c.rect.y; y < c.rect.y + c.rect.height; ++y)
        for (int x = c.rect.x; x < c.rect.x + c.rect.width; ++x) {
          auto& v = hit[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
          ASSERT_EQ(v, 0) << "pixel " << x << "," << y << " served twice in one frame";
          v = 1;
        }
    }
    ASSERT_EQ(samples, g.pixels());
    ASSERT_EQ(p.samples, g.pixels());
  };
  check(s.nextFrame());  // the first frame is a global update
  auto order = spiralOrder(g, g.index(g.cols() / 3, g.rows() / 2));
  s.startPass(order, q, smooth ? g.count() / 4 : g.count(), smooth, 4);
  int frames = 0;
  while (s.passActive() && frames < 100000) {
    check(s.nextFrame());
    ++frames;
  }
  ASSERT_FALSE(s.passActive()) << "the pass finishes";
  std::int64_t expectFrames = (static_cast<std::int64_t>(q) * g.pixels() + g.pixels() - 1) / g.pixels();
  // Whole tiles at uniform Q leave a remainder each frame that goes to other tiles' strips.
  EXPECT_LE(frames, expectFrames * 11 / 10 + 2) << "the queue drains at about the budget's pace";
  for (int tile = 0; tile < g.count(); ++tile)
    EXPECT_GE(s.tileSamples()[static_cast<std::size_t>(tile)], smooth ? 1.0 : q - 1e-9) << "tile " << tile;
  for (int i = 0; i < 3; ++i) check(s.nextFrame());
  EXPECT_EQ(s.mode(), AccumMode::Refinement);
}

TEST(Scheduler, BudgetIsExactlyOneFrameForEveryQualityAndOddSizes) {
  for (int q : {1, 2, 3, 7, 64, 100, 512})
    for (auto [w, h] : {std::pair{333, 177}, std::pair{64, 48}, std::pair{17, 5}})
      for (int t : {8, 16, 32}) checkBudget(w, h, t, q, false);
}

TEST(Scheduler, SmoothTransitionCapsStaleSumsAndKeepsTheBudget) {
  for (int q : {1, 7, 64}) checkBudget(333, 177, 16, q, true);
  TileGrid g(64, 64, 16);
  TileScheduler s(g);
  s.nextFrame();
  for (int i = 0; i < 100; ++i) s.nextFrame();  // refinement: 101 spp everywhere
  EXPECT_NEAR(s.tileSamples()[0], 101.0, 1e-9);
  s.startPass(spiralOrder(g, 0), 2, 1, true, 4);
  FramePlan p = s.nextFrame();
  for (const auto& c : p.chunks) {
    if (c.tile == 0) EXPECT_TRUE(c.restart) << "the prioritized tile restarts";
    else EXPECT_EQ(c.capStale, 4) << "the others keep at most 4 stale samples";
  }
  EXPECT_NEAR(s.tileSamples()[1], 4.0 + 2.0, 1e-9);
}

// A preview restarts its tiles at a sample per block and nothing else: the other tiles keep their
// converged sums until the pass reaches them at full resolution, and the pass has not advanced.
TEST(Scheduler, APreviewRestartsOnlyItsTilesAndLeavesThePassWhereItWas) {
  TileGrid g(64, 64, 16);
  TileScheduler s(g);
  s.nextFrame();
  for (int i = 0; i < 31; ++i) s.nextFrame();  // refinement: 32 spp everywhere
  s.startPass(spiralOrder(g, 5), 16, g.count(), false, 1);
  const std::vector<int> touched = {5, 6};
  s.setPreviewTiles(touched);
  EXPECT_FALSE(s.previewDone());
  FramePlan p = s.nextFrame(2);
  EXPECT_EQ(p.servedTiles, touched);
  for (const TileChunk& c : p.chunks) {
    EXPECT_TRUE(c.restart);
    EXPECT_EQ(c.block, 2);
    EXPECT_EQ(c.quality, 4) << "Q / block^2";
  }
  EXPECT_TRUE(s.previewDone());
  EXPECT_EQ(s.queueServed(), 0u) << "the pass starts at full resolution from its beginning";
  for (int t = 0; t < g.count(); ++t) {
    const bool previewed = t == 5 || t == 6;
    EXPECT_NEAR(s.tileSamples()[static_cast<std::size_t>(t)], previewed ? 4.0 : 32.0, 1e-9) << t;
    EXPECT_EQ(s.startedTiles()[static_cast<std::size_t>(t)], previewed ? 1 : 0) << "the denoiser's region grows over the preview";
  }
  // A new pass has no preview of its own, but the previewed tiles hold the edit's samples until
  // the pass re-renders them at full resolution: the denoiser still counts them as re-rendered.
  s.startPass(spiralOrder(g, 0), 16, g.count(), false, 1);
  EXPECT_TRUE(s.previewDone());
  EXPECT_EQ(s.startedTiles()[5], 1);
  while (s.passActive()) s.nextFrame();
  EXPECT_NEAR(s.tileSamples()[5], 16.0, 1e-9) << "restarted at full resolution";
  s.startPass(spiralOrder(g, 0), 16, g.count(), false, 1);
  EXPECT_EQ(s.startedTiles()[5], 0) << "served at full resolution: no longer a preview's";
  // A render region set before a preview ends keeps the preview inside it.
  s.setPreviewTiles({9, 10});
  std::vector<char> region;
  for (int t = 0; t < g.count(); ++t) region.push_back(t == 9 ? 1 : 0);
  s.setRegion(region);
  FramePlan inside = s.nextFrame(2);
  EXPECT_EQ(inside.servedTiles, std::vector<int>{9});
}

TEST(Scheduler, GlobalUpdateRestartsEveryTileThenRefines) {
  TileGrid g(100, 60, 16);
  TileScheduler s(g);
  FramePlan first = s.nextFrame();
  EXPECT_EQ(first.mode, AccumMode::GlobalUpdate);
  EXPECT_EQ(first.chunks.size(), static_cast<std::size_t>(g.count()));
  for (const auto& c : first.chunks) EXPECT_TRUE(c.restart);
  FramePlan second = s.nextFrame();
  EXPECT_EQ(second.mode, AccumMode::Refinement);
  for (const auto& c : second.chunks) EXPECT_FALSE(c.restart);
  // An edit during a pass restarts the queue from the new point.
  s.startPass(spiralOrder(g, 0), 64, g.count(), false, 1);
  s.nextFrame();
  s.startPass(spiralOrder(g, g.count() - 1), 64, g.count(), false, 1);
  FramePlan again = s.nextFrame();
  EXPECT_EQ(again.chunks.front().tile, g.count() - 1);
  EXPECT_TRUE(again.chunks.front().restart);
}

TEST(Scheduler, ARenderRegionTracesOnlyItsTilesWithTheBudgetAndNoPixelTwice) {
  TileGrid g(96, 64, 16);  // 6 x 4 tiles
  TileScheduler s(g);
  s.nextFrame();
  std::vector<char> region(static_cast<std::size_t>(g.count()), 0);
  for (int t : {g.index(1, 1), g.index(2, 1), g.index(1, 2), g.index(2, 2)}) region[static_cast<std::size_t>(t)] = 1;
  s.setRegion(region);
  auto check = [&](const FramePlan& p, const char* what) {
    SCOPED_TRACE(what);
    std::vector<unsigned char> hit(static_cast<std::size_t>(g.pixels()), 0);
    for (const auto& c : p.chunks) {
      EXPECT_TRUE(region[static_cast<std::size_t>(c.tile)]) << "tile " << c.tile << " is outside the region";
      for (int y = c.rect.y; y < c.rect.y + c.rect.height; ++y)
        for (int x = c.rect.x; x < c.rect.x + c.rect.width; ++x) {
          auto& v = hit[static_cast<std::size_t>(y) * 96u + static_cast<std::size_t>(x)];
          EXPECT_EQ(v, 0) << "pixel served twice";
          v = 1;
        }
    }
    EXPECT_LE(p.samples, g.pixels());
    EXPECT_GE(p.samples, g.pixels() * 9 / 10) << "the region gets (about) the whole budget";
  };
  FramePlan refine = s.nextFrame();
  EXPECT_EQ(refine.mode, AccumMode::Refinement);
  check(refine, "refinement");
  EXPECT_EQ(refine.chunks.size(), 4u) << "each region tile once";
  EXPECT_EQ(refine.chunks.front().quality, 6) << "6 times the samples: the region is a sixth of the image";
  s.startPass(spiralOrder(g, 0), 8, g.count(), false, 1);
  EXPECT_EQ(s.queueLength(), 4u) << "a pass skips tiles outside the region";
  check(s.nextFrame(), "incremental");
  s.globalUpdate();
  check(s.nextFrame(), "global update");
  s.setRegion({});
  s.globalUpdate();
  FramePlan whole = s.nextFrame();
  EXPECT_EQ(whole.chunks.size(), static_cast<std::size_t>(g.count())) << "clearing the region renders everything again";
}

TEST(Scheduler, SampleIndicesNeverRepeatForAPixel) {
  TileGrid g(48, 32, 16);
  TileScheduler s(g);
  std::vector<std::set<std::uint32_t>> seen(static_cast<std::size_t>(g.pixels()));
  for (int f = 0; f < 40; ++f) {
    if (f == 5 || f == 17) s.startPass(spiralOrder(g, f % g.count()), 3, g.count(), false, 1);
    FramePlan p = s.nextFrame();
    for (const auto& c : p.chunks)
      for (int y = c.rect.y; y < c.rect.y + c.rect.height; ++y)
        for (int x = c.rect.x; x < c.rect.x + c.rect.width; ++x)
          for (int k = 0; k < c.quality; ++k)
            ASSERT_TRUE(seen[static_cast<std::size_t>(y * g.width() + x)].insert(c.sampleBase + static_cast<std::uint32_t>(k)).second);
  }
}

TEST(Method, NamesRoundTripAndSettingsAreChecked) {
  for (const auto& n : methodNames()) {
    MethodKind k;
    ASSERT_TRUE(methodFromName(n, &k));
    EXPECT_EQ(n, methodName(k));
  }
  MethodKind k;
  EXPECT_FALSE(methodFromName("nope", &k));
  MethodSettings s;
  EXPECT_EQ(validateMethodSettings(s), "");
  s.tileSize = 12;
  EXPECT_NE(validateMethodSettings(s), "");
  s.tileSize = 16;
  s.quality = 0;
  EXPECT_NE(validateMethodSettings(s), "") << "automatic Q only for indirection";
  s.kind = MethodKind::Indirection;
  EXPECT_EQ(validateMethodSettings(s), "");
}

}  // namespace
}  // namespace retile

namespace retile {
namespace {

TEST(Refinement, CreditsSendTheBudgetToTheTilesWithTheFewestSamples) {
  // 4x2 tiles of 16x16; after the global update every tile has 1 spp. Six keep a history of 100
  // spp (credit), two lost theirs: refinement raises those two first, and spends the whole
  // budget exactly.
  TileGrid g(64, 32, 16);
  TileScheduler s(g);
  s.nextFrame();  // the global update
  std::vector<double> credit(8, 100.0);
  credit[2] = credit[5] = 0.0;
  s.setCredit(credit);
  FramePlan p = s.nextFrame();
  EXPECT_EQ(p.mode, AccumMode::Refinement);
  std::int64_t samples = 0;
  int servedOthers = 0;
  for (const TileChunk& c : p.chunks) {
    samples += c.rect.pixels() * c.quality;
    if (c.tile != 2 && c.tile != 5) ++servedOthers;
  }
  EXPECT_EQ(samples, 64 * 32) << "exactly W x H samples";
  EXPECT_EQ(servedOthers, 0) << "the budget goes to the tiles that lost their history";
  EXPECT_NEAR(s.tileSamples()[2], 5.0, 1e-9) << "1 + 4 spp each: 8 tiles' worth of samples over 2";
  EXPECT_NEAR(s.tileSamples()[5], 5.0, 1e-9);
  // Without credits, every tile gets one sample a frame as before.
  s.setCredit({});
  FramePlan q = s.nextFrame();
  EXPECT_EQ(q.chunks.size(), 8u);
}

TEST(Refinement, DuringAPassTilesThatLostTheirHistoryCatchUpWithHalfTheBudget) {
  // 8x2 tiles of 16x16, every one holding 100 spp of history. A pass at Q = 4 over all of them:
  // each frame's budget (16 tiles' worth at 1 spp) finishes four tiles. Once the first finished
  // tile's history is rejected (credit 0), later frames give it up to half the budget while the
  // pass goes on with the rest; every frame still traces exactly W x H samples, no pixel twice.
  TileGrid g(128, 32, 16);
  TileScheduler s(g);
  s.nextFrame();  // the global update
  std::vector<int> order(16);
  for (int i = 0; i < 16; ++i) order[static_cast<std::size_t>(i)] = i;
  s.startPass(order, 4, 16, false, 64);
  std::vector<double> credit(16, 100.0);
  s.setCredit(credit);
  s.nextFrame();
  EXPECT_EQ(s.queueServed(), 4u) << "no tile is behind yet: the whole budget goes to the pass";
  credit[0] = 0.0;  // tile 0's history was rejected: it holds its 4 fresh spp only
  s.setCredit(credit);
  std::size_t servedBefore = s.queueServed();
  FramePlan second = s.nextFrame();
  std::int64_t samples = 0, toTile0 = 0;
  std::vector<int> covered(static_cast<std::size_t>(g.pixels()), 0);
  for (const TileChunk& c : second.chunks) {
    samples += c.rect.pixels() * c.quality;
    if (c.tile == 0) toTile0 += c.rect.pixels() * c.quality;
    for (int y = c.rect.y; y < c.rect.y + c.rect.height; ++y)
      for (int x = c.rect.x; x < c.rect.x + c.rect.width; ++x) ++covered[static_cast<std::size_t>(y * 128 + x)];
  }
  EXPECT_EQ(samples, 128 * 32) << "exactly W x H samples";
  EXPECT_LE(*std::max_element(covered.begin(), covered.end()), 1) << "no pixel twice in a frame";
  EXPECT_EQ(toTile0, 128 * 32 / 2) << "half the budget raises the tile that lost its history";
  EXPECT_EQ(s.queueServed(), servedBefore + 2) << "the pass goes on with the other half";
  EXPECT_TRUE(s.passActive());
  // Without credits (no reuse) the pass has the whole budget, as the paper's method.
  TileScheduler plain(g);
  plain.nextFrame();
  plain.startPass(order, 4, 16, false, 64);
  plain.nextFrame();
  plain.nextFrame();
  EXPECT_EQ(plain.queueServed(), 8u);
}

}  // namespace
}  // namespace retile
