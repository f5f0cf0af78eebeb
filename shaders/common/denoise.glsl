// Shared by the denoiser's passes and the compositor: which pixel an invocation handles, the
// demodulation by the guide hit's albedo, and the packed texel the a-trous iterations read.
#ifndef RETILE_DENOISE_GLSL
#define RETILE_DENOISE_GLSL

const float kBackgroundDepth = 1e20;  // a pixel whose guides saw no surface
// Demodulation divides by the albedo, but never by less than this: a channel of a nearly black
// albedo would otherwise carry its noise, amplified, into its neighbours' average.
const float kAlbedoFloor = 0.1;

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// The invocation's pixel inside push.domain (8x8 workgroups over it: no integer division per
// pixel, which lavapipe does lane by lane); false past the domain's right or bottom edge (those
// invocations still run, on the domain's last pixel, and must not write).
bool domainPixel(out uint index, out ivec2 xy) {
  ivec2 local = ivec2(gl_GlobalInvocationID.xy);
  xy = push.domain.xy + min(local, push.domain.zw - 1);
  index = uint(xy.y) * push.image.x + uint(xy.x);
  return all(lessThan(local, push.domain.zw));
}

ivec2 clampToDomain(ivec2 q) { return clamp(q, push.domain.xy, push.domain.xy + push.domain.zw - 1); }
uint pixelIndex(ivec2 q) { return uint(q.y) * push.image.x + uint(q.x); }

// What the preparation reads of a pixel's accumulation: its mean, the mean of the squares of its
// luminance, and the guides (the first non-specular hit's albedo, normal, depth and the emission
// seen up to it), each a mean over the pixel's samples. For shaders that bind uAccum and uAccumAux
// before including this. (lavapipe fetches every texel named, used or not: a shader that needs
// less reads less.)
#ifdef DENOISE_READS_ACCUMULATION
struct Guides {
  vec3 mean, albedo, emission, normal;
  float meanSquare, depth, samples;
};
Guides readGuides(int i) {
  vec4 s = texelFetch(uAccum, i * 2), c = texelFetch(uAccum, i * 2 + 1);
  vec4 a = texelFetch(uAccumAux, i * int(kAuxVec4s)), b = texelFetch(uAccumAux, i * int(kAuxVec4s) + 1);
  vec4 e = texelFetch(uAccumAux, i * int(kAuxVec4s) + 2);
  float inv = s.w > 0.0 ? 1.0 / s.w : 0.0;
  Guides g;
  g.samples = s.w;
  g.mean = (s.rgb - c.rgb) * inv;
  g.meanSquare = c.w * inv;
  g.albedo = a.rgb * inv;
  g.emission = e.rgb * inv;
  float len = length(b.xyz);
  g.normal = len > 0.0 ? b.xyz / len : vec3(0.0, 0.0, 1.0);
  g.depth = a.w >= 1e29 ? kBackgroundDepth : a.w;
  return g;
}
#endif

vec3 demodulate(vec3 c, vec3 albedo) { return c / max(albedo, vec3(kAlbedoFloor)); }
vec3 remodulate(vec3 c, vec3 albedo) { return c * max(albedo, vec3(kAlbedoFloor)); }

// The a-trous iterations read the demodulated colour and the standard deviation of the pixel's
// mean as four halves (one RGBA16F texel, converted by the fetch) and the pixel's normal and depth
// from the surface texel, which never changes between iterations; they write the halves only.
uvec2 packColor(vec3 color, float variance) {
  return uvec2(packHalf2x16(color.rg), packHalf2x16(vec2(color.b, sqrt(max(variance, 0.0)))));
}

#endif
