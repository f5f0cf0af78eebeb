// The evaluation's metrics on pairs whose answers are known in closed form, and on the
// properties each is built for (masking hides error in texture, SSIM sees structure).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "retile/metrics.h"

namespace retile {
namespace {

struct Image {
  int width, height;
  std::vector<float> rgb;
  Image(int w, int h, float grey) : width(w), height(h), rgb(static_cast<std::size_t>(w) * h * 3, grey) {}
  MetricImage view() const { return {rgb.data(), width, height}; }
  void set(int x, int y, float grey) {
    for (int c = 0; c < 3; ++c) rgb[(static_cast<std::size_t>(y) * width + x) * 3 + c] = grey;
  }
  float at(int x, int y) const { return rgb[(static_cast<std::size_t>(y) * width + x) * 3]; }
};

Image noisy(const Image& base, float amplitude, unsigned seed) {
  Image out = base;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-amplitude, amplitude);
  for (int y = 0; y < base.height; ++y)
    for (int x = 0; x < base.width; ++x) out.set(x, y, std::clamp(base.at(x, y) + u(rng), 0.0f, 1.0f));
  return out;
}

TEST(Metrics, PsnrOfAConstantOffsetIsKnown) {
  const Image ref(32, 24, 0.5f), off(32, 24, 0.6f);
  EXPECT_NEAR(rootMeanSquaredError(off.view(), ref.view()), 0.1, 1e-6);
  EXPECT_NEAR(psnr(off.view(), ref.view()), 20.0, 1e-4);  // 10 log10(1 / 0.01)
  EXPECT_TRUE(std::isinf(psnr(ref.view(), ref.view())));
}

TEST(Metrics, AMaskScoresOnlyItsPixels) {
  Image ref(16, 16, 0.5f), a = ref;
  std::vector<std::uint8_t> left(16 * 16, 0), right(16 * 16, 0);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      (x < 8 ? left : right)[static_cast<std::size_t>(y) * 16 + x] = 1;
      if (x >= 8) a.set(x, y, 0.7f);  // only the right half differs
    }
  EXPECT_EQ(meanSquaredError(a.view(), ref.view(), left.data()), 0.0);
  EXPECT_NEAR(rootMeanSquaredError(a.view(), ref.view(), right.data()), 0.2, 1e-6);
  EXPECT_NEAR(meanSquaredError(a.view(), ref.view()), 0.5 * 0.04, 1e-7);
  EXPECT_TRUE(std::isinf(psnrHvsM(a.view(), ref.view(), left.data())));
  EXPECT_TRUE(std::isfinite(psnrHvsM(a.view(), ref.view(), right.data())));
}

TEST(Metrics, SsimOfFlatImagesIsTheLuminanceTerm) {
  // Flat images have no variance: SSIM is (2 a b + C1) / (a^2 + b^2 + C1), for any size.
  for (int size : {8, 40}) {
    const Image a(size, size, 0.3f), b(size, size, 0.5f);
    const double c1 = 0.0001, expected = (2 * 0.3 * 0.5 + c1) / (0.09 + 0.25 + c1);
    EXPECT_NEAR(ssim(a.view(), b.view()), expected, 1e-6) << size;
    EXPECT_NEAR(ssim(a.view(), a.view()), 1.0, 1e-12);
  }
}

TEST(Metrics, SsimSeesStructureThatMseDoesNot) {
  // A checkerboard and its inverse have the mean of the reference and the same variance: the
  // luminance and contrast terms are 1 and the structure term is -1.
  Image board(32, 32, 0.0f), inverse(32, 32, 0.0f);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const bool on = (x / 2 + y / 2) % 2 == 0;
      board.set(x, y, on ? 0.7f : 0.3f);
      inverse.set(x, y, on ? 0.3f : 0.7f);
    }
  EXPECT_LT(ssim(inverse.view(), board.view()), -0.9);
  // Noise of the same energy scores better than the inversion, and less noise better still.
  const Image more = noisy(board, 0.3f, 1), less = noisy(board, 0.05f, 2);
  EXPECT_GT(ssim(more.view(), board.view()), ssim(inverse.view(), board.view()));
  EXPECT_GT(ssim(less.view(), board.view()), ssim(more.view(), board.view()));
  EXPECT_LT(ssim(less.view(), board.view()), 1.0);
}

