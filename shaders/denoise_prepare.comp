#version 460
// Denoiser, pass 1 of 4: per pixel of the domain, the accumulated mean less the emission seen at
// the guide hit (lights are not noise: they are added back exact), demodulated by the guides'
// albedo (so textures are not blurred); the guide surface (normal, depth) and the luminance
// moments the variance estimate needs. Reads the accumulation; never writes it (the denoiser is a
// view: the accumulation stays unbiased).
#extension GL_GOOGLE_include_directive : require

#include "shared/layouts.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(push_constant) uniform Push { DenoisePush push; };

layout(set = 0, binding = kBindDenoisePrepareAccum) uniform samplerBuffer uAccum;     // [2p] sum, count; [2p+1] compensation, squares
layout(set = 0, binding = kBindDenoisePrepareAccumAux) uniform samplerBuffer uAccumAux;  // kAuxVec4s per pixel

#define DENOISE_READS_ACCUMULATION
#include "common/denoise.glsl"
layout(set = 0, binding = kBindDenoisePrepareColors, std430) writeonly buffer Colors { uvec2 colors[]; };    // packColor, variance 0 for now
layout(set = 0, binding = kBindDenoisePrepareSurface, std430) writeonly buffer Surface { vec4 surface[]; };  // normal, depth
layout(set = 0, binding = kBindDenoisePrepareMoments, std430) writeonly buffer Moments { vec4 moments[]; };  // luminance, mean square, samples, -
layout(set = 0, binding = kBindDenoisePrepareTiles, std430) readonly buffer Tiles { uint tileCodes[]; };

void main() {
  uint p;
  ivec2 xy;
  bool live = domainPixel(p, xy);
  Guides g = readGuides(int(p));
  vec3 demod = demodulate(max(g.mean - g.emission, vec3(0.0)), g.albedo);
  // The moments are of the raw luminance; taking the emission out and demodulating scale a pixel's
  // luminance by about this (an exactly emitting pixel has no variance to keep).
  float lum = luminance(g.mean);
  float k = lum > 1e-8 ? luminance(demod) / lum : 1.0;
  // A pixel of a tile outside this frame's filter (not re-rendered yet) gets a depth no other pixel
  // is near: every weight towards it is zero.
  uint tile = uint(xy.y / int(push.tiles.x)) * push.tiles.y + uint(xy.x / int(push.tiles.x));
  bool takesPart = (tileCodes[tile] & kTileFiltered) != 0u;
  if (!live) return;
  colors[p] = packColor(demod, 0.0);
  // Where the guides saw no surface the normal is a fixed one, so that two such pixels weigh each
  // other fully and no test for the background is needed per tap.
  surface[p] = vec4(g.depth >= kBackgroundDepth ? vec3(0.0, 0.0, 1.0) : g.normal, takesPart ? g.depth : -kBackgroundDepth);
  moments[p] = vec4(luminance(demod), g.meanSquare * k * k, g.samples, 0.0);
}
