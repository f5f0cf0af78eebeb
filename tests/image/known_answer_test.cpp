// Renders with known answers: each would catch a real bug in sampling, MIS or light transport.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "gpu_support.h"
#include "retile/edit.h"
#include "retile/image.h"
#include "scene/primitives.h"
#include "test_support.h"

namespace retile {
namespace {

RenderImage renderScene(Renderer& r, const Scene& s, int spp, std::uint32_t seed = 1) {
  r.setScene(s);
  RenderRequest req;
  req.samplesPerPixel = spp;
  req.seed = seed;
  return r.render(req);
}

// The camera at `height` above the origin, looking down -y with image x along world x.
void lookStraightDown(Scene& s, float height, float fovDegrees) {
  s.camera.position = {0, height, 0};
  s.camera.target = {0, 0, 0};
  s.camera.up = {0, 0, -1};
  s.camera.verticalFov = radians(fovDegrees);
}

Material grey(float albedo) {
  Material m;
  m.albedo = Vec3{albedo};
  return m;
}

// A directional light of irradiance `intensity` travelling straight down (-y): a sun overhead.
void addSun(Scene& s, float intensity) {
  Light sun;
  sun.id = s.newId();
  sun.type = LightType::Directional;
  sun.intensity = intensity;
  s.lights.push_back(sun);
}

// Mean over the pixels whose first hit is `object`, of one channel (green by default: most tests
// use grey).
double meanOver(const RenderImage& img, NodeId object, int* count = nullptr, int channel = 1) {
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < img.objectId.size(); ++i)
    if (img.objectId[i] == object) {
      sum += img.color[i * 3 + static_cast<std::size_t>(channel)];
      ++n;
    }
  if (count) *count = n;
  return n ? sum / n : 0.0;
}

// The image's mean of the green channel (grey scenes: their radiance).
double imageMean(const RenderImage& img) {
  double sum = 0;
  for (std::size_t i = 0; i < img.color.size() / 3; ++i) sum += img.color[i * 3 + 1];
  return sum / static_cast<double>(img.color.size() / 3);
}

// A linear grey texture of `width` x `height` texels, texel (x, y) (row y from the top) holding
// value(x, y), written to `dir` as EXR and added to the scene.
template <class Value>
NodeId addImageTexture(Scene& s, const std::filesystem::path& dir, const std::string& name, int width, int height, Value value) {
  RenderImage img;
  img.width = width;
  img.height = height;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) img.color.push_back(value(x, y));
  const auto file = dir / (name + ".exr");
  EXPECT_TRUE(writeRenderImage(img, file).ok()) << file;
  Texture t;
  t.id = s.newId();
  t.name = name;
  t.path = file;
  t.colorSpace = TextureColorSpace::Linear;
  s.textures.push_back(t);
  return t.id;
}

// The same, whose column x holds value(x).
template <class Value>
NodeId addColumnTexture(Scene& s, const std::filesystem::path& dir, const std::string& name, int width, int height, Value value) {
  return addImageTexture(s, dir, name, width, height, [&](int x, int) { return value(x); });
}

TEST(KnownAnswer, WhiteFurnaceConvexObject) {
  // A convex diffuse sphere of albedo rho under a uniform sky of radiance L reflects rho * L in
  // every direction: light reaches it once and leaves. Exercises environment sampling and MIS.
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(48, 48);
  s.camera = test::frontCamera(30);
  s.settings.maxBounces = 4;
  s.environment.color = Vec3{1.0f};
  Material m;
  m.albedo = Vec3{0.8f};
  NodeId sphere = test::addMeshObject(s, "sphere", makeSphere(), test::addMaterial(s, m), Mat4::translate({0, 0, -4}));
  RenderImage img = renderScene(*r, s, 256);
  int n;
  double mean = meanOver(img, sphere, &n);
  ASSERT_GT(n, 500);
  EXPECT_NEAR(mean, 0.8, 0.008) << "within 1 %";
}

TEST(KnownAnswer, WhiteFurnaceLosslessMaterials) {
  // Under a uniform sky of radiance 1, a surface that neither absorbs nor emits shows 1 wherever
  // paths are long enough: glass (every path through it enters and leaves, so the 1/eta^2 of
  // entering cancels), a white mirror and a thin sheet. Glass rendered almost black before (0.02
  // in the middle: every path leaving glass, and every reflection inside it, was cut).
  RETILE_RENDERER_OR_SKIP(r);
  for (MaterialType type : {MaterialType::Dielectric, MaterialType::Mirror, MaterialType::ThinSheet}) {
    Scene s = test::emptyScene(48, 48);
    s.camera = test::frontCamera(30);
    s.settings.maxBounces = 64;
    s.environment.color = Vec3{1.0f};
    Material m;
    m.type = type;
    m.albedo = Vec3{1.0f};
    m.ior = 1.5f;
    NodeId sphere = test::addMeshObject(s, "sphere", makeSphere(), test::addMaterial(s, m), Mat4::translate({0, 0, -4}));
    RenderImage img = renderScene(*r, s, 128);
    int n;
    double mean = meanOver(img, sphere, &n);
    ASSERT_GT(n, 500);
    // The shading normals of the faceted sphere send a few reflections under the surface at the
    // rim, where they are cut: that is the 1 % allowed.
    EXPECT_NEAR(mean, 1.0, 0.01) << materialTypeName(type);
    float darkest = 1.0f;
    for (std::size_t i = 0; i < img.objectId.size(); ++i)
      if (img.objectId[i] == sphere) darkest = std::min(darkest, img.color[3 * i + 1]);
    EXPECT_GT(darkest, 0.8f) << materialTypeName(type) << ": no pixel of it is dark";
  }
}

// A clear thin sheet of index 1.5 absorbing `absorption` straight across.
Material thinSheet(Vec3 absorption) {
  Material m;
  m.type = MaterialType::ThinSheet;
  m.albedo = Vec3{1.0f};
  m.ior = 1.5f;
  m.coatingAbsorption = absorption;
  return m;
}

// A thin sheet absorbs along its path through it: seen head on before a sky of 1, it passes
// (1 - R) exp(-a), R = 2r / (1 + r) its two faces' reflectance (r = 0.04 at index 1.5) and a its
// absorption straight across, per channel. In a scene with no plastic in it: the absorption was
// read only where a plastic compiled it in, and the sheet was clear.
TEST(KnownAnswer, AThinSheetAbsorbsWithoutAPlasticInTheScene) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(16, 16);
  s.camera = test::frontCamera(2);
  s.settings.maxBounces = 1;
  s.environment.color = Vec3{1.0f};
  const Material sheet = thinSheet(Vec3{0.5f, 1.0f, 2.0f});
  const NodeId quad =
      test::addMeshObject(s, "sheet", makeQuad(), test::addMaterial(s, sheet), Mat4::translate({0, 0, -4}) * Mat4::rotateX(kPi / 2));
  const RenderImage img = renderScene(*r, s, 16);
  const double rf = 0.04, passes = 1 - 2 * rf / (1 + rf);
  for (int c = 0; c < 3; ++c) {
    int n;
    const double mean = meanOver(img, quad, &n, c);
    ASSERT_EQ(n, 16 * 16);
    // What the sheet reflects sees the sky too, and adds R.
    const double a = c == 0 ? sheet.coatingAbsorption.x : c == 1 ? sheet.coatingAbsorption.y : sheet.coatingAbsorption.z;
    const double expected = passes * std::exp(-a) + 2 * rf / (1 + rf);
    EXPECT_NEAR(mean, expected, 0.003) << "channel " << c;
  }
}

// A thin sheet's texture is its thickness (Material::roughnessTexture): a checker of one value v
// across the sheet of the test above scales its absorption by v, and its film: a film of 500 nm
// at thickness 0 is none, so the sheet reflects as a plain one (the sky of 1 seen through it and in
// it adds up to 1 where it absorbs nothing; a film of 500 nm reflects a colour instead).
TEST(KnownAnswer, AThinSheetsThicknessTextureScalesItsAbsorptionAndFilm) {
  RETILE_RENDERER_OR_SKIP(r);
  for (float thickness : {0.0f, 0.4f, 1.0f}) {
    SCOPED_TRACE(thickness);
    Scene s = test::emptyScene(16, 16);
    s.camera = test::frontCamera(2);
    s.settings.maxBounces = 1;
    s.environment.color = Vec3{1.0f};
    Texture t;
    t.id = s.newId();
    t.name = "thickness";
    t.kind = TextureKind::Checker;
    t.checkerOn = t.checkerOff = Vec3{thickness};
    s.textures.push_back(t);
    Material sheet = thinSheet(Vec3{0.5f, 1.0f, 2.0f});
    sheet.roughnessTexture = t.id;
    const NodeId quad =
        test::addMeshObject(s, "sheet", makeQuad(), test::addMaterial(s, sheet), Mat4::translate({0, 0, -4}) * Mat4::rotateX(kPi / 2));
    const RenderImage img = renderScene(*r, s, 16);
    const double rf = 0.04, passes = 1 - 2 * rf / (1 + rf);
    for (int c = 0; c < 3; ++c) {
      const double a = c == 0 ? 0.5 : c == 1 ? 1.0 : 2.0;
      EXPECT_NEAR(meanOver(img, quad, nullptr, c), passes * std::exp(-a * thickness) + 2 * rf / (1 + rf), 0.003) << "channel " << c;
    }
    // The same sheet clear, over a film of 500 nm at that thickness, before a lamp of 1 with
    // nothing behind the camera: what it lets through, 1 - R, R the plain sheet's or the film's.
    s.environment.color = Vec3{0.0f};
    s.materials.back().coatingAbsorption = Vec3{0.0f};
    s.materials.back().filmThickness = 500.0f;
    Material lamp = grey(0.0f);
    lamp.emission = Vec3{1.0f};
    test::addMeshObject(s, "lamp", makeQuad(), test::addMaterial(s, lamp),
                        Mat4::translate({0, 0, -6}) * Mat4::rotateX(kPi / 2) * Mat4::scale(Vec3{10.0f}));
    const RenderImage film = renderScene(*r, s, 16);
    double lo = 1, hi = 0;
    for (int c = 0; c < 3; ++c) {
      const double through = meanOver(film, quad, nullptr, c);
      lo = std::min(lo, through);
      hi = std::max(hi, through);
    }
    if (thickness == 0) {
      EXPECT_NEAR(lo, passes, 0.003) << "no film: a plain sheet";
      EXPECT_NEAR(hi, passes, 0.003) << "no film: a plain sheet";
    } else {
      EXPECT_GT(hi - lo, 0.01) << "a film lets some colours through more than others";
    }
  }
}

// What a thin sheet of index 1.5 absorbing `a` straight across lets through at angle theta to its
// normal: (1 - R) exp(-a / cos t), R each polarisation's 2r / (1 + r) averaged, t the angle inside.
double sheetTransmittance(double theta, double a) {
  const double ci = std::cos(theta), st = std::sin(theta) / 1.5, ct = std::sqrt(1 - st * st);
  const double rs = (ci - 1.5 * ct) / (ci + 1.5 * ct), rp = (1.5 * ci - ct) / (1.5 * ci + ct);
  const double r1 = rs * rs, r2 = rp * rp;
  return (1 - (r1 / (1 + r1) + r2 / (1 + r2))) * std::exp(-a / ct);
}

// Shadow rays pass thin sheets, dimmed by what they let through, as Tungsten's do (its forward
// lobe). A floor of albedo 0.5 one unit under a horizontal sheet absorbing 0.7, seen from between
// the two (the camera's rays do not pass the sheet).
//  - A point light above the sheet, which no path can reach: the floor under it reads the
//    unshaded floor's times the sheet's transmittance head on; black at one bounce, where a path
//    could not pass the sheet and reach the light either (the sheet is a bounce).
//  - A sky of 1 above it, which paths reach through the sheet and light samples see through
//    it, weighed against each other: the floor reads albedo times 2 int T(theta) cos sin, no
//    more (a path that passed the sheet counted as a delta bounce would add the light twice).
TEST(KnownAnswer, ShadowRaysPassAThinSheetDimmed) {
  RETILE_RENDERER_OR_SKIP(r);
  const float a = 0.7f;
  Scene s = test::emptyScene(16, 16);
  s.camera.position = {0, 0.5f, 0};
  s.camera.target = {0, 0, 0};
  s.camera.up = {0, 0, -1};
  s.camera.verticalFov = radians(10.0f);
  s.settings.maxBounces = 2;
  NodeId floor = test::addMeshObject(s, "floor", makeQuad(), test::addMaterial(s, grey(0.5f)), Mat4::scale({1000, 1, 1000}));
  const Material sheet = thinSheet(Vec3{a});
  test::addMeshObject(s, "sheet", makeQuad(), test::addMaterial(s, sheet), Mat4::translate({0, 1, 0}) * Mat4::scale({1000, 1, 1000}));
  Light light;
  light.id = s.newId();
  light.type = LightType::Point;
  light.intensity = 4;
  light.position = {0, 2, 0};
  s.lights.push_back(light);
  auto floorMean = [&](int spp) {
    int n;
    const double mean = meanOver(renderScene(*r, s, spp), floor, &n);
    EXPECT_EQ(n, 16 * 16);
    return mean;
  };
  const double through = floorMean(16);
  s.objects.back().visible = false;
  const double open = floorMean(16);
  EXPECT_GT(open, 0.1);
  EXPECT_NEAR(through / open, sheetTransmittance(0, a), 0.003) << "the point light through the sheet";
  s.objects.back().visible = true;
  // A thickness texture of 0.5 (a checker with both cells so) halves the absorption along the
  // shadow rays too: they look up what the sheet's shading does (kFeatureSheetTextures).
  Texture half;
  half.id = s.newId();
  half.name = "thickness";
  half.kind = TextureKind::Checker;
  half.checkerOn = half.checkerOff = Vec3{0.5f};
  s.textures.push_back(half);
  s.material(s.objects.back().material)->roughnessTexture = half.id;
  EXPECT_NEAR(floorMean(16) / open, sheetTransmittance(0, 0.5 * a), 0.003) << "the point light through a sheet half as thick";
  s.material(s.objects.back().material)->roughnessTexture = kNoNode;
  s.settings.maxBounces = 1;
  EXPECT_LT(floorMean(16), 1e-6) << "one bounce: the sheet is a second";

  // Two such sheets, each blended half and half with black paint: a shadow ray passes both with
  // probability 1/4, each sheet its own draw (one draw for both would pass half the rays).
  s.settings.maxBounces = 3;
  const NodeId sheetMaterial = s.objects.back().material;
  s.material(sheetMaterial)->blendWith = test::addMaterial(s, grey(0.0f));
  s.material(sheetMaterial)->blendRatio = 0.5f;
  test::addMeshObject(s, "sheet 2", makeQuad(), sheetMaterial, Mat4::translate({0, 1.2f, 0}) * Mat4::scale({1000, 1, 1000}));
  const double t0 = sheetTransmittance(0, a);
  EXPECT_NEAR(floorMean(64) / open, 0.25 * t0 * t0, 0.06 * 0.25 * t0 * t0) << "two blended sheets";
  s.objects.pop_back();
  s.material(sheetMaterial)->blendWith = kNoNode;

  s.settings.maxBounces = 2;
  s.lights.clear();
  s.environment.color = Vec3{1.0f};
  double integral = 0;
  const int steps = 2000;
  for (int i = 0; i <= steps; ++i) {
    const double theta = (kPi / 2) * i / steps, w = (i == 0 || i == steps) ? 1 : (i % 2 ? 4 : 2);
    integral += w * sheetTransmittance(theta, a) * std::cos(theta) * std::sin(theta);
  }
  integral *= (kPi / 2) / steps / 3;
  EXPECT_NEAR(floorMean(256), 0.5 * 2 * integral, 0.005) << "the sky through the sheet, once";
}

