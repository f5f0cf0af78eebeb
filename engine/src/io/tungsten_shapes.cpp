// Tungsten shapes, meshes, curves and primitives (io/tungsten_importer.h).
#include "io/tungsten_importer.h"

namespace retile::tungsten {

std::shared_ptr<const MeshGeometry> TungstenImporter::withArea(std::shared_ptr<const MeshGeometry> g, float area) {
  const float meshArea = worldArea(*g, Mat4::identity());
  if (!(meshArea > 0)) return g;
  auto scaled = std::make_shared<MeshGeometry>(*g);
  const float s = std::sqrt(area / meshArea);
  for (Vec3& p : scaled->positions) p = p * s;
  return scaled;
}

std::shared_ptr<const MeshGeometry> TungstenImporter::tungstenSphere() {
  auto g = std::make_shared<MeshGeometry>(*makeSphere());
  for (Vec3& p : g->positions) p = Vec3{-p.x, p.z, p.y};
  for (Vec3& n : g->normals) n = Vec3{-n.x, n.z, n.y};
  return g;
}

std::shared_ptr<const MeshGeometry> TungstenImporter::tungstenQuad() {
  auto g = std::make_shared<MeshGeometry>(*makeQuad());
  for (Vec2& uv : g->uvs) uv.y = 1 - uv.y;
  return g;
}

std::shared_ptr<const MeshGeometry> TungstenImporter::tungstenCube() {
  auto g = std::make_shared<MeshGeometry>(*makeCube());
  for (std::size_t i = 0; i < g->positions.size(); ++i) {
    const Vec3 n = g->normals[i], p = g->positions[i];
    const int dim = std::abs(n.x) > 0.5f ? 0 : std::abs(n.y) > 0.5f ? 1 : 2;
    const float c[3] = {p.x, p.y, p.z};
    g->uvs[i] = {c[(dim + 1) % 3] + 0.5f, c[(dim + 2) % 3] + 0.5f};
  }
  return g;
}

std::shared_ptr<const MeshGeometry> TungstenImporter::tungstenCylinder(bool capped) {
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

std::shared_ptr<const MeshGeometry> TungstenImporter::tungstenDisk(int segments) {
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

Mat4 TungstenImporter::tungstenDiskFrame(const Mat4& xf, Vec3 scale) {
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

std::shared_ptr<const MeshGeometry> TungstenImporter::shape(const std::string& kind) {
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

NodeId TungstenImporter::meshNode(const std::string& key, const std::string& name, std::shared_ptr<const MeshGeometry> g) {
  if (auto it = meshIds_.find(key); it != meshIds_.end()) return it->second;
  Mesh m;
  m.id = out_.scene.newId();
  m.name = name;
  m.geometry = std::move(g);
  out_.scene.meshes.push_back(m);
  meshIds_[key] = m.id;
  return m.id;
}

NodeId TungstenImporter::mirroredMesh(NodeId mesh, bool turnNormals) {
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

void TungstenImporter::smoothNormals(MeshGeometry& g) {
  g.normals.assign(g.positions.size(), Vec3{0.0f});
  for (std::size_t i = 0; i + 2 < g.indices.size(); i += 3) {
    Vec3 a = g.positions[g.indices[i]], b = g.positions[g.indices[i + 1]], c = g.positions[g.indices[i + 2]];
    Vec3 n = cross(b - a, c - a);  // area-weighted
    for (int k = 0; k < 3; ++k) g.normals[g.indices[i + static_cast<std::size_t>(k)]] += n;
  }
  for (Vec3& n : g.normals) n = normalize(n);
}

void TungstenImporter::creasedNormals(MeshGeometry& g) {
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

NodeId TungstenImporter::curves(const Value& p, const std::string& where) {
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
  return meshNode(cat("curves|", ++curvesMeshes_), fs::path(f).stem().string(), std::make_shared<MeshGeometry>(std::move(tubes.geometry)));
}

std::vector<TungstenImporter::MeshPart> TungstenImporter::loadMesh(const Value& p, const std::string& where, bool split) {
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
  if (!smooth) geom.normals.clear();         // flat shading
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

Result<MeshGeometry> TungstenImporter::readWo3(const fs::path& path, std::vector<std::int32_t>* materials) {
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

float TungstenImporter::worldArea(const MeshGeometry& g, const Mat4& m) {
  double a = 0;
  for (std::size_t i = 0; i + 2 < g.indices.size(); i += 3) {
    Vec3 p0 = m.transformPoint(g.positions[g.indices[i]]);
    Vec3 p1 = m.transformPoint(g.positions[g.indices[i + 1]]);
    Vec3 p2 = m.transformPoint(g.positions[g.indices[i + 2]]);
    a += 0.5 * length(cross(p1 - p0, p2 - p0));
  }
  return static_cast<float>(a);
}

void TungstenImporter::environmentFromEmission(const Value& p, const std::string& where) {
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
      warn(cat("environment map '", tex->path.string(), "' is missing: the scene is lit by a constant sky of radiance ", luminance(e.color),
               " instead"));
  } else {
    e.type = EnvironmentType::Constant;
    e.color = t.constant * powerScale;
  }
}

void TungstenImporter::environmentEntry(const Value& v, const std::string& where) {
  if (!v.isObject()) return;
  std::string type = string(v, "type");
  if (type == "envmap" || type == "infinite_sphere") {
    environmentFromEmission(v, where);
  } else {
    warn(cat(where, ": emitter type '", type, "' is not supported; skipped"));
  }
}

// Tungsten's skydome (the Hosek-Wilkie sky model), drawn as a gradient sky, with a warning.
void TungstenImporter::skydome(const Value& p, const std::string& where) {
  Scene& s = out_.scene;
  float intensity = 2;
  number(p, "intensity", &intensity, where);
  s.environment.type = EnvironmentType::Sky;
  s.environment.intensity = intensity * 0.5f;
  // Tungsten's dome is the sky model's upper half; below the horizon it is black.
  s.environment.ground = Vec3{0.0f};
  warn(cat(where, ": the physical skydome is approximated by a gradient sky, black below the horizon as Tungsten's"));
}

// A cap of the sky: a sun whose disc is the cap (Light::angularRadius).
void TungstenImporter::sphereCap(const Value& p, const std::string& where, const Value* tv) {
  Scene& s = out_.scene;
  // A cap of the sky is a sun whose disc is the cap: its radiance is the cap's, which a
  // directional light of the cap's solid angle times that radiance gives (Light::angularRadius).
  Mat4 m = transform(tv, where);
  // Tied to a skydome (Tungsten's InfiniteSphereCap::prepareForRender): the cap is the dome's
  // sun, around the dome's +y, whatever the cap's own transform says.
  if (std::string dome = string(p, "skydome"); !dome.empty() && primitives_) {
    if (std::optional<Mat4> d = transformOfPrimitive(*primitives_, dome)) m = *d;
    else warn(cat(where, ": skydome '", dome, "' names no primitive; the cap keeps its own direction"));
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
}

// A point light: Tungsten's emission is its intensity (W/sr), its power spreads over 4 pi.
void TungstenImporter::pointLight(const Value& p, const std::string& where, const Value* tv) {
  Scene& s = out_.scene;
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
}

// The meshes of a shape primitive (a mesh with several material indices gives one per index),
// its transform `xf` made Tungsten's for the shape (a round sphere and cylinder, a disk's frame),
// and a disk's emission cone; none, with a warning, for a type not rendered.
std::vector<TungstenImporter::MeshPart> TungstenImporter::shapeParts(const Value& p, const std::string& type, const std::string& where,
                                                                     Vec3 scale, bool split, Mat4& xf, float& emissionCone) {
  std::vector<MeshPart> parts;
  if (type == "mesh") {
    parts = loadMesh(p, where, split);
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
    if (mesh == kNoNode) return {};
    parts.push_back({0, mesh});
  } else {
    warn(cat(where, ": primitive type '", type, "' is not supported; skipped"));
    return {};
  }
  return parts;
}

TungstenImporter::Emission TungstenImporter::emissionOf(const Value& p, const std::string& where, const std::vector<MeshPart>& parts,
                                                        const Mat4& xf) {
  Emission light;
  if (const Value* e = p.find("emission")) {
    TextureRef t = texture(*e, where + ".emission", false);
    light = {t.constant, t.texture, true};
  }
  if (const Value* pw = p.find("power")) {
    TextureRef t = texture(*pw, where + ".power", false);
    float area = 0;  // the whole primitive's: its power spreads over every part
    for (const MeshPart& part : parts)
      if (const Mesh* mm = out_.scene.mesh(part.mesh); mm && mm->geometry) area += worldArea(*mm->geometry, xf);
    light = {area > 0 ? t.constant / (kPi * area) : Vec3{0.0f}, t.texture, true};
  }
  return light;
}

std::string TungstenImporter::fillMedium(const Value& p, const std::string& where, Material& mat) {
  std::string medium;
  if (const std::string name = string(p, "int_medium"); !name.empty() && media_.count(name)) {
    if (holdsMedium(mat.type)) {
      medium = name;
      const Filling& f = media_[name];
      mat.interiorAbsorption = f.absorption;
      mat.interiorScattering = f.scattering;
      mat.interiorAnisotropy = f.anisotropy;
    } else {
      warn(cat(where, ": the medium '", name,
               "' is rendered only inside glass or a forward boundary (an int_medium); here light passes through it"));
    }
  }
  if (const std::string name = string(p, "ext_medium"); !name.empty() && media_.count(name)) {
    outside_.emplace_back(where, name);  // warned of once every primitive is read, if nothing holds it
    if (mat.type == MaterialType::Boundary && !medium.empty())
      warn(cat(where, ": a boundary of '", medium, "' inside the medium '", name, "': a path inside it is in '", medium,
               "' alone, but its shadow rays count both"));
  }
  if (!medium.empty()) {
    inside_.insert(medium);
    holders_.emplace_back(where, string(p, "ext_medium"));
  }
  return medium;
}

void TungstenImporter::primitive(const Value& p, const std::string& where) {
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
    skydome(p, where);
    return;
  }
  if (type == "infinite_sphere_cap") {
    sphereCap(p, where, tv);
    return;
  }

  if (type == "point") {
    pointLight(p, where, tv);
    return;
  }

  float emissionCone = 90;  // Material::emissionCone, a disk's cone_angle
  Mat4 xf = transform(tv, where, &scale, type == "quad" || type == "disk");
  if (!ok()) return;
  const Value* bsdfs = p.find("bsdf");
  const bool byIndex = bsdfs && bsdfs->isArray() && !bsdfs->asArray().empty();
  // One part for every shape but a mesh with several material indices.
  std::vector<MeshPart> parts = shapeParts(p, type, where, scale, byIndex && bsdfs->asArray().size() > 1, xf, emissionCone);
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
  const Emission light = emissionOf(p, where, parts, xf);
  const bool emissive = light.emissive;

  // An array names one bsdf per material index (Tungsten's TriangleMesh: a triangle's index
  // picks its bsdf); an index past the array's end takes its last entry.
  if (byIndex && bsdfs->asArray().size() > 1 && type != "mesh")
    warn(cat(where, ": ", bsdfs->asArray().size(), " bsdfs by material index on a ", type, "; it takes the first"));
  for (const MeshPart& part : parts) {
    const std::size_t index =
        byIndex
            ? static_cast<std::size_t>(std::clamp<std::int64_t>(part.material, 0, static_cast<std::int64_t>(bsdfs->asArray().size()) - 1))
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
    const std::string medium = fillMedium(p, where, mat);
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
      m.emission = max(light.radiance, Vec3{0.0f});
      m.emissionTexture = light.texture;
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

}  // namespace retile::tungsten
