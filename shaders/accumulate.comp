#version 460
// Accumulate pass: one invocation per served pixel. Reduces the pixel's q samples of this frame
// (exactly, for any q) and adds them to its running sum, or replaces the sum when the work
// item restarts the pixel. Sums use compensated (Kahan) addition so that thousands of samples
// do not drift.
#extension GL_GOOGLE_include_directive : require

#include "shared/layouts.h"

layout(local_size_x = kAccumulateWorkgroup) in;

layout(set = 0, binding = kBindAccumulateFrame, std140) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = kBindAccumulateWork, std430) readonly buffer Work { WorkItem items[]; };
layout(set = 0, binding = kBindAccumulateSamples, std430) readonly buffer Samples { vec4 samples[]; };
layout(set = 0, binding = kBindAccumulateAux, std430) readonly buffer Aux { vec4 aux[]; };
// Per pixel: [0] colour sum.rgb, sample count; [1] compensation.rgb, sum of squared luminances
// (the second moment, so the denoiser has every pixel's variance whatever tiles restarted).
layout(set = 0, binding = kBindAccumulateAccum, std430) buffer Accum { vec4 accum[]; };
// Per pixel (kAuxVec4s): [0] albedo sum.rgb, depth; [1] normal sum.xyz, instance id; [2] emission sum.rgb, -.
layout(set = 0, binding = kBindAccumulateAccumAux, std430) buffer AccumAux { vec4 accumAux[]; };
// Verified reuse (reuse.comp): the part of the accumulation that is history; bound only when
// push.hasHistory is set.
layout(set = 0, binding = kBindAccumulateHistory, std430) buffer History { vec4 history[]; };

layout(push_constant) uniform Push { AccumulatePush push; };

int findItem(uint pixel) {
  int lo = 0, hi = int(push.itemCount) - 1;
  while (lo < hi) {
    int mid = (lo + hi + 1) >> 1;
    if (items[mid].pixels.x <= pixel) lo = mid; else hi = mid - 1;
  }
  return lo;
}

void main() {
  uint local = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * uint(kAccumulateWorkgroup) + gl_LocalInvocationID.x;
  if (local >= push.pixelCount) return;
  uint k = push.pixelOffset + local;
  WorkItem item = items[findItem(k)];
  uint p = k - item.pixels.x;
  int px = item.rect.x + int(p % uint(item.rect.z));
  int py = item.rect.y + int(p / uint(item.rect.z));
  uint pixel = uint(py) * frame.image.x + uint(px);

  // Compensated summation within the frame too: a tile may take hundreds of samples at once.
  precise vec3 sum = vec3(0.0);
  precise vec3 lost = vec3(0.0);
  precise float count = 0.0;
  precise float squares = 0.0;
  vec3 albedo = vec3(0.0), normal = vec3(0.0), emission = vec3(0.0);
  float depth = 1e30;
  float instance = intBitsToFloat(0);
  bool haveInstance = false;
  // A coarse item's pixels share their block's samples (trace.comp).
  uint block = max(item.pixels.z, 1u), cell = p;
  if (block > 1u) {
    uint cols = (uint(item.rect.z) + block - 1u) / block;
    cell = (uint(py - item.rect.y) / block) * cols + uint(px - item.rect.x) / block;
  }
  for (uint r = 0u; r < item.info.x; ++r) {
    uint slot = item.info.y + cell * item.info.x + r;
    vec4 s = samples[slot];
    precise vec3 y = s.rgb - lost;
    precise vec3 t = sum + y;
    lost = (t - sum) - y;
    sum = t;
    count += s.w;
    float lum = dot(s.rgb, vec3(0.2126, 0.7152, 0.0722));
    squares += lum * lum;
    // Weight 0: a non-finite sample, or a slot the trace pass did not reach; its auxiliary
    // outputs are left out too.
    if (s.w == 0.0) continue;
    vec4 a0 = aux[slot * kAuxVec4s], a1 = aux[slot * kAuxVec4s + 1u], a2 = aux[slot * kAuxVec4s + 2u];
    albedo += a0.rgb;
    normal += a1.xyz;
    emission += a2.rgb;
    depth = min(depth, a0.w);
    if (!haveInstance) instance = a1.w;
    haveInstance = true;
  }

  bool restart = (item.info.w & kWorkRestart) != 0u;
  if (restart && push.hasHistory != 0u) {
    // A restart starts from nothing: no history either.
    history[pixel * 2u] = vec4(0.0);
    history[pixel * 2u + 1u] = vec4(0.0);
  }
  vec4 acc = restart ? vec4(0.0) : accum[pixel * 2u];
  vec4 comp = restart ? vec4(0.0) : accum[pixel * 2u + 1u];
  vec4 aa = restart ? vec4(0.0, 0.0, 0.0, 1e30) : accumAux[pixel * kAuxVec4s];
  vec4 an = restart ? vec4(0.0) : accumAux[pixel * kAuxVec4s + 1u];
  vec4 ae = restart ? vec4(0.0) : accumAux[pixel * kAuxVec4s + 2u];
  if (!restart && (item.info.w & kWorkCapStale) != 0u && acc.w > float(item.pixels.y)) {
    // Smooth transition: the stale sums keep the weight of at most `cap` samples, so the old
    // image fades out in a known number of frames instead of after as many as it had samples.
    float keep = float(item.pixels.y) / acc.w;
    if (push.hasHistory != 0u) {
      // The history is part of the sums: it fades with them, so fresh = sums - history still holds.
      vec4 h0 = history[pixel * 2u], h1 = history[pixel * 2u + 1u];
      if (h0.w > 0.0) {
        history[pixel * 2u] = h0 * keep;
        history[pixel * 2u + 1u] = h1 * keep;
      }
    }
    acc = vec4(acc.rgb * keep, float(item.pixels.y));
    comp *= keep;
    aa.rgb *= keep;
    an.xyz *= keep;
    ae.rgb *= keep;
  }
  // Kahan: add (sum - compensation); the new compensation is what the addition lost.
  precise vec3 y = (sum - lost) - comp.rgb;
  precise vec3 t = acc.rgb + y;
  precise vec3 c = (t - acc.rgb) - y;
  accum[pixel * 2u] = vec4(t, acc.w + count);
  accum[pixel * 2u + 1u] = vec4(c, comp.w + squares);

  accumAux[pixel * kAuxVec4s] = vec4(aa.rgb + albedo, min(aa.w, depth));
  accumAux[pixel * kAuxVec4s + 1u] = vec4(an.xyz + normal, instance);
  accumAux[pixel * kAuxVec4s + 2u] = vec4(ae.rgb + emission, 0.0);
}
