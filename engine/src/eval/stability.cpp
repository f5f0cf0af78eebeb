// The stability suite (retile/eval.h): METHOD.md's failure cases as short edits, each method's
// figure against the global method's.
#include <algorithm>
#include <cmath>
#include <set>

#include "retile/eval.h"
#include "retile/log.h"
#include "scene/primitives.h"

namespace retile::eval {

std::vector<std::string> stabilityCaseNames() {
  return {"ghosting",        "burst",        "off-screen",  "behind-camera",    "fill-screen", "camera-mid-pass",
          "resize-mid-pass", "light-global", "mirror-only", "offscreen-shadow", "extreme"};
}

namespace {

constexpr double kTolerance = 1.5;  // a method passes at up to 1.5x the global method's figure

// Builds a plan frame by frame; score() scores the frame just added against what it shows.
struct PlanBuilder {
  Plan plan;
  Scene now;
  PlanBuilder(const Scene& start, int converge) : now(start) {
    plan.start = start;
    plan.converge = converge;
  }
  Result<bool> frame(std::vector<Edit> edits = {}) {
    Plan::Frame f;
    for (const Edit& e : edits) {
      auto r = applyEdit(now, e);
      if (!r) return Result<bool>::failure(r.error());
    }
    f.edits = std::move(edits);
    plan.frames.push_back(std::move(f));
    if (!plan.frames.back().edits.empty()) plan.lastEditFrame = static_cast<int>(plan.frames.size());
    return true;
  }
  void rest(int n) {
    for (int i = 0; i < n; ++i) plan.frames.push_back({});
  }
  void resize(int w, int h) {
    Plan::Frame f;
    f.resize = std::pair{w, h};
    now.settings.width = w;
    now.settings.height = h;
    plan.frames.push_back(std::move(f));
    plan.lastEditFrame = static_cast<int>(plan.frames.size());
  }
  void score() {
    plan.states.push_back(now);
    plan.frames.back().state = static_cast<int>(plan.states.size()) - 1;
  }
};

Bounds3 objectBounds(const Scene& s, const Object& o) {
  const Mesh* m = s.mesh(o.mesh);
  return m && m->geometry ? transformBounds(o.transform, m->geometry->bounds()) : Bounds3{};
}

Edit moved(const Object& o, Vec3 by) {
  Object m = o;
  m.transform = Mat4::translate(by) * o.transform;
  return SetObject{m};
}

// The scene with one more sphere where a case needs it: behind the camera, seen only in a mirror
// (mirror-only), or above the frame between the light and the floor, seen only by its shadow
// (offscreen-shadow). Lambert green, so that a change of it shows.
Scene withHiddenSphere(Scene s, Vec3 at, float radius, const char* name) {
  Material paint;
  paint.type = MaterialType::Lambert;
  paint.albedo = {0.1f, 0.6f, 0.15f};
  addMeshObject(s, name, makeSphere(24, 48), paint, Mat4::translate(at) * Mat4::scale(Vec3{radius}));
  return s;
}

const Object* objectNamed(const Scene& s, const std::string& name) {
  for (const Object& o : s.objects)
    if (o.name == name) return &o;
  return nullptr;
}

struct Variant {
  std::string label;
  MethodSettings method;
  int width = 0, height = 0;  // 0: the options'
};

bool allFinite(const std::vector<float>& v) {
  return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); });
}

// The methods compared, the global method first: it is every other method's yardstick.
Result<std::vector<Variant>> methodVariants(const std::vector<std::string>& labels) {
  std::vector<Variant> variants;
  for (const auto& label : labels) {
    auto m = parseMethodLabel(label);
    if (!m) return Result<std::vector<Variant>>::failure(m.error());
    variants.push_back({label, m.value()});
  }
  std::stable_partition(variants.begin(), variants.end(), [](const Variant& v) { return v.label == "global"; });
  if (variants.empty() || variants[0].label != "global") variants.insert(variants.begin(), {"global", MethodSettings{MethodKind::Global}});
  return variants;
}

