// `retile eval`: every method through the same scenarios on the same per-frame budget, scored
// frame by frame against converged references (retile/metrics.h), summarised per method.
//
// The pieces: built-in scenarios that fit any scene (the paper's Fig. 6 move, a material, a light
// and a camera edit, a continuous drag); a plan that plays a scenario on a copy of the scene and
// says which frames are scored and against which state; references of those states cached on disk
// by content; one method's run; the summary; the report (CSV and HTML here, its charts and
// strips drawn with Qt by the program that runs it, through ReportHost). Planning and summaries
// are pure; References, runMethod and the reports use the GPU and block the calling thread. One
// thread at a time per object.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "retile/error.h"
#include "retile/image.h"
#include "retile/io.h"
#include "retile/method.h"
#include "retile/scenario.h"
#include "retile/scene.h"
#include "retile/session.h"

namespace retile::eval {

struct Options {
  int width = 320, height = 180;
  int referenceSpp = 1024;
  int every = 50;        // while edits arrive, frames 1, 10, k, 2k, ... are scored; at rest every frame
  int converge = 1024;   // spp before the first edit (the Fig. 6 protocol's; the others take a quarter)
  int moveFrames = 100;  // Fig. 6: +0.005 in y per frame for this many frames
  int restFrames = 100;  // then this many frames without an edit (every other scenario too)
  int dragFrames = 50;
  int cameraFrames = 20;
  double target = 0.02;  // relative RMSE of the affected region that counts as "reached"
  // 96x54, 64 spp to converge, 20 frames of move and 30 at rest, references of 512 spp, target 5 %.
  static Options quick();
};

struct Case {
  std::string name;         // "fig6", "material", ... or the script's file name
  std::string description;  // one sentence for the report
  Scenario script;
};

std::vector<std::string> builtInScenarioNames();  // fig6, material, light, camera, drag
// The built-in scenarios for `scene`, in that order, restricted to `names` (empty: all). The
// edited object is the one an artist would pick: the visible, non-emissive object nearest the
// image centre among those covering 0.2 % to 25 % of it (when none does, the smallest covering
// more: a scene of one object). A scenario the scene cannot play (no light, no object) is left
// out and `skipped` says why.
std::vector<Case> builtInScenarios(const Scene& scene, const Options& options, const std::vector<std::string>& names,
                                   std::vector<std::string>* skipped);
// The object builtInScenarios edits, or kNoNode.
NodeId pickSubject(const Scene& scene);

// "spiral", "global+denoise", "indirection+focus+smooth" (methodLabel's names) to settings:
// indirection methods take automatic Q, as the editor offers them.
Result<MethodSettings> parseMethodLabel(const std::string& label);
// global, spiral, focus, indirection, change, spiral+smooth, global+denoise, spiral+denoise, spiral+reuse.
std::vector<std::string> defaultMethods();

// A scenario played on a copy of the scene, frame by frame, without rendering.
struct Plan {
  Scene start;                 // the scene before the first frame
  NodeId selection = kNoNode;  // set up before converging (leading select steps)
  std::optional<std::vector<FocusPoint>> focus;
  int converge = 0;
  struct Frame {
    std::vector<Edit> edits;  // applied before the frame is traced
    std::optional<NodeId> select;
    std::optional<std::vector<FocusPoint>> focus;
    std::optional<std::pair<int, int>> resize;  // the viewport's new size (the stability suite)
    int state = -1;                             // index into states when the frame is scored, else -1
  };
  std::vector<Frame> frames;  // frame f (from 1) is frames[f - 1]
  std::vector<Scene> states;  // the scene as each scored frame shows it
  int lastEditFrame = 0;      // 0: the scenario edits nothing
};
// Scores frames 1 and 10 (the summary's), every `every`-th frame and every frame from the last
// edit on.
Result<Plan> planScenario(const Scenario& script, const Scene& scene, int every);

// Converged references on disk under `dir`, one per distinct scene state, keyed by the scene's
// content (geometry, materials, lights, camera, settings), the sample count and the renderer's
// shaders, so a second run renders none of them again.
class References {
 public:
  References(std::filesystem::path dir, int spp);
  // The reference of `state` (color, moment2 and sampleCount filled), from disk or rendered.
  Result<RenderImage> get(const Scene& state, const std::function<void(int done, int total)>& progress = {});
  static std::string key(const Scene& state, int spp);
  int rendered() const { return rendered_; }
  int reused() const { return reused_; }

