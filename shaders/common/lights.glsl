// Light sources for next-event estimation and MIS: emissive triangles (alias table by power,
// within the light group chosen for the shading point where there are several),
// the environment (constant, or an equirectangular map importance-sampled by luminance) and
// delta lights (point, spot, directional) and suns (directional lights with a disc).
#ifndef RETILE_LIGHTS_GLSL
#define RETILE_LIGHTS_GLSL

#include "common/scene.glsl"

// Equirectangular convention (Tungsten's), in the map's frame: the top row is straight up (+y),
// the centre column looks along +x and u grows towards +z. The map's frame is the world's
// turned by the environment's rotation about +y and its orientation (environmentToMap in
// retile/scene.h).
vec3 envToMap(vec3 d) {
  return vec3(dot(frame.environmentToMap[0].xyz, d), dot(frame.environmentToMap[1].xyz, d), dot(frame.environmentToMap[2].xyz, d));
}

vec2 directionToEnvUv(vec3 d) {
  vec3 l = envToMap(d);
  float u = atan(l.z, l.x) * (0.5 * INV_PI) + 0.5;
  u -= floor(u);
  float v = acos(clamp(l.y, -1.0, 1.0)) * INV_PI;
  return vec2(u, v);
}

vec3 envUvToDirection(vec2 uv) {
  float phi = 2.0 * PI * (uv.x - 0.5);
  float theta = PI * uv.y;
  float s = sin(theta);
  vec3 l = vec3(s * cos(phi), cos(theta), s * sin(phi));
  // The rows are orthonormal: the transpose takes the map's frame back to the world.
  return l.x * frame.environmentToMap[0].xyz + l.y * frame.environmentToMap[1].xyz + l.z * frame.environmentToMap[2].xyz;
}

ivec2 envTexel(vec2 uv) {
  ivec2 size = frame.environment.zw;
  return clamp(ivec2(uv * vec2(size)), ivec2(0), size - 1);
}

vec3 envRadiance(vec3 d) {
  int type = frame.environment.x;
  if (hasFeature(kFeatureEnvConstant) && type == kEnvConstant) return frame.environmentTint.rgb;
  // Filtered between the four nearest texels, wrapping, as Tungsten's bitmaps are (an infinite
  // sphere's map is one); light samples still pick texels by their own value (envPdf), which is
  // unbiased with MIS: where a dark texel takes light from a bright neighbour, rays that hit the
  // sky carry all of it.
  if (hasFeature(kFeatureEnvMap) && type == kEnvMap) {
    vec2 uv = directionToEnvUv(d);
    return max(sampleTexture(frame.environment.y, vec2(uv.x, 1.0 - uv.y)).rgb, vec3(0.0)) * frame.environmentTint.rgb;
  }
  return vec3(0.0);
}

// Density (solid angle) with which sampleEnvironment picks direction d.
float envPdf(vec3 d) {
  int type = frame.environment.x;
  if (hasFeature(kFeatureEnvConstant) && type == kEnvConstant) return 1.0 / (4.0 * PI);
  if (!hasFeature(kFeatureEnvMap) || type != kEnvMap) return 0.0;
  vec2 uv = directionToEnvUv(d);
  ivec2 t = envTexel(uv);
  float norm = imageLoad(uEnvCdf, 0).x;
  float up = envToMap(d).y;
  float sinActual = sqrt(max(0.0, 1.0 - up * up));
  if (norm <= 0.0 || sinActual <= 1e-6) return 0.0;
  float sinRow = sin(PI * (float(t.y) + 0.5) / float(frame.environment.w));
  vec4 info = imageLoad(uTexInfo, frame.environment.y * kTextureTexels);
  vec3 c = bitmapTexel(floatBitsToInt(info.x), t.y * frame.environment.z + t.x, floatBitsToInt(info.w)).rgb;
  return max(luminance(c), 0.0) * sinRow / (norm * 2.0 * PI * PI * sinActual);
}