// Glass of index 1.0001 (no Fresnel reflection, rays go straight) filled with a medium.
Material filledGlass(Vec3 absorption, Vec3 scattering = Vec3{0.0f}, float anisotropy = 0) {
  Material glass;
  glass.type = MaterialType::Dielectric;
  glass.albedo = Vec3{1.0f};
  glass.ior = 1.0f;
  glass.interiorAbsorption = absorption;
  glass.interiorScattering = scattering;
  glass.interiorAnisotropy = anisotropy;
  return glass;
}

// A 32x32 view through `glass`, a slab one unit thick and wide enough to be endless, head on,
// before a sky of 1.
Scene slabBeforeTheSky(const Material& glass, float fovDegrees, int maxBounces) {
  Scene s = test::emptyScene(32, 32);
  s.camera = test::frontCamera(fovDegrees);
  s.settings.maxBounces = maxBounces;
  s.environment.color = Vec3{1.0f};
  test::addMeshObject(s, "slab", makeCube(), test::addMaterial(s, glass), Mat4::translate({0, 0, -5}) * Mat4::scale({40, 40, 1}));
  return s;
}

TEST(KnownAnswer, GlassFilledWithAnAbsorbingMediumDimsByBeersLaw) {
  // A slab of glass one unit thick, filled with a medium of absorption sigma, before a sky of 1:
  // the middle of the image, where rays cross the slab head on, shows exp(-sigma) per channel;
  // empty glass shows 1.
  RETILE_RENDERER_OR_SKIP(r);
  const float sigma[3] = {0.7f, 0.2f, 0.0f};
  for (bool filled : {true, false}) {
    Scene s = slabBeforeTheSky(filledGlass(filled ? Vec3{sigma[0], sigma[1], sigma[2]} : Vec3{0.0f}), 30, 8);
    RenderImage img = renderScene(*r, s, 16);
    for (int y = 14; y < 18; ++y)
      for (int x = 14; x < 18; ++x)
        for (int c = 0; c < 3; ++c) {
          const double expected = filled ? std::exp(-static_cast<double>(sigma[c])) : 1.0;
          EXPECT_NEAR(img.color[3 * (y * 32 + x) + c], expected, 2e-3) << "pixel " << x << "," << y << " channel " << c;
        }
  }
}

// An emitter of radiance 1 inside a slab of glass of index 1.5, seen head on through its face.
// Radiance is 1.5^2 times as dense inside glass as outside, so the physical form shows it as
// (1 - F) / 1.5^2 = 0.4267 (F = 0.04 head on); Tungsten's glass (Material::tintsReflection) does
// not scale radiance across the surface and shows 1 - F = 0.96, as Tungsten renders a lamp's
// bulb. The sky is black and the emitter's albedo 0: nothing else reaches the camera.
TEST(KnownAnswer, ALampInsideGlassShinesThroughAsItsConventionSays) {
  RETILE_RENDERER_OR_SKIP(r);
  for (bool tungsten : {false, true}) {
    Material glass = filledGlass(Vec3{0.0f});
    glass.ior = 1.5f;
    glass.tintsReflection = tungsten;
    Scene s = slabBeforeTheSky(glass, 30, 8);
    s.environment.color = Vec3{0.0f};
    Material lamp = grey(0.0f);
    lamp.emission = Vec3{1.0f};
    // Facing the camera, halfway through the slab.
    test::addMeshObject(s, "lamp", makeQuad(), test::addMaterial(s, lamp),
                        Mat4::translate({0, 0, -5}) * Mat4::rotateX(kPi / 2) * Mat4::scale({8, 1, 8}));
    RenderImage img = renderScene(*r, s, 64);
    double sum = 0;
    for (int y = 14; y < 18; ++y)
      for (int x = 14; x < 18; ++x) sum += img.color[3 * (y * 32 + x) + 1];
    EXPECT_NEAR(sum / 16, tungsten ? 0.96 : 0.96 / 2.25, 0.01) << (tungsten ? "Tungsten's glass" : "physical glass");
  }
}

// A bubble in ice: a slab of glass of index 1.31 holding a slab of index 0.763 (1 / 1.31, the
// bubble's air seen from the ice: each surface's index is the ratio of its two sides), seen at
// 60 degrees through both before a lamp of radiance 1, the sky black. Every interface then
// reflects the same unpolarised Fresnel share R (going in or out of the bubble is the ice's
// interface turned round), and light reflected back leaves towards the black sky, so the lamp
// shows through n interfaces as (1 - R) / (1 + (n - 1) R), summing every inner reflection: four
// with the bubble, two without. Were the bubble's index taken as 1, it would vanish: two.
TEST(KnownAnswer, ABubbleInGlassReflectsAtEachOfItsSurfaces) {
  RETILE_RENDERER_OR_SKIP(r);
  const double cosI = 0.5, eta = 1.31, cosT = std::sqrt(1 - (1 - cosI * cosI) / (eta * eta));
  const double rs = (cosI - eta * cosT) / (cosI + eta * cosT), rp = (eta * cosI - cosT) / (eta * cosI + cosT);
  const double fresnel = (rs * rs + rp * rp) / 2;  // 0.0553
  for (bool bubble : {true, false}) {
    SCOPED_TRACE(bubble ? "with the bubble" : "ice alone");
    Material ice = filledGlass(Vec3{0.0f});
    ice.ior = static_cast<float>(eta);
    Scene s = slabBeforeTheSky(ice, 1, 32);
    s.objects.front().transform = Mat4::translate({0, 0, -5}) * Mat4::scale({400, 400, 1});
    s.environment.color = Vec3{0.0f};
    s.camera.target = {std::sqrt(3.0f) / 2, 0, -0.5f};  // 60 degrees from the slab's normal
    if (bubble) {
      Material air = filledGlass(Vec3{0.0f});
      air.ior = static_cast<float>(1 / eta);
      test::addMeshObject(s, "bubble", makeCube(), test::addMaterial(s, air), Mat4::translate({0, 0, -5}) * Mat4::scale({300, 300, 0.4f}));
    }
    Material lamp = grey(0.0f);
    lamp.emission = Vec3{1.0f};
    test::addMeshObject(s, "lamp", makeQuad(), test::addMaterial(s, lamp),
                        Mat4::translate({0, 0, -20}) * Mat4::rotateX(kPi / 2) * Mat4::scale({1000, 1, 1000}));
    const int n = bubble ? 4 : 2;
    // 131 072 samples, each 0 or 1: a standard error of 0.0011. Had the bubble index 1: 0.894.
    EXPECT_NEAR(imageMean(renderScene(*r, s, 128)), (1 - fresnel) / (1 + (n - 1) * fresnel), 0.006);
  }
}

// A random walk, independent of the kernel's code, through a slab one unit thick of a medium of
// extinction sigmaT and albedo omega, entered head on and endless sideways: the mean of
// omega^(times scattered) with which walks leave it by either face, scattering by Henyey and
// Greenstein's phase function of asymmetry g.
double slabEscape(double sigmaT, double omega, double g, int walks) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  double sum = 0;
  for (int i = 0; i < walks; ++i) {
    double z = 0, mu = 1, weight = 1;  // depth in the slab, the direction's cosine with its normal
    for (;;) {
      z += mu * -std::log(1 - uniform(rng)) / sigmaT;
      if (z < 0 || z > 1) break;
      weight *= omega;
      // The cosine with the old direction by the inverted CDF, then the new direction's with the normal.
      const double u = uniform(rng), s = (1 - g * g) / (1 - g + 2 * g * u);
      const double cosTheta = std::abs(g) < 1e-3 ? 1 - 2 * u : std::clamp((1 + g * g - s * s) / (2 * g), -1.0, 1.0);
      const double phi = 2 * kPi * uniform(rng);
      mu = mu * cosTheta + std::sqrt(std::max(0.0, 1 - mu * mu)) * std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta)) * std::cos(phi);
    }
    sum += weight;
  }
  return sum / walks;
}

TEST(KnownAnswer, GlassFilledWithAScatteringMediumMatchesARandomWalk) {
  // The same slab filled with a medium that absorbs and scatters, per channel, before a sky of 1
  // all round: through the slab, seen head on by a narrow camera, each channel shows what light
  // keeps after its scattering walk, which slabEscape computes on its own. The first channel does
  // not absorb and must show 1 whatever the walk (energy is conserved); the others depend on the
  // phase function (0.51 even, 0.55 forward, 0.55 back for the second; 0.29, 0.30, 0.35 for the
  // third), and on the channel's own weight in the free flight drawn for one channel.
  RETILE_RENDERER_OR_SKIP(r);
  const Vec3 sigmaA{0.0f, 0.5f, 1.0f}, sigmaS{2.0f, 1.0f, 1.5f};
  for (float g : {0.7f, -0.5f, 0.0f}) {
    SCOPED_TRACE("g " + std::to_string(g));
    Scene s = slabBeforeTheSky(filledGlass(sigmaA, sigmaS, g), 4, 1024);
    RenderImage img = renderScene(*r, s, 64);
    for (int c = 0; c < 3; ++c) {
      double mean = 0;
      for (int i = 0; i < 32 * 32; ++i) mean += img.color[3 * i + c] / (32.0 * 32.0);
      const double sigmaT = sigmaA[c] + sigmaS[c];
      const double expected = slabEscape(sigmaT, sigmaS[c] / sigmaT, g, 400000);
      EXPECT_NEAR(mean, expected, 0.01) << "channel " << c;
    }
  }
}

// A medium filling `holder` two units deep (y from 0 to 2) over a grey floor (y = 0.01), lit by
// a point light at (0.5, lightY, 0), seen straight down from five units above by a 16x16 camera,
// with two bounces. Such a path samples the light once, at its first vertex inside: where it
// scatters in the medium or where it meets the floor (the crossing into glass or a boundary is
// the other bounce). So the image is the medium's single scattering along the view ray plus the
// floor's direct light, each leg dimmed where it runs inside. `everywhere`: the holder's medium
// fills the world instead (Environment::mediumAbsorption and on), with one bounce, as there is
// no crossing.
Scene mediumOverAFloor(const Material& holder, float lightY, float intensity, float albedo, bool everywhere = false) {
  Scene s = test::emptyScene(16, 16);
  lookStraightDown(s, 5, 1);
  // Single scattering and the floor's light alone. Crossing a boundary is a bounce, on a shadow
  // ray too (as in Tungsten): into the holder, the scattering, and a shadow ray's way out to a
  // light outside it.
  s.settings.maxBounces = everywhere ? 1 : holder.type == MaterialType::Boundary ? 3 : 2;
  if (everywhere) {
    s.environment.mediumAbsorption = holder.interiorAbsorption;
    s.environment.mediumScattering = holder.interiorScattering;
    s.environment.mediumAnisotropy = holder.interiorAnisotropy;
  } else {
    test::addMeshObject(s, "holder", makeCube(), test::addMaterial(s, holder), Mat4::translate({0, 1, 0}) * Mat4::scale({40, 2, 40}));
  }
  Material grey;
  grey.albedo = Vec3{albedo};
  test::addMeshObject(s, "floor", makeQuad(), test::addMaterial(s, grey), Mat4::translate({0, 0.01f, 0}) * Mat4::scale({4, 1, 4}));
  Light light;
  light.id = s.newId();
  light.type = LightType::Point;
  light.intensity = intensity;
  light.position = {0.5f, lightY, 0};
  s.lights.push_back(light);
  return s;
}

// What mediumOverAFloor's image should be in a channel of extinction sigmaT and scattering
// sigmaS: the single scattering integrated by Simpson's rule (in *single), plus the floor's light.
// The medium reaches up to `top` (5 where it fills the world, up to the camera); above it, the
// world's medium absorbs `world`.
double overAFloorExpected(double sigmaT, double sigmaS, double g, double lightY, double intensity, double albedo, double* single,
                          double top = 2, double world = 0) {
  // A leg from height y to the light, dimmed by the medium inside (below the top) and the world's outside.
  auto dimmed = [&](double y, double dist) {
    const double inside = lightY <= top ? dist : dist * (top - y) / (lightY - y);
    return std::exp(-sigmaT * inside - world * (dist - inside));
  };
  auto scattered = [&](double below) {  // `below` the top, on the view ray
    const double y = top - below, up = lightY - y, r2 = 0.25 + up * up, dist = std::sqrt(r2), cosTheta = -up / dist;
    const double term = 1 + g * g - 2 * g * cosTheta;
    const double phase = (1 - g * g) / (4 * kPi * term * std::sqrt(term));
    return sigmaS * std::exp(-sigmaT * below) * phase * intensity * dimmed(y, dist) / r2;
  };
  const double above = std::exp(-world * (5 - top));  // the view ray down from the camera to the top
  const double depth = top - 0.01;
  const int steps = 20000;
  double sum = scattered(0) + scattered(depth);
  for (int i = 1; i < steps; ++i) sum += (i % 2 ? 4 : 2) * scattered(depth * i / steps);
  *single = above * sum * depth / steps / 3;
  const double up = lightY - 0.01, toLight = std::sqrt(0.25 + up * up);
  return *single +
         above * std::exp(-sigmaT * depth) * albedo / kPi * intensity * (up / toLight) / (toLight * toLight) * dimmed(0.01, toLight);
}

// mediumOverAFloor in the holder's medium (kOverAFloorAbsorption and kOverAFloorScattering in the
// tests), rendered at 256 spp, against overAFloorExpected within 2 %; `world` absorbing around it.
void expectOverAFloor(Renderer& r, const Material& holder, float lightY, float intensity, bool everywhere = false, float world = 0) {
  const Vec3 sigmaA = holder.interiorAbsorption, sigmaS = holder.interiorScattering;
  const float albedo = 0.8f;
  Scene s = mediumOverAFloor(holder, lightY, intensity, albedo, everywhere);
  if (world > 0) s.environment.mediumAbsorption = Vec3{world};
  RenderImage img = renderScene(r, s, 256);
  for (int c = 0; c < 3; ++c) {
    double single = 0;
    const double expected = overAFloorExpected(sigmaA[c] + sigmaS[c], sigmaS[c], holder.interiorAnisotropy, lightY, intensity, albedo,
                                               &single, everywhere ? 5 : 2, world);
    double mean = 0;
    for (int i = 0; i < 16 * 16; ++i) mean += img.color[3 * i + c] / 256.0;
    EXPECT_NEAR(mean, expected, 0.02 * expected) << "channel " << c << ": single scattering " << single;
  }
}

// No surface, only a medium's boundary (Tungsten's forward bsdf), filled with a medium.
Material boundaryOf(Vec3 absorption, Vec3 scattering = Vec3{0.0f}, float anisotropy = 0) {
  Material m = filledGlass(absorption, scattering, anisotropy);
  m.type = MaterialType::Boundary;
  return m;
}

