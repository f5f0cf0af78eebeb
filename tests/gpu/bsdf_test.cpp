// The renderer's BSDFs (shaders/common/bsdf.glsl, run on the device through BsdfProbe) held to
// their definitions, material by material (issue 15): sampling and evaluation agree (the sampled
// pdf is the evaluated one and the weight is f / pdf), the pdf integrates to the fraction of
// samples that succeed, the directional albedo that sampling estimates equals an independent
// quadrature of eval over the sphere, reflection is reciprocal, and lossless materials keep
// every bit of energy (white furnace).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "gpu_support.h"
#include "render/bsdf_probe.h"

namespace retile {
namespace {

Vec3 direction(float cosTheta, float phi) {
  float s = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
  return {s * std::cos(phi), s * std::sin(phi), cosTheta};
}

Material material(MaterialType type, float albedo, float roughness = 0.3f, float ior = 1.5f) {
  Material m;
  m.type = type;
  m.albedo = Vec3{albedo};
  m.roughness = roughness;
  m.ior = ior;
  m.metal = "Al";
  return m;
}

// Tungsten's hair: the fibre runs along x in the probe's frame (its h is the query's).
Material hair(float roughness, float absorption, float tilt = 2.0f) {
  Material m;
  m.type = MaterialType::Hair;
  m.roughness = roughness;
  m.coatingAbsorption = Vec3{absorption};
  m.hairTilt = tilt;
  return m;
}

Material beckmann(Material m) {
  m.beckmann = true;
  return m;
}

Material separable(Material m) {
  m.separableShadowing = true;
  return m;
}

Material tintsReflection(Material m) {
  m.tintsReflection = true;
  return m;
}

Material coated(Material m, float absorption) {
  m.coatingAbsorption = Vec3{absorption};
  return m;
}

Material phong(float albedo, float roughness, float diffuseRatio) {
  Material m = material(MaterialType::Phong, albedo, roughness);
  m.diffuseRatio = diffuseRatio;
  return m;
}

Material transmitting(float albedo, float transmittance) {
  Material m = material(MaterialType::DiffuseTransmission, albedo);
  m.transmittance = transmittance;
  return m;
}

Material clearCoated(Material m, float ior = 1.5f, float absorption = 0.0f) {
  m.coatIor = ior;
  m.coatAbsorption = Vec3{absorption};
  return m;
}

Material roughCoated(Material m, float alpha, float ior = 1.5f) {
  m.coatIor = ior;
  m.coatRoughness = alpha;
  return m;
}

// Unpolarised Fresnel reflectance from outside a dielectric of index eta at cos c.
double fresnel(double c, double eta) {
  const double s2 = (1 - c * c) / (eta * eta), ct = std::sqrt(1 - s2);
  const double rs = (c - eta * ct) / (c + eta * ct), rp = (eta * c - ct) / (eta * c + ct);
  return 0.5 * (rs * rs + rp * rp);
}

struct Case {
  const char* name;
  Material m;
};

// The materials with a lobe that is not a delta, with roughness wide enough for a 256 x 512
// quadrature of the sphere to resolve.
std::vector<Case> smoothLobed() {
  return {{"lambert", material(MaterialType::Lambert, 0.8f)},
          {"oren_nayar", material(MaterialType::OrenNayar, 0.8f, 0.5f)},
          {"plastic", material(MaterialType::Plastic, 0.8f)},
          {"rough_plastic", material(MaterialType::RoughPlastic, 0.8f, 0.3f)},
          {"rough_conductor", material(MaterialType::RoughConductor, 1.0f, 0.3f)},
          {"rough_dielectric", material(MaterialType::RoughDielectric, 1.0f, 0.3f)},
          {"rough_plastic_beckmann", beckmann(material(MaterialType::RoughPlastic, 0.8f, 0.4f))},
          {"rough_conductor_beckmann", beckmann(material(MaterialType::RoughConductor, 1.0f, 0.3f))},
          {"rough_dielectric_beckmann", beckmann(material(MaterialType::RoughDielectric, 1.0f, 0.3f))},
          {"rough_conductor_separable", separable(material(MaterialType::RoughConductor, 1.0f, 0.3f))},
          {"rough_dielectric_separable", separable(material(MaterialType::RoughDielectric, 1.0f, 0.3f))},
          {"rough_dielectric_tungsten", tintsReflection(material(MaterialType::RoughDielectric, 0.8f, 0.3f))},
          {"rough_plastic_beckmann_separable", separable(beckmann(material(MaterialType::RoughPlastic, 0.8f, 0.4f)))},
          {"plastic_absorbing", coated(material(MaterialType::Plastic, 0.8f), 0.3f)},
          {"rough_plastic_absorbing", coated(material(MaterialType::RoughPlastic, 0.8f, 0.3f), 0.3f)},
          {"phong", phong(0.8f, 0.3f, 0.2f)},
          {"phong_narrow", phong(0.8f, 0.12f, 0.0f)},
          {"diffuse_transmission", transmitting(0.8f, 0.3f)},
          {"hair", hair(0.3f, 0.4f)},
          {"hair_dark", hair(0.5f, 3.0f, -5.0f)},
          {"coated_lambert", clearCoated(material(MaterialType::Lambert, 0.8f))},
          {"coated_rough_conductor", clearCoated(material(MaterialType::RoughConductor, 1.0f, 0.3f), 1.4f, 0.2f)},
          {"coated_rough_plastic", clearCoated(material(MaterialType::RoughPlastic, 0.6f, 0.4f), 1.3f)},
          {"rough_coated_lambert", roughCoated(material(MaterialType::Lambert, 0.8f), 0.3f)},
          {"rough_coated_rough_conductor", roughCoated(material(MaterialType::RoughConductor, 1.0f, 0.2f), 0.4f, 1.4f)}};
}

class Bsdfs : public ::testing::Test {
 protected:
  void SetUp() override {
    RETILE_RENDERER_OR_SKIP(r);
    ctx_ = std::make_unique<vk::Context>();
    probe_ = std::make_unique<BsdfProbe>(*ctx_);
  }
  std::vector<BsdfAnswer> run(const std::vector<BsdfQuery>& q) { return probe_->run(q); }

