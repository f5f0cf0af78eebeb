#version 460
// Path tracing pass: one invocation per sample slot. A frame's slots are spread over work items
// (rectangles of pixels with q samples each), so global rendering (one item: q = 1 in the
// editor, about 2^18 samples a frame offline) and tile re-rendering (many items, any q) run the
// same kernel. Writes per-slot radiance and the first hit's albedo, normal, depth and instance
// for the accumulate pass.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_ballot : require

#include "common/integer.glsl"
#include "common/rng.glsl"
#include "common/bsdf.glsl"
#include "common/lights.glsl"

layout(local_size_x = kTraceWorkgroup) in;

layout(set = 0, binding = kBindTraceWork, std430) readonly buffer Work { WorkItem items[]; };
layout(set = 0, binding = kBindTraceSamples, std430) writeonly buffer Samples { vec4 samples[]; };
layout(set = 0, binding = kBindTraceAux, std430) writeonly buffer Aux { vec4 aux[]; };
// primary, bounce, shadow rays; the most loop iterations of one invocation; paths cut short;
// loop iterations of all invocations, in kLoopIterationUnit; the most of one path segment.
layout(set = 0, binding = kBindTraceStats, std430) buffer Stats { uint rayCounts[kStatsCount]; };

// kLoopBudget (layouts.h): paths stop before a subgroup's lock-stepped invocations could reach
// lavapipe's loop limit (see scene.glsl). That limit is 65535 of lavapipe's own counts, and it
// counts each of our iterations twice (measured: an invocation given 20736 paths was stopped by
// lavapipe when loopIterations read 32659). One more segment of a subgroup's paths, with their
// shadow rays, cost at most 465 of our iterations in the scenes measured (the living room, eight lanes;
// `retile bench throughput` prints it); should a scene's segments be longer, the paths stop
// earlier, when twice the longest segment so far would pass kLoopLimit.

// What the tracer sees of the selected object and of its group, per tile (the indirection-aware
// policy): the instances' set words, then the counters (layouts.h, kSelectionCounters).
layout(set = 0, binding = kBindTraceSelection, std430) buffer Selection { uint selectionCounts[]; };

layout(push_constant) uniform Push { TracePush push; };

// The pixel filter's table (frame.filterWarp's 36 values) in a texel buffer: each lane reads its
// own slot, and a storage buffer read at a different index in each lane is a loop over the
// subgroup's lanes on lavapipe (the table's 16 such reads a segment cost the spaceship 10 %).
layout(set = 0, binding = kBindTraceFilterWarp, r32f) uniform readonly imageBuffer uFilterWarp;

float warpSlot(int i) { return imageLoad(uFilterWarp, i).x; }

// The stepped table's CDF (FilterSampling::SteppedTable) at step i = 0..30: slot i - 1 holds it, step 0's is 0.
float steppedCdf(int i) { return i <= 0 ? 0.0 : warpSlot(i - 1); }

// The stepped tent table at step i = 0..31 in closed form: the weights 1 - k/31 of steps k = 0..30
// sum to 16, so the sum of those below step i, normalised, is (i - i (i - 1) / 62) / 16.
float steppedTentCdf(int i) {
  float f = float(i);
  return (f - f * (f - 1.0) / 62.0) / 16.0;
}

// A sample's offset from the pixel centre along one axis for u in [0, 1): the filter's inverse
// CDF, linear between its 33 tabulated points (layouts.h), or exact for a tent, or from the
// stepped table (as Tungsten's ReconstructionFilter::sample draws: the first step whose CDF
// exceeds the draw, searched from step 1, so the draw lands one step further out than the weight
// it was drawn with).
// Only the way the scene's filter is drawn is compiled in (kFeatureFilter...): every lane runs
// this for every segment, whether it starts a path or not.
float filterOffset(float u) {
  float tent = frame.filterWarp[8].w;
  if (hasFeature(kFeatureFilterTent) && tent > 0.0) return tent * (u < 0.5 ? sqrt(2.0 * u) - 1.0 : 1.0 - sqrt(2.0 - 2.0 * u));
  if (hasFeature(kFeatureFilterSteppedTent) && tent < 0.0 && frame.filterWarp[8].z > 0.0) {
    // As below, with the step found without the table: its search (seven reads a side, each a
    // call over the subgroup's lanes, in every lane of every pass) cost the spaceship about 5 % of its
    // samples/s. The CDF is steppedTentCdf's, equal to the table's up to
    // its float sums' rounding.
    bool negative = u < 0.5;
    float xi = negative ? 2.0 * u : 2.0 * u - 1.0;
    float x = 0.5 * (63.0 - sqrt(max(3969.0 - 3968.0 * xi, 0.0)));  // steppedTentCdf(x) = xi
    int lo = clamp(int(x) + 1, 1, 30);
    float c0 = steppedTentCdf(lo - 1), c1 = steppedTentCdf(lo);
    // The root's rounding can put it a step off: the step is the first whose CDF exceeds xi.
    if (xi < c0 && lo > 1) {
      lo--;
      c1 = c0;
      c0 = steppedTentCdf(lo - 1);
    } else if (xi >= c1 && lo < 30) {
      lo++;
      c0 = c1;
      c1 = steppedTentCdf(lo);
    }
    float offset = -tent * (float(lo) + (xi - c0) / max(c1 - c0, 1e-9)) / 31.0;
    return negative ? -offset : offset;
  }
  if (hasFeature(kFeatureFilterStepped) && tent < 0.0) {
    bool negative = u < 0.5;
    float xi = negative ? 2.0 * u : 2.0 * u - 1.0;
    int lo = 1, hi = 30;  // the first step in 1..29 with CDF > xi, else 30
    for (int k = 0; k < 5; ++k) {
      int mid = (lo + hi) >> 1;
      bool below = mid >= 30 || xi < steppedCdf(mid);
      hi = below ? mid : hi;
      lo = below ? lo : mid + 1;
    }
    float c0 = steppedCdf(lo - 1), c1 = steppedCdf(lo);
    float offset = -tent * (float(lo) + (xi - c0) / max(c1 - c0, 1e-9)) / 31.0;
    return negative ? -offset : offset;
  }
  if (!hasFeature(kFeatureFilterTable)) return 0.0;
  float t = u * float(kFilterWarpSegments);
  int i = min(int(t), kFilterWarpSegments - 1);
  float a = warpSlot(i), b = warpSlot(i + 1);
  return mix(a, b, t - float(i));
}

// Index of the counters of the tile holding pixel (px, py), or -1 when not counting.
int selectionBase(int px, int py) {
  uint t = frame.work.w;
  if (t == 0u || frame.work.z == 0u) return -1;
  uint cols = quotient(frame.image.x + t - 1u, t);
  return int(frame.work.z - 1u + (quotient(uint(py), t) * cols + quotient(uint(px), t)) * uint(kSelectionCounters));
}

// The counted sets an instance belongs to (bit 0: the selected object, bit 1: its group). Read only
// while counting: a storage buffer read costs lavapipe far more than a texel fetch.
uint countedSets(int instance) {
  if (instance < 0) return 0u;
  uint word = selectionCounts[uint(instance) / uint(kInstancesPerSetWord)];
  return (word >> ((uint(instance) % uint(kInstancesPerSetWord)) * 2u)) & 3u;
}