TEST(Metrics, PsnrHvsMOfAFlatOffsetIsKnown) {
  // A flat block's difference is all in its DC coefficient (8 d for an orthonormal DCT), which
  // is never masked and weighs 1.608443: the mean is (1.608443 d)^2 over the 64 coefficients.
  const Image ref(24, 16, 100.0f / 255.0f), off(24, 16, 110.0f / 255.0f);
  const double d = 10.0, expected = 10.0 * std::log10(255.0 * 255.0 / std::pow(1.608443 * d, 2));
  EXPECT_NEAR(psnrHvsM(off.view(), ref.view()), expected, 1e-3);
  EXPECT_NEAR(psnrHvsM(off.view(), ref.view(), nullptr, false), expected, 1e-3) << "nothing to mask on flat blocks";
  EXPECT_TRUE(std::isinf(psnrHvsM(ref.view(), ref.view())));
  const Image tiny(7, 7, 0.2f);
  EXPECT_TRUE(std::isinf(psnrHvsM(tiny.view(), tiny.view()))) << "no whole block";
}

TEST(Metrics, TextureMasksSmallErrors) {
  // The same small noise on a flat image and on a busy texture: PSNR-HVS (no masking) sees
  // about the same error in both; PSNR-HVS-M forgives it in the texture, and never scores below
  // PSNR-HVS.
  Image flat(64, 64, 0.5f), texture(64, 64, 0.5f);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> busy(0.2f, 0.8f);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) texture.set(x, y, busy(rng));
  const Image flatNoisy = noisy(flat, 0.02f, 3), textureNoisy = noisy(texture, 0.02f, 3);
  const double hvsFlat = psnrHvsM(flatNoisy.view(), flat.view(), nullptr, false);
  const double hvsTexture = psnrHvsM(textureNoisy.view(), texture.view(), nullptr, false);
  const double mFlat = psnrHvsM(flatNoisy.view(), flat.view()), mTexture = psnrHvsM(textureNoisy.view(), texture.view());
  EXPECT_NEAR(hvsFlat, hvsTexture, 1.0);
  EXPECT_GE(mFlat, hvsFlat);
  EXPECT_GE(mTexture, hvsTexture);
  EXPECT_GT(mTexture - hvsTexture, mFlat - hvsFlat + 3.0) << "texture hides error";
}

// The affected region: what changed beyond both references' noise, not the noise itself.
TEST(Metrics, TheAffectedRegionIsWhatChangedBeyondNoise) {
  std::mt19937 rng(11);
  std::normal_distribution<float> jitter(0.0f, 1.0f);
  auto reference = [&](bool edited) {
    RenderImage im;
    im.width = 20;
    im.height = 10;
    const std::size_t n = 200;
    const float spp = 64, sigma = 0.1f;  // per sample: the means have 0.0125, their difference 0.018
    im.color.resize(3 * n);
    im.moment2.resize(n);
    im.sampleCount.assign(n, spp);
    for (std::size_t i = 0; i < n; ++i) {
      const int x = static_cast<int>(i % 20);
      float value = 0.5f + (edited && x >= 16 ? 0.15f : 0.0f);  // the edit brightens the right fifth
      value += jitter(rng) * sigma / std::sqrt(spp);            // the mean's own noise
      for (int c = 0; c < 3; ++c) im.color[3 * i + c] = value;
      im.moment2[i] = value * value + sigma * sigma;
    }
    return im;
  };
  const RenderImage before = reference(false), after = reference(true);
  const std::vector<std::uint8_t> mask = affectedPixels(before, after);
  int inside = 0, outside = 0;
  for (std::size_t i = 0; i < mask.size(); ++i) (i % 20 >= 16 ? inside : outside) += mask[i];
  EXPECT_EQ(inside, 40) << "every changed pixel: 0.15 is more than 4 standard errors (0.071) plus noise";
  EXPECT_LE(outside, 1) << "noise alone marks (almost) nothing at 4 standard errors";
  // Without statistics only the relative threshold applies.
  RenderImage bare = before, bareAfter = after;
  bare.moment2.clear();
  bareAfter.moment2.clear();
  int marked = 0;
  for (std::uint8_t m : affectedPixels(bare, bareAfter)) marked += m;
  EXPECT_GT(marked, 40);
}

