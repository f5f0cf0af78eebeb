#version 460
// Denoiser, pass 3 of 4, run kDenoiseIterations times with the step doubling (1, 2, 4, ...): one
// iteration of the edge-avoiding a-trous wavelet filter (the spatial part of SVGF, Schied et al.
// 2017), whose taps are weighted down across normals, depths and luminances. The luminance weight
// is scaled by the filtered variance of the pixel's mean, so as samples accumulate and the
// variance falls, the filter stops blurring and the result goes to the accumulated image.
//
// The kernel is the 3x3 B-spline (1/4, 1/2, 1/4), not SVGF's 5x5: on lavapipe a tap costs the same
// whatever its weight, and the 5x5's 24 taps made each iteration 2.5 times as costly for an
// error at 4 spp lower by a tenth. Taps past the domain's edge are clamped
// onto it (its edge pixels weigh more there) rather than tested and dropped, and the three
// edge-stopping terms share one exp2, with SVGF's cos^128 normal weight as exp(-128 (1 - cos)):
// both agree to within a few per cent where either weight matters.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "shared/layouts.h"

layout(local_size_x = kDenoiseTile, local_size_y = kDenoiseTile) in;
layout(push_constant) uniform Push { DenoisePush push; };

layout(set = 0, binding = kBindDenoiseAtrousIn) uniform samplerBuffer uIn;        // RGBA16F: demodulated colour, std. dev. of the mean
layout(set = 0, binding = kBindDenoiseAtrousSurface) uniform samplerBuffer uSurface;   // normal, depth
layout(set = 0, binding = kBindDenoiseAtrousGradient) uniform samplerBuffer uGradient;  // |depth gradient| per pixel
layout(set = 0, binding = kBindDenoiseAtrousOut, std430) writeonly buffer Out { uvec2 outColors[]; };

#include "common/denoise.glsl"

const float kSigmaLuminance = 6.0;
const float kSigmaDepth = 1.0;
const float kLog2E = 1.4426950409;

// 2^x for x <= 0 as (1 + x ln2 / 16)^16, zero below x = -16 / ln2: four squarings where exp2 is a
// polynomial and a scale per lane. Up to 3 % low at e^-1 and lower further out, where the
// weights are small anyway.
float fastExp2(float x) {
  float y = max(0.0, 1.0 + x * (0.69314718 / 16.0));
  y *= y; y *= y; y *= y;
  return y * y;
}

void main() {
  uint p;
  ivec2 xy;
  bool live = domainPixel(p, xy);
  int step = int(push.image.z);
  vec4 c = texelFetch(uIn, int(p));
  vec4 s = texelFetch(uSurface, int(p));
  float gradient = texelFetch(uGradient, int(p)).x;

  float deviation = c.w;
  float lumP = luminance(c.rgb);
  // Every scale in log2 units, for exp2. The depth tolerance grows with the tap's distance:
  // kSigmaDepth times the depth gradient per pixel, plus a thousandth of the depth per pixel.
  float lumScale = kLog2E / (kSigmaLuminance * deviation + 1e-10);
  float depthScale = kLog2E / ((kSigmaDepth * max(gradient, 0.0) + 1e-3 * max(s.w, 0.0)) * float(step) + 1e-6);
  const float normalScale = 128.0 * kLog2E;

  float sumW = 1.0;
  vec3 sum = c.rgb;
  float sumVar = c.w * c.w;
  [[unroll]] for (int dy = -1; dy <= 1; ++dy)
    [[unroll]] for (int dx = -1; dx <= 1; ++dx) {
      if (dx == 0 && dy == 0) continue;
      int qi = int(pixelIndex(clampToDomain(xy + ivec2(dx, dy) * step)));
      vec4 cq = texelFetch(uIn, qi);
      vec4 sq = texelFetch(uSurface, qi);
      // The kernel's weight relative to the centre's (1/2 x 1/2) and the taps' 1 / distance are
      // constants of the unrolled loop.
      const float kernel = (dx == 0 ? 1.0 : 0.5) * (dy == 0 ? 1.0 : 0.5);
      const float distance = (dx != 0 && dy != 0) ? 0.70710678 : 1.0;
      float e = abs(s.w - sq.w) * (depthScale * distance) + abs(lumP - luminance(cq.rgb)) * lumScale +
                (1.0 - dot(s.xyz, sq.xyz)) * normalScale;
      float w = kernel * fastExp2(-e);
      sumW += w;
      sum += w * cq.rgb;
      sumVar += w * w * cq.w * cq.w;
    }
  if (!live) return;
  outColors[p] = packColor(sum / sumW, sumVar / (sumW * sumW));
}
