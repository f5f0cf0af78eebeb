// Benchmarks print figures; they never pass or fail (speed goals are not tests).
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>
#include <random>
#include <thread>

#include "cli.h"
#include "cli11.h"
#include "render/bvh.h"
#include "retile/engine.h"
#include "retile/log.h"
#include "retile/render.h"
#include "retile/session.h"
#include "scene/primitives.h"
#include "scene/synthetic.h"

namespace retile::cli {
namespace {

using Clock = std::chrono::steady_clock;

// One warm-up frame (pipeline creation, first touch of buffers), then `frames` frames of `spp`
// samples per pixel over the whole image; their statistics summed, and their wall clock (warm-up
// excluded).
FrameStats traceFrames(Renderer& renderer, int w, int h, int frames, int spp, const FrameOptions& options, double* wallSeconds = nullptr) {
  TileWork all{0, 0, w, h, spp, 0, true};
  renderer.renderFrame({all}, options);
  const auto start = Clock::now();
  FrameStats sum;
  for (int f = 0; f < frames; ++f) {
    all.sampleBase = static_cast<std::uint32_t>((f + 1) * spp);
    all.restart = false;
    sum.add(renderer.renderFrame({all}, options));
  }
  if (wallSeconds) *wallSeconds = std::chrono::duration<double>(Clock::now() - start).count();
  return sum;
}

// Throughput against triangle count: the built-in scene plus one sphere tessellated to N
// triangles filling a good part of the view, N from 16 k to 2 M. Samples/s should fall slowly
// (a BVH is logarithmic) and bytes per triangle stay flat.
struct ScaleOptions {
  ImageSize size{320, 180};
  int frames = 16;
  std::optional<int> sppPerFrame;  // empty: as retile render (frameSpp)
};

// --spp-per-frame against the image size: a frame's slots take 64 bytes each on the device (the
// sample and its auxiliary outputs); past 2^24 of them (1 GiB) the option is refused, a usage
// error (exit code 2, as for values out of range), rather than the device asked for gigabytes.
std::optional<std::string> frameTooLarge(ImageSize size, std::optional<int> sppPerFrame) {
  if (!sppPerFrame) return std::nullopt;
  const std::uint64_t slots = std::uint64_t(size.width) * std::uint64_t(size.height) * std::uint64_t(*sppPerFrame);
  if (slots <= (1u << 24)) return std::nullopt;
  return cat("--spp-per-frame: ", *sppPerFrame, " samples per pixel at ", size.width, "x", size.height, " make ", slots,
             " samples a frame, more than 16777216");
}

// The samples per pixel of a benchmark's frames: --spp-per-frame, else as retile render traces.
int frameSpp(ImageSize size, std::optional<int> sppPerFrame) {
  return sppPerFrame.value_or(offlineSamplesPerFrame(size.width, size.height));
}

int benchScale(const ScaleOptions& o) {
  if (auto tooLarge = frameTooLarge(o.size, o.sppPerFrame)) return std::fprintf(stderr, "error: %s\n", tooLarge->c_str()), 2;
  const int w = o.size.width, h = o.size.height, frames = o.frames;
  std::printf("%10s %12s %10s %12s %14s %12s\n", "triangles", "samples/s", "vs first", "upload s", "device MiB", "bytes/tri");
  double first = 0;
  for (int rings : {64, 158, 354, 500, 708}) {  // 4 rings^2 triangles: ~16 k, 100 k, 500 k, 1 M, 2 M
    Scene scene = makeDefaultScene();
    Material mat;
    mat.type = MaterialType::RoughPlastic;
    addMeshObject(scene, "dense sphere", makeSphere(rings, 2 * rings), mat, Mat4::translate({0.2f, 0.6f, 0.6f}) * Mat4::scale(Vec3{0.6f}));
    Renderer renderer;
    auto t0 = Clock::now();
    renderer.setScene(scene);
    const double upload = std::chrono::duration<double>(Clock::now() - t0).count();
    renderer.setMaxBounces(scene.settings.maxBounces);
    renderer.resize(w, h);
    FrameStats sum = traceFrames(renderer, w, h, frames, frameSpp(o.size, o.sppPerFrame), FrameOptions{});
    const double rate = static_cast<double>(sum.samples) / sum.seconds;
    if (first == 0) first = rate;
    const auto tris = renderer.sceneTriangles();
    std::printf("%10llu %10.3f M %9.2fx %12.2f %14.1f %12.1f\n", static_cast<unsigned long long>(tris), rate * 1e-6, rate / first, upload,
                static_cast<double>(renderer.sceneDeviceBytes()) / (1 << 20),
                static_cast<double>(renderer.sceneDeviceBytes()) / static_cast<double>(tris));
    std::fflush(stdout);
  }
  return 0;
}

// Throughput and memory on a furnished room (scene/synthetic.h) of 100 k, 1 M and 4 M triangles
// by default: what a big interior costs, per triangle, with the device memory split by what it
// holds.
struct RoomOptions {
  std::string triangles = "100k,1M,4M";
  ImageSize size{320, 180};
  int frames = 8;
  int maxBounces = 16;
  std::optional<int> sppPerFrame;  // empty: as retile render (frameSpp)
  std::string writeScene;          // also save the first room as a native scene, to look at
  std::string roulette = "standard";
};

// --roulette: the rule by name (standard, low_throughput; tungsten, as Tungsten plays it, is the second).
Roulette rouletteNamed(const std::string& name) { return name == "standard" ? Roulette::Standard : Roulette::LowThroughput; }

// "100k,1M,4M" -> counts; k and M multiply by a thousand and a million.
std::vector<std::uint64_t> parseCounts(const std::string& text) {
  std::vector<std::uint64_t> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string item = text.substr(start, end - start);
    std::uint64_t scale = 1;
    if (!item.empty() && (item.back() == 'k' || item.back() == 'K')) scale = 1000, item.pop_back();
    else if (!item.empty() && (item.back() == 'M' || item.back() == 'm')) scale = 1000000, item.pop_back();
    std::uint64_t v = 0;
    auto r = std::from_chars(item.data(), item.data() + item.size(), v);
    if (r.ec != std::errc() || r.ptr != item.data() + item.size() || v == 0) return {};
    out.push_back(v * scale);
    start = end + 1;
  }
  return out;
}

// The process's peak resident memory so far in MB (VmHWM), 0 where /proc does not say.
double peakResidentMb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::strtod(line.c_str() + 6, nullptr) / 1024.0;
  return 0;
}

