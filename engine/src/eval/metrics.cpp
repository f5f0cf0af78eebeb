#include "retile/metrics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>

#include "retile/error.h"

namespace retile {

namespace {

void checkSizes(MetricImage a, MetricImage ref) {
  RETILE_ASSERT(a.width == ref.width && a.height == ref.height && a.width >= 0 && a.height >= 0, "metrics compare images of the same size");
  RETILE_ASSERT((a.rgb && ref.rgb) || a.width * a.height == 0, "metrics need pixels");
}

bool masked(const std::uint8_t* mask, std::size_t pixel) { return !mask || mask[pixel] != 0; }

std::vector<double> luma(MetricImage im, double scale) {
  const std::size_t n = static_cast<std::size_t>(im.width) * static_cast<std::size_t>(im.height);
  std::vector<double> y(n);
  for (std::size_t i = 0; i < n; ++i) y[i] = scale * (0.299 * im.rgb[3 * i] + 0.587 * im.rgb[3 * i + 1] + 0.114 * im.rgb[3 * i + 2]);
  return y;
}

double toDecibels(double mse, double peak) {
  return mse > 0.0 ? 10.0 * std::log10(peak * peak / mse) : std::numeric_limits<double>::infinity();
}

// JPEG's luminance quantization table (ITU-T T.81, Annex K.1). PSNR-HVS-M's published contrast
// sensitivity table is 25.735088 / this table to the six digits printed (1.608443 = 25.735088 /
// 16), and its masking table is (10 / this table)^2, that is the sensitivity squared over its
// largest value squared; both are derived here rather than copied.
constexpr int kJpegLuma[8][8] = {{16, 11, 10, 16, 24, 40, 51, 61},     {12, 12, 14, 19, 26, 58, 60, 55},
                                 {14, 13, 16, 24, 40, 57, 69, 56},     {14, 17, 22, 29, 51, 87, 80, 62},
                                 {18, 22, 37, 56, 68, 109, 103, 77},   {24, 35, 55, 64, 81, 104, 113, 92},
                                 {49, 64, 78, 87, 103, 121, 120, 101}, {72, 92, 95, 98, 112, 100, 103, 99}};
constexpr double kCsfScale = 25.735088;

double csf(int u, int v) { return kCsfScale / kJpegLuma[u][v]; }
double maskWeight(int u, int v) {
  const double r = 10.0 / kJpegLuma[u][v];
  return r * r;
}

using Block = std::array<std::array<double, 8>, 8>;

// The orthonormal 2-D DCT-II (MATLAB's dct2 on an 8x8 block).
Block dct8(const Block& x) {
  static const auto basis = [] {
    std::array<std::array<double, 8>, 8> c{};
    for (int k = 0; k < 8; ++k)
      for (int n = 0; n < 8; ++n)
        c[k][n] = (k == 0 ? std::sqrt(1.0 / 8.0) : std::sqrt(2.0 / 8.0)) * std::cos(std::numbers::pi * (2 * n + 1) * k / 16.0);
    return c;
  }();
  Block rows{}, out{};
  for (int i = 0; i < 8; ++i)
    for (int k = 0; k < 8; ++k) {
      double s = 0;
      for (int n = 0; n < 8; ++n) s += basis[k][n] * x[i][n];
      rows[i][k] = s;
    }
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 8; ++j) {
      double s = 0;
      for (int n = 0; n < 8; ++n) s += basis[k][n] * rows[n][j];
      out[k][j] = s;
    }
  return out;
}

// Sum of squared deviations from the mean (the authors' vari: variance times the count).
double spread(const Block& b, int u0, int v0, int size) {
  double sum = 0, squares = 0;
  for (int u = u0; u < u0 + size; ++u)
    for (int v = v0; v < v0 + size; ++v) sum += b[u][v], squares += b[u][v] * b[u][v];
  const double n = size * size;
  return std::max(0.0, squares - sum * sum / n);
}

// How much of a coefficient's difference the block's own texture hides: the masking-weighted AC
// energy, scaled down where the block's activity is uneven over its quadrants (an edge beside a
// flat area masks less than texture all over).
double maskingOf(const Block& pixels, const Block& coefficients) {
  double energy = 0;
  for (int u = 0; u < 8; ++u)
    for (int v = 0; v < 8; ++v)
      if (u != 0 || v != 0) energy += coefficients[u][v] * coefficients[u][v] * maskWeight(u, v);
  double activity = spread(pixels, 0, 0, 8);
  if (activity != 0)
    activity = (spread(pixels, 0, 0, 4) + spread(pixels, 0, 4, 4) + spread(pixels, 4, 4, 4) + spread(pixels, 4, 0, 4)) / activity;
  return std::sqrt(energy * activity) / 32.0;
}

}  // namespace

