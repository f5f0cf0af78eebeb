#version 460
// Denoiser, pass 4 of 4: remodulates the filtered illumination by the albedo, adds the emission
// back and writes it into the denoised layer, for the tiles whose code carries kTileWrite (a
// region's newly covered tiles, or every tile when the whole frame is denoised). Older results in
// the layer stay. The guides are read from the accumulation again rather than kept from the
// preparation: on lavapipe a buffer written and read back costs more than the fetches.
#extension GL_GOOGLE_include_directive : require

#include "shared/layouts.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(push_constant) uniform Push { DenoisePush push; };

layout(set = 0, binding = kBindDenoiseFinishColors) uniform samplerBuffer uColors;    // RGBA16F: the filtered demodulated colour
layout(set = 0, binding = kBindDenoiseFinishAccum) uniform samplerBuffer uAccum;
layout(set = 0, binding = kBindDenoiseFinishAccumAux) uniform samplerBuffer uAccumAux;
layout(set = 0, binding = kBindDenoiseFinishTiles, std430) readonly buffer Tiles { uint tileCodes[]; };
layout(set = 0, binding = kBindDenoiseFinishLayer, std430) buffer Layer { vec4 layer[]; };

#include "common/denoise.glsl"

void main() {
  uint p;
  ivec2 xy;
  bool live = domainPixel(p, xy);
  uint tile = uint(xy.y / int(push.tiles.x)) * push.tiles.y + uint(xy.x / int(push.tiles.x));
  // Only what remodulation needs: the sample count, the albedo and the emission sums.
  int i = int(p);
  float n = texelFetch(uAccum, i * 2).w;
  float inv = n > 0.0 ? 1.0 / n : 0.0;
  vec3 albedo = texelFetch(uAccumAux, i * int(kAuxVec4s)).rgb * inv;
  vec3 emission = texelFetch(uAccumAux, i * int(kAuxVec4s) + 2).rgb * inv;
  vec3 c = remodulate(texelFetch(uColors, i).rgb, albedo) + emission;
  if (live && (tileCodes[tile] & kTileWrite) != 0u) layer[p] = vec4(c, 1.0);

}
