// Scene data (read-only texel buffers: on lavapipe a texel fetch costs a fraction of an SSBO
// load, see DESIGN.md) and ray traversal of the two-level BVH.
#ifndef RETILE_SCENE_GLSL
#define RETILE_SCENE_GLSL

#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_vote : require

#include "shared/layouts.h"
#include "common/sampling.glsl"
#include "common/bsdf.glsl"  // RETILE_BOUNDARY

// A storage buffer, not a uniform buffer: lavapipe (Mesa 22.3) "inlines" uniform-buffer values that
// decide branches into a fresh copy of the shader at every bind, and never frees the copies (the
// process grew by 1.9 MB a frame, whatever the image size).
layout(set = 0, binding = kBindTraceFrame, std430) readonly buffer Frame { FrameUniforms frameBuffer; };
// frameBuffer, copied by main before anything else: inside a loop or a branch, a storage buffer
// read is a loop over the lanes on lavapipe even at a uniform address, and the shading code
// reads the frame's constants in many places (the copy made the spaceship 6 % faster).
FrameUniforms frame;
// The scene's buffers are storage texel buffers, read with imageLoad, which lavapipe inlines: a
// texelFetch from a uniform texel buffer is a call per read, through a table of functions.
// Shading reads dozens (a material's fields, its textures' table, the
// instance, the triangle's normals and uvs, the emitters): with all of them inlined the kitchen
// traced about 1.05x, the living room 1.14x, our glass and ice 1.09x, the spaceship 1.02x the
// samples/s, sixteen lanes side by side (with the traversal buffer alone inlined, eight lanes,
// the rest gave the spaceship nothing measurable).
// Triangles, BVH nodes and instance records, addressed by items (layouts.h): three reads a
// traversal step.
layout(set = 0, binding = kBindTraceTraversal, rgba32f) uniform readonly imageBuffer uTraversal;
layout(set = 0, binding = kBindTraceTriShade, rgba32f) uniform readonly imageBuffer uTriShade;
layout(set = 0, binding = kBindTraceInstances, rgba32f) uniform readonly imageBuffer uInstances;
layout(set = 0, binding = kBindTraceMaterials, rgba32f) uniform readonly imageBuffer uMaterials;
layout(set = 0, binding = kBindTraceTexInfo, rgba32f) uniform readonly imageBuffer uTexInfo;
// Every bitmap's texels, as pairs of words: 8-bit RGBA a word each, or RGBA16F two words each
// (layouts.h kTexEightBit).
layout(set = 0, binding = kBindTraceTexels, rg32ui) uniform readonly uimageBuffer uTexels;
layout(set = 0, binding = kBindTraceEmitters, rgba32f) uniform readonly imageBuffer uEmitters;
layout(set = 0, binding = kBindTraceAlias, rgba32f) uniform readonly imageBuffer uEmitterAlias;
layout(set = 0, binding = kBindTraceDelta, rgba32f) uniform readonly imageBuffer uDeltaLights;
layout(set = 0, binding = kBindTraceEnvCdf, r32f) uniform readonly imageBuffer uEnvCdf;

// Traversal stack entries, over both levels of BVH. The builder keeps a level's depth within 40
// plus log2 of its primitives (SAH, then median splits past depth 40): at most 65 levels, so 64
// entries, for the 27 M triangles the traversal buffer can hold, and 128 for two levels. The
// array's size costs memory only; each iteration touches one entry.
const int kStackSize = 128;

// Alpha-tested geometry needs a texture lookup inside traversal, which costs lavapipe a factor of
// about three even when no instance uses it, so the renderer compiles it in only for scenes
// that have cut-outs.
#ifndef RETILE_ALPHA_TEST
#define RETILE_ALPHA_TEST 1
#endif
const float kInfinity = 1e30;
// A quantised box's exit distance is taken this much further (render/bvh.h kSlabSlack).
const float kSlabSlack = 1.0000004;

// The scene's features (kFeature... in layouts.h). lavapipe runs every branch, taken or not (see
// traceRay), so code for what the scene lacks would cost every path segment: the renderer
// compiles a kernel per feature set, and a feature's code sits behind hasFeature, which the
// compiler folds away.
#ifndef RETILE_FEATURES
#define RETILE_FEATURES kFeatureAll
#endif
bool hasFeature(int feature) { return (RETILE_FEATURES & feature) != 0; }

// lavapipe (gallivm) runs eight invocations in lock-step and ends every loop of those eight once
// 65535 loop iterations have run, counted over all loops together, silently: a ray cut off there
// misses what it should hit. One loop iteration is counted while any of the eight runs it (and,
// as measured, twice for each iteration counted here). Each invocation keeps that count in
// loopIterations: it counts its own iterations, and takes the maximum over the lanes running with
// it (syncLoopIterations) after each loop whose iterations differ between lanes, before another
// such loop (a lane's sum over two of them can fall short of the sum of their maxima). That
// maximum is exact for our loops: a loop's lanes run a prefix of its iterations, no loop nests
// inside another one except the path loop of trace.comp (which synchronises after each segment),
// and every lane that ran a loop takes part in the next synchronisation. Each synchronisation is
// a loop over the lanes on lavapipe, so there is one only where lanes part ways and run loops
// that others do not: after shading, in scenes with a sky map (the lanes that sampled it searched
// it). Elsewhere every lane runs the same iterations: the work-item search runs in every lane,
// for a fixed number of steps, whether or not the lane starts a path, and the suns' loop, which
// only the lanes whose path missed run, is counted in every lane (an upper bound). A path stops
// before the count can reach the limit (kLoopBudget in trace.comp); the renderer reports both.
// Real GPUs have no such limit.
uint loopIterations = 0u;