double meanSquaredError(MetricImage a, MetricImage ref, const std::uint8_t* mask) {
  checkSizes(a, ref);
  const std::size_t n = static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height);
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!masked(mask, i)) continue;
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(a.rgb[3 * i + c]) - ref.rgb[3 * i + c];
      sum += d * d;
    }
    ++count;
  }
  return count ? sum / (3.0 * static_cast<double>(count)) : 0.0;
}

double rootMeanSquaredError(MetricImage a, MetricImage ref, const std::uint8_t* mask) { return std::sqrt(meanSquaredError(a, ref, mask)); }

double psnr(MetricImage a, MetricImage ref, const std::uint8_t* mask) { return toDecibels(meanSquaredError(a, ref, mask), 1.0); }

double ssim(MetricImage a, MetricImage ref, const std::uint8_t* mask) {
  checkSizes(a, ref);
  const int w = a.width, h = a.height;
  if (w == 0 || h == 0) return 1.0;
  const std::vector<double> x = luma(a, 1.0), y = luma(ref, 1.0);
  constexpr double kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
  auto index = [&](double mx, double my, double vx, double vy, double cxy) {
    return ((2 * mx * my + kC1) * (2 * cxy + kC2)) / ((mx * mx + my * my + kC1) * (vx + vy + kC2));
  };
  constexpr int kWindow = 11, kRadius = 5;
  if (w < kWindow || h < kWindow) {
    // One window over the whole (small) image, equal weights.
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
    mx /= static_cast<double>(x.size()), my /= static_cast<double>(x.size());
    double vx = 0, vy = 0, cxy = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
      vx += (x[i] - mx) * (x[i] - mx), vy += (y[i] - my) * (y[i] - my), cxy += (x[i] - mx) * (y[i] - my);
    const double n = static_cast<double>(x.size());
    return index(mx, my, vx / n, vy / n, cxy / n);
  }
  std::array<double, kWindow> g{};
  double gs = 0;
  for (int i = 0; i < kWindow; ++i) gs += g[i] = std::exp(-(i - kRadius) * (i - kRadius) / (2.0 * 1.5 * 1.5));
  for (double& v : g) v /= gs;
  // The five local moments, filtered separably over the windows that fit ('valid').
  const int ow = w - kWindow + 1, oh = h - kWindow + 1;
  auto filter = [&](auto value) {
    std::vector<double> rows(static_cast<std::size_t>(ow) * h), out(static_cast<std::size_t>(ow) * oh);
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < ow; ++c) {
        double s = 0;
        for (int k = 0; k < kWindow; ++k) s += g[k] * value(static_cast<std::size_t>(r) * w + c + k);
        rows[static_cast<std::size_t>(r) * ow + c] = s;
      }
    for (int r = 0; r < oh; ++r)
      for (int c = 0; c < ow; ++c) {
        double s = 0;
        for (int k = 0; k < kWindow; ++k) s += g[k] * rows[static_cast<std::size_t>(r + k) * ow + c];
        out[static_cast<std::size_t>(r) * ow + c] = s;
      }
    return out;
  };
  const auto mx = filter([&](std::size_t i) { return x[i]; });
  const auto my = filter([&](std::size_t i) { return y[i]; });
  const auto xx = filter([&](std::size_t i) { return x[i] * x[i]; });
  const auto yy = filter([&](std::size_t i) { return y[i] * y[i]; });
  const auto xy = filter([&](std::size_t i) { return x[i] * y[i]; });
  double sum = 0;
  std::size_t count = 0;
  for (int r = 0; r < oh; ++r)
    for (int c = 0; c < ow; ++c) {
      if (!masked(mask, static_cast<std::size_t>(r + kRadius) * w + c + kRadius)) continue;
      const std::size_t i = static_cast<std::size_t>(r) * ow + c;
      sum += index(mx[i], my[i], xx[i] - mx[i] * mx[i], yy[i] - my[i] * my[i], xy[i] - mx[i] * my[i]);
      ++count;
    }
  return count ? sum / static_cast<double>(count) : 1.0;
}

