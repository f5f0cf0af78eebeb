// Tungsten bsdfs, textures and media (io/tungsten_importer.h).
#include "io/tungsten_importer.h"

namespace retile::tungsten {

void TungstenImporter::underAlbedo(Material& p, const TextureRef& albedo, int depth) {
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

int TungstenImporter::chainLength(const Material& m) const {
  int n = 1;
  for (const Material* at = &m; at->blendWith != kNoNode && n < 16; ++n) {
    at = out_.scene.material(at->blendWith);
    if (!at) break;
  }
  return n;
}

void TungstenImporter::cutChain(Material& m, int keep) {
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

NodeId TungstenImporter::fileTexture(const std::string& ref, TextureColorSpace cs, bool interpolate, bool clampToEdge) {
  std::string key = cat(ref, "|", static_cast<int>(cs), "|", interpolate, "|", clampToEdge);
  if (auto it = textures_.find(key); it != textures_.end()) return it->second;
  Texture t;
  t.id = out_.scene.newId();
  t.kind = TextureKind::File;
  t.path = ref;
  t.name = fs::path(ref).filename().string();
  t.colorSpace = cs;
  t.whenMissing = MissingTexture::BlackAndWhite;
  t.interpolate = interpolate;
  t.clampToEdge = clampToEdge;
  // One warning per missing file, however many materials use it and in whichever role (the checker
  // stands in as a colour, an alpha or a bump alike); the environment says its own.
  if (!resolveScenePath(base_, ref) && !quietMissingTexture_ && missingWarned_.insert(ref).second)
    warn(cat("texture '", ref,
             "' not found; until the file is there it renders as Tungsten renders a missing texture, a black and white checker"));
  out_.scene.textures.push_back(t);
  textures_[key] = t.id;
  return t.id;
}

TextureRef TungstenImporter::texture(const Value& v, const std::string& where, bool data) {
  TextureRef r;
  if (json::toVec3(v, &r.constant)) return r;
  if (v.isString()) {
    r.isTexture = true;
    r.constant = Vec3{1.0f};
    r.texture = fileTexture(v.asString(), data ? TextureColorSpace::Raw : TextureColorSpace::Gamma22);
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
    r.texture = fileTexture(f,
                            data    ? TextureColorSpace::Raw
                            : gamma ? TextureColorSpace::Gamma22
                                    : TextureColorSpace::Linear,
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
    t.truncatedCells = true;
    out_.scene.textures.push_back(t);
    r.isTexture = true;
    r.texture = t.id;
    return r;
  }
  warn(cat(where, ": texture type '", type, "' is not supported; using white"));
  return r;
}

Material TungstenImporter::bsdf(const Value& v, const std::string& where, int depth, bool emitter) {
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

// A bsdf named by a string: the named one, or a stand-in for an undefined name (warned of once).
Material TungstenImporter::namedBsdf(const Value& v, const std::string& where, bool emitter, Material m) {
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

// Tungsten's transparency: its base bsdf, cut out by alpha.
Material TungstenImporter::transparencyBsdf(const Value& v, const std::string& where, int depth, Material m) {
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

// Tungsten's coats: a dielectric layer over a substrate bsdf (Material::coatIor).
Material TungstenImporter::coatBsdf(const Value& v, const std::string& type, const std::string& where, int depth, Material m) {
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

// Tungsten's blend of two bsdfs (Material::blendWith).
Material TungstenImporter::mixedBsdf(const Value& v, const std::string& where, int depth, Material m) {
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
    warn(cat(where,
             ".bsdf0: a blend in a blend whose ratio is a texture or whose bsdf1 is a blend too is "
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

// The bsdfs that map onto one material type, with the parameters they share (albedo, roughness,
// distribution).
Material TungstenImporter::typedBsdf(const Value& v, const std::string& type, const std::string& where, Material m) {
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
      if (named.size() > palik.size() && named.ends_with(palik) && conductorIor(named.substr(0, named.size() - palik.size()), &e2, &k2))
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
    m.tintsReflection = true;
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
      m.tintsReflection = false;
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
    if (const Value* e = v.find("enable_interference"); e && e->isBool() && e->asBool())
      m.filmThickness = std::max(500.0f * thickness, 0.0f);
    m.tintsReflection = true;
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
    m.diffuseRatio = 0.2f;                              // Tungsten's default
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

Material TungstenImporter::bsdfOwn(const Value& v, const std::string& where, int depth, bool emitter) {
  Material m;
  m.albedo = Vec3{1.0f};  // Tungsten's default albedo
  if (v.isString()) return namedBsdf(v, where, emitter, m);
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
  if (type == "transparency") return transparencyBsdf(v, where, depth, m);
  if (type == "smooth_coat" || type == "rough_coat") return coatBsdf(v, type, where, depth, m);
  if (type == "mixed") return mixedBsdf(v, where, depth, m);
  return typedBsdf(v, type, where, m);
}

void TungstenImporter::hairFibre(const Value& v, const std::string& where, Material& m) {
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

bool TungstenImporter::exponentialTransmittance(const Value* t) {
  if (!t) return true;
  if (t->isString()) return t->asString() == "exponential";
  if (!t->isObject()) return false;
  const Value* type = t->find("type");
  return type && type->isString() && type->asString() == "exponential";
}

std::optional<TungstenImporter::Filling> TungstenImporter::mediumFilling(const Value& medium, const std::string& name, std::string* why) {
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
    warn(cat("media: '", name, "': its max_bounces of ", bounces, " is not kept (the scene's limit of ", out_.scene.settings.maxBounces,
             " bounces applies)"));
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

}  // namespace retile::tungsten
