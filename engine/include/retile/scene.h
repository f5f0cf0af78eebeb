// The scene document: what an artist edits and what files hold. Plain values with stable ids.
//
// Ownership and threads: a Scene is a value. The editor's GUI thread owns the live document; the
// render thread holds its own copy, brought up to date by edits (edit.h). Mesh geometry is
// immutable and shared between copies through shared_ptr<const>, so copying a Scene or sending
// an object edit never copies vertex data.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "retile/math.h"
#include "shared/layouts.h"  // the kernel's flags a choice sets (MaterialChoice::flag)

namespace retile {

using NodeId = std::uint64_t;
constexpr NodeId kNoNode = 0;

// Immutable triangle data in object space. normals and uvs are empty or one per position.
struct MeshGeometry {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;
  std::vector<Vec2> uvs;
  std::vector<std::uint32_t> indices;  // three per triangle, all < positions.size()

  std::size_t triangleCount() const { return indices.size() / 3; }
  Bounds3 bounds() const;
};

struct Mesh {
  NodeId id = kNoNode;
  std::string name;
  std::shared_ptr<const MeshGeometry> geometry;
};

enum class TextureKind { File, Embedded, Checker };
// How texel values are turned into linear scene values. Auto: 8-bit formats are sRGB-encoded,
// floating-point formats (EXR, HDR) are linear. Raw: no conversion (roughness, alpha masks).
// Gamma22: 8-bit values v become floor(255 (v/255)^2.2) / 255, a decoding table darker than sRGB
// in the shadows (5 % less blue in the living room's wood floor); floating-point formats stay
// linear. Tungsten's "gamma_correct" (its files' default) is this, so their textures keep the
// values their author saw.
enum class TextureColorSpace { Auto, SRGB, Linear, Raw, Gamma22 };
constexpr int kTextureColorSpaceCount = 5;

// What stands in for a file that cannot be read. Checker: magenta and black squares nobody takes
// for the real texture. BlackAndWhite: a 2x2 checker of 1 and 0 over the uv square, as colour and
// as alpha, what Tungsten draws instead, so that its scene files converge to its pictures with a
// file missing too. Either way the warning names the file.
enum class MissingTexture { Checker, BlackAndWhite };

struct Texture {
  NodeId id = kNoNode;
  std::string name;
  TextureKind kind = TextureKind::File;
  std::filesystem::path path;         // File: absolute, or relative to Scene::baseDirectory
  std::vector<std::uint8_t> encoded;  // Embedded: the file's bytes (PNG, JPEG, ...)
  std::string encodedFormat;          // Embedded: a file extension hint such as "png"
  TextureColorSpace colorSpace = TextureColorSpace::Auto;
  MissingTexture whenMissing = MissingTexture::Checker;
  // How a bitmap is read between and beyond its texels: bilinear, or the nearest texel (a Tungsten
  // bitmap's "interpolate": false); repeated, or its edge texels held beyond [0, 1] (its "clamp").
  bool interpolate = true;
  bool clampToEdge = false;
  Vec3 checkerOn{0.8f}, checkerOff{0.2f};  // Checker: colours and squares per unit of uv
  int checkerResU = 8, checkerResV = 8;
  // Checker: its cells counted by truncating uv times cells toward zero (as Tungsten's
  // CheckerTexture does), so that where uvs go below 0 the cells about 0 are twice as wide and the
  // pattern mirrors; else floored, a pattern that repeats everywhere.
  bool truncatedCells = false;
  friend bool operator==(const Texture&, const Texture&) = default;
};

// The materials the scenes we open use, and no more (see docs/ARCHITECTURE.md).
enum class MaterialType {
  Lambert,
  OrenNayar,        // roughness is the slope deviation sigma in radians
  Plastic,          // smooth dielectric coating (ior) over a Lambert base (albedo)
  RoughPlastic,     // GGX coating of `roughness` over a Lambert base
  Conductor,        // smooth metal with complex index eta + i k, tinted by albedo
  RoughConductor,   // GGX metal
  Mirror,           // perfect reflector of reflectance albedo
  Dielectric,       // smooth glass of index ior, tinted by albedo on transmission
  RoughDielectric,  // GGX glass
  ThinSheet,        // thin dielectric film: reflects by Fresnel, transmits straight through
  Null,             // scatters nothing: a black emitter surface (paths end on it)
  // Tungsten's Phong: albedo times diffuseRatio of Lambert plus the rest in the lobe (n + 2) /
  // (2 pi) cos^n of the angle to the mirror direction, n the exponent 2 / a^2 - 2 of the roughness
  // a (Walter et al. 2007's match of Phong to Beckmann), so that one roughness slider means about
  // the same on every glossy type.
  Phong,
  // Lambertian on both sides: (1 - transmittance) of albedo reflected, transmittance passed to
  // the other side (Tungsten's diffuse_transmission; leaves, paper, lamp shades).
  DiffuseTransmission,
  // No surface at all, only where a medium begins (Tungsten's forward bsdf): every ray passes
  // straight through, entering the interior medium (interiorAbsorption and on) across the front
  // and leaving it across the back. Bounds fog and smoke, where glass would refract.
  Boundary,
  // A hair or fur fibre seen from afar (Tungsten's hair: d'Eon et al. 2011's model with the
  // lobes of Ou et al. 2012): light reflected off the cuticle (R), passed through the fibre
  // (TT) and reflected once inside it (TRT), each in a cone about the fibre (longitudinal
  // roughness, the cuticle's scales tilting the cones by hairTilt) and spread around it. The
  // fibre has index 1.55; its pigment absorbs coatingAbsorption per unit of its radius. Made for
  // the tubes strands are drawn as (scene/curves.h): the fibre's direction is the surface's u
  // direction, and light scattered through it leaves from the same point, so its object should
  // cull back faces.
  Hair,
};
constexpr int kMaterialTypeCount = 15;
const char* materialTypeName(MaterialType t);
bool materialTypeFromName(const std::string& name, MaterialType* out);
// The types whose roughness is a microfacet alpha and which may use Beckmann's distribution.
constexpr bool isMicrofacet(MaterialType t) {
  return t == MaterialType::RoughPlastic || t == MaterialType::RoughConductor || t == MaterialType::RoughDielectric;
}

// The types that pass light to the other side of a surface.
constexpr bool isTransmissiveType(MaterialType t) {
  return t == MaterialType::Dielectric || t == MaterialType::RoughDielectric || t == MaterialType::ThinSheet ||
         t == MaterialType::DiffuseTransmission || t == MaterialType::Boundary || t == MaterialType::Hair;
}

constexpr bool isGlassType(MaterialType t) { return t == MaterialType::Dielectric || t == MaterialType::RoughDielectric; }

// The types that may hold a medium on their inside (Material::filled).
constexpr bool holdsMedium(MaterialType t) { return isGlassType(t) || t == MaterialType::Boundary; }

// The types with a roughness field: microfacet alpha, Oren-Nayar sigma, or Phong's width.
constexpr bool hasRoughness(MaterialType t) {
  return isMicrofacet(t) || t == MaterialType::OrenNayar || t == MaterialType::Phong || t == MaterialType::Hair;
}

// A thin sheet has no roughness: the texture in its roughness slot (Material::roughnessTexture)
// is its film's thickness, Tungsten's textured thinsheet. The kernel, the panel's label and the
// node graph's all ask this, so that the slot means one thing everywhere.
constexpr bool roughnessSlotIsThickness(MaterialType t) { return t == MaterialType::ThinSheet; }

// Materials a hit follows through blends, the first included (Material::blendWith).
constexpr int kMaxBlendChain = 4;
// The densest medium (absorption or scattering per unit of length) a scene may hold: beyond it
// the kernel's sums of extinction times distance would overflow to infinity and then NaN.
constexpr float kMaxExtinction = 1e6f;

// Where the properties panel shows a material's field (shaders/shared/material_fields.h).
enum class MaterialPlace {
  Surface,   // with the type's fields, for the types it applies to
  Coated,    // while the material has a clear coat
  Emissive,  // while it emits
  Bumped,    // beside its bump texture
  Rough,     // beside the roughness, for the types it applies to
  Custom,    // drawn by the panel itself
};
// How the panel edits a colour field: a colour picker, or three fields for values beyond 1.
enum class ColorWidget { Swatch, Channels };

// Expands a row of shaders/shared/material_fields.h for C++.
#define RT_TYPE(t) (1u << static_cast<int>(MaterialType::t))
#define RT_ALL_TYPES ((1u << kMaterialTypeCount) - 1u)
#define RT_PANEL(p) MaterialPlace::p
#define RT_WIDGET(w) ColorWidget::w

// Every row of shaders/shared/material_fields.h expanded into nothing: an includer defines the
// kinds it reads, these the rest.
#define RETILE_IGNORE_SCALAR(member, key, def, lo, hi, types, texel, component, label, unit, decimals, atLo, place, tip)
#define RETILE_IGNORE_COLOR(member, key, r, g, b, hi, types, texel, label, widget, place, tip)
#define RETILE_IGNORE_TEXTURE(member, key, types, texel, component, label, place)
#define RETILE_IGNORE_CHOICE(member, key, off, on, types, flag, label, offLabel, onLabel, place, tip)

struct Material {
  NodeId id = kNoNode;
  std::string name;
  MaterialType type = MaterialType::Lambert;
  // The fields, each described once by its row in material_fields.h.
#define RETILE_MATERIAL_SCALAR(member, key, def, ...) float member = static_cast<float>(def);
#define RETILE_MATERIAL_COLOR(member, key, r, g, b, ...) Vec3 member{static_cast<float>(r), static_cast<float>(g), static_cast<float>(b)};
#define RETILE_MATERIAL_TEXTURE(member, ...) NodeId member = kNoNode;
#define RETILE_MATERIAL_CHOICE(member, ...) bool member = false;
#include "shared/material_fields.h"
#undef RETILE_MATERIAL_SCALAR
#undef RETILE_MATERIAL_COLOR
#undef RETILE_MATERIAL_TEXTURE
#undef RETILE_MATERIAL_CHOICE
  Vec3 radiance() const { return emission * emissionStrength; }
  // Glass or a boundary with a medium that absorbs or scatters.
  bool filled() const {
    return holdsMedium(type) && isFinite(interiorAbsorption) && isFinite(interiorScattering) &&
           (maxComponent(interiorAbsorption) > 0 || maxComponent(interiorScattering) > 0);
  }
  bool coated() const { return coatIor > 1.0f; }
  std::string metal = "Cu";  // conductors: a named metal (see conductorNames) or "custom" (eta, k)
  // A blend of two materials, as Tungsten's `mixed` bsdf: a surface shades as this material with
  // probability blendRatio and as `blendWith` otherwise, chosen again at every hit, which
  // averages to ratio * this + (1 - ratio) * other. Emission, coverage and bump stay this one's.
  // kNoNode: no blend. The other material's own blend is followed in its turn, kMaxBlendChain
  // materials in all at most: blends of blends, as Tungsten files nest them.
  NodeId blendWith = kNoNode;
  // Blends with `other` (kNoNode: no more); a ratio of 1, which would show nothing of it, becomes
  // half and half.
  void setBlendWith(NodeId other) {
    blendWith = other;
    if (other != kNoNode && blendRatio >= 1.0f) blendRatio = 0.5f;
  }