// Largest index i in [0, n) with cdf[base + i] <= u.
int searchCdf(int base, int n, float u) {
  int lo = 0, hi = n;  // cdf[base] = 0, cdf[base + n] = 1
  while (hi - lo > 1) {
    loopIterations++;
    int mid = (lo + hi) >> 1;
    if (imageLoad(uEnvCdf, base + mid).x <= u) lo = mid; else hi = mid;
  }
  syncLoopIterations();
  return lo;
}

vec3 sampleEnvironment(vec2 u, out vec3 radiance, out float pdf) {
  int type = frame.environment.x;
  if (!hasFeature(kFeatureEnvMap) || type == kEnvConstant) {
    radiance = frame.environmentTint.rgb;
    pdf = 1.0 / (4.0 * PI);
    return sampleUniformSphere(u);
  }
  int w = frame.environment.z, h = frame.environment.w;
  int marginal = 1;
  int row = searchCdf(marginal, h, u.y);
  float r0 = imageLoad(uEnvCdf, marginal + row).x, r1 = imageLoad(uEnvCdf, marginal + row + 1).x;
  float fy = r1 > r0 ? (u.y - r0) / (r1 - r0) : 0.5;
  int condBase = 1 + (h + 1) + row * (w + 1);
  int col = searchCdf(condBase, w, u.x);
  float c0 = imageLoad(uEnvCdf, condBase + col).x, c1 = imageLoad(uEnvCdf, condBase + col + 1).x;
  float fx = c1 > c0 ? (u.x - c0) / (c1 - c0) : 0.5;
  vec2 uv = vec2((float(col) + clamp(fx, 0.0, 0.999)) / float(w), (float(row) + clamp(fy, 0.0, 0.999)) / float(h));
  vec3 d = envUvToDirection(uv);
  radiance = envRadiance(d);
  pdf = envPdf(d);
  return d;
}

struct LightSample {
  vec3 dir;       // from the shading point towards the light
  float dist;     // kInfinity for the environment and directional lights
  vec3 radiance;  // arriving radiance (or, for delta lights, irradiance-like intensity / dist^2)
  float pdf;      // solid angle, including the choice of light; for delta lights the pick probability
  bool delta;
};

// About what light group g gives a point at p (render_scene.cpp packEmitters,
// FrameUniforms::lightGroups): its weight scale over the squared distance to its centre, at most
// the weight at its radius, and for a plane the cosine it is seen at from p; nothing from behind a
// plane, where every triangle faces away. Any weight above 0 wherever the group could light p
// keeps the estimate unbiased. render_scene.cpp has its twin, for lightGroupGain.
float lightGroupWeight(int g, vec3 p) {
  vec4 centre = frame.lightGroups[2 * g];
  vec4 plane = frame.lightGroups[2 * g + 1];
  vec3 toCentre = centre.xyz - p;
  float d2 = dot(toCentre, toCentre);
  float w = min(centre.w / max(d2, 1e-30), plane.w);
  if (all(equal(plane.xyz, vec3(0.0)))) return w;
  float h = -dot(plane.xyz, toCentre);
  return h > 0.0 ? w * min(h * inversesqrt(max(d2, 1e-30)), 1.0) : 0.0;
}

// The total of the light groups' weights at the point of the last light sample that chose a
// group, -1 after one that did not (trace.comp keeps it with the path for the emitter it may
// hit next, whose pdf needs it).
float lightGroupTotal = -1.0;

// Chooses a light group for a light sample at p, with u in [0, 1), in one pass: each group with
// weight w replaces the choice so far with probability w over the total so far, and u, rescaled
// to what is left of it, decides the next. -1 when none can light p. Its iterations, and
// lightGroupTotalAt's, are counted in trace.comp's main, in every lane.
int chooseLightGroup(vec3 p, float u, out float probability) {
  float total = 0.0, chosenWeight = 0.0;
  int chosen = -1;
  for (int g = 0; g < frame.bounces.y; ++g) {
    float w = lightGroupWeight(g, p);
    if (!(w > 0.0)) continue;
    total += w;
    float keep = w / total;
    if (u < keep) {
      chosen = g;
      chosenWeight = w;
      u = u / keep;
    } else {
      u = (u - keep) / (1.0 - keep);
    }
    u = clamp(u, 0.0, 0.99999994);
  }
  lightGroupTotal = total;
  probability = chosen >= 0 ? chosenWeight / total : 0.0;
  return chosen;
}

