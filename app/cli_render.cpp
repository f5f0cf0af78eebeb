// `retile render`: a scene to one image, the way a user checks a scene or makes a reference.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "cli.h"
#include "cli11.h"
#include "retile/image.h"
#include "retile/log.h"
#include "retile/render.h"

namespace retile::cli {

namespace {

struct RenderOptions {
  std::string scene;
  std::optional<ImageSize> size;
  std::optional<int> spp, maxBounces, paths;
  int seed = 0;
  std::string out = "retile-render.png";
  std::optional<std::string> view;  // else the scene's (RenderSettings::view), else Standard
  double exposure = 0;
  bool denoise = false;
};

int runRender(const RenderOptions& o) {
  RenderRequest req;
  req.denoise = o.denoise;
  if (o.size) req.width = o.size->width, req.height = o.size->height;
  if (o.spp) req.samplesPerPixel = *o.spp;
  if (o.maxBounces) req.maxBounces = *o.maxBounces;
  if (o.paths) req.pathsPerInvocation = *o.paths;
  req.seed = static_cast<std::uint32_t>(o.seed);
  DisplaySettings display;
  display.exposure = static_cast<float>(o.exposure);
  const std::filesystem::path out = o.out;

  auto loaded = loadScene(o.scene);
  if (!loaded) {
    std::fprintf(stderr, "error: %s\n", loaded.error().c_str());
    return 1;
  }
  for (const auto& w : loaded->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  display.view = o.view ? *o.view : loaded->scene.settings.view.empty() ? "Standard" : loaded->scene.settings.view;

  Renderer renderer;
  std::fprintf(stderr, "device: %s\n", renderer.deviceName().c_str());
  printRenderWarnings(renderer.setScene(loaded->scene), loaded->warnings);
  auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  FrameStats stats;
  RenderImage image = renderer.render(
      req,
      [&](int done, int total) {
        progressBar("rendering", done, total, elapsed());
        return true;
      },
      &stats);
  auto written = writeRenderImage(image, out, display);
  if (!written) {
    std::fprintf(stderr, "error: %s\n", written.error().c_str());
    return 1;
  }
  double seconds = elapsed();
  std::printf("wrote %s (%dx%d, %.0f spp%s, %.1f s, %.3f M samples/s)\n", std::filesystem::absolute(out).string().c_str(), image.width,
              image.height, image.sampleCount.empty() ? 0.0 : static_cast<double>(image.sampleCount[0]), req.denoise ? ", denoised" : "",
              seconds, stats.seconds > 0 ? static_cast<double>(stats.samples) / stats.seconds * 1e-6 : 0.0);
  // A path cut at the loop limit keeps only the light it gathered so far: the image is biased
  // dark where such paths were, so the render says so rather than pass for converged.
  if (stats.cutPaths > 0)
    std::fprintf(stderr,
                 "warning: %llu paths (%.3f %% of the samples) were cut short, or never started, at the trace kernel's "
                 "loop limit: one cut short lacks the light of the rest of its way (the image is a little dark there), "
                 "one never started leaves its pixel a sample short (retile bench throughput shows how near a scene comes)\n",
                 static_cast<unsigned long long>(stats.cutPaths),
                 100.0 * static_cast<double>(stats.cutPaths) / static_cast<double>(std::max<std::uint64_t>(stats.samples, 1)));
  return 0;
}

}  // namespace

void addRender(CLI::App& app, int* status) {
  CLI::App* cmd = app.add_subcommand("render", "Render a scene to an image (PNG through the view transform, or EXR)");
  auto o = std::make_shared<RenderOptions>();
  addScene(*cmd, &o->scene);
  addSize(*cmd, &o->size, "image size", "the scene's");
  addInt(*cmd, "--spp", &o->spp, 1, 1 << 20, "samples per pixel", "the scene's");
  addInt(*cmd, "--seed", &o->seed, 0, 2147483647, "random seed");
  addInt(*cmd, "--max-bounces", &o->maxBounces, 0, 1024, "longest path", "the scene's");
  addInt(*cmd, "--paths", &o->paths, 1, 1 << 20, "paths per trace invocation (a diagnostic: more run closer to the loop limit)",
         "chosen from the last frame's cost")
      ->type_name("P");
  cmd->add_option("--out", o->out, "the image written: FILE.png or FILE.exr (default: " + o->out + ")")
      ->type_name("FILE")
      ->check(CLI::Validator(
          [](std::string& file) {
            const std::string ext = std::filesystem::path(file).extension().string();
            return ext == ".png" || ext == ".exr" ? std::string() : "'" + file + "' must end in .png or .exr";
          },
          ""));
  cmd->add_option("--view", o->view,
                  "the PNG's OCIO view of the sRGB display: Standard, Filmic or Raw (default: the scene's, as a Tungsten "
                  "camera's tonemap says; else Standard)")
      ->type_name("NAME");
  addNumber(*cmd, "--exposure", &o->exposure, -64, 64, "stops, applied before the PNG's view transform")->type_name("STOPS");
  cmd->add_flag("--denoise", o->denoise, "denoise the whole image (the EXR keeps the raw samples too)");
  cmd->callback([o, status] { *status = runRender(*o); });
}

}  // namespace retile::cli
