#include "scene/validate.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <unordered_map>

#include "retile/log.h"

namespace retile {
namespace {

bool sane(float v) { return std::isfinite(v) && std::abs(v) <= kMaxCoordinate; }
bool sane(Vec3 v) { return sane(v.x) && sane(v.y) && sane(v.z); }
bool finiteNonNegative(Vec3 v) { return isFinite(v) && v.x >= 0 && v.y >= 0 && v.z >= 0; }

// A float setting: `fallback` when not finite, else clamped; says so when it changed.
void clampValue(float& v, float lo, float hi, float fallback, const std::string& what, std::vector<std::string>& warnings) {
  float before = v;
  v = std::isfinite(v) ? std::clamp(v, lo, hi) : fallback;
  if (!(v == before)) warnings.push_back(cat(what, " was ", before, "; now ", v));
}

void clampInt(int& v, int lo, int hi, const std::string& what, std::vector<std::string>& warnings) {
  int before = v;
  v = std::clamp(v, lo, hi);
  if (v != before) warnings.push_back(cat(what, " was ", before, "; now ", v));
}

// Colours and radiances: finite and not negative, else `fallback`.
void checkColor(Vec3& c, Vec3 fallback, const std::string& what, std::vector<std::string>& warnings) {
  if (finiteNonNegative(c)) return;
  warnings.push_back(cat(what, " is negative or not finite; set to (", fallback.x, ", ", fallback.y, ", ", fallback.z, ")"));
  c = fallback;
}

// A medium's absorption or scattering: a colour, at most kMaxExtinction per channel.
void checkMedium(Vec3& c, const std::string& what, std::vector<std::string>& warnings) {
  checkColor(c, Vec3{0.0f}, what, warnings);
  if (maxComponent(c) <= kMaxExtinction) return;
  warnings.push_back(cat(what, " is above ", kMaxExtinction, " per unit of length; capped there"));
  c = min(c, Vec3{kMaxExtinction});
}

// Keeps the triangles whose three indices are in range and whose vertices are sane; drops the
// vertices no kept triangle uses (so the mesh's bounds, and the camera framed from them, hold only
// real geometry); drops normals and uvs that are not one per vertex or not finite.
std::shared_ptr<const MeshGeometry> repairGeometry(const MeshGeometry& g, const std::string& what, std::vector<std::string>& warnings) {
  const std::size_t n = g.positions.size();
  const bool normalsFit = g.normals.size() == n, uvsFit = g.uvs.size() == n;
  std::size_t badIndex = 0, badVertex = 0;
  std::vector<std::uint32_t> kept;
  kept.reserve(g.indices.size() - g.indices.size() % 3);
  for (std::size_t t = 0; t + 2 < g.indices.size(); t += 3) {
    bool inRange = true, finite = true;
    for (std::size_t k = 0; k < 3; ++k) {
      std::uint32_t i = g.indices[t + k];
      if (i >= n) inRange = false;
      else if (!sane(g.positions[i])) finite = false;
    }
    if (!inRange) ++badIndex;
    else if (!finite) ++badVertex;
    else
      kept.insert(kept.end(), g.indices.begin() + static_cast<std::ptrdiff_t>(t), g.indices.begin() + static_cast<std::ptrdiff_t>(t + 3));
  }
  bool badNormals =
      !g.normals.empty() && (!normalsFit || !std::all_of(g.normals.begin(), g.normals.end(), [](Vec3 v) { return isFinite(v); }));
  bool badUvs = !g.uvs.empty() &&
                (!uvsFit || !std::all_of(g.uvs.begin(), g.uvs.end(), [](Vec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }));
  const bool ragged = g.indices.size() % 3 != 0;
  // A vertex no triangle uses still counts in the mesh's bounds: garbage ones must go too.
  const bool insaneVertex = !std::all_of(g.positions.begin(), g.positions.end(), [](Vec3 p) { return sane(p); });
  if (!badIndex && !badVertex && !badNormals && !badUvs && !ragged && !insaneVertex) return nullptr;
  std::vector<char> used(n, 0);
  for (std::uint32_t i : kept) used[i] = 1;

  if (badIndex) warnings.push_back(cat(what, ": ", badIndex, " triangles name vertices past its ", n, "; dropped"));
  if (badVertex)
    warnings.push_back(
        cat(what, ": ", badVertex, " triangles have non-finite or absurd coordinates (beyond ", kMaxCoordinate, "); dropped"));
  if (ragged) warnings.push_back(cat(what, ": ", g.indices.size() % 3, " indices left over after the last whole triangle; dropped"));
  if (badNormals) warnings.push_back(cat(what, ": its normals are not one finite normal per vertex; the surface's own are used"));
  if (badUvs) warnings.push_back(cat(what, ": its uvs are not one finite pair per vertex; dropped"));

  auto out = std::make_shared<MeshGeometry>();
  std::vector<std::uint32_t> remap(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!used[i]) continue;
    remap[i] = static_cast<std::uint32_t>(out->positions.size());
    out->positions.push_back(g.positions[i]);
    if (!g.normals.empty() && !badNormals) out->normals.push_back(g.normals[i]);
    if (!g.uvs.empty() && !badUvs) out->uvs.push_back(g.uvs[i]);
  }
  out->indices.reserve(kept.size());
  for (std::uint32_t i : kept) out->indices.push_back(remap[i]);
  return out;
}

bool cameraUsable(const Camera& c) {
  if (!sane(c.position) || !sane(c.target) || !isFinite(c.up)) return false;
  Vec3 forward = c.target - c.position;
  if (!(length(forward) > 0) || !(length(c.up) > 0)) return false;
  // The up vector must not be along the view direction.
  return length(cross(normalize(forward), normalize(c.up))) > 1e-4f && std::isfinite(c.verticalFov) && c.verticalFov > 1e-3f &&
         c.verticalFov < 3.1f;
}

// The front view of the scene's bounds (from +z, y up), as the importers frame a file without a
// camera.
Camera framingCamera(const Scene& scene) {
  Bounds3 b = scene.worldBounds();
  Camera cam;
  cam.verticalFov = radians(40.0f);
  Vec3 center = b.empty() ? Vec3{0.0f} : b.center();
  float radius = b.empty() ? 1.0f : std::max(0.5f * length(b.extent()), 1e-3f);
  if (!isFinite(center) || !std::isfinite(radius)) center = Vec3{0.0f}, radius = 1.0f;
  cam.target = center;
  cam.position = center + Vec3{0.0f, 0.0f, radius / std::tan(cam.verticalFov * 0.5f) + radius};
  cam.up = {0.0f, 1.0f, 0.0f};
  return cam;
}

}  // namespace

