// Tungsten scene files: the scene, its camera and settings, and the import as a whole
// (io/tungsten_importer.h).
#include "io/tungsten_importer.h"

namespace retile::tungsten {

Result<ImportedScene> TungstenImporter::run() {
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
  s.settings.shading = !consistency && twoSided ? ShadingConvention::Unchecked : ShadingConvention::Consistent;
  s.settings.roulette = Roulette::LowThroughput;
  s.settings.rayOffset = RayOffset::FixedEpsilon;
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
      warn(
          "integrator: enable_volume_light_sampling false is not rendered; lights are sampled from media too, which gives the same picture "
          "with less noise, except that point lights and suns, which Tungsten's media then never see, light them here");
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
        warn(cat(where, ": the medium '", name,
                 "' around it is rendered only inside glass or a forward boundary (an int_medium) or around the camera, and neither holds "
                 "it; light passes through it"));
  }
  // Not Tungsten's own key, but Bitterli's living room names its sky this way (an envmap; the
  // room has no other light). Tungsten renders these files without a `constant` entry: the
  // spaceship's constant sky of 0.3 is black in Tungsten's render, and lit the backdrop 60 to
  // 150 times brighter here when it was honoured. So only environment maps are taken from it.
  if (const Value* e = root.find("emissions"); e && e->isArray() && ok())
    for (std::size_t i = 0; i < e->asArray().size(); ++i) {
      const Value& entry = e->asArray()[i];
      if (entry.isObject() && string(entry, "type") == "constant") {
        warn(cat("emissions[", i,
                 "]: a constant sky outside \"primitives\" is left out, as Tungsten leaves it out "
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

void TungstenImporter::focusOn(const Value& primitives) {
  if (std::optional<Mat4> m = transformOfPrimitive(primitives, focusPivot_)) {
    float d = length(m->transformPoint({0, 0, 0}) - out_.scene.camera.position);
    if (std::isfinite(d) && d > 0) out_.scene.camera.focusDistance = d;
    return;
  }
  warn(cat("camera: focus_pivot '", focusPivot_, "' names no primitive; focused at focus_distance"));
}

std::optional<Mat4> TungstenImporter::transformOfPrimitive(const Value& primitives, const std::string& name) {
  for (std::size_t i = 0; i < primitives.asArray().size(); ++i) {
    const Value& p = primitives.asArray()[i];
    if (!p.isObject() || string(p, "name") != name) continue;
    return transform(p.find("transform"), cat("primitives[", i, "].transform"));
  }
  return std::nullopt;
}

void TungstenImporter::dropReplacedBsdfs() {
  Scene& s = out_.scene;
  std::set<NodeId> used;
  for (const Object& o : s.objects) used.insert(o.material);
  for (const Material& m : s.materials) used.insert(m.blendWith);
  std::erase_if(s.materials, [&](const Material& m) { return copied_.count(m.id) && !used.count(m.id); });
}

void TungstenImporter::dropUnusedTextures() {
  Scene& s = out_.scene;
  std::set<NodeId> used{s.environment.map};
  for (const Material& m : s.materials)
    for (NodeId t : m.textures()) used.insert(t);
  std::erase_if(s.textures, [&](const Texture& t) { return !used.count(t.id); });
}

void TungstenImporter::dropUnusedMeshes() {
  Scene& s = out_.scene;
  std::set<NodeId> used;
  for (const Object& o : s.objects) used.insert(o.mesh);
  std::erase_if(s.meshes, [&](const Mesh& m) { return !used.count(m.id); });
}

Result<ImportedScene> TungstenImporter::fail(const std::string& what) {
  if (error_.empty()) error_ = cat(file_.string(), ": ", what);
  return Result<ImportedScene>::failure(error_);
}

void TungstenImporter::problem(const std::string& where, const std::string& what) {
  if (error_.empty()) error_ = cat(file_.string(), ": ", where, ": ", what);
}

bool TungstenImporter::number(const Value& obj, const char* key, float* out, const std::string& where) {
  const Value* v = obj.find(key);
  if (!v) return false;
  if (!json::toFloat(*v, out)) {
    problem(where, cat(key, ": expected a finite number"));
    return false;
  }
  return true;
}

bool TungstenImporter::vec3(const Value& obj, const char* key, Vec3* out, const std::string& where) {
  const Value* v = obj.find(key);
  if (!v) return false;
  if (!json::toVec3(*v, out)) {
    problem(where, cat(key, ": expected a number or three numbers"));
    return false;
  }
  return true;
}

std::string TungstenImporter::string(const Value& obj, const char* key, const std::string& fallback) {
  const Value* v = obj.find(key);
  return v && v->isString() ? v->asString() : fallback;
}

Mat4 TungstenImporter::rotation(Vec3 deg) {
  return Mat4::rotateY(radians(-deg.y)) * Mat4::rotateX(radians(deg.x)) * Mat4::rotateZ(radians(deg.z));
}

Mat4 TungstenImporter::transform(const Value* v, const std::string& where, Vec3* scaleOut, bool flatY) {
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

void TungstenImporter::camera(const Value& c) {
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
  s.settings.filterSampling = FilterSampling::SteppedTable;
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

}  // namespace retile::tungsten

namespace retile {

Result<ImportedScene> importTungsten(const std::filesystem::path& file, const ImportOptions& options) {
  return tungsten::TungstenImporter(file, options).run();
}

}  // namespace retile