  // Every texture reference, for code that visits them all (deletion, validation, copies).
  static constexpr std::size_t kTextureCount = 0
#define RETILE_MATERIAL_TEXTURE(...) +1
#define RETILE_MATERIAL_SCALAR RETILE_IGNORE_SCALAR
#define RETILE_MATERIAL_COLOR RETILE_IGNORE_COLOR
#define RETILE_MATERIAL_CHOICE RETILE_IGNORE_CHOICE
#include "shared/material_fields.h"
#undef RETILE_MATERIAL_TEXTURE
      ;
  std::array<NodeId, kTextureCount> textures() const {
    return {
#define RETILE_MATERIAL_TEXTURE(member, ...) member,
#include "shared/material_fields.h"
#undef RETILE_MATERIAL_TEXTURE
    };
  }
  std::array<NodeId*, kTextureCount> textureSlots() {
    return {
#define RETILE_MATERIAL_TEXTURE(member, ...) &member,
#include "shared/material_fields.h"
#undef RETILE_MATERIAL_TEXTURE
    };
  }
#undef RETILE_MATERIAL_SCALAR
#undef RETILE_MATERIAL_COLOR
#undef RETILE_MATERIAL_CHOICE

  // A boundary is no surface, so nothing on it shines.
  bool emissive() const { return type != MaterialType::Boundary && emissionStrength > 0 && maxComponent(emission) > 0; }
  friend bool operator==(const Material&, const Material&) = default;
};

// One field of Material of each kind, as its row in shaders/shared/material_fields.h describes
// it. The tables are constant: any thread may read them.
struct MaterialRow {
  const char* member;   // the C++ name; the panel's widget takes it as its object name
  const char* key;      // in native files
  std::uint32_t types;  // the types it applies to, a bit per MaterialType
  const char* label;    // the panel's
  MaterialPlace place;  // where the panel shows it
  const char* tip;      // the panel row's tooltip ("" none)
  bool appliesTo(MaterialType t) const { return (types >> static_cast<int>(t)) & 1u; }
};

struct MaterialScalar : MaterialRow {
  float Material::*field;
  float fallback, lo, hi;
  int texel, component;  // packed there for its types; -1: by code
  const char* unit;
  int decimals;
  const char* atLo;  // the panel's text at lo, where lo means none of the field's effect ("" the number)
  bool packed() const { return texel >= 0; }
  float clamp(float v) const { return std::isfinite(v) ? std::clamp(v, lo, hi) : fallback; }
};

struct MaterialColor : MaterialRow {
  Vec3 Material::*field;
  Vec3 fallback;
  float hi;   // each channel is finite and within 0..hi
  int texel;  // its xyz, for its types; -1: by code
  ColorWidget widget;
  bool packed() const { return texel >= 0; }
  bool inRange(Vec3 c) const { return isFinite(c) && minComponent(c) >= 0 && maxComponent(c) <= hi; }
  Vec3 clamp(Vec3 c) const { return isFinite(c) ? min(max(c, Vec3{0.0f}), Vec3{hi}) : fallback; }
};

struct MaterialTexture : MaterialRow {
  NodeId Material::*field;
  int texel, component;  // where its index is packed, for its types
};

struct MaterialChoice : MaterialRow {
  bool Material::*field;
  const char* off;  // the values in native files
  const char* on;
  int flag;              // kMat<flag> (shared/layouts.h), set in the packed type word for its types
  const char* offLabel;  // the panel's
  const char* onLabel;
};

#define RETILE_MATERIAL_COLOR RETILE_IGNORE_COLOR
#define RETILE_MATERIAL_TEXTURE RETILE_IGNORE_TEXTURE
#define RETILE_MATERIAL_CHOICE RETILE_IGNORE_CHOICE
inline constexpr MaterialScalar kMaterialScalars[] = {
#define RETILE_MATERIAL_SCALAR(member, key, def, lo, hi, types, texel, component, label, unit, decimals, atLo, place, tip) \
  {{#member, key, types, label, place, tip},                                                                               \
   &Material::member,                                                                                                      \
   static_cast<float>(def),                                                                                                \
   static_cast<float>(lo),                                                                                                 \
   static_cast<float>(hi),                                                                                                 \
   texel,                                                                                                                  \
   component,                                                                                                              \
   unit,                                                                                                                   \
   decimals,                                                                                                               \
   atLo},
#include "shared/material_fields.h"
#undef RETILE_MATERIAL_SCALAR
};
#undef RETILE_MATERIAL_COLOR
#define RETILE_MATERIAL_SCALAR RETILE_IGNORE_SCALAR
inline constexpr MaterialColor kMaterialColors[] = {
#define RETILE_MATERIAL_COLOR(member, key, r, g, b, hi, types, texel, label, widget, place, tip) \
  {{#member, key, types, label, place, tip},                                                     \
   &Material::member,                                                                            \
   Vec3{static_cast<float>(r), static_cast<float>(g), static_cast<float>(b)},                    \
   static_cast<float>(hi),                                                                       \
   texel,                                                                                        \
   widget},
#include "shared/material_fields.h"
#undef RETILE_MATERIAL_COLOR
};
#define RETILE_MATERIAL_COLOR RETILE_IGNORE_COLOR
#undef RETILE_MATERIAL_TEXTURE
inline constexpr MaterialTexture kMaterialTextures[] = {
#define RETILE_MATERIAL_TEXTURE(member, key, types, texel, component, label, place) \
  {{#member, key, types, label, place, ""}, &Material::member, texel, component},
#include "shared/material_fields.h"
#undef RETILE_MATERIAL_TEXTURE
};
#define RETILE_MATERIAL_TEXTURE RETILE_IGNORE_TEXTURE
#undef RETILE_MATERIAL_CHOICE
inline constexpr MaterialChoice kMaterialChoices[] = {
#define RETILE_MATERIAL_CHOICE(member, key, off, on, types, flag, label, offLabel, onLabel, place, tip) \
  {{#member, key, types, label, place, tip}, &Material::member, off, on, gpu::kMat##flag, offLabel, onLabel},
#include "shared/material_fields.h"
#undef RETILE_MATERIAL_CHOICE
};
#undef RETILE_MATERIAL_SCALAR
#undef RETILE_MATERIAL_COLOR
#undef RETILE_MATERIAL_TEXTURE
#undef RT_TYPE
#undef RT_ALL_TYPES
#undef RT_PANEL
#undef RT_WIDGET
#undef RETILE_IGNORE_SCALAR
#undef RETILE_IGNORE_COLOR
#undef RETILE_IGNORE_TEXTURE
#undef RETILE_IGNORE_CHOICE

// Named metals with RGB complex indices of refraction (linear sRGB primaries).
std::vector<std::string> conductorNames();
bool conductorIor(const std::string& name, Vec3* eta, Vec3* k);

struct Object {
  NodeId id = kNoNode;
  std::string name;
  NodeId mesh = kNoNode;
  NodeId material = kNoNode;
  Mat4 transform;  // object to world
  bool visible = true;
  // Hit from the front only: rays, shadow rays too, pass through its back faces (a Tungsten
  // mesh's backface_culling; a room's walls seen from outside it). The front is the side its
  // winding's normal, carried by the transform's normal matrix, points to.
  bool cullBackFaces = false;
  friend bool operator==(const Object&, const Object&) = default;
};

enum class LightType { Point, Spot, Directional };

// Lights without a surface. Area lights are objects with an emissive material.
struct Light {
  NodeId id = kNoNode;
  std::string name;
  LightType type = LightType::Point;
  Vec3 color{1.0f};
  float intensity = 1.0f;  // point/spot: W/sr scale; directional: irradiance scale
  Vec3 position{0.0f};
  Vec3 direction{0.0f, -1.0f, 0.0f};  // spot and directional: where the light travels
  float spotAngle = radians(30.0f);   // spot: half angle of the cone
  float spotBlend = 0.1f;             // spot: fraction of the cone that falls off
  bool visible = true;
  // Directional: the angular radius of the sun's disc. 0 is a delta light (hard shadows, seen by
  // no ray); wider, the disc casts soft shadows and shows in mirrors and glass, with the same
  // irradiance (intensity) facing it.
  float angularRadius = 0.0f;
  friend bool operator==(const Light&, const Light&) = default;
};

struct Camera {
  Vec3 position{0.0f, 1.0f, 5.0f};
  Vec3 target{0.0f, 1.0f, 0.0f};
  Vec3 up{0.0f, 1.0f, 0.0f};
  float verticalFov = radians(40.0f);
  // A thin lens: rays leave a disc of this radius (scene units) about the position, across the
  // view direction, and meet again on the plane focusDistance along it. 0 is a pinhole.
  float apertureRadius = 0.0f;
  float focusDistance = 1.0f;
};

enum class EnvironmentType { Constant, Map, Sky };
struct Environment {
  EnvironmentType type = EnvironmentType::Constant;
  Vec3 color{0.0f};  // Constant: radiance; Map: multiplier
  float intensity = 1.0f;
  NodeId map = kNoNode;   // Map: an equirectangular texture
  float rotation = 0.0f;  // radians about +y
  // The map's own frame (its up is this matrix's y axis), turned by `rotation` about +y after it.
  // Identity but for tilted skies from imports (a Tungsten infinite_sphere rotated about x or z,
  // or given an "up"); only its rotation part counts.
  Mat4 orientation;
  Vec3 zenith{0.35f, 0.55f, 0.95f};  // Sky: a gradient from zenith to horizon, ground below
  Vec3 horizon{0.9f, 0.92f, 0.95f};
  Vec3 ground{0.3f, 0.28f, 0.25f};
  // The medium that fills the world outside every glass and boundary (fog, haze; a Tungsten
  // camera's medium that nothing holds), as Material::interiorAbsorption and on: absorption and
  // scattering per unit of length, and the phase function's asymmetry. A path that leaves glass
  // or a boundary with no medium around it remembered is back in this one. Where it absorbs or
  // scatters, no light from the environment (sky, map or sun) gets through: that light comes
  // from infinitely far through it.
  Vec3 mediumAbsorption{0.0f}, mediumScattering{0.0f};
  float mediumAnisotropy = 0.0f;
  bool filled() const {
    return isFinite(mediumAbsorption) && isFinite(mediumScattering) &&
           (maxComponent(mediumAbsorption) > 0 || maxComponent(mediumScattering) > 0);
  }
  friend bool operator==(const Environment&, const Environment&) = default;
};

const char* environmentTypeName(EnvironmentType t);  // "constant", "map", "sky"

// World directions to the environment map's frame: `orientation`'s rotation, turned by `rotation`
// about +y (the map's u grows with the angle from +x towards +z, its v downwards from +y).
Mat4 environmentToMap(const Environment& e);

// How samples are spread over and around a pixel (filter importance sampling: each sample's
// position is drawn from the filter, so a pixel's accumulation stays a plain mean and every
// policy's budget is unchanged). `filterWidth` is the footprint's full width in pixels.
enum class PixelFilter { Box, Tent, Gaussian, BlackmanHarris };
constexpr int kPixelFilterCount = 4;
const char* pixelFilterName(PixelFilter f);  // "box", "tent", "gaussian", "blackman_harris"
bool parsePixelFilter(std::string_view name, PixelFilter* out);
float defaultFilterWidth(PixelFilter f);  // box 1, tent 2 (Tungsten's), Gaussian 4, Blackman-Harris 1.5 (Blender's)
// The filter's inverse CDF along one axis at u = i / segments, i = 0..segments: a sample's offset
// from the pixel centre in pixels. Separable filters: x and y are drawn independently.
std::vector<float> pixelFilterWarp(PixelFilter f, float width, int segments);

// How the filter's offsets are drawn. Exact: from the filter itself (pixelFilterWarp).
// SteppedTable: the filter's weight at k/31 of its radius, k = 0..30, makes a 31-step table, and
// a draw that falls in step k lands one step further out, in (k+1)/31..(k+2)/31 of the radius;
// the Gaussian is then exp(-2 x^2) - exp(-8) over a radius of 2 px. The tent comes out about
// 1/31 px wider than the true tent. Tungsten draws its tent and Gaussian so, and its scene files
// ask for it, so that they converge to the picture their author saw (the edges of bright lights
// differ by up to 10 % without it). A box and the other filters are drawn exactly either way.
enum class FilterSampling { Exact, SteppedTable };

// How paths use a mesh's interpolated shading normals. Consistent: the winding decides which side
// faces the viewer; a viewer behind the shading normal is shaded with the geometric one; a path
// whose next direction would cross the true surface ends, so light cannot leak through a mesh.
// Unchecked: the shading normal, turned toward the viewer, alone decides, and paths may cross the
// true surface (two-sided shading, consistency checks off: Tungsten's defaults, which its scene
// files are made with). Smooth meshes then shade differently where the shading normal and the
// true surface disagree, mostly at their rims.
enum class ShadingConvention { Consistent, Unchecked };
// When a path may end early (Russian roulette), keeping the expected value. Standard: after three
// bounces, each bounce survives with its throughput's largest channel, at most 0.95. LowThroughput:
// after three bounces, only a throughput below 0.1 plays, and survives with that. It ends fewer
// paths, so a sample costs more and varies less; Tungsten plays it, and its files use it here so
// that a sample is the same work and the same estimate as in Tungsten.
enum class Roulette { Standard, LowThroughput };
// Where a ray that leaves a surface starts. Robust: a few float ulps off the surface, and never on
// the triangle it leaves, so it hits whatever lies beyond, however close. FixedEpsilon: it starts at
// the point itself and skips everything within 5e-4 scene units of it along its direction
// (Tungsten's DefaultEpsilon; lifted off as well, the kitchen's window frame, lit edge-on, comes
// out 4 to 6 % dark), also when it passes a cut-out (a forward event; a shadow ray: a cut-out or a
// thin sheet). Light then leaks through cracks narrower than that, such as where a skirting board
// dips into the floor, and the contact shadows of surfaces closer than that vanish: Tungsten files
// use it so that they converge to the picture their author saw (the living room's darkest corners
// differ by 8 to 18 % without it; the kitchen's blinds, a shell of cut-outs 0.25 mm thick, let
// through 0.39 of the light as one layer instead of 0.15 as two).
enum class RayOffset { Robust, FixedEpsilon };
constexpr int kSteppedFilterSteps = 31;
// FilterSampling::SteppedTable's CDF at steps 1..30 (step 0's is 0, step 31's is 1), for tent and Gaussian.
std::vector<float> steppedFilterCdf(PixelFilter f);

// The largest image side anything accepts (files, edits, the command line, the renderer).
constexpr int kMaxImageSide = 16384;

struct RenderSettings {
  int width = 640;
  int height = 360;
  int maxBounces = 16;  // paths past it carry ~albedo^17 of the light: < 0.5 % in a Cornell box
  // Light that reaches the camera in fewer bounces (scattering events) is left out: 1 hides the
  // lights seen directly, 2 keeps only indirect light (Tungsten's min_bounces); past maxBounces, nothing.
  int minBounces = 0;
  // Next-event estimation. Off, lights are found only by the paths that hit them (Tungsten's
  // enable_light_sampling false): the same picture with more noise, except that point, spot and
  // delta directional lights, which no path can hit, light nothing.
  bool lightSampling = true;
  int samplesPerPixel = 64;
  std::uint32_t seed = 0;
  // New scenes (the built-in one, glTF/OBJ/FBX imports): Blackman-Harris 1.5 px, as Blender.
  PixelFilter pixelFilter = PixelFilter::BlackmanHarris;
  float filterWidth = 1.5f;
  // Tungsten files ask for the second value of each (their importer sets them).
  FilterSampling filterSampling = FilterSampling::Exact;
  ShadingConvention shading = ShadingConvention::Consistent;
  Roulette roulette = Roulette::Standard;
  RayOffset rayOffset = RayOffset::Robust;
  // The OCIO view the scene's author looked at it through (a Tungsten camera's tonemap), which
  // the editor and `retile render` show it with until told otherwise; empty: the application's
  // default, Standard. Display only: the render is the same whatever it says.
  std::string view;
  friend bool operator==(const RenderSettings&, const RenderSettings&) = default;
};

class Scene {
 public:
  std::vector<Mesh> meshes;
  std::vector<Texture> textures;
  std::vector<Material> materials;
  std::vector<Object> objects;
  std::vector<Light> lights;
  Camera camera;
  Environment environment;
  RenderSettings settings;
  std::filesystem::path baseDirectory;  // relative texture paths resolve against it

  NodeId newId() { return nextId_++; }
  NodeId peekNextId() const { return nextId_; }
  void reserveIds(NodeId next) {
    if (next > nextId_) nextId_ = next;
  }

  Mesh* mesh(NodeId id);
  const Mesh* mesh(NodeId id) const;
  Texture* texture(NodeId id);
  const Texture* texture(NodeId id) const;
  Material* material(NodeId id);
  const Material* material(NodeId id) const;
  Object* object(NodeId id);
  const Object* object(NodeId id) const;
  Light* light(NodeId id);
  const Light* light(NodeId id) const;

  // World bounds of visible objects; used to frame cameras and size environment lights.
  Bounds3 worldBounds() const;
  std::size_t triangleCount() const;
  // Aspect ratio from settings, guarded against zero.
  float aspect() const;

 private:
  NodeId nextId_ = 1;
};

// Where an object sits for an artist: the centre of its mesh's bounds, carried by its transform
// (imported meshes often lie in world space under a transform whose origin is far from them); its
// transform's origin when it has no geometry. The gizmo sits there, turns and scales keep it in
// place, and Properties shows it as the object's position. Walks the mesh's vertices.
Vec3 objectPivot(const Scene& s, const Object& o);

// The built-in look-dev scene: ground, glossy sphere, a cup by a mirror-like panel, a textured
// box, an area light and a sky. Generated in code, so it needs no files.
Scene makeDefaultScene();

}  // namespace retile
