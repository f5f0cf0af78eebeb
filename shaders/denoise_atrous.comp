#version 460
// Denoiser, pass 3 of 4, run kDenoiseIterations times with the step doubling (1, 2, 4, ...): one
// iteration of the edge-avoiding a-trous wavelet filter (the spatial part of SVGF, Schied et al.
// 2017), a 5x5 B-spline kernel whose taps are weighted down across normals (cos^128), depths and
// luminances. (Its two separable 5-tap halves cost a quarter less on lavapipe but streak along
// the rows on flat floors.) The luminance weight is scaled by the filtered variance of the pixel's mean, so as
// samples accumulate and the variance falls, the filter stops blurring and the result goes to the
// accumulated image. Taps outside the domain take no part.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "shared/layouts.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(push_constant) uniform Push { DenoisePush push; };

#include "common/denoise.glsl"

layout(set = 0, binding = 0) uniform samplerBuffer uIn;       // RGBA16F: demodulated colour, std. dev. of the mean
layout(set = 0, binding = 1) uniform samplerBuffer uSurface;  // normal, depth
layout(set = 0, binding = 2) uniform samplerBuffer uGuide;    // [2p].w: |depth gradient|
layout(set = 0, binding = 3, std430) writeonly buffer Out { uvec2 outColors[]; };

const float kSigmaLuminance = 4.0;
const float kSigmaDepth = 1.0;
const float kKernel[3] = float[3](3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0);

void main() {
  uint p;
  ivec2 xy;
  bool live = domainPixel(p, xy);
  int step = int(push.image.z);
  vec4 c = texelFetch(uIn, int(p));
  vec4 s = texelFetch(uSurface, int(p));
  float gradient = texelFetch(uGuide, int(p) * 2).w;
  bool background = s.w >= kBackgroundDepth;

  // The variance at the pixel, blurred 3x3 in the first pass (a single pixel's estimate is
  // itself noisy); later passes read variances the filter has already smoothed.
  float deviation = c.w;
  int blur = step == 1 ? 1 : 0;
  if (blur > 0) {
    deviation = 0.0;
    for (int dy = -blur; dy <= blur; ++dy)
      for (int dx = -blur; dx <= blur; ++dx) {
        float k = (dx == 0 ? 0.5 : 0.25) * (dy == 0 ? 0.5 : 0.25);
        deviation += k * texelFetch(uIn, int(pixelIndex(clampToDomain(xy + ivec2(dx, dy))))).w;
      }
  }
  float lumP = luminance(c.rgb);
  float lumScale = 1.0 / (kSigmaLuminance * deviation + 1e-10);
  // The depth tolerance grows with the tap's distance: kSigmaDepth times the depth gradient per
  // pixel, plus a thousandth of the depth per pixel. One reciprocal a pixel; the taps' 1 / distance
  // are constants of the unrolled loop.
  float depthScale = 1.0 / ((kSigmaDepth * max(gradient, 0.0) + 1e-3 * max(s.w, 0.0)) * float(step) + 1e-6);

  float sumW = 1.0;
  vec3 sum = c.rgb;
  float sumVar = c.w * c.w;
  [[unroll]] for (int dy = -2; dy <= 2; ++dy)
    [[unroll]] for (int dx = -2; dx <= 2; ++dx) {
      if (dx == 0 && dy == 0) continue;
      ivec2 q = xy + ivec2(dx, dy) * step;
      int qi = int(pixelIndex(clampToDomain(q)));
      vec4 cq = texelFetch(uIn, qi);
      vec4 sq = texelFetch(uSurface, qi);
      // cos^128 by seven squarings: lavapipe's pow is an exp and a log per lane.
      float cosine = max(0.0, dot(s.xyz, sq.xyz));
      cosine *= cosine; cosine *= cosine; cosine *= cosine; cosine *= cosine;
      cosine *= cosine; cosine *= cosine; cosine *= cosine;
      bool bothBackground = background && sq.w >= kBackgroundDepth;
      // The depth and luminance terms share one exp.
      float e = abs(s.w - sq.w) * depthScale * inversesqrt(float(dx * dx + dy * dy)) + abs(lumP - luminance(cq.rgb)) * lumScale;
      float w = (inDomain(q) ? kKernel[abs(dx)] * kKernel[abs(dy)] / (kKernel[0] * kKernel[0]) : 0.0) *
                (bothBackground ? 1.0 : cosine) * exp(-e);
      sumW += w;
      sum += w * cq.rgb;
      sumVar += w * w * cq.w * cq.w;
    }
  if (!live) return;
  outColors[p] = packColor(sum / sumW, sumVar / (sumW * sumW));
}
