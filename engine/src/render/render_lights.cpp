#include "render/render_scene.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numeric>
#include <functional>
#include <iterator>
#include <map>
#include <optional>
#include <unordered_set>

#include "core/files.h"
#include "render/packed_trace.h"
#include "io/image_io.h"
#include "retile/color.h"
#include "retile/error.h"
#include "retile/log.h"
#include "render/pack_util.h"

namespace retile {

using namespace pack;

namespace {

// The sky gradient as an equirectangular image: zenith to horizon above, ground below, with a
// soft horizon so importance sampling sees a smooth function.
LinearImage bakeSky(const Environment& e) {
  LinearImage img;
  img.width = 128;
  img.height = 64;
  img.rgba.resize(static_cast<std::size_t>(img.width * img.height * 4));
  for (int y = 0; y < img.height; ++y) {
    float theta = kPi * (static_cast<float>(y) + 0.5f) / static_cast<float>(img.height);
    float up = std::cos(theta);
    Vec3 c;
    if (up >= 0) {
      float t = std::pow(up, 0.5f);
      c = e.horizon * (1 - t) + e.zenith * t;
    } else {
      float t = std::min(1.0f, -up * 8.0f);
      c = e.horizon * (1 - t) + e.ground * t;
    }
    for (int x = 0; x < img.width; ++x) {
      float* p = &img.rgba[static_cast<std::size_t>((y * img.width + x) * 4)];
      p[0] = c.x;
      p[1] = c.y;
      p[2] = c.z;
      p[3] = 1;
    }
  }
  return img;
}

// Vose's alias method: O(1) sampling of an emitter proportional to its power.
std::vector<vec4> aliasTable(const std::vector<float>& weights) {
  std::size_t n = weights.size();
  std::vector<vec4> table(n, vec4{1, 0, 0, 0});
  double total = std::accumulate(weights.begin(), weights.end(), 0.0);
  if (n == 0 || total <= 0) return table;
  std::vector<double> scaled(n);
  std::vector<std::uint32_t> small, large;
  for (std::size_t i = 0; i < n; ++i) {
    scaled[i] = weights[i] * static_cast<double>(n) / total;
    (scaled[i] < 1.0 ? small : large).push_back(static_cast<std::uint32_t>(i));
  }
  while (!small.empty() && !large.empty()) {
    std::uint32_t s = small.back(), l = large.back();
    small.pop_back();
    table[s] = {static_cast<float>(scaled[s]), bitsOf(static_cast<std::int32_t>(l)), 0, 0};
    scaled[l] = (scaled[l] + scaled[s]) - 1.0;
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  for (std::uint32_t i : large) table[i] = {1.0f, bitsOf(static_cast<std::int32_t>(i)), 0, 0};
  for (std::uint32_t i : small) table[i] = {1.0f, bitsOf(static_cast<std::int32_t>(i)), 0, 0};
  return table;
}

// What lightGroupWeight (lights.glsl) gives the light group of `shape` (two texels,
// FrameUniforms::lightGroups) at p; the kernel's twin, for lightGroupGain.
double lightGroupWeight(const vec4* shape, Vec3 p) {
  const Vec3 toCentre = Vec3{shape[0].x, shape[0].y, shape[0].z} - p;
  const double d2 = std::max<double>(dot(toCentre, toCentre), 1e-30);
  const double w = std::min<double>(shape[0].w / d2, shape[1].w);
  const Vec3 normal{shape[1].x, shape[1].y, shape[1].z};
  if (normal.x == 0 && normal.y == 0 && normal.z == 0) return w;
  const double h = -dot(normal, toCentre);
  return h > 0 ? w * std::min(h / std::sqrt(d2), 1.0) : 0.0;
}

// Appends the two texels of FrameUniforms::lightGroups that lightGroupWeight (lights.glsl) reads
// for the `count` emitters (kEmitterTexels each) from `e`, of `power` and `total` power. One
// plane facing one way, seen from behind, gives nothing, which is what Tungsten's quads say of a
// light facing away; any other shape gives to every side.
void pushLightGroupShape(std::vector<vec4>& out, const vec4* e, const float* power, std::size_t count, double total) {
  Bounds3 bounds;
  Vec3 normal{0.0f}, onPlane{0.0f};
  bool planar = true;
  for (std::size_t k = 0; k < count; ++k) {
    const vec4* t = e + k * gpu::kEmitterTexels;
    const Vec3 w0{t[0].x, t[0].y, t[0].z};
    bounds.grow(w0);
    bounds.grow(w0 + Vec3{t[1].x, t[1].y, t[1].z});
    bounds.grow(w0 + Vec3{t[2].x, t[2].y, t[2].z});
    if (!(power[k] > 0)) continue;
    const Vec3 nrm{t[4].x, t[4].y, t[4].z};
    if (length(normal) == 0) normal = nrm, onPlane = w0;
    else if (!(dot(normal, nrm) > 1 - 1e-5f)) planar = false;
  }
  const float radius = bounds.empty() ? 0.0f : 0.5f * length(bounds.extent());
  Vec3 centre = bounds.empty() ? Vec3{0.0f} : bounds.center();
  const float offset = dot(normal, onPlane);
  // Rounding of the placed vertices grows with their distance from the origin.
  const float slack = 1e-4f * radius + 1e-6f * (std::abs(offset) + length(centre));
  for (std::size_t k = 0; planar && k < count; ++k) {
    const vec4* t = e + k * gpu::kEmitterTexels;
    const Vec3 w0{t[0].x, t[0].y, t[0].z};
    for (Vec3 v : {w0, w0 + Vec3{t[1].x, t[1].y, t[1].z}, w0 + Vec3{t[2].x, t[2].y, t[2].z}})
      if (!(std::abs(dot(normal, v) - offset) <= slack)) planar = false;
  }
  planar = planar && length(normal) > 0;
  if (planar) centre = centre - normal * (dot(normal, centre) - offset);  // onto the plane, which the kernel measures from it
  else normal = Vec3{0.0f};
  // What it gives a point at distance d is about its radiance times the solid angle of its area
  // (a plane's seen at the plane's cosine, a solid's a quarter of its area, a convex body's mean
  // projection), over d^2.
  const float scale = static_cast<float>(total / (planar ? kPi : 4 * kPi));
  out.push_back(v4(centre, scale));
  out.push_back(v4(normal, scale / std::max(radius * radius, 1e-30f)));
}

// What an environment's light-sampling distribution and baked sky are made from, as a key: its
// map (the texture and what was decoded for it) or its sky's colours; empty for a constant.
std::string environmentSource(const Environment& e, const Texture* map, const std::string& mapSignature) {
  auto bits = [](Vec3 v) {
    return cat(std::bit_cast<std::uint32_t>(v.x), ",", std::bit_cast<std::uint32_t>(v.y), ",", std::bit_cast<std::uint32_t>(v.z));
  };
  if (e.type == EnvironmentType::Map && map) return cat("map|", map->id, "|", mapSignature);
  if (e.type == EnvironmentType::Sky) return cat("sky|", bits(e.zenith), "|", bits(e.horizon), "|", bits(e.ground));
  return {};
}

}  // namespace

// Taking the groups' weights as what they give, a light sample's second moment where it picks by
// power among all emitters (the sum over groups of w^2 over the group's share of the power)
// against where it picks a group by weight (W^2, the square of their sum), summed over a grid of
// points through the scene. Points near lights weigh most, as they do in an image.
double lightGroupGain(const std::vector<vec4>& shapes, const std::vector<double>& power, const Bounds3& bounds) {
  const double total = std::accumulate(power.begin(), power.end(), 0.0);
  if (bounds.empty() || !(total > 0)) return 1.0;
  const int n = 12;
  const Vec3 extent = bounds.extent();
  double byPower = 0, byWeight = 0;
  for (int i = 0; i < n * n * n; ++i) {
    const Vec3 f{(static_cast<float>(i % n) + 0.5f) / n, (static_cast<float>(i / n % n) + 0.5f) / n,
                 (static_cast<float>(i / (n * n)) + 0.5f) / n};
    const Vec3 p = bounds.lo + Vec3{f.x * extent.x, f.y * extent.y, f.z * extent.z};
    double sum = 0, moment = 0;
    for (std::size_t g = 0; g < power.size(); ++g) {
      const double w = lightGroupWeight(shapes.data() + 2 * g, p);
      sum += w;
      if (w > 0 && power[g] > 0) moment += w * w * total / power[g];
    }
    byPower += moment;
    byWeight += sum * sum;
  }
  return byWeight > 0 ? byPower / byWeight : 1.0;
}

void RenderSceneBuilder::packEmitters(const Scene& scene) {
  data_.emitters.clear();
  std::vector<float> power;
  // Each emissive instance is a light group, its emitters a run of the table.
  struct Group {
    std::size_t first = 0, count = 0;
  };
  std::vector<Group> groups;
  std::size_t count = data_.instanceObject.size();
  for (std::size_t i = 0; i < count; ++i) {
    const Object* o = scene.object(data_.instanceObject[i]);
    const Material* mat = o && o->visible ? scene.material(o->material) : nullptr;
    if (!mat || !mat->emissive()) continue;
    const MeshEntry* mesh = entryOf(*o);
    const Mat4 transform = placement(o->transform, *mesh);
    Mat4 normalMatrix = transform.inverse().transposed();
    auto first = static_cast<std::int32_t>(data_.emitters.size() / gpu::kEmitterTexels);
    data_.instances[i * gpu::kInstanceTexels + 3].w = bitsOf(first);
    // Light samples pick triangles by power: a textured emitter's is its texture's mean times its
    // emission (light samples read the texture where they land, so any choice stays unbiased).
    Vec3 radiance = mat->radiance();
    if (auto it = textureMean_.find(mat->emissionTexture); it != textureMean_.end()) radiance = radiance * it->second;
    // Not scaled down by an emission cone's share of the hemisphere (sin^2 of its half angle):
    // a spot is aimed at what it lights, where it is as bright as without its cone, and scaled
    // it would get a tenth of the samples at 20 degrees, a grainy spot.
    float radianceLum = std::max(luminance(radiance), 1e-6f);
    std::size_t n = mesh->bvh.primOrder.size();
    groups.push_back({power.size(), n});
    for (std::size_t p = 0; p < n; ++p) {
      const vec4* t = data_.meshTraversal.data() + (std::size_t{mesh->triOffset} + p) * gpu::kTriTexels;
      Vec3 v0{t[0].x, t[0].y, t[0].z};
      Vec3 e1{t[1].x, t[1].y, t[1].z};
      Vec3 e2{t[2].x, t[2].y, t[2].z};
      Vec3 w0 = transform.transformPoint(v0);
      Vec3 w1 = transform.transformPoint(v0 + e1);
      Vec3 w2 = transform.transformPoint(v0 + e2);
      Vec3 c = cross(w1 - w0, w2 - w0);
      float area = 0.5f * length(c);
      // The front side is the object-space winding normal carried by the normal matrix, so a
      // mirrored transform does not turn a light around.
      Vec3 nrm = normalize(normalMatrix.transformVector(cross(e1, e2)));
      data_.emitters.push_back(v4(w0, area));
      data_.emitters.push_back(v4(w1 - w0, bitsOf(static_cast<std::int32_t>(i))));
      // The triangle's packed index and the emission texture's, for its uvs at a light sample.
      data_.emitters.push_back(v4(w2 - w0, bitsOf(static_cast<std::int32_t>(mesh->triOffset + p))));
      data_.emitters.push_back(v4(mat->radiance(), 0));
      data_.emitters.push_back(v4(nrm, bitsOf(textureIndex(mat->emissionTexture))));
      power.push_back(area > 0 && std::isfinite(area) && std::isfinite(radianceLum) ? area * kPi * radianceLum : 0.0f);
    }
  }
  data_.lightInScatteringGlass = lightInScatteringGlass(scene);
  emitterPower_ = static_cast<float>(std::accumulate(power.begin(), power.end(), 0.0));
  // Each group's shape, as lightGroupWeight (lights.glsl) reads it: one plane facing one way,
  // seen from behind, gives nothing, which is what Tungsten's quads say of a light facing away.
  data_.lightGroupShapes.clear();
  std::vector<double> groupPower;
  if (groups.size() >= 2 && groups.size() <= static_cast<std::size_t>(gpu::kMaxLightGroups)) {
    for (const Group& grp : groups) {
      const double total = std::accumulate(power.begin() + static_cast<std::ptrdiff_t>(grp.first),
                                           power.begin() + static_cast<std::ptrdiff_t>(grp.first + grp.count), 0.0);
      groupPower.push_back(total);
      pushLightGroupShape(data_.lightGroupShapes, data_.emitters.data() + grp.first * gpu::kEmitterTexels, power.data() + grp.first,
                          grp.count, total);
    }
  }
  // The choice per point costs every light sample a pass over the groups (a tenth of the
  // spaceship's samples/s, whose lamps it helps little): it is compiled in only where it gains.
  data_.lightGroupGain = groupPower.empty() ? 1.0 : lightGroupGain(data_.lightGroupShapes, groupPower, data_.bounds);
  // Once on, they stay on down to kLightGroupKeepGain: a lamp dragged to and fro across one
  // threshold would otherwise swap kernel variants at each crossing (each a pause on lavapipe the
  // first time). Either variant renders the same image in expectation.
  const double needed = data_.lightGroups > 0 ? kLightGroupKeepGain : kLightGroupMinGain;
  data_.lightGroups = data_.lightGroupGain >= needed ? static_cast<int>(groups.size()) : 0;
  if (data_.lightGroups == 0) {
    groups.assign(1, Group{0, power.size()});
    data_.lightGroupShapes.clear();
  }
  data_.emitterAlias.clear();
  std::vector<vec4> runs;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const Group& grp = groups[g];
    const std::vector<float> part(power.begin() + static_cast<std::ptrdiff_t>(grp.first),
                                  power.begin() + static_cast<std::ptrdiff_t>(grp.first + grp.count));
    const double total = std::accumulate(part.begin(), part.end(), 0.0);
    for (std::size_t k = 0; k < part.size(); ++k)
      data_.emitters[(grp.first + k) * gpu::kEmitterTexels + 3].w = total > 0 ? static_cast<float>(part[k] / total) : 0.0f;
    for (vec4 a : aliasTable(part)) {
      a.y = bitsOf(std::bit_cast<std::int32_t>(a.y) + static_cast<std::int32_t>(grp.first));
      a.z = bitsOf(static_cast<std::int32_t>(g));
      data_.emitterAlias.push_back(a);
    }
    if (data_.lightGroups > 0)
      runs.push_back({bitsOf(static_cast<std::int32_t>(grp.first)), bitsOf(static_cast<std::int32_t>(grp.count)), 0, 0});
  }
  data_.emitterAlias.insert(data_.emitterAlias.end(), runs.begin(), runs.end());