  // Runs `count` queries, make(i) making the i-th, in batches that reuse their memory (a whole
  // quadrature at once is 100 MB of queries, and most of its time went to faulting pages in),
  // and gives each answer to use(answer) in order.
  template <class Make, class Use>
  void runBatched(int count, Make make, Use use) {
    constexpr int kBatch = 16384;
    std::vector<BsdfQuery> q;
    q.reserve(kBatch);
    for (int start = 0; start < count; start += kBatch) {
      q.clear();
      for (int i = start; i < std::min(count, start + kBatch); ++i) q.push_back(make(i));
      for (const BsdfAnswer& a : run(q)) use(a);
    }
  }

  // Sampling estimate of the directional albedo (mean weight over stratified u), and the
  // fraction of samples that succeeded.
  std::pair<double, double> sampledAlbedo(const Material& m, Vec3 wo, int n = 256) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    double sum = 0, ok = 0;
    runBatched(
        n * n,
        [&](int k) {
          const int i = k / n, j = k % n;
          const float u = (i + U(rng)) / n, v = (j + U(rng)) / n;
          return BsdfQuery{m, wo, wo, {u, v, U(rng)}};
        },
        [&](const BsdfAnswer& a) {
          sum += luminance(a.weight);
          ok += maxComponent(a.weight) > 0.0f;
        });
    return {sum / (static_cast<double>(n) * n), ok / (static_cast<double>(n) * n)};
  }

  // Midpoint quadrature over the whole sphere in (cos theta, phi), or the upper hemisphere alone:
  // the integral of eval's f * |cos| and of its pdf.
  std::pair<double, double> integrated(const Material& m, Vec3 wo, bool upperOnly = false, int nt = 256, int np = 512) {
    const int first = upperOnly ? nt : 0;
    const double cell = (1.0 / nt) * (2.0 * kPi / np);
    double f = 0, pdf = 0;
    runBatched((2 * nt - first) * np,
               [&](int k) {
                 const int i = first + k / np, j = k % np;
                 return BsdfQuery{m, wo, direction(-1.0f + (i + 0.5f) / nt, 2.0f * kPi * (j + 0.5f) / np), Vec3{0.5f}};
               },
               [&](const BsdfAnswer& a) {
                 f += luminance(a.f) * cell;
                 pdf += a.pdf * cell;
               });
    return {f, pdf};
  }

  // A case's sampled albedo and share of samples that succeed, and the quadrature of its f and
  // pdf, at one angle of view. Two tests hold them to each other; each costs 330,000 queries on
  // lavapipe, so they are made once for the whole suite.
  struct Estimates {
    double sampled = 0, succeeded = 0, quadratureF = 0, quadraturePdf = 0;
  };
  const Estimates& estimates(std::size_t caseIndex, const Material& m, float cosO) {
    static std::map<std::pair<std::size_t, float>, Estimates> made;
    auto [it, isNew] = made.try_emplace({caseIndex, cosO});
    if (isNew) {
      const Vec3 wo = direction(cosO, 0.3f);
      std::tie(it->second.sampled, it->second.succeeded) = sampledAlbedo(m, wo);
      std::tie(it->second.quadratureF, it->second.quadraturePdf) = integrated(m, wo);
    }
    return it->second;
  }
  static constexpr float kAlbedoCosines[] = {0.9f, 0.5f, 0.2f};

  std::unique_ptr<vk::Context> ctx_;
  std::unique_ptr<BsdfProbe> probe_;
};

TEST_F(Bsdfs, SampledPdfsAndWeightsAreWhatEvalGives) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (const Case& c : smoothLobed()) {
    std::vector<BsdfQuery> q;
    for (int i = 0; i < 4000; ++i)
      q.push_back({c.m, direction(0.05f + 0.95f * U(rng), 6.283f * U(rng)), Vec3{0, 0, 1}, {U(rng), U(rng), U(rng)}});
    int checked = 0;
    for (const auto& a : run(q)) {
      if (maxComponent(a.weight) <= 0.0f || a.delta) continue;
      ++checked;
      ASSERT_NEAR(a.sampledPdf, a.pdfAtSample, 1e-3f * a.pdfAtSample + 1e-6f) << c.name;
      Vec3 expected = a.fAtSample / a.sampledPdf;
      ASSERT_NEAR(luminance(a.weight), luminance(expected), 2e-3f * luminance(expected) + 1e-6f) << c.name;
    }
    // Under a clear coat, light the coat sends back inside is lost (as in Tungsten): at index 1.5
    // over a Lambert base more than half of the base's samples.
    EXPECT_GT(checked, c.m.coated() ? 1200 : 2000) << c.name;
  }
}

TEST_F(Bsdfs, PdfIntegratesToTheFractionOfSamplesThatSucceed) {
  const std::vector<Case> cases = smoothLobed();
  for (std::size_t i = 0; i < cases.size(); ++i)
    for (float cosO : kAlbedoCosines) {
      const Case& c = cases[i];
      const Estimates& e = estimates(i, c.m, cosO);
      // Plastic's delta coating is sampled but has no pdf in eval: its share is the rest.
      double deltaShare = 0;
      if (c.m.type == MaterialType::Plastic || (c.m.coated() && c.m.coatRoughness == 0)) {
        const Vec3 wo = direction(cosO, 0.3f);
        std::vector<BsdfQuery> q;
        for (int j = 0; j < 4096; ++j) q.push_back({c.m, wo, wo, {(j % 64 + 0.5f) / 64, (j / 64 + 0.5f) / 64, (j + 0.5f) / 4096}});
        for (const auto& a : run(q)) deltaShare += a.delta ? 1.0 / 4096 : 0.0;
      }
      EXPECT_NEAR(e.quadraturePdf, e.succeeded - deltaShare, 0.01) << c.name << " at cos " << cosO;
    }
}