// A small change spread over every pixel, under per-pixel noise larger than it (a light made
// 4 % brighter, seen through a path tracer's noise): no single pixel shows it, 4x4 blocks do.
TEST(Metrics, TheAffectedRegionPoolsBlocksToFindSmallWidespreadChanges) {
  std::mt19937 rng(5);
  std::normal_distribution<float> jitter(0.0f, 1.0f);
  auto reference = [&](float scale) {
    RenderImage im;
    im.width = 32;
    im.height = 16;
    const std::size_t n = 512;
    const float spp = 256, sigma = 2.0f;  // per sample; the mean's standard error 0.125
    im.color.resize(3 * n);
    im.moment2.resize(n);
    im.sampleCount.assign(n, spp);
    for (std::size_t i = 0; i < n; ++i) {
      const float value = 1.0f * scale + jitter(rng) * sigma / std::sqrt(spp);
      for (int c = 0; c < 3; ++c) im.color[3 * i + c] = value;
      im.moment2[i] = value * value + sigma * sigma;
    }
    return im;
  };
  const RenderImage before = reference(1.0f), brighter = reference(1.5f), same = reference(1.0f);
  // Per pixel the difference's standard error is 0.18: 4 of them (0.71) hide a 0.5 change; a
  // block's is 0.044, so 0.5 stands out.
  int marked = 0;
  for (std::uint8_t m : affectedPixels(before, brighter)) marked += m;
  EXPECT_GT(marked, 500) << "of 512";
  int noise = 0;
  for (std::uint8_t m : affectedPixels(before, same)) noise += m;
  EXPECT_LE(noise, 16) << "at most one block of noise alone";
}

}  // namespace
}  // namespace retile

