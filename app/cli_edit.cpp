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

using SteadyClock = std::chrono::steady_clock;

double elapsedSince(SteadyClock::time_point t0) { return std::chrono::duration<double>(SteadyClock::now() - t0).count(); }

// The display-referred copy of a linear image, what PSNR, SSIM and PSNR-HVS-M compare: the image
// as a viewer sees it.
std::vector<float> displayReferred(const ColorConfig& colors, const std::vector<float>& linear) {
  std::vector<float> out(linear.size());
  colors.toDisplayFloat(linear.data(), linear.size() / 3, DisplaySettings{}, out.data());
  for (float& v : out) v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
  return out;
}

// What --reference scores the frames against: the fresh render of the final state, and the
// pixels the script changed (and the others). Empty without --reference.
struct Reference {
  std::shared_ptr<const ColorConfig> colors;
  std::vector<float> linear, display;
  std::vector<std::uint8_t> affected, rest;
  std::size_t affectedCount = 0;
};

// Each state from its own renderer and seed, at `spp`; reference.exr is the final state's.
Reference renderReferences(const Scene& start, const Scene& finalScene, int spp, const std::filesystem::path& outDir) {
  Reference out;
  out.colors = ColorConfig::get();
  Renderer r;
  auto render = [&](const Scene& state, const char* what) {
    r.setScene(state);
    RenderRequest req;
    req.width = start.settings.width;
    req.height = start.settings.height;
    req.samplesPerPixel = spp;
    req.seed = 0x5eed;
    auto t0 = SteadyClock::now();
    return r.render(req, [&](int done, int total) {
      progressBar(what, done, total, elapsedSince(t0));
      return true;
    });
  };
  RenderImage img = render(finalScene, "reference");
  out.linear = img.color;
  out.display = displayReferred(*out.colors, out.linear);
  writeRenderImage(img, outDir / "reference.exr");
  // The starting state's reference too: where the two differ beyond their noise is the region
  // the edits affected, scored apart from the rest.
  RenderImage before = render(start, "reference before");
  out.affected = affectedPixels(before, img);
  out.rest.resize(out.affected.size());
  for (std::size_t i = 0; i < out.affected.size(); ++i) out.affectedCount += out.affected[i], out.rest[i] = !out.affected[i];
  std::fprintf(stderr, "affected region: %zu of %zu pixels\n", out.affectedCount, out.affected.size());
  return out;
}

// frames.csv's scores of what a frame shows against the reference: PSNR, SSIM, PSNR-HVS-M, and
// RMSE and PSNR of the affected region and of the rest; empty fields without a reference.
std::string frameScores(const Reference& ref, const FrameRecord& rec, int w, int h) {
  if (ref.display.empty() || !rec.image) return ",,,,,,";
  const std::vector<float> shown = displayReferred(*ref.colors, rec.image->shown());
  const MetricImage a{shown.data(), w, h}, r{ref.display.data(), w, h};
  char q[192];
  if (ref.affectedCount > 0)
    std::snprintf(q, sizeof q, "%.3f,%.5f,%.3f,%.5f,%.5f,%.3f,%.3f", psnr(a, r), ssim(a, r), psnrHvsM(a, r),
                  rootMeanSquaredError(a, r, ref.affected.data()), rootMeanSquaredError(a, r, ref.rest.data()),
                  psnr(a, r, ref.affected.data()), psnr(a, r, ref.rest.data()));
  else  // nothing changed: no affected scores, the rest is the whole image
    std::snprintf(q, sizeof q, "%.3f,%.5f,%.3f,,%.5f,,%.3f", psnr(a, r), ssim(a, r), psnrHvsM(a, r), rootMeanSquaredError(a, r),
                  psnr(a, r));
  return q;
}

// Applies the selection and focus steps at the head of the script, which hold while the scene
// converges, as an artist selects before editing: the indirection counters are gathered then.
// Returns the first step after them.
Result<std::size_t> applyLeadingSteps(RenderSession& session, const Scenario& scenario, const std::string& scriptFile) {
  std::size_t firstStep = 0;
  for (; firstStep < scenario.steps.size(); ++firstStep) {
    const ScenarioStep& step = scenario.steps[firstStep];
    if (step.kind != ScenarioStep::Kind::Select && step.kind != ScenarioStep::Kind::Focus) break;
    auto e = stepEdits(step, 0, session.scene(), session.selection());
    if (!e) return Result<std::size_t>::failure(cat(scriptFile, ": steps[", firstStep, "]: ", e.error()));
    if (e->select) session.select(*e->select);
    if (e->focus) session.setFocus(*e->focus);
  }
  return firstStep;
}