const Vec3 kOverAFloorAbsorption{0.2f, 0.5f, 0.0f}, kOverAFloorScattering{0.5f, 0.3f, 0.0f};

TEST(KnownAnswer, ALightInsideFilledGlassLightsItsMediumAndWhatItHolds) {
  // Glass of index 1.0001 holds the medium, the floor and the light, half a unit off the view ray
  // (mediumOverAFloor): every leg is dimmed, to the light too. The third channel is empty: the
  // floor's light alone, undimmed.
  RETILE_RENDERER_OR_SKIP(r);
  expectOverAFloor(*r, filledGlass(kOverAFloorAbsorption, kOverAFloorScattering, 0.5f), 1, 10);
}

TEST(KnownAnswer, AMediumInsideABoundaryMatchesARandomWalk) {
  // The random-walk slab again, bounded by a boundary instead of glass: nothing at the faces at
  // all, so the walk is the same. Unlike glass, a boundary lets shadow rays through, so here a
  // scattering point's light sample reaches the sky, dimmed by the medium up to the face it
  // leaves by: the sum of the crossings' signed depths, as the traversal finds them. The slab is
  // mirrored (z scaled by -1) and its mesh shared with a far copy, so that rays meet it in its
  // own space, as an instance: a crossing's side must come out the same there.
  RETILE_RENDERER_OR_SKIP(r);
  const Vec3 sigmaA{0.0f, 0.5f, 1.0f}, sigmaS{2.0f, 1.0f, 1.5f};
  const float g = 0.7f;
  Scene s = slabBeforeTheSky(boundaryOf(sigmaA, sigmaS, g), 4, 1024);
  s.objects[0].transform = Mat4::translate({0, 0, -5}) * Mat4::scale({40, 40, -1});
  Object copy = s.objects[0];
  copy.id = s.newId();
  copy.transform = Mat4::translate({1000, 0, 0});
  s.objects.push_back(copy);
  RenderImage img = renderScene(*r, s, 64);
  for (int c = 0; c < 3; ++c) {
    double mean = 0;
    for (int i = 0; i < 32 * 32; ++i) mean += img.color[3 * i + c] / (32.0 * 32.0);
    const double sigmaT = sigmaA[c] + sigmaS[c];
    EXPECT_NEAR(mean, slabEscape(sigmaT, sigmaS[c] / sigmaT, g, 400000), 0.01) << "channel " << c;
  }
}

TEST(KnownAnswer, GlassInFogLeavesThePathInTheFog) {
  // A fog slab two units thick (a boundary, absorbing only) holds a slab of empty glass of index
  // 1.0001 one unit thick: a ray through both crosses one unit of fog, exp(-sigma), not the half
  // unit before the glass alone (as when leaving glass meant leaving every medium).
  RETILE_RENDERER_OR_SKIP(r);
  const float sigma[3] = {0.7f, 0.2f, 0.0f};
  Scene s = slabBeforeTheSky(boundaryOf(Vec3{sigma[0], sigma[1], sigma[2]}), 30, 8);
  s.objects[0].transform = Mat4::translate({0, 0, -5}) * Mat4::scale({40, 40, 2});
  test::addMeshObject(s, "glass", makeCube(), test::addMaterial(s, filledGlass(Vec3{0.0f})),
                      Mat4::translate({0, 0, -5}) * Mat4::scale({30, 30, 1}));
  // Four crossings: Tungsten's roulette spares paths this bright, so the pixels carry no noise.
  s.settings.roulette = Roulette::LowThroughput;
  RenderImage img = renderScene(*r, s, 16);
  for (int y = 14; y < 18; ++y)
    for (int x = 14; x < 18; ++x)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(img.color[3 * (y * 32 + x) + c], std::exp(-static_cast<double>(sigma[c])), 2e-3)
            << "pixel " << x << "," << y << " channel " << c;
}

TEST(KnownAnswer, ACameraInsideFogSeesThroughItsWayOut) {
  // The camera in the middle of a fog box (a boundary, absorbing) five units from its walls,
  // before a sky of 1: a ray head on shows exp(-5 sigma), the fog it starts in (mediaAround)
  // counted up to the wall. Moved out of the box, the camera sees exp(-10 sigma) through it. In
  // empty glass one unit across in the fog's middle, it sees exp(-4.5 sigma): the fog around the
  // glass is where its paths go on.
  RETILE_RENDERER_OR_SKIP(r);
  const float sigma[3] = {0.1f, 0.3f, 0.0f};
  Scene s = test::emptyScene(32, 32);
  s.camera = test::frontCamera(10);
  s.environment.color = Vec3{1.0f};
  test::addMeshObject(s, "fog", makeCube(), test::addMaterial(s, boundaryOf(Vec3{sigma[0], sigma[1], sigma[2]})),
                      Mat4::scale({10, 10, 10}));
  for (float z : {0.0f, 6.0f}) {
    s.camera.position.z = z;
    s.camera.target.z = z - 1;
    RenderImage img = renderScene(*r, s, 4);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(img.color[3 * (16 * 32 + 16) + c], std::exp(-static_cast<double>(sigma[c]) * (z == 0 ? 5 : 10)), 2e-3)
          << "camera at z " << z << ", channel " << c;
  }
  s.camera = test::frontCamera(10);
  test::addMeshObject(s, "glass", makeCube(), test::addMaterial(s, filledGlass(Vec3{0.0f})), Mat4::identity());
  RenderImage img = renderScene(*r, s, 4);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(img.color[3 * (16 * 32 + 16) + c], std::exp(-static_cast<double>(sigma[c]) * 4.5), 2e-3) << "in glass, channel " << c;
}

TEST(KnownAnswer, ALightOutsideABoundaryLightsTheMediumInside) {
  // A boundary holds the medium and the floor; the light is one unit above it and shines in
  // through its top (mediumOverAFloor), so a shadow ray is dimmed only on its way up to the top:
  // its way out counts, the rest does not. The third channel is empty: the floor's light alone.
  RETILE_RENDERER_OR_SKIP(r);
  expectOverAFloor(*r, boundaryOf(kOverAFloorAbsorption, kOverAFloorScattering, -0.3f), 3, 40);
}

// A sun straight above lights a plane through five stacked boundaries, each a slab one unit thick
// of absorbing medium: ten crossings on every shadow ray, more than the four a lane records before
// it must pause until they are counted (Trace::crossings), so the count goes on across rounds of
// the traversal loop. The plane reads albedo / pi E exp(-5 sigma), in each channel. Packed direct
// (triangles name their instance and its boundary flag) and with instance records. Each crossing
// is a bounce, as for a path (and in Tungsten): at ten bounces the light is out of reach. The
// same with Tungsten's ray offset and cut-outs that let everything through, below the slabs and
// inside two of them: the shadow ray, traced again past each (resolveForward), counts each
// crossing once, also the far side of a slab it met before the cut-out inside.
TEST(KnownAnswer, AShadowRayCountsEveryBoundaryItCrosses) {
  RETILE_RENDERER_OR_SKIP(direct);
  std::string why;
  auto records = test::makeRecordsRenderer(&why);
  ASSERT_TRUE(records) << why;
  const Vec3 sigma{0.1f, 0.25f, 0.0f};
  Scene s = test::emptyScene(16, 16);
  lookStraightDown(s, 1, 2);
  s.settings.maxBounces = 11;  // the plane, then ten crossings (the sky is black, the sun a delta)
  NodeId plane = test::addMeshObject(s, "plane", makeQuad(), test::addMaterial(s, grey(0.5f)), Mat4::scale({4, 1, 4}));
  const NodeId fog = test::addMaterial(s, boundaryOf(sigma));
  for (int i = 0; i < 5; ++i)
    test::addMeshObject(s, "slab", makeCube(), fog,
                        Mat4::translate({0, 2.5f + 2.0f * static_cast<float>(i), 0}) * Mat4::scale({40, 1, 40}));
  addSun(s, 2.0f);
  for (Renderer* r : {direct.get(), records.get()}) {
    RenderImage img = renderScene(*r, s, 4);
    for (int c = 0; c < 3; ++c) {
      int n = 0;
      const double mean = meanOver(img, plane, &n, c);
      ASSERT_GT(n, 0);
      const double expected = 0.5 / kPi * 2.0 * std::exp(-5.0 * static_cast<double>(sigma[c]));
      EXPECT_NEAR(mean, expected, 1e-3 * expected) << (r == direct.get() ? "direct" : "records") << ", channel " << c;
    }
  }
  s.settings.maxBounces = 10;
  EXPECT_EQ(meanOver(renderScene(*direct, s, 4), plane), 0.0) << "ten crossings at ten bounces";
  s.settings.maxBounces = 11;
  s.settings.rayOffset = RayOffset::FixedEpsilon;
  Material clear = grey(0.0f);
  clear.alpha = 0.0f;
  const NodeId clearMaterial = test::addMaterial(s, clear);
  for (float y : {1.0f, 2.5f, 6.5f})
    test::addMeshObject(s, "clear", makeQuad(), clearMaterial, Mat4::translate({0, y, 0}) * Mat4::scale({40, 1, 40}));
  lookStraightDown(s, 0.5f, 2);
  for (Renderer* r : {direct.get(), records.get()}) {
    RenderImage img = renderScene(*r, s, 4);
    for (int c = 0; c < 3; ++c) {
      const double mean = meanOver(img, plane, nullptr, c);
      const double expected = 0.5 / kPi * 2.0 * std::exp(-5.0 * static_cast<double>(sigma[c]));
      EXPECT_NEAR(mean, expected, 1e-3 * expected)
          << "Tungsten's offset, cut-outs, " << (r == direct.get() ? "direct" : "records") << ", channel " << c;
    }
  }
}

TEST(KnownAnswer, TheWorldsMediumDimsWhatTheCameraSeesAndHidesTheSky) {
  // The world filled with a medium that absorbs sigma (Environment::mediumAbsorption), before a
  // sky of 1: the sky is infinitely far, so it shows in the channel that does not absorb alone.
  // A lit wall ten units ahead shows exp(-10 sigma); with a slab of empty glass one unit thick
  // between, exp(-9 sigma) (out of the glass, the path is back in the world's medium); from inside
  // a fog box (a boundary) two units from its walls, exp(-2 fog - 7 sigma): the camera starts in
  // the fog (mediaAround) and goes on into the world's medium.
  RETILE_RENDERER_OR_SKIP(r);
  const Vec3 sigma{0.1f, 0.3f, 0.0f}, fog{0.2f, 0.05f, 0.5f};
  Scene s = test::emptyScene(32, 32);
  s.camera = test::frontCamera(10);
  s.environment.color = Vec3{1.0f};
  s.environment.mediumAbsorption = sigma;
  auto expectCentre = [&](Vec3 expected, const char* what) {
    RenderImage img = renderScene(*r, s, 4);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.color[3 * (16 * 32 + 16) + c], expected[c], 2e-3) << what << ", channel " << c;
  };
  expectCentre(Vec3{0, 0, 1}, "the sky");
  Material light;
  light.albedo = Vec3{0.0f};
  light.emission = Vec3{1.0f};
  test::addMeshObject(s, "light", makeCube(), test::addMaterial(s, light), Mat4::translate({0, 0, -10.5f}) * Mat4::scale({40, 40, 1}));
  auto beer = [](Vec3 depth) { return Vec3{std::exp(-depth.x), std::exp(-depth.y), std::exp(-depth.z)}; };
  expectCentre(beer(sigma * 10.0f), "a wall ten units ahead");
  test::addMeshObject(s, "glass", makeCube(), test::addMaterial(s, filledGlass(Vec3{0.0f})),
                      Mat4::translate({0, 0, -5}) * Mat4::scale({40, 40, 1}));
  expectCentre(beer(sigma * 9.0f), "through empty glass");
  test::addMeshObject(s, "fog", makeCube(), test::addMaterial(s, boundaryOf(fog)), Mat4::scale({4, 4, 4}));
  expectCentre(beer(fog * 2.0f + sigma * 7.0f), "from inside a fog box");
  // The fog box grown round the glass too (z from -7 to 1): into the glass from the fog and out,
  // then out of the fog into the world's medium, which the path no longer remembers by then.
  s.objects.back().transform = Mat4::translate({0, 0, -3}) * Mat4::scale({50, 50, 8});
  expectCentre(beer(fog * 6.0f + sigma * 3.0f), "through glass in a fog box");
}

TEST(KnownAnswer, AThinHazeHidesTheSkyBehindABoundary) {
  // The random-walk slab behind a boundary (AMediumInsideABoundaryMatchesARandomWalk) in a world
  // haze of 1e-6 in the first two channels: however thin, it is infinitely deep towards the sky,
  // so those channels are black, shadow rays that cross the boundary out to the sky included
  // (the slab's 2 and 1.5 per unit crossed must not make the haze look like rounding). The third
  // channel has no haze and keeps the walk's value.
  RETILE_RENDERER_OR_SKIP(r);
  const Vec3 sigmaA{0.0f, 0.5f, 1.0f}, sigmaS{2.0f, 1.0f, 1.5f};
  Scene s = slabBeforeTheSky(boundaryOf(sigmaA, sigmaS, 0.7f), 4, 1024);
  s.environment.mediumAbsorption = Vec3{1e-6f, 1e-6f, 0.0f};
  RenderImage img = renderScene(*r, s, 64);
  double mean[3] = {0, 0, 0};
  for (int i = 0; i < 32 * 32; ++i)
    for (int c = 0; c < 3; ++c) mean[c] += img.color[3 * i + c] / (32.0 * 32.0);
  EXPECT_EQ(mean[0], 0.0);
  EXPECT_EQ(mean[1], 0.0);
  EXPECT_NEAR(mean[2], slabEscape(2.5, 0.6, 0.7, 400000), 0.01);
}

TEST(KnownAnswer, TheWorldsMediumScattersALightsLight) {
  // The medium over the floor (mediumOverAFloor) fills the world instead: the camera's paths
  // start in it, the view ray runs in it all the way down from the camera, and so does every leg
  // to the light.
  RETILE_RENDERER_OR_SKIP(r);
  expectOverAFloor(*r, filledGlass(kOverAFloorAbsorption, kOverAFloorScattering, 0.5f), 1, 10, true);
}

TEST(KnownAnswer, ABoundaryInTheWorldsMediumTradesOneMediumForTheOther) {
  // ALightOutsideABoundaryLightsTheMediumInside in a world that absorbs 0.15 in every channel:
  // the view ray crosses three units of the world's medium to the boundary, and a shadow ray from
  // inside runs in the boundary's medium up to its top and in the world's above it. In the third
  // channel the boundary holds a vacuum inside the world's medium.
  RETILE_RENDERER_OR_SKIP(r);
  expectOverAFloor(*r, boundaryOf(kOverAFloorAbsorption, kOverAFloorScattering, -0.3f), 3, 40, false, 0.15f);
}

// A closed furnace: the camera inside a sphere that emits le and reflects rho, at most `bounces`.
// Reversed winding and normals turn the sphere's front side, and so its emission, inwards. (A
// negative scale would not: transformed normals keep pointing out of the surface.)
Scene closedFurnace(float rho, float le, int bounces) {
  Scene s = test::emptyScene(16, 16);
  s.camera = test::frontCamera(60);
  s.settings.maxBounces = bounces;
  Material m;
  m.albedo = Vec3{rho};
  m.emission = Vec3{le};
  auto inside = std::make_shared<MeshGeometry>(*makeSphere(24, 48));
  for (std::size_t t = 0; t < inside->indices.size(); t += 3) std::swap(inside->indices[t + 1], inside->indices[t + 2]);
  for (Vec3& n : inside->normals) n = -n;
  test::addMeshObject(s, "inside", inside, test::addMaterial(s, m), Mat4::scale(Vec3{3.0f}));
  return s;
}

