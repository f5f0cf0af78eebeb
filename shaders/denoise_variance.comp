#version 460
// Denoiser, pass 2 of 4: the variance of each pixel's mean, which scales the filter's luminance
// edge-stopping. With eight samples or more the pixel's own second moment gives it; with fewer (too
// few for an estimate of its own) the moments of its neighbours on the same surface (normal and
// depth alike) stand in: a 3x3 grid with a step of 2 pixels, so 9 taps span 5x5 pixels, and the
// first a-trous iteration blurs the result over 3x3 more (7x7 in all, as SVGF's 7x7 estimate, at
// a fifth of the fetches). Also the depth gradient the depth edge-stopping is scaled by, from the
// same taps.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "shared/layouts.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(push_constant) uniform Push { DenoisePush push; };

#include "common/denoise.glsl"

layout(set = 0, binding = kBindDenoiseVarianceColors) uniform samplerBuffer uColors;   // RGBA16F view of packColor
layout(set = 0, binding = kBindDenoiseVarianceSurface) uniform samplerBuffer uSurface;  // normal, depth
layout(set = 0, binding = kBindDenoiseVarianceMoments) uniform samplerBuffer uMoments;
layout(set = 0, binding = kBindDenoiseVarianceOut, std430) writeonly buffer Out { uvec2 outColors[]; };
layout(set = 0, binding = kBindDenoiseVarianceGradient, std430) writeonly buffer Gradient { float gradients[]; };  // |depth gradient| per pixel

void main() {
  uint p;
  ivec2 xy;
  bool live = domainPixel(p, xy);
  vec4 t = texelFetch(uSurface, int(p));
  vec4 m = texelFetch(uMoments, int(p));
  float n = m.z;
  // Depths within 5 % of the pixel's count as the same surface.
  float depthScale = 1.0 / (0.05 * max(t.w, 0.0) + 1e-4);
  float sumW = 0.0, sumL = 0.0, sumL2 = 0.0, sumV = 0.0;
  float depths[9];
  [[unroll]] for (int k = 0; k < 9; ++k) {
    ivec2 q = clampToDomain(xy + 2 * ivec2(k % 3 - 1, k / 3 - 1));
    int qi = int(pixelIndex(q));
    vec4 tq = texelFetch(uSurface, qi);
    vec4 mq = texelFetch(uMoments, qi);
    depths[k] = tq.w;
    // cos^32 by five squarings (lavapipe's pow is an exp and a log per lane).
    float w = max(0.0, dot(t.xyz, tq.xyz));
    w *= w; w *= w; w *= w; w *= w; w *= w;
    w *= exp(-abs(t.w - tq.w) * depthScale) * (mq.z > 0.0 ? 1.0 : 0.0);
    sumW += w;
    sumL += w * mq.x;
    sumL2 += w * mq.y;
    sumV += w * max(0.0, mq.y - mq.x * mq.x);
  }
  float mean = sumL / max(sumW, 1e-8);
  float variance = n < 8.0 ? max(0.0, sumL2 / max(sumW, 1e-8) - mean * mean) : sumV / max(sumW, 1e-8);
  // Central differences over 4 pixels (taps 3 and 5 are left and right, 1 and 7 above and below).
  // Per pixel, and never above 5 % of the depth (at silhouettes the difference is between surfaces).
  float dz = 0.25 * max(abs(depths[5] - depths[3]), abs(depths[7] - depths[1]));
  float gradient = t.w >= kBackgroundDepth ? 0.0 : min(dz, 0.05 * t.w);
  vec3 color = texelFetch(uColors, int(p)).rgb;
  if (!live) return;
  outColors[p] = packColor(color, variance / max(n, 1.0));
  gradients[p] = gradient;
}
