// Tungsten / Bitterli scene.json: the format the paper's scenes come in. Conventions (transform
// order, Euler angles, shape extents, camera field of view, bounce counting) follow Tungsten so
// scenes look as their authors rendered them; see docs/ARCHITECTURE.md for the mapping.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "core/files.h"
#include "core/json.h"
#include "io/curve_reader.h"
#include "retile/io.h"
#include "retile/log.h"
#include "scene/curves.h"
#include "scene/primitives.h"

namespace fs = std::filesystem;

namespace retile {
namespace {

using json::Value;

// The scalar Tungsten reads from a colour where it wants one number (TexelConversion::
// REQUEST_AVERAGE: roughness, blend ratios, alpha, bump): the mean of its channels.
float channelMean(Vec3 c) { return (c.x + c.y + c.z) / 3.0f; }

struct TextureRef {
  bool isTexture = false;
  Vec3 constant{1.0f};
  NodeId texture = kNoNode;
};

class TungstenImporter {
 public:
  TungstenImporter(fs::path file, const ImportOptions& options) : file_(std::move(file)), options_(options) {
    base_ = file_.parent_path();
    out_.format = "tungsten";
    out_.scene.baseDirectory = base_;
  }

  Result<ImportedScene> run() {
    using R = Result<ImportedScene>;
    auto text = readFile(file_, options_.maxFileBytes);
    if (!text) return R::failure(text.error());
    auto parsed = json::parse(text.value());
    if (!parsed) return R::failure(cat(file_.string(), ": not valid JSON: ", parsed.error()));
    const Value& root = parsed.value();
    if (!root.isObject()) return R::failure(cat(file_.string(), ": the top level is not a JSON object"));
    if (!root.find("primitives") && !root.find("bsdfs"))
      return R::failure(cat(file_.string(), ": not a Tungsten scene (no \"primitives\" or \"bsdfs\")"));
    Scene& s = out_.scene;
    s.environment.type = EnvironmentType::Constant;
    s.environment.color = Vec3{0.0f};

    if (const Value* b = root.find("bsdfs")) {
      if (!b->isArray()) return fail("bsdfs: expected an array");
      for (std::size_t i = 0; i < b->asArray().size() && ok(); ++i) {
        const Value& v = b->asArray()[i];
        Material m = bsdf(v, cat("bsdfs[", i, "]"));
        if (!ok()) break;
        m.id = s.newId();
        if (m.name.empty()) m.name = cat("bsdf ", i);
        named_[m.name] = m;
        s.materials.push_back(m);
      }
    }
    if (const Value* c = root.find("camera"); c && ok()) camera(*c);
    s.settings.maxBounces = 63;  // Tungsten's default of 64 path segments, where the file says none
    const Value* integrator = root.find("integrator");
    if (integrator && !integrator->isObject()) integrator = nullptr;
    if (const Value* in = integrator) {
      float mb;
      if (const Value* v = in->find("max_bounces"); v && json::toFloat(*v, &mb) && mb >= 0)
        s.settings.maxBounces = std::clamp(static_cast<int>(mb) - 1, 0, 1024);  // Tungsten counts segments
    }
    // Tungsten's defaults: two-sided shading on, consistency checks off. With the checks on, its
    // paths end about where ours do (ours also shade with the geometric normal where the viewer
    // is behind the shading normal); one-sided shading has no counterpart here.
    bool consistency = false, twoSided = true;
    if (const Value* in = integrator) {
      if (const Value* v = in->find("enable_consistency_checks"); v && v->isBool()) consistency = v->asBool();
      if (const Value* v = in->find("enable_two_sided_shading"); v && v->isBool()) twoSided = v->asBool();
    }
    s.settings.shading = !consistency && twoSided ? ShadingConvention::Tungsten : ShadingConvention::Consistent;
    s.settings.roulette = Roulette::Tungsten;
    s.settings.rayOffset = RayOffset::Tungsten;
    if (!twoSided) warn("integrator: one-sided shading (enable_two_sided_shading: false) is rendered two-sided");
    if (const Value* in = integrator) {
      // Tungsten counts bounces as scattering events, as RenderSettings::minBounces does (unlike
      // max_bounces, which counts path segments).
      float minBounces = 0;
      if (const Value* v = in->find("min_bounces"); v && json::toFloat(*v, &minBounces) && minBounces >= 1)
        s.settings.minBounces = std::clamp(static_cast<int>(minBounces), 0, 1024);
      if (const Value* v = in->find("enable_light_sampling"); v && v->isBool()) s.settings.lightSampling = v->asBool();
      // Tungsten can turn it off in media alone; here it is one setting for surfaces and media.
      if (const Value* v = in->find("enable_volume_light_sampling"); v && v->isBool() && !v->asBool() && s.settings.lightSampling)
        warn("integrator: enable_volume_light_sampling false is not rendered; lights are sampled from media too, which gives the same picture with less noise, except that point lights and suns, which Tungsten's media then never see, light them here");
      if (std::string type = string(*in, "type", "path_tracer"); type != "path_tracer")
        warn(cat("integrator: '", type, "' is rendered by path tracing, which converges to the same picture"));
    }
    if (const Value* r = root.find("renderer"); r && r->isObject()) {
      float spp;
      if (const Value* v = r->find("spp"); v && json::toFloat(*v, &spp) && spp >= 1)
        s.settings.samplesPerPixel = std::clamp(static_cast<int>(spp), 1, 1 << 20);
    }
    if (const Value* m = root.find("media"); m && m->isArray() && !m->asArray().empty()) {
      // A homogeneous medium is rendered inside glass (Material::filled).
      for (std::size_t i = 0; i < m->asArray().size(); ++i) {
        const Value& medium = m->asArray()[i];
        if (!medium.isObject()) continue;
        const std::string name = string(medium, "name", "?");
        mediaNamed_.insert(name);
        std::string why;
        if (auto filling = mediumFilling(medium, name, &why)) media_[name] = *filling;
        else warn(cat("media: '", name, "' is not rendered (", why, "); light travels through it as through a vacuum"));
      }
    }
    if (const Value* p = root.find("primitives"); p && ok()) {
      if (!p->isArray()) return fail("primitives: expected an array");
      primitives_ = p;
      for (std::size_t i = 0; i < p->asArray().size() && ok(); ++i) primitive(p->asArray()[i], cat("primitives[", i, "]"));
      if (!focusPivot_.empty() && ok()) focusOn(*p);
      // A camera's medium that nothing holds is everywhere else: the world's. One that something
      // holds is found by the camera's position (render_scene.h mediaAround).
      std::string world;
      if (!cameraMedium_.empty() && !inside_.count(cameraMedium_) && media_.count(cameraMedium_)) {
        world = cameraMedium_;
        const Filling& f = media_[world];
        s.environment.mediumAbsorption = f.absorption;
        s.environment.mediumScattering = f.scattering;
        s.environment.mediumAnisotropy = f.anisotropy;
        // Leaving a holder, Tungsten's path goes into the holder's ext_medium (a vacuum when it
        // names none); here it goes back to the medium it came from, usually the world's.
        std::size_t elsewhere = 0;
        std::string first;
        for (const auto& [where, ext] : holders_)
          if (ext != world && elsewhere++ == 0) first = cat(where, " (", ext.empty() ? "none" : cat("'", ext, "'"), ")");
        if (elsewhere > 0)
          warn(cat(elsewhere, " glass or boundary primitives with a medium inside name another ext_medium than the camera's '", world,
                   "', the first ", first, "; a path that leaves one goes back to the medium it came from"));
      } else if (!cameraMedium_.empty() && !inside_.count(cameraMedium_) && !mediaNamed_.count(cameraMedium_)) {
        warn(cat("camera: the medium '", cameraMedium_, "' is not defined; the camera is in a vacuum"));
      }
      for (const auto& [where, name] : outside_)
        if (!inside_.count(name) && name != world)
          warn(cat(where, ": the medium '", name, "' around it is rendered only inside glass or a forward boundary (an int_medium) or around the camera, and neither holds it; light passes through it"));
    }
    // Not Tungsten's own key, but Bitterli's living room names its sky this way (an envmap; the
    // room has no other light). Tungsten renders these files without a `constant` entry: the
    // spaceship's constant sky of 0.3 is black in Tungsten's render, and lit the backdrop 60 to
    // 150 times brighter here when it was honoured. So only environment maps are taken from it.
    if (const Value* e = root.find("emissions"); e && e->isArray() && ok())
      for (std::size_t i = 0; i < e->asArray().size(); ++i) {
        const Value& entry = e->asArray()[i];
        if (entry.isObject() && string(entry, "type") == "constant") {
          warn(cat("emissions[", i, "]: a constant sky outside \"primitives\" is left out, as Tungsten leaves it out "
                   "(add an infinite_sphere primitive to light the scene with it)"));
          continue;
        }
        environmentEntry(entry, cat("emissions[", i, "]"));
      }
    if (!ok()) return R::failure(error_);
    if (s.objects.empty() && s.environment.type == EnvironmentType::Constant && maxComponent(s.environment.color) <= 0)
      return fail("the scene has no geometry and no light");
    dropReplacedBsdfs();
    dropUnusedTextures();
    dropUnusedMeshes();
    return std::move(out_);
  }

 private:
  // The thin lens focuses as far as the origin of the primitive focus_pivot names (Tungsten's
  // ThinlensCamera::prepareForRender), else where focus_distance says.
  void focusOn(const Value& primitives) {
    if (std::optional<Mat4> m = transformOfPrimitive(primitives, focusPivot_)) {
      float d = length(m->transformPoint({0, 0, 0}) - out_.scene.camera.position);
      if (std::isfinite(d) && d > 0) out_.scene.camera.focusDistance = d;
      return;
    }
    warn(cat("camera: focus_pivot '", focusPivot_, "' names no primitive; focused at focus_distance"));
  }

  // The transform of the first primitive called `name` (the identity when it has none), or
  // nothing when no primitive is.
  std::optional<Mat4> transformOfPrimitive(const Value& primitives, const std::string& name) {
    for (std::size_t i = 0; i < primitives.asArray().size(); ++i) {
      const Value& p = primitives.asArray()[i];
      if (!p.isObject() || string(p, "name") != name) continue;
      return transform(p.find("transform"), cat("primitives[", i, "].transform"));
    }
    return std::nullopt;
  }

