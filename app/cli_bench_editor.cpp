// The editor's benchmarks: its frames/s at rest and during a drag, and how soon a material edit
// can be judged at rest. Both drive an Engine as the editor does (render thread, mailbox, the
// editor's method and previews), without a window. They print figures and never pass or fail.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <thread>

#include "cli.h"
#include "cli11.h"
#include "core/numbers.h"
#include "retile/engine.h"
#include "retile/image.h"

namespace retile::cli {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The editor's settings, so that the figures are the editor's: its method (denoised) and its
// previews while edits come (ui::EditorOptions).
struct EditorLike {
  std::string method = methodName(MethodSettings{}.kind);
  bool denoise = true;
  int preview = 2;

  void add(CLI::App& cmd) {
    std::string methods;
    for (const auto& n : methodNames()) methods += (methods.empty() ? "" : ", ") + n;
    cmd.add_option("--method", method, "the re-rendering method: " + methods + " (default: " + method + ")")
        ->type_name("NAME")
        ->check(oneOf("method", methodNames()));
    cmd.add_flag_function(
        "--no-denoise", [this](std::int64_t) { denoise = false; }, "without the editor's denoiser");
    addInt(cmd, "--preview", &preview, 1, 16, "while edits come, a sample per N x N pixels (the editor's; 1: none)");
  }
  MethodSettings settings() const {
    MethodSettings m;
    methodFromName(method, &m.kind);  // checked by the option
    m.denoise = denoise;
    return m;
  }
  EngineOptions engine() const {
    EngineOptions o;
    o.maxSamplesPerPixel = 0;  // refine for ever: frames must keep coming
    o.previewBlock = preview;
    return o;
  }
};

struct FramesOptions {
  std::string scene;
  ImageSize size{240, 135};
  int seconds = 5;
  EditorLike editor;
  bool drag = false;
  std::optional<std::string> object;
};

// The scene at the size the benchmark renders; nullopt (said on stderr) when it cannot be read.
std::optional<Scene> sceneAt(const std::string& file, ImageSize size) {
  auto loaded = loadScene(file);
  if (!loaded) {
    std::fprintf(stderr, "error: %s\n", loaded.error().c_str());
    return std::nullopt;
  }
  Scene scene = std::move(loaded->scene);
  scene.settings.width = size.width;
  scene.settings.height = size.height;
  return scene;
}

int benchFrames(const FramesOptions& opt) {
  std::optional<Scene> read = sceneAt(opt.scene, opt.size);
  if (!read) return 1;
  const Scene& scene = *read;
  NodeId dragged = kNoNode;
  for (const Object& o : scene.objects)
    if (dragged == kNoNode && (!opt.object || o.name == *opt.object)) dragged = o.id;
  if (opt.drag && dragged == kNoNode) return std::fprintf(stderr, "error: no object to drag\n"), 1;
  Object moving = dragged != kNoNode ? *scene.object(dragged) : Object{};

  Engine engine(scene, opt.editor.settings(), opt.editor.engine());
  engine.start();
  std::uint64_t seen = 0, version = 0, previews = 0;
  auto pump = [&](Clock::time_point until) {
    while (Clock::now() < until) {
      auto f = engine.latestFrame();
      if (f && f->frame != seen) {
        seen = f->frame;
        previews += f->block > 1;
        if (opt.drag) {
          moving.transform = Mat4::translate({0.002f, 0, 0}) * moving.transform;
          engine.submit(SetObject{moving}, ++version);
        }
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  };
  pump(Clock::now() + std::chrono::seconds(1));
  const std::uint64_t first = engine.framesRendered();
  previews = 0;
  auto start = Clock::now();
  pump(start + std::chrono::seconds(opt.seconds));
  const double s = secondsSince(start);
  const std::uint64_t frames = engine.framesRendered() - first;
  engine.stop();
  for (const auto& e : engine.takeErrors())
    if (e.rfind("warning: ", 0) != 0) return std::fprintf(stderr, "error: %s\n", e.c_str()), 1;
  std::printf("scene          %s at %dx%d, %s%s\n", opt.scene.c_str(), scene.settings.width, scene.settings.height,
              methodLabel(opt.editor.settings()).c_str(), opt.drag ? ", dragging an object every frame" : ", at rest");
  std::printf("frames/s       %.2f (%llu frames in %.1f s; %llu of those shown were previews at 1/%d)\n", static_cast<double>(frames) / s,
              static_cast<unsigned long long>(frames), s, static_cast<unsigned long long>(previews), opt.editor.preview);
  return 0;
}

struct RestOptions {
  std::string scene;
  ImageSize size{260, 146};  // the editor's image at its default window (1280 x 800), at rest
  EditorLike editor;
  std::string material;
  std::vector<double> roughness{0.05, 0.2};
  int converge = 20, seconds = 10;
  std::string outDir = "retile-rest";
};

// The scene converges; then, for each roughness, the material takes it and the picture rests for
// `seconds`: how soon the pass at full resolution is done, how many samples the material's pixels
// then hold, and the picture as the editor shows it (PNG) to judge.
int benchRest(const RestOptions& opt) {
  std::optional<Scene> read = sceneAt(opt.scene, opt.size);
  if (!read) return 1;
  const Scene& scene = *read;
  const Material* found = nullptr;
  for (const Material& m : scene.materials)
    if (m.name == opt.material) found = &m;
  if (!found) return std::fprintf(stderr, "error: %s has no material '%s'\n", opt.scene.c_str(), opt.material.c_str()), 1;
  Material material = *found;
  std::filesystem::create_directories(opt.outDir);

  Engine engine(scene, opt.editor.settings(), opt.editor.engine());
  engine.start();
  std::this_thread::sleep_for(std::chrono::seconds(opt.converge));
  std::printf("scene          %s at %dx%d, %s, preview 1/%d; converged for %d s\n", opt.scene.c_str(), opt.size.width, opt.size.height,
              methodLabel(opt.editor.settings()).c_str(), opt.editor.preview, opt.converge);
  std::uint64_t version = 1;
  for (double r : opt.roughness) {
    material.roughness = static_cast<float>(r);
    engine.submit(SetMaterial{material}, ++version);
    const auto start = Clock::now();
    std::optional<double> passDone;
    std::shared_ptr<const FrameRecord> last;
    std::uint64_t frames = 0, seen = 0;
    while (secondsSince(start) < opt.seconds) {
      auto f = engine.latestFrame();
      if (f && f->frame != seen && f->documentVersion == version) {
        seen = f->frame;
        ++frames;
        last = f;
        if (!passDone && f->block == 1 && f->mode == "refinement") passDone = secondsSince(start);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    if (!last || !last->image) return std::fprintf(stderr, "error: no frame after the edit\n"), 1;
    // Samples per pixel where the material is seen.
    double spp = 0;
    std::size_t pixels = 0;
    const auto& ids = last->image->objectId;
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const Object* o = scene.object(static_cast<NodeId>(ids[i]));
      if (!o || o->material != material.id) continue;
      spp += last->image->sampleCount[i];
      ++pixels;
    }
    const auto file = std::filesystem::path(opt.outDir) / ("roughness-" + std::to_string(r).substr(0, 4) + ".png");
    if (auto w = writeRenderImage(*last->image, file); !w) return std::fprintf(stderr, "error: %s\n", w.error().c_str()), 1;
    std::printf("roughness %.3f  %llu frames in %d s; the pass at full resolution done after %s; %.0f spp on its %zu pixels; %s\n", r,
                static_cast<unsigned long long>(frames), opt.seconds,
                passDone ? (std::to_string(*passDone).substr(0, 4) + " s").c_str() : "more than that",
                pixels ? spp / static_cast<double>(pixels) : 0.0, pixels, file.string().c_str());
  }
  engine.stop();
  for (const auto& e : engine.takeErrors())
    if (e.rfind("warning: ", 0) != 0) return std::fprintf(stderr, "error: %s\n", e.c_str()), 1;
  return 0;
}

}  // namespace

void addEditorBenches(CLI::App& bench, int* status) {
  CLI::App* cmd =
      bench.add_subcommand("frames", "The editor's frames/s (render thread and mailbox), at rest or while an object is dragged");
  auto frames = std::make_shared<FramesOptions>();
  addScene(*cmd, &frames->scene);
  addSize(*cmd, &frames->size, "image size");
  addInt(*cmd, "--seconds", &frames->seconds, 1, 3600, "time measured, after one second of warm-up");
  frames->editor.add(*cmd);
  cmd->add_flag("--drag", frames->drag, "move an object a little on every frame shown");
  cmd->add_option("--object", frames->object, "with --drag: the object moved (default: the first)")->type_name("NAME");
  cmd->callback([frames, status] { *status = benchFrames(*frames); });

  cmd = bench.add_subcommand("rest", "How soon a material edit can be judged at rest: the pass's time, samples, pictures");
  auto rest = std::make_shared<RestOptions>();
  addScene(*cmd, &rest->scene);
  addSize(*cmd, &rest->size, "image size (the editor's at its default window)");
  rest->editor.add(*cmd);
  cmd->add_option("--material", rest->material, "the material edited")->required()->type_name("NAME");
  cmd->add_option_function<std::string>(
         "--roughness",
         [rest](const std::string& list) {
           rest->roughness.clear();
           for (std::size_t at = 0; at <= list.size();) {
             const std::size_t end = std::min(list.find(',', at), list.size());
             const auto v = numbers::toDouble(std::string_view(list).substr(at, end - at));
             if (!v || *v < 0 || *v > 1) throw CLI::ValidationError("--roughness", "'" + list + "' is not a list of numbers in 0..1");
             rest->roughness.push_back(*v);
             at = end + 1;
           }
         },
         "the roughness values it takes, one after another (default: 0.05,0.2)")
      ->type_name("R,R");
  addInt(*cmd, "--converge", &rest->converge, 0, 3600, "seconds the scene converges first");
  addInt(*cmd, "--seconds", &rest->seconds, 1, 3600, "seconds at rest after each edit");
  cmd->add_option("--out-dir", rest->outDir, "where the pictures go (default: " + rest->outDir + ")")->type_name("DIR");
  cmd->callback([rest, status] { *status = benchRest(*rest); });
}

}  // namespace retile::cli