double psnrHvsM(MetricImage a, MetricImage ref, const std::uint8_t* mask, bool masking) {
  checkSizes(a, ref);
  const int w = a.width, h = a.height;
  const std::vector<double> x = luma(a, 255.0), y = luma(ref, 255.0);
  double sum = 0;
  std::size_t blocks = 0;
  for (int by = 0; by + 8 <= h; by += 8)
    for (int bx = 0; bx + 8 <= w; bx += 8) {
      bool any = !mask;
      Block px{}, py{};
      for (int u = 0; u < 8; ++u)
        for (int v = 0; v < 8; ++v) {
          const std::size_t i = static_cast<std::size_t>(by + u) * w + bx + v;
          px[u][v] = x[i];
          py[u][v] = y[i];
          any = any || mask[i] != 0;
        }
      if (!any) continue;
      const Block dx = dct8(px), dy = dct8(py);
      const double hidden = masking ? std::max(maskingOf(px, dx), maskingOf(py, dy)) : 0.0;
      for (int u = 0; u < 8; ++u)
        for (int v = 0; v < 8; ++v) {
          double d = std::abs(dx[u][v] - dy[u][v]);
          if (masking && (u != 0 || v != 0)) {
            const double threshold = hidden / maskWeight(u, v);
            d = d < threshold ? 0.0 : d - threshold;
          }
          const double weighted = d * csf(u, v);
          sum += weighted * weighted;
        }
      ++blocks;
    }
  if (blocks == 0) return std::numeric_limits<double>::infinity();
  return toDecibels(sum / (64.0 * static_cast<double>(blocks)), 255.0);
}

std::vector<std::uint8_t> affectedPixels(const RenderImage& before, const RenderImage& after, double z, double relative) {
  RETILE_ASSERT(before.width == after.width && before.height == after.height, "references of the same size");
  const std::size_t n = static_cast<std::size_t>(before.width) * static_cast<std::size_t>(before.height);
  RETILE_ASSERT(before.color.size() == 3 * n && after.color.size() == 3 * n, "references with colour");
  auto lum = [](const RenderImage& im, std::size_t i) {
    return 0.2126 * im.color[3 * i] + 0.7152 * im.color[3 * i + 1] + 0.0722 * im.color[3 * i + 2];
  };
  // The variance of a reference's mean at a pixel; 0 when it lacks the statistics (then only
  // the relative threshold applies).
  auto varianceOfMean = [n](const RenderImage& im, std::size_t i, double mean) {
    if (im.moment2.size() != n || im.sampleCount.size() != n || im.sampleCount[i] <= 1) return 0.0;
    return std::max(0.0, im.moment2[i] - mean * mean) / im.sampleCount[i];
  };
  std::vector<std::uint8_t> mask(n, 0);
  auto changed = [&](double a, double b, double varianceOfDifference) {
    const double d = std::abs(a - b);
    return d > z * std::sqrt(varianceOfDifference) && d > relative * std::max(a, b);
  };
  for (std::size_t i = 0; i < n; ++i) {
    const double a = lum(before, i), b = lum(after, i);
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    mask[i] = changed(a, b, varianceOfMean(before, i, a) + varianceOfMean(after, i, b));
  }
  // A path tracer's per-pixel noise hides small changes spread over many pixels (a light 50 %
  // brighter, seen through its bright, noisy samples): the same test on each aligned block of
  // kBlock x kBlock pixels, whose mean has 1/kBlock^2 of the variance, marks the whole block.
  constexpr int kBlock = 4;
  const int w = before.width, h = before.height;
  for (int by = 0; by < h; by += kBlock)
    for (int bx = 0; bx < w; bx += kBlock) {
      double a = 0, b = 0, var = 0;
      int count = 0;
      for (int y = by; y < std::min(by + kBlock, h); ++y)
        for (int x = bx; x < std::min(bx + kBlock, w); ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
          const double pa = lum(before, i), pb = lum(after, i);
          if (!std::isfinite(pa) || !std::isfinite(pb)) continue;
          a += pa, b += pb;
          var += varianceOfMean(before, i, pa) + varianceOfMean(after, i, pb);
          ++count;
        }
      if (count == 0 || !changed(a / count, b / count, var / (static_cast<double>(count) * count))) continue;
      for (int y = by; y < std::min(by + kBlock, h); ++y)
        for (int x = bx; x < std::min(bx + kBlock, w); ++x)
          mask[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] = 1;
    }
  return mask;
}

