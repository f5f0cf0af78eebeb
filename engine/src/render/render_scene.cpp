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

namespace retile {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

vec4 v4(Vec3 v, float w) { return {v.x, v.y, v.z, w}; }
float bitsOf(std::int32_t i) { return std::bit_cast<float>(i); }
vec4 ints(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d) {
  return {bitsOf(a), bitsOf(b), bitsOf(c), bitsOf(d)};
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
    const Vec3 f{(static_cast<float>(i % n) + 0.5f) / n, (static_cast<float>(i / n % n) + 0.5f) / n, (static_cast<float>(i / (n * n)) + 0.5f) / n};
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

namespace {

// The item naming the record of `kind` at texel `offset` of the traversal buffer (layouts.h).
std::int32_t traversalItem(std::int64_t offset, int kind) {
  if (offset + 4 > gpu::kMaxTraversalTexels)
    throw Error(cat("the scene's triangles and BVHs need more than ", gpu::kMaxTraversalTexels / 1048576,
                    " M texels (about 35 M triangles), more than the renderer's one traversal buffer holds"));
  return static_cast<std::int32_t>((offset << gpu::kItemOffsetShift) | kind);
}

// The unit (layouts.h kUnitTexels) at texel `offset` of the traversal buffer, as a node's base.
std::uint32_t traversalUnit(std::int64_t offset) {
  RETILE_ASSERT(offset % gpu::kUnitTexels == 0, cat("texel ", offset, " is not at a unit"));
  traversalItem(offset, gpu::kItemNode);  // the same limit
  static_assert(gpu::kMaxTraversalTexels / gpu::kUnitTexels < (1 << gpu::kBaseBits));
  return static_cast<std::uint32_t>(offset / gpu::kUnitTexels);
}

// Appends a node's three texels (layouts.h): n's boxes, quantised, its slots' layout (innerCount
// inner children, `used` slots, leaves of instance records or of triangles, where slots 1..3's
// leaves start) and its two bases, the leaves' `leafUnits` units from leafUnit on.
void pushNode(std::vector<vec4>& out, const BvhNode& n, std::uint32_t innerCount, std::uint32_t used, bool instances,
              std::uint32_t starts, std::uint32_t innerUnit, std::uint32_t leafUnit, std::int32_t leafUnits) {
  if (leafUnits > 0) traversalUnit(gpu::kUnitTexels * (std::int64_t{leafUnit} + leafUnits - 1));  // the last within the limit too
  auto word = [](std::uint32_t u) { return std::bit_cast<float>(u); };
  const QuantizedNode q = quantize(n);
  const std::uint32_t layout = innerCount << gpu::kLayoutInner | used << gpu::kLayoutUsed |
                               (instances ? 1u : 0u) << gpu::kLayoutInstances | starts << gpu::kLayoutStarts;
  out.push_back({q.origin[0], q.origin[1], q.origin[2], word(q.exponents | (layout & 255u) << 24)});
  out.push_back({word(q.lo[0]), word(q.lo[1]), word(q.lo[2]), word(q.hi[0])});
  out.push_back({word(q.hi[1]), word(q.hi[2]), word(innerUnit | (layout >> 8 & 63u) << gpu::kBaseBits),
                 word(leafUnit | (layout >> 14) << gpu::kBaseBits)});
}

// Appends `nodes` (render/bvh.h, child indices local to them) to `out`, a part of the traversal
// buffer that starts at its texel `outBase`. Their leaves' records are at texel `leafBase`, one
// unit per triangle of a mesh BVH, or two per reference of the instance BVH (`instances`).
void appendNodes(std::vector<vec4>& out, const std::vector<BvhNode>& nodes, std::int64_t outBase, std::int64_t leafBase,
                 bool instances) {
  const std::int64_t base = outBase + static_cast<std::int64_t>(out.size());
  const std::int64_t leafTexels = instances ? gpu::kInstanceRecordTexels : gpu::kTriTexels;
  static_assert(gpu::kNodeTexels == gpu::kUnitTexels && gpu::kTriTexels == gpu::kUnitTexels &&
                gpu::kInstanceRecordTexels % gpu::kUnitTexels == 0);
  for (const BvhNode& n : nodes) {
    // The children's layout (layouts.h): inner ones, then leaves, each consecutive, then none.
    std::uint32_t innerCount = 0, used = 0, starts = 0;
    std::int32_t leaf = -1, units = 0;  // the first leaf's record; units of the leaves so far
    for (std::size_t c = 0; c < kBvhWidth; ++c) {
      const std::int32_t index = n.index[c], count = n.count[c];
      if (count < 0) continue;
      RETILE_ASSERT(used == c, "a node's empty slot before a used one");
      ++used;
      if (count == 0) {
        RETILE_ASSERT(innerCount == c && index == n.index[0] + static_cast<std::int32_t>(c), "a node's inner children out of order");
        ++innerCount;
        continue;
      }
      RETILE_ASSERT(instances ? count == 1 : count <= gpu::kMaxLeafTriangles, cat("a leaf of ", count));
      if (leaf < 0) leaf = index;
      RETILE_ASSERT(index == leaf + (instances ? units / 2 : units), "a node's leaves are not consecutive");
      if (c > 0) starts |= static_cast<std::uint32_t>(units) << (gpu::kStartBits * (c - 1));
      units += instances ? 2 : count;
    }
    const std::uint32_t innerUnit = innerCount == 0 ? 0 : traversalUnit(base + std::int64_t{n.index[0]} * gpu::kNodeTexels);
    const std::uint32_t leafUnit = leaf < 0 ? 0 : traversalUnit(leafBase + std::int64_t{leaf} * leafTexels);
    pushNode(out, n, innerCount, used, instances, starts, innerUnit, leafUnit, units);
  }
}

// What the instance BVH's leaf p references when it is packed direct: the record at texel
// `texel` of the traversal buffer, an inner node of a mesh BVH or a run of `triangles`.
struct DirectRef {
  std::int64_t texel;
  bool node;
  std::int32_t triangles;
};

// Appends the instance BVH `nodes` to `out`, the top part of the traversal buffer from its texel
// outBase, with each leaf (one reference) replaced by what it references (layouts.h
// kFeatureDirectReferences), copied from `mesh`, the first part: a mesh BVH's inner node becomes
// an inner child, a copy of that node, whose children stay where they are; a run of triangles
// stays a leaf, a copy of the run placed after the nodes. The copies let a node's children stay
// consecutive, as its two bases require, and cost 48 bytes a node and up to 192 a run (at most
// kMaxBraidReferences of them: 3 MiB).
void appendDirectTop(std::vector<vec4>& out, std::int64_t outBase, const std::vector<BvhNode>& nodes,
                     const std::function<DirectRef(std::int32_t)>& refOf, const std::vector<vec4>& mesh) {
  // The nodes in output order: a node of the instance BVH (tlas >= 0) or a copy. Each node's
  // inner children, its own then its copies, are consecutive from inner[node].
  struct Unit {
    std::int32_t tlas;
    std::int64_t copyFrom;
  };
  std::vector<Unit> units{{0, -1}};
  std::vector<std::size_t> inner(nodes.size(), 0);
  for (std::size_t i = 0; i < units.size(); ++i) {
    if (units[i].tlas < 0) continue;
    const BvhNode& n = nodes[static_cast<std::size_t>(units[i].tlas)];
    inner[static_cast<std::size_t>(units[i].tlas)] = units.size();
    for (std::size_t c = 0; c < kBvhWidth; ++c)
      if (n.count[c] == 0) units.push_back({n.index[c], -1});
    for (std::size_t c = 0; c < kBvhWidth; ++c) {
      RETILE_ASSERT(n.count[c] <= 1, "an instance BVH leaf of more than one reference");
      if (n.count[c] > 0)
        if (const DirectRef r = refOf(n.index[c]); r.node) units.push_back({-1, r.texel});
    }
  }
  const std::int64_t first = outBase + static_cast<std::int64_t>(out.size());
  const std::int64_t leafBase = first + static_cast<std::int64_t>(units.size()) * gpu::kNodeTexels;
  std::vector<vec4> leaves;
  for (const Unit& u : units) {
    if (u.tlas < 0) {
      out.insert(out.end(), mesh.begin() + u.copyFrom, mesh.begin() + u.copyFrom + gpu::kNodeTexels);
      continue;
    }
    const BvhNode& n = nodes[static_cast<std::size_t>(u.tlas)];
    BvhNode slots;  // n's children in the order layouts.h asks for: inner ones, then leaves
    std::uint32_t innerCount = 0, used = 0, starts = 0;
    std::int32_t leafUnits = 0;
    const auto leafUnit = static_cast<std::uint32_t>((leafBase + static_cast<std::int64_t>(leaves.size())) / gpu::kUnitTexels);
    auto take = [&](std::size_t c, std::int32_t count) {
      slots.box[used] = n.box[c];
      slots.count[used] = count;
      ++used;
    };
    for (std::size_t c = 0; c < kBvhWidth; ++c)
      if (n.count[c] == 0) take(c, 0), ++innerCount;
    for (std::size_t c = 0; c < kBvhWidth; ++c)
      if (n.count[c] > 0 && refOf(n.index[c]).node) take(c, 0), ++innerCount;
    for (std::size_t c = 0; c < kBvhWidth; ++c) {
      if (n.count[c] <= 0) continue;
      const DirectRef r = refOf(n.index[c]);
      if (r.node) continue;
      if (used > 0) starts |= static_cast<std::uint32_t>(leafUnits) << (gpu::kStartBits * (used - 1));
      take(c, r.triangles);
      leaves.insert(leaves.end(), mesh.begin() + r.texel, mesh.begin() + r.texel + std::int64_t{r.triangles} * gpu::kTriTexels);
      leafUnits += r.triangles;
    }
    const std::uint32_t innerUnit =
        innerCount == 0 ? 0 : traversalUnit(first + static_cast<std::int64_t>(inner[static_cast<std::size_t>(u.tlas)]) * gpu::kNodeTexels);
    pushNode(out, slots, innerCount, used, false, starts, innerUnit, leafUnits > 0 ? traversalUnit(std::int64_t{leafUnit} * gpu::kUnitTexels) : 0,
             leafUnits);
  }
  out.insert(out.end(), leaves.begin(), leaves.end());
}

std::string textureSignature(const Texture& t, const std::filesystem::path& base) {
  switch (t.kind) {
    case TextureKind::File: return cat("file|", (t.path.is_absolute() ? t.path : base / t.path).string(), "|", static_cast<int>(t.colorSpace));
    case TextureKind::Embedded:
      return cat("emb|", t.encoded.size(), "|", fnv1a64(std::string_view(reinterpret_cast<const char*>(t.encoded.data()), t.encoded.size())), "|", static_cast<int>(t.colorSpace));
    case TextureKind::Checker: return "checker";  // analytic: nothing decoded to cache
  }
  return {};
}

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

}  // namespace

std::uint16_t floatToHalf(float f) {
  std::uint32_t x = std::bit_cast<std::uint32_t>(f);
  std::uint32_t sign = (x >> 16) & 0x8000u;
  std::uint32_t mant = x & 0x7fffffu;
  int exp = static_cast<int>((x >> 23) & 0xff);
  if (exp == 255) return static_cast<std::uint16_t>(sign | 0x7c00u | (mant ? 0x200u : 0));  // inf/nan
  int e = exp - 127 + 15;
  if (e >= 31) return static_cast<std::uint16_t>(sign | 0x7c00u);  // overflow to inf
  if (e <= 0) {
    if (e < -10) return static_cast<std::uint16_t>(sign);
    mant |= 0x800000u;
    int shift = 14 - e;
    std::uint32_t half = mant >> shift;
    std::uint32_t rem = mant & ((1u << shift) - 1);
    std::uint32_t mid = 1u << (shift - 1);
    if (rem > mid || (rem == mid && (half & 1))) ++half;
    return static_cast<std::uint16_t>(sign | half);
  }
  std::uint32_t half = sign | (static_cast<std::uint32_t>(e) << 10) | (mant >> 13);
  std::uint32_t rem = mant & 0x1fffu;
  if (rem > 0x1000u || (rem == 0x1000u && (half & 1))) ++half;  // may carry into the exponent: correct
  return static_cast<std::uint16_t>(half);
}

float halfToFloat(std::uint16_t h) {
  std::uint32_t sign = (h & 0x8000u) << 16;
  std::uint32_t exp = (h >> 10) & 0x1f;
  std::uint32_t mant = h & 0x3ffu;
  std::uint32_t bits;
  if (exp == 0) {
    if (mant == 0) {
      bits = sign;
    } else {
      int e = -1;
      do {
        mant <<= 1;
        ++e;
      } while (!(mant & 0x400u));
      bits = sign | (static_cast<std::uint32_t>(127 - 15 - e) << 23) | ((mant & 0x3ffu) << 13);
    }
  } else if (exp == 31) {
    bits = sign | 0x7f800000u | (mant << 13);
  } else {
    bits = sign | ((exp + 127 - 15) << 23) | (mant << 13);
  }
  return std::bit_cast<float>(bits);
}

std::uint64_t RenderSceneData::deviceBytes() const {
  auto v = [](const auto& x) { return static_cast<std::uint64_t>(x.size() * sizeof(x[0])); };
  return v(meshTraversal) + v(topTraversal) + v(triangleShading) + v(instances) + v(materials) +
         v(textureInfo) + v(texels) + v(emitters) + v(emitterAlias) + v(deltaLights) + v(environmentCdf);
}

int filterFeature(const RenderSettings& s) {
  if (s.filterSampling == FilterSampling::Tungsten && s.pixelFilter == PixelFilter::Tent) return gpu::kFeatureFilterTungstenTent;
  if (s.filterSampling == FilterSampling::Tungsten && s.pixelFilter == PixelFilter::Gaussian) return gpu::kFeatureFilterTungsten;
  return s.pixelFilter == PixelFilter::Tent ? gpu::kFeatureFilterTent : gpu::kFeatureFilterTable;
}

std::uint32_t RenderSceneData::features() const {
  std::uint32_t f = 0;
  if (materialTextures) f |= gpu::kFeatureTextures;
  if (environmentType == gpu::kEnvConstant) f |= gpu::kFeatureEnvConstant;
  if (environmentType == gpu::kEnvMap) f |= gpu::kFeatureEnvMap;
  if (!emitters.empty()) f |= gpu::kFeatureEmitters;
  if (!deltaLights.empty()) f |= gpu::kFeatureDeltaLights;
  if (suns > 0) f |= gpu::kFeatureSun;
  if (tungstenShading) f |= gpu::kFeatureTungstenShading;
  if (tungstenRoulette) f |= gpu::kFeatureTungstenRoulette;
  if (tungstenEpsilon) f |= gpu::kFeatureTungstenEpsilon;
  if (cullBack) f |= gpu::kFeatureCullBack;
  if (minBounces > 0) f |= gpu::kFeatureMinBounces;
  if (lightGroups > 0) f |= gpu::kFeatureLightGroups;
  if (materialBump) f |= gpu::kFeatureBump;
  if (emissionTextures) f |= gpu::kFeatureEmissionTextures;
  if (emissionCones) f |= gpu::kFeatureEmissionCone;
  if (materialBlend) f |= gpu::kFeatureBlend;
  if (instanceTransforms) f |= gpu::kFeatureInstanceTransforms;
  if (directReferences) f |= gpu::kFeatureDirectReferences;
  if (byteTexels) f |= gpu::kFeatureByteTexels;
  if (halfTexels) f |= gpu::kFeatureHalfTexels;
  if (srgbTexels) f |= gpu::kFeatureSrgbTexels;
  return f | static_cast<std::uint32_t>(filterFeature);
}

int RenderSceneBuilder::textureIndex(NodeId id) const {
  auto it = textureIndex_.find(id);
  return it == textureIndex_.end() ? -1 : it->second;
}

int RenderSceneBuilder::materialIndex(NodeId id) const {
  auto it = materialIndex_.find(id);
  return it == materialIndex_.end() ? defaultMaterial_ : it->second;
}

std::uint32_t RenderSceneBuilder::update(const Scene& scene, std::uint32_t flags, std::vector<std::string>* warnings) {
  if (first_) flags = kUpdateAll;
  first_ = false;
  data_.tungstenShading = scene.settings.shading == ShadingConvention::Tungsten;  // a kernel variant, no array
  data_.tungstenRoulette = scene.settings.roulette == Roulette::Tungsten;        // likewise
  data_.tungstenEpsilon = scene.settings.rayOffset == RayOffset::Tungsten;       // likewise
  data_.filterFeature = filterFeature(scene.settings);                          // likewise
  data_.minBounces = std::clamp(scene.settings.minBounces, 0, std::max(scene.settings.maxBounces, 0) + 1);  // likewise
  const bool lightSamplingChanged = data_.lightSampling != scene.settings.lightSampling;
  data_.lightSampling = scene.settings.lightSampling;
  timing_ = {};
  std::uint32_t dirty = 0;
  if (flags & kUpdateTextures || flags & kUpdateEnvironment) {
    auto t = Clock::now();
    // The world's medium is compiled into the kernel as a material's is, and hides the suns.
    if (!(worldMediumOf(scene.environment) == data_.worldMedium)) flags |= kUpdateMaterials;
    if (flags & kUpdateTextures) {
      packTextures(scene, warnings);
      dirty |= kDirtyTextures;
      flags |= kUpdateMaterials;  // texture indices may have moved
    }
    dirty |= packEnvironment(scene, warnings);
    timing_.textures = secondsSince(t);
  }
  if (flags & kUpdateGeometry) {
    auto t = Clock::now();
    packGeometry(scene);
    timing_.blas = secondsSince(t);
    dirty |= kDirtyGeometry;
    flags |= kUpdateInstances;
  }
  if (flags & kUpdateMaterials) {
    packMaterials(scene);
    dirty |= kDirtyMaterials;
    flags |= kUpdateInstances;  // instance flags depend on material type and alpha
  }
  if (flags & (kUpdateInstances | kUpdateLights)) {
    auto t = Clock::now();
    if (packInstances(scene, (flags & kUpdateGeometry) != 0)) dirty |= kDirtyTriangleNames;
    timing_.tlas = secondsSince(t);
    t = Clock::now();
    packEmitters(scene);
    timing_.emitters = secondsSince(t);
    dirty |= kDirtyInstances | kDirtyEmitters;
  }
  if (dirty & (kDirtyEmitters | kDirtyEnvironment | kDirtyInstances) || flags & kUpdateEnvironment || lightSamplingChanged)
    choosePickProbabilities(scene);
  return dirty;
}

namespace {
// Calls `visit` on `m` and on each material it blends with, as the kernel follows the chain
// (fetchMaterial): at most kMaxBlendChain, up to a missing one or one that blends with itself.
template <class Visit>
void forEachInBlend(const Scene& scene, const Material& m, Visit visit) {
  const Material* part = &m;
  for (int k = 0; part && k < kMaxBlendChain; ++k) {
    visit(*part);
    part = part->blendWith != kNoNode && part->blendWith != part->id ? scene.material(part->blendWith) : nullptr;
  }
}

bool sheetInBlend(const Scene& scene, const Material& m) {
  bool sheet = false;
  forEachInBlend(scene, m, [&](const Material& part) { sheet = sheet || part.type == MaterialType::ThinSheet; });
  return sheet;
}

bool finite(const Mat4& t) {
  return std::all_of(&t.m[0][0], &t.m[0][0] + 16, [](float v) { return std::isfinite(v); });
}

// The inverse of a transform a mesh can be packed with: affine, finite, invertible and not
// mirrored (a mirror would turn its triangles' winding, which says which side of an emitter
// shines), with a finite affine inverse. Nothing for any other.
std::optional<Mat4> packedInverse(const Mat4& t) {
  if (!finite(t) || t.m[3][0] != 0 || t.m[3][1] != 0 || t.m[3][2] != 0 || t.m[3][3] != 1) return std::nullopt;
  if (!(t.linearDeterminant() > 0)) return std::nullopt;
  const Mat4 inv = t.inverse();
  if (!finite(inv) || inv.m[3][3] != 1) return std::nullopt;
  return inv;
}
}  // namespace

MediumAt worldMediumOf(const Environment& e) {
  if (!e.filled()) return {};
  return {max(e.mediumAbsorption, Vec3{0.0f}), max(e.mediumScattering, Vec3{0.0f}), std::clamp(e.mediumAnisotropy, -0.99f, 0.99f)};
}

Mat4 RenderSceneBuilder::placement(const Mat4& objectTransform, const MeshEntry& mesh) {
  if (mesh.placed == Mat4::identity()) return objectTransform;
  if (objectTransform == mesh.placed) return Mat4::identity();  // exactly, not by rounding
  return objectTransform * mesh.placedInverse;
}

const RenderSceneBuilder::MeshEntry* RenderSceneBuilder::entryOf(const Object& o) const {
  auto it = meshOf_.find(o.mesh);
  if (it == meshOf_.end()) return nullptr;
  // A copy made before the object took another mesh is not its.
  if (auto c = copyOf_.find(o.id); c != copyOf_.end() && c->second->geometry == it->second->geometry) return c->second;
  return it->second;
}

// Packs e.geometry's triangles and BVH into e, placed by `place` when it can be (packedInverse).
void RenderSceneBuilder::packMesh(MeshEntry& e, const Mat4* place) {
  const MeshGeometry& g = *e.geometry;
  std::vector<Vec3> placedPositions, placedNormals;
  const std::optional<Mat4> inverse = place && !(*place == Mat4::identity()) ? packedInverse(*place) : std::nullopt;
  if (inverse) {
    placedPositions.reserve(g.positions.size());
    for (Vec3 v : g.positions) placedPositions.push_back(place->transformPoint(v));
    // Placed, a hostile file's huge coordinates could overflow: such a mesh keeps its own space.
    if (std::all_of(placedPositions.begin(), placedPositions.end(), [](Vec3 v) { return std::isfinite(v.x + v.y + v.z); })) {
      e.placed = *place;
      e.placedInverse = *inverse;
      // Normals by the inverse transpose, not renormalised: interpolating them then equals
      // interpolating the mesh's own and transforming (the shader normalises).
      const Mat4 normalMatrix = e.placedInverse.transposed();
      placedNormals.reserve(g.normals.size());
      for (Vec3 v : g.normals) placedNormals.push_back(normalMatrix.transformVector(v));
    } else {
      placedPositions = {};
    }
  }
  const bool moved = !(e.placed == Mat4::identity());
  const std::vector<Vec3>& positions = moved ? placedPositions : g.positions;
  const std::vector<Vec3>& normals = moved ? placedNormals : g.normals;
  std::size_t n = g.triangleCount();
  std::vector<Bounds3> boxes(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) boxes[i].grow(positions[g.indices[i * 3 + static_cast<std::size_t>(k)]]);
  // A node's layout has four bits for where each leaf's run starts, and the shader tests runs of at most
  // kMaxLeafTriangles (layouts.h).
  static_assert(kMaxLeafSize <= gpu::kMaxLeafTriangles);
  e.bvh = buildBvh(boxes);
  e.steps = expectedSteps(e.bvh, [](std::uint32_t) { return 1.0f; });
  e.triangles.resize(n * gpu::kTriTexels);
  e.shading.resize(n * gpu::kTriShadeTexels);
  bool hasN = !normals.empty(), hasUv = !g.uvs.empty();
  for (std::size_t p = 0; p < n; ++p) {
    std::size_t src = e.bvh.primOrder[p];
    std::uint32_t i0 = g.indices[src * 3], i1 = g.indices[src * 3 + 1], i2 = g.indices[src * 3 + 2];
    Vec3 v0 = positions[i0], v1 = positions[i1], v2 = positions[i2];
    e.triangles[p * gpu::kTriTexels + 0] = v4(v0, 0);
    e.triangles[p * gpu::kTriTexels + 1] = v4(v1 - v0, 0);
    e.triangles[p * gpu::kTriTexels + 2] = v4(v2 - v0, 0);
    Vec3 n0 = hasN ? normals[i0] : Vec3{}, n1 = hasN ? normals[i1] : Vec3{}, n2 = hasN ? normals[i2] : Vec3{};
    Vec2 t0 = hasUv ? g.uvs[i0] : Vec2{}, t1 = hasUv ? g.uvs[i1] : Vec2{}, t2 = hasUv ? g.uvs[i2] : Vec2{};
    // Zero normals (from NaN in the file) fall back to the geometric normal in the shader.
    bool useN = hasN && dot(n0, n0) > 0 && dot(n1, n1) > 0 && dot(n2, n2) > 0;
    e.shading[p * gpu::kTriShadeTexels + 0] = v4(n0, t0.x);
    e.shading[p * gpu::kTriShadeTexels + 1] = v4(n1, t0.y);
    e.shading[p * gpu::kTriShadeTexels + 2] = v4(n2, t1.x);
    e.shading[p * gpu::kTriShadeTexels + 3] = {t1.y, t2.x, t2.y, useN ? 1.0f : 0.0f};
  }
  // Where each leaf's run ends (layouts.h): traversal goes on to the next triangle until then.
  for (const BvhNode& node : e.bvh.nodes)
    for (std::size_t c = 0; c < kBvhWidth; ++c)
      if (node.count[c] > 0) e.triangles[static_cast<std::size_t>(node.index[c] + node.count[c] - 1) * gpu::kTriTexels + 1].w = 1.0f;
}

void RenderSceneBuilder::packGeometry(const Scene& scene) {
  for (auto& [key, e] : meshes_) e.used = false;
  meshOf_.clear();
  copyOf_.clear();
  // A mesh is packed where its first object puts it. An object that puts a shared mesh elsewhere
  // gets a copy packed where it puts it, so that no instance needs a transform, while the
  // copies stay few: at most an eighth more triangles, or 65536 (8 MiB), whichever is more (a
  // scene of truly instanced meshes keeps one of each, and its transforms).
  std::unordered_map<const MeshGeometry*, const Mat4*> firstPlace;
  std::vector<const Object*> elsewhere;
  std::size_t unique = 0, copied = 0;
  for (const Object& o : scene.objects) {
    const Mesh* m = scene.mesh(o.mesh);
    if (!m || !m->geometry || m->geometry->indices.empty()) continue;
    auto [it, first] = firstPlace.try_emplace(m->geometry.get(), &o.transform);
    if (first) {
      unique += m->geometry->triangleCount();
    } else if (!(o.transform == *it->second) && packedInverse(o.transform)) {
      elsewhere.push_back(&o);
      copied += m->geometry->triangleCount();
    }
  }
  for (const Mesh& m : scene.meshes) {
    if (!m.geometry || m.geometry->indices.empty()) continue;
    auto [it, inserted] = meshes_.try_emplace({m.geometry.get(), kNoNode});
    MeshEntry& e = it->second;
    e.used = true;
    meshOf_[m.id] = &e;
    if (!inserted) continue;
    e.geometry = m.geometry;
    auto place = firstPlace.find(m.geometry.get());
    packMesh(e, place == firstPlace.end() ? nullptr : place->second);
  }
  if (copied <= std::max<std::size_t>(unique / 8, 65536)) {
    for (const Object* o : elsewhere) {
      const Mesh* m = scene.mesh(o->mesh);
      auto [it, inserted] = meshes_.try_emplace({m->geometry.get(), o->id});
      MeshEntry& e = it->second;
      e.used = true;
      copyOf_[o->id] = &e;
      if (!inserted) continue;
      e.geometry = m->geometry;
      packMesh(e, &o->transform);
    }
  }
  std::erase_if(meshes_, [](const auto& kv) { return !kv.second.used; });

  // Triangles first, at texel 3p for packed triangle p, so that shading finds a hit's edges
  // from its index alone; then the BVHs, whose leaves name triangle runs. A mesh's packed
  // triangles live in one place only: a new mesh's in its entry until they are placed here, a
  // kept mesh's in the arrays of the last update, from which they are copied.
  std::size_t triangles = 0, nodes = 0;
  for (const auto& [key, e] : meshes_) {
    triangles += e.bvh.primOrder.size();
    nodes += e.bvh.nodes.size();
  }
  std::vector<vec4> traversal, shading;
  traversal.reserve(triangles * gpu::kTriTexels + nodes * gpu::kNodeTexels);
  shading.reserve(triangles * gpu::kTriShadeTexels);
  for (auto& [key, e] : meshes_) {
    const std::size_t n = e.bvh.primOrder.size();
    const auto offset = static_cast<std::uint32_t>(traversal.size() / gpu::kTriTexels);
    const bool fresh = !e.triangles.empty();
    const vec4* tri = fresh ? e.triangles.data() : data_.meshTraversal.data() + std::size_t{e.triOffset} * gpu::kTriTexels;
    const vec4* shade = fresh ? e.shading.data() : data_.triangleShading.data() + std::size_t{e.triOffset} * gpu::kTriShadeTexels;
    traversal.insert(traversal.end(), tri, tri + n * gpu::kTriTexels);
    shading.insert(shading.end(), shade, shade + n * gpu::kTriShadeTexels);
    for (std::size_t p = 0; p < n; ++p)
      traversal[(offset + p) * gpu::kTriTexels].w = bitsOf(static_cast<std::int32_t>(offset + p));
    e.triOffset = offset;
    e.triangles = std::vector<vec4>();  // `= {}` would clear and keep the memory
    e.shading = std::vector<vec4>();
  }
  data_.meshTraversal = std::move(traversal);
  data_.triangleShading = std::move(shading);
  data_.triangleCount = triangles;
  for (auto& [key, e] : meshes_) {
    auto base = static_cast<std::int64_t>(data_.meshTraversal.size());
    e.rootItem = traversalItem(base, gpu::kItemNode);
    appendNodes(data_.meshTraversal, e.bvh.nodes, 0, std::int64_t{e.triOffset} * gpu::kTriTexels, false);
  }
}

static_assert(gpu::kMaxBlendChain == kMaxBlendChain, "the kernel follows as many blends as the scene allows");

// The kernel's material mask holds a bit per type, then Beckmann's, the coat's and the media's.
static_assert(kMaterialTypeCount <= gpu::kMaskBeckmann && gpu::kMaskBeckmann < gpu::kMaskCoat &&
              gpu::kMaskCoat < gpu::kMaskMedium && gpu::kMaskMedium < gpu::kMaskScattering && gpu::kMaskScattering < 32);
static_assert((1 << gpu::kMaskMedium) == 131072, "common/bsdf.glsl's RETILE_MEDIUM tests this bit");

namespace {
// Transmissive types take no coat (Material::coatIor).
bool coatRendered(const Material& m) { return m.coated() && !isTransmissiveType(m.type); }
}  // namespace

float emissionConeCos(const Material& m) {
  return m.emissionCone < 90 ? std::cos(std::max(m.emissionCone, 0.0f) * (kPi / 180)) : 0.0f;  // NaN: the hemisphere
}

std::array<vec4, gpu::kMaterialTexels> packMaterial(const Material& m, int albedoTexture, int roughnessTexture, int alphaTexture,
                                                    int bumpTexture, int emissionTexture, int blendWith, int blendRatioTexture) {
  Vec3 eta = m.eta, k = m.k;
  if (m.metal != "custom" && !conductorIor(m.metal, &eta, &k)) conductorIor("Cu", &eta, &k);
  // Hair has no complex index: the slot carries its scales' tilt in radians, and its index is
  // the fibre's.
  if (m.type == MaterialType::Hair) eta = Vec3{std::isfinite(m.hairTilt) ? std::clamp(m.hairTilt, -45.0f, 45.0f) * (kPi / 180) : 0.0f, 0.0f, 0.0f};
  const bool rough = isMicrofacet(m.type);
  int type = static_cast<int>(m.type) | (rough && m.beckmann ? gpu::kMatBeckmann : 0) |
             (rough && m.separableShadowing ? gpu::kMatSeparable : 0) | ((isGlassType(m.type) || m.type == MaterialType::ThinSheet) && m.tungstenGlass ? gpu::kMatTungstenGlass : 0);
  // Keep roughness away from zero, where GGX turns into a delta the rough code cannot sample.
  float roughness = std::clamp(m.roughness, 0.0f, 1.0f);
  if (rough || m.type == MaterialType::Phong) roughness = std::max(roughness, 1e-3f);
  if (m.type == MaterialType::OrenNayar) roughness = std::clamp(m.roughness, 0.0f, kPi / 2);
  // A thin sheet has no roughness: the slot carries its film's thickness (Material::filmThickness).
  if (roughnessSlotIsThickness(m.type)) roughness = std::isfinite(m.filmThickness) ? std::clamp(m.filmThickness, 0.0f, 1e5f) : 0.0f;
  float ior = m.type == MaterialType::Hair ? 1.55f : std::clamp(m.ior, 1.0001f, 10.0f);
  const bool coated = coatRendered(m);
  // Diffuse light inside a plastic coating reflects back this fraction at the boundary
  // (Jensen et al.'s polynomial fit of the internal diffuse Fresnel reflectance).
  float fdrInt = -1.4399f / (ior * ior) + 0.7099f / ior + 0.6681f + 0.0636f * ior;
  // Diffuse transmission and Phong have no coating: the texel carries the transmittance or the
  // diffuse ratio instead.
  if (m.type == MaterialType::DiffuseTransmission) fdrInt = std::isfinite(m.transmittance) ? m.transmittance : 0.5f;
  if (m.type == MaterialType::Phong) fdrInt = std::isfinite(m.diffuseRatio) ? m.diffuseRatio : 0.2f;
  return {v4(max(m.albedo, Vec3{0.0f}), bitsOf(type)),
          vec4{roughness, ior, std::clamp(m.alpha, 0.0f, 1.0f), std::clamp(fdrInt, 0.0f, 1.0f)},
          v4(eta, bitsOf(albedoTexture)), v4(k, bitsOf(roughnessTexture)),
          v4(max(m.radiance(), Vec3{0.0f}), bitsOf(alphaTexture)),
          vec4{bitsOf(m.bumpStrength != 0 ? bumpTexture : -1), m.bumpStrength, bitsOf(emissionTexture), bitsOf(blendWith)},
          v4(max(m.coatingAbsorption, Vec3{0.0f}), std::isfinite(m.blendRatio) ? std::clamp(m.blendRatio, 0.0f, 1.0f) : 1.0f),
          vec4{bitsOf(blendRatioTexture), coated ? std::min(m.coatIor, 10.0f) : 0.0f, emissionConeCos(m), 0},
          // The ninth holds the coat or, for glass, which takes no coat, its medium's absorption;
          // the tenth the medium's scattering and its phase function's asymmetry.
          v4(coated ? max(m.coatAbsorption, Vec3{0.0f}) : m.filled() ? max(m.interiorAbsorption, Vec3{0.0f}) : Vec3{0.0f},
             coated && m.coatRoughness > 0 ? std::clamp(m.coatRoughness, 1e-3f, 1.0f) : 0.0f),
          v4(m.filled() ? max(m.interiorScattering, Vec3{0.0f}) : Vec3{0.0f},
             std::isfinite(m.interiorAnisotropy) ? std::clamp(m.interiorAnisotropy, -0.99f, 0.99f) : 0.0f)};
}

void RenderSceneBuilder::packMaterials(const Scene& scene) {
  data_.materials.clear();
  data_.materialTypes = 0;
  data_.materialTextures = false;
  data_.materialBump = false;
  data_.emissionTextures = false;
  data_.emissionCones = false;
  data_.materialBlend = false;
  materialIndex_.clear();
  // Every material's index first: a blend names its partner by index.
  for (std::size_t i = 0; i < scene.materials.size(); ++i) materialIndex_[scene.materials[i].id] = static_cast<int>(i);
  auto pack = [&](const Material& m) {
    data_.materialTypes |= 1u << static_cast<int>(m.type);
    // The kernel compiles Beckmann's distribution in only for scenes that use it.
    if (m.beckmann && isMicrofacet(m.type))
      data_.materialTypes |= 1u << gpu::kMaskBeckmann;
    if (coatRendered(m)) data_.materialTypes |= 1u << gpu::kMaskCoat;
    if (m.filled()) data_.materialTypes |= 1u << gpu::kMaskMedium;
    if (m.filled() && maxComponent(m.interiorScattering) > 0) data_.materialTypes |= 1u << gpu::kMaskScattering;
    // A type without roughness reads no roughness texture: the kernel would scale what the slot
    // holds for it (hair's tilt) by the texture's mean.
    const int roughnessTexture = readsRoughnessSlot(m.type) ? textureIndex(m.roughnessTexture) : -1;
    if (textureIndex(m.albedoTexture) >= 0 || roughnessTexture >= 0) data_.materialTextures = true;
    if (textureIndex(m.bumpTexture) >= 0 && m.bumpStrength != 0) data_.materialBump = true;
    if (textureIndex(m.emissionTexture) >= 0 && m.emissive()) data_.emissionTextures = true;
    if (emissionConeCos(m) != 0 && m.emissive()) data_.emissionCones = true;
    int blendWith = -1, ratioTexture = -1;
    const bool texturedRatio = textureIndex(m.blendRatioTexture) >= 0;
    // A boundary blends with nothing and nothing with it: the traversal takes an instance's own
    // material for whether its shadow rays pass, and a surface that were partly a boundary would
    // block them all the same.
    const auto it = materialIndex_.find(m.blendWith);
    const bool boundary = m.type == MaterialType::Boundary ||
                          (it != materialIndex_.end() && scene.materials[static_cast<std::size_t>(it->second)].type == MaterialType::Boundary);
    if (!boundary && it != materialIndex_.end() && m.blendWith != m.id && (m.blendRatio < 1.0f || texturedRatio)) {
      blendWith = it->second;
      data_.materialBlend = true;
      if (texturedRatio) {
        ratioTexture = textureIndex(m.blendRatioTexture);
        data_.materialTextures = true;
      }
    }
    auto texels = packMaterial(m, textureIndex(m.albedoTexture), roughnessTexture, textureIndex(m.alphaTexture),
                               textureIndex(m.bumpTexture), textureIndex(m.emissionTexture), blendWith, ratioTexture);
    data_.materials.insert(data_.materials.end(), texels.begin(), texels.end());
  };
  for (const Material& m : scene.materials) pack(m);
  // The world's medium compiles the same kernel code in as a material's (trace.comp RETILE_MEDIUM).
  const Environment& env = scene.environment;
  const bool fog = env.filled();
  data_.worldMedium = worldMediumOf(env);
  if (fog) data_.materialTypes |= 1u << gpu::kMaskMedium;
  if (fog && maxComponent(env.mediumScattering) > 0) data_.materialTypes |= 1u << gpu::kMaskScattering;
  defaultMaterial_ = static_cast<int>(data_.materials.size() / gpu::kMaterialTexels);
  Material fallback;
  fallback.albedo = Vec3{0.6f};
  pack(fallback);
}

MediaAround mediaAround(const RenderSceneData& d, Vec3 point) {
  // Outside every holder is the world's medium. Glass holds a vacuum at least, so where the world
  // has a medium, empty glass counts too.
  const MediaAround outside{d.worldMedium, d.worldMedium};
  constexpr std::uint32_t kHolders = 1u << gpu::kMatDielectric | 1u << gpu::kMatRoughDielectric | 1u << gpu::kMatBoundary;
  if (!(d.materialTypes & (1u << gpu::kMaskMedium)) || !(d.materialTypes & kHolders) || d.tlasRoot < 0) return outside;
  const bool transforms = d.instanceTransforms;
  const bool direct = d.directReferences && !transforms;
  auto intOf = [](float f) { return std::bit_cast<std::int32_t>(f); };
  auto mediumOf = [&](std::int32_t material) {
    if (material < 0) return d.worldMedium;
    const std::size_t mbase = static_cast<std::size_t>(material) * gpu::kMaterialTexels;
    const vec4 &interior = d.materials[mbase + 8], &scattering = d.materials[mbase + 9];
    const int type = intOf(d.materials[mbase].w) & gpu::kMatTypeBits;
    return MediumAt{{interior.x, interior.y, interior.z}, {scattering.x, scattering.y, scattering.z}, scattering.w,
                    type == gpu::kMatDielectric || type == gpu::kMatRoughDielectric};
  };
  // The first two holders a ray from the point leaves by faces it did not come in by (-1: it
  // leaves the scene first). kUndecided where it meets an opaque surface before (a wall does not
  // tell which of its sides a medium is on: the volumetric caustic's gas fills a box of plain
  // walls closed by one boundary), unless `throughWalls`. Glass counts even empty (the path is in
  // a vacuum inside it), a boundary only with its medium (one without leaves the path's as it is).
  constexpr std::int32_t kUndecided = -2;
  struct Left {
    std::int32_t first = kUndecided, second = kUndecided;
  };
  auto leftBy = [&](Vec3 dir, bool throughWalls) {
    Left left;
    std::vector<std::int32_t> entered;
    Vec3 origin = point;
    for (int hits = 0; hits < 64; ++hits) {
      const PackedTrace hit = tracePacked(d.meshTraversal, d.topTraversal, d.tlasRoot, direct, origin, dir, 1e30f);
      if (hit.prim < 0) {
        (left.first == kUndecided ? left.first : left.second) = -1;
        return left;
      }
      const std::size_t base = static_cast<std::size_t>(hit.instance) * gpu::kInstanceTexels;
      const std::int32_t material = hit.instance >= 0 && base + 3 < d.instances.size() ? intOf(d.instances[base + 3].z) : -1;
      const std::size_t mbase = static_cast<std::size_t>(material) * gpu::kMaterialTexels;
      if (material < 0 || mbase + 9 >= d.materials.size()) return left;
      const int type = intOf(d.materials[mbase].w) & gpu::kMatTypeBits;
      const MediumAt medium = mediumOf(material);
      const bool filled = maxComponent(medium.absorption + medium.scattering) > 0;
      const bool glass = medium.glass;
      if (!glass && type != gpu::kMatBoundary && !throughWalls) return left;
      if (glass || (type == gpu::kMatBoundary && filled)) {
        const vec4* t = d.meshTraversal.data() + static_cast<std::size_t>(hit.prim) * gpu::kTriTexels;
        Vec3 n = cross(Vec3{t[1].x, t[1].y, t[1].z}, Vec3{t[2].x, t[2].y, t[2].z});
        if (transforms) {  // the rows of the inverse transform, transposed: the normal's matrix
          const vec4* r = d.instances.data() + base;
          n = Vec3{r[0].x * n.x + r[1].x * n.y + r[2].x * n.z, r[0].y * n.x + r[1].y * n.y + r[2].y * n.z,
                   r[0].z * n.x + r[1].z * n.y + r[2].z * n.z};
        }
        if (dot(n, dir) < 0) {
          entered.push_back(material);
        } else if (!entered.empty() && entered.back() == material) {
          entered.pop_back();
        } else if (left.first == kUndecided) {
          left.first = material;
        } else {
          left.second = material;
          return left;
        }
      }
      const Vec3 at = origin + dir * hit.t;
      origin = at + dir * (1e-4f * (1.0f + std::max({std::abs(at.x), std::abs(at.y), std::abs(at.z)})));
    }
    return left;
  };
  // Fourteen directions (the faces' and the corners' of a cube, turned off the axes, so that no
  // ray runs along a wall or through an edge by design). A holder left is evidence; a ray that
  // leaves the scene is not against it (one side of an open boundary, a water surface, is its
  // medium's), so the holder most rays leave wins, and none only when no ray leaves one. Where
  // every ray meets a wall first, they are cast again through the walls.
  static const Vec3 kDirections[14] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},  {0, -1, 0}, {0, 0, 1},  {0, 0, -1}, {1, 1, 1},
                                       {1, 1, -1}, {1, -1, 1}, {1, -1, -1}, {-1, 1, 1}, {-1, 1, -1}, {-1, -1, 1}, {-1, -1, -1}};
  const Mat4 turn = Mat4::rotateY(0.37f) * Mat4::rotateX(0.23f);
  Left rays[14];
  bool decided = false;
  for (bool throughWalls : {false, true}) {
    for (int i = 0; i < 14; ++i) {
      rays[i] = leftBy(normalize(turn.transformVector(kDirections[i])), throughWalls);
      decided = decided || rays[i].first != kUndecided;
    }
    if (decided) break;
  }
  auto mostLeft = [&](std::int32_t Left::*which, std::int32_t given) {  // of the rays whose first is `given`, if any
    std::map<std::int32_t, int> votes;
    for (const Left& l : rays)
      if (l.*which >= 0 && (given < 0 || l.first == given)) ++votes[l.*which];
    std::int32_t best = -1;
    int most = 0;
    for (const auto& [m, n] : votes)
      if (n > most) {
        most = n;
        best = m;
      }
    return best;
  };
  const std::int32_t inner = mostLeft(&Left::first, -1);
  return inner < 0 ? outside : MediaAround{mediumOf(inner), mediumOf(mostLeft(&Left::second, inner))};
}