  // A blend's part under the blend's albedo. Where the part is itself a chain of blends, the
  // materials after it are copied under the albedo too (they may be a named bsdf's, which keeps
  // its own); the copies replace what the part's own blend had made for it alone.
  void underAlbedo(Material& p, const TextureRef& albedo, int depth = 0) {
    p.albedo = p.albedo * albedo.constant;
    if (albedo.isTexture && p.albedoTexture == kNoNode) p.albedoTexture = albedo.texture;
    const Material* next = p.blendWith != kNoNode ? out_.scene.material(p.blendWith) : nullptr;
    if (!next) return;
    if (albedo.constant == Vec3{1.0f} && !albedo.isTexture) return;  // nothing changes: shared as it is
    Material copy = *next;
    copied_.insert(next->id);
    if (depth + 2 < kMaxBlendChain) underAlbedo(copy, albedo, depth + 1);
    else copy.blendWith = kNoNode;
    copy.id = out_.scene.newId();
    out_.scene.materials.push_back(copy);
    p.blendWith = copy.id;
  }
  // Materials in the chain of blends that starts at m (m itself counts).
  int chainLength(const Material& m) const {
    int n = 1;
    for (const Material* at = &m; at->blendWith != kNoNode && n < 16; ++n) {
      at = out_.scene.material(at->blendWith);
      if (!at) break;
    }
    return n;
  }
  // Ends the chain at m after `keep` materials; the last one kept is copied without its blend.
  void cutChain(Material& m, int keep) {
    if (keep <= 1 || m.blendWith == kNoNode) {
      m.blendWith = kNoNode;
      return;
    }
    const Material* next = out_.scene.material(m.blendWith);
    if (!next) return;
    Material copy = *next;
    copied_.insert(next->id);  // dropped if nothing else uses it
    cutChain(copy, keep - 1);
    copy.id = out_.scene.newId();
    out_.scene.materials.push_back(copy);
    m.blendWith = copy.id;
  }

  // A named bsdf every user of which took a copy of it (emitters, bump maps) would sit in the
  // material list unused, beside its copies: it goes. Bsdfs the file defines but no primitive
  // names stay, for the artist to assign.
  void dropReplacedBsdfs() {
    Scene& s = out_.scene;
    std::set<NodeId> used;
    for (const Object& o : s.objects) used.insert(o.material);
    for (const Material& m : s.materials) used.insert(m.blendWith);
    std::erase_if(s.materials, [&](const Material& m) { return copied_.count(m.id) && !used.count(m.id); });
  }

  // Textures read for what is not rendered (a thin sheet's albedo) or for bsdfs
  // that were replaced; otherwise they would be decoded and packed for nothing.
  void dropUnusedTextures() {
    Scene& s = out_.scene;
    std::set<NodeId> used{s.environment.map};
    for (const Material& m : s.materials)
      for (NodeId t : m.textures()) used.insert(t);
    std::erase_if(s.textures, [&](const Texture& t) { return !used.count(t.id); });
  }

  // Meshes no object uses (a file only ever used mirrored, whose copy replaced it; one whose
  // primitive was skipped after it loaded), which would be packed and saved for nothing.
  void dropUnusedMeshes() {
    Scene& s = out_.scene;
    std::set<NodeId> used;
    for (const Object& o : s.objects) used.insert(o.mesh);
    std::erase_if(s.meshes, [&](const Mesh& m) { return !used.count(m.id); });
  }

  bool ok() const { return error_.empty(); }
  Result<ImportedScene> fail(const std::string& what) {
    if (error_.empty()) error_ = cat(file_.string(), ": ", what);
    return Result<ImportedScene>::failure(error_);
  }
  void problem(const std::string& where, const std::string& what) {
    if (error_.empty()) error_ = cat(file_.string(), ": ", where, ": ", what);
  }
  void warn(const std::string& what) { out_.warnings.push_back(cat(file_.filename().string(), ": ", what)); }
  std::set<std::string> undefinedWarned_;  // undefined bsdf names already reported

  bool number(const Value& obj, const char* key, float* out, const std::string& where) {
    const Value* v = obj.find(key);
    if (!v) return false;
    if (!json::toFloat(*v, out)) {
      problem(where, cat(key, ": expected a finite number"));
      return false;
    }
    return true;
  }
  bool vec3(const Value& obj, const char* key, Vec3* out, const std::string& where) {
    const Value* v = obj.find(key);
    if (!v) return false;
    if (!json::toVec3(*v, out)) {
      problem(where, cat(key, ": expected a number or three numbers"));
      return false;
    }
    return true;
  }
  std::string string(const Value& obj, const char* key, const std::string& fallback = {}) {
    const Value* v = obj.find(key);
    return v && v->isString() ? v->asString() : fallback;
  }

  NodeId fileTexture(const std::string& ref, TextureColorSpace cs, bool interpolate = true, bool clampToEdge = false) {
    std::string key = cat(ref, "|", static_cast<int>(cs), "|", interpolate, "|", clampToEdge);
    if (auto it = textures_.find(key); it != textures_.end()) return it->second;
    Texture t;
    t.id = out_.scene.newId();
    t.kind = TextureKind::File;
    t.path = ref;
    t.name = fs::path(ref).filename().string();
    t.colorSpace = cs;
    t.whenMissing = MissingTexture::Tungsten;
    t.interpolate = interpolate;
    t.clampToEdge = clampToEdge;
    // One warning per missing file, however many materials use it; the environment says its own.
    if (!resolveScenePath(base_, ref) && !quietMissingTexture_ && missingWarned_.insert(ref).second)
      warn(cat("texture '", ref, "' not found; until the file is there it renders as Tungsten renders a missing texture, a black and white checker (as colour and as alpha)"));
    out_.scene.textures.push_back(t);
    textures_[key] = t.id;
    return t.id;
  }

  // A Tungsten texture value: number, [r,g,b], "file", or {type: bitmap|constant|checker}.
  TextureRef texture(const Value& v, const std::string& where, bool data) {
    TextureRef r;
    if (json::toVec3(v, &r.constant)) return r;
    if (v.isString()) {
      r.isTexture = true;
      r.constant = Vec3{1.0f};
      r.texture = fileTexture(v.asString(), data ? TextureColorSpace::Raw : TextureColorSpace::TungstenGamma);
      return r;
    }
    if (!v.isObject()) {
      problem(where, "expected a number, a colour, a file name or a texture object");
      return r;
    }
    std::string type = string(v, "type");
    if (type == "constant") {
      if (const Value* c = v.find("value"); !c || !json::toVec3(*c, &r.constant)) problem(where, "constant texture without a value");
      return r;
    }
    if (type == "bitmap") {
      std::string f = string(v, "file");
      if (f.empty()) {
        problem(where, "bitmap texture without a file");
        return r;
      }
      bool gamma = true;
      if (const Value* g = v.find("gamma_correct"); g && g->isBool()) gamma = g->asBool();
      float scale = 1;
      number(v, "scale", &scale, where);
      bool interpolate = true, clampToEdge = false;  // Tungsten's defaults
      if (const Value* i = v.find("interpolate"); i && i->isBool()) interpolate = i->asBool();
      if (const Value* c = v.find("clamp"); c && c->isBool()) clampToEdge = c->asBool();
      r.isTexture = true;
      r.constant = Vec3{scale};
      r.texture = fileTexture(f, data ? TextureColorSpace::Raw : gamma ? TextureColorSpace::TungstenGamma : TextureColorSpace::Linear,
                              interpolate, clampToEdge);
      return r;
    }
    if (type == "checker") {
      Texture t;
      t.id = out_.scene.newId();
      t.kind = TextureKind::Checker;
      t.name = "checker";
      t.checkerOn = Vec3{0.8f};
      t.checkerOff = Vec3{0.2f};
      vec3(v, "on_color", &t.checkerOn, where);
      vec3(v, "off_color", &t.checkerOff, where);
      float ru = 20, rv = 20;
      number(v, "res_u", &ru, where);
      number(v, "res_v", &rv, where);
      t.checkerResU = std::clamp(static_cast<int>(ru), 1, 100000);
      t.checkerResV = std::clamp(static_cast<int>(rv), 1, 100000);
      t.tungstenCells = true;
      out_.scene.textures.push_back(t);
      r.isTexture = true;
      r.texture = t.id;
      return r;
    }
    warn(cat(where, ": texture type '", type, "' is not supported; using white"));
    return r;
  }

  // `emitter`: the primitive carries emission, so an undefined name there stands for Tungsten's
  // null bsdf (published Bitterli-derived files name "null" or "NULL" for their lights without
  // defining it).
  // A bsdf and, in the Tungsten of its newer files, its bump map (Bsdf::fromJson; older files put
  // it on the primitive, which the primitive's copy of the bsdf then takes instead). Read as data,
  // the channels averaged (REQUEST_AVERAGE: Tungsten's gamma table is for colours only), the
  // slope times the bitmap's scale.
  Material bsdf(const Value& v, const std::string& where, int depth = 0, bool emitter = false) {
    Material m = bsdfOwn(v, where, depth, emitter);
    if (const Value* bump = v.isObject() ? v.find("bump") : nullptr; bump && ok()) {
      TextureRef t = texture(*bump, where + ".bump", true);
      if (t.isTexture) {
        m.bumpTexture = t.texture;
        m.bumpStrength = t.constant.x;
      }
    }
    return m;
  }