// The total chooseLightGroup at p adds up, in the same order.
float lightGroupTotalAt(vec3 p) {
  float total = 0.0;
  for (int g = 0; g < frame.bounces.y; ++g) {
    float w = lightGroupWeight(g, p);
    if (w > 0.0) total += w;
  }
  return total;
}

// Picks one light in proportion to frame.lightPick and samples it as seen from p.
LightSample sampleLight(vec3 p, vec3 u) {
  LightSample ls;
  ls.dir = vec3(0.0, 1.0, 0.0);
  ls.dist = kInfinity;
  ls.radiance = vec3(0.0);
  ls.pdf = 0.0;
  ls.delta = false;
  float pe = frame.lightPick.x, pv = frame.lightPick.y;
  if (hasFeature(kFeatureEmitters) && u.z < pe) {
    int first = 0, n = frame.scene.z;
    float groupProbability = 1.0;
    if (hasFeature(kFeatureLightGroups)) {
      // What is left of u.z below pe is again uniform.
      int g = chooseLightGroup(p, u.z / pe, groupProbability);
      if (g < 0) return ls;
      vec4 r = imageLoad(uEmitterAlias, frame.scene.z + g * kLightGroupTexels);
      first = floatBitsToInt(r.x);
      n = floatBitsToInt(r.y);
    }
    float scaled = u.x * float(n);
    int i = min(int(scaled), n - 1);
    float frac = scaled - float(i);
    vec4 alias = imageLoad(uEmitterAlias, first + i);
    int e = frac < alias.x ? first + i : floatBitsToInt(alias.y);
    int base = e * kEmitterTexels;
    vec4 t0 = imageLoad(uEmitters, base), t1 = imageLoad(uEmitters, base + 1), t2 = imageLoad(uEmitters, base + 2);
    vec4 t3 = imageLoad(uEmitters, base + 3), t4 = imageLoad(uEmitters, base + 4);
    // The fraction left over from the alias choice is again uniform: reuse it for the point.
    float reuse = frac < alias.x ? frac / max(alias.x, 1e-7) : (frac - alias.x) / max(1.0 - alias.x, 1e-7);
    vec2 b = sampleTriangle(vec2(clamp(reuse, 0.0, 0.9999999), u.y));
    vec3 q = t0.xyz + b.x * t1.xyz + b.y * t2.xyz;
    vec3 toL = q - p;
    float d2 = dot(toL, toL);
    float d = sqrt(d2);
    if (d <= 0.0) return ls;
    ls.dir = toL / d;
    float cosL = -dot(t4.xyz, ls.dir);
    if (cosL <= 0.0 || t0.w <= 0.0) return ls;  // emitters shine from their front only
    if (hasFeature(kFeatureEmissionCone) && cosL <= emissionConeCos(instanceMaterial(floatBitsToInt(t1.w)))) return ls;
    ls.dist = d;
    ls.radiance = t3.rgb;
    if (hasFeature(kFeatureEmissionTextures) && floatBitsToInt(t4.w) >= 0)
      ls.radiance *= sampleTexture(floatBitsToInt(t4.w), triangleUv(floatBitsToInt(t2.w), b.x, b.y)).rgb;
    ls.pdf = pe * groupProbability * t3.w * d2 / (cosL * t0.w);
    return ls;
  }
  if (hasFeature(kFeatureEnvConstant | kFeatureEnvMap) && u.z < pe + pv) {
    float pdf;
    ls.dir = sampleEnvironment(u.xy, ls.radiance, pdf);
    ls.pdf = pv * pdf;
    return ls;
  }
  int n = frame.scene.w;
  if (!hasFeature(kFeatureDeltaLights) || n == 0) return ls;
  float scaled = u.x * float(n);
  int i = min(int(scaled), n - 1);
  vec4 a = imageLoad(uDeltaLights, i * kDeltaLightTexels);
  vec4 b = imageLoad(uDeltaLights, i * kDeltaLightTexels + 1);
  vec4 c = imageLoad(uDeltaLights, i * kDeltaLightTexels + 2);
  int type = floatBitsToInt(a.w);
  ls.delta = true;
  ls.pdf = frame.lightPick.z / float(n);
  if (hasFeature(kFeatureSun) && type == kLightSun) {
    // Uniform over the disc's cone; the pick's leftover fraction is again uniform.
    float oneMinusCos = clamp(scaled - float(i), 0.0, 1.0) * b.w;
    float sinT = sqrt(max(0.0, oneMinusCos * (2.0 - oneMinusCos))), phi = 2.0 * PI * u.y;
    vec3 axis = -b.xyz, tx, ty;
    makeFrame(axis, tx, ty);
    ls.dir = normalize(sinT * (cos(phi) * tx + sin(phi) * ty) + (1.0 - oneMinusCos) * axis);
    ls.radiance = c.rgb;
    ls.pdf /= c.w;
    ls.delta = false;
    return ls;
  }
  if (type == kLightDirectional) {
    ls.dir = -b.xyz;
    ls.radiance = c.rgb;
    return ls;
  }
  vec3 toL = a.xyz - p;
  float d2 = dot(toL, toL);
  if (d2 <= 0.0) return ls;
  ls.dist = sqrt(d2);
  ls.dir = toL / ls.dist;
  float falloff = 1.0;
  if (type == kLightSpot) {
    float cosA = dot(-ls.dir, b.xyz);
    falloff = smoothstep(b.w, max(c.w, b.w + 1e-4), cosA);
  }
  ls.radiance = c.rgb * (falloff / d2);
  return ls;
}