// Plays the script's steps after the leading ones and writes frames.csv and the frames. Frames
// are pipelined: frame n+1 is submitted (its edits applied first) before frame n is read back
// and written, so the device traces while this thread writes.
class EditPlayer {
 public:
  // The frames are width x height; `total` of them.
  EditPlayer(RenderSession& session, const EditOptions& o, const Reference& ref, const std::filesystem::path& outDir, int width, int height,
             int total)
      : session_(session), o_(o), ref_(ref), outDir_(outDir), w_(width), h_(height), total_(total), csv_(outDir / "frames.csv") {
    csv_ << "frame,step,method,mode,samples,tiles_served,queue_left,quality,ms,schedule_ms,trace_ms,rel_rmse,"
            "denoise_regions,denoise_width,denoise_height,psnr,ssim,psnr_hvs_m,rmse_affected,rmse_rest,psnr_affected,"
            "psnr_rest,reused_tiles,rejected_tiles\n";
  }

  // Returns false on an error, said on stderr.
  bool play(const Scenario& scenario, std::size_t firstStep) {
    t0_ = SteadyClock::now();
    const bool images = !o_.noImages;
    for (std::size_t si = firstStep; si < scenario.steps.size(); ++si) {
      const ScenarioStep& step = scenario.steps[si];
      bool instant = step.kind == ScenarioStep::Kind::Select || step.kind == ScenarioStep::Kind::Focus;
      for (int f = 0; f < (instant ? 1 : step.frames); ++f) {
        auto e = stepEdits(step, f, session_.scene(), session_.selection());
        if (!e) return std::fprintf(stderr, "\nerror: %s: steps[%zu]: %s\n", o_.script.c_str(), si, e.error().c_str()), false;
        if (e->select) session_.select(*e->select);
        if (e->focus) session_.setFocus(*e->focus);
        for (const Edit& edit : e->edits) {
          auto r = session_.applyEdit(edit);
          if (!r) return std::fprintf(stderr, "\nerror: steps[%zu]: %s\n", si, r.error().c_str()), false;
        }
        if (instant) break;
        session_.submitFrame(images || !ref_.linear.empty());
        submitted_.push_back({si, !e->edits.empty()});
        if (session_.framesInFlight() > 1 && !finishOne()) return false;
      }
    }
    while (session_.framesInFlight() > 0)
      if (!finishOne()) return false;
    wallMs_ = elapsedSince(t0_) * 1e3;
    csv_.close();
    return true;
  }

  // The summary on stdout, after play; the exit status: 1 when a frame missed the budget.
  int report(const MethodSettings& method, int converge) const {
    const int frame = frame_;
    std::printf("method         %s, T=%d, Q=%s\n", methodLabel(method).c_str(), method.tileSize,
                method.quality ? std::to_string(method.quality).c_str() : "auto");
    std::printf("frames         %d after %d converging; every frame traced %s %dx%d samples\n", frame, converge, exact_ ? "exactly" : "NOT",
                w_, h_);
    std::printf("frame rate     %.1f frames/s (%.1f ms a frame, wall clock, frames pipelined)\n", wallMs_ > 0 ? frame * 1e3 / wallMs_ : 0.0,
                frame ? wallMs_ / frame : 0.0);
    std::printf("scheduling     %.2f %% of frame time (%.3f ms a frame)\n", wallMs_ > 0 ? 100.0 * sumScheduleMs_ / wallMs_ : 0.0,
                frame ? sumScheduleMs_ / frame : 0.0);
    if (!ref_.linear.empty()) {
      if (settledFrame_ > 0)
        std::printf("settled        %d frames after the last edit (relative RMSE of %dx%d blocks below %.3g from then on)\n",
                    settledFrame_ - lastEditFrame_, o_.block, o_.block, o_.threshold);
      else
        std::printf("settled        not within the script (relative RMSE of %dx%d blocks stayed above %.3g)\n", o_.block, o_.block,
                    o_.threshold);
    }
    std::printf("wrote          %s\n", (outDir_ / "frames.csv").string().c_str());
    return exact_ ? 0 : 1;
  }