void syncLoopIterations() { loopIterations = subgroupMax(loopIterations); }

struct Hit {
  float t;
  float u, v;
  int prim;      // global packed triangle index, -1 for a miss
  int instance;
};

// Texel i of a bitmap whose texels start at pair `offset`, linear RGBA. The sRGB curve is applied
// to each texel before filtering, as when bitmaps were decoded to floats on the CPU. Only the
// storages the scene has are compiled in (kFeatureByteTexels and on), by the preprocessor: lavapipe
// inlines every call before it drops dead code, and a kernel that reads no texture took 12 MB
// more to compile with this function's whole body in each of its seventeen calls.
vec4 bitmapTexel(int offset, int i, int flags) {
#if (RETILE_FEATURES & RT_FEATURE_BYTE_TEXELS) != 0
  if (!hasFeature(kFeatureHalfTexels) || (flags & kTexEightBit) != 0) {
    uvec2 pair = imageLoad(uTexels, offset + (i >> 1)).xy;
    uint word = (i & 1) != 0 ? pair.y : pair.x;
    vec4 c = vec4((uvec4(word) >> uvec4(0u, 8u, 16u, 24u)) & 255u) * (1.0 / 255.0);
#if (RETILE_FEATURES & RT_FEATURE_SRGB_TEXELS) != 0
    if ((flags & kTexSrgb) != 0)
      c.rgb = mix(c.rgb / 12.92, pow((c.rgb + 0.055) / 1.055, vec3(2.4)), greaterThan(c.rgb, vec3(0.04045)));
#endif
    return c;
  }
#endif
#if (RETILE_FEATURES & RT_FEATURE_HALF_TEXELS) != 0
  uvec2 h = imageLoad(uTexels, offset + i).xy;
  vec4 c = vec4(unpackHalf2x16(h.x), unpackHalf2x16(h.y));
  c.rgb *= exp2(float((flags >> kTexScaleShift) & kTexScaleMax));
  return c;
#else
  return vec4(0.0);
#endif
}

