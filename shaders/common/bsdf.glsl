// The materials of scene.h, evaluated and sampled in a local frame whose z axis is the shading
// normal. eval returns f * |cos(wi)|; sample returns that divided by the pdf. Opaque materials
// expect wo.z > 0 (the caller makes surfaces two-sided); dielectrics use the sign of wo.z to
// tell entering from leaving.
#ifndef RETILE_BSDF_GLSL
#define RETILE_BSDF_GLSL

#include "shared/layouts.h"
#include "common/sampling.glsl"

// The material types the scene has (bit k for type k). The renderer compiles the kernel for them
// alone: lavapipe runs every branch some lane of eight takes, and code for absent types still
// costs registers and spills (removing the nine unused types speeds the Cornell box up by 9 %).
#ifndef RETILE_MATERIALS
#define RETILE_MATERIALS 0x7ffff
#endif
const int kMaterialMask = RETILE_MATERIALS;
bool isMat(int t, int k) { return (kMaterialMask & (1 << k)) != 0 && t == k; }
// Some rough material of the scene asks for Beckmann's distribution (bit kMaskBeckmann of the
// mask): without it the Beckmann code is not compiled in.
const bool kBeckmannUsed = (kMaterialMask & (1 << kMaskBeckmann)) != 0;
// Likewise the clear coat (bit kMaskCoat), glass filled with a medium (kMaskMedium) and a medium
// that scatters (kMaskScattering: a scene whose media only absorb compiles no scattering code).
const bool kCoatUsed = (kMaterialMask & (1 << kMaskCoat)) != 0;
const bool kMediumUsed = (kMaterialMask & (1 << kMaskMedium)) != 0;
const bool kScatteringUsed = (kMaterialMask & (1 << kMaskScattering)) != 0;
// The same for the preprocessor (bit 17 is kMaskMedium): the path's medium (trace.comp) is not
// even declared without one, so that a scene without filled glass carries no dead field.
// Likewise bit 13, kMatBoundary: only then do shadow rays pass surfaces (scene.glsl traceStep).
#define RETILE_MEDIUM ((RETILE_MATERIALS & 131072) != 0)
#define RETILE_BOUNDARY ((RETILE_MATERIALS & 8192) != 0)
// And bit 9, kMatThinSheet: shadow rays pass thin sheets, dimmed (trace.comp sheetPasses).
#define RETILE_SHEET ((RETILE_MATERIALS & 512) != 0)

struct Material {
  int type;
  vec3 albedo;
  float roughness;   // microfacet alpha, Oren-Nayar sigma, Phong's a (exponent 2 / a^2 - 2), or a thin
                     // sheet's film thickness in nm (0: no interference; Material::filmThickness)
  bool beckmann;     // rough types: Beckmann's distribution instead of GGX
  bool separable;    // rough types: G = G1(wo) G1(wi) instead of height-correlated
  bool tintsReflection;  // glass: albedo tints reflection too, no (n_t / n_i)^2 across (Material::tintsReflection)
  float ior;
  float fdrInt;      // plastic: internal diffuse Fresnel reflectance of the coating; diffuse
                     // transmission: the transmittance; Phong: the diffuse ratio (packMaterial)
  vec3 coating;      // plastic: the coating's absorption (sigma_a times thickness); thin sheet: the sheet's
  vec3 eta;
  vec3 k;
  vec3 emission;
  float coatIor;        // a clear coat's index; no coat at 1 or below
  vec3 coatAbsorption;  // inside the coat, sigma_a times thickness
  float coatRoughness;  // a rough coat's GGX alpha; 0: smooth
  vec3 interior;        // glass: its medium's absorption per unit of length
  vec4 scattering;      // glass: its medium's scattering per unit of length, and in w the phase
                        // function's asymmetry g (read by trace.comp, not by the BSDF)
  // Hair: the fibre's direction in the shading frame, and where across its width the light
  // meets it (h in -1..1, drawn afresh at each hit: see hairEval). Set by the caller.
  vec3 hairT;
  float hairH;
};

// The material's texels as render/render_scene.cpp packMaterial writes them, textures not applied.
Material unpackMaterial(vec4 t0, vec4 t1, vec4 t2, vec4 t3, vec4 t4, vec4 t6, vec4 t7, vec4 t8) {
  Material m;
  int type = floatBitsToInt(t0.w);
  m.type = type & kMatTypeBits;
  m.beckmann = kBeckmannUsed && (type & kMatBeckmann) != 0;
  m.separable = (type & kMatSeparable) != 0;
  m.tintsReflection = (type & kMatTintsReflection) != 0;
  m.albedo = t0.rgb;
  m.roughness = t1.x;
  m.ior = t1.y;
  m.fdrInt = t1.w;
  m.eta = t2.xyz;
  m.k = t3.xyz;
  m.emission = t4.rgb;
  m.coating = t6.rgb;
  m.coatIor = kCoatUsed ? t7.y : 0.0;
  m.coatAbsorption = t8.rgb;
  m.coatRoughness = t8.w;
  m.interior = kMediumUsed ? t8.rgb : vec3(0.0);
  m.scattering = vec4(0.0);
  m.hairT = vec3(1.0, 0.0, 0.0);
  m.hairH = 0.0;
  return m;
}

struct BsdfSample {
  vec3 wi;
  vec3 weight;  // f * |cos| / pdf
  float pdf;    // solid angle; meaningless when delta
  bool delta;
  bool transmitted;
};

// A failed sample: no weight; the caller ends the path.
BsdfSample noSample() {
  BsdfSample s;
  s.wi = vec3(0.0, 0.0, 1.0);
  s.weight = vec3(0.0);
  s.pdf = 0.0;
  s.delta = false;
  s.transmitted = false;
  return s;
}