Result<bool> validateScene(Scene& scene, std::vector<std::string>& warnings) {
  std::size_t trianglesBefore = 0, trianglesAfter = 0;
  for (Mesh& m : scene.meshes) {
    if (!m.geometry) continue;
    trianglesBefore += m.geometry->triangleCount();
    if (auto repaired = repairGeometry(*m.geometry, cat("mesh '", m.name, "'"), warnings)) m.geometry = std::move(repaired);
    trianglesAfter += m.geometry->triangleCount();
  }

  for (Object& o : scene.objects) {
    if (o.transform.isFinite() && sane(o.transform.translation())) continue;
    warnings.push_back(cat("object '", o.name, "': its transform is not finite or places it beyond ", kMaxCoordinate, "; hidden"));
    o.transform = Mat4{};
    o.visible = false;
  }

  for (Material& m : scene.materials) {
    const std::string what = cat("material '", m.name, "'");
    for (const MaterialScalar& f : kMaterialScalars) clampValue(m.*f.field, f.lo, f.hi, f.fallback, cat(what, ": ", f.key), warnings);
    // Only Oren-Nayar's sigma goes past 1.
    if (m.type != MaterialType::OrenNayar) clampValue(m.roughness, 0.0f, 1.0f, 0.1f, what + ": roughness", warnings);
    for (const MaterialColor& f : kMaterialColors) {
      Vec3& c = m.*f.field;
      if (f.inRange(c)) continue;
      const Vec3 before = c;
      c = f.clamp(c);
      warnings.push_back(cat(what, ": ", f.key, " (", before.x, ", ", before.y, ", ", before.z, ") is negative, above ", f.hi,
                             " or not a number; now (", c.x, ", ", c.y, ", ", c.z, ")"));
    }
  }

  std::size_t lightsBefore = scene.lights.size();
  std::erase_if(scene.lights, [&](const Light& l) {
    bool ok = sane(l.position) && isFinite(l.direction) && length(l.direction) > 0 && finiteNonNegative(l.color) &&
              std::isfinite(l.intensity) && l.intensity >= 0;
    if (!ok) warnings.push_back(cat("light '", l.name, "': position, direction, colour or intensity not finite (or negative); left out"));
    return !ok;
  });
  for (Light& l : scene.lights) {
    clampValue(l.spotAngle, 1e-3f, 1.5707963f, radians(30.0f), cat("light '", l.name, "': spot angle"), warnings);
    clampValue(l.spotBlend, 0.0f, 1.0f, 0.1f, cat("light '", l.name, "': spot blend"), warnings);
    clampValue(l.angularRadius, 0.0f, 1.5707963f, 0.0f, cat("light '", l.name, "': angular radius"), warnings);
  }

  Environment& env = scene.environment;
  checkColor(env.color, Vec3{0.0f}, "environment colour", warnings);
  clampValue(env.intensity, 0.0f, 1e9f, 1.0f, "environment intensity", warnings);
  clampValue(env.rotation, -1e4f, 1e4f, 0.0f, "environment rotation", warnings);
  if (!env.orientation.isFinite()) {
    warnings.push_back("environment orientation: not finite numbers; upright instead");
    env.orientation = Mat4{};
  }
  checkColor(env.zenith, Vec3{0.35f, 0.55f, 0.95f}, "sky zenith", warnings);
  checkColor(env.horizon, Vec3{0.9f, 0.92f, 0.95f}, "sky horizon", warnings);
  checkColor(env.ground, Vec3{0.3f, 0.28f, 0.25f}, "sky ground", warnings);
  checkMedium(env.mediumAbsorption, "environment medium absorption", warnings);
  checkMedium(env.mediumScattering, "environment medium scattering", warnings);
  clampValue(env.mediumAnisotropy, -0.99f, 0.99f, 0.0f, "environment medium anisotropy", warnings);

  for (Texture& t : scene.textures) {
    clampInt(t.checkerResU, 1, 4096, cat("texture '", t.name, "': checker squares across"), warnings);
    clampInt(t.checkerResV, 1, 4096, cat("texture '", t.name, "': checker squares down"), warnings);
  }

  RenderSettings& s = scene.settings;
  clampInt(s.width, 1, kMaxImageSide, "image width", warnings);
  clampInt(s.height, 1, kMaxImageSide, "image height", warnings);
  clampInt(s.maxBounces, 0, 1024, "max bounces", warnings);
  clampInt(s.minBounces, 0, 1024, "min bounces", warnings);
  clampInt(s.samplesPerPixel, 1, 1 << 20, "samples per pixel", warnings);
  clampValue(s.filterWidth, 0.25f, 16.0f, defaultFilterWidth(s.pixelFilter), "pixel filter width", warnings);

  if (!cameraUsable(scene.camera)) {
    warnings.push_back(cat("the camera (at ", scene.camera.position.x, ", ", scene.camera.position.y, ", ", scene.camera.position.z,
                           ") is not finite, too far out or looks nowhere; framing the scene instead"));
    scene.camera = framingCamera(scene);
  }
  Camera& cam = scene.camera;
  if (!(std::isfinite(cam.apertureRadius) && cam.apertureRadius >= 0 && std::isfinite(cam.focusDistance) && cam.focusDistance > 0)) {
    warnings.push_back(cat("the camera's lens (aperture radius ", cam.apertureRadius, ", focus distance ", cam.focusDistance,
                           ") is not usable; rendering through a pinhole"));
    cam.apertureRadius = 0.0f;
    cam.focusDistance = 1.0f;
  }

  if ((trianglesBefore > 0 || lightsBefore > 0) && trianglesAfter == 0 && scene.lights.empty())
    return Result<bool>::failure(cat("nothing to render is left: all ", trianglesBefore, " triangles and ", lightsBefore,
                                     " lights have non-finite or absurd values"));
  return true;
}

}  // namespace retile