TEST_F(Bsdfs, SamplingAndQuadratureAgreeOnTheDirectionalAlbedo) {
  const std::vector<Case> cases = smoothLobed();
  for (std::size_t i = 0; i < cases.size(); ++i)
    for (float cosO : kAlbedoCosines) {
      const Case& c = cases[i];
      const Estimates& e = estimates(i, c.m, cosO);
      const double sampled = e.sampled, quadrature = e.quadratureF;

      double delta = 0;  // smooth plastic's coating and a clear coat reflect F(cos) as a delta
      if (c.m.type == MaterialType::Plastic) delta = fresnel(cosO, c.m.ior);
      if (c.m.coated() && c.m.coatRoughness == 0) delta = fresnel(cosO, c.m.coatIor);
      EXPECT_NEAR(sampled, quadrature + delta, 0.01 * (quadrature + delta) + 0.002) << c.name << " at cos " << cosO;
    }
}

// Beckmann against GGX where they differ (a microfacet normal 37 degrees off the surface normal,
// alpha 0.3): the two evals' ratio is D_B G2_B / (D_G G2_G), computed here from the papers'
// formulas (Walter et al. 2007: Beckmann's D and the rational fit of its Smith Lambda; GGX's D
// and Lambda), about a tenth. The Fresnel factor is the same for both and cancels.
TEST_F(Bsdfs, BeckmannIsBeckmannsDistribution) {
  const double a = 0.3, cosH = 0.8, sinH = 0.6;
  const Vec3 wo{0, 0, 1};
  const Vec3 wi{static_cast<float>(2 * cosH * sinH), 0, static_cast<float>(2 * cosH * cosH - 1)};  // wo mirrored about h
  const double tan2H = sinH * sinH / (cosH * cosH);
  const double dBeckmann = std::exp(-tan2H / (a * a)) / (kPi * a * a * std::pow(cosH, 4));
  const double dGgx = a * a / (kPi * std::pow(cosH * cosH * (a * a - 1) + 1, 2));
  const double tanI = std::sqrt(1 - wi.z * wi.z) / wi.z, x = 1 / (a * tanI);
  const double lambdaBeckmann = (1 - 1.259 * x + 0.396 * x * x) / (3.535 * x + 2.181 * x * x);
  const double lambdaGgx = 0.5 * (-1 + std::sqrt(1 + a * a * tanI * tanI));
  const double expected = dBeckmann / (1 + lambdaBeckmann) / (dGgx / (1 + lambdaGgx));
  for (MaterialType t : {MaterialType::RoughConductor, MaterialType::RoughDielectric}) {
    Material ggx = material(t, 1.0f, static_cast<float>(a));
    auto r = run({{ggx, wo, wi, Vec3{0.5f}}, {beckmann(ggx), wo, wi, Vec3{0.5f}}});
    ASSERT_GT(luminance(r[0].f), 0.0f);
    EXPECT_NEAR(luminance(r[1].f) / luminance(r[0].f), expected, 0.002 * expected) << materialTypeName(t);
    EXPECT_LT(expected, 0.2);
  }
}

// Tungsten's Smith shadowing against the height-correlated form, at a grazing pair of directions
// where they differ (alpha 0.5): the evals' ratio is (1 + Lo + Li) / ((1 + Lo)(1 + Li)), from
// GGX's Lambda; D and Fresnel are the same and cancel. For GGX and Beckmann, both reflecting
// types and transmission.
TEST_F(Bsdfs, SeparableShadowingIsTheProductOfBothG1) {
  const double a = 0.5;
  const Vec3 wo = direction(0.25f, 0.0f), wi = direction(0.3f, kPi * 0.8f), wt = direction(-0.3f, kPi * 0.8f);
  auto lambda = [&](Vec3 w, bool beck) {
    const double t = std::sqrt(1 - w.z * w.z) / std::abs(w.z);
    if (!beck) return 0.5 * (-1 + std::sqrt(1 + a * a * t * t));
    const double x = 1 / (a * t);
    return x < 1.6 ? (1 - 1.259 * x + 0.396 * x * x) / (3.535 * x + 2.181 * x * x) : 0.0;
  };
  struct Probe {
    MaterialType type;
    bool beck;
    Vec3 wi;
  };
  for (Probe p : {Probe{MaterialType::RoughConductor, false, wi}, Probe{MaterialType::RoughConductor, true, wi},
                  Probe{MaterialType::RoughPlastic, false, wi}, Probe{MaterialType::RoughDielectric, false, wi},
                  Probe{MaterialType::RoughDielectric, false, wt}}) {
    SCOPED_TRACE(std::string(materialTypeName(p.type)) + (p.beck ? " beckmann" : "") + (p.wi.z < 0 ? " transmitted" : ""));
    Material m = material(p.type, 1.0f, static_cast<float>(a));
    m.beckmann = p.beck;
    // Rough plastic adds its diffuse base: make it black so that only the coating's lobe counts.
    if (p.type == MaterialType::RoughPlastic) m.albedo = Vec3{0.0f};
    const double lo = lambda(wo, p.beck), li = lambda(p.wi, p.beck);
    const double expected = (1 + lo + li) / ((1 + lo) * (1 + li));
    auto r = run({{m, wo, p.wi, Vec3{0.5f}}, {separable(m), wo, p.wi, Vec3{0.5f}}});
    ASSERT_GT(luminance(r[0].f), 0.0f);
    EXPECT_NEAR(luminance(r[1].f) / luminance(r[0].f), expected, 0.002 * expected);
    EXPECT_LT(expected, p.beck ? 0.99 : 0.9) << "the directions are grazing enough for the forms to differ";
    EXPECT_NEAR(r[1].pdf, r[0].pdf, 1e-6 * r[0].pdf) << "shadowing changes the value, not how directions are drawn";
  }
}