 private:
  struct Submitted {
    std::size_t step;
    bool edited;
  };

  // Reads back the oldest frame in flight, scores it, and writes its line and image.
  bool finishOne() {
    FrameRecord rec = session_.finishFrame();
    Submitted sub = submitted_.front();
    submitted_.pop_front();
    ++frame_;
    if (sub.edited) {
      lastEditFrame_ = frame_;
      settledFrame_ = -1;
    }
    exact_ = exact_ && rec.samples == static_cast<std::uint64_t>(w_) * static_cast<std::uint64_t>(h_);
    // The error of what the method shows (denoised, when it denoises).
    const std::vector<float>& ref = ref_.linear;
    double err = !ref.empty() && rec.image ? relativeRmse(rec.image->shown(), ref, w_, h_, o_.block) : NAN;
    if (!ref.empty() && frame_ > lastEditFrame_ && settledFrame_ < 0 && err < o_.threshold) settledFrame_ = frame_;
    if (!ref.empty() && err >= o_.threshold) settledFrame_ = -1;  // settled means: stays under
    sumScheduleMs_ += rec.scheduleMs;
    char line[768];
    const RegionRect outer = rec.denoised.empty() ? RegionRect{} : rec.denoised.back().rect;
    const std::string scores = frameScores(ref_, rec, w_, h_);
    std::snprintf(line, sizeof line, "%d,%zu,%s,%s,%llu,%zu,%zu,%d,%.3f,%.4f,%.3f,%s,%zu,%d,%d,%s,%d,%d\n", frame_, sub.step,
                  rec.method.c_str(), rec.mode.c_str(), static_cast<unsigned long long>(rec.samples), rec.servedTiles.size(),
                  rec.queueLength - rec.queueServed, rec.quality, rec.frameMs, rec.scheduleMs, rec.traceMs,
                  std::isnan(err) ? "" : std::to_string(err).c_str(), rec.denoised.size(), outer.width, outer.height, scores.c_str(),
                  rec.reusedTiles, rec.rejectedTiles);
    csv_ << line;
    if (!o_.noImages && rec.image) {
      char name[64];
      std::snprintf(name, sizeof name, "frame_%05d.exr", frame_);
      auto written = writeRenderImage(*rec.image, outDir_ / name);
      if (!written) {
        std::fprintf(stderr, "\nerror: %s\n", written.error().c_str());
        return false;
      }
    }
    progressBar(rec.method, frame_, total_, elapsedSince(t0_));
    return true;
  }

  RenderSession& session_;
  const EditOptions& o_;
  const Reference& ref_;
  const std::filesystem::path outDir_;
  const int w_, h_, total_;
  std::ofstream csv_;
  std::deque<Submitted> submitted_;
  SteadyClock::time_point t0_;
  int frame_ = 0, lastEditFrame_ = 0, settledFrame_ = -1;
  double sumScheduleMs_ = 0, wallMs_ = 0;
  bool exact_ = true;
};

int runEdit(EditOptions o) {
  MethodSettings& method = o.method;
  methodFromName(o.methodName, &method.kind);  // checked by the option
  method.softBorders = !o.noSoftBorders;
  if (std::string bad = validateMethodSettings(method); !bad.empty()) throw CLI::ValidationError(bad);

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
  const int reference = o.reference.value_or(0);
  const Reference ref = reference > 0 ? renderReferences(scene, finalScene, reference, outDir) : Reference{};

  RenderSession session(scene, method);
  std::fprintf(stderr, "device: %s\n", session.deviceName().c_str());
  printRenderWarnings(session.sceneWarnings(), loaded->warnings);
  auto firstStep = applyLeadingSteps(session, scenario.value(), o.script);
  if (!firstStep) return std::fprintf(stderr, "error: %s\n", firstStep.error().c_str()), 1;
  const auto t0 = SteadyClock::now();
  for (int f = 0; f < converge; ++f) {
    session.renderFrame(false);
    progressBar("converging", f + 1, converge, elapsedSince(t0));
  }

  EditPlayer player(session, o, ref, outDir, scene.settings.width, scene.settings.height, scenario->totalFrames());
  if (!player.play(scenario.value(), firstStep.value())) return 1;
  return player.report(method, converge);
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