namespace {
struct SampleRay {
  Vec3 origin, direction;
};
constexpr float kRayFar = 1e30f;
constexpr int kSamplePaths = 1024;

// A visible instance's triangles, where sample paths may start when the camera sees little.
struct SampleSurface {
  std::uint32_t triOffset, triangles;
  const Mat4* toWorld;    // from the mesh's packed space
  const Mat4* fromWorld;  // its inverse
};

// Rays as a path tracer sends them, to count what a packing costs: from the camera through
// random points of the image, then two diffuse bounces (cosine-weighted, on the side the ray
// came from) from where they hit, traced through the packing given (mesh, top, root). Where
// fewer than a quarter of the camera's rays hit anything (a camera inside a wall or looking
// away), as many paths again start on the visible triangles (chosen by count) with one bounce,
// so that the choice still sees the geometry the camera will turn to. A fixed sequence, so that
// a scene gets the same choice each time it is packed. The shadow rays a path also sends are
// not among them. fromWorldOf(instance): the inverse of the instance's transform to world space.
std::vector<SampleRay> sampleRays(const Scene& scene, const std::vector<vec4>& mesh, const std::vector<vec4>& top, std::int32_t root,
                                  bool direct, std::span<const SampleSurface> surfaces,
                                  const std::function<const Mat4&(std::int32_t)>& fromWorldOf) {
  std::vector<SampleRay> rays;
  std::uint32_t state = 0x9e3779b9u;
  auto random = [&] {  // xorshift32: the same numbers on every platform, unlike <random>'s distributions
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return static_cast<float>(state >> 8) * (1.0f / 16777216.0f);
  };
  // A cosine-weighted direction about n, and the point `at` off the surface towards n by a
  // little more than its coordinates' rounding.
  auto leave = [&](Vec3 at, Vec3 n) {
    const float offset = 1e-4f * (1.0f + std::max({std::abs(at.x), std::abs(at.y), std::abs(at.z)}));
    const float r = std::sqrt(random()), phi = 2 * kPi * random();
    const Vec3 a = std::abs(n.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 u = normalize(cross(a, n)), v = cross(n, u);
    return SampleRay{at + n * offset, normalize(u * (r * std::cos(phi)) + v * (r * std::sin(phi)) + n * std::sqrt(std::max(0.0f, 1 - r * r)))};
  };
  // Traces a path from `ray` for up to `bounces` bounces; whether its first ray hit.
  auto follow = [&](SampleRay ray, int bounces) {
    bool hitFirst = false;
    for (int bounce = 0; bounce <= bounces; ++bounce) {
      if (!std::isfinite(ray.origin.x + ray.origin.y + ray.origin.z + ray.direction.x + ray.direction.y + ray.direction.z)) break;
      rays.push_back(ray);
      const PackedTrace hit = tracePacked(mesh, top, root, direct, ray.origin, ray.direction, kRayFar);
      hitFirst = hitFirst || (bounce == 0 && hit.prim >= 0);
      if (hit.prim < 0 || bounce == bounces) break;
      const vec4* t = mesh.data() + static_cast<std::size_t>(hit.prim) * gpu::kTriTexels;
      Vec3 n = cross(Vec3{t[1].x, t[1].y, t[1].z}, Vec3{t[2].x, t[2].y, t[2].z});
      if (hit.instance >= 0) n = fromWorldOf(hit.instance).transposed().transformVector(n);
      if (!(length(n) > 0)) break;
      n = normalize(n);
      ray = leave(ray.origin + ray.direction * hit.t, dot(n, ray.direction) > 0 ? -n : n);
    }
    return hitFirst;
  };
  const Camera& cam = scene.camera;
  const Mat4 toWorld = Mat4::lookAt(cam.position, cam.target, cam.up);
  const float tanHalf = std::tan(0.5f * std::clamp(cam.verticalFov, 1e-3f, 3.1f));
  const float aspect = scene.settings.height > 0 ? static_cast<float>(scene.settings.width) / static_cast<float>(scene.settings.height) : 1.0f;
  int seen = 0;
  for (int path = 0; path < kSamplePaths; ++path) {
    const float x = (2 * random() - 1) * tanHalf * aspect, y = (2 * random() - 1) * tanHalf;
    seen += follow({cam.position, normalize(toWorld.transformVector(Vec3{x, y, -1}))}, 2) ? 1 : 0;
  }
  std::vector<std::uint64_t> before;  // triangles of the surfaces before each
  std::uint64_t total = 0;
  for (const SampleSurface& f : surfaces) {
    before.push_back(total);
    total += f.triangles;
  }
  for (int path = 0; seen < kSamplePaths / 4 && total > 0 && path < kSamplePaths; ++path) {
    const auto k = std::min(static_cast<std::uint64_t>(random() * static_cast<float>(total)), total - 1);
    const std::size_t f = static_cast<std::size_t>(std::upper_bound(before.begin(), before.end(), k) - before.begin()) - 1;
    const vec4* t = mesh.data() + (std::size_t{surfaces[f].triOffset} + (k - before[f])) * gpu::kTriTexels;
    const Vec3 v0{t[0].x, t[0].y, t[0].z}, e1{t[1].x, t[1].y, t[1].z}, e2{t[2].x, t[2].y, t[2].z};
    const float r = std::sqrt(random()), b = random();
    const Mat4& m = *surfaces[f].toWorld;
    const Vec3 n = surfaces[f].fromWorld->transposed().transformVector(cross(e1, e2));
    if (!(length(n) > 0)) continue;
    const Vec3 side = normalize(n) * (random() < 0.5f ? 1.0f : -1.0f);
    follow(leave(m.transformPoint(v0 + e1 * (r * (1 - b)) + e2 * (r * b)), side), 1);
  }
  return rays;
}
}  // namespace

bool RenderSceneBuilder::packInstances(const Scene& scene, bool chooseBraid) {
  struct Candidate {
    const Object* object;
    const MeshEntry* mesh;
    Mat4 transform;  // from the mesh's packed space to world space
    Bounds3 bounds;
    bool visible;
  };
  // Hidden objects are instances too, with no reference in the instance BVH: so an instance's
  // number does not change when another is hidden or shown, and with direct references (below)
  // the triangles that carry it need not be uploaded again.
  std::vector<Candidate> cands;
  std::size_t visible = 0;
  for (const Object& o : scene.objects) {
    const MeshEntry* mesh = entryOf(o);
    if (!mesh) continue;
    const Mat4 t = placement(o.transform, *mesh);
    Bounds3 b = transformBounds(t, mesh->bvh.bounds);
    if (b.empty()) continue;
    cands.push_back({&o, mesh, t, b, o.visible});
    visible += o.visible ? 1 : 0;
  }

  // Where instances overlap, a ray inside their union is inside every one of their boxes and
  // must enter each. So the instance BVH is built over references to subtrees of the instances'
  // BVHs (partial re-braiding, after Benthin et al. 2017): starting from each instance's root,
  // the reference with the largest box is replaced by its children (up to four) until there are
  // `factor` references per instance. A reference is entered like an instance, at its subtree.
  // Where instances do not overlap, opening them gains nothing, so the factor is chosen by the
  // steps it costs sample rays (below), and kept across small edits (when, below), so that a
  // move builds one instance BVH, whose size stays proportional to the number of objects.
  struct Ref {
    std::uint32_t cand;
    std::int32_t item;  // where traversal enters the instance's BVH
    std::int32_t node;  // that BVH's node index when item is an inner node, else -1
    Bounds3 bounds;     // world space
    std::int32_t triangles = 0;  // a leaf's, when item is one
  };
  auto braid = [&](std::size_t budget) {
    std::vector<Ref> refs;
    refs.reserve(budget);
    for (std::uint32_t c = 0; c < cands.size(); ++c)
      if (cands[c].visible) refs.push_back({c, cands[c].mesh->rootItem, 0, cands[c].bounds});
    auto smaller = [&](std::size_t a, std::size_t b) { return refs[a].bounds.area() < refs[b].bounds.area(); };
    std::vector<std::size_t> open(refs.size());  // a max-heap by area of the references that can still be opened
    std::iota(open.begin(), open.end(), std::size_t{0});
    std::make_heap(open.begin(), open.end(), smaller);
    while (!open.empty() && refs.size() < budget) {
      std::pop_heap(open.begin(), open.end(), smaller);
      const std::size_t r = open.back();
      open.pop_back();
      const Candidate& c = cands[refs[r].cand];
      const BvhNode& n = c.mesh->bvh.nodes[static_cast<std::size_t>(refs[r].node)];
      const std::int64_t nodes = c.mesh->rootItem >> gpu::kItemOffsetShift;
      std::vector<Ref> children;
      for (std::size_t k = 0; k < kBvhWidth; ++k) {
        const std::int32_t index = n.index[k], count = n.count[k];
        if (count < 0) continue;
        const Bounds3 world = transformBounds(c.transform, n.box[k]);
        if (count == 0)
          children.push_back({refs[r].cand, traversalItem(nodes + std::int64_t{index} * gpu::kNodeTexels, gpu::kItemNode), index, world});
        else
          children.push_back({refs[r].cand, traversalItem((std::int64_t{c.mesh->triOffset} + index) * gpu::kTriTexels, gpu::kItemTriangles),
                              -1, world, count});
      }
      if (children.size() < 2) continue;  // a leaf root: nothing to open
      const std::size_t first = refs.size();
      refs[r] = children[0];
      refs.insert(refs.end(), children.begin() + 1, children.end());
      auto reopen = [&](std::size_t i) {
        if (refs[i].node < 0) return;
        open.push_back(i);
        std::push_heap(open.begin(), open.end(), smaller);
      };
      reopen(r);
      for (std::size_t i = first; i < refs.size(); ++i) reopen(i);
    }
    return refs;
  };
  // Direct references (layouts.h kFeatureDirectReferences) need every instance in world space as
  // packed, and each triangle in one instance only, as it names it.
  bool transforms = false, shared = false;
  {
    std::unordered_set<const MeshEntry*> seen;
    for (const Candidate& c : cands) {
      if (!c.visible) continue;
      transforms = transforms || !(c.transform == Mat4::identity());
      shared = shared || !seen.insert(c.mesh).second;
    }
  }
  // A triangle names its instance in kTriInstanceMask's bits.
  const bool direct = directReferences_ && !transforms && !shared && cands.size() <= static_cast<std::size_t>(gpu::kTriInstanceMask);
  BvhBuildOptions opt;
  opt.maxLeafSize = 1;  // a TLAS leaf is one reference: traversal enters its subtree directly
  auto build = [&](std::size_t factor, bool packDirect, std::vector<Ref>* refs) {
    *refs = braid(std::max(visible, std::min(visible * factor, kMaxBraidReferences)));
    std::vector<Bounds3> boxes;
    boxes.reserve(refs->size());
    for (const Ref& r : *refs) boxes.push_back(r.bounds);
    // Entering a reference is one step, unless packed direct, then its subtree's.
    const float enter = packDirect ? 0.0f : 1.0f;
    opt.primCost = [&, enter](std::uint32_t i) {
      const Ref& r = (*refs)[i];
      if (r.node >= 0) return enter + cands[r.cand].mesh->steps[static_cast<std::size_t>(r.node)];
      return enter + static_cast<float>(r.triangles);  // a leaf: its triangles
    };
    return buildBvh(boxes, opt);
  };

  // The instances' records, flags and numbers first: the instance BVH's packing needs them.
  data_.directReferences = direct;
  data_.instances.clear();
  data_.instanceObject.clear();
  data_.instancedTriangles = 0;
  data_.cutOuts = data_.sheetShadows = false;
  data_.cullBack = false;
  data_.instanceTransforms = transforms;
  std::vector<int> flagsOf(cands.size(), 0);
  std::vector<Mat4> inverseOf(cands.size());
  for (std::size_t i = 0; i < cands.size(); ++i) {
    const Candidate& c = cands[i];
    const Material* mat = scene.material(c.object->material);
    int flags = 0;
    // A boundary is crossed whole (its medium must not be left at random).
    if (mat && mat->type != MaterialType::Boundary && (mat->alpha < 1.0f || textureIndex(mat->alphaTexture) >= 0))
      flags |= gpu::kInstanceAlphaTested;
    if (mat && sheetInBlend(scene, *mat)) flags |= gpu::kInstanceSheet;
    if (mat && mat->emissive()) flags |= gpu::kInstanceEmissive;
    if (mat && mat->type == MaterialType::Boundary) flags |= gpu::kInstanceBoundary;
    if (c.object->cullBackFaces) flags |= gpu::kInstanceCullBack;
    if (c.visible && (flags & gpu::kInstanceAlphaTested)) data_.cutOuts = true;
    // A sheet's pause is the cut-outs' (RETILE_ALPHA_TEST).
    if (c.visible && (flags & gpu::kInstanceSheet)) data_.sheetShadows = true;
    if (c.visible && (flags & gpu::kInstanceCullBack)) data_.cullBack = true;
    flagsOf[i] = flags;
    inverseOf[i] = c.transform.inverse();
    const Mat4& inv = inverseOf[i];
    for (int r = 0; r < 3; ++r) data_.instances.push_back({inv.m[r][0], inv.m[r][1], inv.m[r][2], inv.m[r][3]});
    data_.instances.push_back(ints(0, static_cast<std::int32_t>(c.mesh->triOffset), materialIndex(c.object->material), -1));
    data_.instances.push_back(ints(static_cast<std::int32_t>(i) + 1, flags, 0, 0));
    data_.instanceObject.push_back(c.object->id);
    if (c.visible) data_.instancedTriangles += c.mesh->bvh.primOrder.size();
  }
  // Direct, each triangle names its instance: a visible object's, or where none uses its mesh
  // a hidden one's, so that showing it later changes nothing. The names change when objects are
  // added or removed (or a cut-out's or culling flag changes), and then the meshes' part is
  // uploaded again; a mesh whose triangles already name the right instance is not touched.
  bool renamed = false;
  if (direct) {
    std::unordered_map<const MeshEntry*, std::size_t> namer;
    for (std::size_t i = 0; i < cands.size(); ++i)
      if (cands[i].visible) namer[cands[i].mesh] = i;
    for (std::size_t i = 0; i < cands.size(); ++i)
      if (!cands[i].visible) namer.try_emplace(cands[i].mesh, i);
    for (const auto& [mesh, i] : namer) {
      const std::uint32_t name = static_cast<std::uint32_t>(i) | ((flagsOf[i] & gpu::kInstanceAlphaTested) ? gpu::kTriAlphaTested : 0u) |
                                 ((flagsOf[i] & gpu::kInstanceBoundary) ? gpu::kTriBoundary : 0u) |
                                 ((flagsOf[i] & gpu::kInstanceCullBack) ? gpu::kTriCullBack : 0u) |
                                 ((flagsOf[i] & gpu::kInstanceSheet) ? gpu::kTriSheet : 0u);
      if (mesh->named == name) continue;
      mesh->named = name;
      renamed = true;
      const std::size_t from = mesh->triOffset, to = from + mesh->bvh.primOrder.size();
      for (std::size_t p = from; p < to; ++p) data_.meshTraversal[p * gpu::kTriTexels + 2].w = std::bit_cast<float>(name);
    }
  }

  // The top part of the traversal buffer: the instance BVH, then one record per reference (in
  // the BVH's packed order), or, direct, what the references name (copied after the numbering,
  // so that copies of triangles carry it too).
  const auto base = static_cast<std::int64_t>(data_.meshTraversal.size());
  auto pack = [&](const Bvh& tlas, const std::vector<Ref>& refs, bool packDirect) {
    std::vector<vec4> top;
    if (packDirect) {
      appendDirectTop(top, base, tlas.nodes, [&](std::int32_t p) {
        const Ref& r = refs[tlas.primOrder[static_cast<std::size_t>(p)]];
        return DirectRef{r.item >> gpu::kItemOffsetShift, r.node >= 0, r.triangles};
      }, data_.meshTraversal);
      return top;
    }
    const auto records = base + static_cast<std::int64_t>(tlas.nodes.size()) * gpu::kNodeTexels;
    appendNodes(top, tlas.nodes, base, records, true);
    for (std::uint32_t p : tlas.primOrder) {
      const Ref& r = refs[p];
      const Mat4& inv = inverseOf[r.cand];
      top.push_back(ints(r.item, static_cast<std::int32_t>(r.cand), flagsOf[r.cand], 0));
      for (int row = 0; row < 3; ++row) top.push_back({inv.m[row][0], inv.m[row][1], inv.m[row][2], inv.m[row][3]});
      top.insert(top.end(), gpu::kInstanceRecordTexels - 4, vec4{});
    }
    RETILE_ASSERT(records + static_cast<std::int64_t>(refs.size()) * gpu::kInstanceRecordTexels ==
                      base + static_cast<std::int64_t>(top.size()),
                  "instance records out of place");
    return top;
  };
  data_.tlasRoot = traversalItem(base, gpu::kItemNode);

  // How far instances are opened: the factor whose packing costs sample rays the fewest
  // traversal steps, counted as the kernel counts them (tracePacked). The surface area
  // heuristic, used before, assumes rays come from outside every box; a path's rays start on
  // surfaces, inside the boxes of the instances around them, and the heuristic kept the living
  // room's objects whole where 16 references each take 10 % fewer loop iterations a path. A
  // factor must save 1 % of the steps to be taken: more references cost memory and build time.
  // The rays leave the camera as it is when the factor is chosen.
  //
  // Choosing costs tens of milliseconds (the spaceship 30, a room of a million triangles 60), so
  // it is done when meshes change, or when the visible objects differ from those of the last
  // choice by more than an eighth of those (and by more than two), not for each object shown,
  // hidden, added or removed, which would delay the editor's next frame by as much. Direct, a
  // reference costs no step of its own, so the factor for records differs: a scene packed direct
  // chooses it too, from the same rays, so that the first move (which turns direct off) need not
  // choose. A scene packed with records that turns direct (its transforms undone, a duplicate
  // removed) chooses the direct factor then.
  std::vector<NodeId> visibleIds;
  visibleIds.reserve(visible);
  for (const Candidate& c : cands)
    if (c.visible) visibleIds.push_back(c.object->id);
  std::sort(visibleIds.begin(), visibleIds.end());
  std::vector<NodeId> differ;  // objects visible now or then but not both
  std::set_symmetric_difference(visibleIds.begin(), visibleIds.end(), braidVisible_.begin(), braidVisible_.end(), std::back_inserter(differ));
  if (chooseBraid || differ.size() > std::max<std::size_t>(braidVisible_.size() / 8, 2)) {
    braidVisible_ = std::move(visibleIds);
    braidFactor_ = {0, 0};
  }
  std::vector<Ref> refs;
  Bvh tlas;
  std::vector<vec4> top;
  if (braidFactor_[direct] == 0) {
    ++braidChoices_;
    std::vector<Ref> probeRefs;  // the rays are traced through the packing of factor 1
    Bvh probe = build(1, direct, &probeRefs);
    std::vector<vec4> probeTop = pack(probe, probeRefs, direct);
    std::vector<SampleSurface> surfaces;
    for (std::size_t i = 0; i < cands.size(); ++i)
      if (cands[i].visible)
        surfaces.push_back({cands[i].mesh->triOffset, static_cast<std::uint32_t>(cands[i].mesh->bvh.primOrder.size()), &cands[i].transform, &inverseOf[i]});
    const std::vector<SampleRay> rays = sampleRays(scene, data_.meshTraversal, probeTop, data_.tlasRoot, direct, surfaces, [&](std::int32_t instance) -> const Mat4& {
      return inverseOf[static_cast<std::size_t>(instance)];
    });
    auto stepsOf = [&](const std::vector<vec4>& packed, bool packDirect) {
      std::uint64_t steps = 0;
      for (const SampleRay& r : rays) steps += tracePacked(data_.meshTraversal, packed, data_.tlasRoot, packDirect, r.origin, r.direction, kRayFar).steps;
      return steps;
    };
    // The factor for packing `packDirect`, and with `keep` its instance BVH and packing. Factor 1
    // in the current packing is the probe's.
    auto choose = [&](bool packDirect, bool keep) {
      std::vector<Ref> bestRefs;
      Bvh bestTlas;
      std::vector<vec4> bestTop;
      if (packDirect == direct) {
        bestRefs = std::move(probeRefs);
        bestTlas = std::move(probe);
        bestTop = std::move(probeTop);
      } else {
        bestTlas = build(1, packDirect, &bestRefs);
        bestTop = pack(bestTlas, bestRefs, packDirect);
      }
      std::uint64_t best = stepsOf(bestTop, packDirect);
      std::size_t factor = 1, previous = bestRefs.size();
      for (std::size_t f = 2; f <= kMaxBraidFactor && !rays.empty(); f *= 2) {
        std::vector<Ref> tried;
        Bvh bvh = build(f, packDirect, &tried);
        const bool opened = tried.size() > previous;
        previous = tried.size();
        if (!opened) break;  // nothing left to open, or the cap reached
        std::vector<vec4> packed = pack(bvh, tried, packDirect);
        const std::uint64_t steps = stepsOf(packed, packDirect);
        if (static_cast<double>(steps) < 0.99 * static_cast<double>(best)) {
          best = steps;
          factor = f;
          bestRefs = std::move(tried);
          bestTlas = std::move(bvh);
          bestTop = std::move(packed);
        }
      }
      if (keep) {
        refs = std::move(bestRefs);
        tlas = std::move(bestTlas);
        top = std::move(bestTop);
      }
      braidFactor_[packDirect] = factor;
    };
    choose(direct, true);
    if (direct && braidFactor_[false] == 0) choose(false, false);
  } else {
    tlas = build(braidFactor_[direct], direct, &refs);
    top = pack(tlas, refs, direct);
  }
  data_.bounds = tlas.bounds;
  data_.topTraversal = std::move(top);
  data_.instanceReferences = refs.size();
  return renamed;
}

namespace {
// Whether the triangles close a surface: after welding positions that agree to a millionth of the
// mesh's size, every edge is met exactly once in each direction (closed and consistently wound).
// A water surface, a window pane or a mesh with holes is not: a path inside can leave it.
bool closedSurface(const MeshGeometry& g) {
  if (g.indices.empty()) return false;
  const Bounds3 b = g.bounds();
  const float cell = std::max(maxComponent(b.extent()), 1e-30f) * 1e-6f;
  using Cell = std::array<std::int64_t, 3>;
  struct CellHash {
    std::size_t operator()(const Cell& c) const {
      return static_cast<std::size_t>(c[0] * 73856093 ^ c[1] * 19349663 ^ c[2] * 83492791);
    }
  };
  std::unordered_map<Cell, std::uint32_t, CellHash> welded;
  std::vector<std::uint32_t> id(g.positions.size());
  for (std::size_t i = 0; i < g.positions.size(); ++i) {
    const Vec3 q = (g.positions[i] - b.lo) / cell;
    const Cell key{std::llround(q.x), std::llround(q.y), std::llround(q.z)};
    id[i] = welded.emplace(key, static_cast<std::uint32_t>(welded.size())).first->second;
  }
  std::unordered_map<std::uint64_t, int> edges;  // directed edge -> times met
  for (std::size_t t = 0; t + 2 < g.indices.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const std::uint64_t from = id[g.indices[t + e]], to = id[g.indices[t + (e + 1) % 3]];
      if (from == to) continue;  // a degenerate triangle's collapsed edge
      if (++edges[from << 32 | to] > 1) return false;
    }
  for (const auto& [edge, n] : edges)
    if (!edges.count((edge & 0xffffffffu) << 32 | edge >> 32)) return false;
  return true;
}
}  // namespace

bool RenderSceneBuilder::lightInScatteringGlass(const Scene& scene) const {
  // Glass blocks shadow rays, so from a scattering point inside it only a light inside it can be
  // sampled: bounds that meet keep the sampling, and an emissive glass meets itself. That holds
  // only where a path inside cannot get out but through the glass: so any scattering glass that
  // is open (closedSurface), cut out, culled, or blended with something other than uncut glass
  // keeps it too.
  auto isGlass = [](const Material& m) { return m.type == MaterialType::Dielectric || m.type == MaterialType::RoughDielectric; };
  auto scatteringGlass = [&](const Material* m) { return m && isGlass(*m) && m->filled() && maxComponent(m->interiorScattering) > 0; };
  // Most scenes have none: then no instance needs looking at (this runs at every object move).
  if (std::none_of(scene.materials.begin(), scene.materials.end(), [&](const Material& m) { return scatteringGlass(&m); }))
    return false;
  std::vector<Bounds3> glass, lights;
  for (std::size_t i = 0; i < data_.instanceObject.size(); ++i) {
    const Object* o = scene.object(data_.instanceObject[i]);
    const Material* mat = o && o->visible ? scene.material(o->material) : nullptr;
    const MeshEntry* mesh = mat ? entryOf(*o) : nullptr;
    if (!mesh) continue;
    // Its blend chain, as the kernel follows it (fetchMaterial): glass throughout, or not.
    bool scatters = false, allGlass = true;
    forEachInBlend(scene, *mat, [&](const Material& part) {
      scatters = scatters || scatteringGlass(&part);
      allGlass = allGlass && isGlass(part) && part.alpha >= 1 && part.alphaTexture == kNoNode;
    });
    if (scatters) {
      // Culled, its back faces let shadow rays out, and paths.
      if (!allGlass || o->cullBackFaces) return true;
      if (mesh->closed < 0) mesh->closed = mesh->geometry && closedSurface(*mesh->geometry) ? 1 : 0;
      if (!mesh->closed) return true;
    }
    if (!scatters && !mat->emissive()) continue;
    const Bounds3 b = transformBounds(placement(o->transform, *mesh), mesh->bvh.bounds);
    if (scatters) glass.push_back(b);
    if (mat->emissive()) lights.push_back(b);
  }
  if (glass.empty()) return false;
  for (const Light& l : scene.lights)
    if (l.visible && l.type != LightType::Directional) lights.push_back(Bounds3{l.position, l.position});
  auto meet = [](const Bounds3& a, const Bounds3& b) {
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y && a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
  };
  for (const Bounds3& g : glass)
    for (const Bounds3& l : lights)
      if (meet(g, l)) return true;
  return false;
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
      pushLightGroupShape(data_.lightGroupShapes, data_.emitters.data() + grp.first * gpu::kEmitterTexels,
                          power.data() + grp.first, grp.count, total);
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
    if (l.visible && l.intensity > 0 && maxComponent(l.color) > 0 && !(skyHidden && l.type == LightType::Directional))
      lights.push_back(&l);
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

namespace {

constexpr std::uint64_t kMaxTexelBytes = static_cast<std::uint64_t>(gpu::kMaxTexelPairs) * 8;

// Appends linear RGBA floats as RGBA16F, two words a texel (layouts.h); returns their mean
// colour and sets *scaleExponent. Colour brighter than a half's largest value (65504; a sun in a
// sky map often is) is stored divided by 2^*scaleExponent, the power of two that brings it in
// range, and multiplied back where it is read: clipped, it would lose most of the sky's light.
Vec3 appendHalves(std::vector<std::uint32_t>& out, const std::vector<float>& rgba, int* scaleExponent) {
  double sum[3] = {0, 0, 0};
  float brightest = 0;
  for (std::size_t i = 0; i < rgba.size(); ++i)
    if (i % 4 != 3 && std::isfinite(rgba[i])) brightest = std::max(brightest, std::abs(rgba[i]));
  int e = 0;
  while (e < gpu::kTexScaleMax && std::ldexp(65504.0f, e) < brightest) ++e;
  *scaleExponent = e;
  const float unscale = std::ldexp(1.0f, -e);
  out.reserve(out.size() + rgba.size() / 2);
  for (std::size_t i = 0; i + 3 < rgba.size(); i += 4) {
    std::uint16_t c[4];
    for (std::size_t k = 0; k < 4; ++k) {
      const float v = std::isfinite(rgba[i + k]) ? rgba[i + k] : 0.0f;
      if (k < 3) sum[k] += v;
      c[k] = floatToHalf(k < 3 ? v * unscale : v);
    }
    out.push_back(static_cast<std::uint32_t>(c[0]) | static_cast<std::uint32_t>(c[1]) << 16);
    out.push_back(static_cast<std::uint32_t>(c[2]) | static_cast<std::uint32_t>(c[3]) << 16);
  }
  const double n = std::max<double>(static_cast<double>(rgba.size() / 4), 1.0);
  return Vec3{static_cast<float>(sum[0] / n), static_cast<float>(sum[1] / n), static_cast<float>(sum[2] / n)};
}

// Texel i of a packed bitmap, linear RGB, as the shader reads it (scene.glsl bitmapTexel).
Vec3 packedTexel(const std::vector<std::uint32_t>& texels, std::size_t firstWord, std::size_t i, int flags) {
  if (flags & gpu::kTexEightBit) {
    const std::uint32_t w = texels[firstWord + i];
    Vec3 c{static_cast<float>(w & 255u) / 255.0f, static_cast<float>((w >> 8) & 255u) / 255.0f, static_cast<float>((w >> 16) & 255u) / 255.0f};
    if (flags & gpu::kTexSrgb) c = Vec3{srgbCurve(c.x), srgbCurve(c.y), srgbCurve(c.z)};
    return c;
  }
  const std::uint32_t w0 = texels[firstWord + 2 * i], w1 = texels[firstWord + 2 * i + 1];
  const float scale = std::ldexp(1.0f, (flags >> gpu::kTexScaleShift) & gpu::kTexScaleMax);
  return Vec3{halfToFloat(static_cast<std::uint16_t>(w0 & 0xffffu)), halfToFloat(static_cast<std::uint16_t>(w0 >> 16)),
              halfToFloat(static_cast<std::uint16_t>(w1 & 0xffffu))} *
         scale;
}

// Appends 8-bit RGBA, a word a texel (red in the low byte, as the shader reads it), padded to
// whole pairs of words; returns the mean colour as the shader decodes it.
Vec3 appendBytes(std::vector<std::uint32_t>& out, const TextureImage& image) {
  const std::vector<std::uint8_t>& rgba = image.rgba8;
  std::uint64_t count[3][256] = {};
  out.reserve(out.size() + rgba.size() / 4 + 1);
  for (std::size_t i = 0; i + 3 < rgba.size(); i += 4) {
    for (std::size_t k = 0; k < 3; ++k) ++count[k][rgba[i + k]];
    out.push_back(static_cast<std::uint32_t>(rgba[i]) | static_cast<std::uint32_t>(rgba[i + 1]) << 8 |
                  static_cast<std::uint32_t>(rgba[i + 2]) << 16 | static_cast<std::uint32_t>(rgba[i + 3]) << 24);
  }
  if (out.size() % 2) out.push_back(0);
  double sum[3] = {0, 0, 0};
  const std::array<float, 256> values = image.byteValues();
  for (std::size_t v = 0; v < 256; ++v)
    for (std::size_t k = 0; k < 3; ++k) sum[k] += static_cast<double>(values[v]) * static_cast<double>(count[k][v]);
  const double n = std::max<double>(static_cast<double>(rgba.size() / 4), 1.0);
  return Vec3{static_cast<float>(sum[0] / n), static_cast<float>(sum[1] / n), static_cast<float>(sum[2] / n)};
}

}  // namespace

void RenderSceneBuilder::packTextures(const Scene& scene, std::vector<std::string>* warnings) {
  auto& cache = decoded_;
  // Unchanged textures are copied from the last packing, then it is freed.
  std::vector<std::uint32_t> last = std::move(data_.texels);
  data_.texels = {};
  data_.textureInfo.clear();
  data_.byteTexels = data_.halfTexels = data_.srgbTexels = false;
  textureIndex_.clear();
  textureMean_.clear();
  auto appendChecker = [&](Vec3 on, Vec3 off, int ru, int rv, bool truncate = false) {
    data_.textureInfo.push_back(ints(0, 0, 0, gpu::kTexChecker | (truncate ? gpu::kTexTruncate : 0)));
    data_.textureInfo.push_back(v4(on, static_cast<float>(std::max(ru, 1))));
    data_.textureInfo.push_back(v4(off, static_cast<float>(std::max(rv, 1))));
    return (on + off) * 0.5f;
  };
  for (const Texture& t : scene.textures) {
    int index = static_cast<int>(data_.textureInfo.size() / gpu::kTextureTexels);
    textureIndex_[t.id] = index;
    if (t.kind == TextureKind::Checker) {
      textureMean_[t.id] = appendChecker(t.checkerOn, t.checkerOff, t.checkerResU, t.checkerResV, t.tungstenCells);
      continue;
    }
    const std::size_t at = data_.texels.size();
    std::string sig = textureSignature(t, scene.baseDirectory);
    Decoded& d = cache[t.id];
    if (d.signature == sig && d.ok && d.offset + d.words <= last.size()) {
      data_.texels.insert(data_.texels.end(), last.begin() + static_cast<std::ptrdiff_t>(d.offset),
                          last.begin() + static_cast<std::ptrdiff_t>(d.offset + d.words));
    } else if (d.signature != sig || d.ok) {
      d = Decoded{};
      d.signature = sig;
      auto img = loadTexture(t, scene.baseDirectory);
      d.ok = img.ok();
      if (img.ok()) {
        const TextureImage& im = img.value();
        d.width = im.width;
        d.height = im.height;
        d.flags = gpu::kTexBitmap | (im.hasAlpha ? gpu::kTexAlpha : 0);
        if (im.eightBit()) {
          d.flags |= gpu::kTexEightBit | (im.curve == TextureImage::Curve::SRGB ? gpu::kTexSrgb : 0);
          d.mean = appendBytes(data_.texels, im);
        } else {
          int scale = 0;
          d.mean = appendHalves(data_.texels, im.rgba, &scale);
          d.flags |= scale << gpu::kTexScaleShift;
        }
      } else if (warnings) {
        warnings->push_back(cat(img.error(), t.whenMissing == MissingTexture::Tungsten ? "; shown as Tungsten shows it (a black and white checker)"
                                                                                    : "; shown as a magenta checker"));
      }
    }
    d.offset = at;
    d.words = data_.texels.size() - at;
    if (d.ok && data_.texels.size() / 2 > static_cast<std::size_t>(gpu::kMaxTexelPairs)) {
      data_.texels.resize(at);
      d.ok = false;
      d.signature.clear();  // tried again at the next update, when others may have left
      if (warnings)
        warnings->push_back(cat("texture '", t.name, "': the scene's textures need more than the renderer's ",
                                kMaxTexelBytes >> 20, " MiB of texels; shown as a checker"));
    }
    if (d.ok) {
      const bool eightBit = (d.flags & gpu::kTexEightBit) != 0;
      data_.byteTexels |= eightBit;
      data_.halfTexels |= !eightBit;
      data_.srgbTexels |= (d.flags & gpu::kTexSrgb) != 0;
      const int sampling = (t.interpolate ? 0 : gpu::kTexNearest) | (t.clampToEdge ? gpu::kTexClamp : 0);
      data_.textureInfo.push_back(ints(static_cast<std::int32_t>(at / 2), d.width, d.height, d.flags | sampling));
      data_.textureInfo.push_back({0, 0, 0, 0});
      data_.textureInfo.push_back({0, 0, 0, 0});
      textureMean_[t.id] = d.mean;
    } else if (t.whenMissing == MissingTexture::Tungsten) {
      // Tungsten's 2x2 stand-in, its texel (0, 0) white, at the top left.
      textureMean_[t.id] = appendChecker({1, 1, 1}, {0, 0, 0}, 2, 2);
    } else {
      // A visible substitute: nobody mistakes magenta and black squares for the real texture.
      textureMean_[t.id] = appendChecker({1, 0, 1}, {0.05f, 0.05f, 0.05f}, 8, 8);
    }
  }
  // Forget textures that left the scene.
  std::erase_if(cache, [&](const auto& kv) { return !scene.texture(kv.first); });
  sceneTexelWords_ = data_.texels.size();
  sceneTextureInfos_ = data_.textureInfo.size();
  sceneHalfTexels_ = data_.halfTexels;
  packedSky_.clear();
}

namespace {
// What an environment's light-sampling distribution and baked sky are made from, as a key: its
// map (the texture and what was decoded for it) or its sky's colours; empty for a constant.
std::string environmentSource(const Environment& e, const Texture* map, const std::string& mapSignature) {
  auto bits = [](Vec3 v) { return cat(std::bit_cast<std::uint32_t>(v.x), ",", std::bit_cast<std::uint32_t>(v.y), ",", std::bit_cast<std::uint32_t>(v.z)); };
  if (e.type == EnvironmentType::Map && map) return cat("map|", map->id, "|", mapSignature);
  if (e.type == EnvironmentType::Sky) return cat("sky|", bits(e.zenith), "|", bits(e.horizon), "|", bits(e.ground));
  return {};
}
}  // namespace

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
    if (map >= 0 && (std::bit_cast<std::int32_t>(data_.textureInfo[static_cast<std::size_t>(map) * gpu::kTextureTexels].w) & 15) != gpu::kTexBitmap)
      map = -1;  // it could not be read (packTextures said why) and stands in as a checker
    if (map < 0 && warnings)
      warnings->push_back(cat("environment: ", t ? cat("the map '", t->name, "' could not be read") : std::string("no map texture is set"),
                              "; lighting with a constant sky of radiance ", luminance(tint), " instead"));
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
      data_.textureInfo.push_back(ints(static_cast<std::int32_t>(at / 2), baked.width, baked.height, gpu::kTexBitmap | scale << gpu::kTexScaleShift));
      data_.textureInfo.push_back({0, 0, 0, 0});
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
      const float lum = luminance(packedTexel(data_.texels, firstWord, static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x), flags));
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
  float pv = data_.environmentType == gpu::kEnvNone || data_.worldMedium.dimsEveryChannel() ? 0.0f : std::max(environmentPower_ * kPi * radius * radius, 1e-6f);
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