TEST_F(Bsdfs, ReflectionIsReciprocal) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (const Case& c : smoothLobed()) {
    // Tungsten's hair is not reciprocal: its lobes are shifted about wo's cone and its azimuths
    // measured from wo, at the h where wo meets the fibre.
    if (c.m.type == MaterialType::Hair) continue;
    std::vector<BsdfQuery> q;
    for (int i = 0; i < 2000; ++i) {
      Vec3 a = direction(0.05f + 0.95f * U(rng), 6.283f * U(rng)), b = direction(0.05f + 0.95f * U(rng), 6.283f * U(rng));
      q.push_back({c.m, a, b, Vec3{0.5f}});
      q.push_back({c.m, b, a, Vec3{0.5f}});
    }
    auto r = run(q);
    for (std::size_t i = 0; i < q.size(); i += 2) {
      float ab = luminance(r[i].f) / q[i].wi.z, ba = luminance(r[i + 1].f) / q[i + 1].wi.z;
      ASSERT_NEAR(ab, ba, 1e-3f * std::max(ab, ba) + 1e-6f) << c.name;
    }
  }
}

TEST_F(Bsdfs, AnAbsorbingCoatingDimsTheBaseAlongBothPaths) {
  // Tungsten's plastic: the diffuse base seen through a coating of absorption a (sigma_a times
  // thickness) is dimmed by exp(-a (1 / cos wo + 1 / cos wi)); the coating's own reflection is
  // not. The base alone is the material less the same material over a black base.
  for (MaterialType type : {MaterialType::Plastic, MaterialType::RoughPlastic}) {
    const Material clear = material(type, 0.8f), black = material(type, 0.0f);
    std::vector<BsdfQuery> q;
    const std::pair<float, float> angles[] = {{0.9f, 0.8f}, {0.5f, 0.3f}, {0.2f, 0.7f}};
    for (auto [co, ci] : angles) {
      Vec3 wo = direction(co, 0.4f), wi = direction(ci, 2.5f);
      q.push_back({clear, wo, wi});
      q.push_back({coated(clear, 0.25f), wo, wi});
      q.push_back({black, wo, wi});
      q.push_back({coated(black, 0.25f), wo, wi});
    }
    auto a = run(q);
    for (std::size_t k = 0; k < std::size(angles); ++k) {
      const auto [co, ci] = angles[k];
      const double base = a[4 * k].f.y - a[4 * k + 2].f.y, dimmed = a[4 * k + 1].f.y - a[4 * k + 3].f.y;
      EXPECT_NEAR(a[4 * k + 3].f.y, a[4 * k + 2].f.y, 1e-6) << "the coating's reflection is not absorbed";
      ASSERT_GT(base, 0.01);
      EXPECT_NEAR(dimmed / base, std::exp(-0.25 * (1.0 / co + 1.0 / ci)), 1e-4) << "cos " << co << ", " << ci;
    }
  }
}

TEST_F(Bsdfs, LosslessMaterialsKeepAllEnergy) {
  // Sampled directional albedo at three angles. A white mirror and a thin sheet return
  // everything; glass returns everything counted in flux (transmitted radiance is scaled by
  // 1/eta^2 on entering, so entering reflects F and transmits (1 - F) / eta^2); smooth plastic
  // of albedo 1 loses nothing either, if its internal reflectance (fdrInt) is consistent with
  // its Fresnel terms (Jensen's fit: within 1 %).
  for (float cosO : {0.9f, 0.5f, 0.2f}) {
    Vec3 wo = direction(cosO, 0.3f);
    const double eta = 1.5, s2 = (1 - cosO * cosO) / (eta * eta), ct = std::sqrt(1 - s2);
    const double rs = (cosO - eta * ct) / (cosO + eta * ct), rp = (eta * cosO - ct) / (eta * cosO + ct);
    const double F = 0.5 * (rs * rs + rp * rp);
    EXPECT_NEAR(sampledAlbedo(material(MaterialType::Mirror, 1.0f), wo).first, 1.0, 1e-4);
    EXPECT_NEAR(sampledAlbedo(material(MaterialType::ThinSheet, 1.0f), wo).first, 1.0, 1e-4);
    EXPECT_NEAR(sampledAlbedo(material(MaterialType::Dielectric, 1.0f), wo).first, F + (1 - F) / (eta * eta), 0.003);
    EXPECT_NEAR(sampledAlbedo(material(MaterialType::Plastic, 1.0f), wo).first, 1.0, 0.01) << "cos " << cosO;
    // Over a black base the coating reflects F alone; so does a metal of index 1.5 + 0i, which
    // is how Tungsten's dielectric without refraction is imported, tinted by its albedo.
    EXPECT_NEAR(sampledAlbedo(material(MaterialType::Plastic, 0.0f), wo).first, F, 1e-3) << "cos " << cosO;
    Material reflector = material(MaterialType::Conductor, 0.7f);
    reflector.metal = "custom";
    reflector.eta = Vec3{1.5f};
    reflector.k = Vec3{0.0f};
    EXPECT_NEAR(sampledAlbedo(reflector, wo).first, 0.7 * F, 1e-5) << "cos " << cosO;
  }
}

// Glass less dense than what surrounds it (an air bubble in ice: its ior the ratio, below 1)
// reflects everything past its critical angle, asin(ior), and before it reflects F and refracts
// the rest, radiance expanded by 1 / ior^2 on the less dense side.
TEST_F(Bsdfs, GlassLessDenseThanItsSurroundingsReflectsTotallyPastItsCriticalAngle) {
  const double eta = 0.763;
  const Material bubble = material(MaterialType::Dielectric, 1.0f, 0.3f, static_cast<float>(eta));
  const Vec3 grazing = direction(0.3f, 0.3f);  // sin 0.95, past asin(0.763)
  std::vector<BsdfQuery> q;
  for (int i = 0; i < 64; ++i) q.push_back(BsdfQuery{bubble, grazing, grazing, {(i + 0.5f) / 64, 0.5f, 0.5f}});
  for (const BsdfAnswer& a : run(q)) {
    EXPECT_FALSE(a.transmitted);
    EXPECT_NEAR(a.weight.y, 1.0, 1e-5);
    EXPECT_NEAR(a.sampledWi.z, grazing.z, 1e-5);
  }
  for (float cosO : {0.9f, 0.8f}) {
    const Vec3 wo = direction(cosO, 0.3f);
    EXPECT_NEAR(sampledAlbedo(bubble, wo).first, fresnel(cosO, eta) + (1 - fresnel(cosO, eta)) / (eta * eta), 0.003) << "cos " << cosO;
  }
}

