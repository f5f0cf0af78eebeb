// `retile edit`: converges a scene, plays a script of timed edits under one method, and writes
// every frame (EXR) and a per-frame CSV. With --reference, also renders the scene's final state
// fresh and reports each frame's error against it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "cli.h"
#include "cli11.h"
#include "retile/color.h"
#include "retile/eval.h"
#include "retile/image.h"
#include "retile/log.h"
#include "retile/metrics.h"
#include "retile/render.h"
#include "retile/scenario.h"
#include "retile/session.h"

namespace retile::cli {

namespace {

struct EditOptions {
  std::string scene, script, outDir;
  MethodSettings method;  // the kind is set from methodName when the command runs
  std::string methodName;
  std::optional<ImageSize> size;
  std::optional<int> converge, maxBounces, reference;
  int block = 4;
  double threshold = 0.01;
  bool noSoftBorders = false, noImages = false;
};

int runEdit(EditOptions o) {
  MethodSettings& method = o.method;
  methodFromName(o.methodName, &method.kind);  // checked by the option
  method.softBorders = !o.noSoftBorders;
  if (std::string bad = validateMethodSettings(method); !bad.empty()) throw CLI::ValidationError(bad);
  const int reference = o.reference.value_or(0), block = o.block;
  const double threshold = o.threshold;

  auto loaded = loadScene(o.scene);
  if (!loaded) return std::fprintf(stderr, "error: %s\n", loaded.error().c_str()), 1;
  for (const auto& w : loaded->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  Scene scene = loaded->scene;
  if (o.size) scene.settings.width = o.size->width, scene.settings.height = o.size->height;
  if (o.maxBounces) scene.settings.maxBounces = *o.maxBounces;
  auto scenario = loadScenario(o.script);
  if (!scenario) return std::fprintf(stderr, "error: %s\n", scenario.error().c_str()), 1;
  const int converge = o.converge.value_or(scenario->converge);
  // The script played without rendering (eval's planner): its last frame shows the final state.
  auto played = eval::planScenario(scenario.value(), scene, std::numeric_limits<int>::max());
  if (!played) return std::fprintf(stderr, "error: %s: %s\n", o.script.c_str(), played.error().c_str()), 1;
  const Scene& finalScene = played->states.empty() ? played->start : played->states.back();

  std::filesystem::path outDir = o.outDir;
  std::error_code ec;
  std::filesystem::create_directories(outDir, ec);
  if (ec) return std::fprintf(stderr, "error: cannot create %s: %s\n", outDir.string().c_str(), ec.message().c_str()), 1;
  const bool images = !o.noImages;
  const int w = scene.settings.width, h = scene.settings.height;

  // The fresh render of the final state, from its own renderer and seed. The display-referred
  // copies are what PSNR, SSIM and PSNR-HVS-M compare: the image as a viewer sees it.
  std::vector<float> ref, refDisplay;
  const std::shared_ptr<const ColorConfig> colors = reference > 0 ? ColorConfig::get() : nullptr;
  auto displayed = [&](const std::vector<float>& linear) {
    std::vector<float> out(linear.size());
    colors->toDisplayFloat(linear.data(), linear.size() / 3, DisplaySettings{}, out.data());
    for (float& v : out) v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    return out;
  };
  std::vector<std::uint8_t> affected, rest;  // the pixels the script changed, and the others
  std::size_t affectedCount = 0;
  if (reference > 0) {
    Renderer r;
    auto renderReference = [&](const Scene& state, const char* what) {
      r.setScene(state);
      RenderRequest req;
      req.width = w;
      req.height = h;
      req.samplesPerPixel = reference;
      req.seed = 0x5eed;
      auto t0 = std::chrono::steady_clock::now();
      return r.render(req, [&](int done, int total) {
        progressBar(what, done, total, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        return true;
      });
    };
    RenderImage img = renderReference(finalScene, "reference");
    ref = img.color;
    refDisplay = displayed(ref);
    writeRenderImage(img, outDir / "reference.exr");
    // The starting state's reference too: where the two differ beyond their noise is the region
    // the edits affected, scored apart from the rest.
    RenderImage start = renderReference(scene, "reference before");
    affected = affectedPixels(start, img);
    rest.resize(affected.size());
    for (std::size_t i = 0; i < affected.size(); ++i) affectedCount += affected[i], rest[i] = !affected[i];
    std::fprintf(stderr, "affected region: %zu of %zu pixels\n", affectedCount, affected.size());
  }

  RenderSession session(scene, method);
  std::fprintf(stderr, "device: %s\n", session.deviceName().c_str());
  printRenderWarnings(session.sceneWarnings(), loaded->warnings);
  // Selection and focus steps at the head of the script hold while the scene converges, as an
  // artist selects before editing: the indirection counters are gathered then.
  std::size_t firstStep = 0;
  for (; firstStep < scenario->steps.size(); ++firstStep) {
    const ScenarioStep& step = scenario->steps[firstStep];
    if (step.kind != ScenarioStep::Kind::Select && step.kind != ScenarioStep::Kind::Focus) break;
    auto e = stepEdits(step, 0, session.scene(), session.selection());
    if (!e) return std::fprintf(stderr, "error: %s: steps[%zu]: %s\n", o.script.c_str(), firstStep, e.error().c_str()), 1;
    if (e->select) session.select(*e->select);
    if (e->focus) session.setFocus(*e->focus);
  }
  auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  for (int f = 0; f < converge; ++f) {
    session.renderFrame(false);
    progressBar("converging", f + 1, converge, elapsed());
  }

  std::ofstream csv(outDir / "frames.csv");
  csv << "frame,step,method,mode,samples,tiles_served,queue_left,quality,ms,schedule_ms,trace_ms,rel_rmse,"
         "denoise_regions,denoise_width,denoise_height,psnr,ssim,psnr_hvs_m,rmse_affected,rmse_rest,psnr_affected,"
         "psnr_rest,reused_tiles,rejected_tiles\n";
  const int total = scenario->totalFrames();
  int frame = 0, lastEditFrame = 0, settledFrame = -1;
  double sumScheduleMs = 0;
  bool exact = true;
  // Frames are pipelined: frame n+1 is submitted (its edits applied first) before frame n is
  // read back and written, so the device traces while this thread writes.
  struct Submitted {
    std::size_t step;
    bool edited;
  };
  std::deque<Submitted> submitted;
  auto finishOne = [&]() -> bool {
    FrameRecord rec = session.finishFrame();
    Submitted sub = submitted.front();
    submitted.pop_front();
    ++frame;
    if (sub.edited) {
      lastEditFrame = frame;
      settledFrame = -1;
    }
    exact = exact && rec.samples == static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
    // The error of what the method shows (denoised, when it denoises).
    double err = !ref.empty() && rec.image ? relativeRmse(rec.image->shown(), ref, w, h, block) : NAN;
    if (!ref.empty() && frame > lastEditFrame && settledFrame < 0 && err < threshold) settledFrame = frame;
    if (!ref.empty() && err >= threshold) settledFrame = -1;  // settled means: stays under
    sumScheduleMs += rec.scheduleMs;
    char line[768];
    const RegionRect outer = rec.denoised.empty() ? RegionRect{} : rec.denoised.back().rect;
    std::string scores = ",,,,,,";
    if (!refDisplay.empty() && rec.image) {
      const std::vector<float> shown = displayed(rec.image->shown());
      const MetricImage a{shown.data(), w, h}, r{refDisplay.data(), w, h};
      char q[192];
      if (affectedCount > 0)
        std::snprintf(q, sizeof q, "%.3f,%.5f,%.3f,%.5f,%.5f,%.3f,%.3f", psnr(a, r), ssim(a, r), psnrHvsM(a, r),
                      rootMeanSquaredError(a, r, affected.data()), rootMeanSquaredError(a, r, rest.data()), psnr(a, r, affected.data()),
                      psnr(a, r, rest.data()));
      else  // nothing changed: no affected scores, the rest is the whole image
        std::snprintf(q, sizeof q, "%.3f,%.5f,%.3f,,%.5f,,%.3f", psnr(a, r), ssim(a, r), psnrHvsM(a, r), rootMeanSquaredError(a, r),
                      psnr(a, r));
      scores = q;
    }
    std::snprintf(line, sizeof line, "%d,%zu,%s,%s,%llu,%zu,%zu,%d,%.3f,%.4f,%.3f,%s,%zu,%d,%d,%s,%d,%d\n", frame, sub.step,
                  rec.method.c_str(), rec.mode.c_str(), static_cast<unsigned long long>(rec.samples), rec.servedTiles.size(),
                  rec.queueLength - rec.queueServed, rec.quality, rec.frameMs, rec.scheduleMs, rec.traceMs,
                  std::isnan(err) ? "" : std::to_string(err).c_str(), rec.denoised.size(), outer.width, outer.height, scores.c_str(),
                  rec.reusedTiles, rec.rejectedTiles);
    csv << line;
    if (images && rec.image) {
      char name[64];
      std::snprintf(name, sizeof name, "frame_%05d.exr", frame);
      auto written = writeRenderImage(*rec.image, outDir / name);
      if (!written) {
        std::fprintf(stderr, "\nerror: %s\n", written.error().c_str());
        return false;
      }
    }
    progressBar(rec.method, frame, total, elapsed());
    return true;
  };
  t0 = std::chrono::steady_clock::now();
  for (std::size_t si = firstStep; si < scenario->steps.size(); ++si) {
    const ScenarioStep& step = scenario->steps[si];
    bool instant = step.kind == ScenarioStep::Kind::Select || step.kind == ScenarioStep::Kind::Focus;
    for (int f = 0; f < (instant ? 1 : step.frames); ++f) {
      auto e = stepEdits(step, f, session.scene(), session.selection());
      if (!e) return std::fprintf(stderr, "\nerror: %s: steps[%zu]: %s\n", o.script.c_str(), si, e.error().c_str()), 1;
      if (e->select) session.select(*e->select);
      if (e->focus) session.setFocus(*e->focus);
      for (const Edit& edit : e->edits) {
        auto r = session.applyEdit(edit);
        if (!r) return std::fprintf(stderr, "\nerror: steps[%zu]: %s\n", si, r.error().c_str()), 1;
      }
      if (instant) break;
      session.submitFrame(images || !ref.empty());
      submitted.push_back({si, !e->edits.empty()});
      if (session.framesInFlight() > 1 && !finishOne()) return 1;
    }
  }
  while (session.framesInFlight() > 0)
    if (!finishOne()) return 1;
  const double wallMs = elapsed() * 1e3;
  csv.close();
  std::printf("method         %s, T=%d, Q=%s\n", methodLabel(method).c_str(), method.tileSize,
              method.quality ? std::to_string(method.quality).c_str() : "auto");
  std::printf("frames         %d after %d converging; every frame traced %s %dx%d samples\n", frame, converge, exact ? "exactly" : "NOT", w,
              h);
  std::printf("frame rate     %.1f frames/s (%.1f ms a frame, wall clock, frames pipelined)\n", wallMs > 0 ? frame * 1e3 / wallMs : 0.0,
              frame ? wallMs / frame : 0.0);
  std::printf("scheduling     %.2f %% of frame time (%.3f ms a frame)\n", wallMs > 0 ? 100.0 * sumScheduleMs / wallMs : 0.0,
              frame ? sumScheduleMs / frame : 0.0);
  if (!ref.empty()) {
    if (settledFrame > 0)
      std::printf("settled        %d frames after the last edit (relative RMSE of %dx%d blocks below %.3g from then on)\n",
                  settledFrame - lastEditFrame, block, block, threshold);
    else std::printf("settled        not within the script (relative RMSE of %dx%d blocks stayed above %.3g)\n", block, block, threshold);
  }
  std::printf("wrote          %s\n", (outDir / "frames.csv").string().c_str());
  return exact ? 0 : 1;
}

}  // namespace

void addEdit(CLI::App& app, int* status) {
  CLI::App* cmd = app.add_subcommand(
      "edit", "Converge a scene, play a script of timed edits under one method, and write every frame (EXR) and frames.csv");
  auto o = std::make_shared<EditOptions>();
  std::string methods;
  for (const auto& n : methodNames()) methods += (methods.empty() ? "" : ", ") + n;
  addScene(*cmd, &o->scene);
  cmd->add_option("--script", o->script, "the edits, a scenario script (resources/scripts/*.json)")->required()->type_name("EDITS.json");
  cmd->add_option("--method", o->methodName, "the re-rendering method: " + methods)
      ->required()
      ->type_name("NAME")
      ->check(oneOf("method", methodNames()));
  cmd->add_option("--out-dir", o->outDir, "where frames.csv and the frames go (made if missing)")->required()->type_name("DIR");
  addSize(*cmd, &o->size, "image size", "the scene's");
  addInt(*cmd, "--tile", &o->method.tileSize, 8, 32, "tile side T: 8, 16 or 32 pixels")->type_name("T");
  const int quality = o->method.quality;
  auto readQuality = [](const std::string& text) -> Result<int> {
    if (text == "auto") return 0;
    auto q = readInt(text, 1, 4096);
    return q ? q : Result<int>::failure(q.error() + " nor 'auto'");
  };
  cmd->add_option_function<std::string>(
         "--quality", [o, readQuality](const std::string& text) { o->method.quality = readQuality(text).value(); },
         cat("samples per pixel of a served tile, or 'auto', the indirection methods' choice (1..4096; default: ", quality, ")"))
      ->type_name("Q|auto")
      ->check(CLI::Validator(
          [readQuality](std::string& text) {
            auto q = readQuality(text);
            return q ? std::string() : q.error();
          },
          ""));
  cmd->add_flag("--smooth", o->method.smooth, "smooth transition: tiles not yet served keep capped stale samples");
  addInt(*cmd, "--stale-cap", &o->method.staleCap, 1, 1 << 20, "with --smooth: stale samples kept per pixel");
  addInt(*cmd, "--converge", &o->converge, 0, 1 << 20, "samples per pixel before the first edit", "the script's")->type_name("SPP");
  addInt(*cmd, "--max-bounces", &o->maxBounces, 0, 1024, "longest path", "the scene's");
  addInt(*cmd, "--reference", &o->reference, 1, 1 << 20,
         "render the final state fresh at SPP (reference.exr) and score every frame against it", "none")
      ->type_name("SPP");
  addInt(*cmd, "--block", &o->block, 1, 64, "with --reference: side of the blocks the relative RMSE averages");
  addNumber(*cmd, "--threshold", &o->threshold, 0, 1e30, "with --reference: relative RMSE below which a frame counts as settled")
      ->type_name("REL");
  CLI::Option* denoise = cmd->add_flag("--denoise", o->method.denoise, "denoise what the method shows");
  addNumber(*cmd, "--denoise-threshold", &o->method.denoiseThreshold, 0, 1,
            "share of the image's width (height) a pass's region grows by before it is denoised again at its new size")
      ->type_name("SHARE")
      ->needs(denoise);
  cmd->add_flag("--no-soft-borders", o->noSoftBorders, "no blending at seams between tiles showing different things")->needs(denoise);
  CLI::Option* reuse = cmd->add_flag("--reuse", o->method.reuse, "verified reuse: restarted tiles keep samples a test finds in agreement");
  addNumber(*cmd, "--reuse-rate", &o->method.reuseFalseReject, 1e-12, 0.49, "chance that one test of an unchanged tile drops its history")
      ->type_name("A")
      ->needs(reuse);
  cmd->add_flag("--no-images", o->noImages, "write frames.csv only, no EXR per frame");
  cmd->callback([o, status] { *status = runEdit(*o); });
}

}  // namespace retile::cli