  // The bsdf as its type reads it, without the bump map every type may carry (bsdf adds that).
  Material bsdfOwn(const Value& v, const std::string& where, int depth, bool emitter) {
    Material m;
    m.albedo = Vec3{1.0f};  // Tungsten's default albedo
    if (v.isString()) {
      auto it = named_.find(v.asString());
      if (it != named_.end()) return it->second;
      // An undefined name should not cost the artist the whole file: the surface gets a stand-in
      // and the warning names what was missing, once per name.
      const std::string& name = v.asString();
      if (emitter) {
        m.type = MaterialType::Null;
        m.name = name;
      } else {
        // One grey stand-in per name, shared like a defined bsdf, so the artist fixes it once.
        m.type = MaterialType::Lambert;
        m.albedo = Vec3{0.5f};
        m.name = name;
        m.id = out_.scene.newId();
        named_[name] = m;
        out_.scene.materials.push_back(m);
      }
      if (undefinedWarned_.insert(cat(name, emitter)).second)
        warn(cat(where, ": bsdf '", name, "' is not defined; ",
                 emitter ? "the emitter is drawn by its emission only (a null bsdf)" : "drawn as grey diffuse"));
      return m;
    }
    if (!v.isObject()) {
      problem(where, "expected a bsdf object or name");
      return m;
    }
    if (depth > 8) {
      problem(where, "bsdfs nested too deeply");
      return m;
    }
    m.name = string(v, "name");
    std::string type = string(v, "type");
    if (type.empty()) {
      problem(where, "bsdf without a \"type\"");
      return m;
    }
    if (type == "transparency") {
      Material base;  // Tungsten's default: lambert of albedo 1
      base.albedo = Vec3{1.0f};
      if (const Value* b = v.find("base")) base = bsdf(*b, where + ".base", depth + 1);
      std::string name = m.name;
      m = base;
      m.name = name;
      if (const Value* a = v.find("alpha")) {
        TextureRef t = texture(*a, where + ".alpha", true);
        m.alpha = std::clamp(channelMean(t.constant), 0.0f, 1.0f);
        // A missing alpha map is Tungsten's stand-in checker too: half the squares transparent.
        if (t.isTexture) m.alphaTexture = t.texture;
      }
      return m;
    }
    if (type == "smooth_coat" || type == "rough_coat") {
      // Tungsten's coats: a dielectric layer over a substrate bsdf (its default: a rough conductor).
      Material base;
      if (const Value* sv = v.find("substrate")) {
        base = bsdf(*sv, where + ".substrate", depth + 1);
      } else {
        base.type = MaterialType::RoughConductor;
        base.albedo = Vec3{1.0f};
        base.metal = "Cu";
        base.roughness = 0.1f;
        base.separableShadowing = true;
      }
      if (!ok()) return m;
      float ior = 1.3f, thickness = 1;  // Tungsten's defaults
      Vec3 sigmaA{0.0f};
      number(v, "ior", &ior, where);
      number(v, "thickness", &thickness, where);
      const bool rough = type == "rough_coat";
      // Tungsten's rough coat read its absorption as "sigmaA" before it took "sigma_a".
      if (!vec3(v, "sigma_a", &sigmaA, where) && rough) vec3(v, "sigmaA", &sigmaA, where);
      float coatRoughness = 0.02f;  // Tungsten's default
      if (rough) {
        if (const Value* r = v.find("roughness")) {
          TextureRef t = texture(*r, where + ".roughness", true);
          coatRoughness = channelMean(t.constant);
          if (t.isTexture) warn(cat(where, ": a rough coat's textured roughness is taken as ", coatRoughness, " everywhere"));
        }
        if (string(v, "distribution", "ggx") != "ggx") warn(cat(where, ": the rough coat's distribution is rendered as GGX"));
      }
      const std::string name = m.name;
      m = base;
      m.name = name;
      if (isTransmissiveType(m.type)) {
        warn(cat(where, ": a coat over a ", materialTypeName(m.type), " substrate is rendered without the coat"));
        return m;
      }
      if (!(ior > 1.0f)) {
        warn(cat(where, ": a coat of index ", ior, " reflects and refracts nothing; rendered without it"));
        return m;
      }
      if (base.blendWith != kNoNode) warn(cat(where, ": a coat over a blended substrate is rendered on its first part only"));
      if (m.coated()) warn(cat(where, ": a coat over a coat is rendered with the outer coat only"));
      m.coatIor = ior;
      m.coatAbsorption = max(sigmaA * thickness, Vec3{0.0f});
      m.coatRoughness = rough ? std::max(coatRoughness, 1e-3f) : 0.0f;
      return m;
    }
    if (type == "mixed") {
      // Tungsten's blend, albedo * (ratio * bsdf0 + (1 - ratio) * bsdf1): this material is bsdf0
      // under the blend's albedo and blends (Material::blendWith) with a copy of bsdf1 under it.
      // A part that is a blend itself comes back as the first material of its chain of blends,
      // which the kernel follows: bsdf1's chain goes on after bsdf0; a chain in bsdf0 goes after
      // bsdf1 instead (the ratio turned round), where the ratio is a constant and bsdf1 no chain.
      float ratio = 0.5f;
      NodeId ratioTexture = kNoNode;
      if (const Value* r = v.find("ratio")) {
        // A bitmap ratio is read as data, its channels averaged (Tungsten's REQUEST_AVERAGE),
        // times the bitmap's scale.
        TextureRef t = texture(*r, where + ".ratio", true);
        ratio = std::clamp(channelMean(t.constant), 0.0f, 1.0f);
        if (t.isTexture) ratioTexture = t.texture;
      }
      TextureRef albedo;  // Tungsten's default: 1
      if (const Value* a = v.find("albedo")) albedo = texture(*a, where + ".albedo", false);
      auto part = [&](const char* key) {
        const Value* pv = v.find(key);
        if (!pv) {
          problem(where, cat("mixed bsdf without \"", key, "\""));
          return Material{};
        }
        Material p = bsdf(*pv, cat(where, ".", key), depth + 1);
        underAlbedo(p, albedo);
        return p;
      };
      const std::string name = m.name;
      Material zero = part("bsdf0"), one = part("bsdf1");
      if (!ok()) return m;
      Material* first = &zero;
      Material* rest = &one;
      float firstRatio = ratio;
      if (zero.blendWith != kNoNode && one.blendWith == kNoNode && ratioTexture == kNoNode) {
        first = &one;
        rest = &zero;
        firstRatio = 1.0f - ratio;
      } else if (zero.blendWith != kNoNode) {
        warn(cat(where, ".bsdf0: a blend in a blend whose ratio is a texture or whose bsdf1 is a blend too is "
                        "rendered as its first part"));
        copied_.insert(zero.blendWith);  // dropped if nothing else uses it
        zero.blendWith = kNoNode;
        zero.blendRatio = 1;
        zero.blendRatioTexture = kNoNode;
      }
      if (chainLength(*rest) + 1 > kMaxBlendChain) {
        warn(cat(where, ": blends nested more than ", kMaxBlendChain, " materials deep; the deepest are left out"));
        cutChain(*rest, kMaxBlendChain - 1);
      }
      const bool reversed = first == &one;
      rest->id = out_.scene.newId();
      rest->name = cat(name.empty() ? where : name, reversed ? " (bsdf0)" : " (bsdf1)");
      out_.scene.materials.push_back(*rest);
      m = *first;
      m.name = name;
      m.blendWith = rest->id;
      m.blendRatio = firstRatio;
      m.blendRatioTexture = reversed ? kNoNode : ratioTexture;
      return m;
    }
    if (const Value* a = v.find("albedo")) {
      TextureRef t = texture(*a, where + ".albedo", false);
      m.albedo = t.constant;
      m.albedoTexture = t.texture;
    }
    std::string dist = string(v, "distribution", "ggx");
    m.beckmann = dist == "beckmann";
    m.separableShadowing = true;  // Tungsten's Microfacet::G is G1(wi) G1(wo)
    if (dist != "ggx" && dist != "beckmann") warn(cat(where, ": distribution '", dist, "' is rendered as GGX"));
    auto roughness = [&](float fallback) {
      m.roughness = fallback;
      if (const Value* r = v.find("roughness")) {
        TextureRef t = texture(*r, where + ".roughness", true);
        m.roughness = channelMean(t.constant);
        m.roughnessTexture = t.texture;
      }
    };
    auto metal = [&]() {
      m.metal = "Cu";
      Vec3 eta, k;
      if (vec3(v, "eta", &eta, where) && vec3(v, "k", &k, where)) {
        m.metal = "custom";
        m.eta = eta;
        m.k = k;
      }
      std::string named = string(v, "material");
      if (!named.empty()) {
        Vec3 e2, k2;
        // Tungsten also names each metal's table from Palik's handbook "<metal>_palik". Its RGB
        // values are the plain name's, except copper's, whose eta and k differ by under 7 %.
        const std::string palik = "_palik";
        if (named.size() > palik.size() && named.ends_with(palik) &&
            conductorIor(named.substr(0, named.size() - palik.size()), &e2, &k2))
          named.resize(named.size() - palik.size());
        if (conductorIor(named, &e2, &k2)) {
          m.metal = named;
        } else {
          warn(cat(where, ": unknown metal '", named, "'; using copper"));
          m.metal = "Cu";
        }
      }
    };
    number(v, "ior", &m.ior, where);
    if (type == "lambert") {
      m.type = MaterialType::Lambert;
    } else if (type == "oren_nayar") {
      m.type = MaterialType::OrenNayar;
      roughness(1.0f);
      m.roughness /= std::sqrt(2.0f);  // Tungsten's roughness is sigma * sqrt(2)
    } else if (type == "plastic") {
      m.type = MaterialType::Plastic;
    } else if (type == "rough_plastic") {
      m.type = MaterialType::RoughPlastic;
      roughness(0.02f);
    } else if (type == "conductor") {
      m.type = MaterialType::Conductor;
      metal();
    } else if (type == "rough_conductor") {
      m.type = MaterialType::RoughConductor;
      metal();
      roughness(0.1f);
    } else if (type == "mirror") {
      m.type = MaterialType::Mirror;
    } else if (type == "dielectric" || type == "rough_dielectric") {
      const bool rough = type == "rough_dielectric";
      m.type = rough ? MaterialType::RoughDielectric : MaterialType::Dielectric;
      m.tungstenGlass = true;
      if (rough) roughness(0.1f);
      if (const Value* e = v.find("enable_refraction"); e && e->isBool() && !e->asBool()) {
        // Tungsten's dielectric without refraction reflects F times its albedo and transmits
        // nothing; being opaque, it is shaded from the viewer's side (two-sided), so F is always
        // the outside's. That is exactly a metal of index ior + 0i: its Fresnel term is the
        // dielectric's, tinted by the albedo, over the same lobe.
        m.type = rough ? MaterialType::RoughConductor : MaterialType::Conductor;
        m.metal = "custom";
        m.eta = Vec3{std::clamp(m.ior, 1.0001f, 10.0f)};
        m.k = Vec3{0.0f};
        m.tungstenGlass = false;
      }
    } else if (type == "thinsheet") {
      m.type = MaterialType::ThinSheet;
      // Tungsten's thin sheet has no albedo: what passes is dimmed by its sigma_a along twice its
      // thickness (Tungsten's factor), exp(-2 sigma_a thickness / cos t).
      m.albedo = Vec3{1.0f};
      m.albedoTexture = kNoNode;
      Vec3 sigmaA{0.0f};
      float thickness = 0.5f;  // Tungsten's default
      vec3(v, "sigma_a", &sigmaA, where);
      if (const Value* t = v.find("thickness")) {
        // Textured, the thickness is the sheet's roughness texture (Material::roughnessTexture),
        // which scales the absorption and the film below, as given for a thickness of 1.
        TextureRef th = texture(*t, where, true);
        thickness = channelMean(th.constant);
        if (th.isTexture) {
          m.roughnessTexture = th.texture;
          thickness = 1.0f;
        }
      }
      m.coatingAbsorption = max(sigmaA * (2.0f * thickness), Vec3{0.0f});
      // Tungsten's film is its thickness times 500 nm thick (ThinSheetBsdf), its interference
      // drawn as Tungsten draws it.
      if (const Value* e = v.find("enable_interference"); e && e->isBool() && e->asBool()) m.filmThickness = std::max(500.0f * thickness, 0.0f);
      m.tungstenGlass = true;
    } else if (type == "null") {
      m.type = MaterialType::Null;
    } else if (type == "phong") {
      m.type = MaterialType::Phong;
      float exponent = 64;  // Tungsten's default
      number(v, "exponent", &exponent, where);
      if (!(exponent >= 0)) {
        warn(cat(where, ": Phong exponent ", exponent, " is taken as 64"));
        exponent = 64;
      }
      m.roughness = std::sqrt(2.0f / (exponent + 2.0f));  // the inverse of n = 2 / a^2 - 2
      m.diffuseRatio = 0.2f;  // Tungsten's default
      number(v, "diffuse_ratio", &m.diffuseRatio, where);
    } else if (type == "diffuse_transmission") {
      m.type = MaterialType::DiffuseTransmission;
      m.transmittance = 0.5f;  // Tungsten's, which its files cannot change
    } else if (type == "forward") {
      m.type = MaterialType::Boundary;  // every ray passes; its primitive's int_medium fills it
    } else if (type == "hair") {
      hairFibre(v, where, m);
    } else {
      warn(cat(where, ": bsdf type '", type, "' is not supported; rendered as lambert with its albedo"));
      m.type = MaterialType::Lambert;
    }
    if (m.type == MaterialType::Plastic || m.type == MaterialType::RoughPlastic) {
      // The coating absorbs sigma_a per unit of its thickness (Tungsten's defaults: 0 and 1).
      Vec3 sigmaA{0.0f};
      float thickness = 1;
      vec3(v, "sigma_a", &sigmaA, where);
      number(v, "thickness", &thickness, where);
      m.coatingAbsorption = max(sigmaA * thickness, Vec3{0.0f});
    }
    return m;
  }