// The material a hit on material `index` shades with: itself or, for a blend (Material::blendWith),
// its partner when `blendRandom` falls past the ratio (times its texture's channel mean at uv,
// where it has one), and so on along the partner's own blend, kMaxBlendChain materials at most;
// emission stays the hit material's. Without `textured` (a constant) the albedo and roughness are
// the untextured values, and their lookups' code is left out.
Material fetchMaterial(int index, vec2 uv, float blendRandom, bool textured) {
  int shaded = index;
  if (hasFeature(kFeatureBlend)) {
    float u = blendRandom;
    for (int k = 1; k < kMaxBlendChain; ++k) {
      int partner = floatBitsToInt(imageLoad(uMaterials, shaded * kMaterialTexels + 5).w);
      if (partner < 0) break;
      float ratio = RT_MATERIAL_SCALAR(shaded, blendRatio);
      if (hasFeature(kFeatureTextures)) {
        int ratioTex = RT_MATERIAL_TEXTURE(shaded, blendRatioTexture);
        if (ratioTex >= 0) ratio *= dot(sampleTexture(ratioTex, uv).rgb, vec3(1.0 / 3.0));
      }
      if (u < ratio) break;
      // The number left over is uniform again over what remains: the next blend draws from it.
      u = (u - ratio) / max(1.0 - ratio, 1e-6);
      shaded = partner;
    }
  }
  int base = shaded * kMaterialTexels;
  vec4 t2 = imageLoad(uMaterials, base + 2), t3 = imageLoad(uMaterials, base + 3);
  // The coating's absorption (a plastic's, a thin sheet's, a hair's pigment) is read only when
  // the scene has one of them.
  const bool plastics = (kMaterialMask & ((1 << kMatPlastic) | (1 << kMatRoughPlastic) | (1 << kMatThinSheet) | (1 << kMatHair))) != 0;
  Material m = unpackMaterial(imageLoad(uMaterials, base), imageLoad(uMaterials, base + 1), t2, t3,
                              imageLoad(uMaterials, base + 4), plastics ? imageLoad(uMaterials, base + 6) : vec4(0.0),
                              kCoatUsed ? imageLoad(uMaterials, base + 7) : vec4(0.0),
                              kCoatUsed || kMediumUsed ? imageLoad(uMaterials, base + 8) : vec4(0.0));
  if (kScatteringUsed) m.scattering = imageLoad(uMaterials, base + 9);
  // The albedo and roughness textures' slots lie in t2 and t3, fetched above for eta and k
  // (render_materials.cpp asserts it): no second fetch.
  int albedoTex = floatBitsToInt(t2[kMaterialSlot_albedoTexture % 4]), roughTex = floatBitsToInt(t3[kMaterialSlot_roughnessTexture % 4]);
  if (textured && hasFeature(kFeatureTextures) && albedoTex >= 0) m.albedo *= sampleTexture(albedoTex, uv).rgb;
  if (textured && hasFeature(kFeatureRoughnessTextures) && roughTex >= 0) {
    float scale = dot(sampleTexture(roughTex, uv).rgb, vec3(1.0 / 3.0));
    if (isMat(m.type, kMatThinSheet)) {
      // A thin sheet's texture is its thickness (Material::roughnessTexture): its absorption
      // straight across and its film (in the roughness slot; 0, none) grow with it.
      scale = max(scale, 0.0);
      m.roughness *= scale;
      m.coating *= scale;
    } else {
      m.roughness = max(m.roughness * scale, 1e-3);
    }
  }
  if (hasFeature(kFeatureBlend)) m.emission = imageLoad(uMaterials, index * kMaterialTexels + 4).rgb;
  if (hasFeature(kFeatureEmissionTextures)) {
    int emissionTex = RT_MATERIAL_TEXTURE(index, emissionTexture);
    if (emissionTex >= 0) m.emission *= sampleTexture(emissionTex, uv).rgb;
  }
  return m;
}

// Offsets a ray origin off the surface by a few float ulps along n (Waechter and Binder,
// Ray Tracing Gems ch. 6): robust at any distance from the origin, no scene-scale epsilon.
// With RayOffset::FixedEpsilon a ray leaves from the point itself, as Tungsten's do, and only
// skips kFixedRayEpsilon along its direction (surfaceSkip): 256 ulps are 0.06 mm three units from
// the origin, and a grazing light sample lifted by them passes or meets geometry that close
// otherwise than Tungsten's (the kitchen's window frame, lit edge-on, comes out 4 to 6 % dark).
vec3 offsetRay(vec3 p, vec3 n) {
  if (hasFeature(kFeatureFixedEpsilon)) return p;
  const float origin = 1.0 / 32.0, floatScale = 1.0 / 65536.0, intScale = 256.0;
  ivec3 oi = ivec3(intScale * n);
  vec3 pi = vec3(intBitsToFloat(floatBitsToInt(p.x) + (p.x < 0.0 ? -oi.x : oi.x)),
                 intBitsToFloat(floatBitsToInt(p.y) + (p.y < 0.0 ? -oi.y : oi.y)),
                 intBitsToFloat(floatBitsToInt(p.z) + (p.z < 0.0 ? -oi.z : oi.z)));
  return vec3(abs(p.x) < origin ? p.x + floatScale * n.x : pi.x,
              abs(p.y) < origin ? p.y + floatScale * n.y : pi.y,
              abs(p.z) < origin ? p.z + floatScale * n.z : pi.z);
}

// How far along a ray that leaves a surface it starts: with RayOffset::FixedEpsilon it skips what
// lies within kFixedRayEpsilon, so light leaks through cracks narrower than that and contact
// shadows closer than that vanish, as in Tungsten. The skipped piece of a medium
// is not counted on a path's own segment (at most 5e-4 of its optical depth per unit extinction).
float surfaceSkip() { return hasFeature(kFeatureFixedEpsilon) ? kFixedRayEpsilon : 0.0; }

// The work item that holds `slot`. Every lane runs it in every pass, for a slot of its own or
// any, with the same number of iterations (enough for the longest search), so that the lanes'
// loop counts stay equal without a synchronisation (a loop over the lanes on lavapipe; see
// loopIterations in scene.glsl).
int findItem(uint slot) {
  int n = int(frame.work.x);
  int steps = n > 1 ? findMSB(n - 1) + 1 : 0;  // each step leaves at most half the range, rounded up
  int lo = 0, hi = n - 1;
  for (int k = 0; k < steps; ++k) {
    loopIterations++;
    int mid = (lo + hi + 1) >> 1;
    bool right = items[mid].info.y <= slot;
    lo = lo < hi && right ? mid : lo;
    hi = lo < hi && !right ? mid - 1 : hi;
  }
  return lo;
}

// One path's state between segments. An invocation carries one path at a time and starts the
// next of its slots as soon as the current path ends (path regeneration): lavapipe runs a
// subgroup's invocations in lock-step, and without regeneration the lanes whose paths ended early would
// idle until the longest of them had finished (a third of the lanes in the Cornell box).
struct Path {
  uint slot;
  Rng rng;
  vec3 ro, rd;
  ivec2 from;  // the triangle (prim, instance) ro is on, which the ray cannot hit; -1 for none
  vec3 L, beta;
  float etaScale;
  bool specular;  // the last bounce was a delta lobe (the camera ray counts as one)
  float prevPdf;
  vec3 prevPos;
  float prevGroupTotal;  // lightGroupTotal (lights.glsl) at prevPos, -1 if not known
  int depth;
  int selBase;
  // Denoiser guides from the first hit that is not a mirror or glass (guideLooksThrough: so
  // reflections and what is seen through glass keep their own edges): its albedo times the
  // throughput of the chain before it, its normal, the distance along the path to it, and the
  // emission the path collects up to it (the denoiser filters the rest and adds it back, so a
  // light's edge stays exact). An emitter that does not reflect is such a hit too, and so is a
  // point where the path scatters in a medium (scatterInMedium). The object id is the first
  // hit's (picking).
  vec3 auxAlbedo, auxNormal, auxEmission;
  float auxDepth;  // kInfinity until that hit
  float travelled; // distance along the path so far
  int auxInstance;
#if RETILE_MEDIUM
  // Of the medium the path is in (inside filled glass or a boundary, else 0): absorption and
  // scattering per unit of length, and the phase function's asymmetry in scattering.w. And the
  // same of the medium around that one, which the path goes back to when it leaves (crossMedium).
  vec3 absorption, outerAbsorption;
  vec4 scattering, outerScattering;
  bool inGlass, outerInGlass;  // whether those are glass's (which blocks shadow rays)
#endif
};

// The shadow ray of a path vertex's next-event estimation. It is traced with the next segment's
// extension ray, in one loop (Trace): the path's own next segment, or, when the path ended at
// that vertex, the first segment of the path the invocation starts next, so that no segment is
// spent on it alone (a segment costs the shading code for all of a subgroup's lanes).
struct Shadow {
  bool pending;
  vec3 origin, dir;
  ivec2 from;  // as Path::from
  float tMax, random;
  vec3 L;      // what it adds when nothing blocks it
  bool ended;  // its path has ended: its sample is then rewritten as full when nothing blocks it
  uint slot;
  vec3 full;   // its ended path's sample without it
  int selBase;
#if RETILE_BOUNDARY
  // It may cross boundaries into other media, so the way through them is counted once it is
  // traced (resolveShadow): the extinction of the medium it starts in, and the light's distance.
  vec3 sigma;
  float dist;
#endif
#if RETILE_SHEET || RETILE_BOUNDARY
  int depth;  // its path's bounces where it was cast: each sheet or boundary it passes is one more
#endif
};

// Path::auxInstance once the path has scattered in a medium it did not enter by a boundary
// before any hit: no object is what the pixel shows (writeSample writes 0).
const int kPickedNothing = 0x7fffffff;

uint primaryRays = 0u, bounceRays = 0u, shadowRays = 0u;
// The paths that ended each way (FrameStats::PathEnd): they left the scene, met an emitter that
// does not reflect, reached the bounce limit, lost at roulette.
uint pathsLeft = 0u, pathsAtEmitters = 0u, pathsAtLimit = 0u, pathsByRoulette = 0u;