int benchRoom(const RoomOptions& o) {
  if (auto tooLarge = frameTooLarge(o.size, o.sppPerFrame)) return std::fprintf(stderr, "error: %s\n", tooLarge->c_str()), 2;
  const std::vector<std::uint64_t> counts = parseCounts(o.triangles);
  // Loop iterations per path do not drift with the machine's speed, as samples/s does.
  // The peak RSS is the process's so far, so with counts in growing order each row's is its own.
  std::printf("%10s %11s %9s %9s %9s %10s %9s | bytes per triangle: %6s %6s %6s %6s %6s\n", "triangles", "samples/s", "iter/path",
              "build s", "objects", "device MiB", "peak RSS", "total", "tris", "BVH", "shade", "other");
  for (std::uint64_t n : counts) {
    Scene scene = makeFurnishedRoom(n);
    scene.settings.roulette = rouletteNamed(o.roulette);
    if (!o.writeScene.empty() && n == counts.front()) {
      if (auto saved = saveNativeScene(scene, o.writeScene); !saved) return std::fprintf(stderr, "error: %s\n", saved.error().c_str()), 1;
    }
    Renderer renderer;
    auto t0 = Clock::now();
    renderer.setScene(scene);
    const double build = std::chrono::duration<double>(Clock::now() - t0).count();
    renderer.setMaxBounces(o.maxBounces);
    renderer.resize(o.size.width, o.size.height);
    FrameStats sum = traceFrames(renderer, o.size.width, o.size.height, o.frames, frameSpp(o.size, o.sppPerFrame), FrameOptions{});
    const double rate = static_cast<double>(sum.samples) / sum.seconds;
    const double tris = static_cast<double>(renderer.sceneTriangles());
    const Renderer::SceneMemory m = renderer.sceneMemory();
    const double total = static_cast<double>(renderer.sceneDeviceBytes());
    const double iterations = static_cast<double>(sum.loopIterations) / static_cast<double>(std::max<std::uint64_t>(sum.samples, 1));
    std::printf("%10.0f %9.3f M %9.1f %9.2f %9zu %10.1f %6.0f MB | %26.1f %6.1f %6.1f %6.1f %6.1f\n", tris, rate * 1e-6, iterations, build,
                scene.objects.size(), total / (1 << 20), peakResidentMb(), total / tris, static_cast<double>(m.triangles) / tris,
                static_cast<double>(m.bvh) / tris, static_cast<double>(m.shading) / tris, static_cast<double>(m.textures + m.other) / tris);
    std::fflush(stdout);
  }
  return 0;
}

