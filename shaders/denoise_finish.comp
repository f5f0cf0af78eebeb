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

layout(set = 0, binding = 0) uniform samplerBuffer uColors;    // RGBA16F: the filtered demodulated colour
layout(set = 0, binding = 1) uniform samplerBuffer uAccum;
layout(set = 0, binding = 2) uniform samplerBuffer uAccumAux;
layout(set = 0, binding = 3, std430) readonly buffer Tiles { uint tileCodes[]; };
layout(set = 0, binding = 4, std430) buffer Layer { vec4 layer[]; };
#ifdef DENOISE_FINISH_SHOWS
// Compiled as a second pipeline for frames denoised whole, where every tile shows the layer just
// written and there is no seam to soften: the finish writes the displayed image too, and the
// compositor does not run (a pass fewer: an eighth of the denoiser's time on lavapipe).
layout(set = 0, binding = 5, std430) writeonly buffer Display { vec4 display[]; };
#endif

#define DENOISE_READS_ACCUMULATION
#include "common/denoise.glsl"

void main() {
  uint p;
  ivec2 xy;
  bool live = domainPixel(p, xy);
  uint tile = uint(xy.y / int(push.tiles.x)) * push.tiles.y + uint(xy.x / int(push.tiles.x));
  Guides g = readGuides(int(p));
  vec3 c = remodulate(texelFetch(uColors, int(p)).rgb, g.albedo) + g.emission;
  if (live && (tileCodes[tile] & kTileWrite) != 0u) layer[p] = vec4(c, 1.0);
#ifdef DENOISE_FINISH_SHOWS
  if (live) display[p] = vec4(c, 1.0);
#endif
}
