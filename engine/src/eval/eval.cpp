#include "retile/eval.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>

#include "core/files.h"
#include "retile/color.h"
#include "retile/io.h"
#include "retile/log.h"
#include "retile/metrics.h"
#include "retile/render.h"
#include "vk/embedded_shaders.h"

namespace retile::eval {

Options Options::quick() {
  Options o;
  o.width = 96;
  o.height = 54;
  o.referenceSpp = 512;
  o.every = 5;
  o.converge = 64;
  o.moveFrames = 20;
  o.restFrames = 30;
  o.dragFrames = 15;
  o.cameraFrames = 10;
  // At 64 + 30 spp against 512-spp references no method gets within 2 %: the noise alone is
  // above it. 5 % still separates the methods.
  o.target = 0.05;
  return o;
}

std::vector<std::string> builtInScenarioNames() { return {"fig6", "material", "light", "camera", "drag"}; }

std::vector<std::string> defaultMethods() {
  return {"global", "spiral", "focus", "indirection", "change", "spiral+smooth", "global+denoise", "spiral+denoise", "spiral+reuse"};
}

Result<MethodSettings> parseMethodLabel(const std::string& label) {
  using R = Result<MethodSettings>;
  MethodSettings m;
  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    std::size_t plus = label.find('+', start);
    parts.push_back(label.substr(start, plus == std::string::npos ? std::string::npos : plus - start));
    if (plus == std::string::npos) break;
    start = plus + 1;
  }
  if (!methodFromName(parts[0], &m.kind)) return R::failure(cat("unknown method '", parts[0], "' in '", label, "'"));
  for (std::size_t i = 1; i < parts.size(); ++i) {
    if (parts[i] == "smooth") m.smooth = true;
    else if (parts[i] == "denoise") m.denoise = true;
    else if (parts[i] == "reuse") m.reuse = true;
    else if (parts[i] == "focus" && m.kind == MethodKind::Indirection) m.kind = MethodKind::IndirectionFocus;
    else return R::failure(cat("unknown option '", parts[i], "' in method '", label, "' (smooth, denoise, reuse)"));
  }
  if (m.kind == MethodKind::Indirection || m.kind == MethodKind::IndirectionFocus) m.quality = 0;
  if (std::string bad = validateMethodSettings(m); !bad.empty()) return R::failure(cat(label, ": ", bad));
  return m;
}