// What a case starts from: the scene at the suite's size, the object the built-in scenarios edit
// and the view's axes. `subject` points into `scene`, so a Setup stays where it is made.
struct Setup {
  const std::string& name;
  Scene scene;
  int W, H;
  const Object* subject;
  Vec3 forward, right;
  float size;  // the subject's diagonal

  Setup(const std::string& caseName, const Scene& sceneIn, const StabilityOptions& o)
      : name(caseName), scene(sceneIn), W(o.width), H(o.height) {
    scene.settings.width = o.width;
    scene.settings.height = o.height;
    subject = scene.object(pickSubject(scene));
    forward = normalize(scene.camera.target - scene.camera.position);
    right = normalize(cross(forward, scene.camera.up));
    size = subject ? length(objectBounds(scene, *subject).extent()) : 0.0f;
  }
  Setup(const Setup&) = delete;
  Setup& operator=(const Setup&) = delete;

  Result<bool> needSubject() const {
    if (!subject) return Result<bool>::failure(cat(name, ": the scene has no visible object covering 0.2 % of the image or more"));
    return true;
  }
};

// Each case's plan: its edits, the frames scored (the last one's figure counts unless a case says
// otherwise) and its description.

Result<bool> planGhosting(const Setup& c, PlanBuilder& b, std::vector<Variant>& variants, StabilityResult& out) {
  if (auto r = c.needSubject(); !r) return r;
  out.description = cat("A drag at Q=512 of '", c.subject->name, "' by its own size over 10 frames, larger than the ", c.W * c.H / 512,
                        " pixels refreshed per frame; the figure 20 frames after the drag: what is left "
                        "of it at its old positions.");
  for (auto& v : variants) v.method.quality = 512;
  b.plan.selection = c.subject->id;
  for (int f = 0; f < 10; ++f) {
    if (auto r = b.frame({moved(*b.now.object(c.subject->id), c.right * (c.size * 0.1f))}); !r) return r;
  }
  b.rest(20);
  b.score();
  return true;
}

Result<bool> planBurst(const Setup& c, PlanBuilder& b, StabilityResult& out) {
  if (auto r = c.needSubject(); !r) return r;
  out.description = cat("An edit every frame for 100 frames ('", c.subject->name,
                        "' drifts sideways), then 100 at rest; the figure at the end, and the tiles the edits "
                        "changed that were never traced during the burst (starved).");
  b.plan.selection = c.subject->id;
  for (int f = 0; f < 100; ++f) {
    if (auto r = b.frame({moved(*b.now.object(c.subject->id), c.right * (c.size * 0.004f))}); !r) return r;
  }
  b.score();  // frame 100: the state the burst ends in, for the affected region
  b.rest(100);
  b.score();
  return true;
}

// off-screen, behind-camera and fill-screen: the subject leaves the view or fills it.
Result<bool> planSubjectLeaves(const Setup& c, PlanBuilder& b, StabilityResult& out) {
  if (auto r = c.needSubject(); !r) return r;
  const Scene& scene = c.scene;
  const Object& subject = *c.subject;
  b.plan.selection = subject.id;
  const Bounds3 box = objectBounds(scene, subject);
  const float distance = length(box.center() - scene.camera.position);
  if (c.name == "off-screen") {
    // Past the frame's edge: the half-width of the view at the object's distance, twice over.
    const float halfWidth = distance * std::tan(scene.camera.verticalFov * 0.5f) * scene.aspect();
    out.description = cat("'", subject.name, "' leaves the frame sideways over 5 frames; the figure 40 frames later.");
    for (int f = 0; f < 5; ++f)
      if (auto r = b.frame({moved(*b.now.object(subject.id), c.right * ((2.0f * halfWidth + c.size) / 5.0f))}); !r) return r;
  } else if (c.name == "behind-camera") {
    out.description = cat("'", subject.name, "' moves behind the camera over 5 frames; the figure 40 frames later.");
    const Vec3 to = scene.camera.position - c.forward * (c.size + 1.0f);
    for (int f = 0; f < 5; ++f)
      if (auto r = b.frame({moved(*b.now.object(subject.id), (to - box.center()) * 0.2f)}); !r) return r;
  } else {
    out.description = cat("'", subject.name,
                          "' grows about its centre until it fills the frame; the figure 40 "
                          "frames later.");
    Object grown = subject;
    const float k = std::max(2.0f, 2.0f * distance / std::max(c.size, 1e-6f));
    grown.transform = Mat4::translate(box.center()) * Mat4::scale(Vec3{k}) * Mat4::translate(box.center() * -1.0f) * subject.transform;
    if (auto r = b.frame({SetObject{grown}}); !r) return r;
  }
  b.rest(40);
  b.score();
  return true;
}