struct ThroughputOptions {
  std::string scene;
  ImageSize size{256, 256};
  int frames = 16;
  std::optional<int> maxBounces, paths, sppPerFrame;
  std::string roulette;  // empty: the scene's
};

int benchThroughput(const ThroughputOptions& o) {
  if (auto tooLarge = frameTooLarge(o.size, o.sppPerFrame)) return std::fprintf(stderr, "error: %s\n", tooLarge->c_str()), 2;
  const int w = o.size.width, h = o.size.height, frames = o.frames, bounces = o.maxBounces.value_or(-1);
  FrameOptions options;
  if (o.paths) options.pathsPerInvocation = *o.paths;
  auto loaded = loadScene(o.scene);
  if (!loaded) return std::fprintf(stderr, "error: %s\n", loaded.error().c_str()), 1;
  if (!o.roulette.empty()) loaded->scene.settings.roulette = rouletteNamed(o.roulette);

  Renderer renderer;
  auto t0 = Clock::now();
  printRenderWarnings(renderer.setScene(loaded->scene), loaded->warnings);
  double setup = std::chrono::duration<double>(Clock::now() - t0).count();
  renderer.setMaxBounces(bounces >= 0 ? bounces : loaded->scene.settings.maxBounces);
  renderer.resize(w, h);
  double wall = 0;
  const int spp = frameSpp(o.size, o.sppPerFrame);
  FrameStats sum = traceFrames(renderer, w, h, frames, spp, options, &wall);
  double sec = sum.seconds;
  auto tris = renderer.sceneTriangles();
  std::printf("scene          %s (%llu triangles)\n", o.scene.c_str(), static_cast<unsigned long long>(tris));
  std::printf("device         %s\n", renderer.deviceName().c_str());
  std::printf("image          %dx%d, max bounces %d, %d frames of %d spp\n", w, h,
              bounces >= 0 ? bounces : loaded->scene.settings.maxBounces, frames, spp);
  std::printf("samples/s      %.3f M\n", static_cast<double>(sum.samples) / sec * 1e-6);
  std::printf("rays/s         %.3f M total: primary %.3f M, bounce %.3f M, shadow %.3f M\n",
              static_cast<double>(sum.primaryRays + sum.bounceRays + sum.shadowRays) / sec * 1e-6,
              static_cast<double>(sum.primaryRays) / sec * 1e-6, static_cast<double>(sum.bounceRays) / sec * 1e-6,
              static_cast<double>(sum.shadowRays) / sec * 1e-6);
  std::printf("rays/sample    %.2f\n",
              static_cast<double>(sum.primaryRays + sum.bounceRays + sum.shadowRays) / static_cast<double>(sum.samples));
  std::printf("frame time     %.1f ms (device), %.1f ms (wall)\n", sec / frames * 1e3, wall / frames * 1e3);
  std::printf("scene upload   %.3f s (BVH bottom level %.3f s, top level %.4f s)\n", setup, renderer.lastBlasSeconds(),
              renderer.lastTlasSeconds());
  std::string kernel;
  for (const std::string& f : renderer.kernelFeatures()) kernel += (kernel.empty() ? "" : ", ") + f;
  std::printf("kernel         %s\n", kernel.c_str());
  std::printf("top level      %llu references to %llu instances\n", static_cast<unsigned long long>(renderer.sceneInstanceReferences()),
              static_cast<unsigned long long>(renderer.sceneInstances()));
  std::printf(
      "loop iterations %u at most in one invocation (paths stop at %u; lavapipe's limit is near 32767); "
      "%llu paths cut short; %u at most in one path segment\n",
      sum.maxLoopIterations, kTraceLoopBudget, static_cast<unsigned long long>(sum.cutPaths), sum.maxSegmentIterations);
  // Per ray and per iteration, so that two scenes' costs split into how long their paths are, how
  // far their rays search, and what a step costs.
  const double rays = static_cast<double>(std::max<std::uint64_t>(sum.primaryRays + sum.bounceRays + sum.shadowRays, 1));
  const double iterations = static_cast<double>(std::max<std::uint64_t>(sum.loopIterations, 1));
  std::printf("paths          %.1f loop iterations each, %.0f per invocation (last frame); %.1f a ray, %.1f ns of device time each\n",
              static_cast<double>(sum.loopIterations) / static_cast<double>(std::max<std::uint64_t>(sum.samples, 1)),
              sum.pathsPerInvocation, static_cast<double>(sum.loopIterations) / rays, sec / iterations * 1e9);
  // Where the paths' time goes when they are long: how they end.
  const double samples = static_cast<double>(std::max<std::uint64_t>(sum.samples, 1));
  std::uint64_t ended = 0;
  for (std::uint64_t n : sum.pathEnds) ended += n;
  std::printf(
      "path ends      %.1f %% left the scene, %.1f %% met an emitter that does not reflect, %.1f %% at the bounce limit, "
      "%.1f %% by roulette, %.1f %% otherwise (absorbed, or cut short)\n",
      100.0 * static_cast<double>(sum.pathEnds[FrameStats::LeftTheScene]) / samples,
      100.0 * static_cast<double>(sum.pathEnds[FrameStats::AtEmitter]) / samples,
      100.0 * static_cast<double>(sum.pathEnds[FrameStats::AtBounceLimit]) / samples,
      100.0 * static_cast<double>(sum.pathEnds[FrameStats::ByRoulette]) / samples,
      100.0 * static_cast<double>(sum.samples - std::min(ended, sum.samples)) / samples);
  std::printf("device memory  %.3f MiB scene data, %.1f bytes per triangle\n", static_cast<double>(renderer.sceneDeviceBytes()) / (1 << 20),
              tris ? static_cast<double>(renderer.sceneDeviceBytes()) / static_cast<double>(tris) : 0.0);
  return 0;
}