namespace {

struct Projected {
  float fraction = 0;  // of the image covered by the projected bounds, clipped
  Vec2 centre{0.0f};
  float height = 0;  // of the clipped projected bounds, pixels
};

std::optional<Projected> project(const Scene& s, const Bounds3& b) {
  const float w = static_cast<float>(s.settings.width), h = static_cast<float>(s.settings.height);
  Vec2 lo{1e30f, 1e30f}, hi{-1e30f, -1e30f};
  for (int c = 0; c < 8; ++c) {
    Vec3 p{(c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z};
    auto q = projectToImage(s.camera, s.settings.width, s.settings.height, p);
    if (!q) return std::nullopt;  // partly behind the camera: not something to pick
    lo = {std::min(lo.x, q->x), std::min(lo.y, q->y)};
    hi = {std::max(hi.x, q->x), std::max(hi.y, q->y)};
  }
  lo = {std::clamp(lo.x, 0.0f, w), std::clamp(lo.y, 0.0f, h)};
  hi = {std::clamp(hi.x, 0.0f, w), std::clamp(hi.y, 0.0f, h)};
  Projected p;
  p.fraction = (hi.x - lo.x) * (hi.y - lo.y) / (w * h);
  p.centre = {(lo.x + hi.x) * 0.5f, (lo.y + hi.y) * 0.5f};
  p.height = hi.y - lo.y;
  return p;
}

bool uniqueName(const Scene& s, const std::string& name) {
  return !name.empty() && name[0] != '#' &&
         std::count_if(s.objects.begin(), s.objects.end(), [&](const Object& o) { return o.name == name; }) == 1;
}

// How a scenario step names an object: its name when unique, else "#ID" (stepEdits reads both).
std::string reference(const Scene& s, const Object& o) { return uniqueName(s, o.name) ? o.name : cat("#", o.id); }

// For descriptions: the name, or what the object is when it has none.
std::string shown(const Object& o) { return o.name.empty() ? cat("object #", o.id) : o.name; }

Bounds3 worldBounds(const Scene& s, const Object& o) {
  const Mesh* m = s.mesh(o.mesh);
  if (!m || !m->geometry) return {};
  return transformBounds(o.transform, m->geometry->bounds());
}

}  // namespace

NodeId pickSubject(const Scene& s) {
  NodeId best = kNoNode, large = kNoNode;
  float bestDistance = 1e30f, largeFraction = 2.0f;
  const Vec2 middle{static_cast<float>(s.settings.width) * 0.5f, static_cast<float>(s.settings.height) * 0.5f};
  for (const Object& o : s.objects) {
    const Material* mat = s.material(o.material);
    if (!o.visible || (mat && mat->emissive())) continue;
    Bounds3 b = worldBounds(s, o);
    if (b.empty()) continue;
    auto p = project(s, b);
    if (!p || p->fraction < 0.002f) continue;
    if (p->fraction > 0.25f) {  // a scene of one object filling the frame: the smallest such
      if (p->fraction < largeFraction) largeFraction = p->fraction, large = o.id;
      continue;
    }
    float d = length(Vec3{p->centre.x - middle.x, p->centre.y - middle.y, 0.0f});
    if (d < bestDistance) bestDistance = d, best = o.id;
  }
  return best != kNoNode ? best : large;
}

std::vector<Case> builtInScenarios(const Scene& scene, const Options& o, const std::vector<std::string>& names,
                                   std::vector<std::string>* skipped) {
  auto wanted = [&](const char* n) { return names.empty() || std::find(names.begin(), names.end(), n) != names.end(); };
  auto skip = [&](const char* n, const std::string& why) {
    if (wanted(n) && skipped) skipped->push_back(cat(n, ": ", why));
  };
  std::vector<Case> out;
  const NodeId subjectId = pickSubject(scene);
  const Object* subject = scene.object(subjectId);
  ScenarioStep select;
  select.kind = ScenarioStep::Kind::Select;
  if (subject) select.target = reference(scene, *subject);
  // The focus methods get one following point below the object, where its contact shadow or
  // reflection on a floor usually is: a second place its edits change.
  ScenarioStep focus;
  focus.kind = ScenarioStep::Kind::Focus;
  if (subject)
    if (auto p = project(scene, worldBounds(scene, *subject))) {
      FocusPoint fp;
      fp.pixel = {p->centre.x, std::min(p->centre.y + p->height, static_cast<float>(scene.settings.height) - 1.0f)};
      fp.follows = true;
      focus.focus = {fp};
      focus.focusIsUv = {false};
    }
  ScenarioStep rest;
  rest.kind = ScenarioStep::Kind::Wait;
  rest.frames = o.restFrames;

  if (wanted("fig6")) {
    if (!subject) {
      skip("fig6", "no visible object covers 0.2 % of the image or more to move");
    } else {
      Case c;
      c.name = "fig6";
      c.description = cat("The paper's Fig. 6 protocol: converge ", o.converge, " spp, move '", shown(*subject),
                          "' up by 0.005 a frame for ", o.moveFrames, " frames, then ", o.restFrames, " frames at rest.");
      c.script.converge = o.converge;
      c.script.steps = {select, focus};
      ScenarioStep move;
      move.kind = ScenarioStep::Kind::Move;
      move.vector = {0.0f, 0.005f, 0.0f};
      move.frames = o.moveFrames;
      c.script.steps.push_back(move);
      c.script.steps.push_back(rest);
      out.push_back(std::move(c));
    }
  }
  if (wanted("material")) {
    const Material* m = subject ? scene.material(subject->material) : nullptr;
    if (!m) {
      skip("material", subject ? "the picked object has no material" : "no object to pick");
    } else {
      Case c;
      c.name = "material";
      ScenarioStep edit;
      edit.kind = ScenarioStep::Kind::Material;
      edit.target = reference(scene, *subject);  // the object's material
      edit.roughness = m->roughness < 0.3f ? 0.45f : 0.1f;
      Vec3 a = m->albedo;
      bool grey = std::abs(a.x - a.y) < 0.05f && std::abs(a.y - a.z) < 0.05f;
      edit.albedo = grey ? Vec3{0.2f, 0.35f, 0.8f} : Vec3{a.z, a.x, a.y};
      c.description = cat("A material edit: '", m->name, "' on '", shown(*subject), "' takes roughness ", *edit.roughness,
                          " and a new albedo, then ", o.restFrames, " frames at rest.");
      c.script.converge = std::max(o.converge / 4, 1);
      c.script.steps = {select, focus, edit, rest};
      out.push_back(std::move(c));
    }
  }
  if (wanted("light")) {
    ScenarioStep edit;
    edit.kind = ScenarioStep::Kind::Light;
    std::string what;
    for (const Light& l : scene.lights)
      if (l.visible && !l.name.empty()) {
        edit.target = l.name;
        edit.color = Vec3{l.color.x, l.color.y * 0.8f, l.color.z * 0.6f};
        edit.intensity = l.intensity * 1.5f;
        what = l.name;
        break;
      }
    if (edit.target.empty())
      for (const Object& ob : scene.objects) {
        const Material* m = scene.material(ob.material);
        if (ob.visible && m && m->emissive()) {
          edit.target = reference(scene, ob);
          edit.color = Vec3{m->emission.x, m->emission.y * 0.8f, m->emission.z * 0.6f};
          edit.intensity = 1.5f;
          what = shown(ob);
          break;
        }
      }
    if (edit.target.empty()) {
      skip("light", "no light or emitter to edit");
    } else {
      Case c;
      c.name = "light";
      c.description = cat("A light edit: '", what, "' turns warmer and 1.5 times as strong, then ", o.restFrames, " frames at rest.");
      c.script.converge = std::max(o.converge / 4, 1);
      c.script.steps = {edit, rest};
      out.push_back(std::move(c));
    }
  }
  if (wanted("camera")) {
    Case c;
    c.name = "camera";
    c.description = cat("A camera move: the camera orbits its target by 0.5 degrees a frame for ", o.cameraFrames, " frames, then ",
                        o.restFrames, " frames at rest.");
    c.script.converge = std::max(o.converge / 4, 1);
    const Vec3 target = scene.camera.target, offset = scene.camera.position - target;
    for (int f = 1; f <= o.cameraFrames; ++f) {
      ScenarioStep step;
      step.kind = ScenarioStep::Kind::Camera;
      step.cameraPosition = target + Mat4::rotateY(radians(0.5f * static_cast<float>(f))).transformVector(offset);
      step.cameraTarget = target;
      c.script.steps.push_back(step);
    }
    c.script.steps.push_back(rest);
    out.push_back(std::move(c));
  }
  if (wanted("drag")) {
    if (!subject) {
      skip("drag", "no visible object covers 0.2 % of the image or more to drag");
    } else {
      Case c;
      c.name = "drag";
      // Sideways on screen, a fiftieth of the object's size a frame: a hand dragging it.
      Vec3 right = normalize(cross(scene.camera.target - scene.camera.position, scene.camera.up));
      float size = length(worldBounds(scene, *subject).extent());
      ScenarioStep move;
      move.kind = ScenarioStep::Kind::Move;
      move.vector = right * (size * 0.02f);
      move.frames = o.dragFrames;
      c.description = cat("A continuous drag: '", shown(*subject), "' slides sideways by a fiftieth of its size a frame for ", o.dragFrames,
                          " frames, then ", o.restFrames, " frames at rest.");
      c.script.converge = std::max(o.converge / 4, 1);
      c.script.steps = {select, focus, move, rest};
      out.push_back(std::move(c));
    }
  }
  for (auto& c : out) c.script.name = c.name;
  return out;
}

Result<Plan> planScenario(const Scenario& script, const Scene& scene, int every) {
  using R = Result<Plan>;
  every = std::max(every, 1);
  Plan plan;
  plan.converge = script.converge;
  Scene now = scene;
  NodeId selection = kNoNode;
  std::size_t first = 0;
  // Leading select and focus steps hold while the scene converges, as an artist selects before
  // editing (the indirection counters are gathered then).
  for (; first < script.steps.size(); ++first) {
    const ScenarioStep& step = script.steps[first];
    if (step.kind != ScenarioStep::Kind::Select && step.kind != ScenarioStep::Kind::Focus) break;
    auto e = stepEdits(step, 0, now, selection);
    if (!e) return R::failure(cat("steps[", first, "]: ", e.error()));
    if (e->select) selection = plan.selection = *e->select;
    if (e->focus) plan.focus = *e->focus;
  }
  plan.start = now;
  std::optional<NodeId> pendingSelect;
  std::optional<std::vector<FocusPoint>> pendingFocus;
  for (std::size_t si = first; si < script.steps.size(); ++si) {
    const ScenarioStep& step = script.steps[si];
    bool instant = step.kind == ScenarioStep::Kind::Select || step.kind == ScenarioStep::Kind::Focus;
    for (int f = 0; f < (instant ? 1 : step.frames); ++f) {
      auto e = stepEdits(step, f, now, selection);
      if (!e) return R::failure(cat("steps[", si, "]: ", e.error()));
      if (e->select) selection = *e->select, pendingSelect = *e->select;
      if (e->focus) pendingFocus = *e->focus;
      if (instant) break;
      Plan::Frame frame;
      frame.select = std::exchange(pendingSelect, std::nullopt);
      frame.focus = std::exchange(pendingFocus, std::nullopt);
      for (const Edit& edit : e->edits) {
        auto r = applyEdit(now, edit);
        if (!r) return R::failure(cat("steps[", si, "]: ", r.error()));
        frame.edits.push_back(edit);
      }
      plan.frames.push_back(std::move(frame));
      if (!plan.frames.back().edits.empty()) plan.lastEditFrame = static_cast<int>(plan.frames.size());
    }
  }
  // Which frames are scored; a state is kept only for them (copies share geometry).
  Scene replay = plan.start;
  int lastState = -1;
  bool changedSinceState = true;
  for (std::size_t i = 0; i < plan.frames.size(); ++i) {
    const int f = static_cast<int>(i) + 1;
    for (const Edit& edit : plan.frames[i].edits) {
      (void)applyEdit(replay, edit);  // succeeded above
      changedSinceState = true;
    }
    if (f == 1 || f == 10 || f % every == 0 || f >= plan.lastEditFrame) {
      if (changedSinceState || lastState < 0) {
        plan.states.push_back(replay);
        lastState = static_cast<int>(plan.states.size()) - 1;
        changedSinceState = false;
      }
      plan.frames[i].state = lastState;
    }
  }
  return plan;
}

// ---- references ----

namespace {

std::uint64_t fnv(std::uint64_t h, const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}
std::uint64_t fnv(std::uint64_t h, const std::string& s) { return fnv(h, s.data(), s.size()); }

template <class T>
std::uint64_t fnvVector(std::uint64_t h, const std::vector<T>& v) {
  return fnv(h, v.data(), v.size() * sizeof(T));
}

constexpr char kMagic[8] = {'R', 'T', 'R', 'E', 'F', '0', '0', '1'};

Result<RenderImage> readReference(const std::filesystem::path& file, int width, int height) {
  std::ifstream in(file, std::ios::binary);
  char magic[8];
  std::int32_t wh[2];
  if (!in.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0 || !in.read(reinterpret_cast<char*>(wh), sizeof wh) || wh[0] != width ||
      wh[1] != height)
    return Result<RenderImage>::failure(cat(file.string(), ": not a reference of ", width, "x", height));
  RenderImage img;
  img.width = width;
  img.height = height;
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  img.color.resize(n * 3);
  img.moment2.resize(n);
  img.sampleCount.resize(n);
  for (auto* v : {&img.color, &img.moment2, &img.sampleCount})
    if (!in.read(reinterpret_cast<char*>(v->data()), static_cast<std::streamsize>(v->size() * sizeof(float))))
      return Result<RenderImage>::failure(cat(file.string(), ": truncated"));
  return img;
}

}  // namespace

struct References::Gpu {
  Renderer renderer;
};

References::References(std::filesystem::path dir, int spp) : dir_(std::move(dir)), spp_(spp) {}

std::string References::key(const Scene& state, int spp) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  // Geometry by its bytes; everything else through the native format without the geometry blobs.
  Scene light = state;
  for (Mesh& m : light.meshes) {
    if (m.geometry) {
      h = fnvVector(h, m.geometry->positions);
      h = fnvVector(h, m.geometry->normals);
      h = fnvVector(h, m.geometry->uvs);
      h = fnvVector(h, m.geometry->indices);
    }
    m.geometry = nullptr;
  }
  h = fnv(h, nativeSceneToString(light));
  h = fnv(h, light.baseDirectory.string());
  h = fnv(h, &spp, sizeof spp);
  for (const auto& s : vk::embeddedShaders()) h = fnv(fnv(h, s.name), s.source);  // the renderer itself
  char text[20];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

Result<RenderImage> References::get(const Scene& state, const std::function<void(int, int)>& progress) {
  const std::filesystem::path file = dir_ / (key(state, spp_) + ".ref");
  if (std::filesystem::exists(file)) {
    auto r = readReference(file, state.settings.width, state.settings.height);
    if (r) {
      ++reused_;
      return r;
    }
    logWarning(r.error(), "; rendering it again");
  }
  if (!gpu_) gpu_ = std::make_shared<Gpu>();
  gpu_->renderer.setScene(state);
  RenderRequest req;
  req.width = state.settings.width;
  req.height = state.settings.height;
  req.samplesPerPixel = spp_;
  req.seed = 0x5eed;
  RenderImage img = gpu_->renderer.render(req, [&](int done, int total) {
    if (progress) progress(done, total);
    return true;
  });
  ++rendered_;
  std::string bytes(kMagic, 8);
  std::int32_t wh[2] = {img.width, img.height};
  bytes.append(reinterpret_cast<const char*>(wh), sizeof wh);
  for (const auto* v : {&img.color, &img.moment2, &img.sampleCount})
    bytes.append(reinterpret_cast<const char*>(v->data()), v->size() * sizeof(float));
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  auto written = writeFileAtomic(file, bytes);
  if (!written) logWarning("cannot cache a reference: ", written.error());
  return img;
}

Result<Targets> prepareTargets(const Plan& plan, References& refs, const std::function<void(int, int)>& progress) {
  Targets t;
  t.width = plan.start.settings.width;
  t.height = plan.start.settings.height;
  const int total = static_cast<int>(plan.states.size()) + 1;
  auto step = [&](int i) {
    return [&, i](int done, int all) {
      if (progress) progress(i * all + done, total * all);
    };
  };
  auto start = refs.get(plan.start, step(0));
  if (!start) return Result<Targets>::failure(start.error());
  const auto colors = ColorConfig::get();
  const std::size_t n = static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height);
  t.affected.assign(n, 0);
  for (std::size_t s = 0; s < plan.states.size(); ++s) {
    auto img = refs.get(plan.states[s], step(static_cast<int>(s) + 1));
    if (!img) return Result<Targets>::failure(img.error());
    const std::size_t pixels = static_cast<std::size_t>(img->width) * static_cast<std::size_t>(img->height);
    if (img->width == t.width && img->height == t.height) {  // after a resize nothing lines up
      std::vector<std::uint8_t> changed = affectedPixels(start.value(), img.value());
      for (std::size_t i = 0; i < n; ++i) t.affected[i] |= changed[i];
    }
    std::vector<float> shown(img->color.size());
    colors->toDisplayFloat(img->color.data(), pixels, DisplaySettings{}, shown.data());
    for (float& v : shown) v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    t.sizes.emplace_back(img->width, img->height);
    t.linear.push_back(std::move(img->color));
    t.display.push_back(std::move(shown));
  }
  t.rest.resize(n);
  for (std::size_t i = 0; i < n; ++i) t.affectedCount += t.affected[i], t.rest[i] = !t.affected[i];
  return t;
}

