// The native scene format: one JSON document, versioned, lossless. Geometry and embedded images
// are base64 inside it so that a scene is one file (saves are atomic, autosaves self-contained).
#include <cstring>

#include "core/files.h"
#include "core/json.h"
#include "retile/io.h"
#include "retile/log.h"

namespace fs = std::filesystem;

namespace retile {
namespace {

using json::Value;

const char* const kFormatTag = "retile-scene";

template <class T>
Value blob(const std::vector<T>& v) {
  return Value(base64Encode(reinterpret_cast<const std::uint8_t*>(v.data()), v.size() * sizeof(T)));
}

Value mat4(const Mat4& m) {
  json::Array a;
  for (const auto& row : m.m)
    for (float f : row) a.emplace_back(f);
  return Value(std::move(a));
}

const char* colorSpaceName(TextureColorSpace c) {
  switch (c) {
    case TextureColorSpace::Auto: return "auto";
    case TextureColorSpace::SRGB: return "srgb";
    case TextureColorSpace::Linear: return "linear";
    case TextureColorSpace::Raw: return "raw";
    case TextureColorSpace::Gamma22: return "gamma22";
  }
  return "auto";
}
const char* textureKindName(TextureKind k) {
  switch (k) {
    case TextureKind::File: return "file";
    case TextureKind::Embedded: return "embedded";
    case TextureKind::Checker: return "checker";
  }
  return "file";
}
const char* lightTypeName(LightType t) {
  switch (t) {
    case LightType::Point: return "point";
    case LightType::Spot: return "spot";
    case LightType::Directional: return "directional";
  }
  return "point";
}

// Reads fields of one JSON object, remembering the first problem with its location.
class Reader {
 public:
  Reader(std::string* error, std::string where, const Value* v) : error_(error), where_(std::move(where)), v_(v) {
    if (!v_ || !v_->isObject()) problem("", "expected an object");
  }

  bool ok() const { return error_->empty(); }
  const Value* raw(const char* key) const { return v_ && v_->isObject() ? v_->find(key) : nullptr; }

  void problem(const char* key, const std::string& what) {
    if (error_->empty()) *error_ = cat(where_, (key && *key) ? "." : "", key ? key : "", ": ", what);
  }

  template <class F>
  void field(const char* key, F&& read, const char* expected, bool required = false) {
    const Value* f = raw(key);
    if (!f) {
      if (required) problem(key, "missing");
      return;
    }
    if (!read(*f)) problem(key, cat("expected ", expected, ", found ", json::typeName(f->type())));
  }

  void number(const char* key, float* out, bool required = false) {
    field(
        key, [&](const Value& f) { return json::toFloat(f, out); }, "a finite number", required);
  }
  void integer(const char* key, int* out) {
    field(
        key,
        [&](const Value& f) {
          if (!f.isNumber() || f.asNumber() != std::floor(f.asNumber()) || std::abs(f.asNumber()) > 1e9) return false;
          *out = static_cast<int>(f.asNumber());
          return true;
        },
        "an integer");
  }
  void id(const char* key, NodeId* out, bool required = false) {
    field(
        key,
        [&](const Value& f) {
          if (!f.isNumber() || f.asNumber() < 0 || f.asNumber() > 9e15 || f.asNumber() != std::floor(f.asNumber())) return false;
          *out = static_cast<NodeId>(f.asNumber());
          return true;
        },
        "a node id", required);
  }
  void vec3(const char* key, Vec3* out) {
    field(
        key, [&](const Value& f) { return json::toVec3(f, out); }, "three numbers");
  }
  void boolean(const char* key, bool* out) {
    field(
        key,
        [&](const Value& f) {
          if (!f.isBool()) return false;
          *out = f.asBool();
          return true;
        },
        "true or false");
  }
  void string(const char* key, std::string* out, bool required = false) {
    field(
        key,
        [&](const Value& f) {
          if (!f.isString()) return false;
          *out = f.asString();
          return true;
        },
        "a string", required);
  }
  void matrix(const char* key, Mat4* out) {
    field(
        key,
        [&](const Value& f) {
          if (!f.isArray() || f.asArray().size() != 16) return false;
          for (int i = 0; i < 16; ++i)
            if (!json::toFloat(f.asArray()[static_cast<std::size_t>(i)], &out->m[i / 4][i % 4])) return false;
          return true;
        },
        "16 numbers");
  }
  template <class T>
  void blob(const char* key, std::vector<T>* out) {
    const Value* f = raw(key);
    if (!f) return;
    if (!f->isString()) return problem(key, "expected base64 text");
    auto bytes = base64Decode(f->asString());
    if (!bytes) return problem(key, bytes.error());
    if (bytes->size() % sizeof(T)) return problem(key, "data length is not a whole number of elements");
    out->resize(bytes->size() / sizeof(T));
    if (!out->empty()) std::memcpy(out->data(), bytes->data(), bytes->size());
  }
  template <class E>
  void enumeration(const char* key, E* out, const char* (*name)(E), int count) {
    const Value* f = raw(key);
    if (!f) return;
    if (f->isString())
      for (int i = 0; i < count; ++i)
        if (f->asString() == name(static_cast<E>(i))) {
          *out = static_cast<E>(i);
          return;
        }
    problem(key, f->isString() ? cat("unknown value '", f->asString(), "'") : std::string("expected a name"));
  }

