#version 460
// Denoiser, pass 1 of 4: per pixel of the domain, the accumulated mean less the emission seen at
// the guide hit (lights are not noise: they are added back exact), demodulated by the guides'
// albedo (so textures are not blurred); the guides (normal, depth, albedo, emission) and the
// luminance moments the variance estimate needs. Reads the accumulation; never writes it (the
// denoiser is a view: the accumulation stays unbiased).
#extension GL_GOOGLE_include_directive : require

#include "shared/layouts.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(push_constant) uniform Push { DenoisePush push; };

#include "common/denoise.glsl"

layout(set = 0, binding = 0) uniform samplerBuffer uAccum;     // [2p] sum, count; [2p+1] compensation, squares
layout(set = 0, binding = 1) uniform samplerBuffer uAccumAux;  // kAuxVec4s per pixel
layout(set = 0, binding = 2, std430) writeonly buffer Colors { uvec2 colors[]; };    // packColor, variance 0 for now
layout(set = 0, binding = 3, std430) writeonly buffer Surface { vec4 surface[]; };  // normal, depth
layout(set = 0, binding = 4, std430) writeonly buffer Guide { vec4 guide[]; };      // [2p] albedo, -; [2p+1] emission, -
layout(set = 0, binding = 5, std430) writeonly buffer Moments { vec4 moments[]; };  // luminance, mean square, samples, -
layout(set = 0, binding = 6, std430) readonly buffer Tiles { uint tileCodes[]; };

void main() {
  uint p;
  ivec2 xy;
  bool live = domainPixel(p, xy);
  int i = int(p);
  vec4 s = texelFetch(uAccum, i * 2), c = texelFetch(uAccum, i * 2 + 1);
  vec4 a = texelFetch(uAccumAux, i * int(kAuxVec4s)), b = texelFetch(uAccumAux, i * int(kAuxVec4s) + 1);
  vec4 e = texelFetch(uAccumAux, i * int(kAuxVec4s) + 2);
  float n = s.w;
  float inv = n > 0.0 ? 1.0 / n : 0.0;
  vec3 mean = (s.rgb - c.rgb) * inv;
  vec3 albedo = a.rgb * inv;
  vec3 emission = e.rgb * inv;
  float len = length(b.xyz);
  vec3 normal = len > 0.0 ? b.xyz / len : vec3(0.0);
  float depth = a.w >= 1e29 ? kBackgroundDepth : a.w;
  vec3 demod = demodulate(max(mean - emission, vec3(0.0)), albedo);
  // The moments are of the raw luminance; taking the emission out and demodulating scale a pixel's
  // luminance by about this (an exactly emitting pixel has no variance to keep).
  float lum = luminance(mean);
  float k = lum > 1e-8 ? luminance(demod) / lum : 1.0;
  // A pixel of a tile outside this frame's filter (not re-rendered yet) gets a depth no other pixel
  // is near: every weight towards it is zero.
  uint tile = uint(xy.y / int(push.tiles.x)) * push.tiles.y + uint(xy.x / int(push.tiles.x));
  bool takesPart = (tileCodes[tile] & kTileFiltered) != 0u;
  if (!live) return;
  colors[p] = packColor(demod, 0.0);
  surface[p] = takesPart ? vec4(normal, depth) : vec4(0.0, 0.0, 0.0, -kBackgroundDepth);
  guide[p * 2u] = vec4(albedo, 0.0);
  guide[p * 2u + 1u] = vec4(emission, 0.0);
  moments[p] = vec4(luminance(demod), c.w * inv * k * k, n, 0.0);
}