  // Tungsten's hair (HairBcsdf): its melanin gives the pigment's absorption per unit of the
  // fibre's radius (d'Eon et al. 2011's eumelanin and pheomelanin, mixed by the ratio), unless
  // sigma_a is given.
  void hairFibre(const Value& v, const std::string& where, Material& m) {
    m.type = MaterialType::Hair;
    m.albedo = Vec3{1.0f};
    m.roughness = 0.1f;
    number(v, "roughness", &m.roughness, where);
    m.roughness = std::clamp(std::isfinite(m.roughness) ? m.roughness : 0.1f, 0.0f, 1.0f);
    m.hairTilt = 2.0f;
    number(v, "scale_angle", &m.hairTilt, where);
    if (!(std::abs(m.hairTilt) <= 45)) {
      warn(cat(where, ": scale_angle ", m.hairTilt, " is taken as 2"));
      m.hairTilt = 2.0f;
    }
    float ratio = 0.5f, concentration = 0.25f;  // Tungsten's defaults
    number(v, "melanin_ratio", &ratio, where);
    number(v, "melanin_concentration", &concentration, where);
    const Vec3 eumelanin{0.419f, 0.697f, 1.37f}, pheomelanin{0.187f, 0.4f, 1.05f};
    Vec3 sigmaA = (eumelanin * (1 - ratio) + pheomelanin * ratio) * concentration;
    vec3(v, "sigma_a", &sigmaA, where);
    m.coatingAbsorption = isFinite(sigmaA) ? max(sigmaA, Vec3{0.0f}) : Vec3{0.0f};
  }

  // Tungsten's rotYXZ: R = Ry(-ry) Rx(rx) Rz(rz), angles in degrees.
  static Mat4 rotation(Vec3 deg) {
    return Mat4::rotateY(radians(-deg.y)) * Mat4::rotateX(radians(deg.x)) * Mat4::rotateZ(radians(deg.z));
  }