 private:
  std::string* error_;
  std::string where_;
  const Value* v_;
};

const char* materialName(MaterialType t) { return materialTypeName(t); }

}  // namespace

namespace {

// Each item of `items` written by toJson, in order.
template <class T, class F>
json::Array arrayOf(const std::vector<T>& items, F toJson) {
  json::Array a;
  for (const T& x : items) a.push_back(toJson(x));
  return a;
}

Value settingsToJson(const RenderSettings& r) {
  Value settings(json::Object{});
  settings.set("width", r.width);
  settings.set("height", r.height);
  settings.set("max_bounces", r.maxBounces);
  // Written only where they are not the defaults, as files from before them have neither.
  if (r.minBounces != 0) settings.set("min_bounces", r.minBounces);
  if (!r.lightSampling) settings.set("light_sampling", false);
  settings.set("spp", r.samplesPerPixel);
  settings.set("seed", r.seed);
  settings.set("pixel_filter", pixelFilterName(r.pixelFilter));
  settings.set("filter_width", r.filterWidth);
  // Only scenes that came from Tungsten files say them; everything else has the first ways.
  if (r.filterSampling == FilterSampling::SteppedTable) settings.set("filter_sampling", "stepped_table");
  if (r.shading == ShadingConvention::Unchecked) settings.set("shading", "unchecked");
  if (r.roulette == Roulette::LowThroughput) settings.set("roulette", "low_throughput");
  if (r.rayOffset == RayOffset::FixedEpsilon) settings.set("ray_offset", "fixed_epsilon");
  if (!r.view.empty()) settings.set("view", r.view);
  return settings;
}

Value cameraToJson(const Camera& c) {
  Value cam(json::Object{});
  cam.set("position", json::fromVec3(c.position));
  cam.set("target", json::fromVec3(c.target));
  cam.set("up", json::fromVec3(c.up));
  cam.set("vertical_fov", c.verticalFov);
  if (c.apertureRadius > 0) {
    cam.set("aperture_radius", c.apertureRadius);
    cam.set("focus_distance", c.focusDistance);
  }
  return cam;
}

Value environmentToJson(const Environment& e) {
  Value env(json::Object{});
  env.set("type", environmentTypeName(e.type));
  env.set("color", json::fromVec3(e.color));
  env.set("intensity", e.intensity);
  env.set("map", e.map);
  env.set("rotation", e.rotation);
  env.set("orientation", mat4(e.orientation));
  env.set("zenith", json::fromVec3(e.zenith));
  env.set("horizon", json::fromVec3(e.horizon));
  env.set("ground", json::fromVec3(e.ground));
  env.set("medium_absorption", json::fromVec3(e.mediumAbsorption));
  env.set("medium_scattering", json::fromVec3(e.mediumScattering));
  env.set("medium_anisotropy", e.mediumAnisotropy);
  return env;
}

Value meshToJson(const Mesh& m) {
  Value v(json::Object{});
  v.set("id", m.id);
  v.set("name", m.name);
  if (m.geometry) {
    v.set("positions", blob(m.geometry->positions));
    v.set("normals", blob(m.geometry->normals));
    v.set("uvs", blob(m.geometry->uvs));
    v.set("indices", blob(m.geometry->indices));
  }
  return v;
}

Value textureToJson(const Texture& t, const fs::path& baseDirectory) {
  Value v(json::Object{});
  v.set("id", t.id);
  v.set("name", t.name);
  v.set("kind", textureKindName(t.kind));
  v.set("color_space", colorSpaceName(t.colorSpace));
  if (t.whenMissing == MissingTexture::BlackAndWhite) v.set("when_missing", "black_and_white");
  if (!t.interpolate) v.set("interpolate", false);
  if (t.clampToEdge) v.set("clamp", true);
  if (t.kind == TextureKind::File) {
    // Stored as written, plus the absolute location so a copy saved elsewhere still finds it.
    v.set("path", t.path.generic_string());
    fs::path abs = t.path.is_absolute() ? t.path : baseDirectory / t.path;
    v.set("absolute_path", abs.lexically_normal().generic_string());
  } else if (t.kind == TextureKind::Embedded) {
    v.set("format", t.encodedFormat);
    v.set("data", blob(t.encoded));
  } else {
    v.set("on", json::fromVec3(t.checkerOn));
    v.set("off", json::fromVec3(t.checkerOff));
    v.set("res_u", t.checkerResU);
    v.set("res_v", t.checkerResV);
    if (t.truncatedCells) v.set("cells", "truncated");
  }
  return v;
}

Value materialToJson(const Material& m) {
  Value v(json::Object{});
  v.set("id", m.id);
  v.set("name", m.name);
  v.set("type", materialTypeName(m.type));
  // A field at its default is left out: the reader takes the default for what is not there.
  const Material defaults;
  for (const MaterialScalar& f : kMaterialScalars)
    if (m.*f.field != defaults.*f.field) v.set(f.key, m.*f.field);
  for (const MaterialColor& f : kMaterialColors)
    if (m.*f.field != defaults.*f.field) v.set(f.key, json::fromVec3(m.*f.field));
  for (const MaterialTexture& f : kMaterialTextures)
    if (m.*f.field != kNoNode) v.set(f.key, m.*f.field);
  for (const MaterialChoice& f : kMaterialChoices)
    if (m.*f.field) v.set(f.key, f.on);
  v.set("metal", m.metal);
  if (m.blendWith != kNoNode) v.set("blend_with", m.blendWith);
  return v;
}

Value objectToJson(const Object& o) {
  Value v(json::Object{});
  v.set("id", o.id);
  v.set("name", o.name);
  v.set("mesh", o.mesh);
  v.set("material", o.material);
  v.set("transform", mat4(o.transform));
  v.set("visible", o.visible);
  if (o.cullBackFaces) v.set("backface_culling", true);
  return v;
}

Value lightToJson(const Light& l) {
  Value v(json::Object{});
  v.set("id", l.id);
  v.set("name", l.name);
  v.set("type", lightTypeName(l.type));
  v.set("color", json::fromVec3(l.color));
  v.set("intensity", l.intensity);
  v.set("position", json::fromVec3(l.position));
  v.set("direction", json::fromVec3(l.direction));
  v.set("spot_angle", l.spotAngle);
  v.set("spot_blend", l.spotBlend);
  v.set("angular_radius", l.angularRadius);
  v.set("visible", l.visible);
  return v;
}

Value nativeSceneToJson(const Scene& s) {
  Value root(json::Object{});
  root.set("format", kFormatTag);
  root.set("version", kNativeFormatVersion);
  root.set("next_id", s.peekNextId());

  root.set("settings", settingsToJson(s.settings));
  root.set("camera", cameraToJson(s.camera));
  root.set("environment", environmentToJson(s.environment));
  root.set("meshes", arrayOf(s.meshes, meshToJson));
  root.set("textures", arrayOf(s.textures, [&](const Texture& t) { return textureToJson(t, s.baseDirectory); }));
  root.set("materials", arrayOf(s.materials, materialToJson));
  root.set("objects", arrayOf(s.objects, objectToJson));
  root.set("lights", arrayOf(s.lights, lightToJson));
  return root;
}

// A setting or field that is one of two ways, by name: `first` (the enum's first value, or false;
// also when the file says nothing) or `second`. Files saved before these names said what the ways
// do called the second way "tungsten" (`wasTungsten`); they read as they did.
template <class E>
void readEither(Reader& r, const char* key, const char* first, const char* second, E* out, bool wasTungsten = true) {
  std::string name;
  r.string(key, &name);
  if (name == second || (wasTungsten && name == "tungsten")) *out = static_cast<E>(1);
  else if (!name.empty() && name != first) r.problem(key, cat("unknown ", key, " '", name, "' (", first, ", ", second, ")"));
}

void readSettings(Reader& r, RenderSettings& settings) {
  r.integer("width", &settings.width);
  r.integer("height", &settings.height);
  r.integer("max_bounces", &settings.maxBounces);
  r.integer("min_bounces", &settings.minBounces);
  r.boolean("light_sampling", &settings.lightSampling);
  r.integer("spp", &settings.samplesPerPixel);
  int seed = 0;
  r.integer("seed", &seed);
  settings.seed = static_cast<std::uint32_t>(seed);
  // Files from before the pixel filter have none: a box, as they were rendered.
  std::string filter;
  r.string("pixel_filter", &filter);
  if (filter.empty()) settings.pixelFilter = PixelFilter::Box;
  if (!filter.empty() && !parsePixelFilter(filter, &settings.pixelFilter))
    r.problem("pixel_filter", cat("unknown filter '", filter, "' (box, tent, gaussian, blackman_harris)"));
  settings.filterWidth = defaultFilterWidth(settings.pixelFilter);
  r.number("filter_width", &settings.filterWidth);
  if (!(settings.filterWidth > 0.0f && settings.filterWidth <= 16.0f))
    r.problem("filter_width", "expected a width in pixels within (0, 16]");
  readEither(r, "filter_sampling", "exact", "stepped_table", &settings.filterSampling);
  readEither(r, "shading", "consistent", "unchecked", &settings.shading);
  readEither(r, "roulette", "standard", "low_throughput", &settings.roulette);
  readEither(r, "ray_offset", "robust", "fixed_epsilon", &settings.rayOffset);
  r.string("view", &settings.view);
}

void readCamera(Reader& r, Camera& c) {
  r.vec3("position", &c.position);
  r.vec3("target", &c.target);
  r.vec3("up", &c.up);
  r.number("vertical_fov", &c.verticalFov);
  r.number("aperture_radius", &c.apertureRadius);
  r.number("focus_distance", &c.focusDistance);
}

void readEnvironment(Reader& r, Environment& e) {
  r.enumeration("type", &e.type, environmentTypeName, 3);
  r.vec3("color", &e.color);
  r.number("intensity", &e.intensity);
  r.id("map", &e.map);
  r.number("rotation", &e.rotation);
  r.matrix("orientation", &e.orientation);
  r.vec3("zenith", &e.zenith);
  r.vec3("horizon", &e.horizon);
  r.vec3("ground", &e.ground);
  r.vec3("medium_absorption", &e.mediumAbsorption);
  r.vec3("medium_scattering", &e.mediumScattering);
  r.number("medium_anisotropy", &e.mediumAnisotropy);
}

Mesh readMesh(Reader& r, const fs::path& file, std::vector<std::string>* warnings) {
  Mesh m;
  auto g = std::make_shared<MeshGeometry>();
  r.id("id", &m.id, true);
  r.string("name", &m.name);
  r.blob("positions", &g->positions);
  r.blob("normals", &g->normals);
  r.blob("uvs", &g->uvs);
  r.blob("indices", &g->indices);
  std::size_t dropped = sanitizeGeometry(*g);
  if (dropped) warnings->push_back(cat(file.string(), ": mesh '", m.name, "': dropped ", dropped, " invalid triangles"));
  m.geometry = std::move(g);
  return m;
}

Texture readTexture(Reader& r, const fs::path& baseDir) {
  Texture t;
  r.id("id", &t.id, true);
  r.string("name", &t.name);
  r.enumeration("kind", &t.kind, textureKindName, 3);
  std::string colorSpace;
  r.string("color_space", &colorSpace);
  if (colorSpace == "tungsten_gamma") t.colorSpace = TextureColorSpace::Gamma22;  // its name before "gamma22"
  else r.enumeration("color_space", &t.colorSpace, colorSpaceName, kTextureColorSpaceCount);
  readEither(r, "when_missing", "checker", "black_and_white", &t.whenMissing);
  r.boolean("interpolate", &t.interpolate);
  r.boolean("clamp", &t.clampToEdge);
  std::string path, absolute;
  r.string("path", &path);
  r.string("absolute_path", &absolute);
  if (t.kind == TextureKind::File) {
    // Prefer the recorded relative path when it still resolves next to this file.
    std::error_code ec;
    if (!path.empty() && (fs::path(path).is_absolute() || fs::exists(baseDir / path, ec))) t.path = path;
    else if (!absolute.empty()) t.path = absolute;
    else t.path = path;
  }
  r.string("format", &t.encodedFormat);
  r.blob("data", &t.encoded);
  r.vec3("on", &t.checkerOn);
  r.vec3("off", &t.checkerOff);
  r.integer("res_u", &t.checkerResU);
  r.integer("res_v", &t.checkerResV);
  readEither(r, "cells", "floor", "truncated", &t.truncatedCells);
  return t;
}

Material readMaterial(Reader& r) {
  Material m;
  r.id("id", &m.id, true);
  r.string("name", &m.name);
  r.enumeration("type", &m.type, materialName, kMaterialTypeCount);
  for (const MaterialScalar& f : kMaterialScalars) {
    r.number(f.key, &(m.*f.field));
    // Where lo means none of the field's effect, so does anything below it (a coat of index 0.6 is
    // no coat): taken as lo without the warning an out-of-range value gets.
    if (*f.atLo && m.*f.field < f.lo) m.*f.field = f.lo;
  }
  for (const MaterialColor& f : kMaterialColors) r.vec3(f.key, &(m.*f.field));
  for (const MaterialTexture& f : kMaterialTextures) r.id(f.key, &(m.*f.field));
  // Of the choices only the glass convention was ever written "tungsten".
  for (const MaterialChoice& f : kMaterialChoices) readEither(r, f.key, f.off, f.on, &(m.*f.field), f.field == &Material::tintsReflection);
  r.string("metal", &m.metal);
  r.id("blend_with", &m.blendWith);
  return m;
}

Object readObject(Reader& r) {
  Object o;
  r.id("id", &o.id, true);
  r.string("name", &o.name);
  r.id("mesh", &o.mesh);
  r.id("material", &o.material);
  r.matrix("transform", &o.transform);
  r.boolean("visible", &o.visible);
  r.boolean("backface_culling", &o.cullBackFaces);
  return o;
}

Light readLight(Reader& r) {
  Light l;
  r.id("id", &l.id, true);
  r.string("name", &l.name);
  r.enumeration("type", &l.type, lightTypeName, 3);
  r.vec3("color", &l.color);
  r.number("intensity", &l.intensity);
  r.vec3("position", &l.position);
  r.vec3("direction", &l.direction);
  r.number("spot_angle", &l.spotAngle);
  r.number("spot_blend", &l.spotBlend);
  r.number("angular_radius", &l.angularRadius);
  r.boolean("visible", &l.visible);
  return l;
}

}  // namespace

std::string nativeSceneToString(const Scene& s) { return json::write(nativeSceneToJson(s)); }

Result<bool> saveNativeScene(const Scene& scene, const fs::path& file) {
  // A NaN or infinity would be written as null and the file would not read back: refuse, so the
  // file on disk stays as it was and the caller can say which value is at fault.
  const Value root = nativeSceneToJson(scene);
  if (std::string at = json::firstNonFinite(root); !at.empty())
    return Result<bool>::failure(cat(file.string(), ": not saved: ", at, " is not a finite number"));
  return writeFileAtomic(file, json::write(root));
}

Result<ImportedScene> nativeSceneFromString(const std::string& text, const fs::path& file, const fs::path& baseDir) {
  using R = Result<ImportedScene>;
  auto parsed = json::parse(text);
  if (!parsed) return R::failure(cat(file.string(), ": not valid JSON: ", parsed.error()));
  const Value& root = parsed.value();
  const Value* tag = root.find("format");
  if (!tag || !tag->isString() || tag->asString() != kFormatTag)
    return R::failure(cat(file.string(), ": not a Retile scene (no \"format\": \"", kFormatTag, "\")"));
  const Value* ver = root.find("version");
  if (!ver || !ver->isNumber()) return R::failure(cat(file.string(), ": no format version"));
  if (ver->asNumber() > kNativeFormatVersion)
    return R::failure(cat(file.string(), ": written by a newer Retile (format version ", ver->asNumber(), ", this build reads up to ",
                          kNativeFormatVersion, ")"));

  ImportedScene out;
  out.format = "native";
  Scene& s = out.scene;
  s.baseDirectory = baseDir;
  std::string error;
  auto where = [&](const char* list, std::size_t i) { return cat(list, "[", i, "]"); };

  Reader top(&error, "", &root);
  NodeId nextId = 1;
  top.id("next_id", &nextId);

  if (const Value* v = root.find("settings")) {
    Reader r(&error, "settings", v);
    readSettings(r, s.settings);
  }
  if (const Value* v = root.find("camera")) {
    Reader r(&error, "camera", v);
    readCamera(r, s.camera);
  }
  if (const Value* v = root.find("environment")) {
    Reader r(&error, "environment", v);
    readEnvironment(r, s.environment);
  }
  auto list = [&](const char* key) -> const json::Array* {
    const Value* v = root.find(key);
    if (!v) return nullptr;
    if (!v->isArray()) {
      if (error.empty()) error = cat(key, ": expected an array");
      return nullptr;
    }
    return &v->asArray();
  };
  if (auto* a = list("meshes"))
    for (std::size_t i = 0; i < a->size() && error.empty(); ++i) {
      Reader r(&error, where("meshes", i), &(*a)[i]);
      s.meshes.push_back(readMesh(r, file, &out.warnings));
    }
  if (auto* a = list("textures"))
    for (std::size_t i = 0; i < a->size() && error.empty(); ++i) {
      Reader r(&error, where("textures", i), &(*a)[i]);
      s.textures.push_back(readTexture(r, baseDir));
    }
  if (auto* a = list("materials"))
    for (std::size_t i = 0; i < a->size() && error.empty(); ++i) {
      Reader r(&error, where("materials", i), &(*a)[i]);
      s.materials.push_back(readMaterial(r));
    }
  if (auto* a = list("objects"))
    for (std::size_t i = 0; i < a->size() && error.empty(); ++i) {
      Reader r(&error, where("objects", i), &(*a)[i]);
      s.objects.push_back(readObject(r));
    }
  if (auto* a = list("lights"))
    for (std::size_t i = 0; i < a->size() && error.empty(); ++i) {
      Reader r(&error, where("lights", i), &(*a)[i]);
      s.lights.push_back(readLight(r));
    }
  if (!error.empty()) return R::failure(cat(file.string(), ": ", error));

  // References must point at existing nodes of the right kind; ids must be unique.
  std::vector<NodeId> ids;
  NodeId maxId = 0;
  auto note = [&](NodeId id) {
    ids.push_back(id);
    maxId = std::max(maxId, id);
  };
  for (auto& m : s.meshes) note(m.id);
  for (auto& t : s.textures) note(t.id);
  for (auto& m : s.materials) note(m.id);
  for (auto& o : s.objects) note(o.id);
  for (auto& l : s.lights) note(l.id);
  std::sort(ids.begin(), ids.end());
  if (std::adjacent_find(ids.begin(), ids.end()) != ids.end() || (!ids.empty() && ids.front() == kNoNode))
    return R::failure(cat(file.string(), ": node ids are not unique and non-zero"));
  for (Material& m : s.materials)
    for (NodeId* t : m.textureSlots())
      if (*t != kNoNode && !s.texture(*t)) {
        out.warnings.push_back(cat(file.string(), ": material '", m.name, "' names missing texture ", *t));
        *t = kNoNode;
      }
  for (Material& m : s.materials)
    if (m.blendWith != kNoNode && (!s.material(m.blendWith) || m.blendWith == m.id)) {
      out.warnings.push_back(cat(file.string(), ": material '", m.name, "' blends with missing material ", m.blendWith));
      m.blendWith = kNoNode;
    }
  for (Object& o : s.objects) {
    if (o.mesh != kNoNode && !s.mesh(o.mesh)) return R::failure(cat(file.string(), ": object '", o.name, "' names missing mesh ", o.mesh));
    if (o.material != kNoNode && !s.material(o.material)) {
      out.warnings.push_back(cat(file.string(), ": object '", o.name, "' names missing material ", o.material));
      o.material = kNoNode;
    }
  }
  if (s.environment.map != kNoNode && !s.texture(s.environment.map)) {
    out.warnings.push_back(cat(file.string(), ": environment names missing texture ", s.environment.map));
    s.environment.map = kNoNode;
  }
  if (s.settings.width < 1 || s.settings.height < 1 || s.settings.width > kMaxImageSide || s.settings.height > kMaxImageSide)
    return R::failure(cat(file.string(), ": settings: size ", s.settings.width, "x", s.settings.height, " is outside 1..", kMaxImageSide));
  s.reserveIds(std::max(nextId, maxId + 1));
  return out;
}

Result<ImportedScene> loadNativeScene(const fs::path& file, const ImportOptions& options) {
  auto text = readFile(file, options.maxFileBytes);
  if (!text) return Result<ImportedScene>::failure(text.error());
  return nativeSceneFromString(text.value(), file, file.parent_path());
}

}  // namespace retile
