// Helpers the parts of the render scene's packing share (render_*.cpp): texel values, the blend
// chains the kernel follows, texel encodings. Internal to the engine's render module.
#pragma once

#include <bit>
#include <chrono>
#include <cstdint>
#include <vector>

#include "render/render_scene.h"

namespace retile::pack {

using Clock = std::chrono::steady_clock;
inline double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The most texel bytes a scene's textures (and baked sky) may take: what the texel buffer addresses.
inline constexpr std::uint64_t kMaxTexelBytes = static_cast<std::uint64_t>(gpu::kMaxTexelPairs) * 8;

inline vec4 v4(Vec3 v, float w) { return {v.x, v.y, v.z, w}; }
inline float bitsOf(std::int32_t i) { return std::bit_cast<float>(i); }
inline float& component(vec4& v, int c) {
  switch (c) {
    case 0: return v.x;
    case 1: return v.y;
    case 2: return v.z;
    default: return v.w;
  }
}
inline vec4 ints(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d) { return {bitsOf(a), bitsOf(b), bitsOf(c), bitsOf(d)}; }

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

inline bool sheetInBlend(const Scene& scene, const Material& m) {
  bool sheet = false;
  forEachInBlend(scene, m, [&](const Material& part) { sheet = sheet || part.type == MaterialType::ThinSheet; });
  return sheet;
}

// Appends linear RGBA floats as RGBA16F, two words a texel (layouts.h); returns their mean colour
// and sets *scaleExponent (render_textures.cpp).
Vec3 appendHalves(std::vector<std::uint32_t>& out, const std::vector<float>& rgba, int* scaleExponent);
// Texel i of a packed bitmap, linear RGB, as the shader reads it (scene.glsl bitmapTexel).
Vec3 packedTexel(const std::vector<std::uint32_t>& texels, std::size_t firstWord, std::size_t i, int flags);

}  // namespace retile::pack