// Tungsten's glass (Material::tintsReflection): its albedo tints both lobes, and radiance is not
// scaled by eta^2 through the surface, so that white glass returns exactly everything from either
// side, where the physical form returns F + (1 - F) / eta^2 from outside. The rough one's
// transmission is the physical one's times eta^2 (eta = n_i / n_o: the index wi is in over
// wo's), its reflection the physical one's times albedo; its pdf is the same.
TEST_F(Bsdfs, TungstensGlassTintsBothLobesAndKeepsRadiance) {
  const double eta = 1.5;
  for (float cosO : {0.9f, 0.5f, 0.2f})
    for (float side : {1.0f, -1.0f}) {
      SCOPED_TRACE(testing::Message() << "cos " << cosO << (side > 0 ? " outside" : " inside"));
      Vec3 wo = direction(side * cosO, 0.3f);
      EXPECT_NEAR(sampledAlbedo(tintsReflection(material(MaterialType::Dielectric, 1.0f)), wo).first, 1.0, 1e-5);
      EXPECT_NEAR(sampledAlbedo(tintsReflection(material(MaterialType::Dielectric, 0.6f)), wo).first, 0.6, 1e-5);
      if (side > 0) {
        EXPECT_NEAR(sampledAlbedo(material(MaterialType::Dielectric, 0.6f), wo).first,
                    fresnel(cosO, eta) + 0.6 * (1 - fresnel(cosO, eta)) / (eta * eta), 0.003);
      }
    }
  const Material physical = material(MaterialType::RoughDielectric, 0.6f, 0.3f), tungsten = tintsReflection(physical);
  struct Pair {
    Vec3 wo, wi;
    double ratio;
  };
  const Vec3 out = direction(0.7f, 0.2f), in = direction(-0.7f, 0.2f);
  for (Pair p : {Pair{out, direction(-0.6f, 3.0f), eta * eta}, Pair{in, direction(0.6f, 3.0f), 1 / (eta * eta)},
                 Pair{out, direction(0.6f, 3.0f), 0.6}, Pair{in, direction(-0.6f, 3.0f), 0.6}}) {
    auto r = run({{physical, p.wo, p.wi, Vec3{0.5f}}, {tungsten, p.wo, p.wi, Vec3{0.5f}}});
    ASSERT_GT(luminance(r[0].f), 0.0f);
    EXPECT_NEAR(luminance(r[1].f) / luminance(r[0].f), p.ratio, 1e-4 * p.ratio) << p.wo.z << " -> " << p.wi.z;
    EXPECT_NEAR(r[1].pdf, r[0].pdf, 1e-6 * r[0].pdf);
  }
}

// A thin sheet reflects R, each polarisation's 2R / (1 + R) averaged (Tungsten's thin sheet), and
// passes the rest dimmed by exp(-a / cos t), a its absorption (Material::coatingAbsorption) and
// t the angle inside the sheet. Measured with a sheet that absorbs all it passes (R alone) and
// one that absorbs a little.
TEST_F(Bsdfs, AThinSheetReflectsEachPolarisationsShareAndAbsorbsAlongItsPath) {
  const double eta = 1.5;
  for (float cosO : {0.9f, 0.5f, 0.15f}) {
    const double s2 = (1 - cosO * cosO) / (eta * eta), ct = std::sqrt(1 - s2);
    const double rs = (cosO - eta * ct) / (cosO + eta * ct), rp = (eta * cosO - ct) / (eta * cosO + ct);
    const double Rs = rs * rs, Rp = rp * rp, R = Rs / (1 + Rs) + Rp / (1 + Rp);
    const double F = fresnel(cosO, eta);
    Vec3 wo = direction(cosO, 0.3f);
    Material opaque = coated(material(MaterialType::ThinSheet, 1.0f), 60.0f), thin = coated(material(MaterialType::ThinSheet, 1.0f), 0.3f);
    EXPECT_NEAR(sampledAlbedo(opaque, wo).first, R, 5e-4) << "cos " << cosO;
    EXPECT_NEAR(sampledAlbedo(thin, wo).first, R + (1 - R) * std::exp(-0.3 / ct), 5e-4) << "cos " << cosO;
    if (cosO < 0.2f) {
      EXPECT_GT(2 * F / (1 + F) - R, 0.01) << "the averaged form would differ measurably here";
    }
  }
}

