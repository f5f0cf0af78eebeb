// The verified-reuse test on synthetic sums (schedule/reuse.h): its false-reject rate when nothing
// changed, whatever the counts, and how soon it finds a small change spread over a tile.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "schedule/reuse.h"

namespace retile {
namespace {

// A tile of w x h pixels whose samples are normal with the given mean and sd: `n` per pixel.
std::vector<LuminanceSums> sums(std::mt19937& rng, int w, int h, double mean, double sd, int n) {
  std::normal_distribution<double> N(mean, sd);
  std::vector<LuminanceSums> out(static_cast<std::size_t>(w * h));
  for (auto& p : out)
    for (int i = 0; i < n; ++i) {
      double x = N(rng);
      p.count += 1;
      p.sum += x;
      p.squares += x * x;
      for (double& c : p.rgb) c += x;  // grey
    }
  return out;
}

TEST(Reuse, NormalQuantileIsTheTwoSidedOne) {
  EXPECT_NEAR(normalQuantileTwoSided(0.05), 1.959964, 1e-5);
  EXPECT_NEAR(normalQuantileTwoSided(1e-4), 3.890592, 1e-5);
}

TEST(Reuse, AnUnchangedTileKeepsItsHistoryAtTheStatedRate) {
  // alpha = 0.05 so that the rate is measurable in 1000 trials: at most 0.05 of them reject
  // (Bonferroni over the tile's 17 tests makes the rate lower than alpha, never higher).
  for (int fresh : {1, 4, 32}) {
    std::mt19937 rng(11 + fresh);
    int rejected = 0;
    const int trials = 1000;
    for (int t = 0; t < trials; ++t) {
      auto f = sums(rng, 16, 16, 0.3, 0.2, fresh);
      auto h = sums(rng, 16, 16, 0.3, 0.2, 64);
      rejected += testReuse(f, h, 16, 16, 0.05).reject();
    }
    EXPECT_LE(rejected, trials * 0.05 + 3 * std::sqrt(trials * 0.05)) << fresh << " fresh samples per pixel";
    EXPECT_GT(rejected, 0) << "a test that never rejects has no power either";
  }
}

TEST(Reuse, ATwoPercentShiftOverATileIsFoundWithin512FreshSamples) {
  // Samples with a standard deviation of half the mean (a typical lit surface after a few
  // bounces), the default false-reject rate 1e-4 and margin 0.5 %: z grows as
  // (0.02 - 0.005) sqrt(256 n) / 0.5 and passes the threshold (4.8 for a 16x16 tile) at about
  // n = 150 on average; at 512 it is about 9.
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    auto h = sums(rng, 16, 16, 1.0, 0.5, 1024);
    auto f = sums(rng, 16, 16, 1.02, 0.5, 512);
    ReuseTest r = testReuse(f, h, 16, 16, 1e-4);
    EXPECT_TRUE(r.reject()) << "z " << r.statistic << " against " << r.threshold;
  }
  // And not from a handful of samples: the same shift hides in the noise of 4.
  auto h = sums(rng, 16, 16, 1.0, 0.5, 1024);
  auto f = sums(rng, 16, 16, 1.02, 0.5, 4);
  EXPECT_FALSE(testReuse(f, h, 16, 16, 1e-4).reject());
  EXPECT_FALSE(testReuse(sums(rng, 16, 16, 1.004, 0.5, 4096), sums(rng, 16, 16, 1.0, 0.5, 1024), 16, 16, 1e-4).reject())
      << "a shift within the margin is not a change to find, however many samples";
}

TEST(Reuse, AChangeInOneBlockIsFoundWhereTheTileAverageWouldHideIt) {
  std::mt19937 rng(9);
  auto h = sums(rng, 16, 16, 1.0, 0.5, 1024);
  auto f = sums(rng, 16, 16, 1.0, 0.5, 64);
  // One 4x4 block 30 % brighter: a sixteenth of the tile, 1.9 % of its mean.
  for (int y = 4; y < 8; ++y)
    for (int x = 8; x < 12; ++x) {
      auto& p = f[static_cast<std::size_t>(y * 16 + x)];
      p.squares = p.squares * 1.69;
      p.sum *= 1.3;
      for (double& c : p.rgb) c *= 1.3;
    }
  EXPECT_TRUE(testReuse(f, h, 16, 16, 1e-4).reject());
}

TEST(Reuse, AChangeOfHueAtEqualLuminanceIsFound) {
  // Red becomes a green-blue of the same luminance: the luminance test alone would keep it.
  std::mt19937 rng(13);
  auto h = sums(rng, 16, 16, 0.25, 0.1, 256);
  auto f = sums(rng, 16, 16, 0.25, 0.1, 32);
  const double red[3] = {0.25 / 0.2126, 0, 0}, teal[3] = {0, 0.25 / (0.7152 + 0.0722) * 1.0, 0.25 / (0.7152 + 0.0722)};
  for (auto* v : {&h, &f})
    for (auto& p : *v)
      for (int c = 0; c < 3; ++c) p.rgb[c] = p.sum * (v == &h ? red[c] : teal[c]);
  EXPECT_TRUE(testReuse(f, h, 16, 16, 1e-4).reject());
  // The same colour on both sides is kept.
  for (auto& p : f)
    for (int c = 0; c < 3; ++c) p.rgb[c] = p.sum * red[c];
  EXPECT_FALSE(testReuse(f, h, 16, 16, 1e-4).reject());
}

TEST(Reuse, PixelsWithoutSamplesTakeNoPart) {
  std::vector<LuminanceSums> f(16), h(16);
  ReuseTest r = testReuse(f, h, 4, 4, 1e-4);
  EXPECT_EQ(r.pixels, 0);
  EXPECT_FALSE(r.reject());
}

}  // namespace
}  // namespace retile