 private:
  std::filesystem::path dir_;
  int spp_;
  int rendered_ = 0, reused_ = 0;
  struct Gpu;
  std::shared_ptr<Gpu> gpu_;  // made on the first render
};

// A scenario's references, ready to score against: per state the linear image and its display-
// referred copy, and the affected region (pixels whose reference changed beyond noise from the
// start in any scored state) with its complement.
struct Targets {
  int width = 0, height = 0;                        // of the start; the affected masks' size
  std::vector<std::vector<float>> linear, display;  // per plan state
  std::vector<std::pair<int, int>> sizes;           // per plan state (a resize changes it)
  std::vector<std::uint8_t> affected, rest;
  std::size_t affectedCount = 0;
};
Result<Targets> prepareTargets(const Plan& plan, References& refs, const std::function<void(int done, int total)>& progress = {});

// One frame's figures. Scores are NaN on frames that are not scored (and affected ones when the
// scenario changed no pixel).
struct FrameScore {
  int frame = 0;
  double frameMs = 0;         // this frame's wall clock: plan, trace, denoise, read-back
  double ms = 0;              // since frame 1 began, this frame included
  std::uint64_t samples = 0;  // traced since frame 1 began
  std::string mode;
  int quality = 0;
  std::size_t servedTiles = 0, denoiseRegions = 0;
  double rmse = NAN, psnr = NAN, ssim = NAN, psnrHvsM = NAN;
  double rmseAffected = NAN, rmseRest = NAN, psnrAffected = NAN, psnrRest = NAN;
  double relRmse = NAN, relRmseAffected = NAN;  // linear luminance, 4x4 blocks (relativeRmse)
  bool scored() const { return psnr == psnr; }
};

struct Run {
  std::string scene, scenario, method;
  std::vector<FrameScore> frames;
  int lastEditFrame = 0;
  bool exactBudget = true;  // every frame traced exactly width x height samples
  double convergeMs = 0;
};

// Scores an image (linear RGB, the size of the targets) against a plan state.
void scoreFrame(const Targets& targets, int state, const std::vector<float>& linear, FrameScore* score);

// Converges `plan.converge` frames, then plays the plan with `method`, scoring each frame.
// `onFrame` sees every played frame's record and score; returning false stops the run.
Result<Run> runMethod(const Plan& plan, const Targets& targets, const MethodSettings& method,
                      const std::function<bool(const FrameRecord&, const FrameScore&)>& onFrame = {});

// Per method and scenario: PSNR (whole image and affected region) and relative RMSE of the
// affected region at frames 1, 10, 100 and 200 (NaN where the run is shorter or the frame was not
// scored), and the time to the target: from frame 1 to the first scored frame from which the
// affected region's relative RMSE stays at or below it (the whole image's when nothing changed).
struct Summary {
  std::string scene, scenario, method;
  static constexpr int kAt[4] = {1, 10, 100, 200};
  double psnrAt[4] = {NAN, NAN, NAN, NAN};
  double psnrAffectedAt[4] = {NAN, NAN, NAN, NAN};
  double relAffectedAt[4] = {NAN, NAN, NAN, NAN};
  int framesToTarget = -1;  // -1: not reached within the run
  double msToTarget = NAN;
};
Summary summarize(const Run& run, double target);

// metrics.csv and summary.csv, header first.
std::string metricsCsvHeader();
std::string metricsCsvRow(const Run& run, const FrameScore& f);
std::string summaryCsvHeader();
std::string summaryCsvRow(const Summary& s);

// "Model no more than a scene needs": what the renderer holds and compiled for a scene.
struct SceneModel {
  std::uint64_t triangles = 0, deviceBytes = 0;  // device bytes of the scene's buffers, BVH included
  double bytesPerTriangle = 0;
  std::vector<std::string> kernelFeatures;
};
SceneModel modelOf(const Scene& scene);

// ---- The stability suite: where METHOD.md says the methods fail ----
//
// Each case plays a short edit on a scene (the given one, or the built-in scene with an object
// added where the case needs one) under every method, and measures one figure per method: the
// relative RMSE (linear luminance, 4x4 blocks; of the affected region when there is one) at a
// chosen frame against a converged reference of what that frame should show. A method passes
// when its figure is at most 1.5 times the global method's (a restart shows no stale content, so
// it is the yardstick), and no invariant broke: every frame traced exactly W x H samples, no
// pixel went NaN or infinite, nothing threw.
struct StabilityOptions {
  int width = 160, height = 90;
  int referenceSpp = 1024;
  bool small = false;  // the extreme case's large image at 320x180 instead of 3840x2160 (tests)
  std::vector<std::string> methods = defaultMethods();
};

struct StabilityFigure {
  std::string method;  // or the variant of the extreme case ("Q=1", "T=8 3840x2160", ...)
  double value = NAN;  // the case's figure
  double threshold = NAN;
  bool pass = false;
  std::string detail;  // what else was measured (tiles never served, ...)
  std::string broken;  // an invariant that broke; empty: none
};

struct StabilityResult {
  std::string name, description, figure;  // figure: what the value measures
  std::size_t affected = 0;               // pixels the case changes
  std::vector<StabilityFigure> figures;
};

// ghosting, burst, off-screen, behind-camera, fill-screen, camera-mid-pass, resize-mid-pass,
// light-global, mirror-only, offscreen-shadow, extreme.
std::vector<std::string> stabilityCaseNames();
Result<StabilityResult> runStabilityCase(const std::string& name, const Scene& scene, const StabilityOptions& options, References& refs,
                                         const std::function<void(const std::string& what)>& progress = {});

// ---- The reports: what `retile eval` writes in its output directory ----
//
// The engine neither reads scenes by the command line's names, nor owns the terminal, nor links
// Qt, which draws the charts and strips (ui/eval_report.h): the program that runs a report does
// those for it.
struct ReportLine {  // a method's PSNR against time
  std::string name;
  std::vector<std::pair<double, double>> points;
};
struct ReportPoint {  // a method's speed against accuracy
  std::string label;
  double x = 0, y = 0;
  // false: x is a bound (the run's length), not a time measured (ui::ChartPoint::reached).
  bool reached = true;
};

class ReportHost {
 public:
  virtual ~ReportHost() = default;
  // The scene `name` names on the command line ("default": the built-in one).
  virtual Result<ImportedScene> loadScene(const std::string& name) = 0;
  virtual void progress(const std::string& what, int done, int total, double seconds) = 0;
  // Text for the terminal: results on standard output, anything else on standard error.
  virtual void out(const std::string& text) = 0;
  virtual void err(const std::string& text) = 0;
  // The pictures. A strip's cells are drawn as its frames are played (a frame record does not
  // outlive its run): keepStripFrame adds one to row `row` of strip `strip`, which writeStrip
  // writes, its rows labelled `rows` and its columns captioned `captions`.
  virtual void keepStripFrame(std::size_t strip, std::size_t row, const FrameRecord& frame, int scale) = 0;
  virtual Result<bool> writeStrip(std::size_t strip, const std::filesystem::path& file, const std::vector<std::string>& captions,
                                  const std::vector<std::string>& rows) = 0;
  // `base`.png and `base`.svg.
  virtual Result<bool> writeLineChart(const std::filesystem::path& base, const std::string& title, const std::string& xTitle,
                                      const std::string& yTitle, const std::vector<ReportLine>& lines, bool logX) = 0;
  virtual Result<bool> writePointChart(const std::filesystem::path& base, const std::string& title, const std::string& xTitle,
                                       const std::string& yTitle, const std::vector<ReportPoint>& points) = 0;
};

struct ReportRequest {
  Options options;
  std::vector<std::string> scenes;     // as the command line names them
  std::vector<std::string> methods;    // labels (parseMethodLabel), already checked
  std::vector<std::string> scenarios;  // built-in ones; empty: all, or none when there are scripts
  std::vector<Scenario> scripts;
  std::filesystem::path out;
};

// Every method through every scenario of every scene: metrics.csv (written as runs end),
// summary.csv, three charts and a strip of frames per scenario, and index.html tying them
// together, readable offline; the summary table on host.out. Returns the command's exit status:
// 0, or 1 when the report could not be made (said on host.err).
int runReport(const ReportRequest& request, ReportHost& host);
// The stability suite's cases on each scene: stability.csv and stability.html, the figures on
// host.out. Returns 1 when an invariant broke or a case could not run (a method failing a case
// is a finding, not a defect), else 0.
int runStabilityReport(const std::vector<std::string>& scenes, const std::vector<std::string>& cases, const StabilityOptions& options,
                       const std::filesystem::path& out, ReportHost& host);

}  // namespace retile::eval