int benchBvh(int n) {
  // A tessellated wavy surface: triangles of even size, like a scanned mesh.
  int side = static_cast<int>(std::sqrt(n / 2.0)) + 1;
  std::vector<Bounds3> boxes;
  boxes.reserve(static_cast<std::size_t>(side) * side * 2);
  auto height = [](float x, float z) { return 0.1f * std::sin(x * 20) * std::cos(z * 17); };
  for (int j = 0; j < side && static_cast<int>(boxes.size()) < n; ++j)
    for (int i = 0; i < side && static_cast<int>(boxes.size()) < n; ++i) {
      float x0 = static_cast<float>(i) / side, x1 = static_cast<float>(i + 1) / side;
      float z0 = static_cast<float>(j) / side, z1 = static_cast<float>(j + 1) / side;
      Vec3 a{x0, height(x0, z0), z0}, b{x1, height(x1, z0), z0}, c{x1, height(x1, z1), z1}, d{x0, height(x0, z1), z1};
      Bounds3 t1, t2;
      t1.grow(a);
      t1.grow(b);
      t1.grow(c);
      t2.grow(a);
      t2.grow(c);
      t2.grow(d);
      boxes.push_back(t1);
      if (static_cast<int>(boxes.size()) < n) boxes.push_back(t2);
    }
  auto start = Clock::now();
  Bvh bvh = buildBvh(boxes);
  double s = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("bvh build      %zu triangles in %.3f s (%.2f M triangles/s), %zu nodes, depth %d\n", boxes.size(), s,
              static_cast<double>(boxes.size()) / s * 1e-6, bvh.nodes.size(), bvh.depth);
  return 0;
}

// Edit cost against mesh size: the default scene plus one mesh of N triangles; times moving that
// object and changing its material through a RenderSession (what the render thread does between
// frames), N from 10 k to 1 M. Both must stay flat: neither touches mesh data.
int benchEdit(int edits) {
  std::printf("%10s %14s %14s %14s\n", "triangles", "upload s", "move ms/edit", "material ms/edit");
  for (int rings : {64, 224, 708}) {  // 2 * rings * 2 * rings triangles: ~16 k, ~200 k, ~2 M
    Scene scene = makeDefaultScene();
    scene.settings.width = 64;
    scene.settings.height = 36;
    const NodeId id = addMeshObject(scene, "dense sphere", makeSphere(rings, 2 * rings), Material{},
                                    Mat4::translate({0, 1, 0}) * Mat4::scale(Vec3{0.3f}));
    const Object* added = scene.object(id);
    const Material* addedMaterial = added ? scene.material(added->material) : nullptr;
    if (!addedMaterial) return 1;
    Object o = *added;
    Material mat = *addedMaterial;
    const std::size_t triangles = 4u * static_cast<std::size_t>(rings) * static_cast<std::size_t>(rings);
    auto t0 = Clock::now();
    RenderSession session(scene, MethodSettings{});
    double upload = std::chrono::duration<double>(Clock::now() - t0).count();
    session.renderFrame(false);
    double moveMs = 0, materialMs = 0;
    for (int i = 0; i < edits; ++i) {
      o.transform = Mat4::translate({0.001f, 0, 0}) * o.transform;
      auto a = Clock::now();
      session.applyEdit(SetObject{o});
      moveMs += std::chrono::duration<double, std::milli>(Clock::now() - a).count();
      mat.roughness = 0.1f + 0.01f * static_cast<float>(i);
      a = Clock::now();
      session.applyEdit(SetMaterial{mat});
      materialMs += std::chrono::duration<double, std::milli>(Clock::now() - a).count();
    }
    std::printf("%10zu %14.3f %14.3f %14.3f\n", triangles, upload, moveMs / edits, materialMs / edits);
  }
  return 0;
}