// Min bounces (Tungsten's min_bounces): in the closed furnace, a path's light of k bounces is
// Le rho^k, so leaving out fewer than m leaves Le (rho^m - rho^(B+1)) / (1 - rho), and past B
// nothing. Light samples and emitters hit are both cut (either alone left in is caught: at m = 1
// the emitter seen directly adds 1, the light samples of the first vertex rho). Also where a thin
// sheet (outside the furnace, never reached) compiles in the shadow rays that count the sheets
// they pass, which decide at the end of the ray instead of at its start.
TEST(KnownAnswer, ClosedFurnaceWithBounceLimit) {
  // Inside a sphere that emits Le and reflects rho, a path of at most B bounces sees
  // Le * (1 + rho + ... + rho^B). Exercises emitter sampling, MIS, roulette (either rule: with
  // rho 0.5, Tungsten's plays from the fourth bounce on) and the bounce limit.
  RETILE_RENDERER_OR_SKIP(r);
  const float rho = 0.5f, le = 1.0f;
  const int bounces = 6;
  for (Roulette roulette : {Roulette::Standard, Roulette::LowThroughput}) {
    SCOPED_TRACE(roulette == Roulette::LowThroughput ? "Tungsten's roulette" : "standard roulette");
    Scene s = closedFurnace(rho, le, bounces);
    s.settings.roulette = roulette;
    RenderImage img = renderScene(*r, s, 256);
    double expected = le * (1 - std::pow(rho, bounces + 1)) / (1 - rho);
    double mean = test::meanLuminance(img, 0, 0, 16, 16);
    EXPECT_NEAR(mean, expected, expected * 0.01) << "expected " << expected;
  }
}

TEST(KnownAnswer, MinBouncesLeaveOutTheLightOfShorterPaths) {
  RETILE_RENDERER_OR_SKIP(r);
  const float rho = 0.5f, le = 1.0f;
  const int bounces = 6;
  for (bool sheet : {false, true}) {
    SCOPED_TRACE(sheet ? "with a thin sheet in the scene" : "without a sheet");
    Scene s = closedFurnace(rho, le, bounces);
    if (sheet) {
      Material glass;
      glass.type = MaterialType::ThinSheet;
      glass.ior = 1.5f;
      test::addMeshObject(s, "pane", makeQuad(), test::addMaterial(s, glass), Mat4::translate({0, 10, 0}));
    }
    for (int minBounces : {1, 3, 7}) {
      SCOPED_TRACE(minBounces);
      s.settings.minBounces = minBounces;
      // Light of three bounces or more is what roulette plays with: 1024 spp keep it within 1.5 %.
      RenderImage img = renderScene(*r, s, 1024);
      double expected = minBounces > bounces ? 0.0 : le * (std::pow(rho, minBounces) - std::pow(rho, bounces + 1)) / (1 - rho);
      double mean = test::meanLuminance(img, 0, 0, 16, 16);
      if (expected == 0) EXPECT_EQ(mean, 0.0);
      else EXPECT_NEAR(mean, expected, expected * 0.015) << "expected " << expected;
    }
  }
}

// Without light sampling (Tungsten's enable_light_sampling false) lights are found by the paths
// that hit them, at their full weight: the furnace and a floor under the sky read what they read
// with it; a point light, which no path can hit, lights nothing, and with it the floor under it
// reads I rho / (pi h^2).
TEST(KnownAnswer, WithoutLightSamplingOnlyPathsFindLights) {
  RETILE_RENDERER_OR_SKIP(r);
  const float rho = 0.5f;
  Scene furnace = closedFurnace(rho, 1.0f, 6);
  furnace.settings.lightSampling = false;
  double expected = (1 - std::pow(rho, 7)) / (1 - rho);
  EXPECT_NEAR(test::meanLuminance(renderScene(*r, furnace, 256), 0, 0, 16, 16), expected, expected * 0.01);

  Scene sky = test::emptyScene(32, 32);
  lookStraightDown(sky, 3, 20);
  sky.settings.maxBounces = 3;
  sky.settings.lightSampling = false;
  sky.environment.color = Vec3{2.0f};
  NodeId plane = test::addMeshObject(sky, "plane", makeQuad(), test::addMaterial(sky, grey(0.5f)), Mat4::scale({1000, 1, 1000}));
  EXPECT_NEAR(meanOver(renderScene(*r, sky, 128), plane), 1.0, 0.01);

  Scene lamp = test::emptyScene(16, 16);
  lookStraightDown(lamp, 0.5f, 2);
  lamp.settings.maxBounces = 1;
  NodeId floor = test::addMeshObject(lamp, "floor", makeQuad(), test::addMaterial(lamp, grey(0.8f)), Mat4::scale({100, 1, 100}));
  Light point;
  point.id = lamp.newId();
  point.position = {0, 1, 0};
  point.intensity = 2.0f;
  lamp.lights.push_back(point);
  const double lit = 2.0 * 0.8 / kPi;
  EXPECT_NEAR(meanOver(renderScene(*r, lamp, 16), floor), lit, lit * 0.01);
  lamp.settings.lightSampling = false;
  EXPECT_EQ(meanOver(renderScene(*r, lamp, 16), floor), 0.0);
  // Back on, through an update as the editor sends it: the light samples come back.
  lamp.settings.lightSampling = true;
  r->updateScene(lamp, kUpdateSettings);
  RenderRequest req;
  req.samplesPerPixel = 16;
  req.seed = 1;
  EXPECT_NEAR(meanOver(r->render(req), floor), lit, lit * 0.01);
}

TEST(KnownAnswer, DiffusePlaneUnderUniformSky) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(32, 32);
  // Looking straight down at a large plane: it sees only sky above it.
  lookStraightDown(s, 3, 20);
  s.settings.maxBounces = 3;
  s.environment.color = Vec3{2.0f};
  Material m;
  m.albedo = Vec3{0.5f};
  NodeId plane = test::addMeshObject(s, "plane", makeQuad(), test::addMaterial(s, m), Mat4::scale({1000, 1, 1000}));
  RenderImage img = renderScene(*r, s, 128);
  EXPECT_NEAR(meanOver(img, plane), 1.0, 0.01);
}

// Where rays leave a surface (RayOffset). A floor of albedo 0.8 under a black lid h = 2.5e-4
// above it, under a sky of 1, seen from between the two. Robust rays from the floor all meet the
// lid: the floor reads 0. Tungsten's start at the point they leave and skip 5e-4 along their
// direction, so those within 60 degrees of the normal (cos > h / 5e-4) pass the lid and see the
// sky: 0.8 (1 - 0.5^2) = 0.6, by light samples and BSDF samples alike. Away from the origin: there
// the robust offset is ulps of the position, near it a fixed 1.5e-5, which would blur the answer.
// At y = 0.04 those ulps are 1e-6; at y = 4, 1.2e-4, half the gap: a ray lifted by them as well
// passes the lid for cos > 0.26 and reads 0.75, so Tungsten's rays must not be lifted.
TEST(KnownAnswer, TungstensRaysSkipWhatLiesWithinItsEpsilon) {
  RETILE_RENDERER_OR_SKIP(r);
  const float lidAbove = 2.5e-4f;
  for (float floorY : {0.04f, 4.0f}) {
    for (RayOffset offset : {RayOffset::Robust, RayOffset::FixedEpsilon}) {
      SCOPED_TRACE(std::string(offset == RayOffset::FixedEpsilon ? "Tungsten's offset" : "robust offset") + ", the floor at y " +
                   std::to_string(floorY));
      Scene s = test::emptyScene(16, 16);
      // Looking down at (2, 1), away from the quads' diagonals: rounding leaves a crack along a
      // shared edge, wider the larger the triangles.
      s.camera.position = {2, floorY + lidAbove / 2, 1};
      s.camera.target = {2, floorY, 1};
      s.camera.up = {0, 0, -1};
      s.camera.verticalFov = radians(20.0f);
      s.settings.maxBounces = 1;
      s.settings.rayOffset = offset;
      s.environment.color = Vec3{1.0f};
      NodeId floor = test::addMeshObject(s, "floor", makeQuad(), test::addMaterial(s, grey(0.8f)),
                                         Mat4::translate({0, floorY, 0}) * Mat4::scale({10, 1, 10}));
      test::addMeshObject(s, "lid", makeQuad(), test::addMaterial(s, grey(0.0f)),
                          Mat4::translate({0, floorY + lidAbove, 0}) * Mat4::scale({10, 1, 10}));
      RenderImage img = renderScene(*r, s, 256);
      int n;
      const double mean = meanOver(img, floor, &n);
      ASSERT_EQ(n, 16 * 16) << "the camera sees the floor alone";
      // Robust: only the rare ray that grazes out past the lid's edge, 5 units away.
      if (offset == RayOffset::Robust) EXPECT_LT(mean, 1e-6) << "no light gets under the lid";
      else EXPECT_NEAR(mean, 0.6, 0.01);
    }
  }
}

// An object hit from the front only (Object::cullBackFaces, a Tungsten mesh's backface_culling).
// A floor of albedo 0.8 under a sky of 1, and a black lid one unit above it, much wider than the
// gap. Seen from between the two, the floor reads 0.8 where every ray up passes the lid (its
// back faces the floor), by light samples and BSDF samples alike, and almost 0 where the lid
// blocks them (its front faces the floor, or it is hit from both sides). Seen from above the
// lid, the camera sees the lid when its front faces up and sees through it to the floor
// otherwise. The scene is given once and then updated as an edit in the editor updates it: the
// first cases toggle the flag alone, packed direct (each triangle names its instance and flags,
// renamed when they change); the lid turned, mirrored or given the floor's mesh afterwards is
// reached through instance records and their flags.
TEST(KnownAnswer, AnObjectHitFromTheFrontOnlyIsPassedFromBehind) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(16, 16);
  s.settings.maxBounces = 1;
  s.environment.color = Vec3{1.0f};
  auto quad = makeQuad();  // facing +y
  NodeId floor = test::addMeshObject(s, "floor", quad, test::addMaterial(s, grey(0.8f)), Mat4::scale({100, 1, 100}));
  const Mat4 up = Mat4::translate({0, 1, 0}) * Mat4::scale({100, 1, 100});
  NodeId lid = test::addMeshObject(s, "lid", makeQuad(), test::addMaterial(s, grey(0.0f)), up);
  Object* lidObject = &s.objects.back();
  const NodeId ownMesh = lidObject->mesh, floorMesh = s.objects.front().mesh;
  struct Case {
    const char* what;
    Mat4 transform;
    bool shared, culled, between;
    NodeId seen;
    double floorMean;
  };
  // Looking down at (2, 1), away from the quads' diagonals (see the epsilon test above).
  const Case cases[] = {
      {"not culled, from between", up, false, false, true, floor, 0.0},
      {"culled, facing up, from between", up, false, true, true, floor, 0.8},
      {"culled, facing up, from above", up, false, true, false, lid, 0.0},
      {"culled, turned to face down, from above", up * Mat4::rotateX(kPi), false, true, false, floor, 0.0},
      {"culled, mirrored to face down, from above", Mat4::translate({0, 1, 0}) * Mat4::scale({100, -1, 100}), false, true, false, floor,
       0.0},
      {"culled, mirrored, from between", Mat4::translate({0, 1, 0}) * Mat4::scale({100, -1, 100}), false, true, true, floor, 0.0},
      {"culled, the floor's mesh, from between", up, true, true, true, floor, 0.8},
      {"not culled, the floor's mesh, from between", up, true, false, true, floor, 0.0},
      {"culled, the floor's mesh, from above", up, true, true, false, lid, 0.0},
  };
  RenderRequest req;
  req.samplesPerPixel = 128;
  req.seed = 1;
  bool first = true;
  int k = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    lidObject->transform = c.transform;
    lidObject->mesh = c.shared ? floorMesh : ownMesh;
    lidObject->cullBackFaces = c.culled;
    s.camera.position = {2, c.between ? 0.5f : 3.0f, 1};
    s.camera.target = {2, 0, 1};
    s.camera.up = {0, 0, -1};
    s.camera.verticalFov = radians(20.0f);
    if (first) r->setScene(s);
    else r->updateScene(s, kUpdateInstances | kUpdateLights | kUpdateCamera);  // SetObject's, and SetCamera's
    first = false;
    RenderImage img = r->render(req);
    int n;
    const double mean = meanOver(img, c.seen, &n);
    EXPECT_EQ(n, 16 * 16) << "the camera sees " << (c.seen == lid ? "the lid" : "the floor") << " alone";
    if (c.seen == floor && n > 0) {
      EXPECT_NEAR(mean, c.floorMean, 0.01);
    }
    const std::vector<std::string> kernel = r->kernelFeatures();
    EXPECT_EQ(std::find(kernel.begin(), kernel.end(), "back faces culled") != kernel.end(), c.culled)
        << "the kernel culls only when an object asks for it";
    if (k++ < 3) {
      EXPECT_NE(std::find(kernel.begin(), kernel.end(), "direct references"), kernel.end()) << "the flag alone changed";
    }
  }
}

// A sky map bright (2) above its horizon and black below, over a white-ish plane facing up: the
// plane's radiance is albedo / pi times the irradiance from the bright half it sees. Upright: 1.
// Turned upside down by its orientation: 0. Tilted a quarter turn about x (its up along world
// +z): a quarter of the sphere lights the plane, 0.5. Light samples (drawn in the map's frame),
// the sky that BSDF rays hit and the density MIS weighs them by must all turn alike.
TEST(KnownAnswer, ATiltedSkyLightsWhatItsBrightHalfFaces) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(16, 16);
  lookStraightDown(s, 3, 20);
  s.settings.maxBounces = 1;
  const auto dir = test::tempDir();
  s.environment.type = EnvironmentType::Map;
  s.environment.map = addImageTexture(s, dir, "half sky", 64, 32, [](int, int y) { return y < 16 ? 2.0f : 0.0f; });
  s.environment.color = Vec3{1.0f};
  Material m;
  m.albedo = Vec3{0.5f};
  NodeId plane = test::addMeshObject(s, "plane", makeQuad(), test::addMaterial(s, m), Mat4::scale({1000, 1, 1000}));
  for (auto [tilt, expected] : {std::pair{0.0f, 1.0}, std::pair{kPi, 0.0}, std::pair{kPi / 2, 0.5}}) {
    s.environment.orientation = Mat4::rotateX(tilt);
    s.environment.rotation = 0.4f;  // a turn about +y changes none of these
    EXPECT_NEAR(meanOver(renderScene(*r, s, 64), plane), expected, 0.015) << "tilted by " << tilt;
  }

  // A small bright patch off to one side, mostly reached by light samples: the plane under the
  // tilted sky is lit as the plane and camera turned the other way are under the upright sky.
  s.environment.map =
      addImageTexture(s, dir, "patch sky", 64, 32, [](int x, int y) { return y >= 6 && y < 10 && x >= 10 && x < 18 ? 50.0f : 0.05f; });
  const Mat4 tilt = Mat4::rotateZ(0.3f) * Mat4::rotateX(-0.5f), back = tilt.transposed();
  s.environment.orientation = tilt;
  s.environment.rotation = 0;
  const double tilted = meanOver(renderScene(*r, s, 256), plane);
  s.environment.orientation = Mat4{};
  s.objects[0].transform = back * s.objects[0].transform;
  s.camera.position = back.transformVector(s.camera.position);
  s.camera.up = back.transformVector(s.camera.up);
  const double upright = meanOver(renderScene(*r, s, 256), plane);
  EXPECT_GT(upright, 0.3) << "the patch lights the plane";
  EXPECT_NEAR(tilted, upright, 0.02 * upright);
}

