#include <chrono>
#include <cstdio>
#include <filesystem>

#include "cli.h"
#include "retile/image.h"
#include "retile/log.h"
#include "retile/render.h"

namespace retile::cli {

int runRender(const std::vector<std::string>& argv) {
  auto args = parseArgs(argv, {"--size", "--spp", "--seed", "--max-bounces", "--out", "--view", "--exposure"}, {"--denoise"});
  if (!args || args->positional.size() != 1) {
    std::fprintf(stderr,
                 "%s%susage: retile render SCENE [--size WxH] [--spp N] [--seed S] [--max-bounces B] [--denoise] [--out FILE]\n",
                 args ? "" : args.error().c_str(), args ? "" : "\n");
    return 2;
  }
  RenderRequest req;
  req.denoise = args->has("--denoise");
  if (args->has("--size")) {
    auto r = parseSize(args->get("--size"), &req.width, &req.height);
    if (!r) return std::fprintf(stderr, "error: %s\n", r.error().c_str()), 2;
  }
  for (auto [opt, dst, lo, hi] : {std::tuple{"--spp", &req.samplesPerPixel, 1, 1 << 20},
                                  std::tuple{"--max-bounces", &req.maxBounces, 0, 1024}}) {
    if (!args->has(opt)) continue;
    auto v = parseInt(opt, args->get(opt), lo, hi);
    if (!v) return std::fprintf(stderr, "error: %s\n", v.error().c_str()), 2;
    *dst = v.value();
  }
  if (args->has("--seed")) {
    auto v = parseInt("--seed", args->get("--seed"), 0, 2147483647);
    if (!v) return std::fprintf(stderr, "error: %s\n", v.error().c_str()), 2;
    req.seed = static_cast<std::uint32_t>(v.value());
  }
  DisplaySettings display;
  display.view = args->get("--view", "Standard");
  if (args->has("--exposure")) {
    auto v = parseNumber("--exposure", args->get("--exposure"), -64, 64);
    if (!v) return std::fprintf(stderr, "error: %s\n", v.error().c_str()), 2;
    display.exposure = static_cast<float>(v.value());
  }
  std::filesystem::path out = args->get("--out", "retile-render.png");
  std::string ext = out.extension().string();
  if (ext != ".png" && ext != ".exr") {
    std::fprintf(stderr, "error: --out: '%s' must end in .png or .exr\n", out.string().c_str());
    return 2;
  }

  auto loaded = loadScene(args->positional[0]);
  if (!loaded) {
    std::fprintf(stderr, "error: %s\n", loaded.error().c_str());
    return 1;
  }
  for (const auto& w : loaded->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());

  Renderer renderer;
  std::fprintf(stderr, "device: %s\n", renderer.deviceName().c_str());
  printRenderWarnings(renderer.setScene(loaded->scene), loaded->warnings);
  auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  FrameStats stats;
  RenderImage image = renderer.render(req, [&](int done, int total) {
    progressBar("rendering", done, total, elapsed());
    return true;
  }, &stats);
  auto written = writeRenderImage(image, out, display);
  if (!written) {
    std::fprintf(stderr, "error: %s\n", written.error().c_str());
    return 1;
  }
  double seconds = elapsed();
  std::printf("wrote %s (%dx%d, %.0f spp%s, %.1f s, %.3f M samples/s)\n", std::filesystem::absolute(out).string().c_str(),
              image.width, image.height, image.sampleCount.empty() ? 0.0 : static_cast<double>(image.sampleCount[0]),
              req.denoise ? ", denoised" : "", seconds, stats.seconds > 0 ? static_cast<double>(stats.samples) / stats.seconds * 1e-6 : 0.0);
  return 0;
}

}  // namespace retile::cli