// `found`: findItem(slot).
Path startPath(uint slot, int found) {
  WorkItem item = items[found];
  uint inItem = slot - item.info.y;
  uint p = quotient(inItem, item.info.x);  // a pixel's (a block's) q samples are neighbours (layouts.h WorkItem)
  uint rep = inItem - p * item.info.x;
  uint block = max(item.pixels.z, 1u);
  uint cols = quotient(uint(item.rect.z) + block - 1u, block), row = quotient(p, cols);
  int px = item.rect.x + int((p - row * cols) * block);
  int py = item.rect.y + int(row * block);
  uint width = frame.image.x, height = frame.image.y;
  Path path;
  path.slot = slot;
  path.rng = rngInit(uint(py) * width + uint(px), item.info.z + rep, frame.image.z);

  // Every sample jitters its own primary ray, evenly over the pixel's samples, then is placed by
  // the scene's pixel filter (its inverse CDF per axis): filter importance sampling, so the
  // accumulation stays a plain mean per pixel. A coarse item's sample lands anywhere in its block
  // (the part of it inside the item), which all the block's pixels then share.
  vec2 jitter = pixelJitter(uint(py) * width + uint(px), item.info.z + rep, frame.image.z);
  vec2 offset = vec2(filterOffset(jitter.x), filterOffset(jitter.y));
  vec2 at = vec2(0.5);
  if (block > 1u) {
    vec2 extent = vec2(min(int(block), item.rect.x + item.rect.z - px), min(int(block), item.rect.y + item.rect.w - py));
    at = vec2(rand(path.rng), rand(path.rng)) * extent;
  }
  vec2 ndc = vec2((float(px) + at.x + offset.x) / float(width), (float(py) + at.y + offset.y) / float(height)) * 2.0 - 1.0;
  float tanHalf = frame.cameraPosition.w;
  path.rd = normalize(frame.cameraForward.xyz + ndc.x * tanHalf * frame.cameraRight.w * frame.cameraRight.xyz -
                      ndc.y * tanHalf * frame.cameraUp.xyz);
  path.ro = frame.cameraPosition.xyz;
  path.from = ivec2(-1);
  float aperture = frame.cameraUp.w;
  if (aperture > 0.0) {
    // A thin lens: the ray leaves a point of the lens disc (uniform over its area) for the point
    // where the pinhole ray meets the plane in focus. A pinhole draws no numbers for it, so its
    // samples stay what they were.
    vec3 focus = path.ro + path.rd * (frame.cameraForward.w / dot(path.rd, frame.cameraForward.xyz));
    float r = aperture * sqrt(rand(path.rng)), phi = 6.2831853 * rand(path.rng);
    path.ro += r * (cos(phi) * frame.cameraRight.xyz + sin(phi) * frame.cameraUp.xyz);
    path.rd = normalize(focus - path.ro);
  }
  path.L = vec3(0.0);
  path.beta = vec3(1.0);
  path.etaScale = 1.0;
#if RETILE_MEDIUM
  path.absorption = frame.cameraAbsorption.xyz;
  path.scattering = frame.cameraScattering;
  path.outerAbsorption = frame.cameraOuterAbsorption.xyz;
  path.outerScattering = frame.cameraOuterScattering;
  path.inGlass = frame.cameraAbsorption.w > 0.0;
  path.outerInGlass = frame.cameraOuterAbsorption.w > 0.0;
#endif
  path.specular = true;
  path.prevPdf = 0.0;
  path.prevPos = path.ro;
  path.prevGroupTotal = -1.0;
  path.depth = 0;
  path.selBase = hasFeature(kFeatureSelectionCounts) ? selectionBase(px, py) : -1;
  path.auxAlbedo = vec3(0.0);
  path.auxNormal = vec3(0.0);
  path.auxEmission = vec3(0.0);
  path.auxDepth = kInfinity;
  path.travelled = 0.0;
  path.auxInstance = 0;
  return path;
}

// The shading normal ns tilted by a bump map's slope (textureSlope, times the strength), as
// Tungsten tilts it (Primitive::setupTangentFrame): the triangle's unit tangents along u and v
// (q1, q2 its edges, duv1, duv2 theirs in uv) take the slope as their component along ns, and
// their cross product is the new normal, on ns's side. Unchanged where the uvs are degenerate.
vec3 bumpNormal(vec3 ns, vec3 q1, vec3 q2, vec2 duv1, vec2 duv2, vec2 slope) {
  if (abs(duv1.x * duv2.y - duv2.x * duv1.y) < 1e-6) return ns;
  vec3 t = q1 * duv2.y - duv1.y * q2, b = q2 * duv1.x - duv2.x * q1;
  if (!(dot(t, t) > 0.0) || !(dot(b, b) > 0.0)) return ns;  // NaN too
  t = normalize(t);
  b = normalize(b);
  t += ns * (slope.x - dot(ns, t));
  b += ns * (slope.y - dot(ns, b));
  vec3 n = cross(t, b);
  if (!(dot(n, n) > 0.0)) return ns;
  return dot(n, ns) < 0.0 ? -normalize(n) : normalize(n);
}

// The shading normal ns tilted by material `material`'s bump map, if it has one, at uv on the
// triangle of object-space edges e1, e2 and shading texels s0..s3, in the instance whose
// world-to-object rows are r0..r2.
// The triangle's object-space edges e1, e2 in world space (q1, q2), through the inverse of the
// instance's world-to-object rows r0..r2 (by cofactors), and theirs in uv (shading texels s0..s3).
void worldEdges(vec4 r0, vec4 r1, vec4 r2, vec3 e1, vec3 e2, vec4 s0, vec4 s1, vec4 s2, vec4 s3, out vec3 q1, out vec3 q2,
                out vec2 duv1, out vec2 duv2) {
  vec3 c0 = cross(r1.xyz, r2.xyz), c1 = cross(r2.xyz, r0.xyz), c2 = cross(r0.xyz, r1.xyz);
  float det = dot(r0.xyz, c0);
  q1 = (c0 * e1.x + c1 * e1.y + c2 * e1.z) / det;
  q2 = (c0 * e2.x + c1 * e2.y + c2 * e2.z) / det;
  duv1 = vec2(s2.w, s3.x) - vec2(s0.w, s1.w);
  duv2 = s3.yz - vec2(s0.w, s1.w);
}

vec3 bumped(vec3 ns, int material, vec4 r0, vec4 r1, vec4 r2, vec3 e1, vec3 e2, vec4 s0, vec4 s1, vec4 s2, vec4 s3, vec2 uv) {
  if (!hasFeature(kFeatureBump)) return ns;
  int bumpTex = RT_MATERIAL_TEXTURE(material, bumpTexture);
  if (bumpTex < 0) return ns;
  vec3 q1, q2;
  vec2 duv1, duv2;
  worldEdges(r0, r1, r2, e1, e2, s0, s1, s2, s3, q1, q2, duv1, duv2);
  return bumpNormal(ns, q1, q2, duv1, duv2, RT_MATERIAL_SCALAR(material, bumpStrength) * textureSlope(bumpTex, uv));
}

#if RETILE_SHEET && RETILE_ALPHA_TEST
// Whether the shadow ray paused on a candidate hit (trace's pendingPrim and on) passes it as a
// thin sheet, as Tungsten's shadow rays pass its thin sheet (a forward lobe): then dimmed by what
// the sheet lets through along the ray (thinSheetTransmittance, at the shading normal's angle,
// as a path that passes it is). So a light behind a window is sampled through it, a point light
// too, which no path could reach; and the path that passes a sheet keeps the light sample's MIS
// (shadeSegment). Past the traversal loop, once a round.
bool sheetPasses(inout Trace tr) {
  int ibase = tr.pendingInstance * kInstanceTexels;
  int prim = tr.pendingPrim;
  float u = tr.pendingU, v = tr.pendingV, w = 1.0 - u - v;
  int material = floatBitsToInt(imageLoad(uInstances, ibase + 3).z);
  vec4 s0 = imageLoad(uTriShade, prim * kTriShadeTexels), s1 = imageLoad(uTriShade, prim * kTriShadeTexels + 1);
  vec4 s2 = imageLoad(uTriShade, prim * kTriShadeTexels + 2), s3 = imageLoad(uTriShade, prim * kTriShadeTexels + 3);
  vec2 uv = w * vec2(s0.w, s1.w) + u * vec2(s2.w, s3.x) + v * s3.yz;
  // A number of each sheet's own for a blend's choice, as a path draws one at each hit: one for
  // every sheet along the ray would make the same choice at each.
  Material m = fetchMaterial(material, uv, hitRandom(tr.rayRandom, prim, 2246822519u), hasFeature(kFeatureSheetTextures));
  if (!isMat(m.type, kMatThinSheet)) return false;
  // The normal as shadeSegment shades with: interpolated, bumped.
  vec4 r0 = imageLoad(uInstances, ibase), r1 = imageLoad(uInstances, ibase + 1), r2 = imageLoad(uInstances, ibase + 2);
  vec3 e1 = imageLoad(uTraversal, prim * kTriTexels + 1).xyz, e2 = imageLoad(uTraversal, prim * kTriTexels + 2).xyz;
  vec3 nObj = cross(e1, e2);
  vec3 ng = normalize(r0.xyz * nObj.x + r1.xyz * nObj.y + r2.xyz * nObj.z), ns = ng;
  if (s3.w > 0.5) {
    nObj = w * s0.xyz + u * s1.xyz + v * s2.xyz;
    vec3 n = r0.xyz * nObj.x + r1.xyz * nObj.y + r2.xyz * nObj.z;
    if (dot(n, n) > 0.0) {
      ns = normalize(n);
      if (!hasFeature(kFeatureUncheckedShading) && dot(ns, ng) < 0.0) ns = -ns;
    }
  }
  if (hasFeature(kFeatureSheetTextures)) ns = bumped(ns, material, r0, r1, r2, e1, e2, s0, s1, s2, s3, uv);
  vec3 R;
  tr.shadowWeight *= thinSheetTransmittance(m, abs(dot(ns, tr.dir)), R);
  tr.passed++;
  return true;
}
#endif