void scoreFrame(const Targets& t, int state, const std::vector<float>& linear, FrameScore* s) {
  if (state < 0 || state >= static_cast<int>(t.linear.size())) return;
  const auto [w, h] = t.sizes[static_cast<std::size_t>(state)];
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (linear.size() != n * 3) return;
  static const auto colors = ColorConfig::get();
  std::vector<float> shown(n * 3);
  colors->toDisplayFloat(linear.data(), n, DisplaySettings{}, shown.data());
  for (float& v : shown) v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
  const MetricImage a{shown.data(), w, h}, r{t.display[state].data(), w, h};
  s->rmse = rootMeanSquaredError(a, r);
  s->psnr = psnr(a, r);
  s->ssim = ssim(a, r);
  s->psnrHvsM = psnrHvsM(a, r);
  s->relRmse = relativeRmse(linear, t.linear[state], w, h, 4);
  if (w != t.width || h != t.height) return;  // the masks belong to the start's size
  if (t.affectedCount > 0) {
    s->rmseAffected = rootMeanSquaredError(a, r, t.affected.data());
    s->psnrAffected = psnr(a, r, t.affected.data());
    s->relRmseAffected = relativeRmse(linear, t.linear[state], w, h, 4, t.affected.data());
  }
  s->rmseRest = rootMeanSquaredError(a, r, t.rest.data());
  s->psnrRest = psnr(a, r, t.rest.data());
}