// Meshes are packed where their objects first put them (render_scene.h), and an object moved
// afterwards is reached through its instance's transform from there: the picture is the one of a
// scene packed with the object where it now is. A cube over a plane under a white sky, turned
// and moved after packing: the plane's shadowed light, and which pixels see the cube.
TEST(KnownAnswer, AnObjectMovedAfterPackingRendersAsIfPackedThere) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(32, 32);
  lookStraightDown(s, 6, 60);
  s.settings.maxBounces = 2;
  s.environment.color = Vec3{1.0f};
  Material m;
  m.albedo = Vec3{0.5f};
  const NodeId mat = test::addMaterial(s, m);
  const NodeId plane = test::addMeshObject(s, "plane", makeQuad(), mat, Mat4::scale({10, 1, 10}));
  const NodeId cube = test::addMeshObject(s, "cube", makeCube(), mat, Mat4::translate({-1, 1, 0}) * Mat4::scale(Vec3{0.5f}));
  r->setScene(s);
  s.object(cube)->transform = Mat4::translate({1, 1.5f, 0.5f}) * Mat4::rotateY(0.6f) * Mat4::scale({0.8f, 0.4f, 1.2f});
  r->updateScene(s, kUpdateInstances);
  RenderRequest req;
  req.samplesPerPixel = 128;
  req.seed = 1;  // renderScene's: the same rays, so that only the geometry can tell the two apart
  const RenderImage moved = r->render(req);
  const RenderImage packed = renderScene(*r, s, 128, req.seed);
  int cubeMoved = 0, cubePacked = 0, differ = 0;
  for (std::size_t i = 0; i < moved.objectId.size(); ++i) {
    cubeMoved += moved.objectId[i] == cube;
    cubePacked += packed.objectId[i] == cube;
    differ += moved.objectId[i] != packed.objectId[i];
  }
  EXPECT_GT(cubePacked, 20) << "the cube is in view";
  EXPECT_NEAR(cubeMoved, cubePacked, 3);
  EXPECT_LE(differ, 2) << "pixels whose first hit differs (a ray that grazes an edge may round either way)";
  const double lit = meanOver(packed, plane);
  EXPECT_LT(lit, 0.5 * 0.99) << "the cube shades part of the plane";
  EXPECT_NEAR(meanOver(moved, plane), lit, 0.01 * lit);
}

// Seen straight along +x the sky's u is 0.5, the edge between the two middle columns of a map of
// eight whose columns alternate 0 and 1: filtered between the nearest texels (as Tungsten's
// bitmaps are) every pixel of a 2-degree view reads about 0.5; read from the nearest texel
// alone, half of them would read 0 and half 1.
TEST(KnownAnswer, TheSkyIsFilteredBetweenTexels) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(16, 16);
  s.camera.position = {0, 0, 0};
  s.camera.target = {1, 0, 0};
  s.camera.up = {0, 1, 0};
  s.camera.verticalFov = radians(2.0f);
  s.environment.type = EnvironmentType::Map;
  s.environment.map = addColumnTexture(s, test::tempDir(), "stripes", 8, 4, [](int x) { return static_cast<float>(x % 2); });
  s.environment.color = Vec3{1.0f};
  RenderImage img = renderScene(*r, s, 16);
  double lo = 1, hi = 0;
  for (std::size_t i = 0; i < img.color.size() / 3; ++i) {
    lo = std::min<double>(lo, img.color[i * 3 + 1]);
    hi = std::max<double>(hi, img.color[i * 3 + 1]);
  }
  EXPECT_GT(lo, 0.45);
  EXPECT_LT(hi, 0.55);
}

// Seen from 3 above the origin, looking down, under a sky of radiance 1 and one bounce: a lambert
// surface there reads its albedo.
Scene underUnitSky(int width, int height, float fovDegrees) {
  Scene s = test::emptyScene(width, height);
  lookStraightDown(s, 3, fovDegrees);
  s.settings.maxBounces = 1;
  s.environment.color = Vec3{1.0f};
  return s;
}

// A blend (Tungsten's mixed bsdf) shades as either part, chosen again at every hit: a white
// lambert blended at ratio 0.3 with a black one, under a sky of 1, reads 0.3 (1 if the blend
// were ignored); an emitting blend keeps its emission whichever part a hit shades with.
TEST(KnownAnswer, ABlendShadesAsEitherPartInProportion) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = underUnitSky(16, 16, 20);
  Material white = grey(1.0f);
  white.blendWith = test::addMaterial(s, grey(0.0f));
  white.blendRatio = 0.3f;
  NodeId blend = test::addMaterial(s, white);
  NodeId plane = test::addMeshObject(s, "plane", makeQuad(), blend, Mat4::scale({1000, 1, 1000}));
  EXPECT_NEAR(meanOver(renderScene(*r, s, 64), plane), 0.3, 0.015);
  s.material(blend)->emission = Vec3{2.0f};
  EXPECT_NEAR(meanOver(renderScene(*r, s, 64), plane), 2.3, 0.03) << "the emission is the blend's, whichever part shades";
}

// A blend whose partner blends in its turn (Tungsten's blends of blends): white at 0.4, else
// white at 0.5, else black, under a sky of 1, reads 0.4 + 0.6 * 0.5 = 0.7 (0.4 + 0.6 = 1 if the
// partner's own blend were not followed).
TEST(KnownAnswer, ABlendOfABlendShadesAsTheChainSays) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = underUnitSky(16, 16, 20);
  Material second = grey(1.0f);
  second.blendWith = test::addMaterial(s, grey(0.0f));
  second.blendRatio = 0.5f;
  Material first = grey(1.0f);
  first.blendWith = test::addMaterial(s, second);
  first.blendRatio = 0.4f;
  NodeId plane = test::addMeshObject(s, "plane", makeQuad(), test::addMaterial(s, first), Mat4::scale({1000, 1, 1000}));
  EXPECT_NEAR(meanOver(renderScene(*r, s, 64), plane), 0.7, 0.02);
}

// A blend whose ratio has a texture (Tungsten's textured `ratio`): the ratio is the constant
// times the texture's channel mean where the surface is hit. A white lambert blended with a black
// one at 0.8 times a mask of 1 over u < 0.5 and 0.25 over the rest, under a sky of 1, reads 0.8
// over the one half and 0.2 over the other (both 0.8 if the texture were ignored).
TEST(KnownAnswer, ATexturedBlendRatioVariesOverTheSurface) {
  RETILE_RENDERER_OR_SKIP(r);
  auto dir = test::tempDir();
  Scene s = underUnitSky(32, 32, 16);  // the unit quad fills the frame
  Material white = grey(1.0f);
  white.blendWith = test::addMaterial(s, grey(0.0f));
  white.blendRatio = 0.8f;
  white.blendRatioTexture = addColumnTexture(s, dir, "mask", 64, 1, [](int x) { return x < 32 ? 1.0f : 0.25f; });
  NodeId plane = test::addMeshObject(s, "plane", makeQuad(), test::addMaterial(s, white), Mat4::identity());
  const RenderImage img = renderScene(*r, s, 256);
  // Image x runs along world x and u: the mask's edge is down the middle; its texels are
  // filtered across it, so the columns next to it are left out.
  double left = 0, right = 0;
  int nLeft = 0, nRight = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * img.width + x;
      ASSERT_EQ(img.objectId[i], plane) << "the quad fills the frame";
      if (x < 12) left += img.color[i * 3 + 1], ++nLeft;
      if (x >= 20) right += img.color[i * 3 + 1], ++nRight;
    }
  EXPECT_NEAR(left / nLeft, 0.8, 0.02);
  EXPECT_NEAR(right / nRight, 0.2, 0.015);
}

// An 8-bit grey texture of one row (PPM, so that the reader sees 8 bits), added to the scene.
NodeId addByteRow(Scene& s, const std::filesystem::path& dir, const std::string& name, const std::vector<int>& row,
                  TextureColorSpace space) {
  const auto file = dir / (name + ".ppm");
  std::vector<std::uint8_t> rgb;
  for (int v : row) rgb.insert(rgb.end(), 3, static_cast<std::uint8_t>(v));
  test::writePpm(file, static_cast<int>(row.size()), 1, rgb);
  return test::addFileTexture(s, file, space);
}

// 8-bit textures keep their bytes on the device (a word a texel, two to a pair) and are decoded
// there, as they were decoded on the CPU before: sRGB by its curve, Tungsten's gamma by its table
// (applied to the bytes), linear as they are. Between them, textures of odd texel counts and
// half-float textures, so that every one's offset is checked. Under a sky of 1 with one bounce, a
// white lambert textured with a uniform texture reads the texture's value. A row of two texels,
// 255 then 0, filtered and wrapped, rises from 0.5 at u = 0 to 1 at u = 1/4 and falls to 0 at 3/4:
// over the left half of the frame (u from a to 1/2, the view 16 degrees wide from 3 above the
// unit quad) it averages (3/8 - a/2 - a^2) / (1/2 - a), 0.782, and over the right half 1 minus
// that; with the texels of a pair swapped, the other way round. Last, a sky map of 1 instead of
// the constant sky.
TEST(KnownAnswer, EightBitTexturesReadAsTheirDecodedValues) {
  RETILE_RENDERER_OR_SKIP(r);
  auto dir = test::tempDir();
  Scene s = underUnitSky(32, 32, 16);  // the unit quad fills the frame
  const double tungsten100 = std::floor(255.0 * std::pow(100.0 / 255.0, 2.2)) / 255.0;
  const double srgb200 = std::pow((200.0 / 255.0 + 0.055) / 1.055, 2.4);
  struct Case {
    NodeId texture;
    double expected;
    const char* what;
  };
  const std::vector<Case> cases = {
      {addColumnTexture(s, dir, "half-first", 3, 1, [](int) { return 0.5f; }), 0.5, "a half-float texture of 3 texels"},
      {addByteRow(s, dir, "srgb", std::vector<int>(3, 200), TextureColorSpace::SRGB), srgb200, "8-bit sRGB, 3 texels"},
      {addByteRow(s, dir, "tungsten", std::vector<int>(5, 100), TextureColorSpace::Gamma22), tungsten100,
       "8-bit with Tungsten's gamma, 5 texels"},
      {addColumnTexture(s, dir, "half-after", 3, 1, [](int) { return 0.25f; }), 0.25, "a half-float texture after 8-bit ones"},
      {addByteRow(s, dir, "linear", std::vector<int>(1, 64), TextureColorSpace::Linear), 64.0 / 255.0, "8-bit linear, 1 texel"},
  };
  const NodeId pairTexture = addByteRow(s, dir, "pair", {255, 0}, TextureColorSpace::Linear);
  Material white = grey(1.0f);
  white.albedoTexture = cases[0].texture;
  const NodeId material = test::addMaterial(s, white);
  const NodeId plane = test::addMeshObject(s, "plane", makeQuad(), material, Mat4::identity());
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    s.material(material)->albedoTexture = c.texture;
    EXPECT_NEAR(meanOver(renderScene(*r, s, 16), plane), c.expected, 0.004);
  }
  s.material(material)->albedoTexture = pairTexture;
  const RenderImage img = renderScene(*r, s, 64);
  double left = 0, right = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const double v = img.color[(static_cast<std::size_t>(y) * img.width + x) * 3 + 1];
      (x < img.width / 2 ? left : right) += v;
    }
  const double half = img.width / 2.0 * img.height;
  const double a = 0.5 - 3.0 * std::tan(8.0 * std::numbers::pi / 180.0);
  const double expected = (0.375 - 0.5 * a - a * a) / (0.5 - a);
  EXPECT_NEAR(left / half, expected, 0.006);
  EXPECT_NEAR(right / half, 1.0 - expected, 0.006);
  // A sky map of 1 (half floats) among 8-bit textures, the only half floats: both storages are
  // read in one kernel.
  std::erase_if(s.textures, [&](const Texture& t) { return t.id == cases[0].texture || t.id == cases[3].texture; });
  s.environment.type = EnvironmentType::Map;
  s.environment.map = addColumnTexture(s, dir, "sky", 4, 2, [](int) { return 1.0f; });
  s.material(material)->albedoTexture = cases[2].texture;
  EXPECT_NEAR(meanOver(renderScene(*r, s, 16), plane), tungsten100, 0.004) << "under a sky map";
}

// An sRGB byte decodes to the sRGB curve to 1e-4 of its value, tighter than the EightBit test's
// lambert under a sky can say (a cheaper curve in the kernel must keep to it): seen directly with
// no bounce, an emitter of 1 textured by a uniform sRGB texture shows the texture's decoded value
// in every pixel. The bytes straddle the curve's linear foot (10 and 11 about 0.04045) and span
// the rest.
TEST(KnownAnswer, SrgbBytesDecodeToTheirCurve) {
  RETILE_RENDERER_OR_SKIP(r);
  auto dir = test::tempDir();
  Scene s = underUnitSky(8, 8, 16);  // the unit quad fills the frame
  s.settings.maxBounces = 0;
  Material light = grey(0.0f);
  light.emission = Vec3{1.0f};
  const NodeId material = test::addMaterial(s, light);
  const NodeId plane = test::addMeshObject(s, "plane", makeQuad(), material, Mat4::identity());
  for (int byte : {0, 1, 10, 11, 12, 30, 64, 100, 128, 180, 230, 254, 255}) {
    SCOPED_TRACE("byte " + std::to_string(byte));
    const double c = byte / 255.0;
    const double expected = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
    s.material(material)->emissionTexture =
        addByteRow(s, dir, "b" + std::to_string(byte), std::vector<int>(3, byte), TextureColorSpace::SRGB);
    EXPECT_NEAR(meanOver(renderScene(*r, s, 1), plane), expected, 1e-4 * expected + 1e-7);
  }
}