  data_.deltaLights.clear();
  deltaPower_ = 0;
  Bounds3 b = data_.bounds;
  float radius = b.empty() ? 1.0f : 0.5f * length(b.extent());
  data_.suns = 0;
  // Below 1e-4 radians (0.006 degrees) a disc is drawn as the delta light it nearly is: its solid
  // angle would underflow in the radiance's division.
  auto isSun = [](const Light& l) { return l.type == LightType::Directional && l.angularRadius > 1e-4f; };
  std::vector<const Light*> lights;  // suns first: rays that leave the scene look for them alone
  // Through a world's medium that dims every channel, no light from infinitely far gets through.
  const bool skyHidden = data_.worldMedium.dimsEveryChannel();
  for (const Light& l : scene.lights)
    if (l.visible && l.intensity > 0 && maxComponent(l.color) > 0 && !(skyHidden && l.type == LightType::Directional)) lights.push_back(&l);
  std::stable_partition(lights.begin(), lights.end(), [&](const Light* l) { return isSun(*l); });
  for (const Light* light : lights) {
    const Light& l = *light;
    Vec3 intensity = l.color * l.intensity;
    if (isSun(l)) {
      // The disc's radiance is the intensity over its solid angle: a small disc lights what faces
      // it as the delta light of that intensity does, a wider one by E (1 + cos radius) / 2.
      float half = 0.5f * std::min(l.angularRadius, kPi / 2);
      float oneMinusCos = 2 * std::sin(half) * std::sin(half);  // no cancellation for small discs
      float solidAngle = 2 * kPi * oneMinusCos;
      data_.deltaLights.push_back(v4(Vec3{0.0f}, bitsOf(gpu::kLightSun)));
      data_.deltaLights.push_back(v4(normalize(l.direction), oneMinusCos));
      data_.deltaLights.push_back(v4(intensity / solidAngle, solidAngle));
      data_.deltaLights.push_back({0, 0, 0, 0});
      deltaPower_ += kPi * radius * radius * luminance(intensity);
      ++data_.suns;
      continue;
    }
    int type = l.type == LightType::Point ? gpu::kLightPoint : l.type == LightType::Spot ? gpu::kLightSpot : gpu::kLightDirectional;
    float cosOuter = std::cos(std::clamp(l.spotAngle, 0.001f, kPi / 2));
    float cosInner = std::cos(std::clamp(l.spotAngle * (1 - std::clamp(l.spotBlend, 0.0f, 1.0f)), 0.0f, kPi / 2));
    data_.deltaLights.push_back(v4(l.position, bitsOf(type)));
    data_.deltaLights.push_back(v4(normalize(l.direction), cosOuter));
    data_.deltaLights.push_back(v4(intensity, cosInner));
    data_.deltaLights.push_back({0, 0, 0, 0});
    float lum = luminance(intensity);
    if (type == gpu::kLightPoint) deltaPower_ += 4 * kPi * lum;
    else if (type == gpu::kLightSpot) deltaPower_ += 2 * kPi * (1 - 0.5f * (cosInner + cosOuter)) * lum;
    else deltaPower_ += kPi * radius * radius * lum;
  }
}

std::uint32_t RenderSceneBuilder::packEnvironment(const Scene& scene, std::vector<std::string>* warnings) {
  const Environment& e = scene.environment;
  std::uint32_t dirty = 0;
  data_.environmentType = gpu::kEnvNone;
  data_.environmentMap = -1;
  data_.environmentWidth = data_.environmentHeight = 0;
  data_.environmentToMap = environmentToMap(e);
  environmentPower_ = 0;
  Vec3 tint = e.color * e.intensity;
  int map = -1;  // the map's texture index
  std::string source;
  if (e.type == EnvironmentType::Map) {
    // The map is one of the scene's textures, packed with them (packTextures), so it is read
    // like any bitmap and stored once.
    const Texture* t = scene.texture(e.map);
    map = t ? textureIndex(t->id) : -1;
    if (map >= 0 &&
        (std::bit_cast<std::int32_t>(data_.textureInfo[static_cast<std::size_t>(map) * gpu::kTextureTexels].w) & 15) != gpu::kTexBitmap)
      map = -1;  // it could not be read (packTextures said why) and stands in as a checker
    if (map < 0 && warnings) {
      // A file that could not be read leads with its path and why (as a texture's warning does,
      // so that one the import already reported is recognised: importReported).
      const auto read = t ? decoded_.find(t->id) : decoded_.end();
      const std::string why = read != decoded_.end() && !read->second.error.empty() ? read->second.error
                              : t ? cat("environment: the map '", t->name, "' could not be read")
                                  : std::string("environment: no map texture is set");
      warnings->push_back(cat(why, "; the sky is a constant of radiance ", luminance(tint), " instead of the map"));
    }
    if (map >= 0) source = environmentSource(e, t, decoded_[t->id].signature);
  }
  // A sky packed after the scene's textures stays while it is the same sky.
  const std::string sky = e.type == EnvironmentType::Sky ? environmentSource(e, nullptr, {}) : std::string();
  if (packedSky_ != sky) {
    if (data_.texels.size() != sceneTexelWords_ || data_.textureInfo.size() != sceneTextureInfos_) dirty |= kDirtyTextures;
    data_.texels.resize(sceneTexelWords_);
    data_.textureInfo.resize(sceneTextureInfos_);
    data_.halfTexels = sceneHalfTexels_;
    packedSky_.clear();
  }
  if (!sky.empty()) {
    tint = Vec3{e.intensity};
    if (packedSky_ == sky) {
      map = static_cast<int>(sceneTextureInfos_ / gpu::kTextureTexels);
      source = sky;
    } else if (LinearImage baked = bakeSky(e);
               (data_.texels.size() + baked.rgba.size() / 2) / 2 <= static_cast<std::size_t>(gpu::kMaxTexelPairs)) {
      map = static_cast<int>(data_.textureInfo.size() / gpu::kTextureTexels);
      const std::size_t at = data_.texels.size();
      int scale = 0;
      appendHalves(data_.texels, baked.rgba, &scale);
      data_.textureInfo.push_back(
          ints(static_cast<std::int32_t>(at / 2), baked.width, baked.height, gpu::kTexBitmap | scale << gpu::kTexScaleShift));
      data_.textureInfo.push_back(ints(-1, 0, 0, 0));  // no slopes: nothing bumps by a sky
      data_.textureInfo.push_back({0, 0, 0, 0});
      data_.halfTexels = true;
      packedSky_ = source = sky;
      dirty |= kDirtyTextures;
    } else if (warnings) {
      warnings->push_back(cat("environment: the sky and the scene's textures need more than the renderer's ", kMaxTexelBytes >> 20,
                              " MiB of texels; lighting with a constant sky of radiance ", luminance(tint), " instead"));
    }
  }
  if (map < 0) {
    if (!environmentSource_.empty() || data_.environmentCdf.size() != 1) dirty |= kDirtyEnvironment;
    data_.environmentCdf.assign(1, 0.0f);
    environmentSource_.clear();
    if (maxComponent(tint) > 0) {
      data_.environmentType = gpu::kEnvConstant;
      data_.environmentTint = tint;
      environmentPower_ = kPi * luminance(tint);
    }
    return dirty;
  }
  const vec4 info = data_.textureInfo[static_cast<std::size_t>(map) * gpu::kTextureTexels];
  const std::size_t firstWord = static_cast<std::size_t>(std::bit_cast<std::int32_t>(info.x)) * 2;
  const int w = std::bit_cast<std::int32_t>(info.y), h = std::bit_cast<std::int32_t>(info.z), flags = std::bit_cast<std::int32_t>(info.w);
  data_.environmentMap = map;
  data_.environmentType = gpu::kEnvMap;
  data_.environmentTint = tint;
  data_.environmentWidth = w;
  data_.environmentHeight = h;

  if (source != environmentSource_ || data_.environmentCdf.size() == 1) {
    environmentMean_ = environmentDistribution(firstWord, w, h, flags);
    environmentSource_ = source;
    dirty |= kDirtyEnvironment;
  }
  environmentPower_ = kPi * luminance(tint) * static_cast<float>(environmentMean_) * (kPi / 2);
  if (environmentMean_ <= 0) data_.environmentType = gpu::kEnvNone;
  return dirty;
}

double RenderSceneBuilder::environmentDistribution(std::size_t firstWord, int w, int h, int flags) {
  // Piecewise-constant 2D distribution proportional to luminance * sin(theta) of the texel, so
  // directions are drawn in proportion to the radiance they carry. Values are read back from the
  // packed texels so the shader's pdf uses what it samples.
  std::vector<float>& cdf = data_.environmentCdf;
  cdf.assign(1 + static_cast<std::size_t>(h + 1) + static_cast<std::size_t>(h) * static_cast<std::size_t>(w + 1), 0.0f);
  float* marginal = &cdf[1];
  float* conditional = &cdf[1 + static_cast<std::size_t>(h + 1)];
  double total = 0;
  std::vector<double> rowSums(static_cast<std::size_t>(h));
  for (int y = 0; y < h; ++y) {
    float sinTheta = std::sin(kPi * (static_cast<float>(y) + 0.5f) / static_cast<float>(h));
    float* row = conditional + static_cast<std::size_t>(y) * static_cast<std::size_t>(w + 1);
    double acc = 0;
    row[0] = 0;
    for (int x = 0; x < w; ++x) {
      const float lum = luminance(packedTexel(
          data_.texels, firstWord, static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x), flags));
      acc += std::max(lum, 0.0f) * sinTheta;
      row[x + 1] = static_cast<float>(acc);
    }
    rowSums[static_cast<std::size_t>(y)] = acc;
    if (acc > 0)
      for (int x = 1; x <= w; ++x) row[x] = static_cast<float>(row[x] / acc);
    else
      for (int x = 1; x <= w; ++x) row[x] = static_cast<float>(x) / static_cast<float>(w);
    total += acc;
  }
  marginal[0] = 0;
  double acc = 0;
  for (int y = 0; y < h; ++y) {
    acc += rowSums[static_cast<std::size_t>(y)];
    marginal[y + 1] = total > 0 ? static_cast<float>(acc / total) : static_cast<float>(y + 1) / static_cast<float>(h);
  }
  // Normaliser: mean of luminance * sin(theta) over texels. pdf(direction) = lum / (norm * 2 pi^2).
  cdf[0] = total > 0 ? static_cast<float>(total / (static_cast<double>(w) * h)) : 0.0f;
  return total > 0 ? total / (static_cast<double>(w) * h) : 0.0;
}

