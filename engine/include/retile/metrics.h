// Image metrics for comparing methods (retile eval): the paper's Fig. 6 reports PSNR and
// PSNR-HVS-M; RMSE and SSIM are the other usual two.
//
// Every function compares an image with a reference of the same size. Both are display-referred
// RGB (the view transform applied and clamped to [0, 1], as a viewer sees them), 3 floats per
// pixel, row-major. A mask (one byte per pixel, nullptr: every pixel) restricts the comparison
// to the pixels where it is not 0, so that the region an edit affected and the rest can be scored
// apart. Pure functions of their arguments: any thread may call them.
#pragma once

#include <cstdint>
#include <vector>

#include "retile/image.h"

namespace retile {

struct MetricImage {
  const float* rgb = nullptr;  // width * height * 3
  int width = 0, height = 0;
};

// Mean squared error over the three channels of the masked pixels (0 when no pixel is masked).
double meanSquaredError(MetricImage a, MetricImage ref, const std::uint8_t* mask = nullptr);
// sqrt(meanSquaredError).
double rootMeanSquaredError(MetricImage a, MetricImage ref, const std::uint8_t* mask = nullptr);
// 10 log10(1 / MSE) in dB, the peak being 1; +infinity for identical images.
double psnr(MetricImage a, MetricImage ref, const std::uint8_t* mask = nullptr);

// Structural similarity (Z. Wang, A. C. Bovik, H. R. Sheikh, E. P. Simoncelli, "Image quality
// assessment: from error visibility to structural similarity", IEEE TIP 13(4), 2004, eq. 13):
// on luma (Rec. 601 weights), with the paper's 11x11 Gaussian window (sigma 1.5), K1 = 0.01,
// K2 = 0.03 and L = 1, averaged over the windows that fit inside the image whose centre is
// masked. An image smaller than the window is one window with equal weights. Without the
// reference code's automatic down-sampling of large images. 1 for identical images.
double ssim(MetricImage a, MetricImage ref, const std::uint8_t* mask = nullptr);

// PSNR-HVS-M (N. Ponomarenko, F. Silvestri, K. Egiazarian, M. Carli, J. Astola, V. Lukin, "On
// between-coefficient contrast masking of DCT basis functions", VPQM 2007) on luma in [0, 255]:
// the difference of each 8x8 block's DCT coefficients, less what the block's own texture masks,
// weighted by the contrast sensitivity of each coefficient, as 10 log10(255^2 / mean). Blocks are
// the non-overlapping 8x8 blocks inside the image (as in the authors' code); with a mask, the
// blocks with at least one masked pixel. `masking` false gives PSNR-HVS (the same without
// contrast masking), which is never higher. +infinity for identical images or no block.
double psnrHvsM(MetricImage a, MetricImage ref, const std::uint8_t* mask = nullptr, bool masking = true);

// The pixels an edit changed: where two converged references, of the scene before the edit and
// after it, differ in luminance by more than `z` standard errors of their two means (each from
// the reference's per-pixel variance, moment2 - mean^2, over its sample count) and by more than
// `relative` of the brighter of the two; and every pixel of an aligned 4x4 block whose block means
// pass the same test (pooling finds small changes spread over many noisy pixels). 1 marks a
// changed pixel. Both references are linear renders of the same size with moment2 and
// sampleCount (Renderer::render fills them).
std::vector<std::uint8_t> affectedPixels(const RenderImage& before, const RenderImage& after, double z = 4.0, double relative = 0.01);

// Two linear renders of the same view compared the way Retile is checked against another renderer
// (issue 15): both averaged over aligned block x block squares (partial ones at the right and
// bottom edges), so that per-pixel noise averages out and what is left is bias. Pixels inside an
// `exclude` rectangle take no part; a block keeps its place only if at least half its pixels do.
// Noise floor: the same comparison between two renders of ours at different seeds.
struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
  bool contains(int px, int py) const { return px >= x && px < x + width && py >= y && py < y + height; }
};

struct BlockComparison {
  double meanA = 0.0, meanRef = 0.0;  // mean of R, G and B over the compared pixels
  // sqrt(sum over blocks and channels of (A - Ref)^2) / sqrt(sum of Ref^2): relative RMSE of the
  // block means.
  double relativeRmse = 0.0;
  int cols = 0, rows = 0, blocks = 0;  // the block grid and the blocks compared
  // Per block (row-major), its mean luminance in A and Ref and its share of the summed squared
  // error (the shares of the compared blocks sum to 1); NaN for blocks left out.
  std::vector<double> lumA, lumRef, errorShare;
};

BlockComparison compareBlocks(MetricImage a, MetricImage ref, int block, const std::vector<PixelRect>& exclude = {});

// How much of compareBlocks(a, ref) noise can explain, given b, a second render of ours at
// another seed. The floor compareBlocks(a, b) holds only our noise; a reference noisier than our
// renders (another renderer's sampling of a caustic, say) raises the distance to it with no bias
// at all. Each block's noise is estimated from the spread of its pixels, taking pixel noise as
// independent: ours from a - b (twice our pixel variance), the reference's from
// ref - (a + b) / 2 (its pixel variance plus half ours, clamped at 0). Differences at pixel scale
// (an edge placed a little apart, another filter) count as the reference's noise, and so does the
// clamp, so that estimate is an upper bound; block means are little moved by them. Same grid and
// exclusions as compareBlocks; blocks of one pixel have no spread and are not estimated.
struct BlockNoise {
  // The block means' standard errors, summed in squares over blocks and channels, relative to
  // the reference's block means as BlockComparison::relativeRmse is. sqrt(2) ours is the
  // root-mean-square of compareBlocks(a, b): with a few noisy blocks dominating, one pair's floor
  // is usually below it.
  double ours = 0.0, reference = 0.0;
  // compareBlocks(a, ref) / compareBlocks(a, b) to expect when the renderers differ by noise
  // alone, in root-mean-squares: sqrt((ours^2 + reference^2) / (2 ours^2)).
  double expectedRatio = 0.0;
  // Per block (row-major; NaN where not scored): mean luminance of a minus ref's, in units of the
  // standard error of that difference (half-float rounding counted in). Mean of z^2 near 1, and
  // about 0.27 % of blocks past 3, when only noise differs. A block black in all three images is
  // not scored.
  std::vector<double> z;
  double meanSquaredZ = 0.0;
  int beyond3 = 0;
  int blocks = 0;  // blocks whose noise was estimated
  int scored = 0;  // of those, blocks with a z
};

BlockNoise blockNoise(MetricImage a, MetricImage b, MetricImage ref, int block, const std::vector<PixelRect>& exclude = {});

}  // namespace retile