namespace retile {
namespace {

TEST(Metrics, BlockComparisonAveragesBlocksAndLeavesOutExcludedPixels) {
  // 32x16, two 16x16 blocks: A is the reference plus 10 % on the right block, and a wild pixel in
  // an excluded corner of the left one.
  const int w = 32, h = 16;
  std::vector<float> ref(w * h * 3, 0.5f), a = ref;
  for (int y = 0; y < h; ++y)
    for (int x = 16; x < w; ++x)
      for (int c = 0; c < 3; ++c) a[(y * w + x) * 3 + c] = 0.55f;
  a[0] = 1000.0f;
  BlockComparison b = compareBlocks({a.data(), w, h}, {ref.data(), w, h}, 16, {{0, 0, 2, 2}});
  EXPECT_EQ(b.blocks, 2);
  EXPECT_NEAR(b.meanRef, 0.5, 1e-9);
  EXPECT_NEAR(b.meanA / b.meanRef, 1.05, 1e-3) << "the excluded pixel takes no part";
  // Block means 0.5/0.5 and 0.55/0.5 per channel: sqrt(3 * 0.05^2) / sqrt(6 * 0.25).
  EXPECT_NEAR(b.relativeRmse, std::sqrt(3 * 0.0025) / std::sqrt(6 * 0.25), 1e-6);
  EXPECT_NEAR(b.errorShare[1], 1.0, 1e-9) << "all of the error is in the right block";
  EXPECT_NEAR(b.lumA[1] / b.lumRef[1], 1.1, 1e-5);
  // A block mostly excluded is left out.
  BlockComparison c = compareBlocks({a.data(), w, h}, {ref.data(), w, h}, 16, {{0, 0, 16, 12}});
  EXPECT_EQ(c.blocks, 1);
  EXPECT_TRUE(std::isnan(c.errorShare[0]));
}

TEST(Metrics, BlockNoiseTellsAReferencesNoiseFromABias) {
  // 256x256, 256 blocks: a smooth picture, our two renders with pixel noise 0.05 and the
  // reference with 0.1. With no bias the distance to the reference is sqrt((1 + 4) / 2) = 1.58
  // times the floor, and every block's difference is noise.
  const int w = 256, h = 256;
  std::mt19937 rng(3);
  std::normal_distribution<float> unit(0.0f, 1.0f);
  std::vector<float> truth(w * h * 3), a(truth.size()), b(truth.size()), ref(truth.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) truth[(y * w + x) * 3 + c] = 0.3f + 0.4f * float(x) / w + 0.1f * float(c);
  auto noisy = [&](std::vector<float>& out, float sigma) {
    for (std::size_t i = 0; i < truth.size(); ++i) out[i] = truth[i] + sigma * unit(rng);
  };
  noisy(a, 0.05f);
  noisy(b, 0.05f);
  noisy(ref, 0.1f);
  const MetricImage ia{a.data(), w, h}, ib{b.data(), w, h};
  BlockNoise n = blockNoise(ia, ib, {ref.data(), w, h}, 16);
  EXPECT_EQ(n.blocks, 256);
  EXPECT_EQ(n.scored, 256);
  EXPECT_NEAR(n.reference / n.ours, 2.0, 0.1);
  EXPECT_NEAR(n.expectedRatio, std::sqrt(2.5), 0.08);
  const double ratio = compareBlocks(ia, {ref.data(), w, h}, 16).relativeRmse / compareBlocks(ia, ib, 16).relativeRmse;
  EXPECT_NEAR(ratio, n.expectedRatio, 0.15) << "the ratio noise alone gives";
  EXPECT_NEAR(compareBlocks(ia, ib, 16).relativeRmse / (std::sqrt(2.0) * n.ours), 1.0, 0.15) << "our floor, expected";
  EXPECT_NEAR(n.meanSquaredZ, 1.0, 0.25);
  EXPECT_LE(n.beyond3, 3);

  // Ten blocks of the reference 0.05 darker, about nine standard errors of the difference in
  // luminance (its pixel noise is 0.75 of a channel's: 0.75 sqrt(0.05^2 + 0.1^2) / 16 = 0.0052):
  // each stands out; the noise estimates barely move.
  for (int k = 0; k < 10; ++k)
    for (int y = 16 * k; y < 16 * k + 16; ++y)
      for (int x = 32; x < 48; ++x)
        for (int c = 0; c < 3; ++c) ref[(y * w + x) * 3 + c] -= 0.05f;
  BlockNoise biased = blockNoise(ia, ib, {ref.data(), w, h}, 16);
  EXPECT_NEAR(biased.reference / n.reference, 1.0, 0.01);
  EXPECT_EQ(biased.beyond3, 10 + n.beyond3);
  for (int k = 0; k < 10; ++k) EXPECT_GT(biased.z[static_cast<std::size_t>(k * 16 + 2)], 5.0) << "block row " << k;
  EXPECT_GT(biased.meanSquaredZ, n.meanSquaredZ + 10 * 25.0 / 256);

  // Three identical flat images: no noise at all, yet each block's z stays finite (half-float
  // rounding is the noise left), and a black image is not scored.
  std::vector<float> flat(truth.size(), 0.25f), black(truth.size(), 0.0f);
  const MetricImage f{flat.data(), w, h}, k{black.data(), w, h};
  BlockNoise still = blockNoise(f, f, f, 16);
  EXPECT_EQ(still.scored, 256);
  EXPECT_EQ(still.meanSquaredZ, 0.0);
  EXPECT_EQ(blockNoise(k, k, k, 16).scored, 0);
  EXPECT_EQ(blockNoise(f, f, f, 1).blocks, 0) << "a pixel has no spread";
}

}  // namespace
}  // namespace retile