// Edit cost on a real scene: removing its first visible object and adding it back, the first
// move (which, in a scene packed without instance transforms, turns direct references off),
// further moves, showing or hiding it and changing its material, each through a RenderSession
// as the render thread applies them. The visible objects never differ from the loaded scene's by
// more than the one, so none of these edits traces sample rays to choose the braid factor again
// (render_scene.cpp packInstances).
int benchEditScene(const std::string& path, int edits) {
  auto loaded = loadScene(path);
  if (!loaded) return std::fprintf(stderr, "error: %s\n", loaded.error().c_str()), 1;
  Scene& scene = loaded->scene;
  scene.settings.width = 64;
  scene.settings.height = 36;
  auto it = std::find_if(scene.objects.begin(), scene.objects.end(), [](const Object& o) { return o.visible; });
  const Material* material = it == scene.objects.end() ? nullptr : scene.material(it->material);
  if (!material) return std::fprintf(stderr, "error: %s: no visible object with a material to edit\n", path.c_str()), 1;
  Object o = *it;
  Material mat = *material;
  auto t0 = Clock::now();
  RenderSession session(scene, MethodSettings{});
  const double upload = std::chrono::duration<double>(Clock::now() - t0).count();
  session.renderFrame(false);
  session.prepareMoves();  // as the render thread does once its first frame is out
  // A refused edit would be timed as a fast one: it ends the benchmark instead.
  std::string refused;
  auto timed = [&session, &refused](const Edit& e) {
    const auto a = Clock::now();
    const auto applied = session.applyEdit(e);
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - a).count();
    if (!applied.ok() && refused.empty()) refused = cat(editName(e), ": ", applied.error());
    return ms;
  };
  auto moved = [&o] {
    o.transform = Mat4::translate({0.001f, 0, 0}) * o.transform;
    return SetObject{o};
  };
  // Once each, before anything moves (a scene packed direct renames the triangles of the
  // instances renumbered): removing the object renumbers the instances after it, adding it back
  // puts it last.
  const double removeMs = timed(RemoveNode{o.id});
  const double addMs = timed(AddObject{o});
  const double firstMove = timed(moved());
  double moveMs = 0, visibilityMs = 0, materialMs = 0, environmentMs = 0;
  Environment environment = scene.environment;
  for (int i = 0; i < edits; ++i) {
    moveMs += timed(moved());
    o.visible = !o.visible;
    visibilityMs += timed(SetObject{o});
    mat.roughness = 0.1f + 0.01f * static_cast<float>(i % 50);
    materialMs += timed(SetMaterial{mat});
    // A drag of the sky's intensity: its map (or baked sky) stays as it was.
    environment.intensity *= i % 2 ? 1.0f / 1.01f : 1.01f;
    environmentMs += timed(SetEnvironment{environment});
  }
  if (!refused.empty()) return std::fprintf(stderr, "error: %s: an edit was refused: %s\n", path.c_str(), refused.c_str()), 1;
  std::printf("scene            %s (%zu objects; edited: %s)\n", path.c_str(), scene.objects.size(), o.name.c_str());
  std::printf("upload           %.3f s\n", upload);
  std::printf("first move       %.3f ms\n", firstMove);
  std::printf("move             %.3f ms/edit\n", moveMs / edits);
  std::printf("show or hide     %.3f ms/edit\n", visibilityMs / edits);
  std::printf("material         %.3f ms/edit\n", materialMs / edits);
  std::printf("sky intensity    %.3f ms/edit (%s)\n", environmentMs / edits, environmentTypeName(environment.type));
  std::printf("remove, add      %.3f ms, %.3f ms\n", removeMs, addMs);
  return 0;
}