// Texture lookup, bilinear or nearest, repeated or held at the edges (kTexNearest, kTexClamp);
// checkers are analytic.
vec4 sampleTexture(int index, vec2 uv) {
  vec4 info = imageLoad(uTexInfo, index * kTextureTexels);
  int kind = floatBitsToInt(info.w);
  if ((kind & 15) == kTexChecker) {
    vec4 on = imageLoad(uTexInfo, index * kTextureTexels + 1);
    vec4 off = imageLoad(uTexInfo, index * kTextureTexels + 2);
    vec2 at = uv * vec2(on.w, off.w);
    ivec2 cell = (kind & kTexTruncate) != 0 ? ivec2(at) : ivec2(floor(at));
    return ((cell.x ^ cell.y) & 1) != 0 ? vec4(on.rgb, 1.0) : vec4(off.rgb, 1.0);
  }
  int offset = floatBitsToInt(info.x);
  int w = floatBitsToInt(info.y), h = floatBitsToInt(info.z);
  // v points up in every format we import; image rows go down. Wrap in floating point first:
  // GLSL leaves % of negative integers undefined, and far-away uvs overflow an int.
  bool clampToEdge = (kind & kTexClamp) != 0, nearest = (kind & kTexNearest) != 0;
  vec2 wrapped = vec2(uv.x, 1.0 - uv.y);
  wrapped = any(isnan(wrapped)) || any(isinf(wrapped)) ? vec2(0.0) : clampToEdge ? clamp(wrapped, 0.0, 1.0) : wrapped - floor(wrapped);
  ivec2 size = ivec2(w, h);
  vec2 p = wrapped * vec2(size) - (nearest ? 0.0 : 0.5);
  vec2 f = nearest ? vec2(0.0) : fract(p);
  ivec2 base = ivec2(floor(p));
  ivec2 i0 = clamp(base + ivec2(lessThan(base, ivec2(0))) * (clampToEdge ? ivec2(0) : size), ivec2(0), size - 1);
  ivec2 i1 = i0 + 1;
  i1 = clampToEdge ? clamp(base + 1, ivec2(0), size - 1) : i1 - ivec2(greaterThanEqual(i1, size)) * size;
  vec4 a = bitmapTexel(offset, i0.y * w + i0.x, kind);
  vec4 b = bitmapTexel(offset, i0.y * w + i1.x, kind);
  vec4 c = bitmapTexel(offset, i1.y * w + i0.x, kind);
  vec4 d = bitmapTexel(offset, i1.y * w + i1.x, kind);
  return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

// Texel i of slopes packed from pair `offset` on, two halves a word (render_materials.cpp
// appendSlopes).
vec2 slopeTexel(int offset, int i) {
  uvec2 pair = imageLoad(uTexels, offset + (i >> 1)).xy;
  return unpackHalf2x16((i & 1) != 0 ? pair.y : pair.x);
}

// The slope of a texture's value (the mean of its colour channels) at uv, as Tungsten's bump
// maps take it (BitmapTexture::derivatives): differences across two texels, along u and down the
// image's rows, interpolated between the four texels about uv. Not divided by the texel size:
// the slope of a bump map depends on its resolution, as in Tungsten. Each texel's differences
// are packed after its colour, so that this reads four words instead of twelve texels. Checkers
// are flat, as is a bitmap packed without slopes (offset -1: packTextures gives slopes to every
// texture a material bumps by, so none should be met).
vec2 textureSlope(int index, vec2 uv) {
  vec4 info = imageLoad(uTexInfo, index * kTextureTexels);
  int offset = floatBitsToInt(imageLoad(uTexInfo, index * kTextureTexels + 1).x);
  if ((floatBitsToInt(info.w) & 15) == kTexChecker || offset < 0) return vec2(0.0);
  offset = max(offset, 0);  // the lanes that returned still run what follows, on lavapipe
  int w = max(floatBitsToInt(info.y), 1), h = max(floatBitsToInt(info.z), 1);
  vec2 wrapped = vec2(uv.x, 1.0 - uv.y);
  wrapped = any(isnan(wrapped)) || any(isinf(wrapped)) ? vec2(0.0) : wrapped - floor(wrapped);
  vec2 p = wrapped * vec2(w, h) - 0.5;
  vec2 f = p - floor(p);
  // Columns i and i + 1, rows likewise, wrapped: i is from -1 to w - 1 (h - 1). Not by %:
  // lavapipe divides integers one lane at a time.
  ivec2 i0 = ivec2(floor(p));
  ivec2 i1 = i0 + 1;
  i0 += ivec2(lessThan(i0, ivec2(0))) * ivec2(w, h);
  i1 -= ivec2(greaterThanEqual(i1, ivec2(w, h))) * ivec2(w, h);
  vec2 s00 = slopeTexel(offset, i0.y * w + i0.x), s01 = slopeTexel(offset, i0.y * w + i1.x);
  vec2 s10 = slopeTexel(offset, i1.y * w + i0.x), s11 = slopeTexel(offset, i1.y * w + i1.x);
  return mix(mix(s00, s01, f.x), mix(s10, s11, f.x), f.y);
}

float sampleAlphaTexture(int index, vec2 uv) {
  vec4 info = imageLoad(uTexInfo, index * kTextureTexels);
  vec4 t = sampleTexture(index, uv);
  // Without an alpha channel, the channels' mean, as Tungsten reads a transparency's alpha
  // (REQUEST_AUTO); for a grey mask that is its value.
  return (floatBitsToInt(info.w) & kTexAlpha) != 0 ? t.a : dot(t.rgb, vec3(1.0 / 3.0));
}

vec2 triangleUv(int prim, float u, float v) {
  vec4 s0 = imageLoad(uTriShade, prim * kTriShadeTexels + 0);
  vec4 s1 = imageLoad(uTriShade, prim * kTriShadeTexels + 1);
  vec4 s2 = imageLoad(uTriShade, prim * kTriShadeTexels + 2);
  vec4 s3 = imageLoad(uTriShade, prim * kTriShadeTexels + 3);
  vec2 t0 = vec2(s0.w, s1.w), t1 = vec2(s2.w, s3.x), t2 = s3.yz;
  return (1.0 - u - v) * t0 + u * t1 + v * t2;
}

// Stochastic cut-out: a candidate hit on an alpha-tested instance counts with probability alpha.
// The random number comes from the ray and the triangle, so a shadow ray and the camera agree.
// A number in [0, 1) of the ray's and a triangle's (hit by it), decorrelated by `salt` between uses.
float hitRandom(float rayRandom, int prim, uint salt) {
  uint h = floatBitsToUint(rayRandom) ^ (uint(prim) * salt);
  h = h * 747796405u + 2891336453u;
  h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
  return float(((h >> 22u) ^ h) >> 8) * (1.0 / 16777216.0);
}

// The index of an instance's material.
int instanceMaterial(int instance) { return floatBitsToInt(imageLoad(uInstances, instance * kInstanceTexels + 3).z); }

// The cosine of a material's emission cone (Material::emissionCone): its front emits toward
// directions whose cosine with its normal is above it (0: the hemisphere).
float emissionConeCos(int material) { return imageLoad(uMaterials, material * kMaterialTexels + 7).z; }

bool alphaPasses(int instance, int prim, float u, float v, float rayRandom) {
  int material = instanceMaterial(instance);
  int alphaTex = RT_MATERIAL_TEXTURE(material, alphaTexture);
  float alpha = RT_MATERIAL_SCALAR(material, alpha);
  if (alphaTex >= 0) alpha *= sampleAlphaTexture(alphaTex, triangleUv(prim, u, v));
  return hitRandom(rayRandom, prim, 2654435761u) < alpha;
}

// The item of a node's child in `slot` (layouts.h), from the node's layout.
int childItem(uint slot, uint innerCount, uint starts, uint innerBase, uint leafBase, int leafKind) {
  bool inner = slot < innerCount;
  uint unit = inner ? innerBase + slot : leafBase + ((starts >> (uint(kStartBits) * slot)) & ((1u << kStartBits) - 1u));
  return (int(unit * uint(kUnitTexels)) << kItemOffsetShift) | (inner ? kItemNode : leafKind);
}

vec3 safeInverse(vec3 d) {
  const float eps = 1e-12;
  return vec3(abs(d.x) > eps ? 1.0 / d.x : (d.x >= 0.0 ? 1e30 : -1e30),
              abs(d.y) > eps ? 1.0 / d.y : (d.y >= 0.0 ? 1e30 : -1e30),
              abs(d.z) > eps ? 1.0 / d.z : (d.z >= 0.0 ? 1e30 : -1e30));
}

// A lane's rays in flight: the closest hit of an extension ray (when `first`) and then any opaque
// hit of its path's shadow ray up to tMax2 (when `second`), traced one after the other in one loop
// (of traceStep, in trace.comp's main). A ray not traced comes back as a miss. One loop for both:
// lavapipe runs eight lanes in lock-step and a loop as long as its slowest lane, so the eight
// extension rays and then the eight shadow rays in two loops ran the longest of each (157 loop
// iterations per spaceship path against 131 in one loop), and the loop's code is compiled once.
// The state outlives the loop: a lane whose rays are not done when the loop ends goes on with
// them in the next.
//
// Every value here is carried through every iteration of that loop, and one written in a branch
// costs a select in every iteration (lavapipe runs both sides of a branch), so the state is kept
// small: the extension ray's hit stays in `hit` while the shadow ray is traced (any hit but a
// boundary's ends a shadow ray, so its distance limit stays tMax2 and only what blocks it is
// kept: `blocker`).
struct Trace {
  bool second;    // a shadow ray follows the extension ray
  bool onShadow;  // the lane traces the shadow ray now (also once done: then tMax2 is -1)
  bool done;      // both rays are traced: hit and blocker hold what they found
  bool idle;      // it was given nothing to trace
  vec3 origin, dir, invDir;  // the current ray, in world space
  // The triangle (prim, instance) the current ray leaves, which it cannot hit again (a triangle is
  // flat). The offset origin alone did not keep rays off a large triangle: the intersection's
  // rounding grows with the triangle's size, the offset with the origin's magnitude.
  ivec2 from;
  float rayRandom;
  vec3 origin2, dir2, invDir2;
  ivec2 from2;
  float tMax2, random2;
  vec3 o, d, invD;  // the current ray in the space of the instance it is in (kFeatureInstanceTransforms)
  int item, top, stackSize;
  int instance, instFlags;
  int instanceSp;  // stack depth on entering the current instance: popping back to it leaves
  Hit hit;         // the extension ray's closest hit so far (a miss when it was not traced)
  int blocker;     // the instance that blocks the shadow ray, -1 when nothing does
#if RETILE_BOUNDARY
  // The boundaries (kMatBoundary) the shadow ray crossed, which do not block it, in any order: the
  // sum of their media's extinctions less the world's (FrameUniforms::worldAbsorption; the empty
  // ones count none), + entering across the front and - leaving, and of the same
  // times minus the distance to the crossing. Its optical depth to a light at distance d, from a
  // medium of extinction s, is then (s + crossedSigma) d + crossedDepth (trace.comp resolveShadow).
  // crossedScale sums the extinctions' sizes, to tell rounding from a medium still around.
  vec3 crossedSigma, crossedDepth;
  float crossedScale;
  // The boundaries (kInstanceBoundary, kTriBoundary) a shadow ray crossed in this round of the
  // traversal loop, up to four, whose media are not counted yet: trace.comp counts them past the
  // loop for every lane at once (countCrossings), where in the loop lavapipe paid for the four
  // fetches of a boundary's medium at every step of every lane. Each is its instance + 1, negated
  // when the ray leaves across the back, and its distance. A fifth pauses the lane on it
  // (crossingPending), as a cut-out's candidate does (alphaPending, below), until they are
  // counted; the step is then taken again.
  int crossings;
  ivec4 crossingInstance;
  vec4 crossingT;
  bool crossingPending;
#endif
#if RETILE_SHEET
  // What the thin sheets a shadow ray passed let through along it (they pause it as cut-outs do:
  // alphaPending), taken past the loop (trace.comp sheetPasses).
  vec3 shadowWeight;
#endif
#if RETILE_SHEET || RETILE_BOUNDARY
  // How many sheets and boundaries it passed: each a bounce, as for a path (trace.comp resolveShadow).
  int passed;
#endif
#if RETILE_ALPHA_TEST
  // A candidate hit on an alpha-tested triangle pauses the lane's traversal on it (alphaPending)
  // until trace.comp, past the traversal loop, looks its alpha up for every paused lane at once:
  // lavapipe would pay for that lookup (fifteen fetches) at every step of every lane in the loop,
  // taken or not. The answer, alphaDecision (1 passes, -1 does not, 0 none yet), is taken when
  // the next step tests the same triangle again.
  bool alphaPending;
  int alphaDecision;
  int pendingPrim, pendingInstance;
  float pendingU, pendingV;
  // With the fixed ray offset (kFeatureFixedEpsilon) a pass is a forward event, as Tungsten's: the
  // ray goes on from the point it passed, skipping what lies within kFixedRayEpsilon beyond it, so
  // that a shell of cut-outs thinner than that (a blind's two faces 0.25 mm apart) is one layer,
  // as in Tungsten, not two. What a ray skips depends on the order it meets things in, which the
  // traversal does not follow, so then nothing is decided in the loop: the ray's segment finds
  // its nearest cut-out (an extension ray its closest hit, flagged hitForward; a shadow ray the
  // nearest cut-out, sheet or boundary, at forwardT, with its opaque blockers as any hit up to there),
  // pauses on it once the segment is traced (alphaPending), and once decided (trace.comp
  // resolveForward) either stops there or is traced again from tNear = past it + the epsilon.
  bool hitForward;
  float forwardT, tNear;
#if RETILE_BOUNDARY
  // A boundary a shadow ray crosses is a forward event too, counted once the ray passes it: when
  // the nearest is one, its crossing (as Trace::crossingInstance holds one), else 0.
  int forwardCrossing;
#endif
#endif
};

// `root` is frame.scene.x, the instance BVH's root, which the caller reads once.
void beginTrace(inout Trace tr, int root, bool first, vec3 origin1, vec3 dir1, ivec2 from1, float random1, bool second,
                vec3 origin2, vec3 dir2, ivec2 from2, float tMax2, float random2) {
  Hit miss;
  miss.t = kInfinity;
  miss.prim = -1;
  miss.instance = -1;
  miss.u = 0.0;
  miss.v = 0.0;
  tr.hit = miss;
  tr.blocker = -1;
#if RETILE_BOUNDARY
  tr.crossedSigma = vec3(0.0);
  tr.crossedDepth = vec3(0.0);
  tr.crossedScale = 0.0;
  tr.crossings = 0;
  tr.crossingPending = false;
#endif
  tr.idle = !(first || second);
  tr.done = tr.idle;
  tr.second = second;
  // A lane with nothing to trace visits the root with a ray that enters nothing (see traceStep):
  // its limit, tMax2, is negative.
  tr.onShadow = !first;
  tMax2 = tr.idle ? -1.0 : tMax2;
  tr.origin2 = origin2;
  tr.dir2 = dir2;
  tr.invDir2 = safeInverse(dir2);
  tr.tMax2 = tMax2;
  tr.random2 = random2;
  tr.origin = tr.onShadow ? origin2 : origin1;
  tr.dir = tr.onShadow ? dir2 : dir1;
  tr.invDir = tr.onShadow ? tr.invDir2 : safeInverse(dir1);
  tr.rayRandom = tr.onShadow ? random2 : random1;
  tr.from = tr.onShadow ? from2 : from1;
  tr.from2 = from2;
  tr.o = tr.origin;
  tr.d = tr.dir;
  tr.invD = tr.invDir;
  tr.item = root;
  tr.top = 0;
  tr.stackSize = 0;
  tr.instance = -1;
  tr.instFlags = 0;
  tr.instanceSp = -1;
#if RETILE_ALPHA_TEST
  tr.alphaPending = false;
  tr.alphaDecision = 0;
  tr.hitForward = false;
  tr.forwardT = kInfinity;
  tr.tNear = 0.0;
#if RETILE_BOUNDARY
  tr.forwardCrossing = 0;
#endif
#endif
#if RETILE_SHEET
  tr.shadowWeight = vec3(1.0);
#endif
#if RETILE_SHEET || RETILE_BOUNDARY
  tr.passed = 0;
#endif
}

#if RETILE_BOUNDARY
// Counts the boundaries the lane's shadow ray crossed (Trace::crossings) into its crossed media,
// and lets a lane paused on a fifth go on. Outside the traversal loop (trace.comp).
void countCrossings(inout Trace tr) {
  for (int i = 0; i < tr.crossings; ++i) {
    int code = tr.crossingInstance[i];
    int material = floatBitsToInt(imageLoad(uInstances, (abs(code) - 1) * kInstanceTexels + 3).z) * kMaterialTexels;
    vec3 sigma = imageLoad(uMaterials, material + 8).rgb + imageLoad(uMaterials, material + 9).rgb;
    tr.crossedScale += maxComponent(sigma);
    // The change of medium across it: from the world's (or to it) for one that holds a medium;
    // none for an empty one, which leaves the ray's medium as it is.
    if (maxComponent(sigma) > 0.0) sigma -= frame.worldAbsorption.xyz + frame.worldScattering.rgb;
    sigma = code > 0 ? sigma : -sigma;
    tr.crossedSigma += sigma;
    tr.crossedDepth -= sigma * tr.crossingT[i];
  }
  tr.passed += tr.crossings;
  tr.crossings = 0;
  tr.crossingPending = false;
}
#endif

// Whether a lane waits, paused on a candidate hit, for what is looked up between rounds of the
// traversal loop (trace.comp).
#if RETILE_ALPHA_TEST && RETILE_BOUNDARY
#define TRACE_PAUSED(tr) ((tr).alphaPending || (tr).crossingPending)
#elif RETILE_ALPHA_TEST
#define TRACE_PAUSED(tr) ((tr).alphaPending)
#elif RETILE_BOUNDARY
#define TRACE_PAUSED(tr) ((tr).crossingPending)
#else
#define TRACE_PAUSED(tr) false
#endif

// One step of a lane's traversal. The caller (trace.comp's main) holds the stack below the top
// entry: `below` is the entry a pop brings to the top, and tr.top is already in the slot a push
// moves it to.
//
// lavapipe (Mesa 22.3) runs both sides of every branch with lanes masked off: an if skips no
// code, even when no lane takes it. A loop iteration therefore costs all the code in its body,
// whichever step each lane is at. So one iteration does one step of any kind (visit a node to
// take one of its four children, test one triangle, or enter an instance), and all three read
// their record through the same three texel fetches of the one traversal buffer. Testing up to two leaves of four
// triangles in the visiting iteration, as before, made every iteration pay for 24 fetches.
void traceStep(inout Trace tr, int below, int root) {
#if RETILE_ALPHA_TEST
  if (tr.alphaPending) return;  // paused on a candidate whose alpha is not known yet
#endif
#if RETILE_BOUNDARY
  if (tr.crossingPending) return;  // paused on a fifth boundary until the four are counted
#endif
  // Without instance transforms the ray in an instance's space is the world's, and the loop
  // carries nine values fewer (tr.o, d and invD are then never read, and compiled out).
  const bool transforms = hasFeature(kFeatureInstanceTransforms);
  // With the instances' nodes copied into the instance BVH there are no records to enter, and a
  // triangle names its instance itself.
  const bool direct = hasFeature(kFeatureDirectReferences) && !transforms;
  vec3 rayO = transforms ? tr.o : tr.origin, rayD = transforms ? tr.d : tr.dir;
  vec3 rayInvD = transforms ? tr.invD : tr.invDir;
  // How far the current ray looks: a shadow ray to its light, an extension ray to its hit so far.
  float tLimit = tr.onShadow ? tr.tMax2 : tr.hit.t;
  // And from where: past what a ray that passed a cut-out skips (Trace::hitForward).
  float tMin = 0.0;
#if RETILE_ALPHA_TEST
  const bool forwardEvents = hasFeature(kFeatureFixedEpsilon);
  if (forwardEvents) {
    tMin = tr.tNear;
    // A shadow ray's segment ends at the nearest cut-out it has met (it is traced on from there).
    if (tr.onShadow) tLimit = min(tLimit, tr.forwardT);
  }
#endif
  int item = tr.item;
  int at = item >> kItemOffsetShift;
  int kind = item & 3;
  vec4 r0 = imageLoad(uTraversal, at), r1 = imageLoad(uTraversal, at + 1), r2 = imageLoad(uTraversal, at + 2);
  // Only an instance's transform needs a fourth.
  vec4 r3 = vec4(0.0);
  if (transforms) r3 = imageLoad(uTraversal, at + 3);
  int next = -1;
  bool finished = false;
  if (kind == kItemNode) {
    // Four child boxes, quantised (render/bvh.h QuantizedNode): a plane's distance is
    // (origin - o) / d + q * scale / d, each axis for the four children at once. The children
    // are taken nearest entry first, one per visit, and one entry is pushed (see the stack in
    // trace.comp's main): the one child left, or, with more left, the node itself, with the
    // position to go on from in its item's count bits. Its next visit tests the boxes again,
    // against the hit found meanwhile, and ranks them as before (the entry distances do not
    // depend on the hit).
    vec3 invD = rayInvD;
    uvec3 e = (uvec3(floatBitsToUint(r0.w)) >> uvec3(0u, 8u, 16u)) & 255u;
    vec3 base = (r0.xyz - rayO) * invD;
    vec3 scaled = uintBitsToFloat(e << 23u) * invD;
    uvec4 qa = floatBitsToUint(r1), qb = floatBitsToUint(r2);
    // The planes a ray enters and leaves by: lo and hi swap where the direction is negative.
    bool bx = invD.x < 0.0, by = invD.y < 0.0, bz = invD.z < 0.0;
    uint inX = bx ? qa.w : qa.x, outX = bx ? qa.x : qa.w;
    uint inY = by ? qb.x : qa.y, outY = by ? qa.y : qb.x;
    uint inZ = bz ? qb.y : qa.z, outZ = bz ? qa.z : qb.y;
    const uvec4 bytes = uvec4(0u, 8u, 16u, 24u);
    // Axis by axis, so that few values are live at once. Selects rather than min and max:
    // lavapipe gives those NaN semantics at three instructions each. tNear is never NaN (a
    // distance only replaces a smaller one), so the ranks below are a strict order.
    vec4 tNear = base.x + vec4((uvec4(inX) >> bytes) & 255u) * scaled.x;
    // From tMin on (0 but for a ray traced again past a cut-out): boxes left behind are not entered.
    tNear = mix(vec4(tMin), tNear, greaterThan(tNear, vec4(tMin)));
    vec4 tFar = base.x + vec4((uvec4(outX) >> bytes) & 255u) * scaled.x;
    vec4 t = base.y + vec4((uvec4(inY) >> bytes) & 255u) * scaled.y;
    tNear = mix(tNear, t, greaterThan(t, tNear));
    t = base.y + vec4((uvec4(outY) >> bytes) & 255u) * scaled.y;
    tFar = mix(tFar, t, lessThan(t, tFar));
    t = base.z + vec4((uvec4(inZ) >> bytes) & 255u) * scaled.z;
    tNear = mix(tNear, t, greaterThan(t, tNear));
    t = base.z + vec4((uvec4(outZ) >> bytes) & 255u) * scaled.z;
    tFar = mix(tFar, t, lessThan(t, tFar)) * kSlabSlack;
    tFar = mix(vec4(tLimit), tFar, lessThan(tFar, vec4(tLimit)));
    // The children (layouts.h): inner ones first, one unit each from `inner` on, then leaves,
    // whose runs start where the layout says, from `leaves` on.
    uint shape = (floatBitsToUint(r0.w) >> 24) | ((qb.z >> (kBaseBits - 8)) & 0x3f00u) | ((qb.w >> (kBaseBits - 14)) & 0xfc000u);
    uint innerCount = (shape >> kLayoutInner) & 7u;
    int leafKind = !direct && (shape & (1u << kLayoutInstances)) != 0u ? kItemInstance : kItemTriangles;
    uint starts = (shape >> (kLayoutStarts - kStartBits)) & ~((1u << kStartBits) - 1u);  // a field a slot, slot 0's 0
    const uint baseMask = (1u << kBaseBits) - 1u;
    uint innerBase = qb.z & baseMask, leafBase = qb.w & baseMask;
    // An empty slot's box is inside out (render/bvh.cpp quantize), but in a node of no extent far
    // from the origin its planes can round to one point: the count of used slots says it is empty.
    ivec4 entered = ivec4(lessThanEqual(tNear, tFar)) * ivec4(lessThan(uvec4(0u, 1u, 2u, 3u), uvec4((shape >> kLayoutUsed) & 7u)));
    // Each child's rank, nearest entry first (render/bvh.cpp childRanks). Ties, frequent where the
    // ray starts inside several boxes, go to the later slot: leaves before inner children, and
    // among each the ones the builder's collapse opened later. That took 7 % fewer loop
    // iterations in the room of 1.06 M triangles than ties in slot order, and 2 % on the
    // spaceship; the children sorted by area for the ties did worse.
    bool c01 = tNear.y <= tNear.x, c02 = tNear.z <= tNear.x, c03 = tNear.w <= tNear.x;
    bool c12 = tNear.z <= tNear.y, c13 = tNear.w <= tNear.y, c23 = tNear.w <= tNear.z;
    uvec4 rank = uvec4(uint(c01) + uint(c02) + uint(c03), uint(!c01) + uint(c12) + uint(c13),
                       uint(!c02) + uint(!c12) + uint(c23), uint(!c03) + uint(!c13) + uint(!c23));
    uint inOrder = (uint(entered.x) << rank.x) | (uint(entered.y) << rank.y) | (uint(entered.z) << rank.z) | (uint(entered.w) << rank.w);
    uint left = inOrder & (15u << uint((item >> 2) & 3));
    int pos = findLSB(left);
    uint rest = left & (left - 1u);
    int pos2 = findLSB(rest);
    uint slot = rank.x == uint(pos) ? 0u : (rank.y == uint(pos) ? 1u : (rank.z == uint(pos) ? 2u : 3u));
    uint slot2 = rank.x == uint(pos2) ? 0u : (rank.y == uint(pos2) ? 1u : (rank.z == uint(pos2) ? 2u : 3u));
    if (left != 0u) next = childItem(slot, innerCount, starts, innerBase, leafBase, leafKind);
    // What is pushed: the one child left, as it is, or the node, to go on from pos + 1.
    int otherChild = childItem(slot2, innerCount, starts, innerBase, leafBase, leafKind);
    if (rest != 0u && tr.stackSize < kStackSize) {
      tr.top = (rest & (rest - 1u)) == 0u ? otherChild : (item & ~12) | ((pos + 1) << 2);
      tr.stackSize++;
    }
  } else if (kind == kItemTriangles) {
    // Moeller-Trumbore against v0 = r0.xyz, e1 = r1.xyz, e2 = r2.xyz.
    vec3 d = rayD;
    vec3 pv = cross(d, r2.xyz);
    float det = dot(r1.xyz, pv);
    float inv = 1.0 / det;
    vec3 s = rayO - r0.xyz;
    float uu = dot(s, pv) * inv;
    vec3 q = cross(s, r1.xyz);
    float vv = dot(d, q) * inv;
    float tt = dot(r2.xyz, q) * inv;
    int p = floatBitsToInt(r0.w);
    int instance = direct ? floatBitsToInt(r2.w) & kTriInstanceMask : tr.instance;
    bool found = det != 0.0 && uu >= 0.0 && vv >= 0.0 && uu + vv <= 1.0 && tt > tMin && tt < tLimit &&
                 (p != tr.from.x || instance != tr.from.y);
    if (hasFeature(kFeatureCullBack)) {
      // det is -dot(d, the triangle's normal): negative where the ray meets its back, which an
      // object hit from the front only lets every ray, shadow rays too, pass (as Tungsten's
      // backface_culling does). In object space, so a mirroring transform keeps the side that
      // the winding and the normal matrix call the front (trace.comp's frontFace).
      bool culls = direct ? (floatBitsToInt(r2.w) & kTriCullBack) != 0 : (tr.instFlags & kInstanceCullBack) != 0;
      found = found && !(culls && det < 0.0);
    }
    bool forwardHit = false;
#if RETILE_ALPHA_TEST
    bool alphaTested = direct ? (floatBitsToInt(r2.w) & kTriAlphaTested) != 0 : (tr.instFlags & kInstanceAlphaTested) != 0;
#if RETILE_SHEET
    // A thin sheet pauses shadow rays alone: an extension ray hits it.
    alphaTested = alphaTested || (tr.onShadow && (direct ? (floatBitsToInt(r2.w) & kTriSheet) != 0 : (tr.instFlags & kInstanceSheet) != 0));
#endif
    if (forwardEvents) {
      // Decided once the segment is traced: an extension ray's hit like any other, flagged; a
      // shadow ray's the nearest so far (tLimit is the nearest before it).
      forwardHit = alphaTested;
      if (found && alphaTested && tr.onShadow) {
        tr.forwardT = tt;
        tr.pendingPrim = p;
        tr.pendingInstance = instance;
        tr.pendingU = uu;
        tr.pendingV = vv;
#if RETILE_BOUNDARY
        tr.forwardCrossing = 0;
#endif
        found = false;
      }
    } else {
      if (found && alphaTested && tr.alphaDecision == 0) {
        // Pause here, the item unchanged, so that the step is taken again with the answer.
        tr.alphaPending = true;
        tr.pendingPrim = p;
        tr.pendingInstance = instance;
        tr.pendingU = uu;
        tr.pendingV = vv;
        return;
      }
      if (found && alphaTested) found = tr.alphaDecision > 0;
      tr.alphaDecision = 0;
    }
#endif
#if RETILE_BOUNDARY
    // A boundary is no surface: the shadow ray goes on, into the medium on its other side, which
    // countCrossings counts. (A boundary is never a cut-out: packInstances.)
    bool boundary = direct ? (floatBitsToInt(r2.w) & kTriBoundary) != 0 : (tr.instFlags & kInstanceBoundary) != 0;
    bool crosses = found && tr.onShadow && boundary;
#if RETILE_ALPHA_TEST
    if (forwardEvents && crosses) {
      // With the fixed offset, the nearest so far (Trace::forwardCrossing): crossed, and counted,
      // once the segment is traced, so that one the ray skips past a cut-out is not counted.
      tr.forwardT = tt;
      tr.pendingPrim = p;
      tr.pendingInstance = instance;
      tr.pendingU = uu;
      tr.pendingV = vv;
      tr.forwardCrossing = det > 0.0 ? instance + 1 : -(instance + 1);
      found = false;
      crosses = false;
    }
#endif
    if (crosses) {
      if (tr.crossings == 4) {
        // Pause here, the item unchanged, so that the step is taken again once they are counted.
        tr.crossingPending = true;
        return;
      }
      // det is -dot(d, the triangle's normal): positive across the front, into its medium.
      tr.crossingInstance[tr.crossings] = det > 0.0 ? instance + 1 : -(instance + 1);
      tr.crossingT[tr.crossings] = tt;
      tr.crossings++;
      found = false;
    }
#endif
    if (found && tr.onShadow) {
      tr.blocker = instance;
      finished = true;
    }
    if (found && !tr.onShadow) {
      tr.hit.t = tt;
      tr.hit.u = uu;
      tr.hit.v = vv;
      tr.hit.prim = p;
      tr.hit.instance = instance;
#if RETILE_ALPHA_TEST
      tr.hitForward = forwardHit;
#endif
    }
    // The rest of the leaf: one triangle further on, until the run's last.
    if (r1.w == 0.0) next = item + (kTriTexels << kItemOffsetShift);
  } else if (!direct) {
    // Enter an instance: transform the ray (t is preserved because d is not renormalised).
    tr.instance = floatBitsToInt(r0.y);
    tr.instFlags = floatBitsToInt(r0.z);
    if (transforms) {
      vec3 origin = tr.origin, dir = tr.dir;
      tr.o = vec3(dot(r1.xyz, origin) + r1.w, dot(r2.xyz, origin) + r2.w, dot(r3.xyz, origin) + r3.w);
      tr.d = vec3(dot(r1.xyz, dir), dot(r2.xyz, dir), dot(r3.xyz, dir));
      tr.invD = safeInverse(tr.d);
    }
    tr.instanceSp = tr.stackSize;
    next = floatBitsToInt(r0.x);
  }
  if (next < 0 && !finished) {
    finished = tr.stackSize == 0;
    if (!finished) {
      next = tr.top;
      tr.top = below;
      tr.stackSize--;
    }
  }
#if RETILE_ALPHA_TEST
  if (forwardEvents && finished && (tr.onShadow ? tr.blocker < 0 && tr.forwardT < kInfinity : tr.hitForward)) {
    // The segment ends at a cut-out (Trace::hitForward): wait for it to be decided.
    if (!tr.onShadow) {
      tr.pendingPrim = tr.hit.prim;
      tr.pendingInstance = tr.hit.instance;
      tr.pendingU = tr.hit.u;
      tr.pendingV = tr.hit.v;
    }
    tr.alphaPending = true;
    return;
  }
#endif
  if (finished && (tr.onShadow || !tr.second)) {
    // Both rays done. The lane stays in the loop until it ends, visiting the root with a ray
    // that enters nothing (a negative limit): a lane that left the loop made every iteration's
    // stack write, masked for it, reload its slot and mispredict.
    tr.done = true;
    tr.onShadow = true;
    tr.tMax2 = -1.0;
    tr.stackSize = 0;
    next = root;
  } else if (finished) {
    // The extension ray is done: the shadow ray starts at the instance BVH's root.
    tr.onShadow = true;
    tr.origin = tr.origin2;
    tr.dir = tr.dir2;
    tr.invDir = tr.invDir2;
    tr.rayRandom = tr.random2;
    tr.from = tr.from2;
    tr.stackSize = 0;
#if RETILE_ALPHA_TEST
    tr.tNear = 0.0;
#endif
    next = root;
  }
  if (tr.stackSize < tr.instanceSp || finished) {
    // Back from the instance to world space (or to the shadow ray's).
    tr.o = tr.origin;
    tr.d = tr.dir;
    tr.invD = tr.invDir;
    tr.instance = -1;
    tr.instanceSp = -1;
  }
  tr.item = next;
}

#endif