namespace {

// The aligned block x block squares of a width x height image (partial ones at the right and
// bottom edges), row-major, each with the indices of its pixels outside `exclude`; a block with
// fewer than half its pixels left has none (it is left out). One flat array: at blocks of one
// pixel a vector per block would cost a megapixel image a million allocations.
struct BlockGrid {
  int cols = 0, rows = 0;
  std::vector<std::size_t> index, start;  // block k's pixels: index[start[k]] .. index[start[k + 1] - 1]
  std::size_t blocks() const { return start.size() - 1; }
  std::span<const std::size_t> pixels(std::size_t k) const { return {index.data() + start[k], start[k + 1] - start[k]}; }
};

BlockGrid blockGrid(int width, int height, int block, const std::vector<PixelRect>& exclude) {
  RETILE_ASSERT(block >= 1, "blocks of at least one pixel");
  BlockGrid g;
  g.cols = (width + block - 1) / block;
  g.rows = (height + block - 1) / block;
  g.index.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  g.start.reserve(static_cast<std::size_t>(g.cols) * static_cast<std::size_t>(g.rows) + 1);
  g.start.push_back(0);
  for (int by = 0; by < g.rows; ++by)
    for (int bx = 0; bx < g.cols; ++bx) {
      int all = 0;
      for (int y = by * block; y < std::min(height, (by + 1) * block); ++y)
        for (int x = bx * block; x < std::min(width, (bx + 1) * block); ++x) {
          ++all;
          if (std::none_of(exclude.begin(), exclude.end(), [&](const PixelRect& r) { return r.contains(x, y); }))
            g.index.push_back(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x));
        }
      if (2 * (g.index.size() - g.start.back()) < static_cast<std::size_t>(all)) g.index.resize(g.start.back());
      g.start.push_back(g.index.size());
    }
  return g;
}

double pixelLuminance(MetricImage im, std::size_t i) {
  return 0.2126 * im.rgb[3 * i] + 0.7152 * im.rgb[3 * i + 1] + 0.0722 * im.rgb[3 * i + 2];
}

}  // namespace

BlockComparison compareBlocks(MetricImage a, MetricImage ref, int block, const std::vector<PixelRect>& exclude) {
  checkSizes(a, ref);
  const BlockGrid grid = blockGrid(a.width, a.height, block, exclude);
  BlockComparison out;
  out.cols = grid.cols;
  out.rows = grid.rows;
  const std::size_t nb = grid.blocks();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.lumA.assign(nb, nan);
  out.lumRef.assign(nb, nan);
  out.errorShare.assign(nb, nan);
  std::vector<double> squared(nb, nan);
  double sumA = 0.0, sumRef = 0.0, err = 0.0, norm = 0.0;
  std::size_t pixels = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    const auto in = grid.pixels(b);
    if (in.empty()) continue;
    double ma[3] = {0, 0, 0}, mr[3] = {0, 0, 0};
    for (std::size_t i : in)
      for (std::size_t c = 0; c < 3; ++c) {
        ma[c] += a.rgb[3 * i + c];
        mr[c] += ref.rgb[3 * i + c];
      }
    const double n = static_cast<double>(in.size());
    double e = 0.0;
    for (int c = 0; c < 3; ++c) {
      sumA += ma[c];
      sumRef += mr[c];
      ma[c] /= n;
      mr[c] /= n;
      e += (ma[c] - mr[c]) * (ma[c] - mr[c]);
      norm += mr[c] * mr[c];
    }
    pixels += in.size();
    squared[b] = e;
    err += e;
    out.lumA[b] = 0.2126 * ma[0] + 0.7152 * ma[1] + 0.0722 * ma[2];
    out.lumRef[b] = 0.2126 * mr[0] + 0.7152 * mr[1] + 0.0722 * mr[2];
    ++out.blocks;
  }
  if (pixels > 0) {
    out.meanA = sumA / (3.0 * static_cast<double>(pixels));
    out.meanRef = sumRef / (3.0 * static_cast<double>(pixels));
  }
  out.relativeRmse = norm > 0.0 ? std::sqrt(err / norm) : (err > 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
  for (std::size_t b = 0; b < nb; ++b)
    if (!std::isnan(squared[b])) out.errorShare[b] = err > 0.0 ? squared[b] / err : 0.0;
  return out;
}