#if RETILE_ALPHA_TEST
// With the fixed ray offset (RayOffset::FixedEpsilon): the cut-out (or, for a shadow ray, thin
// sheet) a lane's ray segment paused on at its end (Trace::hitForward), decided `solid` or
// passed. Solid, the ray ends there (a shadow ray blocked), as traceStep ends one; passed, it is
// a forward event, as in Tungsten: the ray is traced again from the root, from tNear,
// kFixedRayEpsilon past the point it passed, as a ray leaves a surface; so it skips what lies
// within that of it (the blinds' second face) and meets what lies beyond in turn. Past the
// traversal loop, once a round.
void resolveForward(inout Trace tr, bool solid, int root) {
  if (solid && tr.onShadow) tr.blocker = tr.pendingInstance;
  if (solid && (tr.onShadow || !tr.second)) {
    tr.done = true;
    tr.onShadow = true;
    tr.tMax2 = -1.0;
  } else if (solid) {
    // The extension ray's hit stands: its shadow ray follows, from its own origin.
    tr.onShadow = true;
    tr.origin = tr.origin2;
    tr.dir = tr.dir2;
    tr.invDir = tr.invDir2;
    tr.rayRandom = tr.random2;
    tr.from = tr.from2;
    tr.tNear = 0.0;
  } else {
    tr.tNear = (tr.onShadow ? tr.forwardT : tr.hit.t) + kFixedRayEpsilon;
    if (!tr.onShadow) {
      // The extension ray looks for its closest hit again, past that.
      tr.hit.t = kInfinity;
      tr.hit.prim = -1;
      tr.hit.instance = -1;
    }
  }
  tr.hitForward = false;
  tr.forwardT = kInfinity;
#if RETILE_BOUNDARY
  tr.forwardCrossing = 0;
#endif
  tr.item = root;
  tr.stackSize = 0;
  tr.o = tr.origin;
  tr.d = tr.dir;
  tr.invD = tr.invDir;
  tr.instance = -1;
  tr.instanceSp = -1;
}
#endif

// Surfaces whose reflection or refraction shows other objects' edges: mirrors, smooth glass and
// metal, and their nearly smooth rough kinds. The denoiser's guides look through them.
bool guideLooksThrough(Material m) {
  bool nearlySmooth = (isMat(m.type, kMatRoughConductor) || isMat(m.type, kMatRoughDielectric)) && m.roughness < 0.1;
  return (isDeltaMaterial(m) && !isMat(m.type, kMatNull)) || nearlySmooth;
}

// Writes the path's sample and first-hit outputs to its slot, weighted 1 once it has ended. A
// non-finite sample is traced (it counts against the budget) but weighted 0, so one bad path
// cannot poison a pixel's sum; the accumulator counts only weighted samples.
void writeSample(Path path, bool ended) {
  bool valid = !(any(isnan(path.L)) || any(isinf(path.L)));
  samples[path.slot] = valid ? vec4(path.L, ended ? 1.0 : 0.0) : vec4(0.0);
  aux[path.slot * kAuxVec4s] = vec4(path.auxAlbedo, path.auxDepth);
  int picked = abs(path.auxInstance);
  aux[path.slot * kAuxVec4s + 1u] = vec4(path.auxNormal, intBitsToFloat(picked == kPickedNothing ? 0 : picked));
  aux[path.slot * kAuxVec4s + 2u] = vec4(path.auxEmission, 0.0);
}

// The path has no next direction: a pending shadow ray goes on with the next path.
bool endPath(Path path, inout Shadow shadow) {
  shadow.ended = true;
  shadow.slot = path.slot;
  shadow.full = path.L;
  return false;
}

// A shadow ray traced (by `tr`, whose blocker is the instance that blocks it, -1 when nothing
// does): its path's light, or its ended path's sample rewritten.
void resolveShadow(inout Path path, inout Shadow shadow, Trace tr) {
  int blocker = tr.blocker;
  if (!shadow.pending) return;
  shadowRays++;
  if (hasFeature(kFeatureSelectionCounts) && shadow.selBase >= 0 && blocker >= 0) {
    uint sets = countedSets(blocker);
    for (int k = 0; k < kCountedSets; ++k)
      if ((sets & (1u << k)) != 0u) atomicAdd(selectionCounts[shadow.selBase + 3 * k + 2], 1u);
  }
  bool visible = blocker < 0;
  vec3 L = shadow.L;
#if RETILE_SHEET
  L *= tr.shadowWeight;  // dimmed by the thin sheets it passed
#endif
#if RETILE_SHEET || RETILE_BOUNDARY
  // Each sheet or boundary it passed is a bounce, as for a path that passes it (shadeSegment):
  // past the last bounce no path reaches the light that way, and neither does the light sample,
  // whose MIS weight counts on that path.
  visible = visible && shadow.depth + tr.passed < int(frame.image.w);
  // Its light arrives in one bounce more than its path's vertex has, and one for each of those.
  if (hasFeature(kFeatureMinBounces)) visible = visible && shadow.depth + 1 + tr.passed >= frame.bounces.x;
#endif
#if RETILE_BOUNDARY
  // Its optical depth through the media it ran in (Trace::crossedSigma). A negative one only
  // comes of boundaries that do not close, or of nested ones, whose media the path replaces and
  // the sum adds (the importer warns of those).
  vec3 sigma = shadow.sigma + tr.crossedSigma;
  vec3 depth = tr.crossedDepth;
  if (shadow.dist >= kInfinity) {
    // To a light at infinity, the medium the ray ends in must be none: up to rounding, none is
    // left of the boundaries' (whose crossings count relative to the world's medium), and the
    // world, where every such ray ends, has none either, however thin.
    float rounding = 1e-5 * (maxComponent(shadow.sigma) + tr.crossedScale);
    vec3 world = frame.worldAbsorption.xyz + frame.worldScattering.rgb;
    depth += kInfinity * max(vec3(greaterThan(sigma, vec3(rounding))), vec3(greaterThan(world, vec3(0.0))));
  } else {
    depth += sigma * shadow.dist;
  }
  L *= exp(-max(depth, vec3(0.0)));
#endif
  // An ended path's sample was written when it ended (the lane may have started another since).
  if (visible && !shadow.ended) path.L += L;
  vec3 full = shadow.full + L;
  bool valid = !(any(isnan(full)) || any(isinf(full)));
  if (visible && shadow.ended) samples[shadow.slot] = valid ? vec4(full, 1.0) : vec4(0.0);
  shadow.pending = false;
}

// Russian roulette after a few bounces, keeping the expected value (Roulette, scene.h). Returns
// false when the path has ended.
bool survivesRoulette(inout Path path, inout Shadow shadow) {
  if (path.depth > 3) {
    float m = maxComponent(path.beta * path.etaScale);
    float q = hasFeature(kFeatureLowThroughputRoulette) ? (m < 0.1 ? 1.0 - m : 0.0) : max(0.05, 1.0 - m);
    if (rand(path.rng) < q) {
      pathsByRoulette++;
      return endPath(path, shadow);
    }
    path.beta /= 1.0 - q;
  }
  return true;
}

