#include "render/render_scene.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numeric>
#include <stdexcept>
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

std::string textureSignature(const Texture& t, const std::filesystem::path& base) {
  switch (t.kind) {
    case TextureKind::File:
      return cat("file|", (t.path.is_absolute() ? t.path : base / t.path).string(), "|", static_cast<int>(t.colorSpace));
    case TextureKind::Embedded:
      return cat("emb|", t.encoded.size(), "|",
                 fnv1a64(std::string_view(reinterpret_cast<const char*>(t.encoded.data()), t.encoded.size())), "|",
                 static_cast<int>(t.colorSpace));
    case TextureKind::Checker: return "checker";  // analytic: nothing decoded to cache
  }
  return {};
}

}  // namespace

// The kernel's material mask holds a bit per type, then Beckmann's, the coat's and the media's.
static_assert(kMaterialTypeCount <= gpu::kMaskBeckmann && gpu::kMaskBeckmann < gpu::kMaskCoat && gpu::kMaskCoat < gpu::kMaskMedium &&
              gpu::kMaskMedium < gpu::kMaskScattering && gpu::kMaskScattering < 32);
static_assert((1 << gpu::kMaskMedium) == 131072, "common/bsdf.glsl's RETILE_MEDIUM tests this bit");

namespace {
// Transmissive types take no coat (Material::coatIor).
bool coatRendered(const Material& m) { return m.coated() && !isTransmissiveType(m.type); }
}  // namespace

float emissionConeCos(const Material& m) {
  return m.emissionCone < 90 ? std::cos(std::max(m.emissionCone, 0.0f) * (kPi / 180)) : 0.0f;  // NaN: the hemisphere
}

namespace {
// A field's row; a field without one fails to compile where evaluated at compile time.
constexpr const MaterialTexture& textureRow(NodeId Material::*field) {
  for (const MaterialTexture& t : kMaterialTextures)
    if (t.field == field) return t;
  throw std::logic_error("no texture row for this field");
}
constexpr const MaterialColor& colorRow(Vec3 Material::*field) {
  for (const MaterialColor& c : kMaterialColors)
    if (c.field == field) return c;
  throw std::logic_error("no colour row for this field");
}
}  // namespace
// trace.comp's fetchMaterial reads these two from the texels it has fetched for eta and k.
static_assert(textureRow(&Material::albedoTexture).texel == 2 && textureRow(&Material::roughnessTexture).texel == 3);
// unpackMaterial (common/bsdf.glsl) reads the packed colours by position: albedo from texel 0,
// the coating's absorption from texel 6.
static_assert(colorRow(&Material::albedo).texel == 0 && colorRow(&Material::coatingAbsorption).texel == 6);
static_assert(
    [] {
      for (const MaterialColor& c : kMaterialColors)
        if (c.texel >= 0 && c.field != &Material::albedo && c.field != &Material::coatingAbsorption) return false;
      return true;
    }(),
    "a colour packed by its row needs its texel read in unpackMaterial, and asserted here");