// Over a film (Material::filmThickness, nm) a thin sheet reflects by channel: each polarisation
// passes (1 - R)^2 / (1 + R^2 - 2 R cos phi) (Airy's), or as Tungsten has it
// (1 - R)^2 / sqrt(1 + R^4 - 2 R^2 cos phi), phi = 4 pi n d cos t / lambda at 650, 510 and
// 475 nm. Sampled per channel from a sheet that absorbs all it passes, at three angles and two
// films; no film reflects as the plain sheet, which is also Airy's mean over the phase.
TEST_F(Bsdfs, AThinFilmReflectsEachChannelByItsPhase) {
  const double eta = 1.33;
  const double lambda[3] = {650, 510, 475};
  for (bool tungsten : {false, true})
    for (float film : {0.0f, 300.0f, 820.0f}) {
      for (float cosO : {0.95f, 0.6f, 0.25f}) {
        const double s2 = (1 - cosO * cosO) / (eta * eta), ct = std::sqrt(1 - s2);
        const double rs = (cosO - eta * ct) / (cosO + eta * ct), rp = (eta * cosO - ct) / (eta * cosO + ct);
        const double Rs = rs * rs, Rp = rp * rp;
        Material m = coated(material(MaterialType::ThinSheet, 1.0f), 60.0f);
        m.ior = static_cast<float>(eta);
        m.filmThickness = film;
        m.tintsReflection = tungsten;
        const Vec3 wo = direction(cosO, 0.3f);
        std::vector<BsdfQuery> q;
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> U(0.0f, 1.0f);
        const int n = 4096;
        for (int i = 0; i < n; ++i) q.push_back({m, wo, wo, {(i + U(rng)) / n, U(rng), U(rng)}});
        double sum[3] = {0, 0, 0};
        for (const auto& a : run(q))
          for (int c = 0; c < 3; ++c) sum[c] += (c == 0 ? a.weight.x : c == 1 ? a.weight.y : a.weight.z) / n;
        for (int c = 0; c < 3; ++c) {
          const double cosPhi = std::cos(4 * kPi * eta * film * ct / lambda[c]);
          auto passes = [&](double R) {
            return tungsten ? (1 - R) * (1 - R) / std::sqrt(1 + R * R * R * R - 2 * R * R * cosPhi)
                            : (1 - R) * (1 - R) / (1 + R * R - 2 * R * cosPhi);
          };
          // No film is the plain sheet.
          const double expected = film == 0.0f ? Rs / (1 + Rs) + Rp / (1 + Rp) : 1 - 0.5 * (passes(Rs) + passes(Rp));
          EXPECT_NEAR(sum[c], expected, 2e-3) << (tungsten ? "Tungsten's" : "Airy's") << ", film " << film << " nm, cos " << cosO
                                              << ", channel " << c;
          // A film that absorbs nothing passes what it does not reflect, in every channel.
          if (film > 0.0f) {
            Material clear = m;
            clear.coatingAbsorption = Vec3{0.0f};
            std::vector<BsdfQuery> cq;
            // Stratified in the choice between the two, finely: a channel's weight differs from its
            // mean's by R / pR, so an imbalance of one sample in k shows as about 1 / k.
            const int k = 65536;
            for (int i = 0; i < k; ++i) cq.push_back({clear, wo, wo, {(i + 0.5f) / k, 0.5f, 0.5f}});
            double both = 0;
            for (const auto& ans : run(cq)) both += (c == 0 ? ans.weight.x : c == 1 ? ans.weight.y : ans.weight.z) / k;
            EXPECT_NEAR(both, 1.0, 1e-4) << "reflected and passed, channel " << c;
          }
          if (film > 0.0f && !tungsten) {
            // Airy's mean over the phase is the plain sheet's: numerically, over a period.
            double mean = 0;
            for (int k = 0; k < 720; ++k) {
              const double cp = std::cos(2 * kPi * (k + 0.5) / 720);
              auto airy = [&](double R) { return (1 - R) * (1 - R) / (1 + R * R - 2 * R * cp); };
              mean += (1 - 0.5 * (airy(Rs) + airy(Rp))) / 720;
            }
            EXPECT_NEAR(mean, Rs / (1 + Rs) + Rp / (1 + Rp), 1e-7);
          }
        }
      }
    }
}

// Tungsten's Phong (PhongBsdf): f cos = albedo cos(wi) (r / pi + (1 - r) (n + 2) / (2 pi)
// cos^n(alpha)), alpha the angle between wi and wo's mirror direction, r the diffuse ratio, the
// lobe's part below the surface lost; its sampling density is r cos(wi) / pi + (1 - r) (n + 1) /
// (2 pi) cos^n(alpha). The exponent comes from the roughness a as 2 / a^2 - 2. At normal
// incidence the whole lobe is above the surface and white reflects exactly everything; at
// grazing incidence part of the lobe is cut off.
TEST_F(Bsdfs, PhongIsTungstensNormalisedLobe) {
  const float a = 0.2f;
  const double n = 2.0 / (a * a) - 2.0;  // 48
  const Vec3 wo = direction(0.6f, 0.0f);
  const Vec3 mirror{-wo.x, -wo.y, wo.z};
  const Vec3 wis[] = {direction(0.6f, kPi), direction(0.55f, kPi + 0.1f), direction(0.7f, kPi - 0.2f), direction(0.9f, 0.0f)};
  for (double ratio : {0.0, 0.3}) {
    SCOPED_TRACE(ratio);
    const Material white = phong(1.0f, a, static_cast<float>(ratio));
    std::vector<BsdfQuery> q;
    for (Vec3 wi : wis) q.push_back({white, wo, wi});
    auto r = run(q);
    for (std::size_t k = 0; k < std::size(wis); ++k) {
      const double c = std::max(0.0, static_cast<double>(dot(mirror, wis[k])));
      const double expected = ((1 - ratio) * (n + 2) / (2 * kPi) * std::pow(c, n) + ratio / kPi) * wis[k].z;
      const double pdf = (1 - ratio) * (n + 1) / (2 * kPi) * std::pow(c, n) + ratio * wis[k].z / kPi;
      EXPECT_NEAR(r[k].f.y, expected, 1e-3 * expected + 1e-7) << "direction " << k;
      EXPECT_NEAR(r[k].pdf, pdf, 1e-3 * pdf + 1e-7) << "direction " << k;
    }
    EXPECT_GT(r[0].f.y, 3.0f) << "the mirror direction is the lobe's peak";
    EXPECT_NEAR(sampledAlbedo(white, Vec3{0, 0, 1}).first, 1.0, 0.003);
  }
  EXPECT_LT(sampledAlbedo(phong(1.0f, 0.5f, 0.0f), direction(0.2f, 0.0f)).first, 0.8)
      << "a wide lobe at grazing incidence loses what falls below the surface";
  // Roughness 1 is the exponent 0: a uniform lobe over the mirror direction's hemisphere, nothing
  // (and no NaN) beyond it.
  const Vec3 wo2 = direction(0.5f, 0.0f), behind = direction(0.1f, 0.0f);
  auto r = run({{phong(1.0f, 1.0f, 0.0f), wo2, behind}, {phong(1.0f, 1.0f, 0.0f), wo2, direction(0.5f, kPi)}});
  EXPECT_EQ(r[0].f.y, 0.0f) << "the side of the mirror direction's plane away from it";
  EXPECT_NEAR(r[1].f.y, 2 / (2 * kPi) * 0.5, 1e-5);
}