  // flatY: the shape lies in y = 0 (quad, disk), so a zero y scale means nothing and is
  // replaced by 1 to keep the matrix invertible.
  Mat4 transform(const Value* v, const std::string& where, Vec3* scaleOut = nullptr, bool flatY = false) {
    Mat4 m;
    if (scaleOut) *scaleOut = Vec3{1.0f};
    if (!v) return m;
    if (v->isArray()) {
      if (v->asArray().size() != 16) {
        problem(where, "transform: a matrix needs 16 numbers");
        return m;
      }
      for (int i = 0; i < 16; ++i)
        if (!json::toFloat(v->asArray()[static_cast<std::size_t>(i)], &m.m[i / 4][i % 4])) {
          problem(where, "transform: matrix entries must be finite numbers");
          return m;
        }
      if (scaleOut)
        *scaleOut = {length(m.transformVector({1, 0, 0})), length(m.transformVector({0, 1, 0})), length(m.transformVector({0, 0, 1}))};
      return m;
    }
    if (!v->isObject()) {
      problem(where, "transform: expected an object or 16 numbers");
      return m;
    }
    Vec3 pos{0.0f}, scale{1.0f}, rot{0.0f};
    vec3(*v, "position", &pos, where);
    vec3(*v, "scale", &scale, where);
    vec3(*v, "rotation", &rot, where);
    if (flatY && scale.y == 0) scale.y = 1;
    Vec3 axis[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    bool given[3] = {false, false, false};
    Vec3 lookAt;
    if (vec3(*v, "look_at", &lookAt, where)) {
      axis[2] = lookAt - pos;
      given[2] = true;
    }
    Vec3 up;
    if (vec3(*v, "up", &up, where)) {
      axis[1] = up;
      given[1] = true;
    }
    const char* names[3] = {"x_axis", "y_axis", "z_axis"};
    for (int i = 0; i < 3; ++i) {
      Vec3 a;
      if (vec3(*v, names[i], &a, where)) {
        axis[i] = a;
        given[i] = true;
      }
    }
    // Gram-Schmidt in an order that keeps the explicitly given axes (Tungsten's rules).
    int order[3] = {2, 1, 0};
    if (given[0] && !given[1] && !given[2]) order[0] = 0, order[1] = 2, order[2] = 1;
    else if (!given[0] && given[1] && !given[2]) order[0] = 1, order[1] = 2, order[2] = 0;
    else if (given[0] && given[1] && !given[2]) order[0] = 1, order[1] = 0, order[2] = 2;
    else if (given[0] && !given[1] && given[2]) order[0] = 2, order[1] = 0, order[2] = 1;
    Vec3& a = axis[order[0]];
    Vec3& b = axis[order[1]];
    Vec3& c = axis[order[2]];
    a = normalize(a);
    if (length(a) == 0) a = order[0] == 0 ? Vec3{1, 0, 0} : order[0] == 1 ? Vec3{0, 1, 0} : Vec3{0, 0, 1};
    b = b - a * dot(a, b);
    if (length(b) < 1e-6f) b = std::abs(a.x) < 0.9f ? cross(a, {1, 0, 0}) : cross(a, {0, 1, 0});
    b = normalize(b);
    c = c - a * dot(a, c) - b * dot(b, c);
    c = length(c) < 1e-6f ? cross(a, b) : normalize(c);
    if (dot(cross(axis[0], axis[1]), axis[2]) < 0) {
      if (!given[0]) axis[0] = -axis[0];
      else if (!given[1]) axis[1] = -axis[1];
      else axis[2] = -axis[2];
    }
    Mat4 basis;
    for (int col = 0; col < 3; ++col)
      for (int row = 0; row < 3; ++row) basis.m[row][col] = axis[col][row];
    if (scaleOut) *scaleOut = scale;
    return Mat4::translate(pos) * rotation(rot) * basis * Mat4::scale(scale);
  }

  void camera(const Value& c) {
    const std::string where = "camera";
    if (!c.isObject()) return problem(where, "expected an object");
    Scene& s = out_.scene;
    std::string type = string(c, "type", "pinhole");
    if (type == "thinlens") {
      // Tungsten's ThinlensCamera: a disc of radius aperture_size, sharp on the plane focus_distance
      // along the view direction (its defaults 0.001 and 1), or as far as focus_pivot's origin.
      s.camera.apertureRadius = 0.001f;
      s.camera.focusDistance = 1.0f;
      number(c, "aperture_size", &s.camera.apertureRadius, where);
      number(c, "focus_distance", &s.camera.focusDistance, where);
      if (!(s.camera.apertureRadius >= 0) || !(s.camera.focusDistance > 0))
        return problem(where, "aperture_size must not be negative and focus_distance must be positive");
      focusPivot_ = string(c, "focus_pivot");
      float catEye = 0;
      number(c, "cateye", &catEye, where);
      if (catEye > 0) warn("camera: the cat's-eye vignetting of a thin lens (cateye) is left out");
      if (c.find("aperture")) warn("camera: an aperture texture is rendered as a round aperture");
    } else if (type != "pinhole") {
      warn(cat("camera type '", type, "' is rendered as a pinhole camera"));
    }
    // Its tonemap is how the author saw the scene: the nearest of our views shows it (the
    // render itself is linear either way). Tungsten's default, gamma, is Standard's sRGB curve.
    const std::string tonemap = string(c, "tonemap", "gamma");
    if (tonemap == "filmic") {
      s.settings.view = "Filmic";
    } else if (tonemap == "linear") {
      s.settings.view = "Raw";
    } else if (tonemap == "reinhard" || tonemap == "pbrt") {
      s.settings.view = "Filmic";
      warn(cat("camera: tonemap '", tonemap, "' is shown through the Filmic view, the nearest there is"));
    } else {
      s.settings.view = "Standard";
      if (tonemap != "gamma") warn(cat("camera: unknown tonemap '", tonemap, "'; shown through the Standard view"));
    }
    // The renderer finds the medium around the camera itself (mediaAround): one that glass or a
    // boundary holds. Warned of once every primitive is read, if none does.
    cameraMedium_ = string(c, "medium");
    if (const Value* r = c.find("resolution")) {
      Vec2 res;
      if (!json::toVec2(*r, &res) || res.x < 1 || res.y < 1 || res.x > kMaxImageSide || res.y > kMaxImageSide)
        return problem(where, cat("resolution: expected one or two whole numbers within 1..", kMaxImageSide));
      s.settings.width = static_cast<int>(res.x);
      s.settings.height = static_cast<int>(res.y);
    } else {
      s.settings.width = 1000;
      s.settings.height = 563;
    }
    // Tungsten's default filter is the tent; the scene's author saw every edge through it.
    s.settings.pixelFilter = PixelFilter::Tent;
    if (const Value* f = c.find("reconstruction_filter"); f && f->isString()) {
      if (f->asString() == "dirac") {
        s.settings.pixelFilter = PixelFilter::Box;
        warn("camera: reconstruction filter 'dirac' is rendered as a box filter");
      } else if (!parsePixelFilter(f->asString(), &s.settings.pixelFilter)) {
        warn(cat("camera: reconstruction filter '", f->asString(), "' is not supported; rendered with a tent"));
      }
    }
    s.settings.filterWidth = defaultFilterWidth(s.settings.pixelFilter);  // Tungsten's widths
    s.settings.filterSampling = FilterSampling::Tungsten;
    float fov = 60;
    number(c, "fov", &fov, where);
    if (!(fov > 0 && fov < 180)) return problem(where, "fov must be between 0 and 180 degrees");
    // Tungsten's fov is horizontal; ours is vertical at the scene's aspect ratio.
    s.camera.verticalFov = 2.0f * std::atan(std::tan(radians(fov) * 0.5f) / s.aspect());
    const Value* t = c.find("transform");
    if (t && t->isObject() && t->find("look_at")) {
      Vec3 pos{0.0f}, at{0, 0, 1}, up{0, 1, 0};
      vec3(*t, "position", &pos, where);
      vec3(*t, "look_at", &at, where);
      vec3(*t, "up", &up, where);
      if (length(at - pos) == 0) return problem(where, "position and look_at coincide");
      s.camera.position = pos;
      s.camera.target = at;
      s.camera.up = length(up) > 0 ? up : Vec3{0, 1, 0};
    } else if (t) {
      Mat4 m = transform(t, where);
      s.camera.position = m.transformPoint({0, 0, 0});
      s.camera.target = s.camera.position + normalize(m.transformVector({0, 0, 1}));
      s.camera.up = normalize(m.transformVector({0, 1, 0}));
    }
  }

  // Tessellated, a sphere or a disk has a little less area than Tungsten's analytic shape (0.09 %
  // for the sphere's 48 x 96, 0.16 % for the disk's 64-gon), and as an emitter gives that much less
  // light, which is most of the 0.2 % a scene lit by them may differ by. Scaled out to the true area.
  static std::shared_ptr<const MeshGeometry> withArea(std::shared_ptr<const MeshGeometry> g, float area) {
    const float meshArea = worldArea(*g, Mat4::identity());
    if (!(meshArea > 0)) return g;
    auto scaled = std::make_shared<MeshGeometry>(*g);
    const float s = std::sqrt(area / meshArea);
    for (Vec3& p : scaled->positions) p = p * s;
    return scaled;
  }

  // Tungsten's sphere has its poles on z and u = atan2(y, x) / 2 pi + 1/2, v = acos(z) / pi
  // (Sphere::intersectionInfo); ours has them on y. The same mesh turned by (x, y, z) -> (-x, z, y),
  // a rotation, carries uvs that are Tungsten's, so that a textured sphere looks as in Tungsten.
  static std::shared_ptr<const MeshGeometry> tungstenSphere() {
    auto g = std::make_shared<MeshGeometry>(*makeSphere());
    for (Vec3& p : g->positions) p = Vec3{-p.x, p.z, p.y};
    for (Vec3& n : g->normals) n = Vec3{-n.x, n.z, n.y};
    return g;
  }

  // Tungsten's quad has v = 1/2 - z (Quad::intersect: v = 1 - l1); ours z + 1/2.
  static std::shared_ptr<const MeshGeometry> tungstenQuad() {
    auto g = std::make_shared<MeshGeometry>(*makeQuad());
    for (Vec2& uv : g->uvs) uv.y = 1 - uv.y;
    return g;
  }

  // Tungsten's cube maps a face across its other two axes in turn, (y, z) on the x faces, (z, x)
  // on the y faces, (x, y) on the z faces, each from 0 to 1 and unmirrored on either side
  // (Cube::intersectionInfo). Ours spans each face by its own corners.
  static std::shared_ptr<const MeshGeometry> tungstenCube() {
    auto g = std::make_shared<MeshGeometry>(*makeCube());
    for (std::size_t i = 0; i < g->positions.size(); ++i) {
      const Vec3 n = g->normals[i], p = g->positions[i];
      const int dim = std::abs(n.x) > 0.5f ? 0 : std::abs(n.y) > 0.5f ? 1 : 2;
      const float c[3] = {p.x, p.y, p.z};
      g->uvs[i] = {c[(dim + 1) % 3] + 0.5f, c[(dim + 2) % 3] + 0.5f};
    }
    return g;
  }

  // Tungsten's cylinder has u = atan2(z, x) / 2 pi + 1/2 and v = y + 1/2 on its wall and
  // (x + 1/2, z + 1/2) on its caps (Cylinder::intersectionInfo). Ours, turned half a turn about y
  // (a rotation), has its seam where Tungsten's u wraps and u = 1 - Tungsten's along the wall.
  static std::shared_ptr<const MeshGeometry> tungstenCylinder(bool capped) {
    auto g = std::make_shared<MeshGeometry>(*makeCylinder(capped));
    for (std::size_t i = 0; i < g->positions.size(); ++i) {
      Vec3& p = g->positions[i];
      Vec3& n = g->normals[i];
      p = Vec3{-p.x, p.y, -p.z};
      n = Vec3{-n.x, n.y, -n.z};
      g->uvs[i] = std::abs(n.y) > 0.5f ? Vec2{p.x + 0.5f, p.z + 0.5f} : Vec2{1 - g->uvs[i].x, g->uvs[i].y};
    }
    return g;
  }

  // A disk of radius 1 facing +y whose u runs from 0 to 1 as -x turns towards -z, v from its
  // centre out. Placed by tungstenDiskFrame, that is Tungsten's parametrisation.
  static std::shared_ptr<const MeshGeometry> tungstenDisk(int segments) {
    auto g = std::make_shared<MeshGeometry>();
    for (int s = 0; s <= segments; ++s) {
      const float u = static_cast<float>(s) / static_cast<float>(segments), phi = 2 * kPi * u;
      // A centre vertex per segment, at the segment's middle u, so that u does not blur across
      // the disk towards its middle.
      for (float r : {0.0f, 1.0f}) {
        g->positions.push_back({-r * std::cos(phi), 0, -r * std::sin(phi)});
        g->normals.push_back({0, 1, 0});
        g->uvs.push_back({r > 0 ? u : (static_cast<float>(s) + 0.5f) / static_cast<float>(segments), r});
      }
    }
    for (int s = 0; s < segments; ++s) {
      const auto c = static_cast<std::uint32_t>(2 * s);
      g->indices.insert(g->indices.end(), {c, c + 3, c + 1});  // counter-clockwise seen from +y
    }
    return g;
  }

  // Tungsten's disk is round whatever its scale: its radius is the larger of the x and z scales,
  // its normal the transformed y axis, and u the angle about it in a frame taken from the normal
  // alone (Disk::prepareForRender, TangentFrame), so the same disk turned about its normal keeps
  // its uvs where they were in the world. The frame's columns are that frame's bitangent, the
  // normal and its tangent, each times the radius.
  static Mat4 tungstenDiskFrame(const Mat4& xf, Vec3 scale) {
    const float r = std::max(std::abs(scale.x), std::abs(scale.z));
    const Vec3 n = normalize(xf.transformVector({0, 1, 0}));
    const Vec3 t0 = std::abs(n.x) > std::abs(n.y) ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
    const Vec3 b = normalize(cross(n, t0));
    const Vec3 t = cross(b, n);
    const Vec3 c = xf.transformPoint({0, 0, 0});
    Mat4 m;
    const Vec3 cols[4] = {b * r, n * r, t * r, c};
    for (int j = 0; j < 4; ++j) {
      m.m[0][j] = cols[j].x;
      m.m[1][j] = cols[j].y;
      m.m[2][j] = cols[j].z;
    }
    return m;
  }

  std::shared_ptr<const MeshGeometry> shape(const std::string& kind) {
    auto it = shapes_.find(kind);
    if (it != shapes_.end()) return it->second;
    std::shared_ptr<const MeshGeometry> g;
    if (kind == "quad") g = tungstenQuad();
    else if (kind == "cube") g = tungstenCube();
    else if (kind == "sphere") g = withArea(tungstenSphere(), 4 * kPi);
    else if (kind == "disk") g = withArea(tungstenDisk(64), kPi);
    else if (kind == "cylinder") g = tungstenCylinder(true);
    else if (kind == "open cylinder") g = tungstenCylinder(false);
    shapes_[kind] = g;
    return g;
  }

  NodeId meshNode(const std::string& key, const std::string& name, std::shared_ptr<const MeshGeometry> g) {
    if (auto it = meshIds_.find(key); it != meshIds_.end()) return it->second;
    Mesh m;
    m.id = out_.scene.newId();
    m.name = name;
    m.geometry = std::move(g);
    out_.scene.meshes.push_back(m);
    meshIds_[key] = m.id;
    return m.id;
  }

  // A copy of `mesh` with every triangle wound the other way. A mesh's normals stay as they are:
  // Tungsten carries them by the normal matrix, as we do. A quad's turn with its winding: its
  // shading normal is its winding's (Quad::intersectionInfo).
  NodeId mirroredMesh(NodeId mesh, bool turnNormals) {
    if (auto it = mirroredOf_.find(mesh); it != mirroredOf_.end()) return it->second;
    const Mesh* m = out_.scene.mesh(mesh);
    if (!m || !m->geometry) return mesh;
    auto g = std::make_shared<MeshGeometry>(*m->geometry);
    for (std::size_t t = 0; t + 2 < g->indices.size(); t += 3) std::swap(g->indices[t + 1], g->indices[t + 2]);
    if (turnNormals)
      for (Vec3& n : g->normals) n = -n;
    Mesh copy;
    copy.id = out_.scene.newId();
    copy.name = m->name;  // what an object made from it is called
    copy.geometry = std::move(g);
    out_.scene.meshes.push_back(std::move(copy));
    return mirroredOf_[mesh] = out_.scene.meshes.back().id;
  }

  static void smoothNormals(MeshGeometry& g) {
    g.normals.assign(g.positions.size(), Vec3{0.0f});
    for (std::size_t i = 0; i + 2 < g.indices.size(); i += 3) {
      Vec3 a = g.positions[g.indices[i]], b = g.positions[g.indices[i + 1]], c = g.positions[g.indices[i + 2]];
      Vec3 n = cross(b - a, c - a);  // area-weighted
      for (int k = 0; k < 3; ++k) g.normals[g.indices[i + static_cast<std::size_t>(k)]] += n;
    }
    for (Vec3& n : g.normals) n = normalize(n);
  }

  // Tungsten's recompute_normals (TriangleMesh::calcSmoothVertexNormals), rebuilt from what it
  // does: vertices at one position are smoothed together, area-weighted, but not across a crease
  // of more than 27 degrees (cos 0.15 pi). A corner whose face turns further from the first face
  // that used its vertex gets a vertex of its own, which keeps that face's flat normal; a vertex
  // takes the faces around its position within 27 degrees of its own first face. Smoothing by
  // shared index alone rounded a box's edges and left seams where a file splits vertices.
  static void creasedNormals(MeshGeometry& g) {
    const float limit = std::cos(kPi * 0.15f);
    const std::size_t original = g.positions.size(), triangles = g.indices.size() / 3;
    const bool hasUvs = g.uvs.size() == original;
    std::vector<Vec3> faceNormal(triangles), weighted(triangles);
    for (std::size_t t = 0; t < triangles; ++t) {
      const Vec3 a = g.positions[g.indices[t * 3]], b = g.positions[g.indices[t * 3 + 1]], c = g.positions[g.indices[t * 3 + 2]];
      weighted[t] = cross(b - a, c - a);
      const float len = length(weighted[t]);
      faceNormal[t] = len > 0 && std::isfinite(len) ? weighted[t] / len : Vec3{0, 1, 0};
    }
    std::vector<Vec3> own(original, Vec3{0, 1, 0});  // each vertex's first face's normal
    std::vector<char> used(original, 0);
    for (std::size_t corner = 0; corner < triangles * 3; ++corner) {
      const std::uint32_t v = g.indices[corner];
      const Vec3 n = faceNormal[corner / 3];
      if (!used[v]) {
        used[v] = 1;
        own[v] = n;
      } else if (dot(own[v], n) < limit) {
        g.indices[corner] = static_cast<std::uint32_t>(g.positions.size());
        g.positions.push_back(g.positions[v]);
        if (hasUvs) g.uvs.push_back(g.uvs[v]);
        own.push_back(n);
      }
    }
    // The original vertices at each position (+ 0.0f: -0 and 0 are one place).
    auto key = [](Vec3 p) {
      std::array<std::uint32_t, 3> k;
      const float c[3] = {p.x + 0.0f, p.y + 0.0f, p.z + 0.0f};
      std::memcpy(k.data(), c, sizeof c);
      return k;
    };
    std::map<std::array<std::uint32_t, 3>, std::vector<std::uint32_t>> at;
    for (std::uint32_t v = 0; v < original; ++v) at[key(g.positions[v])].push_back(v);
    std::vector<Vec3> sum(original, Vec3{0.0f});
    for (std::size_t corner = 0; corner < triangles * 3; ++corner) {
      const std::size_t t = corner / 3;
      for (std::uint32_t u : at[key(g.positions[g.indices[corner]])])
        if (dot(own[u], faceNormal[t]) >= limit) sum[u] += weighted[t];
    }
    g.normals = own;  // a corner's own vertex keeps its face's normal
    for (std::size_t v = 0; v < original; ++v)
      if (const float len = length(sum[v]); len > 0 && std::isfinite(len)) g.normals[v] = sum[v] / len;
  }

  // The tubes of a "curves" primitive's strands (scene/curves.h), as a mesh: its file (.hair or
  // .fiber) with Tungsten's curve_thickness, curve_taper and subsample applied. (Tungsten widens
  // strands by the transform's mean scale, as a uniform scale does here; under a scale that is
  // not uniform the tubes are flattened where Tungsten's stay round.) kNoNode when there is
  // nothing to draw.
  NodeId curves(const Value& p, const std::string& where) {
    const std::string f = string(p, "file");
    if (f.empty()) {
      warn(cat(where, ": curves without a \"file\"; skipped"));
      return kNoNode;
    }
    auto path = resolveScenePath(base_, f);
    if (!path) {
      warn(cat(where, ": curve file '", f, "' not found; the primitive is skipped"));
      return kNoNode;
    }
    float thickness = 0, subsample = 0;
    const bool overridden = number(p, "curve_thickness", &thickness, where);
    bool taper = false;
    if (const Value* v = p.find("curve_taper"); v && v->isBool()) taper = v->asBool();
    number(p, "subsample", &subsample, where);
    if (const std::string mode = string(p, "mode", "half_cylinder"); mode == "ribbon")
      warn(cat(where, ": ribbon curves are drawn as round tubes"));
    std::vector<std::string> warnings;
    Result<CurveSet> read = readCurves(*path, &warnings, options_);
    for (auto& w : warnings) out_.warnings.push_back(w);
    if (!read) {
      warn(cat(where, ": ", read.error(), "; the primitive is skipped"));
      return kNoNode;
    }
    CurveSet c = std::move(read.value());
    if (overridden && !(thickness >= 0 && std::isfinite(thickness))) {
      warn(cat(where, ": curve_thickness ", thickness, " is taken as 0.01"));
      thickness = 0.01f;
    }
    applyCurveThickness(c, overridden ? &thickness : nullptr, taper);
    if (subsample > 0) {
      // Tungsten leaves each strand out with this probability (Curves::prepareForRender), drawn
      // from its own random sequence: the same share is left out here, not the same strands.
      CurveSet kept;
      std::uint64_t state = 0x9e3779b97f4a7c15ull;
      for (std::size_t i = 0; i < c.ends.size(); ++i) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        if (static_cast<float>(state >> 40) / 16777216.0f < subsample) continue;
        for (std::uint32_t n = i ? c.ends[i - 1] : 0; n < c.ends[i]; ++n) {
          kept.positions.push_back(c.positions[n]);
          kept.radii.push_back(c.radii[n]);
        }
        kept.ends.push_back(static_cast<std::uint32_t>(kept.positions.size()));
      }
      c = std::move(kept);
    }
    CurveTubeOptions tubeOptions;
    tubeOptions.maxTriangles = std::min<std::uint64_t>(tubeOptions.maxTriangles, options_.maxTriangles);
    CurveTubes tubes = makeCurveTubes(c, tubeOptions);
    if (tubes.strandsKept == 0) {
      warn(cat(where, ": '", f, "' has no strand of three nodes or more; the primitive is skipped"));
      return kNoNode;
    }
    if (tubes.strandsKept < tubes.strandsUsable)
      warn(cat(where, ": '", f, "' has ", c.pieceCount(), " spline pieces, more than ", tubeOptions.maxTriangles,
               " triangles of tubes can draw; drawn with ", tubes.strandsKept, " of its ", tubes.strandsUsable, " strands"));
    if (std::size_t dropped = sanitizeGeometry(tubes.geometry, nullptr); dropped)
      warn(cat(where, ": ", dropped, " triangles of tubes with a position that is not finite were left out"));
    if (tubes.geometry.indices.empty()) {
      warn(cat(where, ": '", f, "' leaves no tube to draw; the primitive is skipped"));
      return kNoNode;
    }
    // Each primitive its own mesh: the same file with other settings is other tubes.
    return meshNode(cat("curves|", ++curvesMeshes_), fs::path(f).stem().string(),
                    std::make_shared<MeshGeometry>(std::move(tubes.geometry)));
  }

