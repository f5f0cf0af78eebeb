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
  return v(meshTraversal) + v(topTraversal) + v(triangleShading) + v(instances) + v(materials) + v(textureInfo) + v(texels) + v(emitters) +
         v(emitterAlias) + v(deltaLights) + v(environmentCdf);
}

int filterFeature(const RenderSettings& s) {
  if (s.filterSampling == FilterSampling::SteppedTable && s.pixelFilter == PixelFilter::Tent) return gpu::kFeatureFilterSteppedTent;
  if (s.filterSampling == FilterSampling::SteppedTable && s.pixelFilter == PixelFilter::Gaussian) return gpu::kFeatureFilterStepped;
  return s.pixelFilter == PixelFilter::Tent ? gpu::kFeatureFilterTent : gpu::kFeatureFilterTable;
}

std::uint32_t RenderSceneData::features() const {
  std::uint32_t f = 0;
  if (materialTextures) f |= gpu::kFeatureTextures;
  if (roughnessTextures) f |= gpu::kFeatureRoughnessTextures;
  if (sheetTextures) f |= gpu::kFeatureSheetTextures;
  if (environmentType == gpu::kEnvConstant) f |= gpu::kFeatureEnvConstant;
  if (environmentType == gpu::kEnvMap) f |= gpu::kFeatureEnvMap;
  if (!emitters.empty()) f |= gpu::kFeatureEmitters;
  if (!deltaLights.empty()) f |= gpu::kFeatureDeltaLights;
  if (suns > 0) f |= gpu::kFeatureSun;
  if (uncheckedShading) f |= gpu::kFeatureUncheckedShading;
  if (lowThroughputRoulette) f |= gpu::kFeatureLowThroughputRoulette;
  if (fixedEpsilon) f |= gpu::kFeatureFixedEpsilon;
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
  data_.uncheckedShading = scene.settings.shading == ShadingConvention::Unchecked;                          // a kernel variant, no array
  data_.lowThroughputRoulette = scene.settings.roulette == Roulette::LowThroughput;                         // likewise
  data_.fixedEpsilon = scene.settings.rayOffset == RayOffset::FixedEpsilon;                                 // likewise
  data_.filterFeature = filterFeature(scene.settings);                                                      // likewise
  data_.minBounces = std::clamp(scene.settings.minBounces, 0, std::max(scene.settings.maxBounces, 0) + 1);  // likewise
  const bool lightSamplingChanged = data_.lightSampling != scene.settings.lightSampling;
  data_.lightSampling = scene.settings.lightSampling;
  timing_ = {};
  std::uint32_t dirty = 0;
  // A texture that a material starts or stops bumping by gains or loses its slopes.
  if ((flags & kUpdateMaterials) && !(flags & kUpdateTextures) && bumpTextures(scene) != slopeTextures_) flags |= kUpdateTextures;
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

}  // namespace retile