// The material types with only delta lobes, a coat left out.
bool isDeltaBase(Material m) {
  return isMat(m.type, kMatConductor) || isMat(m.type, kMatMirror) || isMat(m.type, kMatDielectric) || isMat(m.type, kMatThinSheet) ||
         isMat(m.type, kMatNull);
}

// Materials with only delta lobes: light sampling cannot reach them. Smooth plastic is not one:
// its diffuse base takes light samples and its specular lobe is sampled inside bsdfSample; nor is
// a smooth metal under a rough coat, whose lobe takes them.
bool isDeltaMaterial(Material m) { return isDeltaBase(m) && !(kCoatUsed && m.coatIor > 1.0 && m.coatRoughness > 0.0); }

bool isTransmissive(Material m) {
  return isMat(m.type, kMatDielectric) || isMat(m.type, kMatRoughDielectric) || isMat(m.type, kMatThinSheet) ||
         isMat(m.type, kMatDiffuseTransmission) || isMat(m.type, kMatHair);
}

// The reflectances of the two polarisations (s, p) at a dielectric boundary; eta = n_transmitted /
// n_incident, cosI >= 0. Both 1 for total internal reflection.
vec2 fresnelPolarised(float cosI, float eta, out float cosT) {
  float sin2T = (1.0 - cosI * cosI) / (eta * eta);
  if (sin2T >= 1.0) {
    cosT = 0.0;
    return vec2(1.0);
  }
  cosT = sqrt(1.0 - sin2T);
  float rs = (cosI - eta * cosT) / (cosI + eta * cosT);
  float rp = (eta * cosI - cosT) / (eta * cosI + cosT);
  return vec2(rs * rs, rp * rp);
}

// Unpolarised: the two's mean.
float fresnelDielectric(float cosI, float eta, out float cosT) {
  vec2 r = fresnelPolarised(cosI, eta, cosT);
  return 0.5 * (r.x + r.y);
}

float fresnelDielectric(float cosI, float eta) {
  float cosT;
  return fresnelDielectric(cosI, eta, cosT);
}

// A thin sheet's reflectance per channel. It reflects at both faces, and light bounces between
// them: for each polarisation R + T^2 R / (1 - R^2) = 2R / (1 + R) in all, the two then averaged
// (as Tungsten's thin sheet, not the average's 2F / (1 + F), which is larger). Over a film of
// thickness m.roughness nm the waves interfere, phi the phase the film's two faces put between
// them at 650, 510 and 475 nm: each polarisation passes (1 - R)^2 / (1 + R^2 - 2 R cos phi) of
// what reaches it (Airy's, whose mean over the phase is the plain sheet's), or, as Tungsten draws
// it (m.tintsReflection; Fresnel::thinFilmReflectanceInterference),
// (1 - R)^2 / sqrt(1 + R^4 - 2 R^2 cos phi), whose colours are a few per cent of Airy's.
// cosT: the angle's inside the sheet.
vec3 thinSheetReflectances(Material m, float cosI, out float cosT) {
  vec2 r = fresnelPolarised(cosI, m.ior, cosT);
  if (m.roughness <= 0.0) return vec3(r.x / (1.0 + r.x) + r.y / (1.0 + r.y));
  // 1 + a^2 - 2a cos phi as (1 - a)^2 + 4a sin^2(phi / 2): no cancellation near grazing angles,
  // where a nears 1 and the difference of the first form rounded to 0.
  vec3 half2 = sin(2.0 * PI * m.ior * m.roughness * cosT / vec3(650.0, 510.0, 475.0));
  half2 *= half2;
  vec2 t2 = (1.0 - r) * (1.0 - r);
  vec2 a = m.tintsReflection ? r * r : r;  // Tungsten squares the reflectances once more
  vec3 ds = (1.0 - a.x) * (1.0 - a.x) + 4.0 * a.x * half2, dp = (1.0 - a.y) * (1.0 - a.y) + 4.0 * a.y * half2;
  if (m.tintsReflection) {
    ds = sqrt(ds);
    dp = sqrt(dp);
  }
  return clamp(1.0 - 0.5 * (t2.x / max(ds, vec3(1e-30)) + t2.y / max(dp, vec3(1e-30))), 0.0, 1.0);
}

// What a thin sheet lets straight through at |cos| cosO to its normal: what it does not reflect
// (R, per channel), tinted by its albedo and dimmed by its absorption along its slanted way
// through (m.coating: the absorption straight across). The same for a path that passes it and a
// shadow ray.
vec3 thinSheetTransmittance(Material m, float cosO, out vec3 R) {
  float cosIn;
  R = thinSheetReflectances(m, cosO, cosIn);
  return m.albedo * (1.0 - R) * exp(-m.coating / max(cosIn, 1e-4));
}

// Exact unpolarised reflectance of a conductor with complex index eta + i k.
vec3 fresnelConductor(float cosI, vec3 eta, vec3 k) {
  float c2 = cosI * cosI;
  float s2 = 1.0 - c2;
  vec3 eta2 = eta * eta, k2 = k * k;
  vec3 t0 = eta2 - k2 - s2;
  vec3 a2b2 = sqrt(max(t0 * t0 + 4.0 * eta2 * k2, vec3(0.0)));
  vec3 t1 = a2b2 + c2;
  vec3 a = sqrt(max(0.5 * (a2b2 + t0), vec3(0.0)));
  vec3 t2 = 2.0 * cosI * a;
  vec3 rs = (t1 - t2) / max(t1 + t2, vec3(1e-12));
  vec3 t3 = c2 * a2b2 + s2 * s2;
  vec3 t4 = t2 * s2;
  vec3 rp = rs * (t3 - t4) / max(t3 + t4, vec3(1e-12));
  return clamp(0.5 * (rp + rs), 0.0, 1.0);
}

