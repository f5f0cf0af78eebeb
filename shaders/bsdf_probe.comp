#version 460
// Evaluates and samples the renderer's BSDFs (common/bsdf.glsl, the code the tracer runs) for
// given materials and directions, so that tests can check them against their definitions:
// energy, reciprocity, pdfs and directional albedo (render/bsdf_probe.h).
#extension GL_GOOGLE_include_directive : require

#include "common/bsdf.glsl"

layout(local_size_x = 64) in;

// Per query: the material's kMaterialTexels texels, then wo (and in w a hair's h), wi and the
// sample's random numbers.
layout(set = 0, binding = kBindBsdfProbeQueries, std430) readonly buffer Queries { vec4 queries[]; };
// Per query: eval(wo, wi) (f * |cos wi|, pdf); the sample's wi and pdf; its weight and flags
// (1: delta, 2: transmitted); eval at the sampled wi (f * |cos|, pdf).
layout(set = 0, binding = kBindBsdfProbeAnswers, std430) writeonly buffer Answers { vec4 answers[]; };

layout(push_constant) uniform Push { uint count; } push;

const uint kQueryVec4s = uint(kMaterialTexels) + 3u;

void main() {
  uint q = gl_GlobalInvocationID.x;
  if (q >= push.count) return;
  uint base = q * kQueryVec4s;
  Material m = unpackMaterial(queries[base], queries[base + 1u], queries[base + 2u], queries[base + 3u], queries[base + 4u],
                              queries[base + 6u], queries[base + 7u], queries[base + 8u]);
  uint at = base + uint(kMaterialTexels);
  vec3 wo = queries[at].xyz, wi = queries[at + 1u].xyz, u = queries[at + 2u].xyz;
  m.hairH = queries[at].w;  // the fibre runs along x (unpackMaterial)
  float pdf;
  vec3 f = bsdfEval(m, wo, wi, pdf);
  BsdfSample s = bsdfSample(m, wo, u);
  float pdfAt;
  vec3 fAt = bsdfEval(m, wo, s.wi, pdfAt);
  answers[q * 4u] = vec4(f, pdf);
  answers[q * 4u + 1u] = vec4(s.wi, s.pdf);
  answers[q * 4u + 2u] = vec4(s.weight, float((s.delta ? 1 : 0) | (s.transmitted ? 2 : 0)));
  answers[q * 4u + 3u] = vec4(fAt, pdfAt);
}