  // A mesh file's triangles that take the bsdf of one material index.
  struct MeshPart {
    std::int32_t material = 0;
    NodeId mesh = kNoNode;
  };

  // The mesh of a "mesh" primitive: with `split` (the primitive names several bsdfs), one part
  // per material index its triangles carry (a .wo3 file's; an OBJ file's are all 0), each a mesh
  // of its own; else one part, of the first triangle's index. Empty when the file is unusable.
  std::vector<MeshPart> loadMesh(const Value& p, const std::string& where, bool split) {
    std::string f = string(p, "file");
    if (f.empty()) {
      problem(where, "mesh without a \"file\"");
      return {};
    }
    bool smooth = false, recompute = false;
    if (const Value* v = p.find("smooth"); v && v->isBool()) smooth = v->asBool();
    if (const Value* v = p.find("recompute_normals"); v && v->isBool()) recompute = v->asBool();
    std::string key = cat(f, "|", smooth, recompute);
    const std::string partsKey = cat(key, "|", split);
    if (auto it = meshParts_.find(partsKey); it != meshParts_.end()) return it->second;
    auto path = resolveScenePath(base_, f);
    if (!path) {
      warn(cat(where, ": mesh file '", f, "' not found; the primitive is skipped"));
      return {};
    }
    std::vector<std::string> warnings;
    Result<MeshGeometry> g = Result<MeshGeometry>::failure("");
    std::vector<std::int32_t> materials;  // per triangle, wo3 only
    std::string ext = extensionLower(*path);
    if (ext == "obj") g = readObjGeometry(*path, &warnings, options_);
    else if (ext == "wo3") g = readWo3(*path, &materials);
    else g = Result<MeshGeometry>::failure(cat(path->string(), ": unsupported mesh format '.", ext, "' (obj or wo3)"));
    for (auto& w : warnings) out_.warnings.push_back(w);
    if (!g) {
      warn(cat(where, ": ", g.error(), "; the primitive is skipped"));
      return {};
    }
    MeshGeometry geom = std::move(g.value());
    if (!smooth) geom.normals.clear();  // flat shading
    else if (recompute) creasedNormals(geom);  // across the parts' seams
    else if (geom.normals.empty()) smoothNormals(geom);
    const std::string name = fs::path(f).stem().string();
    std::vector<MeshPart> parts;
    if (!split || materials.size() * 3 != geom.indices.size() ||
        std::all_of(materials.begin(), materials.end(), [&](std::int32_t m) { return m == materials.front(); })) {
      parts.push_back({materials.empty() ? 0 : materials.front(), meshNode(key, name, std::make_shared<MeshGeometry>(std::move(geom)))});
    } else {
      std::set<std::int32_t> indices(materials.begin(), materials.end());
      std::vector<std::uint32_t> remap(geom.positions.size(), UINT32_MAX);  // whole-mesh vertex -> the part's
      for (std::int32_t m : indices) {
        // The part's triangles with their vertices, renumbered.
        auto part = std::make_shared<MeshGeometry>();
        std::vector<std::uint32_t> used;
        for (std::size_t t = 0; t < materials.size(); ++t) {
          if (materials[t] != m) continue;
          for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = geom.indices[t * 3 + static_cast<std::size_t>(k)];
            if (remap[v] == UINT32_MAX) {
              remap[v] = static_cast<std::uint32_t>(part->positions.size());
              used.push_back(v);
              part->positions.push_back(geom.positions[v]);
              if (!geom.normals.empty()) part->normals.push_back(geom.normals[v]);
              if (!geom.uvs.empty()) part->uvs.push_back(geom.uvs[v]);
            }
            part->indices.push_back(remap[v]);
          }
        }
        for (std::uint32_t v : used) remap[v] = UINT32_MAX;
        parts.push_back({m, meshNode(cat(key, "|", m), cat(name, " [", m, "]"), std::move(part))});
      }
    }
    meshParts_[partsKey] = parts;
    return parts;
  }

  // Tungsten's binary mesh: uint64 vertex count, {pos, normal, uv} per vertex, uint64 triangle
  // count, {3 x uint32, int32 material} per triangle. `materials` gets the kept triangles' indices.
  Result<MeshGeometry> readWo3(const fs::path& path, std::vector<std::int32_t>* materials) {
    using R = Result<MeshGeometry>;
    auto data = readFile(path, options_.maxFileBytes);
    if (!data) return R::failure(data.error());
    const std::string& d = data.value();
    std::size_t pos = 0;
    auto u64 = [&](std::uint64_t* v) {
      if (pos + 8 > d.size()) return false;
      std::memcpy(v, d.data() + pos, 8);
      pos += 8;
      return true;
    };
    std::uint64_t nv = 0, nt = 0;
    if (!u64(&nv) || nv > (d.size() - pos) / 32) return R::failure(cat(path.string(), ": truncated or corrupt (vertex count)"));
    MeshGeometry g;
    g.positions.resize(nv);
    g.normals.resize(nv);
    g.uvs.resize(nv);
    for (std::uint64_t i = 0; i < nv; ++i) {
      float f[8];
      std::memcpy(f, d.data() + pos, 32);
      pos += 32;
      g.positions[i] = {f[0], f[1], f[2]};
      g.normals[i] = {f[3], f[4], f[5]};
      g.uvs[i] = {f[6], f[7]};
    }
    if (!u64(&nt) || nt > (d.size() - pos) / 16) return R::failure(cat(path.string(), ": truncated or corrupt (triangle count)"));
    if (nt > options_.maxTriangles) return R::failure(cat(path.string(), ": more than ", options_.maxTriangles, " triangles"));
    g.indices.resize(nt * 3);
    materials->resize(nt);
    for (std::uint64_t i = 0; i < nt; ++i) {
      std::memcpy(&g.indices[i * 3], d.data() + pos, 12);
      std::memcpy(&(*materials)[i], d.data() + pos + 12, 4);
      pos += 16;
    }
    std::size_t dropped = sanitizeGeometry(g, materials);
    if (dropped) warn(cat(path.filename().string(), ": dropped ", dropped, " invalid triangles"));
    if (g.indices.empty()) return R::failure(cat(path.string(), ": contains no triangles"));
    return g;
  }