// The denoiser's cost: the whole frame denoised and composed, against a frame of 1 spp traced and
// accumulated at the same size (what the denoise variants add to each frame of the global method
// and of continuous refinement; incremental passes denoise only a growing region, now and then).
struct DenoiseOptions {
  std::string scene = "default";
  ImageSize size{640, 360};
  int frames = 15;
};

int benchDenoise(const DenoiseOptions& o) {
  const int w = o.size.width, h = o.size.height, frames = o.frames;
  auto loaded = loadScene(o.scene);
  if (!loaded) return std::fprintf(stderr, "error: %s\n", loaded.error().c_str()), 1;
  Renderer renderer;
  printRenderWarnings(renderer.setScene(loaded->scene), loaded->warnings);
  renderer.resize(w, h);
  FrameOptions denoise;
  denoise.denoise = wholeFrameDenoise(w, h);
  FrameOptions composeOnly = denoise;
  composeOnly.denoise.filter = false;
  FrameOptions timed = denoise;
  timed.denoise.timePasses = true;
  TileWork all{0, 0, w, h, 1, 0, true};
  // Warm-up: pipelines and buffers are made on first use.
  renderer.renderFrame({all});
  renderer.renderFrame({}, denoise);
  // Interleaved, one of each per round, and the medians: the machine's speed drifts by 10 to 20 %
  // over minutes, so only figures taken side by side compare.
  auto ms = [](auto&& what) {
    auto t0 = Clock::now();
    what();
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  };
  std::vector<double> trace, denoised, composed;
  std::vector<const char*> passNames;
  std::vector<std::vector<double>> passMs;
  for (int i = 0; i < frames; ++i) {
    all.sampleBase = static_cast<std::uint32_t>(i + 1);
    all.restart = false;
    trace.push_back(ms([&] { renderer.renderFrame({all}); }));
    denoised.push_back(ms([&] { renderer.renderFrame({}, denoise); }));
    composed.push_back(ms([&] { renderer.renderFrame({}, composeOnly); }));
    // A fourth frame, timed pass by pass on the device (its timestamps are not free, so the
    // frame above, untimed, gives the total).
    FrameStats passes = renderer.renderFrame({}, timed);
    passMs.resize(passes.denoisePasses.size());
    passNames.resize(passes.denoisePasses.size());
    for (std::size_t k = 0; k < passes.denoisePasses.size(); ++k) {
      passNames[k] = passes.denoisePasses[k].name;
      passMs[k].push_back(passes.denoisePasses[k].ms);
    }
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  double traceMs = median(trace), denoiseMs = median(denoised), composeMs = median(composed);
  std::printf("image          %dx%d, %s\n", w, h, o.scene.c_str());
  std::printf("frame          %.1f ms (1 spp traced and accumulated; medians of %d interleaved rounds)\n", traceMs, frames);
  std::printf("denoise        %.1f ms (the passes below; a frame denoised whole needs no compositor)\n", denoiseMs);
  for (std::size_t k = 0; k < passMs.size(); ++k) std::printf("  %-12s %.1f ms on the device\n", passNames[k], median(passMs[k]));
  std::printf("compose        %.1f ms (the compositor alone)\n", composeMs);
  std::printf("denoise share  %.1f ms a frame at %dx%d: %.0f %% of the %.1f ms frame\n", denoiseMs, w, h, 100.0 * denoiseMs / traceMs,
              traceMs);
  return 0;
}

}  // namespace