Result<Run> runMethod(const Plan& plan, const Targets& targets, const MethodSettings& method,
                      const std::function<bool(const FrameRecord&, const FrameScore&)>& onFrame) {
  Run run;
  run.method = methodLabel(method);
  run.lastEditFrame = plan.lastEditFrame;
  RenderSession session(plan.start, method);
  if (plan.selection != kNoNode) session.select(plan.selection);
  if (plan.focus) session.setFocus(*plan.focus);
  using Clock = std::chrono::steady_clock;
  auto t0 = Clock::now();
  for (int f = 0; f < plan.converge; ++f) session.renderFrame(false);
  run.convergeMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  std::uint64_t budget = static_cast<std::uint64_t>(plan.start.settings.width) * static_cast<std::uint64_t>(plan.start.settings.height);
  double ms = 0;
  std::uint64_t samples = 0;
  for (std::size_t i = 0; i < plan.frames.size(); ++i) {
    const Plan::Frame& pf = plan.frames[i];
    auto begin = Clock::now();
    if (pf.select) session.select(*pf.select);
    if (pf.focus) session.setFocus(*pf.focus);
    if (pf.resize) {
      session.resize(pf.resize->first, pf.resize->second);
      budget = static_cast<std::uint64_t>(pf.resize->first) * static_cast<std::uint64_t>(pf.resize->second);
    }
    for (const Edit& e : pf.edits) {
      auto r = session.applyEdit(e);
      if (!r) return Result<Run>::failure(cat("frame ", i + 1, ": ", r.error()));
    }
    FrameRecord rec = session.renderFrame(true);
    FrameScore s;
    s.frame = static_cast<int>(i) + 1;
    s.frameMs = std::chrono::duration<double, std::milli>(Clock::now() - begin).count();
    ms += s.frameMs;
    samples += rec.samples;
    s.ms = ms;
    s.samples = samples;
    s.mode = rec.mode;
    s.quality = rec.quality;
    s.servedTiles = rec.servedTiles.size();
    s.denoiseRegions = rec.denoised.size();
    run.exactBudget = run.exactBudget && rec.samples == budget;
    if (pf.state >= 0 && rec.image) scoreFrame(targets, pf.state, rec.image->shown(), &s);
    run.frames.push_back(s);
    if (onFrame && !onFrame(rec, s)) break;
  }
  return run;
}