  static float worldArea(const MeshGeometry& g, const Mat4& m) {
    double a = 0;
    for (std::size_t i = 0; i + 2 < g.indices.size(); i += 3) {
      Vec3 p0 = m.transformPoint(g.positions[g.indices[i]]);
      Vec3 p1 = m.transformPoint(g.positions[g.indices[i + 1]]);
      Vec3 p2 = m.transformPoint(g.positions[g.indices[i + 2]]);
      a += 0.5 * length(cross(p1 - p0, p2 - p0));
    }
    return static_cast<float>(a);
  }

  // The sky's frame is its transform's rotation (InfiniteSphere: _rotTransform, scale and position
  // dropped): R = Ry(-ry) Rx(rx) Rz(rz) times the basis of any axes given. Its turn about y is
  // the environment's rotation, the rest (tilts, an "up") its orientation.
  void environmentFromEmission(const Value& p, const std::string& where) {
    Environment& e = out_.scene.environment;
    e.intensity = 1;
    e.rotation = 0;
    e.orientation = Mat4{};
    if (const Value* t = p.find("transform")) {
      Vec3 rot{0.0f};
      if (t->isObject()) vec3(*t, "rotation", &rot, where);
      e.rotation = radians(-rot.y);
      e.orientation = (Mat4::rotateY(radians(rot.y)) * transform(t, where)).rotationPart();
    }
    const Value* em = p.find("emission");
    if (!em) em = p.find("radiance");
    float powerScale = 1;
    if (!em) {
      em = p.find("power");
      powerScale = 1 / (4 * kPi);
    }
    if (!em) {
      e.type = EnvironmentType::Constant;
      e.color = Vec3{1.0f};
      return;
    }
    quietMissingTexture_ = true;
    TextureRef t = texture(*em, where + ".emission", false);
    quietMissingTexture_ = false;
    if (t.isTexture) {
      e.type = EnvironmentType::Map;
      e.map = t.texture;
      e.color = t.constant * powerScale;
      const Texture* tex = out_.scene.texture(t.texture);
      if (tex && tex->kind == TextureKind::File && !resolveScenePath(base_, tex->path.string()))
        warn(cat("environment map '", tex->path.string(), "' is missing: the scene is lit by a constant sky of radiance ",
                 luminance(e.color), " instead"));
    } else {
      e.type = EnvironmentType::Constant;
      e.color = t.constant * powerScale;
    }
  }

  void environmentEntry(const Value& v, const std::string& where) {
    if (!v.isObject()) return;
    std::string type = string(v, "type");
    if (type == "envmap" || type == "infinite_sphere") {
      environmentFromEmission(v, where);
    } else {
      warn(cat(where, ": emitter type '", type, "' is not supported; skipped"));
    }
  }

  void primitive(const Value& p, const std::string& where) {
    if (!p.isObject()) return problem(where, "expected an object");
    std::string type = string(p, "type");
    if (type.empty()) return problem(where, "primitive without a \"type\"");
    Scene& s = out_.scene;
    Vec3 scale;
    const Value* tv = p.find("transform");

    if (type == "infinite_sphere") {
      environmentFromEmission(p, where);
      return;
    }
    if (type == "skydome") {
      float intensity = 2;
      number(p, "intensity", &intensity, where);
      s.environment.type = EnvironmentType::Sky;
      s.environment.intensity = intensity * 0.5f;
      // Tungsten's dome is the sky model's upper half; below the horizon it is black.
      s.environment.ground = Vec3{0.0f};
      warn(cat(where, ": the physical skydome is approximated by a gradient sky, black below the horizon as Tungsten's"));
      return;
    }
    if (type == "infinite_sphere_cap") {
      // A cap of the sky is a sun whose disc is the cap: its radiance is the cap's, which a
      // directional light of the cap's solid angle times that radiance gives (Light::angularRadius).
      Mat4 m = transform(tv, where);
      // Tied to a skydome (Tungsten's InfiniteSphereCap::prepareForRender): the cap is the dome's
      // sun, around the dome's +y, whatever the cap's own transform says.
      if (std::string dome = string(p, "skydome"); !dome.empty() && primitives_) {
        if (std::optional<Mat4> d = transformOfPrimitive(*primitives_, dome))
          m = *d;
        else
          warn(cat(where, ": skydome '", dome, "' names no primitive; the cap keeps its own direction"));
      }
      float cap = 10;
      number(p, "cap_angle", &cap, where);
      Vec3 radiance{1.0f};
      if (const Value* e = p.find("emission")) radiance = texture(*e, where, false).constant;
      Light l;
      l.id = s.newId();
      l.name = string(p, "name", "sun");
      l.type = LightType::Directional;
      l.direction = -normalize(m.transformVector({0, 1, 0}));
      l.angularRadius = std::isfinite(cap) ? std::clamp(radians(cap), 0.0f, kPi / 2) : radians(10.0f);
      if (!(cap >= 0 && cap <= 90)) warn(cat(where, ": cap_angle ", cap, " is taken as ", degrees(l.angularRadius), " degrees"));
      float solidAngle = 2 * kPi * (1 - std::cos(l.angularRadius));
      // Given as power, its radiance is the power over the cap's solid angle (Tungsten's
      // InfiniteSphereCap::powerToRadianceFactor).
      if (const Value* pw = p.find("power"); pw && !p.find("emission") && solidAngle > 0)
        radiance = texture(*pw, where + ".power", false).constant / solidAngle;
      float power = maxComponent(radiance) * solidAngle;
      l.color = power > 0 ? radiance / maxComponent(radiance) : Vec3{1.0f};
      l.intensity = power;
      s.lights.push_back(l);
      return;
    }

    if (type == "point") {
      // A point light: Tungsten's emission is its intensity (W/sr), its power spreads over 4 pi.
      Mat4 m = transform(tv, where);
      Vec3 intensity{0.0f};
      if (const Value* e = p.find("emission")) intensity = texture(*e, where + ".emission", false).constant;
      if (const Value* pw = p.find("power")) intensity = texture(*pw, where + ".power", false).constant / (4 * kPi);
      if (!ok()) return;
      Light l;
      l.id = s.newId();
      l.name = string(p, "name", cat("point ", s.lights.size() + 1));
      l.type = LightType::Point;
      l.position = m.transformPoint({0, 0, 0});
      l.intensity = maxComponent(intensity);
      l.color = l.intensity > 0 ? intensity / l.intensity : Vec3{1.0f};
      if (!std::isfinite(l.intensity) || !isFinite(l.position)) {
        warn(cat(where, ": the point light's position or intensity is not finite; skipped"));
        return;
      }
      s.lights.push_back(l);
      return;
    }

    std::vector<MeshPart> parts;  // one for every shape but a mesh with several material indices
    float emissionCone = 90;      // Material::emissionCone, a disk's cone_angle
    Mat4 xf = transform(tv, where, &scale, type == "quad" || type == "disk");
    if (!ok()) return;
    const Value* bsdfs = p.find("bsdf");
    const bool byIndex = bsdfs && bsdfs->isArray() && !bsdfs->asArray().empty();
    if (type == "mesh") {
      parts = loadMesh(p, where, byIndex && bsdfs->asArray().size() > 1);
    } else if (type == "quad" || type == "cube") {
      parts.push_back({0, meshNode(type, type, shape(type))});
    } else if (type == "disk") {
      xf = tungstenDiskFrame(xf, scale);
      // Tungsten's disk emits only within this cone about its normal (Disk::evalDirect), and its
      // light samples outside it find nothing (Disk::sampleDirect). Wider than the hemisphere, its
      // back would glow too, but only for paths that hit it: not rendered.
      if (number(p, "cone_angle", &emissionCone, where) && std::abs(emissionCone) > 90) {
        warn(cat(where, ": cone_angle ", emissionCone, " is wider than the hemisphere; only the front emits, as with 90"));
        emissionCone = 90;
      }
      emissionCone = std::abs(emissionCone);  // Tungsten takes its cosine
      parts.push_back({0, meshNode(type, type, shape(type))});
    } else if (type == "sphere") {
      // Tungsten's sphere radius is the largest scale; the shape stays round.
      float r = std::max({std::abs(scale.x), std::abs(scale.y), std::abs(scale.z)});
      Vec3 safe{scale.x != 0 ? r / scale.x : 0, scale.y != 0 ? r / scale.y : 0, scale.z != 0 ? r / scale.z : 0};
      xf = xf * Mat4::scale(safe);
      parts.push_back({0, meshNode(type, type, shape(type))});
    } else if (type == "cylinder") {
      // Round too: the radius is half the larger of the x and z scales, the height the y scale.
      float r = std::max(std::abs(scale.x), std::abs(scale.z));
      xf = xf * Mat4::scale({scale.x != 0 ? r / scale.x : 0, 1, scale.z != 0 ? r / scale.z : 0});
      bool capped = true;
      if (const Value* c = p.find("capped"); c && c->isBool()) capped = c->asBool();
      std::string kind = capped ? "cylinder" : "open cylinder";
      parts.push_back({0, meshNode(kind, "cylinder", shape(kind))});
    } else if (type == "curves") {
      NodeId mesh = curves(p, where);
      if (mesh == kNoNode) return;
      parts.push_back({0, mesh});
    } else {
      warn(cat(where, ": primitive type '", type, "' is not supported; skipped"));
      return;
    }
    if (!ok() || parts.empty()) return;
    if (!xf.isFinite() || xf.inverse().m[3][3] == 0.0f) {
      warn(cat(where, ": transform is degenerate; the primitive is skipped"));
      return;
    }
    // Tungsten takes a mesh's and a quad's front from their winding in world space (a mesh's
    // vertices are transformed before Embree sees them, a quad's normal is the cross product of
    // its transformed edges); ours is the object's winding carried by the normal matrix, which a
    // mirroring transform turns the other way. So a mirrored one is wound the other way, and its
    // light shines, its glass is entered and its back faces are culled on Tungsten's side.
    // (Tungsten's other shapes face out, or along their transformed axis, as ours do.)
    if ((type == "mesh" || type == "quad") && xf.linearDeterminant() < 0)
      for (MeshPart& part : parts) part.mesh = mirroredMesh(part.mesh, type == "quad");

    // A bump map belongs to the primitive in Tungsten and to the material here (as emission
    // does): the primitive gets its own copy of its bsdf. A constant has no slope.
    NodeId bumpTexture = kNoNode;
    float bumpStrength = 1;
    if (const Value* bump = p.find("bump")) {
      TextureRef t = texture(*bump, where + ".bump", true);
      if (!ok()) return;
      number(p, "bump_strength", &bumpStrength, where);
      bumpTexture = t.texture;
      bumpStrength *= t.constant.x;  // a bitmap's scale
    }
    Vec3 emission{0.0f};
    NodeId emissionTexture = kNoNode;
    bool emissive = false;
    if (const Value* e = p.find("emission")) {
      TextureRef t = texture(*e, where + ".emission", false);
      emission = t.constant;
      emissionTexture = t.texture;
      emissive = true;
    }
    if (const Value* pw = p.find("power")) {
      TextureRef t = texture(*pw, where + ".power", false);
      float area = 0;  // the whole primitive's: its power spreads over every part
      for (const MeshPart& part : parts)
        if (const Mesh* mm = s.mesh(part.mesh); mm && mm->geometry) area += worldArea(*mm->geometry, xf);
      emission = area > 0 ? t.constant / (kPi * area) : Vec3{0.0f};
      emissionTexture = t.texture;
      emissive = true;
    }

    // An array names one bsdf per material index (Tungsten's TriangleMesh: a triangle's index
    // picks its bsdf); an index past the array's end takes its last entry.
    if (byIndex && bsdfs->asArray().size() > 1 && type != "mesh")
      warn(cat(where, ": ", bsdfs->asArray().size(), " bsdfs by material index on a ", type, "; it takes the first"));
    for (const MeshPart& part : parts) {
      const std::size_t index = byIndex ? static_cast<std::size_t>(std::clamp<std::int64_t>(part.material, 0,
                                                                     static_cast<std::int64_t>(bsdfs->asArray().size()) - 1))
                                        : 0;
      const Value* b = byIndex ? &bsdfs->asArray()[index] : bsdfs;
      const std::string bsdfWhere = byIndex ? cat(where, ".bsdf[", index, "]") : where + ".bsdf";
      Material mat;
      mat.albedo = Vec3{1.0f};
      if (b) {
        mat = bsdf(*b, bsdfWhere, 0, emissive);
        if (!ok()) return;
      } else if (type == "curves") {
        hairFibre(json::Value(json::Object{}), bsdfWhere, mat);  // Tungsten's curves default to hair
      }
      const bool named = b && b->isString();
      NodeId materialId = kNoNode;
      if (bumpTexture != kNoNode) {
        mat.bumpTexture = bumpTexture;
        mat.bumpStrength = bumpStrength;
      }
      // A medium inside glass or a boundary belongs to the primitive in Tungsten and to the
      // material here. The one outside (ext_medium) is where the path comes from, which it
      // remembers, so it needs nothing, if something holds it inside.
      std::string medium;
      if (const std::string name = string(p, "int_medium"); !name.empty() && media_.count(name)) {
        if (holdsMedium(mat.type)) {
          medium = name;
          const Filling& f = media_[name];
          mat.interiorAbsorption = f.absorption;
          mat.interiorScattering = f.scattering;
          mat.interiorAnisotropy = f.anisotropy;
        } else {
          warn(cat(where, ": the medium '", name, "' is rendered only inside glass or a forward boundary (an int_medium); here light passes through it"));
        }
      }
      if (const std::string name = string(p, "ext_medium"); !name.empty() && media_.count(name)) {
        outside_.emplace_back(where, name);  // warned of once every primitive is read, if nothing holds it
        if (mat.type == MaterialType::Boundary && !medium.empty())
          warn(cat(where, ": a boundary of '", medium, "' inside the medium '", name,
                   "': a path inside it is in '", medium, "' alone, but its shadow rays count both"));
      }
      if (!medium.empty()) {
        inside_.insert(medium);
        holders_.emplace_back(where, string(p, "ext_medium"));
      }
      if ((bumpTexture != kNoNode || !medium.empty()) && !emissive) {
        // Primitives naming the same bsdf with the same bump and medium share one copy; an
        // inline bsdf is the primitive's own (two unnamed ones must not meet under the empty name).
        auto key = std::make_tuple(mat.name, bumpTexture, bumpStrength, medium);
        if (auto it = bumped_.find(key); named && it != bumped_.end()) {
          materialId = it->second;
        } else {
          if (named) copied_.insert(mat.id);
          Material m = mat;
          m.id = s.newId();
          m.name = cat(mat.name.empty() ? where : mat.name, medium.empty() ? " (bump)" : cat(" (", medium, ")"));
          s.materials.push_back(m);
          materialId = m.id;
          if (named) bumped_[key] = m.id;
        }
      } else if (emissive) {
        // Emission belongs to the primitive in Tungsten and to the material here: give each
        // emitter its own copy of its bsdf.
        if (named) copied_.insert(mat.id);
        Material m = mat;
        m.id = s.newId();
        m.name = cat(mat.name.empty() ? std::string("emitter") : mat.name, " (", string(p, "name", cat("light ", ++emitters_)), ")");
        m.emission = max(emission, Vec3{0.0f});
        m.emissionTexture = emissionTexture;
        m.emissionCone = emissionCone;
        s.materials.push_back(m);
        materialId = m.id;
      } else if (!mat.name.empty() && named_.count(mat.name) && named) {
        materialId = named_[mat.name].id;
      } else {
        Material m = mat;
        m.id = s.newId();
        if (m.name.empty()) m.name = cat(where, " material");
        s.materials.push_back(m);
        materialId = m.id;
      }

      Object o;
      o.id = s.newId();
      const Mesh* mm = s.mesh(part.mesh);
      o.name = string(p, "name", mm ? mm->name : type);
      if (parts.size() > 1) o.name = cat(o.name, " [", part.material, "]");
      o.mesh = part.mesh;
      o.material = materialId;
      o.transform = xf;
      // Only Tungsten's meshes read it (its TriangleMesh); its analytic shapes are hit from both sides.
      if (const Value* v = p.find("backface_culling"); type == "mesh" && v && v->isBool()) o.cullBackFaces = v->asBool();
      // Tungsten's curves are the half of a tube that faces the ray: a tube's far side lets
      // every ray through, so that light scattered through a fibre leaves it.
      if (type == "curves") o.cullBackFaces = true;
      s.objects.push_back(o);
    }
  }