// What the suns' discs add along direction d, out of the scene, each weighted against its light
// samples (unless the ray came off a delta lobe, which no light sample can stand in for).
vec3 sunsSeen(vec3 d, bool specular, float bsdfPdf) {
  vec3 seen = vec3(0.0);
  int n = frame.scene.w;
  // Its iterations are counted in trace.comp's main, in every lane (see loopIterations).
  for (int i = 0; i < int(frame.lightPick.w); ++i) {
    vec4 b = imageLoad(uDeltaLights, i * kDeltaLightTexels + 1);
    vec4 c = imageLoad(uDeltaLights, i * kDeltaLightTexels + 2);
    bool inside = 1.0 + dot(d, b.xyz) <= b.w;
    float w = specular ? 1.0 : powerHeuristic(bsdfPdf, frame.lightPick.z / (float(n) * c.w));
    seen += inside ? c.rgb * w : vec3(0.0);
  }
  return seen;
}

// pdf with which sampleLight would have chosen the emitter point hit by a BSDF ray; groupTotal
// is lightGroupTotal of the light sample at `from` (below 0: not known).
float emitterPdf(int emitter, vec3 from, vec3 hitPos, float cosL, float groupTotal) {
  vec4 t0 = imageLoad(uEmitters, emitter * kEmitterTexels);
  vec4 t3 = imageLoad(uEmitters, emitter * kEmitterTexels + 3);
  vec3 d = hitPos - from;
  if (cosL <= 0.0 || t0.w <= 0.0) return 0.0;
  float pick = frame.lightPick.x * t3.w;
  if (hasFeature(kFeatureLightGroups)) {
    float total = groupTotal >= 0.0 ? groupTotal : lightGroupTotalAt(from);
    pick *= total > 0.0 ? lightGroupWeight(floatBitsToInt(imageLoad(uEmitterAlias, emitter).z), from) / total : 0.0;
  }
  return pick * dot(d, d) / (cosL * t0.w);
}

#endif
