#version 460
// The displayed image: per tile the raw accumulation or the denoised layer (tileCodes), with soft
// borders. Where two tiles show different things (fresh and stale samples, or two regions'
// denoised results), each pixel within `feather` pixels of the seam blends in something of the
// other side, half at the seam falling to none at the feather's width, so the seam is not mistaken
// for a shadow or an edge. Across a seam between raw samples and the layer, that is what the other
// tile shows at the same pixel (a cross-fade between the pixel's two values); across a seam
// between two tiles of one kind (raw and raw, or two regions' results in the one layer), a pixel
// has one value of that kind, so its mirror image across the seam stands in. (The mirror image at
// raw-to-layer seams too put other places' content beside them: with the change method's scattered
// fresh tiles it doubled the error.) One invocation per pixel of the image.
#extension GL_GOOGLE_include_directive : require

#include "shared/layouts.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(push_constant) uniform Push { DenoisePush push; };

#include "common/denoise.glsl"

layout(set = 0, binding = kBindComposeAccum) uniform samplerBuffer uAccum;
layout(set = 0, binding = kBindComposeLayer) uniform samplerBuffer uLayer;
layout(set = 0, binding = kBindComposeTiles, std430) readonly buffer Tiles { uint tileCodes[]; };
layout(set = 0, binding = kBindComposeDisplay, std430) writeonly buffer Display { vec4 display[]; };

uint codeAt(ivec2 tile) { return tileCodes[uint(tile.y) * push.tiles.y + uint(tile.x)] & kTileKindMask; }

vec3 shown(ivec2 q, uint code) {
  int i = int(pixelIndex(q));
  vec4 s = texelFetch(uAccum, i * 2);
  vec3 raw = s.w > 0.0 ? (s.rgb - texelFetch(uAccum, i * 2 + 1).rgb) / s.w : vec3(0.0);
  return code >= kTileLayer ? texelFetch(uLayer, i).rgb : raw;
}

void main() {
  uint p;
  ivec2 xy;
  bool live = domainPixel(p, xy);
  int T = int(push.tiles.x);
  ivec2 tile = xy / T;
  ivec2 cols = ivec2(int(push.tiles.y), (int(push.image.y) + T - 1) / T);
  uint code = codeAt(tile);
  vec3 v = shown(xy, code);
  float feather = float(push.image.w);
  ivec2 origin = tile * T;
  ivec2 size = min(ivec2(T), ivec2(push.image.xy) - origin);
  vec3 blend = vec3(0.0);
  float total = 0.0;
  // Left, right, top, bottom: the neighbouring tile, this pixel's distance to the shared edge and
  // its mirror image across it.
  // Without soft borders the loop does not run (lavapipe runs a loop only while some lane needs it).
  int sides = feather > 0.0 ? 4 : 0;
  for (int side = 0; side < sides; ++side) {
    ivec2 dir = side == 0 ? ivec2(-1, 0) : side == 1 ? ivec2(1, 0) : side == 2 ? ivec2(0, -1) : ivec2(0, 1);
    ivec2 other = tile + dir;
    bool exists = all(greaterThanEqual(other, ivec2(0))) && all(lessThan(other, cols));
    ivec2 o = clamp(other, ivec2(0), cols - 1);
    int axis = side < 2 ? 0 : 1;
    int local = xy[axis] - origin[axis];
    int d = (side == 0 || side == 2) ? local : size[axis] - 1 - local;  // whole pixels to the edge
    ivec2 mirror = xy;
    mirror[axis] = (side == 0 || side == 2) ? origin[axis] - 1 - local : origin[axis] + size[axis] + d;
    mirror = clamp(mirror, ivec2(0), ivec2(push.image.xy) - 1);
    uint otherCode = codeAt(o);
    float w = exists && otherCode != code ? 0.5 * max(0.0, 1.0 - (float(d) + 0.5) / max(feather, 1e-6)) : 0.0;
    bool sameKind = (code < kTileLayer) == (otherCode < kTileLayer);
    blend += w * shown(sameKind ? mirror : xy, otherCode);
    total += w;
  }
  v = v * (1.0 - total) + blend;
  if (live) display[p] = vec4(v, 1.0);
}