// camera-mid-pass and resize-mid-pass: the subject moves, and the view changes 3 frames into the pass.
Result<bool> planMidPass(const Setup& c, PlanBuilder& b, StabilityResult& out) {
  if (auto r = c.needSubject(); !r) return r;
  b.plan.selection = c.subject->id;
  if (auto r = b.frame({moved(*c.subject, c.scene.camera.up * (c.size * 0.1f))}); !r) return r;
  b.rest(2);
  if (c.name == "camera-mid-pass") {
    out.description = cat("'", c.subject->name,
                          "' moves, and 3 frames into the pass the camera orbits 3 degrees; the "
                          "figure 40 frames later.");
    Camera cam = c.scene.camera;
    cam.position = cam.target + Mat4::rotateY(radians(3.0f)).transformVector(cam.position - cam.target);
    if (auto r = b.frame({SetCamera{cam}}); !r) return r;
  } else {
    const int w2 = c.W * 3 / 4 + 1, h2 = c.H * 3 / 4 + 1;
    out.description = cat("'", c.subject->name, "' moves, and 3 frames into the pass the viewport is resized to ", w2, "x", h2,
                          " (odd sizes); the figure 40 frames later, whole image.");
    b.resize(w2, h2);
  }
  b.rest(40);
  b.score();
  return true;
}

Result<bool> planLightGlobal(const Setup& c, PlanBuilder& b, StabilityResult& out) {
  const Scene& scene = c.scene;
  ScenarioStep step;
  step.kind = ScenarioStep::Kind::Light;
  for (const Light& l : scene.lights)
    if (l.visible && !l.name.empty()) {
      step.target = l.name;
      step.intensity = l.intensity * 1.5f;
      break;
    }
  if (step.target.empty())
    for (const Object& ob : scene.objects) {
      const Material* m = scene.material(ob.material);
      if (ob.visible && m && m->emissive()) {
        step.target = cat("#", ob.id);  // emitters are often unnamed
        step.intensity = 1.5f;
        break;
      }
    }
  if (step.target.empty()) return Result<bool>::failure(cat(c.name, ": the scene has no light or emitter"));
  out.description = cat("'", step.target,
                        "' becomes 1.5 times as strong: every lit pixel changes; the figure 60 "
                        "frames later.");
  auto e = stepEdits(step, 0, scene, kNoNode);
  if (!e) return Result<bool>::failure(e.error());
  if (auto r = b.frame(e->edits); !r) return r;
  b.rest(59);
  b.score();
  return true;
}

// Starts the plan over on `base`, a scene with the object `added` put in for the case, with
// that object selected, as when picked in the outliner.
Result<Object> startWithAdded(PlanBuilder& b, const Scene& base, const std::string& added, const std::string& caseName) {
  b = PlanBuilder(base, 64);
  const Object* object = objectNamed(base, added);
  if (!object) return Result<Object>::failure(cat(caseName, ": the added sphere is missing"));
  b.plan.selection = object->id;
  return *object;
}