SceneModel modelOf(const Scene& scene) {
  Renderer r;
  r.setScene(scene);
  SceneModel m;
  m.triangles = r.sceneTriangles();
  m.deviceBytes = r.sceneDeviceBytes();
  m.bytesPerTriangle = m.triangles ? static_cast<double>(m.deviceBytes) / static_cast<double>(m.triangles) : 0.0;
  m.kernelFeatures = r.kernelFeatures();
  return m;
}

Summary summarize(const Run& run, double target) {
  Summary s;
  s.scene = run.scene;
  s.scenario = run.scenario;
  s.method = run.method;
  for (int k = 0; k < 4; ++k) {
    const int f = Summary::kAt[k];
    if (f > static_cast<int>(run.frames.size())) continue;
    const FrameScore& fs = run.frames[static_cast<std::size_t>(f - 1)];
    s.psnrAt[k] = fs.psnr;
    s.psnrAffectedAt[k] = fs.psnrAffected;
    s.relAffectedAt[k] = fs.relRmseAffected;
  }
  // The first scored frame from which the error stays at or below the target.
  const FrameScore* from = nullptr;
  for (const FrameScore& fs : run.frames) {
    if (!fs.scored()) continue;
    double e = std::isnan(fs.relRmseAffected) ? fs.relRmse : fs.relRmseAffected;
    if (!(e <= target)) from = nullptr;
    else if (!from) from = &fs;
  }
  if (from) {
    s.framesToTarget = from->frame;
    s.msToTarget = from->ms;
  }
  return s;
}