std::array<vec4, gpu::kMaterialTexels> packMaterial(const Material& m, const std::function<int(NodeId)>& textureIndex, int blendWith) {
  Vec3 eta = m.eta, k = m.k;
  if (m.metal != "custom" && !conductorIor(m.metal, &eta, &k)) conductorIor("Cu", &eta, &k);
  int type = static_cast<int>(m.type);
  for (const MaterialChoice& c : kMaterialChoices)
    if (m.*c.field && c.appliesTo(m.type)) type |= c.flag;
  // Keep roughness away from zero, where GGX turns into a delta the rough code cannot sample.
  const bool rough = isMicrofacet(m.type);
  float roughness = std::clamp(m.roughness, 0.0f, 1.0f);
  if (rough || m.type == MaterialType::Phong) roughness = std::max(roughness, 1e-3f);
  if (m.type == MaterialType::OrenNayar) roughness = std::clamp(m.roughness, 0.0f, kPi / 2);
  // Glass and sheets may be less dense than what is around them (an air bubble in ice: its ior
  // the ratio, below 1); a coating may not. An index of 1, where a rough interface's half vector
  // is undefined, is kept a hair away from.
  const bool lessDense = (isGlassType(m.type) || m.type == MaterialType::ThinSheet) && m.ior < 1.0f;
  float ior = m.type == MaterialType::Hair ? 1.55f : lessDense ? std::clamp(m.ior, 0.1f, 0.9999f) : std::clamp(m.ior, 1.0001f, 10.0f);
  const bool coated = coatRendered(m);
  // Diffuse light inside a plastic coating reflects back this fraction at the boundary
  // (Jensen et al.'s polynomial fit of the internal diffuse Fresnel reflectance).
  float fdrInt = -1.4399f / (ior * ior) + 0.7099f / ior + 0.6681f + 0.0636f * ior;
  std::array<vec4, gpu::kMaterialTexels> texels{v4(Vec3{0.0f}, bitsOf(type)), vec4{roughness, ior, 0, std::clamp(fdrInt, 0.0f, 1.0f)},
                                                v4(eta, 0), v4(k, 0), v4(max(m.radiance(), Vec3{0.0f}), 0),
                                                vec4{0, 0, 0, bitsOf(blendWith)}, vec4{0, 0, 0, 0},
                                                vec4{0, coated ? std::min(m.coatIor, 10.0f) : 0.0f, emissionConeCos(m), 0},
                                                // The ninth holds the coat or, for glass, which takes no coat, its medium's absorption;
                                                // the tenth the medium's scattering.
                                                v4(coated       ? max(m.coatAbsorption, Vec3{0.0f})
                                                   : m.filled() ? max(m.interiorAbsorption, Vec3{0.0f})
                                                                : Vec3{0.0f},
                                                   coated && m.coatRoughness > 0 ? std::clamp(m.coatRoughness, 1e-3f, 1.0f) : 0.0f),
                                                v4(m.filled() ? max(m.interiorScattering, Vec3{0.0f}) : Vec3{0.0f}, 0)};
  // The fields material_fields.h places, for the types that have them: after the rest, since a
  // type-specific field takes a slot another type uses for something else.
  for (const MaterialScalar& f : kMaterialScalars)
    if (f.packed() && f.appliesTo(m.type)) component(texels[static_cast<std::size_t>(f.texel)], f.component) = f.clamp(m.*f.field);
  for (const MaterialColor& c : kMaterialColors) {
    if (!c.packed() || !c.appliesTo(m.type)) continue;
    const Vec3 v = c.clamp(m.*c.field);
    vec4& t = texels[static_cast<std::size_t>(c.texel)];
    t.x = v.x, t.y = v.y, t.z = v.z;
  }
  for (const MaterialTexture& f : kMaterialTextures) {
    const NodeId id = m.*f.field;
    int index = f.appliesTo(m.type) && id != kNoNode && textureIndex ? textureIndex(id) : -1;
    // A bump of strength 0 and a ratio without a blend do nothing: the kernel skips them.
    if ((f.field == &Material::bumpTexture && m.bumpStrength == 0) || (f.field == &Material::blendRatioTexture && blendWith < 0))
      index = -1;
    component(texels[static_cast<std::size_t>(f.texel)], f.component) = bitsOf(index);
  }
  return texels;
}

