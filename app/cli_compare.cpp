// retile compare: how far a render is from another renderer's reference, in units of our own
// noise (issue 15's acceptance): block-averaged relative RMSE against the reference and, with a
// second render of ours at another seed, against that (the noise floor), and how much of the
// difference both renders' noise can explain (blockNoise).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numeric>

#include "cli.h"
#include "cli11.h"
#include "io/image_io.h"
#include "retile/metrics.h"

namespace retile::cli {

namespace {

struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;
};

Result<RgbImage> readRgb(const std::string& file) {
  auto im = readImageRaw(file);
  if (!im) return Result<RgbImage>::failure(im.error());
  RgbImage out{im->width, im->height, {}};
  out.rgb.resize(static_cast<std::size_t>(im->width) * static_cast<std::size_t>(im->height) * 3);
  for (std::size_t i = 0; i * 3 < out.rgb.size(); ++i)
    for (std::size_t c = 0; c < 3; ++c) out.rgb[3 * i + c] = im->rgba[4 * i + c];
  if (std::any_of(out.rgb.begin(), out.rgb.end(), [](float v) { return !std::isfinite(v); }))
    return Result<RgbImage>::failure(file + ": has pixels that are not finite numbers");
  return out;
}

Result<PixelRect> parseRect(const std::string& text) {
  PixelRect r;
  int* dst[4] = {&r.x, &r.y, &r.width, &r.height};
  std::size_t at = 0;
  for (int i = 0; i < 4; ++i) {
    std::size_t end = i < 3 ? text.find(',', at) : text.size();
    if (end == std::string::npos) return Result<PixelRect>::failure("'" + text + "' is not X,Y,W,H");
    auto v = readInt(text.substr(at, end - at), 0, 1 << 20);
    if (!v) return Result<PixelRect>::failure(v.error());
    *dst[i] = v.value();
    at = end + 1;
  }
  return r;
}

struct CompareOptions {
  std::string image, reference, noise;
  int block = 16, worst = 8;
  std::vector<std::string> exclude;
};

// How much of the distance to the reference the two renders' noise explains (blockNoise).
void printNoise(const BlockNoise& noise, double distance) {
  if (noise.blocks == 0) {
    std::printf("noise of the block means: not estimated (it needs blocks of two pixels or more)\n");
    return;
  }
  std::printf(
      "noise of the block means, estimated from the spread of each block's pixels (the reference's is an\n"
      "upper bound: differences at pixel scale, such as edges, count as its noise):\n");
  std::printf("  ours %.3g, the reference's %.3g: with no bias the ratio would be about %.2f\n", noise.ours, noise.reference,
              noise.expectedRatio);
  // One pair's floor is a sum dominated by a few bright, noisy blocks: it scatters widely, mostly
  // below its root-mean-square, and the ratio with it (the spaceship: 1.38 to 2.42 over six pairs).
  const double rmsFloor = std::sqrt(2.0) * noise.ours;
  std::printf("  root-mean-square floor of our noise: %.3g; ratio against it %.2f\n", rmsFloor,
              rmsFloor > 0 ? distance / rmsFloor : std::numeric_limits<double>::infinity());
  std::printf(
      "  block differences in units of both renders' noise: mean square %.2f (1 when only noise differs); "
      "%d of %d blocks beyond 3 (noise alone: %.1f)\n",
      noise.meanSquaredZ, noise.beyond3, noise.scored, 0.0027 * noise.scored);
}

int runCompare(const CompareOptions& o) {
  const int block = o.block, worst = o.worst;
  std::vector<PixelRect> exclude;
  for (const auto& text : o.exclude) exclude.push_back(parseRect(text).value());  // checked by the option
  std::vector<std::string> files = {o.image, o.reference};
  if (!o.noise.empty()) files.push_back(o.noise);
  std::vector<RgbImage> images;
  for (const auto& f : files) {
    auto im = readRgb(f);
    if (!im) return std::fprintf(stderr, "error: %s\n", im.error().c_str()), 1;
    if (!images.empty() && (im->width != images[0].width || im->height != images[0].height)) {
      std::fprintf(stderr, "error: %s is %dx%d, %s is %dx%d\n", f.c_str(), im->width, im->height, files[0].c_str(), images[0].width,
                   images[0].height);
      return 1;
    }
    images.push_back(std::move(im.value()));
  }
  auto view = [&](std::size_t i) { return MetricImage{images[i].rgb.data(), images[i].width, images[i].height}; };
  BlockComparison c = compareBlocks(view(0), view(1), block, exclude);
  BlockNoise noise;  // with --noise
  std::printf("compared: %d of %d %dx%d blocks\n", c.blocks, c.cols * c.rows, block, block);
  std::printf("mean RGB: %.6g against %.6g (%+.3f %%)\n", c.meanA, c.meanRef, c.meanRef > 0 ? 100.0 * (c.meanA / c.meanRef - 1.0) : 0.0);
  std::printf("relative RMSE of block means against the reference: %.4f\n", c.relativeRmse);
  if (images.size() == 3) {
    BlockComparison n = compareBlocks(view(0), view(2), block, exclude);
    std::printf("noise floor (against %s): %.4f; ratio %.2f\n", files[2].c_str(), n.relativeRmse,
                n.relativeRmse > 0 ? c.relativeRmse / n.relativeRmse : std::numeric_limits<double>::infinity());
    std::printf("mean RGB of the two seeds differ by %+.3f %%\n", n.meanRef > 0 ? 100.0 * (n.meanA / n.meanRef - 1.0) : 0.0);
    // Noise, ours or the reference's, averages away as blocks grow; a systematic difference does
    // not, so a ratio that climbs with the block size points at a bias rather than at noise.
    std::printf("by block size (a ratio that grows with the size is a systematic difference, not noise):\n");
    for (int size = 1; size <= 32; size *= 2) {
      const BlockComparison cs = size == block ? c : compareBlocks(view(0), view(1), size, exclude);
      const BlockComparison ns = size == block ? n : compareBlocks(view(0), view(2), size, exclude);
      std::printf("  block %2d: %.4f against a floor of %.4f, ratio %.2f\n", size, cs.relativeRmse, ns.relativeRmse,
                  ns.relativeRmse > 0 ? cs.relativeRmse / ns.relativeRmse : std::numeric_limits<double>::infinity());
    }
    noise = blockNoise(view(0), view(2), view(1), block, exclude);
    printNoise(noise, c.relativeRmse);
  }
  std::vector<std::size_t> order(c.errorShare.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  order.erase(std::remove_if(order.begin(), order.end(), [&](std::size_t b) { return std::isnan(c.errorShare[b]); }), order.end());
  std::sort(order.begin(), order.end(), [&](std::size_t p, std::size_t q) { return c.errorShare[p] > c.errorShare[q]; });
  // Block b's top-left pixel, and how far apart its luminances are in percent.
  auto column = [&](std::size_t b) { return static_cast<int>(b % static_cast<std::size_t>(c.cols)) * block; };
  auto row = [&](std::size_t b) { return static_cast<int>(b / static_cast<std::size_t>(c.cols)) * block; };
  auto apart = [&](std::size_t b) { return c.lumRef[b] > 0 ? 100.0 * (c.lumA[b] / c.lumRef[b] - 1.0) : 0.0; };
  const bool withZ = noise.blocks > 0;
  if (worst > 0 && !order.empty())
    std::printf("largest shares of the error (block at pixel x, y: share, luminance against reference%s):\n",
                withZ ? ", difference in units of its noise" : "");
  for (std::size_t k = 0; k < order.size() && k < static_cast<std::size_t>(worst); ++k) {
    std::size_t b = order[k];
    std::printf("  %4d, %4d: %5.1f %%  %.4g against %.4g (%+.0f %%)", column(b), row(b), 100.0 * c.errorShare[b], c.lumA[b], c.lumRef[b],
                apart(b));
    if (withZ && !std::isnan(noise.z[b])) std::printf("  z %+.1f", noise.z[b]);
    std::printf("\n");
  }
  if (withZ && worst > 0 && noise.beyond3 > 0) {
    // Small but certain differences: in smooth, low-noise regions a bias too small to carry a
    // share of the error still stands out against the noise.
    order.erase(std::remove_if(order.begin(), order.end(), [&](std::size_t b) { return std::isnan(noise.z[b]); }), order.end());
    std::sort(order.begin(), order.end(), [&](std::size_t p, std::size_t q) { return std::abs(noise.z[p]) > std::abs(noise.z[q]); });
    std::printf("largest differences in units of their noise (block at pixel x, y: z, luminance against reference):\n");
    for (std::size_t k = 0; k < order.size() && k < static_cast<std::size_t>(worst) && std::abs(noise.z[order[k]]) > 3.0; ++k) {
      std::size_t b = order[k];
      std::printf("  %4d, %4d: z %+6.1f  %.4g against %.4g (%+.1f %%)\n", column(b), row(b), noise.z[b], c.lumA[b], c.lumRef[b], apart(b));
    }
  }
  return 0;
}

}  // namespace

void addCompare(CLI::App& app, int* status) {
  CLI::App* cmd = app.add_subcommand("compare",
                                     "How far IMAGE is from REFERENCE (another renderer's), in units of our own noise: relative RMSE of "
                                     "block means");
  auto o = std::make_shared<CompareOptions>();
  cmd->add_option("IMAGE", o->image, "our render (EXR, PNG, any image OpenImageIO reads)")->required()->type_name("");
  cmd->add_option("REFERENCE", o->reference, "the image to compare against")->required()->type_name("");
  cmd->add_option("--noise", o->noise, "a second render of IMAGE's scene at another seed: its distance from IMAGE is the noise floor")
      ->type_name("IMAGE2");
  addInt(*cmd, "--block", &o->block, 1, 4096, "side of the blocks averaged");
  cmd->add_option("--exclude", o->exclude,
                  "leave out the pixels of this rectangle (repeat for more); a block counts if half its pixels remain")
      ->type_name("X,Y,W,H")
      ->allow_extra_args(false)
      ->check(CLI::Validator(
          [](std::string& text) {
            auto r = parseRect(text);
            return r ? std::string() : r.error();
          },
          ""));
  addInt(*cmd, "--worst", &o->worst, 0, 1000, "list the blocks with the largest shares of the error")->type_name("K");
  cmd->callback([o, status] { *status = runCompare(*o); });
}

}  // namespace retile::cli