  fs::path file_;
  fs::path base_;
  ImportOptions options_;
  ImportedScene out_;
  std::string error_;
  std::map<std::string, Material> named_;
  std::string focusPivot_;  // the thin lens camera's focus_pivot
  const Value* primitives_ = nullptr;  // the file's primitives, while they are imported
  std::map<std::string, NodeId> textures_;
  std::set<std::string> missingWarned_;
  bool quietMissingTexture_ = false;
  std::map<std::string, NodeId> meshIds_;
  std::map<NodeId, NodeId> mirroredOf_;  // a mesh -> its copy wound the other way
  std::map<std::string, std::vector<MeshPart>> meshParts_;  // a mesh file's parts, by loadMesh's key
  std::map<std::string, std::shared_ptr<const MeshGeometry>> shapes_;
  int emitters_ = 0;
  int curvesMeshes_ = 0;
  std::set<NodeId> copied_;  // named bsdfs some primitive took a copy of (dropReplacedBsdfs)
  // (bsdf, bump texture, strength, medium) -> its copy
  std::map<std::tuple<std::string, NodeId, float, std::string>, NodeId> bumped_;
  // A homogeneous medium, as the glass or boundary it fills holds it (Material::interiorAbsorption and on).
  struct Filling {
    Vec3 absorption{0.0f}, scattering{0.0f};
    float anisotropy = 0.0f;
  };
  // Tungsten's homogeneous medium: sigma_a and sigma_s times density, and its phase function
  // (isotropic by default, as in Tungsten's Medium). Read leniently: nothing for a medium that is
  // not understood, with the reason in `why`; the caller names it in a warning and leaves it out.
  // Tungsten's newer media name their transmittance, and write {"type": "exponential"}, the
  // homogeneous medium's own, into every file they save; no key means the same.
  static bool exponentialTransmittance(const Value* t) {
    if (!t) return true;
    if (t->isString()) return t->asString() == "exponential";
    if (!t->isObject()) return false;
    const Value* type = t->find("type");
    return type && type->isString() && type->asString() == "exponential";
  }
  std::optional<Filling> mediumFilling(const Value& medium, const std::string& name, std::string* why) {
    Vec3 sigmaA{0.0f}, sigmaS{0.0f};
    float density = 1;
    const Value *a = medium.find("sigma_a"), *sc = medium.find("sigma_s"), *d = medium.find("density");
    const std::string type = string(medium, "type");
    if (type != "homogeneous") *why = cat("a ", type.empty() ? "medium of no type" : cat(type, " medium"), "; only homogeneous ones are");
    else if (!exponentialTransmittance(medium.find("transmittance"))) *why = "a non-exponential transmittance";
    else if (!((!a || json::toVec3(*a, &sigmaA)) && (!sc || json::toVec3(*sc, &sigmaS)) && (!d || json::toFloat(*d, &density))))
      *why = "sigma_a, sigma_s or density is not a number";
    if (!why->empty()) return std::nullopt;
    Filling f{max(sigmaA * density, Vec3{0.0f}), max(sigmaS * density, Vec3{0.0f}), 0.0f};
    if (!(density >= 0) || !isFinite(f.absorption) || !isFinite(f.scattering)) {
      *why = "a negative or infinite density or coefficient";
      return std::nullopt;
    }
    // Tungsten writes its default, 1024, into every medium it saves: only a tighter limit matters.
    float bounces = 0;
    if (const Value* v = medium.find("max_bounces"); v && json::toFloat(*v, &bounces) && bounces < out_.scene.settings.maxBounces)
      warn(cat("media: '", name, "': its max_bounces of ", bounces, " is not kept (the scene's limit of ",
               out_.scene.settings.maxBounces, " bounces applies)"));
    if (const Value* phase = medium.find("phase_function"); phase && maxComponent(f.scattering) > 0) {
      // An object with its type (Tungsten's form); the type alone as a string is read too.
      const std::string phaseType = phase->isString() ? phase->asString() : phase->isObject() ? string(*phase, "type") : "";
      float g = 0;
      if (phaseType == "henyey_greenstein") {
        const Value* v = phase->isObject() ? phase->find("g") : nullptr;
        if (v && json::toFloat(*v, &g) && std::isfinite(g)) {
          f.anisotropy = std::clamp(g, -0.99f, 0.99f);
          if (f.anisotropy != g) warn(cat("media: '", name, "': the phase function's g of ", g, " is rendered as ", f.anisotropy));
        } else if (v) {
          warn(cat("media: '", name, "': the phase function's g is not a number; rendered isotropic"));
        }
      } else if (phaseType == "rayleigh") {
        warn(cat("media: '", name, "': the Rayleigh phase function is rendered isotropic (the same mean cosine, 0)"));
      } else if (phaseType != "isotropic") {
        warn(cat("media: '", name, "': unknown phase function '", phaseType, "', rendered isotropic"));
      }
    }
    return f;
  }
  std::map<std::string, Filling> media_;  // homogeneous media by name
  std::set<std::string> mediaNamed_;      // every medium's name, rendered or not
  std::set<std::string> inside_;  // the media some glass or boundary holds
  std::vector<std::pair<std::string, std::string>> holders_;  // where a medium is held, and the ext_medium named there
  std::string cameraMedium_;      // the camera's
  std::vector<std::pair<std::string, std::string>> outside_;  // where an ext_medium is named, and the name
};

}  // namespace

Result<ImportedScene> importTungsten(const fs::path& file, const ImportOptions& options) {
  return TungstenImporter(file, options).run();
}

}  // namespace retile