void RenderSceneBuilder::packMaterials(const Scene& scene) {
  data_.materials.clear();
  data_.materialTypes = 0;
  data_.materialTextures = false;
  data_.roughnessTextures = false;
  data_.sheetTextures = false;
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
    if (m.beckmann && isMicrofacet(m.type)) data_.materialTypes |= 1u << gpu::kMaskBeckmann;
    if (coatRendered(m)) data_.materialTypes |= 1u << gpu::kMaskCoat;
    if (m.filled()) data_.materialTypes |= 1u << gpu::kMaskMedium;
    if (m.filled() && maxComponent(m.interiorScattering) > 0) data_.materialTypes |= 1u << gpu::kMaskScattering;
    if (emissionConeCos(m) != 0 && m.emissive()) data_.emissionCones = true;
    int blendWith = -1;
    const bool texturedRatio = textureIndex(m.blendRatioTexture) >= 0;
    // A boundary blends with nothing and nothing with it: the traversal takes an instance's own
    // material for whether its shadow rays pass, and a surface that were partly a boundary would
    // block them all the same.
    const auto it = materialIndex_.find(m.blendWith);
    const bool boundary =
        m.type == MaterialType::Boundary ||
        (it != materialIndex_.end() && scene.materials[static_cast<std::size_t>(it->second)].type == MaterialType::Boundary);
    if (!boundary && it != materialIndex_.end() && m.blendWith != m.id && (m.blendRatio < 1.0f || texturedRatio)) {
      blendWith = it->second;
      data_.materialBlend = true;
    }
    auto texels = packMaterial(
        m, [this](NodeId t) { return textureIndex(t); }, blendWith);
    // The kernel's texture code, for the textures packMaterial kept (those its type reads).
    auto packed = [&texels](const MaterialTexture& t) {
      return std::bit_cast<std::int32_t>(component(texels[static_cast<std::size_t>(t.texel)], t.component)) >= 0;
    };
    static constexpr const MaterialTexture& albedo = textureRow(&Material::albedoTexture);
    static constexpr const MaterialTexture& roughness = textureRow(&Material::roughnessTexture);
    static constexpr const MaterialTexture& ratio = textureRow(&Material::blendRatioTexture);
    static constexpr const MaterialTexture& bump = textureRow(&Material::bumpTexture);
    static constexpr const MaterialTexture& emission = textureRow(&Material::emissionTexture);
    if (packed(albedo) || packed(ratio)) data_.materialTextures = true;
    if (packed(roughness)) data_.roughnessTextures = true;
    if (m.type == MaterialType::ThinSheet && (packed(albedo) || packed(roughness) || packed(bump))) data_.sheetTextures = true;
    if (packed(bump)) data_.materialBump = true;
    if (packed(emission) && m.emissive()) data_.emissionTextures = true;
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

namespace pack {

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
    Vec3 c{static_cast<float>(w & 255u) / 255.0f, static_cast<float>((w >> 8) & 255u) / 255.0f,
           static_cast<float>((w >> 16) & 255u) / 255.0f};
    if (flags & gpu::kTexSrgb) c = Vec3{srgbCurve(c.x), srgbCurve(c.y), srgbCurve(c.z)};
    return c;
  }
  const std::uint32_t w0 = texels[firstWord + 2 * i], w1 = texels[firstWord + 2 * i + 1];
  const float scale = std::ldexp(1.0f, (flags >> gpu::kTexScaleShift) & gpu::kTexScaleMax);
  return Vec3{halfToFloat(static_cast<std::uint16_t>(w0 & 0xffffu)), halfToFloat(static_cast<std::uint16_t>(w0 >> 16)),
              halfToFloat(static_cast<std::uint16_t>(w1 & 0xffffu))} *
         scale;
}

}  // namespace pack

namespace {
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

// Appends the slopes of the bitmap just packed at texels[firstWord...] (w x h texels, `flags`),
// a word a texel as two halves, padded to whole pairs of words: what scene.glsl textureSlope
// interpolates. A texel's slope is Tungsten's (BitmapTexture::derivatives): the difference of the
// channels' mean across the two texels beside it, along u and down the image's rows, wrapped.
// Four lookups a bump then read these instead of twelve of the colour.
void appendSlopes(std::vector<std::uint32_t>& texels, std::size_t firstWord, int w, int h, int flags) {
  const auto width = static_cast<std::size_t>(w), height = static_cast<std::size_t>(h);
  std::vector<float> mean(width * height);
  for (std::size_t i = 0; i < mean.size(); ++i) {
    const Vec3 c = packedTexel(texels, firstWord, i, flags);
    mean[i] = (c.x + c.y + c.z) * (1.0f / 3.0f);
  }
  // A slope beyond a half's range (only of half-float texels far beyond it) is held at its edge.
  auto half = [](float v) { return std::uint32_t{floatToHalf(std::clamp(v, -65504.0f, 65504.0f))}; };
  texels.reserve(texels.size() + mean.size() + 1);
  for (std::size_t y = 0; y < height; ++y)
    for (std::size_t x = 0; x < width; ++x) {
      const float du = mean[y * width + (x + 1) % width] - mean[y * width + (x + width - 1) % width];
      const float dv = mean[(y + 1) % height * width + x] - mean[(y + height - 1) % height * width + x];
      texels.push_back(half(du) | half(dv) << 16);
    }
  if (texels.size() % 2) texels.push_back(0);
}

}  // namespace

