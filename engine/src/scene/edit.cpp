#include "retile/edit.h"

#include <algorithm>
#include <cmath>

#include "retile/log.h"

namespace retile {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

using Applied = Result<std::uint32_t>;

Applied fail(const std::string& message) { return Applied::failure(message); }

bool finite(float v) { return std::isfinite(v); }

// A medium's fields (a material's interior, the world's): empty when they are in range.
std::string checkMedium(Vec3 absorption, Vec3 scattering, float anisotropy) {
  if (minComponent(absorption) < 0 || minComponent(scattering) < 0 || maxComponent(absorption) > kMaxExtinction ||
      maxComponent(scattering) > kMaxExtinction || !(std::abs(anisotropy) <= 0.99f))
    return cat("a medium's absorption and scattering must be within 0..", kMaxExtinction, ", its anisotropy within -0.99..0.99");
  return {};
}

std::string checkMaterial(const Scene& s, const Material& m) {
  for (const MaterialColor& f : kMaterialColors)
    if (!f.inRange(m.*f.field)) return cat("material '", m.name, "': its ", f.key, " must be finite and within 0..", f.hi);
  for (const MaterialScalar& f : kMaterialScalars) {
    const float v = m.*f.field;
    if (!finite(v)) return cat("material '", m.name, "': its ", f.key, " is not a finite number");
    if (v < f.lo || v > f.hi)
      return cat("material '", m.name, "': its ", f.key, " must be within ", f.lo, "..", f.hi, *f.unit ? " " : "", f.unit);
  }
  if (m.blendWith != kNoNode && (m.blendWith == m.id || !s.material(m.blendWith)))
    return cat("material '", m.name, "': it cannot blend with material ", m.blendWith);
  for (NodeId t : m.textures())
    if (t != kNoNode && !s.texture(t)) return cat("material '", m.name, "': texture ", t, " does not exist");
  return {};
}

std::string checkObject(const Scene& s, const Object& o) {
  if (!o.transform.isFinite()) return cat("object '", o.name, "': transform is not finite");
  if (o.mesh != kNoNode && !s.mesh(o.mesh)) return cat("object '", o.name, "': mesh ", o.mesh, " does not exist");
  if (o.material != kNoNode && !s.material(o.material)) return cat("object '", o.name, "': material ", o.material, " does not exist");
  return {};
}

std::string checkLight(const Light& l) {
  if (!isFinite(l.color) || !isFinite(l.position) || !isFinite(l.direction) || !finite(l.intensity) || !finite(l.spotAngle) ||
      !finite(l.spotBlend) || !finite(l.angularRadius))
    return cat("light '", l.name, "': a parameter is not a finite number");
  // radians(90) in float may round a hair past pi / 2.
  if (l.angularRadius < 0 || l.angularRadius > kPi / 2 + 1e-6f)
    return cat("light '", l.name, "': the angular radius must be between 0 and 90 degrees");
  return {};
}

std::string checkCamera(const Camera& c) {
  if (!isFinite(c.position) || !isFinite(c.target) || !isFinite(c.up) || !finite(c.verticalFov) || !finite(c.apertureRadius) ||
      !finite(c.focusDistance))
    return "camera: a parameter is not a finite number";
  if (c.verticalFov <= 0 || c.verticalFov >= kPi) return "camera: field of view must be between 0 and 180 degrees";
  if (c.apertureRadius < 0) return "camera: the aperture radius must not be negative";
  if (!(c.focusDistance > 0)) return "camera: the focus distance must be positive";
  if (length(c.target - c.position) == 0) return "camera: position and target coincide";
  return {};
}

std::string checkSettings(const RenderSettings& r) {
  if (r.width < 1 || r.height < 1 || r.width > kMaxImageSide || r.height > kMaxImageSide)
    return cat("render settings: size ", r.width, "x", r.height, " is outside 1..", kMaxImageSide);
  if (r.maxBounces < 0 || r.maxBounces > 1024) return "render settings: max bounces must be within 0..1024";
  if (r.minBounces < 0 || r.minBounces > 1024) return "render settings: min bounces must be within 0..1024";
  if (r.samplesPerPixel < 1) return "render settings: samples per pixel must be at least 1";
  return {};
}

template <class T>
bool idTaken(const Scene& s, NodeId id) {
  return s.mesh(id) || s.material(id) || s.object(id) || s.light(id) || s.texture(id);
}

template <class Node>
Applied replaceNode(std::vector<Node>& nodes, const Node& value, const char* kind, std::uint32_t flags) {
  for (Node& n : nodes)
    if (n.id == value.id) {
      n = value;
      return flags;
    }
  return fail(cat(kind, " ", value.id, " does not exist"));
}

template <class Node>
Applied addNode(Scene& s, std::vector<Node>& nodes, const Node& value, const char* kind, std::uint32_t flags) {
  if (value.id == kNoNode) return fail(cat("new ", kind, " has no id"));
  if (idTaken<Node>(s, value.id)) return fail(cat("new ", kind, ": id ", value.id, " is taken"));
  nodes.push_back(value);
  s.reserveIds(value.id + 1);
  return flags;
}

}  // namespace