// A texture of two texels, 1 and 0, across the unit quad that fills the frame (the frame spans u
// from a to 1 - a). Read at the nearest texel (Texture::interpolate off), the left half is 1 and
// the right 0 but for the column the pixel filter straddles; held at its edges (clampToEdge), the
// bilinear ramp runs from u = 0.25 to 0.75 only, so the left half's mean is (0.4375 - a) / (0.5 -
// a) where repeating gives the EightBit test's (0.375 - a / 2 - a^2) / (0.5 - a).
TEST(KnownAnswer, ABitmapIsReadAtItsNearestTexelOrHeldAtItsEdgesWhenAsked) {
  RETILE_RENDERER_OR_SKIP(r);
  auto dir = test::tempDir();
  Scene s = underUnitSky(32, 32, 16);
  const NodeId pair = addByteRow(s, dir, "pair", {255, 0}, TextureColorSpace::Linear);
  Material white = grey(1.0f);
  white.albedoTexture = pair;
  test::addMeshObject(s, "plane", makeQuad(), test::addMaterial(s, white), Mat4::identity());
  auto halves = [&] {
    const RenderImage img = renderScene(*r, s, 64);
    double left = 0, right = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x)
        (x < img.width / 2 ? left : right) += img.color[(static_cast<std::size_t>(y) * img.width + x) * 3 + 1];
    const double half = img.width / 2.0 * img.height;
    return std::pair{left / half, right / half};
  };
  const double a = 0.5 - 3.0 * std::tan(8.0 * std::numbers::pi / 180.0);
  s.texture(pair)->interpolate = false;
  auto [nearLeft, nearRight] = halves();
  EXPECT_GT(nearLeft, 0.96);
  EXPECT_LT(nearRight, 0.04);
  EXPECT_NEAR(nearLeft + nearRight, 1.0, 0.006);
  s.texture(pair)->interpolate = true;
  s.texture(pair)->clampToEdge = true;
  auto [heldLeft, heldRight] = halves();
  EXPECT_NEAR(heldLeft, (0.4375 - a) / (0.5 - a), 0.006);
  EXPECT_NEAR(heldRight, 1.0 - (0.4375 - a) / (0.5 - a), 0.006);
  EXPECT_GT(heldLeft - (0.375 - 0.5 * a - a * a) / (0.5 - a), 0.05) << "repeating would read measurably less";
}

// A checker of two cells across u, on 1 and off 0, on the unit quad whose u runs from -1 to 1
// (the frame spans x from -0.42 to 0.42). Floored, the cells left of the middle are u * 2 in
// [-2, -1) off and [-1, 0) on; counted as Tungsten counts them (truncated toward zero), (-2, -1] is
// on and (-1, 1) off, a cell twice as wide about u = 0. Right of the middle both agree.
TEST(KnownAnswer, ATungstenCheckerCountsItsCellsTowardZero) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = underUnitSky(32, 32, 16);
  Texture checker;
  checker.id = s.newId();
  checker.name = "checker";
  checker.kind = TextureKind::Checker;
  checker.checkerOn = Vec3{1.0f};
  checker.checkerOff = Vec3{0.0f};
  checker.checkerResU = 2;
  checker.checkerResV = 1;
  s.textures.push_back(checker);
  Material white = grey(1.0f);
  white.albedoTexture = checker.id;
  auto quad = std::make_shared<MeshGeometry>(*makeQuad());
  for (std::size_t i = 0; i < quad->positions.size(); ++i) quad->uvs[i] = {2 * quad->positions[i].x, 0.5f};
  test::addMeshObject(s, "plane", quad, test::addMaterial(s, white), Mat4::identity());
  // Columns well inside x in (-0.42, -0.25) and (-0.25, 0), then (0, 0.25) and (0.25, 0.42).
  auto columns = [](const RenderImage& img, int from, int to) {
    double sum = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = from; x <= to; ++x) sum += img.color[(static_cast<std::size_t>(y) * img.width + x) * 3 + 1];
    return sum / ((to - from + 1) * img.height);
  };
  const int outerLeft[2] = {1, 4}, innerLeft[2] = {9, 13}, innerRight[2] = {18, 22}, outerRight[2] = {27, 30};
  const RenderImage floored = renderScene(*r, s, 32);
  EXPECT_LT(columns(floored, outerLeft[0], outerLeft[1]), 0.02) << "floored";
  EXPECT_GT(columns(floored, innerLeft[0], innerLeft[1]), 0.98);
  s.texture(checker.id)->truncatedCells = true;
  const RenderImage truncated = renderScene(*r, s, 32);
  EXPECT_GT(columns(truncated, outerLeft[0], outerLeft[1]), 0.98) << "truncated";
  EXPECT_LT(columns(truncated, innerLeft[0], innerLeft[1]), 0.02);
  EXPECT_LT(columns(truncated, innerRight[0], innerRight[1]), 0.02) << "right of the middle both agree";
  EXPECT_GT(columns(truncated, outerRight[0], outerRight[1]), 0.98);
}

// A sky map brighter than a half float's largest value (65504), as a sun in an HDR sky often is:
// its texels are stored scaled down by a power of two and scaled back where they are read. A
// uniform map of 2e6 (green) over a lambert plane of albedo 0.5 reads 1e6; clipped to halves, the
// map read infinite and lit nothing.
TEST(KnownAnswer, ASkyBrighterThanAHalfFloatKeepsItsLight) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = underUnitSky(16, 16, 20);
  const auto file = test::tempDir() / "bright-sky.pfm";
  {
    // Portable float map: little-endian floats (the negative scale says so), bottom row first.
    std::ofstream out(file, std::ios::binary);
    out << "PF\n8 4\n-1.0\n";
    const float texel[3] = {1e6f, 2e6f, 3e6f};
    for (int i = 0; i < 8 * 4; ++i) out.write(reinterpret_cast<const char*>(texel), sizeof texel);
  }
  s.environment.type = EnvironmentType::Map;
  s.environment.map = test::addFileTexture(s, file, TextureColorSpace::Linear);
  NodeId plane = test::addMeshObject(s, "plane", makeQuad(), test::addMaterial(s, grey(0.5f)), Mat4::scale({1000, 1, 1000}));
  EXPECT_NEAR(meanOver(renderScene(*r, s, 16), plane), 1e6, 1e4);
}

// A cut-out (alpha below 1) lets a ray through with probability 1 - alpha, camera rays and
// shadow rays alike: a black plane of alpha 0.3 one unit above a white one, under a sky of 1 with
// one bounce, shows the white plane in 0.7 of the samples, lit through the cut-out by 0.7 of the
// sky: 0.49 over the image. The same with the alpha in an 8-bit texture (77 of 255), and with
// many cut-outs stacked (ten planes of alpha 0.1: 0.9^10 squared), where rays meet one
// candidate after another.
TEST(KnownAnswer, ACutOutLetsThroughWhatItsAlphaLeavesOut) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = underUnitSky(16, 16, 20);
  test::addMeshObject(s, "white", makeQuad(), test::addMaterial(s, grey(1.0f)), Mat4::scale({1000, 1, 1000}));
  Material cut = grey(0.0f);
  cut.alpha = 0.3f;
  const NodeId cutMaterial = test::addMaterial(s, cut);
  test::addMeshObject(s, "cut-out", makeQuad(), cutMaterial, Mat4::translate({0, 1, 0}) * Mat4::scale({1000, 1, 1000}));
  EXPECT_NEAR(imageMean(renderScene(*r, s, 64)), 0.49, 0.015) << "constant alpha";
  s.material(cutMaterial)->alpha = 1.0f;
  s.material(cutMaterial)->alphaTexture = addByteRow(s, test::tempDir(), "alpha", std::vector<int>(3, 77), TextureColorSpace::Raw);
  const double through = 1.0 - 77.0 / 255.0;
  EXPECT_NEAR(imageMean(renderScene(*r, s, 64)), through * through, 0.015) << "alpha from a texture";
  // A texture without an alpha channel covers by its channels' mean (Tungsten's REQUEST_AUTO):
  // red 231 alone is 77 too (read by its red, it would let 0.009 through).
  const auto redFile = test::tempDir() / "red.ppm";
  test::writePpm(redFile, 3, 1, {231, 0, 0, 231, 0, 0, 231, 0, 0});
  s.material(cutMaterial)->alphaTexture = test::addFileTexture(s, redFile, TextureColorSpace::Raw);
  EXPECT_NEAR(imageMean(renderScene(*r, s, 64)), through * through, 0.015) << "alpha from a colour texture";
  s.material(cutMaterial)->alphaTexture = kNoNode;
  s.material(cutMaterial)->alpha = 0.1f;
  for (int i = 1; i < 10; ++i)
    test::addMeshObject(s, "cut-out", makeQuad(), cutMaterial, Mat4::translate({0, 1 + 0.1f * i, 0}) * Mat4::scale({1000, 1, 1000}));
  EXPECT_NEAR(imageMean(renderScene(*r, s, 64)), std::pow(0.9, 20), 0.015) << "ten cut-outs";
}

// A ray that passes a cut-out leaves it as Tungsten's rays leave a surface (RayOffset): with
// Tungsten's offset it skips what lies within 5e-4 beyond it, and goes on from the next thing it
// meets past that. So a thin shell of cut-outs (the kitchen's blinds: two faces 0.25 mm apart)
// lets through 1 - alpha where the faces lie within 5e-4 of each other along the ray, not
// (1 - alpha)^2. A white floor under a sky of 1, and above it n black cut-outs of alpha 0.3, h
// apart, seen from above: a camera ray (within 10 degrees of the normal: the leading factors
// below) and the floor's light from a direction at cos theta = c meet the layers spaced h / c
// along the ray. Two layers,
// h = 2.5e-4: the second is skipped where c >= h / 5e-4 = 0.5, a share 1 - 0.5^2 = 0.75 of the
// floor's cosine-weighted sky: 0.7 (0.7 0.75 + 0.49 0.25) = 0.45325. Three, h = 3e-4: the
// second is skipped wherever c >= 0.6 (0.64 of the sky) and the third, 6e-4 past the first, is
// met there: 0.49 (0.49 0.64 + 0.343 0.36) = 0.214; one that skipped whatever lay within 5e-4 of
// any passed layer would skip the third behind a passed second. The robust offset meets every
// layer: 0.7^(2n). Bounces enough that a pass counted as one (Tungsten's forward event) would
// change nothing: light reaches the floor's paths once.
TEST(KnownAnswer, APassedCutOutIsLeftAsTheRaysOffsetSays) {
  RETILE_RENDERER_OR_SKIP(r);
  for (RayOffset offset : {RayOffset::Robust, RayOffset::FixedEpsilon}) {
    for (int layers : {2, 3}) {
      SCOPED_TRACE(std::string(offset == RayOffset::FixedEpsilon ? "fixed offset, " : "robust offset, ") + std::to_string(layers) +
                   " layers");
      Scene s = underUnitSky(16, 16, 20);
      s.settings.maxBounces = 16;
      s.settings.rayOffset = offset;
      test::addMeshObject(s, "white", makeQuad(), test::addMaterial(s, grey(1.0f)), Mat4::scale({1000, 1, 1000}));
      Material cut = grey(0.0f);
      cut.alpha = 0.3f;
      const NodeId cutMaterial = test::addMaterial(s, cut);
      const float h = layers == 2 ? 2.5e-4f : 3e-4f;
      for (int i = 0; i < layers; ++i)
        test::addMeshObject(s, "layer", makeQuad(), cutMaterial,
                            Mat4::translate({0, 1 + h * static_cast<float>(i), 0}) * Mat4::scale({1000, 1, 1000}));
      double expected = std::pow(0.7, 2 * layers);
      if (offset == RayOffset::FixedEpsilon)
        expected = layers == 2 ? 0.7 * (0.7 * 0.75 + 0.49 * 0.25) : 0.49 * (0.49 * 0.64 + 0.343 * 0.36);
      EXPECT_NEAR(imageMean(renderScene(*r, s, 128)), expected, 0.012);
    }
  }
}

// The pixel filter (filter importance sampling): a light's straight edge on a pixel boundary.
// With a box each pixel sees only its own square; with Tungsten's tent (one pixel each way) the
// pixel on either side of the edge takes 1/8 from across it (the tent's mass beyond half a pixel);
// drawn as Tungsten draws it (31 steps, each landing one step further out) 0.1457 (0.2913 of one
// side's mass lies beyond half a pixel, from a direct evaluation of Tungsten's sampling routine).
TEST(KnownAnswer, PixelFiltersSpreadAnEdgeAsTheyShould) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(32, 8);
  lookStraightDown(s, 3, 20);  // image x is world x: the edge x = 0 is the boundary of columns 15 and 16
  s.settings.maxBounces = 0;
  Material light;
  light.albedo = Vec3{0.0f};
  light.emission = Vec3{1.0f};
  test::addMeshObject(s, "light", makeQuad(), test::addMaterial(s, light),
                      Mat4::translate({-500, 0, 0}) * Mat4::scale({1000, 1, 2000}));  // x from -1000 to 0
  auto column = [](const RenderImage& img, int x) {
    double sum = 0;
    for (int y = 0; y < img.height; ++y) sum += img.color[(static_cast<std::size_t>(y) * img.width + x) * 3 + 1];
    return sum / img.height;
  };
  for (auto [filter, sampling, inner, across] :
       {std::tuple{PixelFilter::Box, FilterSampling::Exact, 1.0, 0.0}, std::tuple{PixelFilter::Tent, FilterSampling::Exact, 0.875, 0.125},
        std::tuple{PixelFilter::Tent, FilterSampling::SteppedTable, 0.8543, 0.1457},
        std::tuple{PixelFilter::Box, FilterSampling::SteppedTable, 1.0, 0.0}}) {
    SCOPED_TRACE(std::string(pixelFilterName(filter)) + (sampling == FilterSampling::SteppedTable ? " as Tungsten draws it" : ""));
    s.settings.pixelFilter = filter;
    s.settings.filterWidth = defaultFilterWidth(filter);
    s.settings.filterSampling = sampling;
    const RenderImage img = renderScene(*r, s, 256);
    const double a = column(img, 15), b = column(img, 16);
    // 0.008: the two tents' spreads differ by 0.021
    EXPECT_NEAR(std::max(a, b), inner, 0.008);
    EXPECT_NEAR(std::min(a, b), across, 0.008);
    EXPECT_NEAR(std::max(column(img, 13), column(img, 18)), 1.0, 0.02) << "two pixels away: untouched";
    EXPECT_NEAR(std::min(column(img, 13), column(img, 18)), 0.0, 0.02);
  }
}

double smallLightOnPlane(Renderer& r, float height, NodeId* planeOut) {
  Scene s = test::emptyScene(16, 16);
  lookStraightDown(s, 0.5f, 2);  // just the spot below the light
  s.settings.maxBounces = 1;     // direct light only
  Material plane;
  plane.albedo = Vec3{1.0f};
  *planeOut = test::addMeshObject(s, "plane", makeQuad(), test::addMaterial(s, plane), Mat4::scale({100, 1, 100}));
  Material light;
  light.albedo = Vec3{0.0f};
  light.emission = Vec3{100.0f};
  test::addMeshObject(s, "light", makeQuad(), test::addMaterial(s, light),
                      Mat4::translate({0, height, 0}) * Mat4::rotateX(kPi) * Mat4::scale({0.05f, 1, 0.05f}));
  RenderImage img = renderScene(r, s, 64);
  return meanOver(img, *planeOut);
}

