#include "retile/scenario.h"

#include <charconv>
#include <cmath>

#include "core/files.h"
#include "core/json.h"
#include "retile/log.h"

namespace retile {

int Scenario::totalFrames() const {
  int n = 0;
  for (const auto& s : steps)
    if (s.kind != ScenarioStep::Kind::Select && s.kind != ScenarioStep::Kind::Focus) n += s.frames;
  return n;
}

namespace {

using json::Value;

struct StepReader {
  const Value& v;
  std::string where;
  std::string* error;

  bool vec3(const char* key, std::optional<Vec3>* out) {
    const Value* x = v.find(key);
    if (!x) return true;
    Vec3 r;
    if (!json::toVec3(*x, &r) || !isFinite(r)) return fail(cat(key, " must be a number or three numbers"));
    *out = r;
    return true;
  }
  bool number(const char* key, std::optional<float>* out) {
    const Value* x = v.find(key);
    if (!x) return true;
    if (!x->isNumber() || !std::isfinite(x->asNumber())) return fail(cat(key, " must be a number"));
    *out = static_cast<float>(x->asNumber());
    return true;
  }
  bool frames(int* out, int fallback) {
    *out = fallback;
    const Value* x = v.find("frames");
    if (!x) return true;
    if (!x->isNumber() || x->asNumber() < 1 || x->asNumber() > 1e6) return fail("frames must be 1..1000000");
    *out = static_cast<int>(x->asNumber());
    return true;
  }
  bool fail(const std::string& what) {
    *error = cat(where, ": ", what);
    return false;
  }
};

}  // namespace

Result<Scenario> parseScenario(const std::string& text, const std::string& name) {
  using R = Result<Scenario>;
  auto root = json::parse(text);
  if (!root) return R::failure(cat(name, ": ", root.error()));
  if (!root->isObject()) return R::failure(cat(name, ": a scenario is a JSON object with \"steps\""));
  Scenario sc;
  sc.name = name;
  if (const Value* c = root->find("converge")) {
    if (!c->isNumber() || c->asNumber() < 0 || c->asNumber() > 1 << 20) return R::failure(cat(name, ": converge must be 0..1048576"));
    sc.converge = static_cast<int>(c->asNumber());
  }
  const Value* steps = root->find("steps");
  if (!steps || !steps->isArray()) return R::failure(cat(name, ": \"steps\" must be an array"));
  std::string error;
  for (std::size_t i = 0; i < steps->asArray().size(); ++i) {
    const Value& v = steps->asArray()[i];
    StepReader r{v, cat(name, ": steps[", i, "]"), &error};
    if (!v.isObject()) return R::failure(cat(r.where, ": a step is an object"));
    ScenarioStep s;
    auto str = [&](const char* key) -> std::string {
      const Value* x = v.find(key);
      return x && x->isString() ? x->asString() : std::string();
    };
    bool ok = true;
    if (const Value* x = v.find("select")) {
      s.kind = ScenarioStep::Kind::Select;
      if (x->isString()) s.candidates.push_back(x->asString());
      if (x->isArray())
        for (const Value& n : x->asArray())
          if (n.isString()) s.candidates.push_back(n.asString());
      if (s.candidates.empty()) return R::failure(cat(r.where, ": select names an object, or lists names to try"));
      s.target = s.candidates.front();
    } else if (const Value* m = v.find("move"); m && !v.find("light")) {
      s.kind = ScenarioStep::Kind::Move;
      if (!json::toVec3(*m, &s.vector) || !isFinite(s.vector)) return R::failure(cat(r.where, ": move must be three numbers"));
      s.target = str("object");
      ok = r.frames(&s.frames, 1);
    } else if (const Value* w = v.find("wait")) {
      s.kind = ScenarioStep::Kind::Wait;
      if (!w->isNumber() || w->asNumber() < 1 || w->asNumber() > 1e6) return R::failure(cat(r.where, ": wait must be 1..1000000 frames"));
      s.frames = static_cast<int>(w->asNumber());
    } else if (v.find("material")) {
      s.kind = ScenarioStep::Kind::Material;
      s.target = str("material");
      const Value* set = v.find("set");
      if (!set || !set->isObject()) return R::failure(cat(r.where, ": a material step needs \"set\": {...}"));
      StepReader sr{*set, r.where + ".set", &error};
      ok = sr.number("roughness", &s.roughness) && sr.number("ior", &s.ior) && sr.vec3("albedo", &s.albedo) &&
           sr.vec3("emission", &s.emission) && r.frames(&s.frames, 1);
    } else if (v.find("light")) {
      s.kind = ScenarioStep::Kind::Light;
      s.target = str("light");
      std::optional<Vec3> move;
      ok = r.vec3("move", &move) && r.vec3("color", &s.color) && r.number("intensity", &s.intensity) && r.vec3("position", &s.position) &&
           r.frames(&s.frames, 1);
      if (move) s.vector = *move;
    } else if (const Value* c = v.find("camera")) {
      s.kind = ScenarioStep::Kind::Camera;
      StepReader cr{*c, r.where + ".camera", &error};
      ok = cr.vec3("position", &s.cameraPosition) && cr.vec3("target", &s.cameraTarget) && r.frames(&s.frames, 1);
    } else if (const Value* f = v.find("focus")) {
      s.kind = ScenarioStep::Kind::Focus;
      if (!f->isArray() || f->asArray().size() > 3) return R::failure(cat(r.where, ": focus is a list of up to 3 points"));
      for (const Value& p : f->asArray()) {
        FocusPoint fp;
        const Value* px = p.find("pixel");
        const Value* uv = p.find("uv");
        if (!(px && json::toVec2(*px, &fp.pixel)) && !(uv && json::toVec2(*uv, &fp.pixel)))
          return R::failure(cat(r.where, ": a focus point needs \"pixel\": [x, y] or \"uv\": [u, v]"));
        s.focusIsUv.push_back(!px);
        if (const Value* fo = p.find("follows"); fo && fo->isBool()) fp.follows = fo->asBool();
        s.focus.push_back(fp);
      }
    } else {
      return R::failure(cat(r.where, ": unknown step (expected select, move, wait, material, light, camera or focus)"));
    }
    if (!ok) return R::failure(error);
    sc.steps.push_back(std::move(s));
  }
  return sc;
}

Result<Scenario> loadScenario(const std::filesystem::path& file) {
  auto text = readFile(file, 1 << 24);
  if (!text) return Result<Scenario>::failure(text.error());
  return parseScenario(text.value(), file.string());
}

namespace {

// By name, or "#ID" for objects without a unique name (what the evaluation's built-in scenarios
// use on any scene). A name wins over an id.
const Object* objectByName(const Scene& s, const std::string& name) {
  for (const Object& o : s.objects)
    if (o.name == name) return &o;
  if (name.size() > 1 && name[0] == '#') {
    NodeId id = 0;
    auto r = std::from_chars(name.data() + 1, name.data() + name.size(), id);
    if (r.ec == std::errc() && r.ptr == name.data() + name.size()) return s.object(id);
  }
  return nullptr;
}

}  // namespace

Result<StepEdits> stepEdits(const ScenarioStep& step, int frameInStep, const Scene& scene, NodeId selection) {
  using R = Result<StepEdits>;
  StepEdits out;
  using K = ScenarioStep::Kind;
  switch (step.kind) {
    case K::Select: {
      std::string tried;
      for (const auto& name : step.candidates.empty() ? std::vector<std::string>{step.target} : step.candidates) {
        if (const Object* o = objectByName(scene, name)) {
          out.select = o->id;
          return out;
        }
        tried += (tried.empty() ? "'" : ", '") + name + "'";
      }
      return R::failure(cat("select: no object named ", tried));
    }
    case K::Focus:
      out.focus = step.focus;
      for (std::size_t i = 0; i < out.focus->size() && i < step.focusIsUv.size(); ++i)
        if (step.focusIsUv[i])
          (*out.focus)[i].pixel = {(*out.focus)[i].pixel.x * static_cast<float>(scene.settings.width),
                                   (*out.focus)[i].pixel.y * static_cast<float>(scene.settings.height)};
      return out;
    case K::Wait: return out;
    case K::Move: {
      const Object* o = step.target.empty() ? scene.object(selection) : objectByName(scene, step.target);
      if (!o)
        return R::failure(step.target.empty() ? std::string("move: nothing is selected")
                                              : cat("move: no object named '", step.target, "'"));
      Object moved = *o;
      moved.transform = Mat4::translate(step.vector) * o->transform;
      out.edits.push_back(SetObject{moved});
      return out;
    }
    case K::Material: {
      if (frameInStep > 0) return out;
      const Material* m = nullptr;
      for (const Material& x : scene.materials)
        if (x.name == step.target) m = &x;
      if (!m)
        if (const Object* o = objectByName(scene, step.target)) m = scene.material(o->material);
      if (!m) return R::failure(cat("material: no material or object named '", step.target, "'"));
      Material e = *m;
      if (step.roughness) e.roughness = *step.roughness;
      if (step.ior) e.ior = *step.ior;
      if (step.albedo) e.albedo = *step.albedo;
      if (step.emission) e.emission = *step.emission;
      out.edits.push_back(SetMaterial{e});
      return out;
    }
    case K::Light: {
      if (frameInStep > 0 && step.vector == Vec3{0.0f}) return out;
      for (const Light& l : scene.lights)
        if (l.name == step.target) {
          Light e = l;
          if (frameInStep == 0) {
            if (step.color) e.color = *step.color;
            if (step.intensity) e.intensity = *step.intensity;
            if (step.position) e.position = *step.position;
          }
          e.position = e.position + step.vector;
          out.edits.push_back(SetLight{e});
          return out;
        }
      const Object* o = objectByName(scene, step.target);
      const Material* m = o ? scene.material(o->material) : nullptr;
      if (!o || !m || !m->emissive()) return R::failure(cat("light: no light or emissive object named '", step.target, "'"));
      if (frameInStep == 0 && (step.color || step.intensity)) {
        Material e = *m;
        float scale = step.intensity.value_or(1.0f);
        Vec3 base = step.color.value_or(m->emission);
        e.emission = base * scale;
        out.edits.push_back(SetMaterial{e});
      }
      if (!(step.vector == Vec3{0.0f}) || (frameInStep == 0 && step.position)) {
        Object moved = *o;
        Mat4 t = moved.transform;
        if (frameInStep == 0 && step.position) {
          Vec3 now = t.transformPoint(Vec3{0.0f});
          t = Mat4::translate(*step.position - now) * t;
        }
        moved.transform = Mat4::translate(step.vector) * t;
        out.edits.push_back(SetObject{moved});
      }
      return out;
    }
    case K::Camera: {
      if (frameInStep > 0) return out;
      Camera c = scene.camera;
      if (step.cameraPosition) c.position = *step.cameraPosition;
      if (step.cameraTarget) c.target = *step.cameraTarget;
      out.edits.push_back(SetCamera{c});
      return out;
    }
  }
  return out;
}

double relativeRmse(const std::vector<float>& a, const std::vector<float>& ref, int width, int height, int block,
                    const std::uint8_t* mask) {
  block = std::max(block, 1);
  if (a.size() != ref.size() || a.size() < static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3) return NAN;
  double se = 0, sum = 0;
  std::size_t n = 0;
  for (int by = 0; by + block <= height; by += block)
    for (int bx = 0; bx + block <= width; bx += block) {
      double la = 0, lr = 0;
      int count = 0;
      for (int y = by; y < by + block; ++y)
        for (int x = bx; x < bx + block; ++x) {
          std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
          if (mask && !mask[p]) continue;
          std::size_t i = p * 3;
          la += 0.2126 * a[i] + 0.7152 * a[i + 1] + 0.0722 * a[i + 2];
          lr += 0.2126 * ref[i] + 0.7152 * ref[i + 1] + 0.0722 * ref[i + 2];
          ++count;
        }
      if (count == 0) continue;
      la /= count;
      lr /= count;
      se += (la - lr) * (la - lr);
      sum += lr;
      ++n;
    }
  if (n == 0 || sum <= 0) return NAN;
  return std::sqrt(se / static_cast<double>(n)) / (sum / static_cast<double>(n));
}

}  // namespace retile