Result<bool> planMirrorOnly(const Setup& c, PlanBuilder& b, StabilityResult& out) {
  // Any scene: a mirror half way to the camera's target, facing the camera, and a sphere behind
  // the camera on its axis: the sphere shows in the mirror and nowhere else.
  const Scene& scene = c.scene;
  const float d = std::max(length(scene.camera.target - scene.camera.position), 1e-3f);
  const Vec3 up = normalize(cross(c.right, c.forward));
  const float mirrorH = d * std::tan(scene.camera.verticalFov * 0.5f) * 0.4f;  // 40 % of the view's height
  Scene base = withHiddenSphere(scene, scene.camera.position - c.forward * (0.3f * d), 0.1f * d, "Hidden Sphere");
  Material mirror;
  mirror.type = MaterialType::Mirror;
  mirror.albedo = Vec3{0.9f};
  Mat4 facing;
  const Vec3 centre = scene.camera.position + c.forward * (0.5f * d);
  for (int i = 0; i < 3; ++i) {  // the quad's x, its normal (+y) and its z, to the view's axes
    facing.m[i][0] = c.right[i] * mirrorH * scene.aspect();
    facing.m[i][1] = -c.forward[i];
    facing.m[i][2] = up[i] * mirrorH;
    facing.m[i][3] = centre[i];
  }
  addMeshObject(base, "Stability Mirror", makeQuad(), mirror, facing);
  auto hidden = startWithAdded(b, base, "Hidden Sphere", c.name);
  if (!hidden) return Result<bool>::failure(hidden.error());
  out.description =
      "A mirror is put between the camera and its target and a sphere behind the camera; the sphere's "
      "material changes colour, seen only in the mirror; the figure 20 frames later.";
  Material m = *base.material(hidden->material);
  m.albedo = {0.8f, 0.1f, 0.6f};
  if (auto r = b.frame({SetMaterial{m}}); !r) return r;
  b.rest(19);
  b.score();
  return true;
}

Result<bool> planOffscreenShadow(const Setup& c, PlanBuilder& b, StabilityResult& out) {
  // This needs an object placed just so between the light and the floor: the built-in scene,
  // whatever was asked for.
  Scene base = makeDefaultScene();
  base.settings.width = c.W;
  base.settings.height = c.H;
  base = withHiddenSphere(base, {-0.2f, 2.3f, 0.9f}, 0.3f, "Shadow Caster");
  auto hidden = startWithAdded(b, base, "Shadow Caster", c.name);
  if (!hidden) return Result<bool>::failure(hidden.error());
  out.description =
      "A sphere above the frame, seen only by its shadow on the floor, moves sideways over 10 frames "
      "(built-in scene; it is the selection, as when picked in the outliner); the figure 10 frames "
      "later.";
  for (int f = 0; f < 10; ++f)
    if (auto r = b.frame({moved(*b.now.object(hidden->id), Vec3{0.04f, 0, 0})}); !r) return r;
  b.rest(10);
  b.score();
  return true;
}

Result<bool> planCase(const Setup& c, PlanBuilder& b, std::vector<Variant>& variants, StabilityResult& out) {
  const std::string& name = c.name;
  if (name == "ghosting") return planGhosting(c, b, variants, out);
  if (name == "burst") return planBurst(c, b, out);
  if (name == "off-screen" || name == "behind-camera" || name == "fill-screen") return planSubjectLeaves(c, b, out);
  if (name == "camera-mid-pass" || name == "resize-mid-pass") return planMidPass(c, b, out);
  if (name == "light-global") return planLightGlobal(c, b, out);
  if (name == "mirror-only") return planMirrorOnly(c, b, out);
  if (name == "offscreen-shadow") return planOffscreenShadow(c, b, out);
  return Result<bool>::failure(cat("unknown stability case '", name, "'"));
}

