#version 460
// Verified reuse, before the frame's samples are accumulated (schedule/reuse.h): per pixel of
// each item, keep the accumulation as the history when an edit restarts the tile, go back to the
// history when another edit restarts it while the history is still kept (edits in a burst compare
// against the last converged samples, not against half-fresh ones), or drop the history from the
// accumulation when the test rejected it. (A plain restart forgets the history in accumulate.comp.) Sums stay exact: a pixel's accumulation is its history
// plus its fresh samples at every moment, compensations included.
#extension GL_GOOGLE_include_directive : require

#include "shared/layouts.h"

layout(local_size_x = kAccumulateWorkgroup) in;

layout(set = 0, binding = kBindReuseFrame, std140) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = kBindReuseItems, std430) readonly buffer Items { ReuseItem items[]; };
layout(set = 0, binding = kBindReuseAccum, std430) buffer Accum { vec4 accum[]; };
layout(set = 0, binding = kBindReuseHistory, std430) buffer History { vec4 history[]; };
layout(set = 0, binding = kBindReuseAccumAux, std430) buffer AccumAux { vec4 accumAux[]; };

layout(push_constant) uniform Push { ReusePush push; };

int findItem(uint pixel) {
  int lo = 0, hi = int(push.itemCount) - 1;
  while (lo < hi) {
    int mid = (lo + hi + 1) >> 1;
    if (items[mid].info.y <= pixel) lo = mid; else hi = mid - 1;
  }
  return lo;
}

void main() {
  uint k = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * uint(kAccumulateWorkgroup) + gl_LocalInvocationID.x;
  if (k >= push.pixelCount) return;
  ReuseItem item = items[findItem(k)];
  uint p = k - item.info.y;
  int px = item.rect.x + int(p % uint(item.rect.z));
  int py = item.rect.y + int(p / uint(item.rect.z));
  uint pixel = uint(py) * frame.image.x + uint(px);
  vec4 a0 = accum[pixel * 2u], a1 = accum[pixel * 2u + 1u];
  vec4 h0 = history[pixel * 2u], h1 = history[pixel * 2u + 1u];
  uint op = item.info.x;
  if (op == kReuseStart) {
    if (h0.w > 0.0) {
      accum[pixel * 2u] = h0;
      accum[pixel * 2u + 1u] = h1;
    } else {
      history[pixel * 2u] = a0;
      history[pixel * 2u + 1u] = a1;
    }
  } else {  // kReuseReject
    if (h0.w > 0.0) {
      // Both sums carry a Kahan compensation: subtract the compensated values.
      accum[pixel * 2u] = vec4((a0.rgb - a1.rgb) - (h0.rgb - h1.rgb), max(a0.w - h0.w, 0.0));
      accum[pixel * 2u + 1u] = vec4(0.0, 0.0, 0.0, max(a1.w - h1.w, 0.0));
      // The first-hit guides restart with the fresh samples: the old ones may show what moved.
      float keep = a0.w > 0.0 ? max(a0.w - h0.w, 0.0) / a0.w : 0.0;
      for (uint j = 0u; j < uint(kAuxVec4s); ++j) {
        vec4 x = accumAux[pixel * uint(kAuxVec4s) + j];
        accumAux[pixel * uint(kAuxVec4s) + j] = j == 0u ? vec4(x.rgb * keep, x.w) : (j == 1u ? vec4(x.xyz * keep, x.w) : x * keep);
      }
    }
    history[pixel * 2u] = vec4(0.0);
    history[pixel * 2u + 1u] = vec4(0.0);
  }
}