#if RETILE_MEDIUM
// What a ray keeps over `dist` through a medium of extinction sigmaT (nothing, to a light at
// infinity, in the channels where the medium has any).
vec3 transmittance(vec3 sigmaT, float dist) {
  return dist >= kInfinity ? vec3(lessThanEqual(sigmaT, vec3(0.0))) : exp(-sigmaT * dist);
}
#endif

// Sets off the shadow ray of a next-event estimate from `origin` (on triangle `from`, or -1) in a
// medium of extinction sigmaT to the light sample, adding L, dimmed by the media on its way, when
// nothing blocks it; traced with the path's next segment.
// `skip`: how far along the ray from the light sample's point the origin is (surfaceSkip).
void castShadow(inout Shadow shadow, inout Path path, vec3 origin, float skip, ivec2 from, LightSample ls, vec3 L, vec3 sigmaT) {
#if !(RETILE_SHEET || RETILE_BOUNDARY)
  // Its light arrives in one bounce more than the path has taken: too few, and it is not traced.
  // (Past sheets and boundaries, each one more: resolveShadow decides.)
  if (hasFeature(kFeatureMinBounces) && path.depth + 1 < frame.bounces.x) return;
#endif
#if RETILE_BOUNDARY
  shadow.sigma = sigmaT;
  shadow.dist = ls.dist;
#elif RETILE_MEDIUM
  L *= transmittance(sigmaT, ls.dist);
#endif
  shadow.origin = origin + ls.dir * skip;
  shadow.from = from;
  shadow.dir = ls.dir;
  shadow.tMax = ls.dist >= kInfinity ? kInfinity : ls.dist * (1.0 - 1e-4) - skip;
  shadow.random = rand(path.rng);
  shadow.L = L;
  shadow.ended = false;
  shadow.selBase = path.selBase;
  shadow.pending = true;
#if RETILE_SHEET || RETILE_BOUNDARY
  shadow.depth = path.depth;
#endif
}

#if RETILE_MEDIUM
// Through glass or a boundary (Material::holdsMedium) the path enters its medium across the front,
// the one it was in becoming the one around, and goes back to that one across the back. Around
// that, which a path does not remember, is taken to be the world's medium.
void crossMedium(inout Path path, Material m, bool frontFace) {
  if (frontFace) {
    path.outerAbsorption = path.absorption;
    path.outerScattering = path.scattering;
    path.outerInGlass = path.inGlass;
    path.absorption = m.interior;
    path.scattering = m.scattering;
    path.inGlass = !isMat(m.type, kMatBoundary);
  } else {
    path.absorption = path.outerAbsorption;
    path.scattering = path.outerScattering;
    path.inGlass = path.outerInGlass;
    path.outerAbsorption = frame.worldAbsorption.xyz;
    path.outerScattering = frame.worldScattering;
    path.outerInGlass = false;
  }
}

// The path scatters in its medium (of extinction sigmaT) `flight` along its ray, short of its
// hit at hitT. As at a surface, a light is sampled (its shadow ray dimmed by the media on its
// way; glass round the medium blocks light from outside, as in Tungsten, a boundary does not)
// and weighed against the phase function, which then gives the next direction. A scattering
// event is a bounce, as in Tungsten. Returns false when the path has ended.
bool scatterInMedium(inout Path path, inout Shadow shadow, float flight, float hitT, vec3 sigmaT) {
  vec3 crossed = exp(-sigmaT * flight);
  float pdf = dot(sigmaT * crossed, vec3(1.0 / 3.0));
  path.travelled += flight;
  // The medium's boundary, if the path came in by one; else (the camera's or the world's medium)
  // nothing: what the path meets after scattering is not what the pixel shows.
  path.auxInstance = path.auxInstance == 0 ? kPickedNothing : abs(path.auxInstance);
  if (path.auxDepth >= kInfinity) {
    // The denoiser's guide: the medium's albedo where the path first scatters, facing back.
    path.auxAlbedo = path.beta * path.scattering.rgb / max(sigmaT, vec3(1e-30));
    path.auxNormal = -path.rd;
    path.auxDepth = path.travelled;
  }
  path.beta *= pdf > 0.0 ? path.scattering.rgb * crossed / pdf : vec3(0.0);
  if (path.depth >= int(frame.image.w)) {
    pathsAtLimit++;
    return false;
  }
  if (!(maxComponent(path.beta) > 0.0)) return false;
  // Kept short of the surface, so that rounding cannot put the point on its far side.
  vec3 pos = path.ro + min(flight, hitT * 0.99999) * path.rd;
  float g = path.scattering.w;
  // Inside glass with no light in it, a light sample's shadow ray could only meet the glass,
  // which blocks it, so none is cast; and the next direction meets no light before the glass, so
  // no hit needs the weight the sample would have shared.
  bool blockedByGlass = path.inGlass && frame.worldAbsorption.w > 0.0;
  lightGroupTotal = -1.0;
  if ((frame.lightPick.x + frame.lightPick.y + frame.lightPick.z) > 0.0 && !blockedByGlass) {
    vec3 lu = vec3(rand(path.rng), rand(path.rng), rand(path.rng));
    LightSample ls = sampleLight(pos, lu);
    if (ls.pdf > 0.0 && maxComponent(ls.radiance) > 0.0) {
      float phase = henyeyGreenstein(dot(path.rd, ls.dir), g);
      float w = ls.delta ? 1.0 : powerHeuristic(ls.pdf, phase);
      castShadow(shadow, path, pos, 0.0, ivec2(-1), ls, path.beta * phase * ls.radiance * (w / ls.pdf), sigmaT);
    }
  }
  vec3 next = sampleHenyeyGreenstein(path.rd, g, vec2(rand(path.rng), rand(path.rng)));
  path.prevPdf = henyeyGreenstein(dot(path.rd, next), g);
  path.rd = next;
  path.ro = pos;
  path.from = ivec2(-1);
  path.specular = false;
  path.prevPos = pos;
  path.prevGroupTotal = lightGroupTotal;
  path.depth++;
  return survivesRoulette(path, shadow);
}
#endif

