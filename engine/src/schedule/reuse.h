// Verified sample reuse (issue 16): when an edit restarts a tile, its converged samples (the
// history) are kept beside the fresh ones, and the tile shows and accumulates both for as long as
// the fresh estimate agrees with the history within noise. This is the test that decides, and the
// per-tile states (ReuseTracker, reuse_tracker.h, keeps them). Pure CPU, no Vulkan; any thread.
//
// The test, per tile and per aligned 4x4 block of it (pooling finds small changes spread over many
// pixels, a single block finds a small local one): with each pixel's luminance mean over its fresh
// samples f_p (n_p of them) and over its history h_p (m_p), and the per-sample variance s_p^2 of the
// history (its second moment less its mean squared: under "nothing changed" the fresh samples
// have the same variance, and the history's estimate of it rests on many samples),
//     z = max(0, |sum_p (f_p - h_p)| - margin * sum_p h_p) / sqrt(sum_p s_p^2 (1/n_p + 1/m_p))
// over the block's pixels with fresh samples (the margin: kReuseMargin below); and the same for each of R, G and B, whose variance
// is taken as the luminance's scaled by (channel mean / luminance mean)^2 (only luminance has a
// second moment; a change of hue at equal luminance would pass a luminance test). The history is
// rejected when |z| of the tile or of any block exceeds the two-sided normal quantile of
// alpha / tests (Bonferroni over the tile's tests), alpha being the false-reject rate: the chance
// that one test of an unchanged tile drops its history. A kept history that is off by d (in
// luminance) is found once sqrt(n) d / s passes the threshold: the test's power grows with the
// fresh count n, so any real change is found eventually. While kept, the shown mean is
// (m h + n f) / (m + n); its error from a kept history is at most m / (m + n) times the largest
// difference the test lets pass, z * s * sqrt(1/n + 1/m) (docs/ARCHITECTURE.md states the bound).
#pragma once

#include <cstdint>
#include <vector>

#include "schedule/tile_grid.h"

namespace retile {

// A pixel's sums: samples, the sum of their luminance and of its square, the sums of R, G, B.
struct LuminanceSums {
  double count = 0, sum = 0, squares = 0;
  double rgb[3] = {0, 0, 0};
};

struct ReuseTest {
  double statistic = 0;  // the largest |z| of the tile and its blocks
  double threshold = 0;  // the rejection threshold for this tile's number of tests
  int pixels = 0;        // pixels with both fresh samples and a history
  // The whole tile's summed differences, their variances and the summed history means
  // (luminance, R, G, B), for pooling with other tiles.
  double diff[4] = {0, 0, 0, 0}, var[4] = {0, 0, 0, 0}, base[4] = {0, 0, 0, 0};
  bool reject() const { return statistic > threshold; }
};

// The two-sided normal quantile: |Z| > z with probability p.
double normalQuantileTwoSided(double p);

// Differences smaller than this fraction of the history's mean are not changes to find: without a
// margin the pooled tests, with thousands of fresh samples over the whole image, found the
// 0.1 %-level change of indirect light a moved cup makes everywhere and dropped every history
// (the picture's error doubled). A kept history is then off by at most the margin plus what the
// test lets pass, and its weight m / (m + n) still takes that to 0.
constexpr double kReuseMargin = 0.005;

// Tests one tile: `fresh` and `history` hold the tile's pixels row by row (width x height). Pixels
// without fresh samples or without a history take no part.
ReuseTest testReuse(const std::vector<LuminanceSums>& fresh, const std::vector<LuminanceSums>& history, int width, int height,
                    double falseRejectRate, double margin = kReuseMargin);

// Pools tiles' whole-tile sums into one test (luminance, R, G, B; Bonferroni over the four): a
// change too small for any one tile's test, spread over many tiles (a light a few per cent
// brighter), is found by the pool of a tile's neighbourhood or of the whole image.
ReuseTest testPooled(const std::vector<const ReuseTest*>& tiles, double falseRejectRate, double margin = kReuseMargin);

enum class TileReuse : std::uint8_t {
  None,      // no history kept (no edit since the last global restart, or nothing to keep)
  Reusing,   // history kept and shown with the fresh samples, tested every frame
  Rejected,  // the history disagreed with the fresh samples and was dropped until the next edit
};

}  // namespace retile
