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

}  // namespace

Result<StabilityResult> runStabilityCase(const std::string& name, const Scene& sceneIn, const StabilityOptions& o, References& refs,
                                         const std::function<void(const std::string&)>& progress) {
  using R = Result<StabilityResult>;
  StabilityResult out;
  out.name = name;
  out.figure = "relative RMSE (affected region, 4x4 blocks) at the case's frame";
  Scene scene = sceneIn;
  scene.settings.width = o.width;
  scene.settings.height = o.height;
  const int W = o.width, H = o.height;

  std::vector<Variant> variants;
  for (const auto& label : o.methods) {
    auto m = parseMethodLabel(label);
    if (!m) return R::failure(m.error());
    variants.push_back({label, m.value()});
  }
  // The global method first: it is every other method's yardstick.
  std::stable_partition(variants.begin(), variants.end(), [](const Variant& v) { return v.label == "global"; });
  if (variants.empty() || variants[0].label != "global") variants.insert(variants.begin(), {"global", MethodSettings{MethodKind::Global}});

  const Object* subject = scene.object(pickSubject(scene));
  const Vec3 forward = normalize(scene.camera.target - scene.camera.position);
  const Vec3 right = normalize(cross(forward, scene.camera.up));
  const float size = subject ? length(objectBounds(scene, *subject).extent()) : 0.0f;
  auto needSubject = [&]() -> Result<bool> {
    if (!subject) return Result<bool>::failure(cat(name, ": the scene has no visible object covering 0.2 % of the image or more"));
    return true;
  };

  PlanBuilder b(scene, 64);
  // The frame whose figure counts is the last one unless a case says otherwise.
  if (name == "ghosting") {
    if (auto r = needSubject(); !r) return R::failure(r.error());
    out.description = cat("A drag at Q=512 of '", subject->name, "' by its own size over 10 frames, larger than the ", W * H / 512,
                          " pixels refreshed per frame; the figure 20 frames after the drag: what is left "
                          "of it at its old positions.");
    for (auto& v : variants) v.method.quality = 512;
    b.plan.selection = subject->id;
    for (int f = 0; f < 10; ++f) {
      if (auto r = b.frame({moved(*b.now.object(subject->id), right * (size * 0.1f))}); !r) return R::failure(r.error());
    }
    b.rest(20);
    b.score();
  } else if (name == "burst") {
    if (auto r = needSubject(); !r) return R::failure(r.error());
    out.description = cat("An edit every frame for 100 frames ('", subject->name,
                          "' drifts sideways), then 100 at rest; the figure at the end, and the tiles the edits "
                          "changed that were never traced during the burst (starved).");
    b.plan.selection = subject->id;
    for (int f = 0; f < 100; ++f) {
      if (auto r = b.frame({moved(*b.now.object(subject->id), right * (size * 0.004f))}); !r) return R::failure(r.error());
    }
    b.score();  // frame 100: the state the burst ends in, for the affected region
    b.rest(100);
    b.score();
  } else if (name == "off-screen" || name == "behind-camera" || name == "fill-screen") {
    if (auto r = needSubject(); !r) return R::failure(r.error());
    b.plan.selection = subject->id;
    const Bounds3 box = objectBounds(scene, *subject);
    const float distance = length(box.center() - scene.camera.position);
    if (name == "off-screen") {
      // Past the frame's edge: the half-width of the view at the object's distance, twice over.
      const float halfWidth = distance * std::tan(scene.camera.verticalFov * 0.5f) * scene.aspect();
      out.description = cat("'", subject->name, "' leaves the frame sideways over 5 frames; the figure 40 frames later.");
      for (int f = 0; f < 5; ++f)
        if (auto r = b.frame({moved(*b.now.object(subject->id), right * ((2.0f * halfWidth + size) / 5.0f))}); !r)
          return R::failure(r.error());
    } else if (name == "behind-camera") {
      out.description = cat("'", subject->name, "' moves behind the camera over 5 frames; the figure 40 frames later.");
      const Vec3 to = scene.camera.position - forward * (size + 1.0f);
      for (int f = 0; f < 5; ++f)
        if (auto r = b.frame({moved(*b.now.object(subject->id), (to - box.center()) * 0.2f)}); !r) return R::failure(r.error());
    } else {
      out.description = cat("'", subject->name,
                            "' grows about its centre until it fills the frame; the figure 40 "
                            "frames later.");
      Object grown = *subject;
      const float k = std::max(2.0f, 2.0f * distance / std::max(size, 1e-6f));
      grown.transform = Mat4::translate(box.center()) * Mat4::scale(Vec3{k}) * Mat4::translate(box.center() * -1.0f) * subject->transform;
      if (auto r = b.frame({SetObject{grown}}); !r) return R::failure(r.error());
    }
    b.rest(40);
    b.score();
  } else if (name == "camera-mid-pass" || name == "resize-mid-pass") {
    if (auto r = needSubject(); !r) return R::failure(r.error());
    b.plan.selection = subject->id;
    if (auto r = b.frame({moved(*subject, scene.camera.up * (size * 0.1f))}); !r) return R::failure(r.error());
    b.rest(2);
    if (name == "camera-mid-pass") {
      out.description = cat("'", subject->name,
                            "' moves, and 3 frames into the pass the camera orbits 3 degrees; the "
                            "figure 40 frames later.");
      Camera c = scene.camera;
      c.position = c.target + Mat4::rotateY(radians(3.0f)).transformVector(c.position - c.target);
      if (auto r = b.frame({SetCamera{c}}); !r) return R::failure(r.error());
    } else {
      const int w2 = W * 3 / 4 + 1, h2 = H * 3 / 4 + 1;
      out.description = cat("'", subject->name, "' moves, and 3 frames into the pass the viewport is resized to ", w2, "x", h2,
                            " (odd sizes); the figure 40 frames later, whole image.");
      b.resize(w2, h2);
    }
    b.rest(40);
    b.score();
  } else if (name == "light-global") {
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
    if (step.target.empty()) return R::failure(cat(name, ": the scene has no light or emitter"));
    out.description = cat("'", step.target,
                          "' becomes 1.5 times as strong: every lit pixel changes; the figure 60 "
                          "frames later.");
    auto e = stepEdits(step, 0, scene, kNoNode);
    if (!e) return R::failure(e.error());
    if (auto r = b.frame(e->edits); !r) return R::failure(r.error());
    b.rest(59);
    b.score();
  } else if (name == "mirror-only") {
    // Any scene: a mirror half way to the camera's target, facing the camera, and a sphere behind
    // the camera on its axis: the sphere shows in the mirror and nowhere else.
    const float d = std::max(length(scene.camera.target - scene.camera.position), 1e-3f);
    const Vec3 up = normalize(cross(right, forward));
    const float mirrorH = d * std::tan(scene.camera.verticalFov * 0.5f) * 0.4f;  // 40 % of the view's height
    Scene base = withHiddenSphere(scene, scene.camera.position - forward * (0.3f * d), 0.1f * d, "Hidden Sphere");
    Material mirror;
    mirror.type = MaterialType::Mirror;
    mirror.albedo = Vec3{0.9f};
    Mat4 facing;
    const Vec3 centre = scene.camera.position + forward * (0.5f * d);
    for (int i = 0; i < 3; ++i) {  // the quad's x, its normal (+y) and its z, to the view's axes
      facing.m[i][0] = right[i] * mirrorH * scene.aspect();
      facing.m[i][1] = -forward[i];
      facing.m[i][2] = up[i] * mirrorH;
      facing.m[i][3] = centre[i];
    }
    addMeshObject(base, "Stability Mirror", makeQuad(), mirror, facing);
    b = PlanBuilder(base, 64);
    const Object* hidden = objectNamed(base, "Hidden Sphere");
    if (!hidden) return R::failure(cat(name, ": the added sphere is missing"));
    b.plan.selection = hidden->id;
    out.description =
        "A mirror is put between the camera and its target and a sphere behind the camera; the sphere's "
        "material changes colour, seen only in the mirror; the figure 20 frames later.";
    Material m = *base.material(hidden->material);
    m.albedo = {0.8f, 0.1f, 0.6f};
    if (auto r = b.frame({SetMaterial{m}}); !r) return R::failure(r.error());
    b.rest(19);
    b.score();
  } else if (name == "offscreen-shadow") {
    // This needs an object placed just so between the light and the floor: the built-in scene,
    // whatever was asked for.
    Scene base = makeDefaultScene();
    base.settings.width = W;
    base.settings.height = H;
    base = withHiddenSphere(base, {-0.2f, 2.3f, 0.9f}, 0.3f, "Shadow Caster");
    b = PlanBuilder(base, 64);
    const Object* hidden = objectNamed(base, "Shadow Caster");
    if (!hidden) return R::failure(cat(name, ": the added sphere is missing"));
    b.plan.selection = hidden->id;
    out.description =
        "A sphere above the frame, seen only by its shadow on the floor, moves sideways over 10 frames "
        "(built-in scene; it is the selection, as when picked in the outliner); the figure 10 frames "
        "later.";
    for (int f = 0; f < 10; ++f)
      if (auto r = b.frame({moved(*b.now.object(hidden->id), Vec3{0.04f, 0, 0})}); !r) return R::failure(r.error());
    b.rest(10);
    b.score();
  } else if (name == "extreme") {
    out.description = o.small ? "Extreme settings: T=8 at 320x180, Q=1, Q=2, Q larger than a frame's whole budget, a 1x1 "
                                "image; each with an edit and 20 frames after it. The figure: frames whose budget was "
                                "exactly W x H, as a fraction (1 passes)."
                              : "Extreme settings: T=8 at 3840x2160, Q=1, Q=2, Q larger than a frame's whole budget, a "
                                "1x1 image; each with an edit and 20 frames after it (3 at 3840x2160). The figure: "
                                "frames whose budget was exactly W x H, as a fraction (1 passes).";
    out.figure = "frames with the exact budget (fraction)";
    MethodSettings spiral;
    spiral.kind = MethodKind::Spiral;
    std::vector<Variant> vs;
    MethodSettings t8 = spiral;
    t8.tileSize = 8;
    vs.push_back({o.small ? "spiral T=8 320x180" : "spiral T=8 3840x2160", t8, o.small ? 320 : 3840, o.small ? 180 : 2160});
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
    for (const Variant& v : vs) {
      if (progress) progress(v.label);
      StabilityFigure fig;
      fig.method = v.label;
      fig.threshold = 1.0;
      try {
        Scene s = scene;
        if (v.width > 0) s.settings.width = v.width, s.settings.height = v.height;
        PlanBuilder pb(s, 4);
        if (subject) {
          pb.plan.selection = subject->id;
          if (auto r = pb.frame({moved(*subject, scene.camera.up * (size * 0.1f))}); !r) return R::failure(r.error());
        } else {
          Camera c = s.camera;
          c.position = c.position + right * 0.05f;
          if (auto r = pb.frame({SetCamera{c}}); !r) return R::failure(r.error());
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
      out.figures.push_back(fig);
    }
    return out;
  } else {
    return R::failure(cat("unknown stability case '", name, "'"));
  }

  if (progress) progress(name + " references");
  auto targets = prepareTargets(b.plan, refs);
  if (!targets) return R::failure(targets.error());
  out.affected = targets->affectedCount;
  // The figure is the last scored frame's; the burst also scores the burst's last frame, for the
  // tiles it should have reached.
  const int figureFrame = static_cast<int>(b.plan.frames.size());
  double yardstick = NAN;
  for (const Variant& v : variants) {
    if (progress) progress(cat(name, " ", v.label));
    StabilityFigure fig;
    fig.method = v.label;
    bool finite = true;
    std::set<int> servedDuringBurst;
    int cols = 0, rows = 0, tile = 0;
    try {
      auto run = runMethod(b.plan, targets.value(), v.method, [&](const FrameRecord& rec, const FrameScore& s) {
        if (rec.image) finite = finite && allFinite(rec.image->shown());
        if (name == "burst" && s.frame <= 100) servedDuringBurst.insert(rec.servedTiles.begin(), rec.servedTiles.end());
        cols = rec.cols, rows = rec.rows, tile = rec.tileSize;
        return true;
      });
      if (!run) {
        fig.broken = run.error();
      } else {
        const FrameScore& last = run->frames[static_cast<std::size_t>(figureFrame - 1)];
        fig.value = std::isnan(last.relRmseAffected) ? last.relRmse : last.relRmseAffected;
        if (!run->exactBudget) fig.broken = "a frame did not trace exactly W x H samples";
        if (!finite) fig.broken = "a pixel went NaN or infinite";
      }
    } catch (const std::exception& e) {
      fig.broken = e.what();
    }
    if (name == "burst" && fig.broken.empty() && tile > 0) {
      // Tiles holding a changed pixel that no frame of the burst traced.
      int starved = 0;
      for (int ty = 0; ty < rows; ++ty)
        for (int tx = 0; tx < cols; ++tx) {
          bool changed = false;
          for (int y = ty * tile; y < std::min((ty + 1) * tile, H) && !changed; ++y)
            for (int x = tx * tile; x < std::min((tx + 1) * tile, W) && !changed; ++x)
              changed = targets->affected[static_cast<std::size_t>(y) * static_cast<std::size_t>(W) + static_cast<std::size_t>(x)];
          if (changed && !servedDuringBurst.count(ty * cols + tx)) ++starved;
        }
      fig.detail = cat(starved, " changed tiles never traced during the burst");
      if (starved > 0) fig.pass = false;
    }
    if (v.label == "global") yardstick = fig.value;
    fig.threshold = yardstick * kTolerance;
    fig.pass = fig.broken.empty() && fig.value <= fig.threshold && (name != "burst" || fig.detail.rfind("0 ", 0) == 0);
    out.figures.push_back(fig);
  }
  return out;
}

}  // namespace retile::eval