void RenderSceneBuilder::choosePickProbabilities(const Scene&) {
  Bounds3 b = data_.bounds;
  float radius = b.empty() ? 1.0f : std::max(0.5f * length(b.extent()), 1e-3f);
  // Rough powers; every present kind keeps at least 15 % so a weak but important light (a sky
  // through a small window) is never starved.
  float pe = data_.emitters.empty() ? 0.0f : std::max(emitterPower_, 1e-6f);
  // No light from the environment gets through a world's medium that dims every channel.
  float pv = data_.environmentType == gpu::kEnvNone || data_.worldMedium.dimsEveryChannel()
                 ? 0.0f
                 : std::max(environmentPower_ * kPi * radius * radius, 1e-6f);
  float pd = data_.deltaLights.empty() ? 0.0f : std::max(deltaPower_, 1e-6f);
  float sum = pe + pv + pd;
  float p[3] = {0, 0, 0};
  if (sum > 0) {
    p[0] = pe / sum;
    p[1] = pv / sum;
    p[2] = pd / sum;
    int present = (pe > 0) + (pv > 0) + (pd > 0);
    const float floor = 0.15f;
    if (present > 1) {
      float extra = 0;
      for (int i = 0; i < 3; ++i)
        if ((i == 0 ? pe : i == 1 ? pv : pd) > 0 && p[i] < floor) {
          extra += floor - p[i];
          p[i] = floor;
        }
      float big = 0;
      for (float v : p) big += v > floor ? v - floor : 0;
      for (float& v : p)
        if (v > floor && big > 0) v -= extra * (v - floor) / big;
    }
  }
  for (int i = 0; i < 3; ++i) data_.lightPick[i] = data_.lightSampling ? p[i] : 0.0f;
}

}  // namespace retile