// Shading normals that lie (ShadingConvention): a plane whose normals lean 80 degrees towards +x,
// lit only by a point light below it on that side. Consistent: the light is behind the true
// surface, so the plane stays black. Tungsten's convention (two-sided shading, no consistency
// checks) lights it as if the shading normal were the surface: albedo / pi * I * cos / d^2 with the
// cosine taken against the shading normal.
TEST(KnownAnswer, ShadingConventionsDisagreeWhereTheShadingNormalLies) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(16, 16);
  lookStraightDown(s, 3, 2);
  s.settings.maxBounces = 1;
  auto g = std::make_shared<MeshGeometry>(*makeQuad());
  const float lean = radians(80);
  const Vec3 ns{std::sin(lean), std::cos(lean), 0};
  g->normals.assign(4, ns);
  Material m;
  m.albedo = Vec3{1.0f};
  NodeId plane = test::addMeshObject(s, "plane", g, test::addMaterial(s, m), Mat4{});
  Light light;
  light.id = s.newId();
  light.type = LightType::Point;
  light.intensity = 10.0f;
  light.position = {3, -0.5f, 0};
  s.lights.push_back(light);
  const Vec3 toLight = light.position;  // from the plane's centre
  const double d2 = dot(toLight, toLight);
  const double expected = 10.0 / kPi * dot(ns, toLight) / std::sqrt(d2) / d2;

  double consistent = meanOver(renderScene(*r, s, 64), plane);
  s.settings.shading = ShadingConvention::Unchecked;
  double tungsten = meanOver(renderScene(*r, s, 64), plane);
  EXPECT_LT(consistent, 1e-6) << "light from behind the true surface";
  EXPECT_NEAR(tungsten, expected, 0.03 * expected);
  EXPECT_GT(expected, 0.3);
}

TEST(KnownAnswer, ABumpMapTiltsTheNormalByItsSlope) {
  // A height that climbs 1/64 a texel along u: Tungsten's slope (the difference across two
  // texels) is 1/32, times a strength of 16 it is 0.5. On the default quad (u along +x, v along
  // +z, its uv winding opposite to its faces') Tungsten's tangents make the normal (0.5, 1, 0)
  // normalised. A sun from (+-1, 1, 0) then lights a white plane by E/pi n.l: 0.949 E/pi from the
  // side the normal leans to, 0.316 E/pi from the other, 0.707 E/pi without the bump.
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(16, 16);
  lookStraightDown(s, 3, 2);  // the middle tenth of the plane, far from the ramp's wrap
  s.settings.maxBounces = 1;
  Material m;
  m.albedo = Vec3{1.0f};
  m.bumpTexture = addColumnTexture(s, test::tempDir(), "ramp", 64, 8, [](int x) { return static_cast<float>(x) / 64.0f; });
  m.bumpStrength = 16.0f;
  NodeId material = test::addMaterial(s, m);
  NodeId plane = test::addMeshObject(s, "plane", makeQuad(), material, Mat4::scale({4, 1, 4}));
  addSun(s, 1.0f);

  const double n = std::sqrt(1.25), l = std::sqrt(2.0);
  for (float side : {1.0f, -1.0f}) {
    s.lights[0].direction = normalize(Vec3{-side, -1, 0});  // where the light travels
    double expected = (side * 0.5 + 1.0) / (n * l) / kPi;
    EXPECT_NEAR(meanOver(renderScene(*r, s, 16), plane), expected, 0.01 * expected) << "sun on the side " << side;
  }
  s.material(material)->bumpStrength = 0.0f;
  double flat = 1.0 / l / kPi;
  EXPECT_NEAR(meanOver(renderScene(*r, s, 16), plane), flat, 0.01 * flat) << "no slope, no tilt";
}

// A sun of irradiance E overhead, with a disc of angular radius a, lights a white plane by
// E (1 + cos a) / 2 / pi: its radiance E / (solid angle) over the cone's projected area
// pi sin^2 a. Light samples over the cone and BSDF rays that leave towards it share the
// answer through MIS; a wide disc makes both count. Seen directly, the disc is that radiance.
TEST(KnownAnswer, ASunsDiscLightsAndShowsAsItsRadiance) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(16, 16);
  lookStraightDown(s, 3, 2);
  s.settings.maxBounces = 1;
  NodeId plane = test::addMeshObject(s, "plane", makeQuad(), test::addMaterial(s, grey(1.0f)), Mat4::scale({4, 1, 4}));
  addSun(s, 2.0f);
  for (float degreesWide : {0.0f, 0.5f, 30.0f, 60.0f}) {
    s.lights[0].angularRadius = radians(degreesWide);
    double expected = 2.0 * (1.0 + std::cos(radians(degreesWide))) / 2.0 / kPi;
    EXPECT_NEAR(meanOver(renderScene(*r, s, 64), plane), expected, 0.015 * expected) << degreesWide << " degrees";
  }

  // Looking up into a disc of 20 degrees with a field of view of 10: every pixel is in it.
  s.objects.clear();
  s.camera.position = {0, 0, 0};
  s.camera.target = {0, 1, 0};
  s.camera.up = {0, 0, -1};
  s.camera.verticalFov = radians(10.0f);
  s.lights[0].angularRadius = radians(20.0f);
  RenderImage sky = renderScene(*r, s, 4);
  double mean = 0;
  for (std::size_t i = 1; i < sky.color.size(); i += 3) mean += sky.color[i];
  mean /= static_cast<double>(sky.color.size() / 3);
  const double radiance = 2.0 / (2 * kPi * (1 - std::cos(radians(20.0f))));
  EXPECT_NEAR(mean, radiance, 1e-3 * radiance);
  // Turned away, it is not there.
  s.lights[0].direction = {0, 1, 0};
  RenderImage away = renderScene(*r, s, 4);
  EXPECT_EQ(*std::max_element(away.color.begin(), away.color.end()), 0.0f);
}

TEST(KnownAnswer, ATexturedEmitterLightsAsItsLitPartAlone) {
  // A 1x1 emitter whose texture is 1 over its half u < 0.5 and 0 over the rest lights the floor
  // below as a 0.5x1 emitter over that half does: light samples (which pick points over the
  // whole quad and must read the texture there) and BSDF rays that hit it agree.
  RETILE_RENDERER_OR_SKIP(r);
  auto dir = test::tempDir();

  auto floorLitBy = [&](bool textured) {
    Scene s = test::emptyScene(16, 16);
    lookStraightDown(s, 3, 2);
    s.settings.maxBounces = 1;
    Material white;
    white.albedo = Vec3{1.0f};
    NodeId floor = test::addMeshObject(s, "floor", makeQuad(), test::addMaterial(s, white), Mat4::scale({8, 1, 8}));
    Material light;
    light.albedo = Vec3{0.0f};
    light.emission = Vec3{5.0f};
    // Facing down (the quad's u still runs along +x), 1 above the floor, off to the side.
    const Mat4 down = Mat4::rotateX(kPi);
    if (textured) {
      light.emissionTexture = addColumnTexture(s, dir, "half", 64, 1, [](int x) { return x < 32 ? 1.0f : 0.0f; });
      test::addMeshObject(s, "light", makeQuad(), test::addMaterial(s, light), Mat4::translate({1.5f, 1, 0}) * down);
    } else {
      test::addMeshObject(s, "light", makeQuad(), test::addMaterial(s, light),
                          Mat4::translate({1.25f, 1, 0}) * Mat4::scale({0.5f, 1, 1}) * down);
    }
    return meanOver(renderScene(*r, s, 256), floor);
  };
  const double reference = floorLitBy(false), textured = floorLitBy(true);
  EXPECT_GT(reference, 0.05);
  EXPECT_NEAR(textured, reference, 0.03 * reference);
}

// A 0.5 x 0.5 emitter 1 above a white floor, facing it, whose front emits into a cone of 30
// degrees (Material::emissionCone), seen from just below it. Where every point of the emitter sees
// the floor within the cone, the floor is lit as by the emitter with its whole hemisphere; where
// none does, it is black, which holds only if both light samples and the rays that hit the
// emitter keep to the cone (either alone leaves light there). Seen head on, the emitter shows its
// radiance; from outside its cone, black. Edited to 90, it lights the far floor too.
TEST(KnownAnswer, AnEmissionConeLightsOnlyWithinIt) {
  RETILE_RENDERER_OR_SKIP(r);
  const int n = 32;
  const float halfWidth = 1.5f, below = 0.9f;  // the floor seen from -1.5 to 1.5
  Scene s = test::emptyScene(n, n);
  s.settings.maxBounces = 1;
  lookStraightDown(s, below, 2 * degrees(std::atan(halfWidth / below)));
  NodeId floor = test::addMeshObject(s, "floor", makeQuad(), test::addMaterial(s, grey(1.0f)), Mat4::scale({100, 1, 100}));
  Material lamp;
  lamp.albedo = Vec3{0.0f};
  lamp.emission = Vec3{4.0f};
  lamp.emissionCone = 30;
  const NodeId lampMaterial = test::addMaterial(s, lamp);
  NodeId light = test::addMeshObject(s, "light", makeQuad(), lampMaterial,
                                     Mat4::translate({0, 1, 0}) * Mat4::rotateX(kPi) * Mat4::scale({0.5f, 1, 0.5f}));
  RenderRequest req;
  req.samplesPerPixel = 256;
  req.seed = 3;
  // The floor's mean over pixels nearer its centre than `inner`, and over those further than `outer`.
  auto floorBy = [&](const RenderImage& img, float inner, float outer) {
    double sums[2] = {0, 0};
    int counts[2] = {0, 0};
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const std::size_t i = static_cast<std::size_t>(y * n + x);
        if (img.objectId[i] != floor) continue;
        const float fx = (2 * (x + 0.5f) / n - 1) * halfWidth, fz = (2 * (y + 0.5f) / n - 1) * halfWidth;
        const float d = std::sqrt(fx * fx + fz * fz);
        const int k = d < inner ? 0 : d > outer ? 1 : -1;
        if (k < 0) continue;
        sums[k] += img.color[i * 3 + 1];
        ++counts[k];
      }
    EXPECT_GT(counts[0], 4);
    EXPECT_GT(counts[1], 100);
    return std::pair<double, double>{sums[0] / std::max(counts[0], 1), sums[1] / std::max(counts[1], 1)};
  };
  // Within 0.15 of the centre every point of the lamp is within 27 degrees; beyond 1.05, every
  // one is beyond 32.
  r->setScene(s);
  const auto [coneNear, coneFar] = floorBy(r->render(req), 0.15f, 1.05f);
  auto kernel = r->kernelFeatures();
  EXPECT_NE(std::find(kernel.begin(), kernel.end(), "emission cones"), kernel.end());
  s.material(lampMaterial)->emissionCone = 90;
  r->updateScene(s, kUpdateMaterials);  // SetMaterial's, for a new cone
  const auto [wideNear, wideFar] = floorBy(r->render(req), 0.15f, 1.05f);
  kernel = r->kernelFeatures();
  EXPECT_EQ(std::find(kernel.begin(), kernel.end(), "emission cones"), kernel.end()) << "compiled in only where a cone is narrower";
  // About L A / (pi h^2) = 4 x 0.25 / pi under the lamp: 0.29 less its edges' cosines.
  EXPECT_GT(wideNear, 0.25);
  EXPECT_LT(wideNear, 0.32);
  EXPECT_NEAR(coneNear, wideNear, 0.02 * wideNear);
  EXPECT_GT(wideFar, 0.02);
  EXPECT_EQ(coneFar, 0.0);

  // The lamp itself, head on from below and from 66 degrees off its normal.
  s.material(lampMaterial)->emissionCone = 30;
  for (bool headOn : {true, false}) {
    s.camera.position = headOn ? Vec3{0, 0.1f, 0} : Vec3{2, 0.1f, 0};
    s.camera.target = {0, 1, 0};
    s.camera.up = {0, 0, -1};
    s.camera.verticalFov = radians(5.0f);
    r->setScene(s);
    int seen = 0;
    const double mean = meanOver(r->render(req), light, &seen);
    EXPECT_GT(seen, 10) << headOn;
    EXPECT_NEAR(mean, headOn ? 4.0 : 0.0, 1e-3) << headOn;
  }
}

// Two 1 x 1 lamps 0.5 above a white floor, facing it, and a 3 x 3 one above the camera facing
// away from everything (a ceiling lamp seen from its ceiling), with 9/11 of the power. As three
// objects, three light groups: light samples at the floor go to the two that can light it. As one
// mesh, one group: picked by power among all triangles, most go to the one facing away. The
// floor's mean is the same either way (with the emitters' pdfs for the rays that hit them right
// too); with groups, its noise is lower.
TEST(KnownAnswer, LightGroupsSpendLightSamplesOnLampsThatCanLightThePoint) {
  RETILE_RENDERER_OR_SKIP(r);
  const int n = 32;
  struct Lamp {
    Vec3 at;
    float size;
    bool down;
  };
  const Lamp lamps[3] = {{{-0.8f, 0.5f, 0}, 1, true}, {{0.8f, 0.5f, 0.3f}, 1, true}, {{0, 4, 0}, 3, false}};
  auto placed = [](const Lamp& l) {
    return Mat4::translate(l.at) * (l.down ? Mat4::rotateX(kPi) : Mat4::identity()) * Mat4::scale({l.size, 1, l.size});
  };
  struct Result {
    double mean, noise;
  };
  auto floorLit = [&](bool grouped) {
    Scene s = test::emptyScene(n, n);
    s.settings.maxBounces = 1;
    lookStraightDown(s, 3, 80);
    NodeId floor = test::addMeshObject(s, "floor", makeQuad(), test::addMaterial(s, grey(1.0f)), Mat4::scale({8, 1, 8}));
    Material lamp;
    lamp.albedo = Vec3{0.0f};
    lamp.emission = Vec3{4.0f};
    const NodeId lampId = test::addMaterial(s, lamp);
    if (grouped) {
      for (const Lamp& l : lamps) test::addMeshObject(s, "lamp", makeQuad(), lampId, placed(l));
    } else {
      auto all = std::make_shared<MeshGeometry>();
      const auto quad = makeQuad();
      for (const Lamp& l : lamps) {
        const auto base = static_cast<std::uint32_t>(all->positions.size());
        const Mat4 m = placed(l);
        for (std::size_t v = 0; v < quad->positions.size(); ++v) {
          all->positions.push_back(m.transformPoint(quad->positions[v]));
          all->normals.push_back(normalize(m.transformVector(quad->normals[v])));
          all->uvs.push_back(quad->uvs[v]);
        }
        for (std::uint32_t i : quad->indices) all->indices.push_back(base + i);
      }
      test::addMeshObject(s, "lamps", all, lampId, Mat4::identity());
    }
    const RenderImage a = renderScene(*r, s, 256, 1), b = renderScene(*r, s, 256, 2);
    const auto kernel = r->kernelFeatures();
    EXPECT_EQ(std::find(kernel.begin(), kernel.end(), "light groups") != kernel.end(), grouped);
    int seen = 0;
    const double mean = 0.5 * (meanOver(a, floor, &seen) + meanOver(b, floor));
    EXPECT_GT(seen, 600);
    double squares = 0;
    for (std::size_t i = 0; i < a.objectId.size(); ++i)
      if (a.objectId[i] == floor) {
        const double d = a.color[i * 3 + 1] - b.color[i * 3 + 1];
        squares += d * d;
      }
    return Result{mean, std::sqrt(squares / (2.0 * seen)) / mean};
  };
  const Result groups = floorLit(true), one = floorLit(false);
  EXPECT_GT(groups.mean, 0.1);
  EXPECT_NEAR(groups.mean, one.mean, 0.01 * one.mean);
  EXPECT_GT(one.noise, 1.5 * groups.noise) << "with groups " << groups.noise << ", as one " << one.noise;
}