// Shades the hit of the path's last segment (its ray from path.ro along path.rd): emission,
// next-event estimation (its shadow ray is traced with the next segment) and the next direction.
// Returns false when the path has ended.
bool shadeSegment(inout Path path, inout Shadow shadow, Hit hit) {
  int maxBounces = int(frame.image.w);
  vec3 ro = path.ro, rd = path.rd;
  if (path.depth == 0) primaryRays++; else bounceRays++;
  // The segment's way through the medium it ran in; a ray that leaves the scene from inside one
  // (glass not closed) is absorbed on its infinite way. In a medium that scatters, the path may
  // scatter before the hit, which it then does not reach.
#if RETILE_MEDIUM
  if (kScatteringUsed && maxComponent(path.scattering.rgb) > 0.0) {
    // Tungsten's free flight (HomogeneousMedium::sampleDistance): a distance drawn for one
    // channel, picked evenly, and weighted by the three channels' mean pdf, so that every
    // channel's estimate is unbiased whatever its own extinction.
    vec3 sigmaT = path.absorption + path.scattering.rgb;
    float sigmaC = sigmaT[min(int(rand(path.rng) * 3.0), 2)];
    float u = rand(path.rng);
    float flight = sigmaC > 0.0 ? -log(1.0 - u) / sigmaC : kInfinity;
    if (flight < hit.t) return scatterInMedium(path, shadow, flight, hit.t, sigmaT);
    vec3 crossed = transmittance(sigmaT, hit.t);  // a miss's t is kInfinity
    float pdf = dot(crossed, vec3(1.0 / 3.0));
    path.beta *= pdf > 0.0 ? crossed / pdf : vec3(0.0);
  } else {
    path.beta *= transmittance(path.absorption, hit.t);
  }
#endif
  if (hasFeature(kFeatureSelectionCounts) && path.selBase >= 0 && hit.prim >= 0) {
    // Direct hits (through boundaries too: nothing is picked yet), then reflections weighted
    // (maxBounces + 1) / depth: 4, 2, 1 at 3 bounces.
    uint sets = countedSets(hit.instance);
    for (int k = 0; k < kCountedSets; ++k) {
      if ((sets & (1u << k)) == 0u) continue;
      if (path.auxInstance <= 0) atomicAdd(selectionCounts[path.selBase + 3 * k], 1u);
      else atomicAdd(selectionCounts[path.selBase + 3 * k + 1], uint(max(maxBounces + 1, 1) / path.depth));
    }
  }

  // Light that reaches the camera in fewer bounces than frame.bounces.x is left out (Tungsten's
  // min_bounces): the sky and the emitters this segment finds, the light samples of vertices before.
  bool counts = !hasFeature(kFeatureMinBounces) || path.depth >= frame.bounces.x;
  if (hit.prim < 0) {
    pathsLeft++;
    if (!counts) return false;
    vec3 Le = envRadiance(rd);
    vec3 added = path.beta * Le;
    if (!path.specular) added *= powerHeuristic(path.prevPdf, frame.lightPick.y * envPdf(rd));
    if (hasFeature(kFeatureSun)) added += path.beta * sunsSeen(rd, path.specular, path.prevPdf);
    path.L += added;
    // The sky seen directly or through mirrors and glass is emission to the denoiser, like a light.
    if (path.auxDepth >= kInfinity) path.auxEmission += added;
    return false;
  }

  int ibase = hit.instance * kInstanceTexels;
  // Without instance transforms every instance's rows are the identity's: three reads fewer.
  vec4 r0 = vec4(1.0, 0.0, 0.0, 0.0), r1 = vec4(0.0, 1.0, 0.0, 0.0), r2 = vec4(0.0, 0.0, 1.0, 0.0);
  if (hasFeature(kFeatureInstanceTransforms)) {
    r0 = imageLoad(uInstances, ibase);
    r1 = imageLoad(uInstances, ibase + 1);
    r2 = imageLoad(uInstances, ibase + 2);
  }
  vec4 info = imageLoad(uInstances, ibase + 3);
  vec4 info2 = imageLoad(uInstances, ibase + 4);
  int instFlags = floatBitsToInt(info2.y);
  vec3 pos = ro + hit.t * rd;

  // Normals go to world space with the inverse transpose, i.e. the transposed world-to-object rows.
  vec3 e1 = imageLoad(uTraversal, hit.prim * kTriTexels + 1).xyz;
  vec3 e2 = imageLoad(uTraversal, hit.prim * kTriTexels + 2).xyz;
  vec3 ngObj = cross(e1, e2);
  vec3 ng = normalize(r0.xyz * ngObj.x + r1.xyz * ngObj.y + r2.xyz * ngObj.z);
  vec4 s0 = imageLoad(uTriShade, hit.prim * kTriShadeTexels + 0);
  vec4 s1 = imageLoad(uTriShade, hit.prim * kTriShadeTexels + 1);
  vec4 s2 = imageLoad(uTriShade, hit.prim * kTriShadeTexels + 2);
  vec4 s3 = imageLoad(uTriShade, hit.prim * kTriShadeTexels + 3);
  float bw = 1.0 - hit.u - hit.v;
  vec2 uv = bw * vec2(s0.w, s1.w) + hit.u * vec2(s2.w, s3.x) + hit.v * s3.yz;
  vec3 ns = ng;
  if (s3.w > 0.5) {
    vec3 nObj = bw * s0.xyz + hit.u * s1.xyz + hit.v * s2.xyz;
    vec3 n = r0.xyz * nObj.x + r1.xyz * nObj.y + r2.xyz * nObj.z;
    if (dot(n, n) > 0.0) {
      ns = normalize(n);
      // Shading normals from files may disagree with the winding; the winding decides the front
      // (unchecked, the shading normal is taken as it is).
      if (!hasFeature(kFeatureUncheckedShading) && dot(ns, ng) < 0.0) ns = -ns;
    }
  }
  ns = bumped(ns, floatBitsToInt(info.z), r0, r1, r2, e1, e2, s0, s1, s2, s3, uv);

  Material m = fetchMaterial(floatBitsToInt(info.z), uv, hasFeature(kFeatureBlend) ? rand(path.rng) : 0.0, true);
  vec3 wo = -rd;
  bool frontFace = dot(ng, wo) > 0.0;

  bool emits = hasFeature(kFeatureEmitters) && (instFlags & kInstanceEmissive) != 0 && frontFace && counts;
  if (hasFeature(kFeatureEmissionCone) && emits) emits = dot(ng, wo) > emissionConeCos(floatBitsToInt(info.z));
  vec3 emitted = vec3(0.0);
  if (emits) {
    emitted = path.beta * m.emission;
    if (!path.specular) {
      int emitter = floatBitsToInt(info.w) + (hit.prim - floatBitsToInt(info.y));
      emitted *= powerHeuristic(path.prevPdf, emitterPdf(emitter, path.prevPos, pos, dot(ng, wo), path.prevGroupTotal));
    }
    path.L += emitted;
  }

  path.travelled += hit.t;
#if RETILE_BOUNDARY
  if (isMat(m.type, kMatBoundary)) {
    // No surface, only where a medium begins or ends: the path goes straight on, into the medium
    // on the other side, as if nothing had been hit (its last vertex, pdf and lobe stay the
    // MIS's), except that the crossing counts as a bounce, as in Tungsten (TraceBase). Nothing
    // changes its weight, so no roulette here: it would only add noise. One that holds no medium
    // leaves the path in the one it is in (Tungsten's selectMedium keeps it too).
    if (path.depth >= maxBounces) {
      pathsAtLimit++;
      return false;
    }
    if (path.auxInstance <= 0) path.auxInstance = -floatBitsToInt(info2.x);
#if RETILE_MEDIUM
    if (maxComponent(m.interior + m.scattering.rgb) > 0.0) crossMedium(path, m, frontFace);
#endif
    path.ro = offsetRay(pos, frontFace ? -ng : ng) + rd * surfaceSkip();
    path.from = ivec2(hit.prim, hit.instance);
    path.depth++;
    return true;
  }
#endif
  // The object picked at the pixel: the first hit (instance ids start at 1), past boundaries
  // (held negated meanwhile: if the path scatters first or leaves the scene, the last of them).
  if (path.auxInstance <= 0) path.auxInstance = floatBitsToInt(info2.x);
  bool nullMaterial = isMat(m.type, kMatNull);
  if (path.auxDepth >= kInfinity) {
    // Up to and at the guide hit, what the path collects from lights is emission to the denoiser.
    path.auxEmission += emitted;
    if (!guideLooksThrough(m)) {
      path.auxAlbedo = nullMaterial ? vec3(0.0) : path.beta * m.albedo;
      path.auxNormal = frontFace ? ns : -ns;
      path.auxDepth = path.travelled;
    }
  }

  if (nullMaterial) {
    pathsAtEmitters++;
    return false;  // an emitter that does not reflect: the path ends here
  }

  if (path.depth >= maxBounces) {
    pathsAtLimit++;
    return false;
  }

  // Shading frame. Opaque materials are two-sided: flip to the viewer's side, of the true surface
  // (consistent) or of the shading normal (unchecked).
  const bool uncheckedShading = hasFeature(kFeatureUncheckedShading);
  bool transmissive = isTransmissive(m);
  vec3 ngs = ng, nss = ns;
  if (!transmissive && !frontFace) ngs = -ng;
  if (!transmissive && (uncheckedShading ? dot(ns, wo) < 0.0 : !frontFace)) nss = -ns;
  vec3 t, b;
  makeFrame(nss, t, b);
  vec3 woL = toLocal(wo, t, b, nss);
  if (!uncheckedShading && !transmissive && woL.z <= 0.0) {
    // The interpolated normal faces away from the viewer: shade with the geometric one.
    nss = ngs;
    makeFrame(nss, t, b);
    woL = toLocal(wo, t, b, nss);
  }

  if (isMat(m.type, kMatHair)) {
    // The fibre runs along the surface's u, as strands' tubes have it (scene/curves.h): dp/du,
    // from the root towards the tip, which the scales' tilt leans by. Where light meets it
    // across its width is drawn here, once for the light sample and the path's next direction.
    vec3 q1, q2;
    vec2 duv1, duv2;
    worldEdges(r0, r1, r2, e1, e2, s0, s1, s2, s3, q1, q2, duv1, duv2);
    float d = duv1.x * duv2.y - duv2.x * duv1.y;
    vec3 along = toLocal((q1 * duv2.y - q2 * duv1.y) * (d < 0.0 ? -1.0 : 1.0), t, b, nss);
    m.hairT = dot(along, along) > 0.0 ? normalize(along) : vec3(1.0, 0.0, 0.0);
    m.hairH = 2.0 * rand(path.rng) - 1.0;
  }

  // Next-event estimation with multiple importance sampling.
  lightGroupTotal = -1.0;
  if (!isDeltaMaterial(m) && (frame.lightPick.x + frame.lightPick.y + frame.lightPick.z) > 0.0) {
    vec3 lu = vec3(rand(path.rng), rand(path.rng), rand(path.rng));
    LightSample ls = sampleLight(pos, lu);
    if (ls.pdf > 0.0 && maxComponent(ls.radiance) > 0.0) {
      float sideL = dot(ls.dir, ngs);
      bool sameSide = sideL > 0.0;
      if (sameSide || transmissive || uncheckedShading) {
        float bsdfPdf;
        vec3 f = bsdfEval(m, woL, toLocal(ls.dir, t, b, nss), bsdfPdf);
        if (maxComponent(f) > 0.0) {
          float w = ls.delta ? 1.0 : powerHeuristic(ls.pdf, bsdfPdf);
          vec3 L = path.beta * f * ls.radiance * (w / ls.pdf);
          vec3 sigmaT = vec3(0.0);
#if RETILE_MEDIUM
          // The shadow ray runs in the path's medium, or, through glass, in the medium on the
          // glass's other side: its own inside when the path comes from outside, else the one
          // around it.
          sigmaT = path.absorption + path.scattering.rgb;
          if ((isMat(m.type, kMatDielectric) || isMat(m.type, kMatRoughDielectric)) && sideL * dot(wo, ngs) < 0.0)
            sigmaT = frontFace ? m.interior + m.scattering.rgb : path.outerAbsorption + path.outerScattering.rgb;
#endif
          castShadow(shadow, path, offsetRay(pos, sideL > 0.0 ? ngs : -ngs), surfaceSkip(), ivec2(hit.prim, hit.instance), ls, L, sigmaT);
        }
      }
    }
  }

  // Continue the path by sampling the BSDF.
  BsdfSample bs = bsdfSample(m, woL, vec3(rand(path.rng), rand(path.rng), rand(path.rng)));
  if (maxComponent(bs.weight) <= 0.0 || any(isnan(bs.weight))) return endPath(path, shadow);
  vec3 wi = toWorld(bs.wi, t, b, nss);
  float sideI = dot(wi, ngs), sideO = dot(wo, ngs);
  // A reflected direction must leave on the viewer's side of the true surface, a transmitted
  // one on the other side; otherwise the shading normal lied and the path would leak. The
  // viewer's side, not the normal's: inside glass it is the back (comparing with the normal
  // alone ended every path leaving glass, and every reflection inside it: black glass).
  // The unchecked convention has no such check (nor has Tungsten: its enable_consistency_checks
  // is off by default).
  // A fibre scatters to every side of its surface: the tube's far side, culled, lets the path
  // through (Material::Hair).
  if (!uncheckedShading && !isMat(m.type, kMatHair) && (bs.transmitted ? sideI * sideO >= 0.0 : sideI * sideO <= 0.0))
    return endPath(path, shadow);
  path.beta *= bs.weight;
#if RETILE_SHEET
  if (bs.transmitted && isMat(m.type, kMatThinSheet)) {
    // Straight through, a bounce, as a boundary is crossed: the light sample of the vertex before
    // saw through the sheet too (sheetPasses), so that vertex's pdf and lobe stay the MIS's.
    path.ro = offsetRay(pos, sideI > 0.0 ? ngs : -ngs) + wi * surfaceSkip();
    path.from = ivec2(hit.prim, hit.instance);
    path.depth++;
    return survivesRoulette(path, shadow);
  }
#endif
  // Through glass the path enters its medium or leaves it for the one around (crossMedium).
#if RETILE_MEDIUM
  // Which side the path came from is the true surface's (as in Tungsten): a shading normal
  // cannot carry the medium out of its glass.
  if (bs.transmitted && (isMat(m.type, kMatDielectric) || isMat(m.type, kMatRoughDielectric))) crossMedium(path, m, frontFace);
#endif
  // Roulette must not see the 1/eta^2 radiance scaling inside glass as lost energy.
  if (bs.transmitted && !m.tintsReflection && !isMat(m.type, kMatThinSheet) && !isMat(m.type, kMatDiffuseTransmission)) path.etaScale *= woL.z > 0.0 ? m.ior * m.ior : 1.0 / (m.ior * m.ior);
  path.specular = bs.delta;
  path.prevPdf = bs.pdf;
  path.prevPos = pos;
  path.prevGroupTotal = lightGroupTotal;
  path.ro = offsetRay(pos, sideI > 0.0 ? ngs : -ngs) + wi * surfaceSkip();
  path.from = ivec2(hit.prim, hit.instance);
  path.rd = wi;
  path.depth++;
  return survivesRoulette(path, shadow);
}