NodeId editTarget(const Edit& edit) {
  return std::visit(Overloaded{
                        [](const SetMaterial& e) { return e.material.id; },
                        [](const SetObject& e) { return e.object.id; },
                        [](const SetLight& e) { return e.light.id; },
                        [](const SetTexture& e) { return e.texture.id; },
                        [](const SetCamera&) { return kNoNode; },
                        [](const SetEnvironment&) { return kNoNode; },
                        [](const SetRenderSettings&) { return kNoNode; },
                        [](const AddMesh& e) { return e.mesh.id; },
                        [](const AddMaterial& e) { return e.material.id; },
                        [](const AddObject& e) { return e.object.id; },
                        [](const AddLight& e) { return e.light.id; },
                        [](const AddTexture& e) { return e.texture.id; },
                        [](const RemoveNode& e) { return e.id; },
                    },
                    edit);
}

std::uint64_t editCoalesceKey(const Edit& edit) { return (static_cast<std::uint64_t>(edit.index()) << 56) ^ editTarget(edit); }

const char* editName(const Edit& edit) {
  static const char* const names[] = {"set material",    "set object",          "set light",  "set texture",  "set camera",
                                      "set environment", "set render settings", "add mesh",   "add material", "add object",
                                      "add light",       "add texture",         "remove node"};
  return names[edit.index()];
}

namespace {

// What the render reads of a scene: the materials of shown objects (through their blends), their
// textures and meshes, and the sky's map.
struct InUse {
  std::vector<NodeId> materials, textures, meshes;
  bool has(const std::vector<NodeId>& v, NodeId id) const { return std::find(v.begin(), v.end(), id) != v.end(); }
};

InUse inUse(const Scene& s) {
  InUse u;
  for (const Object& o : s.objects) {
    if (!o.visible) continue;
    u.meshes.push_back(o.mesh);
    // A blend's partners, each once (a cycle would be refused by the importers, but stop anyway).
    for (NodeId m = o.material; m != kNoNode && !u.has(u.materials, m);) {
      u.materials.push_back(m);
      const Material* mat = s.material(m);
      m = mat ? mat->blendWith : kNoNode;
    }
  }
  for (NodeId m : u.materials)
    if (const Material* mat = s.material(m))
      for (NodeId t : mat->textures())
        if (t != kNoNode) u.textures.push_back(t);
  if (s.environment.map != kNoNode) u.textures.push_back(s.environment.map);
  return u;
}

// Equal but for the name.
template <class Node>
bool sameButName(Node a, const Node& b) {
  a.name = b.name;
  return a == b;
}

}  // namespace

bool changesImage(const Scene& s, const Edit& edit) {
  const InUse u = inUse(s);
  return std::visit(Overloaded{
                        [&](const SetMaterial& e) {
                          const Material* old = s.material(e.material.id);
                          return !old || (u.has(u.materials, old->id) && !sameButName(*old, e.material));
                        },
                        [&](const SetObject& e) {
                          const Object* old = s.object(e.object.id);
                          return !old || ((old->visible || e.object.visible) && !sameButName(*old, e.object));
                        },
                        [&](const SetLight& e) {
                          const Light* old = s.light(e.light.id);
                          return !old || ((old->visible || e.light.visible) && !sameButName(*old, e.light));
                        },
                        [&](const SetTexture& e) {
                          const Texture* old = s.texture(e.texture.id);
                          return !old || (u.has(u.textures, old->id) && !sameButName(*old, e.texture));
                        },
                        [&](const AddMesh&) { return false; },
                        [&](const AddMaterial&) { return false; },
                        [&](const AddTexture&) { return false; },
                        [&](const AddObject& e) { return e.object.visible; },
                        [&](const AddLight& e) { return e.light.visible; },
                        [&](const RemoveNode& e) {
                          if (const Object* o = s.object(e.id)) return o->visible;
                          if (const Light* l = s.light(e.id)) return l->visible;
                          if (s.material(e.id)) return u.has(u.materials, e.id);
                          if (s.texture(e.id)) return u.has(u.textures, e.id);
                          if (s.mesh(e.id)) return u.has(u.meshes, e.id);
                          return true;
                        },
                        [&](const auto&) { return true; },
                    },
                    edit);
}

