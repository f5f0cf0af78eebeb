#version 460
// Denoiser, pass 4 of 4: remodulates the filtered illumination by the albedo, adds the emission
// back and writes it into the denoised layer, for the tiles whose code carries kTileWrite (a
// region's newly covered tiles, or every tile when the whole frame is denoised). Older results in
// the layer stay.
#extension GL_GOOGLE_include_directive : require

#include "shared/layouts.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(push_constant) uniform Push { DenoisePush push; };

#include "common/denoise.glsl"

layout(set = 0, binding = 0) uniform samplerBuffer uColors;  // RGBA16F: the filtered demodulated colour
layout(set = 0, binding = 1) uniform samplerBuffer uGuide;
layout(set = 0, binding = 2, std430) readonly buffer Tiles { uint tileCodes[]; };
layout(set = 0, binding = 3, std430) buffer Layer { vec4 layer[]; };

void main() {
  uint p;
  ivec2 xy;
  bool live = domainPixel(p, xy);
  uint tile = uint(xy.y / int(push.tiles.x)) * push.tiles.y + uint(xy.x / int(push.tiles.x));
  vec3 c = remodulate(texelFetch(uColors, int(p)).rgb, texelFetch(uGuide, int(p) * 2).rgb) +
           texelFetch(uGuide, int(p) * 2 + 1).rgb;
  if (live && (tileCodes[tile] & kTileWrite) != 0u) layer[p] = vec4(c, 1.0);
}