void addBench(CLI::App& app, int* status) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks: they print figures and never pass or fail");
  bench->require_subcommand(1);

  CLI::App* cmd =
      bench->add_subcommand("throughput", "Samples/s, rays/s and device memory of a scene, in frames as retile render traces them");
  auto throughput = std::make_shared<ThroughputOptions>();
  addScene(*cmd, &throughput->scene);
  addSize(*cmd, &throughput->size, "image size");
  addInt(*cmd, "--frames", &throughput->frames, 1, 100000, "frames timed, after one warm-up frame");
  addInt(*cmd, "--max-bounces", &throughput->maxBounces, 0, 1024, "longest path", "the scene's");
  addInt(*cmd, "--paths", &throughput->paths, 1, 1 << 20, "paths per trace invocation", "chosen from the last frame's cost")
      ->type_name("P");
  addInt(*cmd, "--spp-per-frame", &throughput->sppPerFrame, 1, 1024, "samples per pixel in each frame",
         "as retile render: about 2^18 samples a frame");
  cmd->add_option("--roulette", throughput->roulette,
                  "Russian roulette: standard, or low_throughput (also called tungsten) (default: the scene's)")
      ->type_name("RULE")
      ->check(oneOf("roulette", {"standard", "low_throughput", "tungsten"}));
  cmd->callback([throughput, status] { *status = benchThroughput(*throughput); });

  cmd = bench->add_subcommand("bvh", "BVH build time for a tessellated surface of N triangles");
  auto triangles = std::make_shared<int>(1'000'000);
  addInt(*cmd, "--triangles", triangles.get(), 1, 50'000'000, "triangles");
  cmd->callback([triangles, status] { *status = benchBvh(*triangles); });

  cmd = bench->add_subcommand("edit",
                              "Cost of moving an object and changing its material against mesh size (16 k to 2 M "
                              "triangles), or of moving, showing or hiding and recolouring an object of --scene");
  auto edits = std::make_shared<int>(20);
  auto editScene = std::make_shared<std::string>();
  addInt(*cmd, "--edits", edits.get(), 1, 10000, "edits of each kind timed per mesh size");
  cmd->add_option("--scene", *editScene, "time the edits on this scene's first visible object instead")->type_name("SCENE");
  cmd->callback([edits, editScene, status] { *status = editScene->empty() ? benchEdit(*edits) : benchEditScene(*editScene, *edits); });

  addEditorBenches(*bench, status);

  cmd = bench->add_subcommand("denoise", "The denoiser's cost against a frame of 1 spp, pass by pass");
  auto denoise = std::make_shared<DenoiseOptions>();
  cmd->add_option("SCENE", denoise->scene,
                  "a scene file (glTF, OBJ, FBX, PLY, Tungsten scene.json, .retile) or 'default' (default: default)")
      ->type_name("");
  addSize(*cmd, &denoise->size, "image size");
  addInt(*cmd, "--frames", &denoise->frames, 1, 10000, "interleaved rounds timed");
  cmd->callback([denoise, status] { *status = benchDenoise(*denoise); });

  cmd = bench->add_subcommand("room", "Samples/s and memory per triangle on a synthetic furnished room (100 k, 1 M, 4 M triangles)");
  auto room = std::make_shared<RoomOptions>();
  cmd->add_option("--triangles", room->triangles, "triangle counts, k and M allowed (default: 100k,1M,4M)")
      ->type_name("LIST")
      ->check(CLI::Validator(
          [](std::string& v) { return parseCounts(v).empty() ? "--triangles: expected counts such as 100k,1M,4M" : std::string(); }, ""));
  addSize(*cmd, &room->size, "image size");
  addInt(*cmd, "--frames", &room->frames, 1, 100000, "frames timed per size");
  addInt(*cmd, "--spp-per-frame", &room->sppPerFrame, 1, 1024, "samples per pixel in each frame",
         "as retile render: about 2^18 samples a frame");
  addInt(*cmd, "--max-bounces", &room->maxBounces, 0, 1024, "bounce limit");
  cmd->add_option("--write-scene", room->writeScene, "also save the first room as a native scene (.retile)")->type_name("FILE");
  cmd->add_option("--roulette", room->roulette, "Russian roulette: standard, or low_throughput (also called tungsten) (default: standard)")
      ->type_name("RULE")
      ->check(oneOf("roulette", {"standard", "low_throughput", "tungsten"}));
  cmd->callback([room, status] { *status = benchRoom(*room); });

  cmd = bench->add_subcommand("scale", "Samples/s and memory against triangle count (16 k to 2 M)");
  auto scale = std::make_shared<ScaleOptions>();
  addSize(*cmd, &scale->size, "image size");
  addInt(*cmd, "--frames", &scale->frames, 1, 100000, "frames timed per triangle count");
  addInt(*cmd, "--spp-per-frame", &scale->sppPerFrame, 1, 1024, "samples per pixel in each frame",
         "as retile render: about 2^18 samples a frame");
  cmd->callback([scale, status] { *status = benchScale(*scale); });
}

}  // namespace retile::cli