TEST(KnownAnswer, InverseSquareFalloffOfASmallLight) {
  RETILE_RENDERER_OR_SKIP(r);
  NodeId plane;
  double near = smallLightOnPlane(*r, 1.0f, &plane);
  double far = smallLightOnPlane(*r, 2.0f, &plane);
  // Radiance of a Lambertian plane of albedo 1 under a small source: Le * A / (pi * h^2).
  double expectedNear = 100.0 * 0.0025 / (kPi * 1.0);
  EXPECT_NEAR(near, expectedNear, expectedNear * 0.02);
  EXPECT_NEAR(near / far, 4.0, 0.08);
}

// The image of a small square light seen straight down from 4 units: its total and, about its
// centroid, its spread (the mean of the squared distance along x and y, in pixels squared).
struct Spot {
  double total = 0, spread = 0;
};
Spot lightSeenThroughLens(Renderer& r, float apertureRadius, float focusDistance) {
  Scene s = test::emptyScene(64, 64);
  lookStraightDown(s, 4.0f, 10.0f);
  s.camera.apertureRadius = apertureRadius;
  s.camera.focusDistance = focusDistance;
  s.settings.maxBounces = 0;
  // A box filter sums to one over the pixel grid wherever an edge falls, so the total is the
  // light's area in pixels (a narrower Blackman-Harris sums to more or less than one by where the
  // edges fall: 11 % less here).
  s.settings.pixelFilter = PixelFilter::Box;
  s.settings.filterWidth = 1.0f;
  Material light;
  light.albedo = Vec3{0.0f};
  light.emission = Vec3{1.0f};
  test::addMeshObject(s, "light", makeQuad(), test::addMaterial(s, light), Mat4::scale({0.05f, 1, 0.05f}));
  RenderImage img = renderScene(r, s, 1024);
  double sum = 0, sx = 0, sy = 0, sxx = 0, syy = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      double v = img.color[(static_cast<std::size_t>(y) * img.width + x) * 3 + 1];
      sum += v, sx += v * (x + 0.5), sy += v * (y + 0.5), sxx += v * (x + 0.5) * (x + 0.5), syy += v * (y + 0.5) * (y + 0.5);
    }
  Spot spot;
  spot.total = sum;
  double mx = sx / sum, my = sy / sum;
  spot.spread = 0.5 * ((sxx / sum - mx * mx) + (syy / sum - my * my));
  return spot;
}

// A thin lens (Camera::apertureRadius, focusDistance) spreads a point at distance D over a disc of
// radius R |D - F| / D on the plane in focus; a disc of radius rho has a spread of rho^2 / 4 per
// axis, which adds to the light's own and the pixel filter's. Focused on the light, the lens
// changes nothing; and the light's total stays its area in pixels (it is small against its
// distance).
TEST(KnownAnswer, AThinLensBlursByItsCircleOfConfusion) {
  RETILE_RENDERER_OR_SKIP(r);
  const float R = 0.05f, D = 4.0f, F = 2.0f;
  Spot pinhole = lightSeenThroughLens(*r, 0.0f, 1.0f);
  Spot focused = lightSeenThroughLens(*r, R, D);
  Spot blurred = lightSeenThroughLens(*r, R, F);
  // Pixels per unit on the plane in focus: 64 pixels over 2 F tan(5 degrees).
  const double rho = R * std::abs(D - F) / D * 64.0 / (2.0 * F * std::tan(radians(5.0f)));
  EXPECT_NEAR(focused.spread, pinhole.spread, pinhole.spread * 0.05);
  EXPECT_NEAR(blurred.spread - pinhole.spread, rho * rho / 4.0, rho * rho / 4.0 * 0.08)
      << "spread " << blurred.spread << " against " << pinhole.spread << " without the lens";
  const double area = std::pow(0.05 * 64.0 / (2.0 * D * std::tan(radians(5.0f))), 2.0);
  // Within 2.5 %: five seeds of the blurred light ranged over -0.7 to +0.7 %.
  EXPECT_NEAR(pinhole.total, area, area * 0.025);
  EXPECT_NEAR(focused.total, area, area * 0.025);
  EXPECT_NEAR(blurred.total, area, area * 0.025);
}

// The renderer compiles the trace kernel for the lights a scene has (kFeature... in layouts.h).
// Lights and sky brought in and taken out by edits must each light the plane as they should.
TEST(KnownAnswer, LightsAndSkyAddUpAsEditsBringThemInAndTakeThemOut) {
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = test::emptyScene(16, 16);
  lookStraightDown(s, 0.5f, 2);
  s.settings.maxBounces = 1;
  Material m;
  m.albedo = Vec3{0.5f};
  NodeId plane = test::addMeshObject(s, "plane", makeQuad(), test::addMaterial(s, m), Mat4::scale({1000, 1, 1000}));
  r->setScene(s);
  RenderRequest req;
  req.samplesPerPixel = 64;
  req.seed = 1;
  EXPECT_EQ(meanOver(r->render(req), plane), 0.0) << "no light, no sky";

  Light bulb;
  bulb.id = s.newId();
  bulb.position = {0, 1, 0};
  bulb.intensity = 2.0f;
  s.lights.push_back(bulb);
  r->updateScene(s, kUpdateLights);
  // Straight below a point light of intensity I at height 1: albedo / pi * I.
  const double fromBulb = 0.5 / kPi * 2.0;
  EXPECT_NEAR(meanOver(r->render(req), plane), fromBulb, fromBulb * 0.01);

  s.environment.color = Vec3{2.0f};
  r->updateScene(s, kUpdateEnvironment);
  // A uniform sky of radiance Le adds albedo * Le.
  EXPECT_NEAR(meanOver(r->render(req), plane), fromBulb + 1.0, 0.02);

  s.lights.clear();
  r->updateScene(s, kUpdateLights);
  EXPECT_NEAR(meanOver(r->render(req), plane), 1.0, 0.02);

  // A sky's intensity changes the frame's tint alone (its texels and distribution stay on the
  // device): each step must still light the plane as it says, through the edit's own flags.
  auto edit = [&](const Environment& e) {
    auto flags = applyEdit(s, SetEnvironment{e});
    ASSERT_TRUE(flags.ok());
    r->updateScene(s, flags.value());
  };
  Environment e = s.environment;
  e.type = EnvironmentType::Sky;
  e.zenith = e.horizon = e.ground = Vec3{1.5f};
  edit(e);
  EXPECT_NEAR(meanOver(r->render(req), plane), 0.75, 0.02) << "a baked sky of 1.5";
  e.intensity = 2;
  edit(e);
  EXPECT_NEAR(meanOver(r->render(req), plane), 1.5, 0.03) << "twice as bright";
  e.map = addImageTexture(s, test::tempDir(), "uniform-sky", 2, 1, [](int, int) { return 1.0f; });
  r->updateScene(s, kUpdateTextures | kUpdateMaterials | kUpdateEnvironment);
  e.type = EnvironmentType::Map;
  e.color = Vec3{1.0f};
  e.intensity = 1;
  edit(e);
  EXPECT_NEAR(meanOver(r->render(req), plane), 0.5, 0.01) << "a map of 1 in place of the sky";
  e.intensity = 3;
  edit(e);
  EXPECT_NEAR(meanOver(r->render(req), plane), 1.5, 0.03) << "three times as bright";
  e.type = EnvironmentType::Sky;
  edit(e);
  EXPECT_NEAR(meanOver(r->render(req), plane), 2.25, 0.045) << "the sky again, at the map's intensity";
}

TEST(KnownAnswer, EveryMaterialGivesOnlyFiniteSamples) {
  // A non-finite path is dropped by the accumulator (its sample does not count), so a material
  // whose sampling or evaluation goes wrong shows as pixels with fewer samples than traced.
  // Each material type lies on a plane and a sphere, lit by a sky, an area light and a point light;
  // the opaque types also under a coat, smooth or (every other type, the delta ones among them) rough.
  RETILE_RENDERER_OR_SKIP(r);
  for (int t = 0; t < kMaterialTypeCount; ++t) {
    auto type = static_cast<MaterialType>(t);
    if (type == MaterialType::Null) continue;
    for (float roughness : {0.02f, 0.15f, 0.6f, -0.15f}) {
      const bool coat = roughness < 0;
      if (coat && isTransmissiveType(type)) continue;
      roughness = std::abs(roughness);
      Scene s = test::emptyScene(24, 16);
      s.camera.position = {0, 1.0f, 3};
      s.camera.target = {0, 0.3f, 0};
      s.settings.maxBounces = 6;
      s.environment.color = Vec3{1.0f};
      Material m;
      m.type = type;
      m.roughness = roughness;
      m.albedo = Vec3{0.7f};
      if (coat) m.coatIor = 1.5f;
      if (coat && t % 2 == 0) m.coatRoughness = 0.2f;
      NodeId mat = test::addMaterial(s, m);
      test::addMeshObject(s, "plane", makeQuad(), mat, Mat4::scale({10, 1, 10}));
      test::addMeshObject(s, "sphere", makeSphere(16, 32), mat, Mat4::translate({0, 0.5f, 0}) * Mat4::scale(Vec3{0.5f}));
      Material light;
      light.albedo = Vec3{0.0f};
      light.emission = Vec3{5.0f};
      test::addMeshObject(s, "light", makeQuad(), test::addMaterial(s, light),
                          Mat4::translate({0.5f, 2, 0.5f}) * Mat4::rotateX(kPi) * Mat4::scale({0.5f, 1, 0.5f}));
      Light point;
      point.id = s.newId();
      point.position = {-1, 1.5f, 1};
      point.intensity = 2.0f;
      s.lights.push_back(point);
      const int spp = 8;
      RenderImage img = renderScene(*r, s, spp, 7);
      int dropped = 0;
      for (float c : img.sampleCount) dropped += spp - static_cast<int>(c);
      EXPECT_EQ(dropped, 0) << materialTypeName(type) << " at roughness " << roughness << " dropped " << dropped << " of "
                            << img.sampleCount.size() * spp << " samples as non-finite" << (coat ? ", coated" : "");
      EXPECT_TRUE(test::allFinite(img)) << materialTypeName(type);
    }
  }
}

TEST(KnownAnswer, ConvergedRenderEqualsMeanOfIndependentRenders) {
  // One render of K*N samples against K independent renders of N samples each: per pixel the
  // difference of the means must look like noise of the size the parts' spread predicts. K = 16
  // gives the spread estimate 15 degrees of freedom, so a 4.5 sigma excess is rare (< 0.1 %) for an
  // unbiased renderer; a biased or seed-correlated one fails on many pixels at once.
  RETILE_RENDERER_OR_SKIP(r);
  Scene s = makeDefaultScene();
  s.settings.width = 40;
  s.settings.height = 24;
  s.settings.maxBounces = 4;
  const int n = 8, k = 16;
  RenderImage big = renderScene(*r, s, k * n, 1000);
  std::vector<RenderImage> parts;
  for (int seed = 1; seed <= k; ++seed) parts.push_back(renderScene(*r, s, n, std::uint32_t(seed)));
  int outliers = 0, tested = 0;
  double sumDiff = 0, sumMean = 0;
  for (std::size_t i = 0; i < big.color.size(); ++i) {
    double m = 0, m2 = 0;
    for (const auto& p : parts) {
      m += p.color[i];
      m2 += double(p.color[i]) * p.color[i];
    }
    m /= k;
    double var = std::max(0.0, (m2 / k - m * m) * k / (k - 1));  // spread of one N-sample mean
    double se = std::sqrt(var / k + var / k);                    // of (mean of K parts) minus (one K*N render)
    sumDiff += big.color[i] - m;
    sumMean += m;
    if (se <= 1e-6) continue;
    ++tested;
    if (std::abs(big.color[i] - m) > 4.5 * se) ++outliers;
  }
  EXPECT_GT(tested, int(big.color.size() / 2));
  EXPECT_LT(outliers, tested / 100 + 1) << outliers << " of " << tested << " pixels differ by more than 4.5 sigma";
  EXPECT_NEAR(sumDiff / sumMean, 0.0, 0.02) << "the image means must agree";
}

}  // namespace
}  // namespace retile

namespace retile {
namespace {

double dielectricFresnel(double cosI, double eta) {
  const double s2 = (1 - cosI * cosI) / (eta * eta);
  if (s2 >= 1) return 1;
  const double cosT = std::sqrt(1 - s2);
  const double rs = (cosI - eta * cosT) / (cosI + eta * cosT), rp = (eta * cosI - cosT) / (eta * cosI + cosT);
  return 0.5 * (rs * rs + rp * rp);
}

// Hair in the tracer (Material::Hair): a square of it seen head on, its fibres running along
// the square's u (x), the light met at h drawn uniformly across each fibre.
//  - Under a sky of 1 everything the fibre scatters sees 1: each pixel reads the directional
//    albedo, which with the lobes narrow and seen straight across the fibre is the mean over h
//    of R's F(cos gamma) (black) or of F + (1 - F)^2 (1 + F) (clear, no absorption): the pigment
//    is read, and h is uniform.
//  - Lit from above (a sun travelling -y, perpendicular to the fibres), the black fibre's R cone
//    holds the light; turned so that its fibres run along y, towards the sun, it misses it: the
//    fibre's direction is the surface's u.
TEST(KnownAnswer, AFibreScattersAsItsLobesSayAboutItsDirection) {
  RETILE_RENDERER_OR_SKIP(r);
  auto fibre = [](float absorption, float roughness) {
    Material m;
    m.type = MaterialType::Hair;
    m.roughness = roughness;
    m.hairTilt = 0;
    m.coatingAbsorption = Vec3{absorption};
    return m;
  };
  double black = 0, clear = 0;
  const int n = 2000;
  for (int i = 0; i < n; ++i) {
    const double h = (i + 0.5) / n, gi = std::asin(h);
    const double f = dielectricFresnel(std::cos(gi), 1.55);
    black += f / n;
    clear += (f + (1 - f) * (1 - f) * (1 + f)) / n;
  }
  for (auto [absorption, expected] : {std::pair{1e4f, black}, std::pair{0.0f, clear}}) {
    Scene s = test::emptyScene(16, 16);
    s.camera = test::frontCamera(2);
    s.settings.maxBounces = 1;
    s.environment.color = Vec3{1.0f};
    const NodeId quad = test::addMeshObject(s, "fibres", makeQuad(), test::addMaterial(s, fibre(absorption, 0.02f)),
                                            Mat4::translate({0, 0, -4}) * Mat4::rotateX(kPi / 2));
    const RenderImage img = renderScene(*r, s, 256);
    int count;
    EXPECT_NEAR(meanOver(img, quad, &count), expected, 0.02 * expected) << "absorption " << absorption;
    EXPECT_EQ(count, 16 * 16);
  }
  double lit[2];
  for (int turned = 0; turned < 2; ++turned) {
    Scene s = test::emptyScene(16, 16);
    s.camera = test::frontCamera(2);
    s.settings.maxBounces = 1;
    addSun(s, 1.0f);
    const NodeId quad = test::addMeshObject(s, "fibres", makeQuad(), test::addMaterial(s, fibre(1e4f, 0.3f)),
                                            Mat4::translate({0, 0, -4}) * Mat4::rotateZ(turned ? kPi / 2 : 0.0f) * Mat4::rotateX(kPi / 2));
    lit[turned] = meanOver(renderScene(*r, s, 256), quad);
  }
  EXPECT_GT(lit[0], 0.005) << "the sun is in the black fibre's R cone";
  EXPECT_GT(lit[0], 8 * lit[1]) << "fibres running towards the sun: " << lit[0] << " against " << lit[1];
}

}  // namespace
}  // namespace retile
