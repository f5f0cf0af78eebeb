#include "retile/scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

namespace retile {

const char* environmentTypeName(EnvironmentType t) {
  switch (t) {
    case EnvironmentType::Constant: return "constant";
    case EnvironmentType::Map: return "map";
    case EnvironmentType::Sky: return "sky";
  }
  return "constant";
}

const char* pixelFilterName(PixelFilter f) {
  switch (f) {
    case PixelFilter::Box: return "box";
    case PixelFilter::Tent: return "tent";
    case PixelFilter::Gaussian: return "gaussian";
    case PixelFilter::BlackmanHarris: return "blackman_harris";
  }
  return "box";
}

bool parsePixelFilter(std::string_view name, PixelFilter* out) {
  for (int i = 0; i < kPixelFilterCount; ++i)
    if (name == pixelFilterName(static_cast<PixelFilter>(i))) {
      *out = static_cast<PixelFilter>(i);
      return true;
    }
  return false;
}

float defaultFilterWidth(PixelFilter f) {
  switch (f) {
    case PixelFilter::Box: return 1.0f;
    case PixelFilter::Tent: return 2.0f;
    case PixelFilter::Gaussian: return 4.0f;
    case PixelFilter::BlackmanHarris: return 1.5f;
  }
  return 1.0f;
}

std::vector<float> pixelFilterWarp(PixelFilter f, float width, int segments) {
  const double radius = 0.5 * std::clamp(static_cast<double>(width), 0.01, 16.0);
  std::vector<float> warp(static_cast<std::size_t>(segments) + 1);
  // The filter's weight at offset x in [-radius, radius].
  auto weight = [&](double x) {
    const double t = x / radius;  // -1..1
    switch (f) {
      case PixelFilter::Box: return 1.0;
      case PixelFilter::Tent: return std::max(0.0, 1.0 - std::abs(t));
      case PixelFilter::Gaussian: return std::exp(-0.5 * (3.0 * t) * (3.0 * t));  // +-3 sigma across the width
      case PixelFilter::BlackmanHarris: {
        const double a = std::numbers::pi * (t + 1.0);  // 0..2 pi across the width
        return std::max(0.0, 0.35875 - 0.48829 * std::cos(a) + 0.14128 * std::cos(2 * a) - 0.01168 * std::cos(3 * a));
      }
    }
    return 1.0;
  };
  // Tabulate the CDF finely and invert it at u = i / segments.
  constexpr int kFine = 4096;
  std::vector<double> cdf(kFine + 1, 0.0);
  for (int k = 0; k < kFine; ++k) {
    const double x0 = -radius + 2 * radius * k / kFine, x1 = -radius + 2 * radius * (k + 1) / kFine;
    cdf[static_cast<std::size_t>(k) + 1] = cdf[static_cast<std::size_t>(k)] + 0.5 * (weight(x0) + weight(x1)) * (x1 - x0);
  }
  for (double& c : cdf) c /= cdf.back();
  std::size_t k = 0;
  for (int i = 0; i <= segments; ++i) {
    const double u = static_cast<double>(i) / segments;
    while (k + 1 < cdf.size() - 1 && cdf[k + 1] < u) ++k;
    const double span = cdf[k + 1] - cdf[k];
    const double frac = span > 0 ? std::clamp((u - cdf[k]) / span, 0.0, 1.0) : 0.0;
    warp[static_cast<std::size_t>(i)] = static_cast<float>(-radius + 2 * radius * (k + frac) / kFine);
  }
  warp.front() = static_cast<float>(-radius);
  warp.back() = static_cast<float>(radius);
  return warp;
}

std::vector<float> steppedFilterCdf(PixelFilter f) {
  // Tungsten's ReconstructionFilter::precompute: the weights at the steps' inner ends, in float
  // as there, normalised by their sum.
  auto weight = [&](float t) {  // t: 0..1 of the radius
    if (f == PixelFilter::Gaussian) return std::max(std::exp(-2.0f * (2 * t) * (2 * t)) - std::exp(-8.0f), 0.0f);
    return 1.0f - t;  // the tent (and anything else asked for)
  };
  std::vector<float> w(kSteppedFilterSteps);
  float sum = 0;
  for (int i = 0; i < kSteppedFilterSteps; ++i)
    sum += (w[static_cast<std::size_t>(i)] = weight(static_cast<float>(i) / kSteppedFilterSteps));
  std::vector<float> cdf(kSteppedFilterSteps - 1);
  float c = 0;
  for (int i = 1; i < kSteppedFilterSteps; ++i) cdf[static_cast<std::size_t>(i) - 1] = (c += w[static_cast<std::size_t>(i) - 1] / sum);
  return cdf;
}

Mat4 environmentToMap(const Environment& e) { return e.orientation.rotationPart().transposed() * Mat4::rotateY(-e.rotation); }

Bounds3 MeshGeometry::bounds() const {
  Bounds3 b;
  for (const Vec3& p : positions) b.grow(p);
  return b;
}

Vec3 objectPivot(const Scene& s, const Object& o) {
  // The transformed centre of the local bounds, which a turn or scale about it leaves in place
  // (the centre of the transformed bounds is the same point for any affine transform).
  const Mesh* m = s.mesh(o.mesh);
  const Bounds3 b = m && m->geometry ? m->geometry->bounds() : Bounds3{};
  return o.transform.transformPoint(b.empty() ? Vec3{0.0f} : b.center());
}

namespace {

const char* const kMaterialNames[kMaterialTypeCount] = {
    "lambert",    "oren_nayar",       "plastic",   "rough_plastic", "conductor", "rough_conductor",      "mirror",
    "dielectric", "rough_dielectric", "thinsheet", "null",          "phong",     "diffuse_transmission", "boundary",
    "hair"};

// RGB complex indices of refraction of common metals (the same RGB values Tungsten's scenes
// name, from the RPI refractive index tables), so that scene files naming a metal look as
// their authors saw them.
struct Metal {
  const char* name;
  Vec3 eta, k;
};
const Metal kMetals[] = {
    {"Ag", {0.1552646f, 0.1167233f, 0.1383807f}, {4.8283433f, 3.1222459f, 2.1469504f}},
    {"Al", {1.6574600f, 0.8803690f, 0.5212287f}, {9.2238692f, 6.2695232f, 4.8370012f}},
    {"Au", {0.1431190f, 0.3749570f, 1.4424786f}, {3.9831604f, 2.3857207f, 1.6032153f}},
    {"Cr", {4.3696829f, 2.9167025f, 1.6547005f}, {5.2064338f, 4.2313645f, 3.7549468f}},
    {"Cu", {0.2004377f, 0.9240334f, 1.1022120f}, {3.9129485f, 2.4528477f, 2.1421880f}},
    {"Hg", {2.3989315f, 1.4400255f, 0.9095512f}, {6.3276269f, 4.3719414f, 3.4217899f}},
    {"Ir", {3.0864098f, 2.0821938f, 1.6178867f}, {5.5921510f, 4.0671757f, 3.2672611f}},
    {"Mo", {4.4837010f, 3.5254578f, 2.7760769f}, {4.1111308f, 3.4208716f, 3.1506031f}},
    {"Ni", {2.3672754f, 1.6633583f, 1.4670554f}, {4.4988330f, 3.0501644f, 2.3454274f}},
    {"Rh", {2.5857955f, 1.8601866f, 1.5544280f}, {6.7822927f, 4.7029501f, 3.9760892f}},
    {"Ta", {2.0625847f, 2.3930916f, 2.6280685f}, {2.4080468f, 1.7413706f, 1.9470377f}},
    {"TiN", {1.6484692f, 1.1504483f, 1.3797795f}, {3.3684596f, 1.9434889f, 1.1020123f}},
    {"V", {4.2775126f, 3.5131538f, 2.7611257f}, {3.4911845f, 2.8893581f, 3.1116965f}},
    {"W", {4.3707030f, 3.3002972f, 2.9982667f}, {3.5006779f, 2.6048653f, 2.2731931f}},
};

template <class T>
T* findById(std::vector<T>& v, NodeId id) {
  if (id == kNoNode) return nullptr;
  for (T& n : v)
    if (n.id == id) return &n;
  return nullptr;
}

}  // namespace

const char* materialTypeName(MaterialType t) { return kMaterialNames[static_cast<int>(t)]; }

bool materialTypeFromName(const std::string& name, MaterialType* out) {
  for (int i = 0; i < kMaterialTypeCount; ++i)
    if (name == kMaterialNames[i]) {
      *out = static_cast<MaterialType>(i);
      return true;
    }
  return false;
}

std::vector<std::string> conductorNames() {
  std::vector<std::string> names;
  for (const Metal& m : kMetals) names.emplace_back(m.name);
  return names;
}

bool conductorIor(const std::string& name, Vec3* eta, Vec3* k) {
  for (const Metal& m : kMetals)
    if (name == m.name) {
      *eta = m.eta;
      *k = m.k;
      return true;
    }
  return false;
}

Mesh* Scene::mesh(NodeId id) { return findById(meshes, id); }
const Mesh* Scene::mesh(NodeId id) const { return findById(const_cast<std::vector<Mesh>&>(meshes), id); }
Texture* Scene::texture(NodeId id) { return findById(textures, id); }
const Texture* Scene::texture(NodeId id) const { return findById(const_cast<std::vector<Texture>&>(textures), id); }
Material* Scene::material(NodeId id) { return findById(materials, id); }
const Material* Scene::material(NodeId id) const { return findById(const_cast<std::vector<Material>&>(materials), id); }
Object* Scene::object(NodeId id) { return findById(objects, id); }
const Object* Scene::object(NodeId id) const { return findById(const_cast<std::vector<Object>&>(objects), id); }
Light* Scene::light(NodeId id) { return findById(lights, id); }
const Light* Scene::light(NodeId id) const { return findById(const_cast<std::vector<Light>&>(lights), id); }

Bounds3 Scene::worldBounds() const {
  Bounds3 b;
  for (const Object& o : objects) {
    if (!o.visible) continue;
    const Mesh* m = mesh(o.mesh);
    if (!m || !m->geometry) continue;
    b.grow(transformBounds(o.transform, m->geometry->bounds()));
  }
  return b;
}

std::size_t Scene::triangleCount() const {
  std::size_t n = 0;
  for (const Object& o : objects) {
    const Mesh* m = mesh(o.mesh);
    if (m && m->geometry) n += m->geometry->triangleCount();
  }
  return n;
}

float Scene::aspect() const {
  if (settings.width <= 0 || settings.height <= 0) return 1.0f;
  return static_cast<float>(settings.width) / static_cast<float>(settings.height);
}

}  // namespace retile