// Tungsten's diffuse_transmission: Lambertian on both sides, a share t of albedo passed through and
// 1 - t reflected, whichever side the light comes from.
TEST_F(Bsdfs, DiffuseTransmissionSplitsLambertBetweenTheSides) {
  for (float side : {1.0f, -1.0f}) {
    const Vec3 wo = direction(0.7f * side, 0.4f);
    const Material m = transmitting(0.9f, 0.3f);
    auto r = run({{m, wo, direction(0.5f * side, 2.0f)}, {m, wo, direction(-0.5f * side, 2.0f)}});
    EXPECT_NEAR(r[0].f.y, 0.9 * 0.7 * 0.5 / kPi, 1e-5) << "reflected, side " << side;
    EXPECT_NEAR(r[1].f.y, 0.9 * 0.3 * 0.5 / kPi, 1e-5) << "transmitted, side " << side;
    std::vector<BsdfQuery> q;
    for (int i = 0; i < 4096; ++i)
      q.push_back({transmitting(1.0f, 0.3f), wo, wo, {(i % 64 + 0.5f) / 64, (i / 64 + 0.5f) / 64, (i + 0.5f) / 4096}});
    double through = 0, total = 0;
    for (const auto& a : run(q)) {
      total += luminance(a.weight) / 4096;
      if (a.sampledWi.z * wo.z < 0) {
        through += luminance(a.weight) / 4096;
        EXPECT_TRUE(a.transmitted);
      }
    }
    EXPECT_NEAR(total, 1.0, 1e-4) << "white: nothing is lost";
    EXPECT_NEAR(through, 0.3, 1e-3) << "the transmittance passes to the other side";
  }
}

// Tungsten's smooth_coat over a white Lambert base, no absorption: F(wo) reflected, and of the
// (1 - F(wo)) that enters, what leaves is the integral of (1 - F(wi)) cos wi / (pi ior^2) over
// the hemisphere, (2 / ior^2) times that of c (1 - F(c)) over c in [0, 1] (computed here by
// quadrature). Light the coat sends back inside is lost, as in Tungsten. Over a black base the
// coat alone reflects F; absorption dims what passes both ways.
TEST_F(Bsdfs, AClearCoatIsTungstensSmoothCoat) {
  const double ior = 1.5;
  double leave = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const double c = (i + 0.5) / n;
    leave += c * (1 - fresnel(c, ior)) / n;
  }
  leave *= 2 / (ior * ior);
  for (float cosO : {0.9f, 0.5f, 0.2f}) {
    const Vec3 wo = direction(cosO, 0.3f);
    const double F = fresnel(cosO, ior);
    // The coat's share is drawn with sampledAlbedo's unstratified u.z: a binomial error of up to
    // 0.0011 (one standard deviation) on 65536 samples.
    const Material white = clearCoated(material(MaterialType::Lambert, 1.0f));
    EXPECT_NEAR(sampledAlbedo(white, wo).first, F + (1 - F) * leave, 0.005) << "cos " << cosO;
    EXPECT_NEAR(integrated(white, wo).first, (1 - F) * leave, 0.003) << "eval, cos " << cosO;
    EXPECT_NEAR(sampledAlbedo(clearCoated(material(MaterialType::Lambert, 0.0f)), wo).first, F, 0.005) << "cos " << cosO;
  }
  EXPECT_LT(leave, 0.75) << "the coat keeps a real share inside";
  // Absorption a over a white mirror seen head on: F + (1 - F)^2 exp(-2 a), all of it a delta.
  const Material mirror = clearCoated(material(MaterialType::Mirror, 1.0f), 1.5f, 0.3f);
  const double F0 = fresnel(1.0, ior);
  EXPECT_NEAR(sampledAlbedo(mirror, Vec3{0, 0, 1}).first, F0 + (1 - F0) * (1 - F0) * std::exp(-0.6), 1e-3);
  auto r = run({{mirror, Vec3{0, 0, 1}, Vec3{0, 0, 1}, Vec3{0.5f, 0.5f, 0.99f}}});
  EXPECT_TRUE(r[0].delta);
  EXPECT_NEAR(r[0].sampledWi.z, 1.0f, 1e-5f) << "the mirror below reflects straight back out through the coat";
}