std::vector<NodeId> bumpTextures(const Scene& scene) {
  static constexpr const MaterialTexture& bump = textureRow(&Material::bumpTexture);
  std::vector<NodeId> ids;
  for (const Material& m : scene.materials)
    if (m.bumpTexture != kNoNode && m.bumpStrength != 0 && bump.appliesTo(m.type)) ids.push_back(m.bumpTexture);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

void RenderSceneBuilder::packTextures(const Scene& scene, std::vector<std::string>* warnings) {
  auto& cache = decoded_;
  // Unchanged textures are copied from the last packing, then it is freed.
  std::vector<std::uint32_t> last = std::move(data_.texels);
  data_.texels = {};
  data_.textureInfo.clear();
  data_.byteTexels = data_.halfTexels = data_.srgbTexels = false;
  textureIndex_.clear();
  textureMean_.clear();
  slopeTextures_ = bumpTextures(scene);
  auto appendChecker = [&](Vec3 on, Vec3 off, int ru, int rv, bool truncate = false) {
    data_.textureInfo.push_back(ints(0, 0, 0, gpu::kTexChecker | (truncate ? gpu::kTexTruncate : 0)));
    data_.textureInfo.push_back(v4(on, static_cast<float>(std::max(ru, 1))));
    data_.textureInfo.push_back(v4(off, static_cast<float>(std::max(rv, 1))));
    return (on + off) * 0.5f;
  };
  auto environmentOnly = [&](NodeId id) {
    if (scene.environment.type != EnvironmentType::Map || scene.environment.map != id) return false;
    return std::none_of(scene.materials.begin(), scene.materials.end(), [id](const Material& m) {
      const auto used = m.textures();
      return std::find(used.begin(), used.end(), id) != used.end();
    });
  };
  for (const Texture& t : scene.textures) {
    int index = static_cast<int>(data_.textureInfo.size() / gpu::kTextureTexels);
    textureIndex_[t.id] = index;
    if (t.kind == TextureKind::Checker) {
      textureMean_[t.id] = appendChecker(t.checkerOn, t.checkerOff, t.checkerResU, t.checkerResV, t.truncatedCells);
      continue;
    }
    const std::size_t at = data_.texels.size();
    const bool slopes = std::binary_search(slopeTextures_.begin(), slopeTextures_.end(), t.id);
    std::string sig = textureSignature(t, scene.baseDirectory);
    Decoded& d = cache[t.id];
    // The slopes the last packing left after the colour, copied again if they are still wanted.
    auto lastSlopes = last.end();
    if (d.signature == sig && d.ok && d.offset + d.words + d.slopeWords <= last.size()) {
      const auto colour = last.begin() + static_cast<std::ptrdiff_t>(d.offset);
      data_.texels.insert(data_.texels.end(), colour, colour + static_cast<std::ptrdiff_t>(d.words));
      if (d.slopeWords) lastSlopes = colour + static_cast<std::ptrdiff_t>(d.words);
    } else if (d.signature != sig || d.ok) {
      d = Decoded{};
      d.signature = sig;
      auto img = loadTexture(t, scene.baseDirectory);
      d.ok = img.ok();
      if (!img.ok()) d.error = img.error();
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
      } else if (warnings && !environmentOnly(t.id)) {
        // (What a sky map that cannot be read stands in for, the environment's warning says.)
        warnings->push_back(cat(img.error(), t.whenMissing == MissingTexture::BlackAndWhite
                                                 ? "; shown as Tungsten shows it (a black and white checker)"
                                                 : "; shown as a magenta checker"));
      }
    }
    d.offset = at;
    d.words = data_.texels.size() - at;
    if (d.ok && slopes) {
      if (lastSlopes != last.end())
        data_.texels.insert(data_.texels.end(), lastSlopes, lastSlopes + static_cast<std::ptrdiff_t>(d.slopeWords));
      else appendSlopes(data_.texels, at, d.width, d.height, d.flags);
    }
    d.slopeWords = data_.texels.size() - at - d.words;
    if (d.ok && data_.texels.size() / 2 > static_cast<std::size_t>(gpu::kMaxTexelPairs)) {
      data_.texels.resize(at);
      d.slopeWords = 0;
      d.ok = false;
      d.signature.clear();  // tried again at the next update, when others may have left
      if (warnings)
        warnings->push_back(cat("texture '", t.name, "': the scene's textures need more than the renderer's ", kMaxTexelBytes >> 20,
                                " MiB of texels; shown as a checker"));
    }
    if (d.ok) {
      const bool eightBit = (d.flags & gpu::kTexEightBit) != 0;
      data_.byteTexels |= eightBit;
      data_.halfTexels |= !eightBit;
      data_.srgbTexels |= (d.flags & gpu::kTexSrgb) != 0;
      const int sampling = (t.interpolate ? 0 : gpu::kTexNearest) | (t.clampToEdge ? gpu::kTexClamp : 0);
      data_.textureInfo.push_back(ints(static_cast<std::int32_t>(at / 2), d.width, d.height, d.flags | sampling));
      data_.textureInfo.push_back(ints(d.slopeWords ? static_cast<std::int32_t>((at + d.words) / 2) : -1, 0, 0, 0));
      data_.textureInfo.push_back({0, 0, 0, 0});
      textureMean_[t.id] = d.mean;
    } else if (t.whenMissing == MissingTexture::BlackAndWhite) {
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

}  // namespace retile