namespace {

std::string num(double v, int decimals) {
  if (std::isnan(v)) return "";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

}  // namespace

std::string metricsCsvHeader() {
  return "scenario,scene,method,frame,ms,samples,rmse,psnr,ssim,psnr_hvs_m,rmse_affected,rmse_rest,psnr_affected,"
         "psnr_rest,rel_rmse,rel_rmse_affected,frame_ms,mode,quality,served_tiles,denoise_regions\n";
}

std::string metricsCsvRow(const Run& r, const FrameScore& f) {
  return cat(r.scenario, ",", r.scene, ",", r.method, ",", f.frame, ",", num(f.ms, 3), ",", f.samples, ",", num(f.rmse, 6), ",",
             num(f.psnr, 3), ",", num(f.ssim, 5), ",", num(f.psnrHvsM, 3), ",", num(f.rmseAffected, 6), ",", num(f.rmseRest, 6), ",",
             num(f.psnrAffected, 3), ",", num(f.psnrRest, 3), ",", num(f.relRmse, 5), ",", num(f.relRmseAffected, 5), ",",
             num(f.frameMs, 3), ",", f.mode, ",", f.quality, ",", f.servedTiles, ",", f.denoiseRegions, "\n");
}

std::string summaryCsvHeader() {
  std::string h = "scenario,scene,method";
  for (int f : Summary::kAt) h += cat(",psnr_", f);
  for (int f : Summary::kAt) h += cat(",psnr_affected_", f);
  for (int f : Summary::kAt) h += cat(",rel_rmse_affected_", f);
  return h + ",frames_to_target,ms_to_target\n";
}

std::string summaryCsvRow(const Summary& s) {
  std::string row = cat(s.scenario, ",", s.scene, ",", s.method);
  for (double v : s.psnrAt) row += "," + num(v, 3);
  for (double v : s.psnrAffectedAt) row += "," + num(v, 3);
  for (double v : s.relAffectedAt) row += "," + num(v, 5);
  row += cat(",", s.framesToTarget >= 0 ? std::to_string(s.framesToTarget) : std::string(), ",", num(s.msToTarget, 1));
  return row + "\n";
}

}  // namespace retile::eval