// The extreme case's settings, each played on its own rather than against the global method.
std::vector<Variant> extremeVariants(bool small) {
  MethodSettings spiral;
  spiral.kind = MethodKind::Spiral;
  std::vector<Variant> vs;
  MethodSettings t8 = spiral;
  t8.tileSize = 8;
  vs.push_back({small ? "spiral T=8 320x180" : "spiral T=8 3840x2160", t8, small ? 320 : 3840, small ? 180 : 2160});
  MethodSettings q1 = spiral, q2 = spiral, qHuge = spiral;
  q1.quality = 1;
  q2.quality = 2;
  qHuge.quality = 4096;  // a 16x16 tile needs 1 M samples: more than any frame of these sizes
  vs.push_back({"spiral Q=1", q1});
  vs.push_back({"spiral Q=2", q2});
  vs.push_back({"spiral Q=4096", qHuge});
  vs.push_back({"global 1x1", MethodSettings{MethodKind::Global}, 1, 1});
  vs.push_back({"spiral 1x1", spiral, 1, 1});
  MethodSettings ind;
  ind.kind = MethodKind::Indirection;
  ind.quality = 0;
  vs.push_back({"indirection Q=auto 1x1", ind, 1, 1});
  return vs;
}

// One extreme setting: an edit (the subject's move, else the camera's) and the frames after it;
// the figure is the share of frames whose budget was exactly W x H.
Result<StabilityFigure> runExtremeVariant(const Setup& c, const Variant& v) {
  StabilityFigure fig;
  fig.method = v.label;
  fig.threshold = 1.0;
  try {
    Scene s = c.scene;
    if (v.width > 0) s.settings.width = v.width, s.settings.height = v.height;
    PlanBuilder pb(s, 4);
    if (c.subject) {
      pb.plan.selection = c.subject->id;
      if (auto r = pb.frame({moved(*c.subject, c.scene.camera.up * (c.size * 0.1f))}); !r)
        return Result<StabilityFigure>::failure(r.error());
    } else {
      Camera cam = s.camera;
      cam.position = cam.position + c.right * 0.05f;
      if (auto r = pb.frame({SetCamera{cam}}); !r) return Result<StabilityFigure>::failure(r.error());
    }
    pb.rest(v.width >= 3840 ? 2 : 20);
    Targets none;
    int exact = 0, frames = 0;
    bool finite = true;
    const std::uint64_t budget = static_cast<std::uint64_t>(s.settings.width) * static_cast<std::uint64_t>(s.settings.height);
    std::set<int> served;
    auto run = runMethod(pb.plan, none, v.method, [&](const FrameRecord& rec, const FrameScore&) {
      ++frames;
      exact += rec.samples == budget;
      if (rec.image) finite = finite && allFinite(rec.image->shown());
      served.insert(rec.servedTiles.begin(), rec.servedTiles.end());
      return true;
    });
    if (!run) {
      fig.broken = run.error();
    } else {
      fig.value = frames ? static_cast<double>(exact) / frames : 0.0;
      fig.detail = cat(served.size(), " distinct tiles traced after the edit");
      if (!finite) fig.broken = "a pixel went NaN or infinite";
      if (served.empty()) fig.broken = "no tile was traced after the edit";
    }
  } catch (const std::exception& e) {
    fig.broken = e.what();
  }
  fig.pass = fig.broken.empty() && fig.value >= 1.0;
  return fig;
}

Result<bool> runExtreme(const Setup& c, bool small, const std::function<void(const std::string&)>& progress, StabilityResult& out) {
  out.description = small ? "Extreme settings: T=8 at 320x180, Q=1, Q=2, Q larger than a frame's whole budget, a 1x1 "
                            "image; each with an edit and 20 frames after it. The figure: frames whose budget was "
                            "exactly W x H, as a fraction (1 passes)."
                          : "Extreme settings: T=8 at 3840x2160, Q=1, Q=2, Q larger than a frame's whole budget, a "
                            "1x1 image; each with an edit and 20 frames after it (3 at 3840x2160). The figure: "
                            "frames whose budget was exactly W x H, as a fraction (1 passes).";
  out.figure = "frames with the exact budget (fraction)";
  for (const Variant& v : extremeVariants(small)) {
    if (progress) progress(v.label);
    auto fig = runExtremeVariant(c, v);
    if (!fig) return Result<bool>::failure(fig.error());
    out.figures.push_back(std::move(fig.value()));
  }
  return true;
}