Result<std::uint32_t> applyEdit(Scene& s, const Edit& edit) {
  return std::visit(Overloaded{
                        [&](const SetMaterial& e) -> Applied {
                          if (auto why = checkMaterial(s, e.material); !why.empty()) return fail(why);
                          const Material* old = s.material(e.material.id);
                          if (!old) return fail(cat("material ", e.material.id, " does not exist"));
                          // Emission decides which triangles are lights.
                          std::uint32_t flags = kUpdateMaterials;
                          if (old->radiance() != e.material.radiance()) flags |= kUpdateLights;
                          return replaceNode(s.materials, e.material, "material", flags);
                        },
                        [&](const SetObject& e) -> Applied {
                          if (auto why = checkObject(s, e.object); !why.empty()) return fail(why);
                          return replaceNode(s.objects, e.object, "object", kUpdateInstances | kUpdateLights);
                        },
                        [&](const SetLight& e) -> Applied {
                          if (auto why = checkLight(e.light); !why.empty()) return fail(why);
                          return replaceNode(s.lights, e.light, "light", kUpdateLights);
                        },
                        [&](const SetTexture& e) -> Applied {
                          return replaceNode(s.textures, e.texture, "texture", kUpdateTextures | kUpdateMaterials | kUpdateEnvironment);
                        },
                        [&](const SetCamera& e) -> Applied {
                          if (auto why = checkCamera(e.camera); !why.empty()) return fail(why);
                          s.camera = e.camera;
                          return kUpdateCamera;
                        },
                        [&](const SetEnvironment& e) -> Applied {
                          const Environment& v = e.environment;
                          if (!isFinite(v.color) || !std::isfinite(v.intensity) || !std::isfinite(v.rotation) || !isFinite(v.zenith) ||
                              !isFinite(v.horizon) || !isFinite(v.ground) || !v.orientation.isFinite() || !isFinite(v.mediumAbsorption) ||
                              !isFinite(v.mediumScattering) || !std::isfinite(v.mediumAnisotropy))
                            return fail("environment: a parameter is not a finite number");
                          if (auto why = checkMedium(v.mediumAbsorption, v.mediumScattering, v.mediumAnisotropy); !why.empty())
                            return fail("environment: " + why);
                          if (v.map != kNoNode && !s.texture(v.map)) return fail("environment: map texture does not exist");
                          // Only the medium changed (a drag in its fields): no sky to decode and pack again.
                          Environment sky = v;
                          sky.mediumAbsorption = s.environment.mediumAbsorption;
                          sky.mediumScattering = s.environment.mediumScattering;
                          sky.mediumAnisotropy = s.environment.mediumAnisotropy;
                          const bool skyChanged = !(sky == s.environment);
                          s.environment = v;
                          return skyChanged ? kUpdateEnvironment : kUpdateMaterials;
                        },
                        [&](const SetRenderSettings& e) -> Applied {
                          if (auto why = checkSettings(e.settings); !why.empty()) return fail(why);
                          s.settings = e.settings;
                          return kUpdateSettings;
                        },
                        [&](const AddMesh& e) -> Applied {
                          if (!e.mesh.geometry) return fail("new mesh has no geometry");
                          return addNode(s, s.meshes, e.mesh, "mesh", kUpdateGeometry);
                        },
                        [&](const AddMaterial& e) -> Applied {
                          if (auto why = checkMaterial(s, e.material); !why.empty()) return fail(why);
                          return addNode(s, s.materials, e.material, "material", kUpdateMaterials);
                        },
                        [&](const AddObject& e) -> Applied {
                          if (auto why = checkObject(s, e.object); !why.empty()) return fail(why);
                          return addNode(s, s.objects, e.object, "object", kUpdateInstances | kUpdateLights);
                        },
                        [&](const AddLight& e) -> Applied {
                          if (auto why = checkLight(e.light); !why.empty()) return fail(why);
                          return addNode(s, s.lights, e.light, "light", kUpdateLights);
                        },
                        [&](const AddTexture& e) -> Applied { return addNode(s, s.textures, e.texture, "texture", kUpdateTextures); },
                        [&](const RemoveNode& e) -> Applied {
                          NodeId id = e.id;
                          std::uint32_t flags = 0;
                          auto erase = [&](auto& nodes, std::uint32_t f) {
                            auto n = std::erase_if(nodes, [&](const auto& node) { return node.id == id; });
                            if (n) flags |= f;
                          };
                          erase(s.meshes, kUpdateGeometry | kUpdateInstances | kUpdateLights);
                          erase(s.materials, kUpdateMaterials | kUpdateInstances | kUpdateLights);
                          erase(s.objects, kUpdateInstances | kUpdateLights);
                          erase(s.lights, kUpdateLights);
                          erase(s.textures, kUpdateTextures | kUpdateMaterials | kUpdateEnvironment);
                          if (!flags) return fail(cat("node ", id, " does not exist"));
                          // Clear dangling references so the scene stays consistent.
                          for (Object& o : s.objects) {
                            if (o.mesh == id) o.mesh = kNoNode;
                            if (o.material == id) o.material = kNoNode;
                          }
                          for (Material& m : s.materials) {
                            for (NodeId* t : m.textureSlots())
                              if (*t == id) *t = kNoNode;
                            if (m.blendWith == id) m.blendWith = kNoNode;
                          }
                          if (s.environment.map == id) {
                            s.environment.map = kNoNode;
                            s.environment.type = EnvironmentType::Constant;
                          }
                          return flags;
                        },
                    },
                    edit);
}

Result<std::uint32_t> Document::apply(const Edit& edit) {
  auto r = applyEdit(scene_, edit);
  if (r.ok()) ++version_;
  return r;
}

}  // namespace retile
