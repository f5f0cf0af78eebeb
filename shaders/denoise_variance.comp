#version 460
// Denoiser, pass 2 of 4: the variance of each pixel's mean, which scales the filter's luminance
// edge-stopping. With eight samples or more the pixel's own second moment gives it; with fewer (too
// few for an estimate of its own) its 7x7 neighbours on the same surface (normal and depth alike)
// stand in. Also the depth gradient the depth edge-stopping is scaled by.
#extension GL_GOOGLE_include_directive : require

#include "shared/layouts.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(push_constant) uniform Push { DenoisePush push; };

#include "common/denoise.glsl"

layout(set = 0, binding = 0) uniform samplerBuffer uColors;   // RGBA16F view of packColor
layout(set = 0, binding = 1) uniform samplerBuffer uSurface;  // normal, depth
layout(set = 0, binding = 2) uniform samplerBuffer uMoments;
layout(set = 0, binding = 3, std430) writeonly buffer Out { uvec2 outColors[]; };
layout(set = 0, binding = 4, std430) buffer Guide { vec4 guide[]; };  // writes [2p].w: |depth gradient|

float depthAt(ivec2 q) { return texelFetch(uSurface, int(pixelIndex(clampToDomain(q)))).w; }

void main() {
  uint p;
  ivec2 xy;
  bool live = domainPixel(p, xy);
  vec4 t = texelFetch(uSurface, int(p));
  vec4 m = texelFetch(uMoments, int(p));
  float n = m.z;
  float variance = max(0.0, m.y - m.x * m.x);
  // The loop's radius, not a branch around it, decides: lavapipe runs both sides of a branch, but
  // a loop only as long as some lane needs it.
  int radius = n < 8.0 ? 3 : 0;
  if (radius > 0) {
    float sumW = 0.0, sumL = 0.0, sumL2 = 0.0;
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        ivec2 q = xy + ivec2(dx, dy);
        int qi = int(pixelIndex(clampToDomain(q)));
        vec4 tq = texelFetch(uSurface, qi);
        vec4 mq = texelFetch(uMoments, qi);
        bool bothBackground = t.w >= kBackgroundDepth && tq.w >= kBackgroundDepth;
        float w = inDomain(q) ? 1.0 : 0.0;
        w *= bothBackground ? 1.0 : pow(max(0.0, dot(t.xyz, tq.xyz)), 32.0);
        w *= exp(-abs(t.w - tq.w) / (0.05 * max(min(t.w, tq.w), 0.0) + 1e-4));
        w *= mq.z > 0.0 ? 1.0 : 0.0;
        sumW += w;
        sumL += w * mq.x;
        sumL2 += w * mq.y;
      }
    float mean = sumL / max(sumW, 1e-8);
    variance = max(0.0, sumL2 / max(sumW, 1e-8) - mean * mean);
  }
  float dzx = abs(depthAt(xy + ivec2(1, 0)) - depthAt(xy - ivec2(1, 0)));
  float dzy = abs(depthAt(xy + ivec2(0, 1)) - depthAt(xy - ivec2(0, 1)));
  float gradient = t.w >= kBackgroundDepth ? 0.0 : 0.5 * min(max(dzx, dzy), 0.1 * t.w);
  vec3 color = texelFetch(uColors, int(p)).rgb;
  if (!live) return;
  outColors[p] = packColor(color, variance / max(n, 1.0));
  guide[p * 2u].w = gradient;
}