// Tiles holding a changed pixel that no frame of the burst traced.
int starvedTiles(const Setup& c, const Targets& targets, const std::set<int>& servedDuringBurst, int cols, int rows, int tile) {
  int starved = 0;
  for (int ty = 0; ty < rows; ++ty)
    for (int tx = 0; tx < cols; ++tx) {
      bool changed = false;
      for (int y = ty * tile; y < std::min((ty + 1) * tile, c.H) && !changed; ++y)
        for (int x = tx * tile; x < std::min((tx + 1) * tile, c.W) && !changed; ++x)
          changed = targets.affected[static_cast<std::size_t>(y) * static_cast<std::size_t>(c.W) + static_cast<std::size_t>(x)];
      if (changed && !servedDuringBurst.count(ty * cols + tx)) ++starved;
    }
  return starved;
}

// One method's figure at the plan's last frame; the burst also counts the tiles it starved.
StabilityFigure scoreVariant(const Setup& c, const Plan& plan, const Targets& targets, const Variant& v) {
  const bool burst = c.name == "burst";
  StabilityFigure fig;
  fig.method = v.label;
  bool finite = true;
  std::set<int> servedDuringBurst;
  int cols = 0, rows = 0, tile = 0;
  try {
    auto run = runMethod(plan, targets, v.method, [&](const FrameRecord& rec, const FrameScore& s) {
      if (rec.image) finite = finite && allFinite(rec.image->shown());
      if (burst && s.frame <= 100) servedDuringBurst.insert(rec.servedTiles.begin(), rec.servedTiles.end());
      cols = rec.cols, rows = rec.rows, tile = rec.tileSize;
      return true;
    });
    if (!run) {
      fig.broken = run.error();
    } else {
      // The figure is the last scored frame's; the burst also scores the burst's last frame, for
      // the tiles it should have reached.
      const FrameScore& last = run->frames[plan.frames.size() - 1];
      fig.value = std::isnan(last.relRmseAffected) ? last.relRmse : last.relRmseAffected;
      if (!run->exactBudget) fig.broken = "a frame did not trace exactly W x H samples";
      if (!finite) fig.broken = "a pixel went NaN or infinite";
    }
  } catch (const std::exception& e) {
    fig.broken = e.what();
  }
  if (burst && fig.broken.empty() && tile > 0) {
    const int starved = starvedTiles(c, targets, servedDuringBurst, cols, rows, tile);
    fig.detail = cat(starved, " changed tiles never traced during the burst");
    if (starved > 0) fig.pass = false;
  }
  return fig;
}

}  // namespace

Result<StabilityResult> runStabilityCase(const std::string& name, const Scene& sceneIn, const StabilityOptions& o, References& refs,
                                         const std::function<void(const std::string&)>& progress) {
  using R = Result<StabilityResult>;
  StabilityResult out;
  out.name = name;
  out.figure = "relative RMSE (affected region, 4x4 blocks) at the case's frame";
  auto variants = methodVariants(o.methods);
  if (!variants) return R::failure(variants.error());
  const Setup c(name, sceneIn, o);
  if (name == "extreme") {
    if (auto r = runExtreme(c, o.small, progress, out); !r) return R::failure(r.error());
    return out;
  }
  PlanBuilder b(c.scene, 64);
  if (auto r = planCase(c, b, variants.value(), out); !r) return R::failure(r.error());

  if (progress) progress(name + " references");
  auto targets = prepareTargets(b.plan, refs);
  if (!targets) return R::failure(targets.error());
  out.affected = targets->affectedCount;
  double yardstick = NAN;
  for (const Variant& v : variants.value()) {
    if (progress) progress(cat(name, " ", v.label));
    StabilityFigure fig = scoreVariant(c, b.plan, targets.value(), v);
    if (v.label == "global") yardstick = fig.value;
    fig.threshold = yardstick * kTolerance;
    fig.pass = fig.broken.empty() && fig.value <= fig.threshold && (name != "burst" || fig.detail.rfind("0 ", 0) == 0);
    out.figures.push_back(fig);
  }
  return out;
}

}  // namespace retile::eval