// Tungsten's rough_coat: the coat reflects as a rough dielectric's reflection lobe (GGX, both G1),
// and what is below is seen as through the smooth coat. A mirror under it keeps its delta.
TEST_F(Bsdfs, ARoughCoatIsTungstensRoughCoat) {
  const float a = 0.25f, ior = 1.5f;
  Material glass = separable(material(MaterialType::RoughDielectric, 1.0f, a, ior));
  const Material overBlack = roughCoated(material(MaterialType::Lambert, 0.0f), a, ior);
  const Material overWhite = roughCoated(material(MaterialType::Lambert, 1.0f), a, ior);
  const Material smoothOverWhite = clearCoated(material(MaterialType::Lambert, 1.0f), ior);
  const std::pair<float, float> angles[] = {{0.9f, 0.8f}, {0.5f, 0.45f}, {0.2f, 0.3f}};
  std::vector<BsdfQuery> q;
  for (auto [co, ci] : angles) {
    const Vec3 wo = direction(co, 0.0f), wi = direction(ci, kPi + 0.1f);
    for (const Material& m : {glass, overBlack, overWhite, smoothOverWhite}) q.push_back({m, wo, wi});
  }
  auto r = run(q);
  for (std::size_t k = 0; k < std::size(angles); ++k) {
    const double co = angles[k].first;
    const BsdfAnswer *dielectric = &r[4 * k], *black = &r[4 * k + 1], *white = &r[4 * k + 2], *smooth = &r[4 * k + 3];
    ASSERT_GT(dielectric->f.y, 0.0f);
    EXPECT_NEAR(black->f.y, dielectric->f.y, 1e-4 * dielectric->f.y) << "the coat's lobe, cos " << co;
    EXPECT_NEAR(white->f.y - black->f.y, smooth->f.y, 1e-4 * smooth->f.y) << "the base's share, cos " << co;
  }
  // Over a black base only the coat's lobe reflects: its albedo is the rough glass's reflection.
  for (float cosO : {0.9f, 0.3f}) {
    const Vec3 wo = direction(cosO, 0.3f);
    EXPECT_NEAR(integrated(overBlack, wo).first, integrated(glass, wo, true).first, 1e-4) << "cos " << cosO;
  }
  // Over a white mirror, head on: the lobe's albedo and (1 - F)^2 through the coat, as a delta.
  const Material overMirror = roughCoated(material(MaterialType::Mirror, 1.0f), a, ior);
  const double F0 = fresnel(1.0, ior);
  EXPECT_NEAR(sampledAlbedo(overMirror, Vec3{0, 0, 1}).first, integrated(glass, Vec3{0, 0, 1}, true).first + (1 - F0) * (1 - F0), 0.005);
  auto d = run({{overMirror, Vec3{0, 0, 1}, Vec3{0, 0, 1}, Vec3{0.5f, 0.5f, 0.99f}}});
  EXPECT_TRUE(d[0].delta) << "the mirror's own reflection stays a delta under the rough coat";
}

}  // namespace
}  // namespace retile

namespace retile {
namespace {

// Tungsten's hair (d'Eon et al. 2011). Seen straight across the fibre (wo perpendicular to it,
// which runs along x) with its lobes narrow and untilted, every lobe's cone is about theta_i =
// 0, where the half difference angle is 0: lobe R keeps F(cos gamma) of the light (gamma =
// asin h, where across the fibre it is met), TT (1 - F)^2 exp(-2 a cos gamma_t) and TRT that
// times F exp(-2 a cos gamma_t) again, gamma_t = asin(h / 1.55), a the absorption per unit of
// radius. The directional albedo that sampling estimates must be their sum; and where the light
// goes: R mirrored about the normal at gamma (phi = -2 gamma, phi about the fibre from wo
// towards the fibre x wo, here -y), TT straight on at h = 0.
TEST_F(Bsdfs, HairKeepsWhatItsLobesAttenuationsSay) {
  const Vec3 wo{0, 0, 1};
  for (float h : {0.0f, 0.5f, 0.9f})
    for (float a : {0.0f, 0.3f, 1e4f}) {
      const double gi = std::asin(h), gt = std::asin(h / 1.55);
      const double f = fresnel(std::cos(gi), 1.55), t = std::exp(-2.0 * a * std::cos(gt));
      const double expected = f + (1 - f) * (1 - f) * t * (1 + f * t);
      std::vector<BsdfQuery> q;
      for (int i = 0; i < 256; ++i)
        for (int j = 0; j < 256; ++j)
          q.push_back({hair(0.02f, a, 0.0f),
                       wo,
                       wo,
                       {(i + 0.5f) / 256, (j + 0.5f) / 256, ((i * 256 + j) * 0.618034f) - std::floor((i * 256 + j) * 0.618034f)},
                       h});
      double sum = 0;
      for (const auto& r : run(q)) sum += luminance(r.weight) / static_cast<double>(q.size());
      EXPECT_NEAR(sum, expected, 0.01 * expected + 1e-4) << "h " << h << ", absorption " << a;
    }
  // Where each goes, by eval around the fibre (theta_i = 0): the black fibre's R peaks at -2
  // gamma, the clear one's TT at pi.
  for (float h : {0.0f, 0.5f}) {
    std::vector<BsdfQuery> q;
    for (int j = 0; j < 720; ++j) {
      const float phi = -kPi + (j + 0.5f) * kPi / 360;
      q.push_back({hair(0.1f, 1e4f, 0.0f), wo, {0, -std::sin(phi), std::cos(phi)}, Vec3{0.5f}, h});
    }
    const auto r = run(q);
    int best = 0;
    for (int j = 0; j < 720; ++j)
      if (r[j].f.y > r[best].f.y) best = j;
    EXPECT_NEAR(-kPi + (best + 0.5f) * kPi / 360, -2 * std::asin(h), 0.02) << "R at h " << h;
  }
  auto r = run({{hair(0.1f, 0.0f, 0.0f), wo, {0, 0, -1}}, {hair(0.1f, 0.0f, 0.0f), wo, {0, 1, 0}}});
  EXPECT_GT(r[0].f.y, 50 * r[1].f.y) << "TT goes straight through";
}

// The scales' tilt leans the lobes along the fibre, as in Tungsten (its theta_I shifted by -2
// tilt for R): seen straight across the fibre, a black one reflects most towards theta_i =
// 2 tilt, towards its tip (the fibre runs from root to tip along +x).
TEST_F(Bsdfs, HairScalesTiltItsLobes) {
  const Vec3 wo{0, 0, 1};
  const float tilt = 6.0f;
  std::vector<BsdfQuery> q;
  for (int j = 0; j < 400; ++j) {
    const float theta = -0.5f + (j + 0.5f) / 400.0f;
    q.push_back({hair(0.05f, 1e4f, tilt), wo, {std::sin(theta), 0, std::cos(theta)}});
  }
  const auto r = run(q);
  int best = 0;
  for (int j = 0; j < 400; ++j)
    if (r[j].f.y > r[best].f.y) best = j;
  EXPECT_NEAR(-0.5f + (best + 0.5f) / 400.0f, 2 * radians(tilt), 0.01) << "the black fibre's R";
}

}  // namespace
}  // namespace retile