// How many slots the invocation `i` owns: i, i + invocations, ... below the dispatch's count.
uint ownSlots(uint i) { return i < push.invocations && i < push.slotCount ? quotient(push.slotCount - i + push.invocations - 1u, push.invocations) : 0u; }

void main() {
  frame = frameBuffer;  // see scene.glsl
  uint invocation = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * uint(kTraceWorkgroup) + gl_LocalInvocationID.x;
  // Invocation i is given slots i, i + invocations, ...: neighbouring lanes start on neighbouring
  // slots, a pixel's samples or neighbouring pixels. The lanes of a subgroup (lavapipe's eight or
  // sixteen in lock-step) share theirs: the subgroup's m-th path is the (m / lanes)-th slot of its lane
  // m % lanes, started by whichever lane is free first. Kept each to its own slots, a lane that
  // drew short paths idled at the end until the one with the longest was through (a tenth of the
  // traversal loop's lane steps in the living room, 7 % in the kitchen). Which lane traces a
  // slot changes nothing in its sample. Sharing needs the subgroup's invocations consecutive, as
  // in one-dimensional workgroups on lavapipe and the GPUs we know; elsewhere each lane keeps to
  // its own. Lanes past the last invocation have no slots of their own but take part, in the
  // loop and in the sharing, so that every lane of the subgroup sees every iteration and
  // loopIterations stays exact.
  const uint lane = gl_SubgroupInvocationID;
  const bool sharedSlots = subgroupAll(invocation - lane == subgroupBroadcastFirst(invocation - lane)) &&
                           subgroupMax(invocation) - subgroupMin(invocation) == gl_SubgroupSize - 1u;
  const uint firstLane = sharedSlots ? invocation - lane : invocation;
  // Lanes of the subgroup with slots of their own (none past the last invocation).
  const uint slotLanes = firstLane < push.invocations ? min(sharedSlots ? gl_SubgroupSize : 1u, push.invocations - firstLane) : 0u;
  // Paths the subgroup (or, not shared, the lane) has taken from its slots so far: the same in
  // every lane when shared.
  uint taken = 0u;
  // Until its first path starts, a lane's slot is the spare one past the frame's last (it writes none).
  Path path;
  path.slot = frame.work.y;
  path.L = vec3(0.0);
  path.auxAlbedo = vec3(0.0);
  path.auxNormal = vec3(0.0);
  path.auxEmission = vec3(0.0);
  path.auxDepth = kInfinity;
  path.travelled = 0.0;
  path.auxInstance = 0;
#if RETILE_MEDIUM
  path.absorption = vec3(0.0);
  path.scattering = vec4(0.0);
  path.outerAbsorption = vec3(0.0);
  path.outerScattering = vec4(0.0);
  path.inGlass = false;
  path.outerInGlass = false;
#endif
  bool alive = false;
  Shadow shadow;
  shadow.pending = false;
  // Read once, here (read from the storage buffer in every traversal step, these two cost the
  // spaceship about 10 % of its samples/s; see frame in scene.glsl).
  const int root = frame.scene.x;
  const bool noGeometry = frame.scene.y == 0;
  Trace tr;
  beginTrace(tr, root, false, vec3(0.0), vec3(0.0, 0.0, 1.0), ivec2(-1), 0.0, false, vec3(0.0), vec3(0.0, 0.0, 1.0), ivec2(-1), 0.0, 0.0);
  // The traversal stack: its top entry in Trace::top, the ones below it in this array. lavapipe
  // turns an access to a per-invocation array at a varying index into a loop over the subgroup's lanes
  // with a branch per lane on the lane's mask. So each iteration reads and writes the array once,
  // outside any branch, whatever the step: it reads the entry a pop would bring to the top and
  // writes the top to the slot a push would move it to. That write is harmless when nothing is
  // pushed (the slot is above the array's part of the stack). Outside every branch a lane's mask
  // changes only when its query ends, so the per-lane branches predict well; inside the push
  // branch they mispredicted, and the two accesses took a quarter of the time. Keeping the top
  // eight entries in variables instead cost registers (spilled) and shifts on every push and pop.
  // The last slot takes the spill of a full stack.
  // It is main's own: as a global, the same array cost 8 % of the spaceship's samples/s.
  int stackBelow[kStackSize];
  const uint readyLanes = uint(gl_SubgroupSize) * uint(kTraceReadyLanes) / 16u;
  uint cutPaths = 0u;
  uint maxSegment = 0u;
  bool outOfBudget = false;
  // Every lane's count is the subgroup's here: the last synchronisation of an iteration (after the
  // traversal) is also the first of the next.
  for (;;) {
    loopIterations++;
    // Out of loop budget (the same decision in every lane): paths end as they stand, their rays
    // in flight or not (a shadow ray still to trace is dropped, from an ended path too), and
    // slots not yet started keep the weight 0 the renderer cleared them to.
    outOfBudget = loopIterations > kLoopBudget || loopIterations + 2u * maxSegment > kLoopLimit;
    // The lanes whose rays are done take their hits, shade, and set off their next rays; the
    // others' rays are still in flight (the traversal loop below).
    bool ready = tr.done && !outOfBudget, ended = false;
    if (ready && !tr.idle) {
      resolveShadow(path, shadow, tr);
      ended = alive && !shadeSegment(path, shadow, tr.hit);
      alive = alive && !ended;
    }
    // A path's sample is written once, when it ends or is cut short, from this one call: lavapipe
    // runs a branch's code whether or not a lane takes it, and each of the four stores is a loop
    // over the lanes and over the components. (Written by every lane every iteration, as it was
    // to keep lavapipe's per-lane store branches predictable, they took a tenth of the time.)
    if (ended || (outOfBudget && alive)) writeSample(path, true);
    if (outOfBudget) {
      if (alive) cutPaths++;
      break;
    }
    // Loops only some lanes ran while shading (see loopIterations in scene.glsl). The sky map's
    // searches, in the lanes that sampled it: every lane takes the count. The suns' loop, one
    // iteration a sun, in the lanes whose path missed: every lane counts it, whether or not one
    // ran it, which may count it once too often (paths then stop a little earlier) and costs no
    // synchronisation, a loop over the lanes on lavapipe. After this the lanes' counts are equal,
    // and every other loop of the pass (the work-item search, the traversal) runs the same
    // iterations in every lane.
    if (hasFeature(kFeatureEnvMap)) syncLoopIterations();
    if (hasFeature(kFeatureSun)) loopIterations += uint(frame.lightPick.w);
    // Likewise the light groups' loops, a group an iteration, in the lanes that shaded: at most
    // one light sample's choice and one emitter's pdf without its total.
    if (hasFeature(kFeatureLightGroups)) loopIterations += 2u * uint(frame.bounces.y);
    bool wants = ready && !alive;
    uint m = taken;
    if (sharedSlots) {
      uvec4 asking = subgroupBallot(wants);
      m += subgroupBallotExclusiveBitCount(asking);
      taken += subgroupBallotBitCount(asking);
    } else if (wants) {
      taken++;
    }
    uint round = quotient(m, max(slotLanes, 1u));
    uint slot = slotLanes == 0u ? push.slotCount : firstLane + (m - round * slotLanes) + round * push.invocations;
    bool starts = wants && slot < push.slotCount;
    // Every lane searches, outside any branch, so that every lane counts the search's iterations.
    int found = findItem(push.slotOffset + (starts ? slot : 0u));
    if (starts) {
      path = startPath(push.slotOffset + slot, found);
      alive = true;
    }
    if (ready)
      beginTrace(tr, root, alive, path.ro, path.rd, path.from, alive ? rand(path.rng) : 0.0, shadow.pending, shadow.origin, shadow.dir, shadow.from,
                 shadow.tMax, shadow.random);
    // The loop below ends when no more than this many lanes are still busy: idle lanes are done
    // from the start and never wait, so counting the busy ones is enough.
    uint idleLanes = subgroupBallotBitCount(subgroupBallot(tr.idle));
    if (idleLanes == gl_SubgroupSize) break;
    uint busyAtExit = idleLanes + readyLanes >= gl_SubgroupSize ? 0u : gl_SubgroupSize - readyLanes - idleLanes;
    uint segmentStart = loopIterations;
    // Trace until enough of the lanes are done (kTraceReadyLanes of every sixteen): lavapipe runs a
    // loop as long as its slowest lane, and waiting for all eight left a lane idle more than half
    // the time. The lanes that are done leave with their hits for the shading code above and come
    // back with new rays; the others go on where they stopped. Lanes given nothing (Trace::idle)
    // do not count as waiting, so the last paths of an invocation run to the end. Some lane has a
    // ray here, so the loop has work when it starts.
#if RETILE_ALPHA_TEST || RETILE_BOUNDARY
    // Rounds of the traversal loop: lanes paused on a candidate hit of an alpha-tested triangle
    // (Trace::alphaPending), or on a shadow ray's fifth boundary (crossingPending), count as
    // waiting. Between rounds, outside the loop, where it costs once a round instead of at every
    // step of every lane, they look the alpha up, and every lane counts the boundaries it crossed.
    for (;;) {
#endif
    while (!noGeometry) {
      loopIterations++;
      int below = stackBelow[clamp(tr.stackSize - 2, 0, kStackSize - 1)];  // the top after a pop
      stackBelow[clamp(tr.stackSize - 1, 0, kStackSize - 1)] = tr.top;     // where a push moves the top
      traceStep(tr, below, root);
      // One ballot a step: a subgroup operation is a loop over the lanes on lavapipe, which holds
      // about a tenth of this loop's time (subgroupAdd's loop as much; checking every second
      // step, with the step written twice in the loop, was slower).
      if (subgroupBallotBitCount(subgroupBallot(!tr.done && !TRACE_PAUSED(tr))) <= busyAtExit) break;
    }
#if RETILE_ALPHA_TEST || RETILE_BOUNDARY
#if RETILE_ALPHA_TEST
      if (tr.alphaPending) {
#if RETILE_SHEET
        // Paused on a cut-out, or (a shadow ray) on a thin sheet, or both.
        int flags = floatBitsToInt(imageLoad(uInstances, tr.pendingInstance * kInstanceTexels + 4).y);
        bool solid = (flags & kInstanceAlphaTested) == 0 || alphaPasses(tr.pendingInstance, tr.pendingPrim, tr.pendingU, tr.pendingV, tr.rayRandom);
        if (solid && tr.onShadow && (flags & kInstanceSheet) != 0) solid = !sheetPasses(tr);
#else
        bool solid = alphaPasses(tr.pendingInstance, tr.pendingPrim, tr.pendingU, tr.pendingV, tr.rayRandom);
#endif
#if RETILE_BOUNDARY
        if (tr.forwardCrossing != 0) {
          // A boundary (Trace::forwardCrossing): crossed, counted below (countCrossings).
          solid = false;
          tr.crossingInstance[tr.crossings] = tr.forwardCrossing;
          tr.crossingT[tr.crossings] = tr.forwardT;
          tr.crossings++;
        }
#endif
        if (hasFeature(kFeatureFixedEpsilon)) resolveForward(tr, solid, root);
        else tr.alphaDecision = solid ? 1 : -1;
        tr.alphaPending = false;
      }
#endif
#if RETILE_BOUNDARY
      countCrossings(tr);
#endif
      loopIterations++;  // a round is a loop iteration too (the 65535 of them)
      if (noGeometry || subgroupBallotBitCount(subgroupBallot(!tr.done)) <= busyAtExit) break;
    }
#endif
    if (noGeometry) tr.done = true;  // nothing to hit
    // Every lane ran every iteration of that loop (its exit is the same in all), so the counts,
    // equal before it, still are.
    maxSegment = max(maxSegment, loopIterations - segmentStart);
  }
  if (outOfBudget) {
    // Cut short: the slots not started count too, each lane its own less those taken (all
    // counted once, in the first lane, when shared). Here, after the loop, this costs once an
    // invocation; in it, it cost every round (lavapipe runs a branch no lane takes).
    uint own = lane < slotLanes || !sharedSlots ? ownSlots(firstLane + (sharedSlots ? lane : 0u)) : 0u;
    uint all = sharedSlots ? subgroupAdd(own) : own;
    if (!sharedSlots || subgroupElect()) cutPaths += all - min(taken, all);
  }
  atomicAdd(rayCounts[0], primaryRays);
  atomicAdd(rayCounts[1], bounceRays);
  atomicAdd(rayCounts[2], shadowRays);
  atomicMax(rayCounts[3], loopIterations);
  // Every lane of a subgroup with slots counts: those past the last invocation trace its paths too.
  if (slotLanes > 0u) atomicAdd(rayCounts[5], (loopIterations + kLoopIterationUnit / 2u) / kLoopIterationUnit);
  if (cutPaths > 0u) atomicAdd(rayCounts[4], cutPaths);
  atomicMax(rayCounts[6], maxSegment);
  atomicAdd(rayCounts[kStatsPathEnds], pathsLeft);
  atomicAdd(rayCounts[kStatsPathEnds + 1], pathsAtEmitters);
  atomicAdd(rayCounts[kStatsPathEnds + 2], pathsAtLimit);
  atomicAdd(rayCounts[kStatsPathEnds + 3], pathsByRoulette);
}
