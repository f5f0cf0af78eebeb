#version 460
// Runs common/integer.glsl's helpers on given numbers, so that tests can check them against the
// CPU's integer arithmetic (tests/gpu/shader_math_test.cpp).
#extension GL_GOOGLE_include_directive : require

#include "shared/layouts.h"
#include "common/integer.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = kBindIntegerProbeQueries, std430) readonly buffer Queries { uvec2 queries[]; };  // a, b
layout(set = 0, binding = kBindIntegerProbeAnswers, std430) writeonly buffer Answers { uint answers[]; };   // quotient(a, b)

layout(push_constant) uniform Push { uint count; } push;

void main() {
  uint q = gl_GlobalInvocationID.x;
  if (q >= push.count) return;
  answers[q] = quotient(queries[q].x, queries[q].y);
}