BlockNoise blockNoise(MetricImage a, MetricImage b, MetricImage ref, int block, const std::vector<PixelRect>& exclude) {
  checkSizes(a, ref);
  checkSizes(b, ref);
  const BlockGrid grid = blockGrid(a.width, a.height, block, exclude);
  BlockNoise out;
  out.z.assign(grid.blocks(), std::numeric_limits<double>::quiet_NaN());
  // Sample variance about the block's mean of d(i), over the block's pixels (two passes: a bright
  // light's pixels would cancel in the sum of squares).
  auto spread = [](std::span<const std::size_t> in, auto d) {
    const double n = static_cast<double>(in.size());
    double mean = 0.0, sq = 0.0;
    for (std::size_t i : in) mean += d(i);
    mean /= n;
    for (std::size_t i : in) sq += (d(i) - mean) * (d(i) - mean);
    return sq / (n - 1.0);
  };
  double varOurs = 0.0, varRef = 0.0, norm = 0.0, zSquared = 0.0;
  for (std::size_t k = 0; k < grid.blocks(); ++k) {
    const auto in = grid.pixels(k);
    if (in.empty()) continue;
    const double n = static_cast<double>(in.size());
    double ma = 0.0, mr = 0.0, channel[3] = {0, 0, 0};
    for (std::size_t i : in) {
      ma += pixelLuminance(a, i);
      mr += pixelLuminance(ref, i);
      for (std::size_t c = 0; c < 3; ++c) channel[c] += ref.rgb[3 * i + c];
    }
    for (std::size_t c = 0; c < 3; ++c) norm += (channel[c] / n) * (channel[c] / n);  // as compareBlocks normalises
    if (in.size() < 2) continue;                                                      // no spread to estimate a noise from
    // Per channel and in luminance (c = 3): A - B has twice our pixel variance; Ref - (A + B) / 2
    // has the reference's plus half ours.
    double ours[4], theirs[4];
    for (std::size_t c = 0; c < 4; ++c) {
      auto value = [c](MetricImage im, std::size_t i) { return c < 3 ? double(im.rgb[3 * i + c]) : pixelLuminance(im, i); };
      ours[c] = 0.5 * spread(in, [&](std::size_t i) { return value(a, i) - value(b, i); });
      theirs[c] =
          std::max(0.0, spread(in, [&](std::size_t i) { return value(ref, i) - 0.5 * (value(a, i) + value(b, i)); }) - 0.5 * ours[c]);
    }
    for (std::size_t c = 0; c < 3; ++c) {
      varOurs += ours[c] / n;
      varRef += theirs[c] / n;
    }
    ++out.blocks;
    // Both images' rounding to half floats (11 significant bits) counts as noise, undivided by n
    // (in a flat region every pixel rounds the same way): a region rendered without noise would
    // otherwise stand out at an infinite z.
    const double rounding = std::ldexp(std::max(std::abs(ma), std::abs(mr)) / n, -11);
    const double se = std::sqrt((ours[3] + theirs[3]) / n + 2.0 * rounding * rounding / 3.0), d = (ma - mr) / n;
    if (!(se > 0.0)) continue;  // black in all three images: nothing to tell
    out.z[k] = d / se;
    zSquared += out.z[k] * out.z[k];
    out.beyond3 += std::abs(out.z[k]) > 3.0;
    ++out.scored;
  }
  if (out.blocks == 0) return out;
  out.ours = norm > 0.0 ? std::sqrt(varOurs / norm) : 0.0;
  out.reference = norm > 0.0 ? std::sqrt(varRef / norm) : 0.0;
  out.expectedRatio = varOurs > 0.0 ? std::sqrt((varOurs + varRef) / (2.0 * varOurs)) : std::numeric_limits<double>::infinity();
  out.meanSquaredZ = out.scored > 0 ? zSquared / out.scored : 0.0;
  return out;
}

}  // namespace retile