float ggxD(vec3 h, float a) {
  float a2 = a * a;
  float c = h.z * h.z * (a2 - 1.0) + 1.0;
  return a2 / (PI * c * c);
}

float ggxLambda(vec3 w, float a) {
  float c2 = w.z * w.z;
  if (c2 >= 1.0) return 0.0;
  float t2 = (1.0 - c2) / max(c2, 1e-12);
  return 0.5 * (-1.0 + sqrt(1.0 + a * a * t2));
}

float ggxG1(vec3 w, float a) { return 1.0 / (1.0 + ggxLambda(w, a)); }

// Heitz 2018: sample a microfacet normal from the distribution of normals visible from wo.
vec3 sampleGgxVisibleNormal(vec3 wo, float a, vec2 u) {
  vec3 vh = normalize(vec3(a * wo.x, a * wo.y, wo.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) / sqrt(lensq) : vec3(1.0, 0.0, 0.0);
  vec3 t2 = cross(vh, t1);
  float r = sqrt(u.x);
  float phi = 2.0 * PI * u.y;
  float p1 = r * cos(phi);
  float p2 = r * sin(phi);
  float s = 0.5 * (1.0 + vh.z);
  p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
  vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
  return normalize(vec3(a * nh.x, a * nh.y, max(1e-6, nh.z)));
}

// Beckmann's distribution, with the rational fit of Smith's Lambda (Walter et al. 2007), as
// Tungsten has it.
float beckmannD(vec3 h, float a) {
  if (h.z <= 0.0) return 0.0;
  float c2 = h.z * h.z;
  return exp(-(1.0 - c2) / (c2 * a * a)) / (PI * a * a * c2 * c2);
}

float beckmannLambda(vec3 w, float a) {
  float c2 = w.z * w.z;
  if (c2 >= 1.0) return 0.0;
  float x = sqrt(c2 / max(1.0 - c2, 1e-12)) / a;  // 1 / (alpha tan(theta))
  return x < 1.6 ? (1.0 - 1.259 * x + 0.396 * x * x) / (3.535 * x + 2.181 * x * x) : 0.0;
}

// The material's microfacet distribution: GGX, or Beckmann where asked for.
float mfD(Material m, vec3 h, float a) { return kBeckmannUsed && m.beckmann ? beckmannD(h, a) : ggxD(h, a); }
float mfLambda(Material m, vec3 w, float a) { return kBeckmannUsed && m.beckmann ? beckmannLambda(w, a) : ggxLambda(w, a); }
float mfG1(Material m, vec3 w, float a) { return 1.0 / (1.0 + mfLambda(m, w, a)); }
float mfG2(Material m, vec3 wo, vec3 wi, float a) {
  float lo = mfLambda(m, wo, a), li = mfLambda(m, wi, a);
  return m.separable ? 1.0 / ((1.0 + lo) * (1.0 + li)) : 1.0 / (1.0 + lo + li);
}

// A microfacet normal for wo: GGX's visible normals; Beckmann's D cos(theta) (as Tungsten draws it).
vec3 mfSample(Material m, vec3 wo, float a, vec2 u) {
  if (kBeckmannUsed && m.beckmann) {
    float t2 = -a * a * log(max(1.0 - u.x, 1e-12));
    float c = 1.0 / sqrt(1.0 + t2), sn = sqrt(max(0.0, 1.0 - c * c));
    float phi = 2.0 * PI * u.y;
    return vec3(sn * cos(phi), sn * sin(phi), c);
  }
  return sampleGgxVisibleNormal(wo, a, u);
}

// The solid-angle density mfSample gives h.
float mfNormalPdf(Material m, vec3 wo, vec3 h, float a) {
  if (kBeckmannUsed && m.beckmann) return beckmannD(h, a) * max(h.z, 0.0);
  return ggxD(h, a) * ggxG1(wo, a) * max(dot(wo, h), 0.0) / wo.z;
}

// pdf of wi = reflect(wo, h) when h comes from mfSample.
float mfReflectionPdf(Material m, vec3 wo, vec3 h, float a) { return mfNormalPdf(m, wo, h, a) / (4.0 * max(dot(wo, h), 1e-12)); }

float plasticSpecularProbability(Material m, float cosO) {
  float fo = fresnelDielectric(cosO, m.ior);
  // The base as seen through the coating at normal incidence both ways.
  float diffuse = (1.0 - fo) * luminance(m.albedo * exp(-2.0 * m.coating));
  return clamp(fo / max(fo + diffuse, 1e-6), 0.05, 0.95);
}

// Lambertian base under a dielectric coating: both Fresnel transmissions, the 1/eta^2 of
// leaving the denser layer, and the sum of internal reflections (1 - albedo * fdrInt).
vec3 plasticDiffuse(Material m, vec3 wo, vec3 wi) {
  float fo = fresnelDielectric(wo.z, m.ior);
  float fi = fresnelDielectric(wi.z, m.ior);
  vec3 base = m.albedo / (1.0 - m.albedo * m.fdrInt);
  // An absorbing coating dims the light on its two slanted paths through it (Tungsten's plastic).
  vec3 through = exp(-m.coating * (1.0 / max(wo.z, 1e-6) + 1.0 / max(wi.z, 1e-6)));
  return base * through * (INV_PI * (1.0 - fo) * (1.0 - fi) / (m.ior * m.ior));
}

float phongExponent(Material m) { return max(2.0 / (m.roughness * m.roughness) - 2.0, 0.0); }

float orenNayarFactor(Material m, vec3 wo, vec3 wi) {
  float s2 = m.roughness * m.roughness;
  float A = 1.0 - 0.5 * s2 / (s2 + 0.33);
  float B = 0.45 * s2 / (s2 + 0.09);
  float sinO = sqrt(max(0.0, 1.0 - wo.z * wo.z)), sinI = sqrt(max(0.0, 1.0 - wi.z * wi.z));
  float cosPhi = 0.0;
  if (sinO > 1e-4 && sinI > 1e-4) cosPhi = max(0.0, (wo.x * wi.x + wo.y * wi.y) / (sinO * sinI));
  float sinAlpha = wo.z < wi.z ? sinO : sinI;
  float tanBeta = wo.z < wi.z ? sinI / max(wi.z, 1e-6) : sinO / max(wo.z, 1e-6);
  return A + B * cosPhi * sinAlpha * tanBeta;
}

// D, G2 and the density with which mfSample draws h, sharing what they have in common (Lambda of
// o, D).
struct MicrofacetTerms {
  float D, G2, normalPdf;
};

MicrofacetTerms microfacetTerms(Material m, vec3 o, vec3 i, vec3 h, float a) {
  MicrofacetTerms r;
  r.D = mfD(m, h, a);
  float lo = mfLambda(m, o, a), li = mfLambda(m, i, a);
  r.G2 = m.separable ? 1.0 / ((1.0 + lo) * (1.0 + li)) : 1.0 / (1.0 + lo + li);
  r.normalPdf = kBeckmannUsed && m.beckmann ? r.D * max(h.z, 0.0) : r.D * (1.0 / (1.0 + lo)) * max(dot(o, h), 0.0) / o.z;
  return r;
}

// f * |cos(wi)| and the pdf sample() would have for wi. Zero for delta lobes.
//
// Hair, as Tungsten's HairBcsdf has it (d'Eon et al. 2011, "An Energy-Conserving Hair
// Reflectance Model", with the lobe shifts of Ou et al. 2012). Angles are about the fibre: theta
// from the plane normal to it (sin theta = the direction's component along it), phi around it,
// from wo. Lobe p (0: R, 1: TT, 2: TRT) is M_p(theta_i) A_p N_p(phi): M_p d'Eon's longitudinal
// cone of variance v_p about the mirror of theta_o shifted by the scales' tilt, A_p what Fresnel
// and the pigment leave of it, N_p a wrapped Gaussian of deviation beta_R about the azimuth
// Phi_p that a ray meeting the fibre at h leaves by. Tungsten integrates A_p N_p over h into a
// table; here h is the one drawn for the hit (m.hairH, uniform), which averages to the same, and
// NEE and sampling at the hit share it, so their weights stay exact. As Tungsten's, eval is f
// times the cosine (it integrates to the energy kept), and lobes past TRT are left out.
const float kHairEta = 1.55;

float hairI0(float x) {
  float sum = 1.0, x2 = x * x, term = x2, denom = 4.0;
  for (int i = 1; i <= 10; ++i) {
    sum += term / denom;
    term *= x2;
    denom *= 4.0 * float((i + 1) * (i + 1));
  }
  return sum;
}

// d'Eon's longitudinal lobe of variance v for the angles a (theta_o shifted) and b (theta_i);
// below v = 0.1 through logarithms, where I0 and sinh overflow.
float hairM(float v, float sinA, float sinB, float cosA, float cosB) {
  float a = cosA * cosB / v, b = sinA * sinB / v;
  if (v < 0.1) {
    float logI0 = a > 12.0 ? a + 0.5 * (log(1.0 / (2.0 * PI * a)) + 1.0 / (8.0 * a)) : log(hairI0(a));
    return exp(-b + logI0 - 1.0 / v + 0.6931 + log(1.0 / (2.0 * v)));
  }
  return exp(-b) * hairI0(a) / (2.0 * v * sinh(1.0 / v));
}

// An angle taken into -pi..pi.
float hairWrap(float phi) { return phi - 2.0 * PI * floor((phi + PI) / (2.0 * PI)); }

// The wrapped Gaussian of deviation beta (Tungsten's "detector" D); beta is at most pi / 2, so
// the neighbouring turns are all that count.
float hairD(float beta, float phi) {
  float x = hairWrap(phi), k = 1.0 / (sqrt(2.0 * PI) * beta), s = -0.5 / (beta * beta);
  return k * (exp(s * x * x) + exp(s * (x - 2.0 * PI) * (x - 2.0 * PI)) + exp(s * (x + 2.0 * PI) * (x + 2.0 * PI)));
}

// Azimuths are drawn from a logistic trimmed to -pi..pi of the Gaussian's variance (its tails
// are heavier, so the weights stay bounded); its density and its inverse.
float hairLogisticScale(float beta) { return beta * (sqrt(3.0) / PI); }
float hairLogisticCdf(float x, float s) { return 1.0 / (1.0 + exp(-x / s)); }
float hairLogisticPdf(float x, float s) {
  float e = exp(-abs(x) / s);
  return e / (s * (1.0 + e) * (1.0 + e)) / (hairLogisticCdf(PI, s) - hairLogisticCdf(-PI, s));
}
float hairLogisticSample(float u, float s) {
  float lo = hairLogisticCdf(-PI, s), hi = hairLogisticCdf(PI, s);
  float c = clamp(lo + u * (hi - lo), 1e-7, 1.0 - 1e-7);
  return clamp(-s * log(1.0 / c - 1.0), -PI, PI);
}

// The fibre's frame seen from wo: T along it, z wo's part across it, x = T x z.
void hairFrame(Material m, vec3 wo, out vec3 T, out vec3 z, out vec3 x) {
  T = m.hairT;
  z = wo - T * dot(wo, T);
  float len = length(z);
  if (len < 1e-6) {
    vec3 b;
    makeFrame(T, z, b);
  } else {
    z /= len;
  }
  x = cross(T, z);
}

// What of lobes R, TT and TRT the fibre gives at h, for the half difference angle's cosine cosD.
vec3 hairAttenuation(Material m, float cosD, float h, int p) {
  float sin2D = 1.0 - cosD * cosD;
  float cosT = sqrt(max(1.0 - sin2D / (kHairEta * kHairEta), 0.0));
  float etaPrime = sqrt(max(kHairEta * kHairEta - sin2D, 0.0)) / max(cosD, 1e-4);
  float gammaI = asin(clamp(h, -1.0, 1.0)), gammaT = asin(clamp(h / etaPrime, -1.0, 1.0));
  float f = fresnelDielectric(cosD * cos(gammaI), kHairEta);
  vec3 through = exp(-m.coating / max(cosT, 1e-4) * (2.0 * cos(gammaT)));
  if (p == 0) return vec3(f);
  vec3 a = (1.0 - f) * (1.0 - f) * through;
  return p == 1 ? a : a * f * through;
}

// The azimuth lobe p leaves by, for a ray meeting the fibre at h.
float hairPhi(float cosD, float h, int p) {
  float sin2D = 1.0 - cosD * cosD;
  float etaPrime = sqrt(max(kHairEta * kHairEta - sin2D, 0.0)) / max(cosD, 1e-4);
  float gammaI = asin(clamp(h, -1.0, 1.0)), gammaT = asin(clamp(h / etaPrime, -1.0, 1.0));
  return 2.0 * float(p) * gammaT - 2.0 * gammaI + float(p) * PI;
}

// The lobes' shares of the samples: their attenuations for theta_i the mirror of theta_o (as
// Tungsten weighs them), whatever wi is drawn, so that the pdf can be evaluated for any wi.
vec3 hairLobeWeights(Material m, float cosO, float h) {
  vec3 w = vec3(luminance(hairAttenuation(m, cosO, h, 0)), luminance(hairAttenuation(m, cosO, h, 1)),
                luminance(hairAttenuation(m, cosO, h, 2)));
  float sum = w.x + w.y + w.z;
  return sum > 0.0 ? w / sum : vec3(1.0, 0.0, 0.0);
}

vec3 hairEval(Material m, vec3 wo, vec3 wi, out float pdf) {
  vec3 T, z, x;
  hairFrame(m, wo, T, z, x);
  float sinO = clamp(dot(wo, T), -1.0, 1.0), sinI = clamp(dot(wi, T), -1.0, 1.0);
  float cosO = sqrt(1.0 - sinO * sinO), cosI = sqrt(1.0 - sinI * sinI);
  float thetaO = asin(sinO), thetaI = asin(sinI);
  float cosD = cos(0.5 * (thetaI - thetaO));
  float phi = atan(dot(wi, x), dot(wi, z));
  float tilt = radians(m.eta.x);  // degrees (Material::hairTilt)
  float betaR = max(0.5 * PI * m.roughness, 0.04);
  float v[3] = float[3](betaR * betaR, 0.25 * betaR * betaR, 4.0 * betaR * betaR);
  float shift[3] = float[3](-2.0 * tilt, tilt, 4.0 * tilt);
  vec3 weights = hairLobeWeights(m, cosO, m.hairH);
  float s = hairLogisticScale(betaR);
  vec3 f = vec3(0.0);
  pdf = 0.0;
  for (int p = 0; p < 3; ++p) {
    float t = thetaO + shift[p];
    float M = hairM(v[p], sin(t), sinI, cos(t), cosI);
    float dphi = phi - hairPhi(cosD, m.hairH, p);
    f += M * hairAttenuation(m, cosD, m.hairH, p) * hairD(betaR, dphi);
    pdf += weights[p] * M * hairLogisticPdf(hairWrap(dphi), s);
  }
  return f;
}

// A direction drawn for hairEval's pdf: a lobe by hairLobeWeights, theta_i from its cone, phi
// about its azimuth. (baseSample weighs it by hairEval.)
vec3 hairSample(Material m, vec3 wo, vec3 u) {
  vec3 T, z, x;
  hairFrame(m, wo, T, z, x);
  float sinO = clamp(dot(wo, T), -1.0, 1.0), cosO = sqrt(1.0 - sinO * sinO);
  float thetaO = asin(sinO);
  float tilt = radians(m.eta.x);  // degrees (Material::hairTilt)
  float betaR = max(0.5 * PI * m.roughness, 0.04);
  vec3 weights = hairLobeWeights(m, cosO, m.hairH);
  int p = u.z < weights.x ? 0 : (u.z < weights.x + weights.y ? 1 : 2);
  // What is left of u.z within the lobe's share is uniform again: the azimuth's.
  float lo = p == 0 ? 0.0 : (p == 1 ? weights.x : weights.x + weights.y);
  float uPhi = clamp((u.z - lo) / max(weights[p], 1e-7), 0.0, 1.0);
  float v = p == 0 ? betaR * betaR : (p == 1 ? 0.25 * betaR * betaR : 4.0 * betaR * betaR);
  float t = thetaO + (p == 0 ? -2.0 * tilt : (p == 1 ? tilt : 4.0 * tilt));
  // theta_i about the cone (d'Eon's lobe, sampled in its numerically stable form).
  float c = 1.0 + v * log(max(u.x, 1e-7) + (1.0 - u.x) * exp(-2.0 / v));
  float sc = sqrt(max(1.0 - c * c, 0.0));
  float sinI = clamp(-c * sin(t) + sc * cos(2.0 * PI * u.y) * cos(t), -1.0, 1.0);
  float cosI = sqrt(1.0 - sinI * sinI);
  float cosD = cos(0.5 * (asin(sinI) - thetaO));
  float phi = hairPhi(cosD, m.hairH, p) + hairLogisticSample(uPhi, hairLogisticScale(betaR));
  return T * sinI + cosI * (cos(phi) * z + sin(phi) * x);
}

// The three microfacet types share one evaluation of their half vector, D, G2 and pdf, and the
// dielectric ones one Fresnel term: lavapipe runs the code of every type the kernel has for every
// lane, and one copy of it per type made the spaceship's shading code (rough dielectric, rough
// plastic and rough conductor, two calls a segment) several times longer.
vec3 baseEval(Material m, vec3 wo, vec3 wi, out float pdf) {
  pdf = 0.0;
  int t = m.type;
  bool roughDielectric = isMat(t, kMatRoughDielectric), roughPlastic = isMat(t, kMatRoughPlastic);
  bool roughConductor = isMat(t, kMatRoughConductor);
  // A rough dielectric is evaluated from the side wo is on, as if that were the outside.
  bool entering = wo.z > 0.0;
  bool flip = roughDielectric && !entering;
  vec3 o = flip ? -wo : wo, i = flip ? -wi : wi;
  if (isMat(t, kMatHair)) return hairEval(m, wo, wi, pdf);
  if (isMat(t, kMatDiffuseTransmission)) {
    // Either side may face the viewer: reflection keeps the side, transmission changes it.
    float share = wo.z * wi.z < 0.0 ? m.fdrInt : 1.0 - m.fdrInt;
    pdf = share * abs(wi.z) * INV_PI;
    return m.albedo * pdf;
  }
  if (roughDielectric ? (o.z <= 0.0 || i.z == 0.0) : (wo.z <= 0.0 || wi.z <= 0.0 || isDeltaBase(m))) return vec3(0.0);
  if (isMat(t, kMatLambert)) {
    pdf = wi.z * INV_PI;
    return m.albedo * (INV_PI * wi.z);
  }
  if (isMat(t, kMatOrenNayar)) {
    pdf = wi.z * INV_PI;
    return m.albedo * (INV_PI * orenNayarFactor(m, wo, wi) * wi.z);
  }
  if (isMat(t, kMatPhong)) {
    // A share r (fdrInt's texel: Tungsten's diffuse_ratio) of Lambert and 1 - r of the lobe
    // around the mirror direction, of which what falls below the surface is lost.
    float n = phongExponent(m), r = m.fdrInt;
    float d = dot(vec3(-wo.xy, wo.z), wi);
    float c = d > 0.0 ? pow(d, n) : 0.0;
    pdf = (1.0 - r) * c * (n + 1.0) * (0.5 * INV_PI) + r * wi.z * INV_PI;
    return m.albedo * (((1.0 - r) * c * (n + 2.0) * (0.5 * INV_PI) + r * INV_PI) * wi.z);
  }
  if (isMat(t, kMatPlastic)) {
    float ps = plasticSpecularProbability(m, wo.z);
    pdf = (1.0 - ps) * wi.z * INV_PI;
    return plasticDiffuse(m, wo, wi) * wi.z;
  }
  if (!(roughDielectric || roughPlastic || roughConductor)) return vec3(0.0);
  float a = m.roughness;
  float eta = roughDielectric ? (entering ? m.ior : 1.0 / m.ior) : m.ior;
  // Through the boundary (a rough dielectric's i below) the half vector is the refraction's.
  bool through = roughDielectric && i.z < 0.0;
  vec3 h = through ? -(o + eta * i) : o + i;
  float hl = length(h);
  if (hl <= 0.0) return vec3(0.0);
  h /= hl;
  if (h.z < 0.0) h = -h;
  float oh = dot(o, h), ih = dot(i, h);
  if (through && (oh <= 0.0 || ih >= 0.0)) return vec3(0.0);
  MicrofacetTerms mf = microfacetTerms(m, o, i, h, a);
  const bool dielectricFresnel = (kMaterialMask & ((1 << kMatRoughDielectric) | (1 << kMatRoughPlastic))) != 0;
  float F = dielectricFresnel ? fresnelDielectric(oh, eta) : 1.0;
  if (through) {
    float denom = oh + eta * ih;
    float jac = eta * eta * abs(ih) / (denom * denom);
    pdf = (1.0 - F) * mf.normalPdf * jac;
    float f = abs(ih) * oh / (o.z * abs(i.z)) * (1.0 - F) * mf.D * mf.G2 / (denom * denom);
    // Tungsten's form is the adjoint's: radiance not compressed by 1 / eta^2 (eta = n_i / n_o).
    if (m.tintsReflection) f *= eta * eta;
    return m.albedo * (f * abs(i.z));
  }
  float reflectionPdf = mf.normalPdf / (4.0 * max(oh, 1e-12));
  if (roughDielectric) {
    pdf = F * reflectionPdf;
    return (m.tintsReflection ? m.albedo : vec3(1.0)) * (F * mf.D * mf.G2 / (4.0 * o.z));
  }
  if (roughConductor) {
    pdf = reflectionPdf;
    return m.albedo * fresnelConductor(oh, m.eta, m.k) * (mf.D * mf.G2 / (4.0 * wo.z));
  }
  float spec = F * mf.D * mf.G2 / (4.0 * wo.z * wi.z);
  float ps = plasticSpecularProbability(m, wo.z);
  pdf = ps * reflectionPdf + (1.0 - ps) * wi.z * INV_PI;
  return (vec3(spec) + plasticDiffuse(m, wo, wi)) * wi.z;
}

// Delta lobes are weighed where they are drawn; every other direction is weighed by the one
// bsdfEval call at the end, whatever the type. lavapipe runs the code of every material type the
// kernel has for every lane (its branches skip nothing), and each call of bsdfEval is inlined with
// all of them: a call per type that needs one made bsdfSample hold up to four copies (one call:
// the spaceship 5 % faster). Evaluating this direction and the light sample's in one loop instead
// of two calls (a loop not unrolled) was slower again.
BsdfSample baseSample(Material m, vec3 wo, vec3 u) {
  BsdfSample s = noSample();
  bool evaluate = false;  // s.wi is a non-delta lobe's, to weigh by f / pdf
  int t = m.type;
  // One microfacet normal drawn, from the side wo is on (the only side an opaque type samples),
  // and the plastics' specular probability computed once, for whichever type uses them.
  const int microfacetTypes = (1 << kMatRoughDielectric) | (1 << kMatRoughPlastic) | (1 << kMatRoughConductor);
  vec3 h = vec3(0.0, 0.0, 1.0);
  if ((kMaterialMask & microfacetTypes) != 0) h = mfSample(m, wo.z > 0.0 ? wo : -wo, m.roughness, u.xy);
  const int plastics = (1 << kMatPlastic) | (1 << kMatRoughPlastic);
  float ps = (kMaterialMask & plastics) != 0 ? plasticSpecularProbability(m, wo.z) : 0.0;
  if (isMat(t, kMatHair)) {
    s.wi = hairSample(m, wo, u);
    evaluate = true;
  } else if (isMat(t, kMatDielectric) || isMat(t, kMatThinSheet)) {
    bool entering = wo.z > 0.0;
    float cosO = abs(wo.z);
    float eta = entering ? m.ior : 1.0 / m.ior;
    float cosT;
    float F = fresnelDielectric(cosO, eta, cosT);
    s.delta = true;
    if (isMat(t, kMatThinSheet)) {
      // What is not reflected passes straight through (thinSheetTransmittance); the two are
      // chosen by the reflectance's mean over the channels.
      vec3 R;
      vec3 through = thinSheetTransmittance(m, cosO, R);
      float pR = (R.x + R.y + R.z) / 3.0;
      if (u.x < pR) {
        s.wi = vec3(-wo.x, -wo.y, wo.z);
        s.weight = m.roughness > 0.0 ? R / pR : vec3(1.0);
        s.pdf = pR;
      } else {
        s.wi = -wo;
        s.weight = through / max(1.0 - pR, 1e-6);
        s.pdf = 1.0 - pR;
        s.transmitted = true;
      }
    } else if (u.x < F) {
      s.wi = vec3(-wo.x, -wo.y, wo.z);
      s.weight = m.tintsReflection ? m.albedo : vec3(1.0);
      s.pdf = F;
    } else {
      float inv = 1.0 / eta;
      s.wi = normalize(vec3(-wo.x * inv, -wo.y * inv, entering ? -cosT : cosT));
      // Radiance is compressed by 1/eta^2 on entering and expanded on leaving (not in Tungsten).
      s.weight = m.tintsReflection ? m.albedo : m.albedo * (inv * inv);
      s.pdf = 1.0 - F;
      s.transmitted = true;
    }
  } else if (isMat(t, kMatRoughDielectric)) {
    // For GGX f / pdf is G2 / G1 (/ eta^2 through the boundary), for Beckmann's D cos sampling
    // G2 (o.h) / (o.z h.z).
    bool entering = wo.z > 0.0;
    float eta = entering ? m.ior : 1.0 / m.ior;
    vec3 o = entering ? wo : -wo;
    float oh = dot(o, h);
    float F = fresnelDielectric(oh, eta);
    vec3 i;
    if (u.z < F) {
      i = reflect(-o, h);
      evaluate = i.z > 0.0;
    } else {
      i = refract(-o, h, 1.0 / eta);
      evaluate = i.z < 0.0 && dot(i, i) != 0.0;
      s.transmitted = true;
    }
    evaluate = evaluate && o.z > 0.0 && oh > 0.0;
    s.wi = entering ? i : -i;
  } else if (isMat(t, kMatDiffuseTransmission)) {
    s.wi = sampleCosineHemisphere(u.xy);
    s.transmitted = u.z < m.fdrInt;
    s.wi.z = (wo.z > 0.0) != s.transmitted ? s.wi.z : -s.wi.z;
    evaluate = wo.z != 0.0 && s.wi.z != 0.0;
  } else if (wo.z > 0.0) {
    if (isMat(t, kMatPhong) && u.z >= m.fdrInt) {
      // The lobe: cos of the angle to the mirror direction drawn as u^(1 / (n + 1)).
      float ct = pow(u.x, 1.0 / (phongExponent(m) + 1.0)), st = sqrt(max(0.0, 1.0 - ct * ct)), phi = 2.0 * PI * u.y;
      vec3 r = vec3(-wo.xy, wo.z), ta, tb;
      makeFrame(r, ta, tb);
      s.wi = ta * (st * cos(phi)) + tb * (st * sin(phi)) + r * ct;
      evaluate = s.wi.z > 0.0;
    } else if (isMat(t, kMatMirror) || isMat(t, kMatConductor)) {
      s.wi = vec3(-wo.x, -wo.y, wo.z);
      s.weight = isMat(t, kMatConductor) ? m.albedo * fresnelConductor(wo.z, m.eta, m.k) : m.albedo;
      s.pdf = 1.0;
      s.delta = true;
    } else if (isMat(t, kMatPlastic) && u.z < ps) {
      s.wi = vec3(-wo.x, -wo.y, wo.z);
      s.weight = vec3(fresnelDielectric(wo.z, m.ior) / ps);
      s.pdf = ps;
      s.delta = true;
    } else {
      // A microfacet reflection (rough conductor, rough plastic's specular part; for a rough
      // conductor f / pdf is F G2 / G1 with GGX) or the cosine-weighted hemisphere (lambert,
      // Oren-Nayar, the plastics' diffuse part).
      bool microfacet = isMat(t, kMatRoughConductor) || (isMat(t, kMatRoughPlastic) && u.z < ps);
      s.wi = microfacet ? reflect(-wo, h) : sampleCosineHemisphere(u.xy);
      evaluate = s.wi.z > 0.0;
    }
  }
  if (evaluate) {
    float p;
    vec3 f = baseEval(m, wo, s.wi, p);
    s.pdf = p;
    s.weight = p > 0.0 ? f / p : vec3(0.0);
  }
  return s;
}

// The clear coat (Material::coatIor), after Tungsten's smooth_coat: a delta reflection of F(wo)
// drawn with probability F / (F + (1 - F) T), T the coat's transmittance straight down and back;
// otherwise the material below, seen through the coat with both directions refracted. Its
// f cos is (1 - F(wo)) (1 - F(wi)) exp(-a (1 / cos wo' + 1 / cos wi')) f'(wo', wi') cos wi' times
// the solid angle's change cos wi / (ior^2 cos wi'), primes inside the coat: symmetric in wo and wi.
// A rough coat (Tungsten's rough_coat) reflects a GGX lobe instead of the delta, F D G1 G1 /
// (4 cos wo), drawn by its visible normals. (Tungsten's eval has this; its sampling of the base
// under a rough coat weighs by cos wo / cos wo' more, which its eval and the smooth coat do not.)
float coatSpecularProbability(Material m, float fo) {
  float t = exp(-2.0 * dot(m.coatAbsorption, vec3(1.0 / 3.0)));
  // Kept below 1 so that the base is drawn however much the coat absorbs: eval still counts it.
  return min(fo / (fo + (1.0 - fo) * t), 0.95);
}

vec3 bsdfEval(Material m, vec3 wo, vec3 wi, out float pdf) {
  if (!kCoatUsed || m.coatIor <= 1.0) return baseEval(m, wo, wi, pdf);
  pdf = 0.0;
  if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
  float inv = 1.0 / m.coatIor, co, ci;
  float fo = fresnelDielectric(wo.z, m.coatIor, co), fi = fresnelDielectric(wi.z, m.coatIor, ci);
  float p;
  vec3 f = baseEval(m, vec3(wo.xy * inv, co), vec3(wi.xy * inv, ci), p);
  float jacobian = inv * inv * wi.z / ci;
  float ps = coatSpecularProbability(m, fo);
  pdf = (1.0 - ps) * p * jacobian;
  f *= exp(-m.coatAbsorption * (1.0 / co + 1.0 / ci)) * ((1.0 - fo) * (1.0 - fi) * jacobian);
  float a = m.coatRoughness;
  if (a > 0.0) {
    vec3 h = normalize(wo + wi);
    float oh = dot(wo, h);
    float d = ggxD(h, a), g1o = ggxG1(wo, a);
    pdf += ps * d * g1o / (4.0 * wo.z);
    f += vec3(fresnelDielectric(oh, m.coatIor) * d * g1o * ggxG1(wi, a) / (4.0 * wo.z));
  }
  return f;
}

BsdfSample bsdfSample(Material m, vec3 wo, vec3 u) {
  if (!kCoatUsed || m.coatIor <= 1.0) return baseSample(m, wo, u);
  BsdfSample s = noSample();
  if (wo.z <= 0.0) return s;
  float inv = 1.0 / m.coatIor, co;
  float fo = fresnelDielectric(wo.z, m.coatIor, co);
  float ps = coatSpecularProbability(m, fo);
  bool coatLobe = u.z < ps;
  if (coatLobe && m.coatRoughness <= 0.0) {
    s.wi = vec3(-wo.xy, wo.z);
    s.weight = vec3(fo / ps);
    s.pdf = ps;
    s.delta = true;
    return s;
  }
  // One call of each below, whichever lobe is drawn: lavapipe runs every branch, and each call
  // inlines the code of every material type. What is left of u.z is uniform again, for the base's
  // own choice of lobe.
  BsdfSample b = baseSample(m, vec3(wo.xy * inv, co), vec3(u.xy, coatLobe ? 0.5 : (u.z - ps) / (1.0 - ps)));
  float ci = b.wi.z, cOut;
  float fi = fresnelDielectric(max(ci, 0.0), inv, cOut);
  // A base sample the coat reflects back inside is lost, as in Tungsten.
  bool through = maxComponent(b.weight) > 0.0 && ci > 0.0 && fi < 1.0;
  s.wi = coatLobe ? reflect(-wo, sampleGgxVisibleNormal(wo, m.coatRoughness, u.xy)) : normalize(vec3(b.wi.xy * m.coatIor, cOut));
  if (!coatLobe && through && b.delta) {
    s.delta = true;
    s.pdf = b.pdf * (1.0 - ps);
    s.weight = b.weight * exp(-m.coatAbsorption * (1.0 / co + 1.0 / ci)) * ((1.0 - fo) * (1.0 - fi) / (1.0 - ps));
    return s;
  }
  // The rough coat's lobe and the base's share of each direction are weighed together.
  float p = 0.0;
  vec3 f = (coatLobe || through) && s.wi.z > 0.0 ? bsdfEval(m, wo, s.wi, p) : vec3(0.0);
  s.pdf = p;
  s.weight = p > 0.0 ? f / p : vec3(0.0);
  return s;
}

#endif
