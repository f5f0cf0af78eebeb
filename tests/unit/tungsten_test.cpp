#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "retile/io.h"
#include "retile/log.h"
#include "render/bvh.h"
#include "test_support.h"

namespace retile {
namespace {

const Object* objectWithMaterial(const Scene& s, const std::string& prefix) {
  for (const auto& o : s.objects) {
    const Material* m = s.material(o.material);
    if (m && m->name.rfind(prefix, 0) == 0) return &o;
  }
  return nullptr;
}

Bounds3 worldBounds(const Scene& s, const Object& o) { return transformBounds(o.transform, s.mesh(o.mesh)->geometry->bounds()); }

TEST(Tungsten, CornellBoxMatchesTheObjVersion) {
  RETILE_SHARED_OR_SKIP(file, "scenes/cornell-box/scene.json");
  auto r = importTungsten(file);
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  EXPECT_EQ(s.objects.size(), 8u);
  EXPECT_EQ(s.settings.width, 1024);
  EXPECT_EQ(s.settings.maxBounces, 63) << "Tungsten counts path segments, we count bounces";
  EXPECT_NEAR(degrees(s.camera.verticalFov), 19.5f, 1e-3f);  // square image: horizontal == vertical
  EXPECT_EQ(s.settings.pixelFilter, PixelFilter::Tent) << "the scene's reconstruction_filter";
  EXPECT_EQ(s.settings.filterWidth, 2.0f) << "Tungsten's tent reaches one pixel each way";
  EXPECT_EQ(s.settings.filterSampling, FilterSampling::SteppedTable) << "drawn as the scene's author saw it";
  EXPECT_EQ(s.settings.shading, ShadingConvention::Unchecked) << "Tungsten's defaults: two-sided, no consistency checks";
  EXPECT_EQ(s.settings.roulette, Roulette::LowThroughput) << "a sample is the same work as in Tungsten";
  EXPECT_EQ(s.settings.rayOffset, RayOffset::FixedEpsilon) << "what leaks through cracks, as in Tungsten";

  // The light: a downward-facing quad 2 cm below the ceiling, corners as in cornell-box.obj.
  const Object* light = objectWithMaterial(s, "Light");
  ASSERT_TRUE(light);
  EXPECT_EQ(s.material(light->material)->emission, Vec3(17, 12, 4));
  Bounds3 b = worldBounds(s, *light);
  EXPECT_NEAR(b.lo.x, -0.24f, 2e-3f);
  EXPECT_NEAR(b.hi.x, 0.23f, 2e-3f);
  EXPECT_NEAR(b.lo.z, -0.22f, 2e-3f);
  EXPECT_NEAR(b.hi.z, 0.16f, 2e-3f);
  EXPECT_NEAR(b.lo.y, 1.98f, 1e-4f);
  Vec3 n = normalize(light->transform.inverse().transposed().transformVector({0, 1, 0}));
  EXPECT_NEAR(n.y, -1.0f, 1e-5f) << "the light must face down into the room";

  // The short box's bottom corners, as in the OBJ (Euler order and sign of rotation matter).
  const Object* shortBox = objectWithMaterial(s, "ShortBox");
  ASSERT_TRUE(shortBox);
  const Vec3 expected[4] = {{-0.046f, 0, 0.573f}, {0.124f, 0, 0.003f}, {0.533f, 0, 0.746f}, {0.703f, 0, 0.176f}};
  for (const Vec3& e : expected) {
    float best = 1e9f;
    for (const Vec3& p : s.mesh(shortBox->mesh)->geometry->positions)
      best = std::min(best, length(shortBox->transform.transformPoint(p) - e));
    EXPECT_LT(best, 2e-3f) << "corner " << e.x << "," << e.z;
  }
}

TEST(Tungsten, LivingRoomOpensWithSubstitutesForMissingFiles) {
  RETILE_SHARED_OR_SKIP(file, "scenes/living-room/scene.json");
  auto r = importTungsten(file);
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  EXPECT_EQ(s.objects.size(), 65u);
  EXPECT_GT(s.triangleCount(), 140000u);
  EXPECT_EQ(s.environment.type, EnvironmentType::Map);
  EXPECT_EQ(s.environment.color, Vec3(1.0f)) << "the substitute sky has radiance 1";
  bool skyWarned = false, leafWarned = false;
  for (const auto& w : r->warnings) {
    skyWarned = skyWarned || (w.find("Sky 19.exr") != std::string::npos && w.find("constant sky") != std::string::npos);
    leafWarned = leafWarned || w.find("leaf.png") != std::string::npos;
  }
  EXPECT_TRUE(skyWarned);
  EXPECT_TRUE(leafWarned);
  int textured = 0, mirrors = 0, aluminium = 0;
  for (const auto& m : s.materials) {
    textured += m.albedoTexture != kNoNode;
    mirrors += m.type == MaterialType::Mirror;
    aluminium += m.type == MaterialType::RoughConductor && m.metal == "Al";
    if (m.name == "Leaves") {
      // leaf.png is missing: Tungsten's stand-in checker, as colour and as alpha (half the squares
      // transparent), not an opaque surface.
      const Texture* alpha = s.texture(m.alphaTexture);
      ASSERT_TRUE(alpha);
      EXPECT_EQ(alpha->whenMissing, MissingTexture::BlackAndWhite);
      ASSERT_TRUE(s.texture(m.albedoTexture));
      EXPECT_EQ(s.texture(m.albedoTexture)->whenMissing, MissingTexture::BlackAndWhite);
    }
    if (m.name == "PlantPot") {
      EXPECT_NEAR(m.roughness, 1.0f / std::sqrt(2.0f), 1e-6f);
    }
    if (m.name == "TableWood") {
      EXPECT_EQ(m.type, MaterialType::RoughPlastic);
      EXPECT_FLOAT_EQ(m.roughness, 0.05f);
      const Texture* wood = s.texture(m.albedoTexture);
      ASSERT_TRUE(wood);
      EXPECT_EQ(wood->colorSpace, TextureColorSpace::Gamma22) << "decoded as Tungsten decodes it";
    }
  }
  EXPECT_GE(textured, 3);
  EXPECT_EQ(mirrors, 2);
  EXPECT_EQ(aluminium, 1);
  EXPECT_NEAR(degrees(s.camera.verticalFov), 58.7f, 0.1f);
}

std::filesystem::path writeScene(const std::string& text) {
  auto p = test::tempDir() / "scene.json";
  std::ofstream(p) << text;
  return p;
}

TEST(Tungsten, BrokenScenesFailWithTheFileAndPlace) {
  struct Case {
    const char* text;
    const char* expect;
  } cases[] = {
      {"{", "not valid JSON"},
      {"[]", "not a JSON object"},
      {"{\"bsdfs\": 3}", "bsdfs: expected an array"},
      {"{\"primitives\": [{\"bsdf\": {}}]}", "without a \"type\""},
      {"{\"primitives\": [{\"type\": \"quad\", \"transform\": {\"position\": [1, 2]}}]}", "primitives[0]: position"},
      {"{\"primitives\": [{\"type\": \"quad\", \"transform\": [1, 2, 3]}]}", "16 numbers"},
      {"{\"camera\": {\"fov\": 500}, \"primitives\": []}", "fov"},
  };
  for (const Case& c : cases) {
    auto file = writeScene(c.text);
    auto r = importTungsten(file);
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_NE(r.error().find("scene.json"), std::string::npos) << r.error();
    EXPECT_NE(r.error().find(c.expect), std::string::npos) << c.text << " -> " << r.error();
  }
}

// Published Bitterli-derived files name a "null" (or "NULL") bsdf for their lights without
// defining it; a user wants the file open. Undefined names become stand-ins with a warning.
TEST(Tungsten, UndefinedBsdfsBecomeStandInsWithAWarning) {
  auto file = writeScene(R"({"primitives": [
    {"type": "quad", "name": "lamp", "bsdf": "null", "emission": [5, 5, 5]},
    {"type": "quad", "name": "lamp 2", "bsdf": "NULL", "power": 10},
    {"type": "cube", "name": "box", "bsdf": "Nope"},
    {"type": "cube", "name": "box 2", "bsdf": "Nope"}]})");
  auto r = importTungsten(file);
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  ASSERT_EQ(s.objects.size(), 4u);
  const Material* lamp = s.material(s.objects[0].material);
  ASSERT_TRUE(lamp);
  EXPECT_EQ(lamp->type, MaterialType::Null) << "an emitter keeps its emission and nothing else";
  EXPECT_EQ(lamp->emission, Vec3(5, 5, 5));
  EXPECT_EQ(s.material(s.objects[1].material)->type, MaterialType::Null);
  const Material* box = s.material(s.objects[2].material);
  ASSERT_TRUE(box);
  EXPECT_EQ(box->type, MaterialType::Lambert);
  EXPECT_EQ(box->albedo, Vec3(0.5f));
  EXPECT_EQ(s.objects[3].material, s.objects[2].material) << "one stand-in per name";
  int nope = 0, null = 0;
  for (const auto& w : r->warnings) {
    nope += w.find("bsdf 'Nope' is not defined") != std::string::npos && w.find("grey diffuse") != std::string::npos;
    null += w.find("bsdf 'null' is not defined") != std::string::npos && w.find("emission") != std::string::npos;
  }
  EXPECT_EQ(nope, 1) << "named once, with what it became";
  EXPECT_EQ(null, 1);
}

TEST(Tungsten, WhatIsNotRenderedIsNamedInAWarning) {
  // The volumetric caustic's medium and a bsdf per material index: the file opens, and the user
  // learns what the image leaves out.
  auto r = importTungsten(writeScene(R"({"media": [{"name": "gas", "type": "homogeneous", "sigma_s": 1}],
      "camera": {"medium": "gas"},
      "bsdfs": [{"name": "a", "type": "lambert"}, {"name": "b", "type": "mirror"}],
      "primitives": [
        {"type": "quad", "name": "wall", "bsdf": "a", "int_medium": "gas"},
        {"type": "cube", "name": "both", "bsdf": ["a", "b"], "emission": 1}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r->scene.objects.size(), 2u);
  int media = 0, bsdfs = 0;
  for (const auto& w : r->warnings) {
    media += w.find("the medium 'gas' is rendered only inside glass") != std::string::npos;
    bsdfs += w.find("primitives[1]: 2 bsdfs by material index") != std::string::npos;
  }
  EXPECT_EQ(media, 1);
  EXPECT_EQ(bsdfs, 1);
  // The camera's gas, which nothing holds, is the world's medium instead.
  EXPECT_EQ(r->scene.environment.mediumScattering, Vec3(1.0f));
}

// The material of the imported object of that name (a failure, and a default material, when there
// is none).
Material materialOfObject(const Scene& s, const std::string& object) {
  for (const Object& o : s.objects)
    if (o.name == object) return *s.material(o.material);
  ADD_FAILURE() << "no object " << object;
  return Material{};
}

TEST(Tungsten, AForwardSurfaceBoundsItsMedium) {
  // The volumetric caustic's set-up: gas behind an open forward quad, a lens and a light in the
  // gas (their ext_medium). The quad becomes a boundary holding the gas; the lens stays empty
  // glass, whose outside the path remembers; a medium nothing holds is named in a warning.
  auto r = importTungsten(writeScene(R"({"camera": {"medium": "gas"}, "media": [
        {"name": "gas", "type": "homogeneous", "sigma_a": 0.5, "sigma_s": 2, "density": 0.5,
         "phase_function": {"type": "henyey_greenstein", "g": 0.3}},
        {"name": "haze", "type": "homogeneous", "sigma_s": 1},
        {"name": "ink", "type": "homogeneous", "sigma_a": 1}],
      "bsdfs": [{"name": "frontWall", "type": "forward"}, {"name": "sphere", "type": "dielectric", "ior": 1.5},
                {"name": "light", "type": "null"}, {"name": "open", "type": "forward"}],
      "primitives": [
        {"type": "quad", "name": "front", "bsdf": "frontWall", "int_medium": "gas"},
        {"type": "sphere", "name": "lens", "bsdf": "sphere", "ext_medium": "gas"},
        {"type": "quad", "name": "lamp", "bsdf": "light", "ext_medium": "gas", "power": 10},
        {"type": "quad", "name": "veil", "bsdf": "open"},
        {"type": "sphere", "name": "ball", "bsdf": "sphere", "ext_medium": "haze"},
        {"type": "cube", "name": "wall", "bsdf": "light", "int_medium": "ink"},
        {"type": "sphere", "name": "drop", "bsdf": "sphere", "ext_medium": "ink"},
        {"type": "cube", "name": "puff", "bsdf": "open", "int_medium": "haze", "ext_medium": "gas"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  auto materialOf = [&](const char* object) { return materialOfObject(r->scene, object); };
  const Material front = materialOf("front");
  EXPECT_EQ(front.type, MaterialType::Boundary);
  EXPECT_TRUE(front.filled());
  EXPECT_EQ(front.interiorAbsorption, Vec3(0.25f));
  EXPECT_EQ(front.interiorScattering, Vec3(1.0f));
  EXPECT_FLOAT_EQ(front.interiorAnisotropy, 0.3f);
  EXPECT_FALSE(front.emissive());
  EXPECT_EQ(materialOf("lens").type, MaterialType::Dielectric);
  EXPECT_FALSE(materialOf("lens").filled()) << "the gas is around it, not in it";
  EXPECT_EQ(materialOf("veil").type, MaterialType::Boundary) << "a forward surface without a medium passes every ray";
  EXPECT_FALSE(materialOf("veil").filled());
  EXPECT_EQ(materialOf("puff").interiorScattering, Vec3(1.0f));
  int haze = 0, ink = 0, nested = 0;
  for (const auto& w : r->warnings) {
    haze += w.find("the medium 'haze' around it is rendered only inside glass or a forward boundary") != std::string::npos;
    ink += w.find("the medium 'ink' around it is rendered only inside glass") != std::string::npos;
    nested += w.find("a boundary of 'haze' inside the medium 'gas'") != std::string::npos;
  }
  EXPECT_EQ(haze, 0) << "the puff holds it";
  EXPECT_EQ(ink, 1) << "an opaque wall does not hold it";
  EXPECT_EQ(nested, 1) << "nested boundaries' shadow rays add both media";
  for (const auto& w : r->warnings) {
    EXPECT_EQ(w.find("'gas' around it"), std::string::npos) << "the front holds the gas: " << w;
    EXPECT_EQ(w.find("camera:"), std::string::npos) << "the camera is in the gas the front holds: " << w;
  }
}

TEST(Tungsten, ACameraMediumNothingHoldsFillsTheWorld) {
  // Fog everywhere: the camera's medium, which no glass or boundary holds, and the glass's
  // ext_medium, becomes the world's (Environment::medium...), with no warning. An ext_medium
  // that is neither held nor the camera's is still warned of, and so is an undefined camera medium.
  auto r = importTungsten(writeScene(R"({"camera": {"medium": "fog"}, "media": [
        {"name": "fog", "type": "homogeneous", "sigma_a": 0.02, "sigma_s": [0.1, 0.2, 0.3], "density": 2,
         "phase_function": {"type": "henyey_greenstein", "g": 0.6}},
        {"name": "ink", "type": "homogeneous", "sigma_a": 1}],
      "bsdfs": [{"name": "glass", "type": "dielectric", "ior": 1.5}],
      "primitives": [
        {"type": "sphere", "name": "lens", "bsdf": "glass", "ext_medium": "fog"},
        {"type": "sphere", "name": "drop", "bsdf": "glass", "ext_medium": "ink"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Environment& e = r->scene.environment;
  EXPECT_TRUE(e.filled());
  EXPECT_EQ(e.mediumAbsorption, Vec3(0.04f));
  EXPECT_EQ(e.mediumScattering, Vec3(0.2f, 0.4f, 0.6f));
  EXPECT_FLOAT_EQ(e.mediumAnisotropy, 0.6f);
  int fog = 0, ink = 0;
  for (const auto& w : r->warnings) {
    fog += w.find("'fog'") != std::string::npos;
    ink += w.find("the medium 'ink' around it") != std::string::npos;
  }
  EXPECT_EQ(fog, 0);
  EXPECT_EQ(ink, 1);
  // Glass holding ink in the fog, with no ext_medium: Tungsten's path leaves it into a vacuum,
  // this one back into the fog, which the user is told.
  auto held = importTungsten(writeScene(R"({"camera": {"medium": "fog"}, "media": [
        {"name": "fog", "type": "homogeneous", "sigma_s": 0.1}, {"name": "ink", "type": "homogeneous", "sigma_a": 1}],
      "bsdfs": [{"name": "glass", "type": "dielectric", "ior": 1.5}],
      "primitives": [{"type": "sphere", "name": "bottle", "bsdf": "glass", "int_medium": "ink"},
                     {"type": "sphere", "name": "jar", "bsdf": "glass", "int_medium": "ink", "ext_medium": "fog"}]})"));
  ASSERT_TRUE(held.ok()) << held.error();
  EXPECT_TRUE(std::any_of(held->warnings.begin(), held->warnings.end(), [](const std::string& w) {
    return w.find(
               "1 glass or boundary primitives with a medium inside name another ext_medium than the camera's 'fog', the first "
               "primitives[0] (none)") != std::string::npos;
  }));

  auto undefined = importTungsten(writeScene(R"({"camera": {"medium": "smoke"}, "primitives": [{"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(undefined.ok()) << undefined.error();
  EXPECT_FALSE(undefined->scene.environment.filled());
  EXPECT_TRUE(std::any_of(undefined->warnings.begin(), undefined->warnings.end(),
                          [](const std::string& w) { return w.find("camera: the medium 'smoke' is not defined") != std::string::npos; }));
}

// The imported material of that name (a failure, and a default material, when there is none).
Material materialNamed(const Scene& s, const std::string& name) {
  for (const Material& m : s.materials)
    if (m.name == name) return m;
  ADD_FAILURE() << "no material " << name;
  return Material{};
}

// Tungsten's phong and diffuse_transmission are their own materials, not lamberts: the exponent
// becomes the roughness a with n = 2 / a^2 - 2 (Tungsten's default 64), the transmittance is
// Tungsten's fixed half.
TEST(Tungsten, PhongAndDiffuseTransmissionKeepTheirKind) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
        {"name": "p", "type": "phong", "exponent": 18, "diffuse_ratio": 0.35, "albedo": 0.5},
        {"name": "d", "type": "phong"},
        {"name": "t", "type": "diffuse_transmission", "albedo": [0.2, 0.6, 0.3]}],
      "primitives": [{"type": "quad", "bsdf": "p"}, {"type": "quad", "bsdf": "d"}, {"type": "quad", "bsdf": "t"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  for (const auto& w : r->warnings) EXPECT_EQ(w.find("not supported"), std::string::npos) << w;
  auto named = [&](const char* name) { return materialNamed(r->scene, name); };
  EXPECT_EQ(named("p").type, MaterialType::Phong);
  EXPECT_NEAR(2 / (named("p").roughness * named("p").roughness) - 2, 18, 1e-3);
  EXPECT_NEAR(2 / (named("d").roughness * named("d").roughness) - 2, 64, 1e-2);
  EXPECT_FLOAT_EQ(named("p").diffuseRatio, 0.35f);
  EXPECT_FLOAT_EQ(named("d").diffuseRatio, 0.2f) << "Tungsten's default";
  EXPECT_EQ(named("t").type, MaterialType::DiffuseTransmission);
  EXPECT_EQ(named("t").transmittance, 0.5f);
  EXPECT_NEAR(named("t").albedo.y, 0.6f, 1e-6f);
}

// Tungsten's coats: the substrate is the material, the coat's index, absorption (sigma_a times
// thickness) and roughness ride on it. A rough coat also takes "sigmaA", which older Tungsten
// read; a coat over glass is left out, with a warning.
TEST(Tungsten, CoatsKeepTheirSubstrateUnderAClearCoat) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
        {"name": "gold", "type": "rough_conductor", "material": "Au", "roughness": 0.2},
        {"name": "lacquer", "type": "smooth_coat", "ior": 1.6, "thickness": 2, "sigma_a": [0.1, 0.2, 0.3], "substrate": "gold"},
        {"name": "satin", "type": "rough_coat", "roughness": 0.3, "sigma_a": 5, "substrate": {"type": "lambert", "albedo": 0.4}},
        {"name": "tinted", "type": "rough_coat", "sigmaA": [0.5, 0, 0], "substrate": {"type": "lambert"}},
        {"name": "default", "type": "smooth_coat"},
        {"name": "glass", "type": "smooth_coat", "substrate": {"type": "dielectric"}}],
      "primitives": [{"type": "quad", "bsdf": "lacquer"}, {"type": "quad", "bsdf": "satin"},
                     {"type": "quad", "bsdf": "default"}, {"type": "quad", "bsdf": "glass"}, {"type": "quad", "bsdf": "tinted"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  auto named = [&](const char* name) { return materialNamed(r->scene, name); };
  const Material lacquer = named("lacquer"), satin = named("satin"), plain = named("default");
  EXPECT_EQ(lacquer.type, MaterialType::RoughConductor);
  EXPECT_EQ(lacquer.metal, "Au");
  EXPECT_FLOAT_EQ(lacquer.coatIor, 1.6f);
  EXPECT_EQ(lacquer.coatAbsorption, Vec3(0.2f, 0.4f, 0.6f));
  EXPECT_EQ(satin.type, MaterialType::Lambert);
  EXPECT_FLOAT_EQ(satin.albedo.x, 0.4f);
  EXPECT_FLOAT_EQ(satin.coatIor, 1.3f) << "Tungsten's default index";
  EXPECT_FLOAT_EQ(satin.coatRoughness, 0.3f);
  EXPECT_EQ(satin.coatAbsorption, Vec3(5.0f));
  EXPECT_EQ(named("tinted").coatAbsorption, Vec3(0.5f, 0.0f, 0.0f));
  EXPECT_FLOAT_EQ(named("tinted").coatRoughness, 0.02f) << "Tungsten's default roughness";
  EXPECT_EQ(lacquer.coatRoughness, 0.0f) << "a smooth coat";
  EXPECT_EQ(plain.type, MaterialType::RoughConductor) << "Tungsten's default substrate";
  EXPECT_EQ(plain.albedo, Vec3(1.0f)) << "Tungsten's default albedo";
  EXPECT_FALSE(named("glass").coated());
  int glass = 0, unsupported = 0;
  for (const auto& w : r->warnings) {
    glass += w.find("a coat over a dielectric substrate is rendered without the coat") != std::string::npos;
    unsupported += w.find("not supported") != std::string::npos;
  }
  EXPECT_EQ(glass, 1);
  EXPECT_EQ(unsupported, 0);
}

// A homogeneous medium fills the glass that names it as its int_medium (sigma_a and sigma_s times
// density, the phase function's asymmetry); elsewhere it is named in a warning, and so is a
// medium of another kind, with the reason. ("isotropic" alone as a string is not Tungsten's form
// but is read too.)
TEST(Tungsten, AHomogeneousMediumFillsItsGlass) {
  auto r = importTungsten(writeScene(R"({"media": [
        {"name": "ink", "type": "homogeneous", "sigma_a": [0.5, 1, 2], "sigma_s": 0, "density": 2},
        {"name": "fog", "type": "homogeneous", "sigma_a": 0.1, "sigma_s": [1, 2, 3], "density": 0.5,
         "phase_function": {"type": "henyey_greenstein", "g": 0.7}},
        {"name": "milk", "type": "homogeneous", "sigma_s": 4, "phase_function": "isotropic"},
        {"name": "sky", "type": "homogeneous", "sigma_s": 1, "phase_function": {"type": "rayleigh"}},
        {"name": "smoke", "type": "voxel", "sigma_s": 1},
        {"name": "haze", "type": "homogeneous", "sigma_s": 1, "transmittance": {"type": "pulse"}},
        {"name": "dense", "type": "homogeneous", "sigma_s": 1, "max_bounces": 2,
         "phase_function": {"type": "henyey_greenstein", "g": 1}}],
      "bsdfs": [{"name": "glass", "type": "dielectric", "ior": 1.33}, {"name": "wall", "type": "lambert"}],
      "primitives": [
        {"type": "sphere", "name": "bottle", "bsdf": "glass", "int_medium": "ink"},
        {"type": "sphere", "name": "empty", "bsdf": "glass"},
        {"type": "quad", "name": "w", "bsdf": "wall", "int_medium": "ink"},
        {"type": "sphere", "name": "misty", "bsdf": "glass", "int_medium": "fog"},
        {"type": "sphere", "name": "jug", "bsdf": "glass", "int_medium": "milk"},
        {"type": "sphere", "name": "dome", "bsdf": "glass", "int_medium": "sky"},
        {"type": "sphere", "name": "smoky", "bsdf": "glass", "int_medium": "smoke"},
        {"type": "sphere", "name": "hazy", "bsdf": "glass", "int_medium": "haze"},
        {"type": "sphere", "name": "thick", "bsdf": "glass", "int_medium": "dense"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  auto materialOf = [&](const char* object) { return materialOfObject(r->scene, object); };
  EXPECT_EQ(materialOf("bottle").interiorAbsorption, Vec3(1.0f, 2.0f, 4.0f));
  EXPECT_EQ(materialOf("bottle").interiorScattering, Vec3(0.0f));
  EXPECT_FLOAT_EQ(materialOf("bottle").ior, 1.33f);
  EXPECT_FALSE(materialOf("empty").filled()) << "the shared glass stays empty";
  const Material misty = materialOf("misty");
  EXPECT_EQ(misty.interiorAbsorption, Vec3(0.05f));
  EXPECT_EQ(misty.interiorScattering, Vec3(0.5f, 1.0f, 1.5f));
  EXPECT_FLOAT_EQ(misty.interiorAnisotropy, 0.7f);
  EXPECT_EQ(materialOf("jug").interiorScattering, Vec3(4.0f));
  EXPECT_EQ(materialOf("jug").interiorAnisotropy, 0.0f);
  EXPECT_EQ(materialOf("dome").interiorScattering, Vec3(1.0f));
  EXPECT_EQ(materialOf("dome").interiorAnisotropy, 0.0f) << "Rayleigh's mean cosine";
  EXPECT_FALSE(materialOf("smoky").filled());
  EXPECT_FALSE(materialOf("hazy").filled());
  EXPECT_FLOAT_EQ(materialOf("thick").interiorAnisotropy, 0.99f);
  int smoke = 0, haze = 0, wall = 0, rayleigh = 0, g = 0, bounces = 0;
  for (const auto& w : r->warnings) {
    smoke += w.find("'smoke' is not rendered (a voxel medium; only homogeneous ones are)") != std::string::npos;
    haze += w.find("'haze' is not rendered (a non-exponential transmittance)") != std::string::npos;
    wall += w.find("the medium 'ink' is rendered only inside glass") != std::string::npos;
    rayleigh += w.find("'sky': the Rayleigh phase function is rendered isotropic") != std::string::npos;
    g += w.find("'dense': the phase function's g of 1 is rendered as 0.99") != std::string::npos;
    bounces += w.find("'dense': its max_bounces of 2 is not kept") != std::string::npos;
  }
  EXPECT_EQ(smoke, 1);
  EXPECT_EQ(haze, 1);
  EXPECT_EQ(wall, 1);
  EXPECT_EQ(rayleigh, 1);
  EXPECT_EQ(g, 1);
  EXPECT_EQ(bounces, 1);
}

// Tungsten turns an infinite_sphere by its transform's rotation, as it turns any primitive: so a
// direction fixed to a quad (its normal, +y in the quad's space) is the sky's up (+y in the map's
// frame) when both have the same transform, tilted, turned and given an "up" alike.
TEST(Tungsten, TheSkyTurnsAsAPrimitiveWithItsTransform) {
  const char* transforms[] = {R"({})",
                              R"({"rotation": [0, 30, 0]})",
                              R"({"rotation": [90, 0, 0]})",
                              R"({"rotation": [20, -70, 45], "position": [3, 1, 2], "scale": 4})",
                              R"({"up": [0, 0, 1]})",
                              R"({"up": [1, 1, 0], "rotation": [0, 90, 0]})",
                              R"([0, 0, 1, 5,  1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 0, 1])"};
  for (const char* t : transforms) {
    SCOPED_TRACE(t);
    auto r = importTungsten(writeScene(std::string(R"({"primitives": [
        {"type": "infinite_sphere", "emission": 1, "transform": )") +
                                       t + R"(},
        {"type": "quad", "name": "q", "bsdf": {"type": "lambert"}, "transform": )" +
                                       t + "}]}"));
    ASSERT_TRUE(r.ok()) << r.error();
    for (const auto& w : r->warnings) EXPECT_EQ(w.find("environment"), std::string::npos) << w;
    ASSERT_EQ(r->scene.objects.size(), 1u);
    const Vec3 quadUp = normalize(r->scene.objects[0].transform.transformVector({0, 1, 0}));
    const Vec3 quadX = normalize(r->scene.objects[0].transform.transformVector({1, 0, 0}));
    const Mat4 toMap = environmentToMap(r->scene.environment);
    const Vec3 up = toMap.transformVector(quadUp), x = toMap.transformVector(quadX);
    EXPECT_NEAR(up.x, 0, 1e-5f);
    EXPECT_NEAR(up.y, 1, 1e-5f);
    EXPECT_NEAR(up.z, 0, 1e-5f);
    EXPECT_NEAR(x.x, 1, 1e-5f) << "the map's u = 0.5 column lies along the primitive's x";
    EXPECT_NEAR(x.z, 0, 1e-5f);
  }
  // The artist's rotation turns a tilted sky about the world's +y: what was seen in direction d
  // is seen in d turned about +y.
  Environment tilted;
  tilted.orientation = Mat4::rotateX(0.7f);
  Environment turned = tilted;
  turned.rotation = 0.25f;
  const Vec3 d = normalize(Vec3{0.3f, -0.2f, 0.9f});
  const Vec3 a = environmentToMap(turned).transformVector(Mat4::rotateY(0.25f).transformVector(d));
  const Vec3 b = environmentToMap(tilted).transformVector(d);
  EXPECT_NEAR(length(a - b), 0, 1e-5f);
}

// Tungsten's .wo3 mesh: vertices (position, normal, uv), then triangles with a material index.
void writeWo3(const std::filesystem::path& file, const std::vector<Vec3>& positions,
              const std::vector<std::array<std::int32_t, 4>>& triangles) {
  std::ofstream out(file, std::ios::binary);
  const std::uint64_t nv = positions.size(), nt = triangles.size();
  out.write(reinterpret_cast<const char*>(&nv), 8);
  for (const Vec3& p : positions) {
    const float v[8] = {p.x, p.y, p.z, 0, 1, 0, 0, 0};
    out.write(reinterpret_cast<const char*>(v), sizeof v);
  }
  out.write(reinterpret_cast<const char*>(&nt), 8);
  for (const auto& t : triangles) out.write(reinterpret_cast<const char*>(t.data()), 16);
}

TEST(Tungsten, AMeshTakesABsdfPerMaterialIndex) {
  auto dir = test::tempDir();
  // Three triangles side by side: material indices 0, 1 and 5 (past the array: its last entry),
  // and one more file whose triangles all carry index 1.
  writeWo3(dir / "three.wo3", {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {2, 0, 0}, {3, 0, 0}, {2, 0, 1}, {4, 0, 0}, {5, 0, 0}, {4, 0, 1}},
           {{0, 2, 1, 0}, {3, 5, 4, 1}, {6, 8, 7, 5}});
  writeWo3(dir / "one.wo3", {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}}, {{0, 2, 1, 1}});
  std::ofstream(dir / "scene.json") << R"({"bsdfs": [{"name": "red", "type": "lambert", "albedo": [1, 0, 0]},
                                                     {"name": "blue", "type": "lambert", "albedo": [0, 0, 1]}],
      "primitives": [{"type": "mesh", "name": "three", "file": "three.wo3", "bsdf": ["red", "blue"]},
                     {"type": "mesh", "name": "one", "file": "one.wo3", "bsdf": ["red", "blue"]}]})";
  auto r = importTungsten(dir / "scene.json");
  ASSERT_TRUE(r.ok()) << r.error();
  for (const auto& w : r->warnings) EXPECT_EQ(w.find("material index"), std::string::npos) << w;
  const Scene& s = r->scene;
  ASSERT_EQ(s.objects.size(), 4u);
  std::vector<std::string> names;
  for (const Object& o : s.objects) {
    const Mesh* mesh = s.mesh(o.mesh);
    ASSERT_TRUE(mesh && mesh->geometry);
    const Bounds3 b = mesh->geometry->bounds();
    names.push_back(cat(o.name, ": ", s.material(o.material)->name, " over x ", b.lo.x, "..", b.hi.x, ", ",
                        mesh->geometry->positions.size(), " vertices"));
  }
  EXPECT_EQ(names, (std::vector<std::string>{"three [0]: red over x 0..1, 3 vertices", "three [1]: blue over x 2..3, 3 vertices",
                                             "three [5]: blue over x 4..5, 3 vertices", "one: blue over x 0..1, 3 vertices"}));
}

TEST(Tungsten, ABsdfEveryUserOfWhichTookACopyIsNotKept) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
        {"name": "lamp", "type": "lambert"}, {"name": "wall", "type": "lambert"}, {"name": "spare", "type": "mirror"}],
      "primitives": [{"type": "quad", "name": "a", "bsdf": "lamp", "emission": 5},
                     {"type": "quad", "name": "b", "bsdf": "lamp", "emission": 2},
                     {"type": "quad", "name": "c", "bsdf": "wall", "emission": 1},
                     {"type": "quad", "name": "d", "bsdf": "wall"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  std::vector<std::string> names;
  for (const Material& m : r->scene.materials) names.push_back(m.name);
  EXPECT_EQ(names, (std::vector<std::string>{"wall", "spare", "lamp (a)", "lamp (b)", "wall (c)"}))
      << "'lamp' only ever became the emitters' copies; 'wall' is used as it is, 'spare' by nothing";
}

TEST(Tungsten, BumpMapsGoToACopyOfTheBsdf) {
  auto dir = test::tempDir();
  {
    std::ofstream(dir / "scene.json") << R"({"bsdfs": [{"name": "a", "type": "lambert"}],
      "primitives": [
        {"type": "quad", "name": "plain", "bsdf": "a"},
        {"type": "quad", "name": "bumped", "bsdf": "a", "bump": {"type": "bitmap", "file": "h.png", "scale": 2}, "bump_strength": 3},
        {"type": "quad", "name": "same", "bsdf": "a", "bump": {"type": "bitmap", "file": "h.png", "scale": 2}, "bump_strength": 3},
        {"type": "quad", "name": "flat", "bsdf": "a", "bump": 0.5},
        {"type": "quad", "name": "red", "bsdf": {"type": "lambert", "albedo": [1, 0, 0]}, "bump": "h.png"},
        {"type": "quad", "name": "blue", "bsdf": {"type": "lambert", "albedo": [0, 0, 1]}, "bump": "h.png"}]})";
  }
  auto r = importTungsten(dir / "scene.json");
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  ASSERT_EQ(s.objects.size(), 6u);
  const Material* plain = s.material(s.objects[0].material);
  const Material* bumped = s.material(s.objects[1].material);
  ASSERT_TRUE(plain && bumped);
  EXPECT_EQ(plain->bumpTexture, kNoNode) << "the shared bsdf stays as it was";
  EXPECT_NE(bumped->bumpTexture, kNoNode);
  EXPECT_EQ(bumped->name, "a (bump)");
  EXPECT_FLOAT_EQ(bumped->bumpStrength, 6.0f) << "bump_strength times the bitmap's scale";
  EXPECT_EQ(s.objects[2].material, s.objects[1].material) << "one copy per bsdf and bump";
  EXPECT_EQ(s.material(s.objects[3].material)->bumpTexture, kNoNode) << "a constant has no slope";
  EXPECT_NE(s.objects[4].material, s.objects[5].material) << "two unnamed inline bsdfs keep their own copies";
  EXPECT_EQ(s.material(s.objects[5].material)->albedo, Vec3(0, 0, 1));
}

// Newer Tungsten files put the bump map in the bsdf (Bsdf::fromJson), at strength 1 times the
// bitmap's scale. Either way it is read as data: Tungsten's gamma table is for colours only.
TEST(Tungsten, ABumpMapInTheBsdfIsTheBsdfsAndReadAsData) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
        {"name": "a", "type": "rough_plastic", "bump": {"type": "bitmap", "file": "h.png", "scale": 0.5}},
        {"name": "b", "type": "lambert", "bump": 0.5}],
      "primitives": [{"type": "quad", "bsdf": "a"}, {"type": "quad", "bsdf": "b"},
        {"type": "quad", "bsdf": "b", "bump": "g.png"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  ASSERT_EQ(s.objects.size(), 3u);
  const Material* a = s.material(s.objects[0].material);
  ASSERT_TRUE(a);
  EXPECT_EQ(a->name, "a") << "the bsdf's own, no copy";
  ASSERT_NE(a->bumpTexture, kNoNode);
  EXPECT_FLOAT_EQ(a->bumpStrength, 0.5f);
  EXPECT_EQ(s.texture(a->bumpTexture)->colorSpace, TextureColorSpace::Raw);
  EXPECT_EQ(s.material(s.objects[1].material)->bumpTexture, kNoNode) << "a constant has no slope";
  const Material* onPrimitive = s.material(s.objects[2].material);
  ASSERT_TRUE(onPrimitive && onPrimitive->bumpTexture != kNoNode);
  EXPECT_EQ(s.texture(onPrimitive->bumpTexture)->colorSpace, TextureColorSpace::Raw);
}

// Tungsten's defaults and scalars where a file leaves them out or gives a colour: 64 path
// segments; a transparency's base is a white lambert; one number from a colour is its channels'
// mean (REQUEST_AVERAGE); a medium may name the exponential transmittance it has; a sun cap may
// be given by its power, spread over its solid angle.
TEST(Tungsten, DefaultsAndScalarsAreTungstens) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
        {"name": "leaf", "type": "transparency", "alpha": 0.5},
        {"name": "metal", "type": "rough_conductor", "roughness": [0.1, 0.2, 0.6]}],
      "media": [{"name": "fog", "type": "homogeneous", "sigma_s": 1, "transmittance": {"type": "exponential"}},
                {"name": "odd", "type": "homogeneous", "sigma_s": 1, "transmittance": {"type": "linear"}}],
      "primitives": [{"type": "quad", "bsdf": "leaf"}, {"type": "quad", "bsdf": "metal"},
        {"type": "cube", "bsdf": {"type": "forward"}, "int_medium": "fog"},
        {"type": "cube", "bsdf": {"type": "forward"}, "int_medium": "odd"},
        {"type": "infinite_sphere_cap", "cap_angle": 5, "power": 30}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  EXPECT_EQ(s.settings.maxBounces, 63) << "no integrator: Tungsten's 64 segments";
  const Material* leaf = s.material(s.objects[0].material);
  ASSERT_TRUE(leaf);
  EXPECT_EQ(leaf->type, MaterialType::Lambert);
  EXPECT_EQ(leaf->albedo, Vec3{1.0f});
  EXPECT_FLOAT_EQ(leaf->alpha, 0.5f);
  EXPECT_NEAR(s.material(s.objects[1].material)->roughness, 0.3f, 1e-6f);
  auto warned = [&](const std::string& what) {
    return std::any_of(r->warnings.begin(), r->warnings.end(), [&](const std::string& w) { return w.find(what) != std::string::npos; });
  };
  EXPECT_FALSE(warned("'fog'")) << "an exponential transmittance is the homogeneous medium's own";
  EXPECT_TRUE(warned("'odd'"));
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_NEAR(s.lights[0].intensity, 30.0f, 1e-3f) << "radiance times the solid angle gives the power back";
}

// recompute_normals as Tungsten recomputes them: smoothed over every vertex at a position, not
// across a crease of more than 27 degrees. A box keeps flat faces; a fold of 10 degrees, its
// second face on vertices of its own (as a uv seam splits them), is smoothed across the fold.
TEST(Tungsten, RecomputedNormalsMergeByPositionAndKeepCreases) {
  auto dir = test::tempDir();
  std::ofstream(dir / "box.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
  const float c = std::cos(radians(10.0f)), sn = std::sin(radians(10.0f));
  std::ofstream(dir / "fold.obj") << "v 0 0 0\nv 0 0 1\nv -1 0 0\n"                      // flat, facing +y
                                  << "v 0 0 0\nv 0 0 1\nv " << c << " " << sn << " 0\n"  // tilted 10 degrees
                                  << "f 1 3 2\nf 4 5 6\n";
  std::ofstream(dir / "scene.json") << R"({"bsdfs": [{"name": "a", "type": "lambert"}], "primitives": [
      {"type": "mesh", "file": "box.obj", "bsdf": "a", "smooth": true, "recompute_normals": true},
      {"type": "mesh", "file": "fold.obj", "bsdf": "a", "smooth": true, "recompute_normals": true}]})";
  auto r = importTungsten(dir / "scene.json");
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  ASSERT_EQ(s.objects.size(), 2u);
  const MeshGeometry& box = *s.mesh(s.objects[0].mesh)->geometry;
  ASSERT_EQ(box.normals.size(), box.positions.size());
  for (std::size_t t = 0; t < box.indices.size(); t += 3) {
    const Vec3 a = box.positions[box.indices[t]], b = box.positions[box.indices[t + 1]], d = box.positions[box.indices[t + 2]];
    const Vec3 face = normalize(cross(b - a, d - a));
    for (int k = 0; k < 3; ++k)
      EXPECT_GT(dot(box.normals[box.indices[t + static_cast<std::size_t>(k)]], face), 0.9999f) << "triangle " << t / 3;
  }
  const MeshGeometry& fold = *s.mesh(s.objects[1].mesh)->geometry;
  ASSERT_EQ(fold.normals.size(), fold.positions.size());
  const Vec3 across = normalize(Vec3{0, 1, 0} + Vec3{-sn, c, 0});  // equal areas
  for (std::uint32_t v : fold.indices)
    if (fold.positions[v].x == 0.0f) {
      EXPECT_GT(dot(fold.normals[v], across), 0.9999f) << "vertex " << v;
    }
}

TEST(Tungsten, PalikMetalNamesAreTheirMetals) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
        {"name": "a", "type": "conductor", "material": "Ni_palik"},
        {"name": "b", "type": "rough_conductor", "material": "Au"},
        {"name": "c", "type": "conductor", "material": "Unobtainium_palik"}],
      "primitives": [{"type": "quad", "bsdf": "a"}, {"type": "quad", "bsdf": "b"}, {"type": "quad", "bsdf": "c"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  std::map<std::string, std::string> metals;
  for (const auto& m : r->scene.materials) metals[m.name] = m.metal;
  EXPECT_EQ(metals["a"], "Ni");
  EXPECT_EQ(metals["b"], "Au");
  EXPECT_EQ(metals["c"], "Cu") << "an unknown metal falls back to copper";
  int unknown = 0;
  for (const auto& w : r->warnings) unknown += w.find("unknown metal 'Unobtainium_palik'") != std::string::npos;
  EXPECT_EQ(unknown, 1) << "named as the file names it";
}

TEST(Tungsten, PointLightsAndCylindersAreImported) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [{"name": "a", "type": "lambert"}],
      "primitives": [
        {"type": "point", "name": "bulb", "transform": {"position": [1, 2, 3]}, "power": [12.566371, 0, 6.2831855]},
        {"type": "point", "transform": {"position": [0, 1, 0]}, "emission": 2},
        {"type": "cylinder", "bsdf": "a", "transform": {"position": [0, 1, 0], "scale": [2, 4, 1]}},
        {"type": "cylinder", "bsdf": "a", "capped": false}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].name, "bulb");
  EXPECT_EQ(s.lights[0].type, LightType::Point);
  EXPECT_NEAR(s.lights[0].position.z, 3.0f, 1e-6f);
  // Power spreads over the sphere of directions: 4 pi W in red is 1 W/sr, 2 pi W in blue half that.
  EXPECT_NEAR(s.lights[0].intensity * s.lights[0].color.x, 1.0f, 1e-5f);
  EXPECT_NEAR(s.lights[0].intensity * s.lights[0].color.z, 0.5f, 1e-5f);
  EXPECT_NEAR(s.lights[1].intensity, 2.0f, 1e-6f) << "emission is the intensity";
  ASSERT_EQ(s.objects.size(), 2u);
  // Round: radius half the larger of the x and z scales (1), height the y scale (4).
  Bounds3 b = worldBounds(s, s.objects[0]);
  EXPECT_NEAR(b.hi.x - b.lo.x, 2.0f, 1e-3f);
  EXPECT_NEAR(b.hi.z - b.lo.z, 2.0f, 1e-3f);
  EXPECT_NEAR(b.lo.y, -1.0f, 1e-4f);
  EXPECT_NEAR(b.hi.y, 3.0f, 1e-4f);
  const auto& capped = *s.mesh(s.objects[0].mesh)->geometry;
  const auto& open = *s.mesh(s.objects[1].mesh)->geometry;
  EXPECT_GT(capped.indices.size(), open.indices.size()) << "the caps close it";
  // Every face points away from the axis or out of its cap.
  for (const auto* g : {&capped, &open})
    for (std::size_t t = 0; t + 2 < g->indices.size(); t += 3) {
      Vec3 p0 = g->positions[g->indices[t]], p1 = g->positions[g->indices[t + 1]], p2 = g->positions[g->indices[t + 2]];
      Vec3 n = cross(p1 - p0, p2 - p0);
      if (length(n) < 1e-9f) continue;
      Vec3 c = (p0 + p1 + p2) / 3.0f;
      Vec3 out = std::abs(c.y) > 0.4999f && std::abs(std::abs(n.y) - length(n)) < 1e-6f ? Vec3{0, c.y, 0} : Vec3{c.x, 0, c.z};
      EXPECT_GT(dot(n, out), 0.0f) << "triangle " << t / 3;
    }
}

// Tungsten's infinite_sphere_cap is a disc of the sky around the transform's +y: a sun of that
// angular radius whose disc keeps the cap's radiance.
TEST(Tungsten, ASkyCapIsASunWithItsDisc) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [{"name": "a", "type": "lambert"}], "primitives": [
        {"type": "quad", "bsdf": "a"},
        {"type": "infinite_sphere_cap", "cap_angle": 2, "emission": [100, 50, 0],
         "transform": {"rotation": [0, 0, 90]}},
        {"type": "infinite_sphere_cap", "cap_angle": 180, "emission": 1}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  ASSERT_EQ(s.lights.size(), 2u);
  const Light& sun = s.lights[0];
  EXPECT_EQ(sun.type, LightType::Directional);
  EXPECT_NEAR(sun.angularRadius, radians(2.0f), 1e-7f);
  // +y turned a quarter about z points along -x; the light travels the other way.
  EXPECT_NEAR(sun.direction.x, 1.0f, 1e-5f);
  const float solidAngle = 2 * kPi * (1 - std::cos(radians(2.0f)));
  EXPECT_NEAR(sun.intensity * sun.color.x / solidAngle, 100.0f, 1e-2f);
  EXPECT_NEAR(sun.intensity * sun.color.y / solidAngle, 50.0f, 1e-2f);
  EXPECT_NEAR(s.lights[1].angularRadius, kPi / 2, 1e-6f) << "at most a hemisphere";
  EXPECT_TRUE(std::any_of(r->warnings.begin(), r->warnings.end(),
                          [](const std::string& w) { return w.find("cap_angle 180") != std::string::npos; }));
}

// A cap that names a skydome is the dome's sun: it points where the dome's +y does, before or
// after the cap in the file, and its own transform is not used.
TEST(Tungsten, ASkyCapTiedToASkydomeFollowsTheDome) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [{"name": "a", "type": "lambert"}], "primitives": [
        {"type": "quad", "bsdf": "a"},
        {"type": "infinite_sphere_cap", "cap_angle": 1, "emission": 10, "skydome": "sky",
         "transform": {"rotation": [90, 0, 0]}},
        {"type": "skydome", "name": "sky", "transform": {"rotation": [0, 0, 90]}},
        {"type": "infinite_sphere_cap", "cap_angle": 1, "emission": 10, "skydome": "nowhere"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  ASSERT_EQ(s.lights.size(), 2u);
  // The dome's +y turned a quarter about z points along -x; the sun's light travels along +x.
  EXPECT_NEAR(s.lights[0].direction.x, 1.0f, 1e-5f);
  EXPECT_NEAR(s.lights[0].direction.y, 0.0f, 1e-5f);
  EXPECT_EQ(s.environment.type, EnvironmentType::Sky);
  EXPECT_EQ(s.environment.ground, Vec3(0.0f)) << "Tungsten's dome is black below the horizon";
  // Naming no primitive, the cap keeps its own transform (here none: straight down), and says so.
  EXPECT_NEAR(s.lights[1].direction.y, -1.0f, 1e-5f);
  EXPECT_TRUE(std::any_of(r->warnings.begin(), r->warnings.end(),
                          [](const std::string& w) { return w.find("skydome 'nowhere' names no primitive") != std::string::npos; }));
}

TEST(Tungsten, TexturedEmissionKeepsItsTexture) {
  auto r = importTungsten(writeScene(R"({"primitives": [
      {"type": "quad", "name": "screen", "emission": {"type": "bitmap", "file": "tv.png", "scale": 4}},
      {"type": "quad", "name": "lamp", "emission": 2}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  const Material* screen = s.material(s.objects[0].material);
  const Material* lamp = s.material(s.objects[1].material);
  ASSERT_TRUE(screen && lamp);
  EXPECT_NE(screen->emissionTexture, kNoNode);
  EXPECT_EQ(screen->emission, Vec3(4.0f)) << "the bitmap's scale is the factor";
  EXPECT_EQ(lamp->emissionTexture, kNoNode);
  for (const auto& w : r->warnings) EXPECT_EQ(w.find("textured emission"), std::string::npos) << w;
}

TEST(Tungsten, APlasticCoatingAbsorbsSigmaATimesItsThickness) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
        {"name": "a", "type": "rough_plastic", "sigma_a": [0.5, 1, 2], "thickness": 0.2},
        {"name": "b", "type": "plastic", "sigma_a": 0.3},
        {"name": "c", "type": "plastic"}],
      "primitives": [{"type": "quad", "bsdf": "a"}, {"type": "quad", "bsdf": "b"}, {"type": "quad", "bsdf": "c"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  std::map<std::string, Vec3> coating;
  for (const auto& m : r->scene.materials) coating[m.name] = m.coatingAbsorption;
  EXPECT_NEAR(coating["a"].x, 0.1f, 1e-6f);
  EXPECT_NEAR(coating["a"].z, 0.4f, 1e-6f);
  EXPECT_NEAR(coating["b"].y, 0.3f, 1e-6f) << "thickness 1 by default";
  EXPECT_EQ(coating["c"], Vec3(0.0f));
  for (const auto& w : r->warnings) EXPECT_EQ(w.find("sigma_a"), std::string::npos) << w;
}

TEST(Tungsten, AMixedBsdfBlendsItsTwoParts) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
        {"name": "gold", "type": "conductor", "material": "Au"},
        {"name": "mix", "type": "mixed", "bsdf0": "gold", "bsdf1": {"type": "lambert", "albedo": 0.2}, "ratio": 0.3, "albedo": 0.5},
        {"name": "even", "type": "mixed", "bsdf0": "gold", "bsdf1": {"type": "lambert"}},
        {"name": "deep", "type": "mixed", "bsdf0": "mix", "bsdf1": {"type": "mixed", "bsdf0": "gold", "bsdf1": {"type": "mirror"}, "ratio": 0.2}}],
      "primitives": [{"type": "quad", "bsdf": "mix"}, {"type": "quad", "bsdf": "even"}, {"type": "quad", "bsdf": "deep"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  const Material* mix = s.material(s.objects[0].material);
  const Material* even = s.material(s.objects[1].material);
  const Material* deep = s.material(s.objects[2].material);
  ASSERT_TRUE(mix && even && deep);
  EXPECT_EQ(mix->name, "mix");
  EXPECT_EQ(mix->type, MaterialType::Conductor) << "bsdf0";
  EXPECT_EQ(mix->metal, "Au");
  EXPECT_NEAR(mix->albedo.y, 0.5f, 1e-6f) << "under the blend's albedo";
  EXPECT_FLOAT_EQ(mix->blendRatio, 0.3f);
  const Material* other = s.material(mix->blendWith);
  ASSERT_TRUE(other);
  EXPECT_EQ(other->type, MaterialType::Lambert);
  EXPECT_NEAR(other->albedo.y, 0.1f, 1e-6f) << "bsdf1 under the blend's albedo too";
  EXPECT_EQ(other->blendWith, kNoNode);
  EXPECT_FLOAT_EQ(even->blendRatio, 0.5f) << "Tungsten's default ratio";
  ASSERT_TRUE(s.material(even->blendWith));
  EXPECT_EQ(s.material(even->blendWith)->type, MaterialType::Lambert);
  // Blends in both parts make no chain: bsdf0's blend (the named 'mix') is drawn as its first
  // part, and bsdf1's chain goes on after it.
  EXPECT_EQ(deep->type, MaterialType::Conductor) << "the named blend 'mix' as its first part";
  EXPECT_FLOAT_EQ(deep->blendRatio, 0.5f);
  const Material* inner = s.material(deep->blendWith);
  ASSERT_TRUE(inner);
  EXPECT_EQ(inner->type, MaterialType::Conductor) << "bsdf1's blend: gold, then the mirror";
  EXPECT_FLOAT_EQ(inner->blendRatio, 0.2f);
  ASSERT_TRUE(s.material(inner->blendWith));
  EXPECT_EQ(s.material(inner->blendWith)->type, MaterialType::Mirror);
  int warned = 0;
  for (const auto& w : r->warnings) warned += w.find("rendered as its first part") != std::string::npos;
  EXPECT_EQ(warned, 1);
}

// Blends of blends become chains the kernel follows (Material::blendWith of a partner): a blend
// in bsdf1 goes on after bsdf0; a blend in bsdf0 goes after bsdf1, the ratio turned round. The
// outer albedo reaches every material of the chain.
TEST(Tungsten, BlendsOfBlendsBecomeChains) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
        {"name": "right", "type": "mixed", "ratio": 0.4, "albedo": 0.5, "bsdf0": {"type": "lambert", "albedo": 0.9},
         "bsdf1": {"type": "mixed", "ratio": 0.25, "bsdf0": {"type": "conductor"}, "bsdf1": {"type": "mirror"}}},
        {"name": "left", "type": "mixed", "ratio": 0.6, "bsdf1": {"type": "lambert"},
         "bsdf0": {"type": "mixed", "ratio": 0.5, "bsdf0": {"type": "conductor"}, "bsdf1": {"type": "mirror"}}}],
      "primitives": [{"type": "quad", "bsdf": "right"}, {"type": "quad", "bsdf": "left"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  auto chain = [&](const Material* m) {
    std::vector<const Material*> out;
    while (m && out.size() < 8) {
      out.push_back(m);
      m = m->blendWith != kNoNode ? s.material(m->blendWith) : nullptr;
    }
    return out;
  };
  auto right = chain(s.material(s.objects[0].material));
  ASSERT_EQ(right.size(), 3u);
  EXPECT_EQ(right[0]->type, MaterialType::Lambert);
  EXPECT_FLOAT_EQ(right[0]->blendRatio, 0.4f);
  EXPECT_NEAR(right[0]->albedo.x, 0.45f, 1e-6f);
  EXPECT_EQ(right[1]->type, MaterialType::Conductor);
  EXPECT_FLOAT_EQ(right[1]->blendRatio, 0.25f);
  EXPECT_NEAR(right[1]->albedo.x, 0.5f, 1e-6f) << "under the outer albedo";
  EXPECT_EQ(right[2]->type, MaterialType::Mirror);
  EXPECT_NEAR(right[2]->albedo.x, 0.5f, 1e-6f) << "under the outer albedo";
  auto left = chain(s.material(s.objects[1].material));
  ASSERT_EQ(left.size(), 3u);
  EXPECT_EQ(left[0]->type, MaterialType::Lambert) << "bsdf1 first";
  EXPECT_FLOAT_EQ(left[0]->blendRatio, 0.4f) << "1 - 0.6";
  EXPECT_EQ(left[1]->type, MaterialType::Conductor);
  EXPECT_FLOAT_EQ(left[1]->blendRatio, 0.5f);
  EXPECT_EQ(left[2]->type, MaterialType::Mirror);
  for (const auto& w : r->warnings) EXPECT_EQ(w.find("blend"), std::string::npos) << w;
  // Nothing left over: every material is an object's or in a chain.
  std::set<NodeId> used;
  for (const Object& o : s.objects) used.insert(o.material);
  for (const Material& m : s.materials) used.insert(m.blendWith);
  for (const Material& m : s.materials) EXPECT_TRUE(used.count(m.id) || m.name == "right" || m.name == "left") << m.name;
}

// A textured ratio is kept as the blend's ratio texture, read as data, its scale the constant.
TEST(Tungsten, ATexturedBlendRatioKeepsItsTexture) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
        {"name": "a", "type": "mixed", "bsdf0": {"type": "lambert"}, "bsdf1": {"type": "mirror"}, "ratio": "mask.png"},
        {"name": "b", "type": "mixed", "bsdf0": {"type": "lambert"}, "bsdf1": {"type": "mirror"},
         "ratio": {"type": "bitmap", "file": "mask.png", "scale": 0.5}}],
      "primitives": [{"type": "quad", "bsdf": "a"}, {"type": "quad", "bsdf": "b"}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  for (int i = 0; i < 2; ++i) {
    const Material* m = s.material(s.objects[i].material);
    ASSERT_TRUE(m);
    ASSERT_TRUE(s.material(m->blendWith));
    const Texture* t = s.texture(m->blendRatioTexture);
    ASSERT_TRUE(t) << m->name;
    EXPECT_EQ(t->path.filename(), "mask.png");
    EXPECT_EQ(t->colorSpace, TextureColorSpace::Raw) << "a ratio is data";
    EXPECT_FLOAT_EQ(m->blendRatio, i == 0 ? 1.0f : 0.5f) << m->name;
  }
  for (const auto& w : r->warnings) EXPECT_EQ(w.find("blend ratio"), std::string::npos) << w;
}

TEST(Tungsten, MissingMeshIsSkippedWithAWarning) {
  auto file = writeScene(R"({"primitives": [
      {"type": "mesh", "file": "nowhere.obj"},
      {"type": "sphere", "transform": {"scale": 0.5}, "emission": 2}]})");
  auto r = importTungsten(file);
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r->scene.objects.size(), 1u);
  ASSERT_FALSE(r->warnings.empty());
  EXPECT_NE(r->warnings[0].find("nowhere.obj"), std::string::npos);
}

TEST(Tungsten, TexturePathsMatchCaseInsensitivelyWithEitherSeparator) {
  auto dir = test::tempDir();
  std::filesystem::create_directories(dir / "Textures");
  std::ofstream(dir / "Textures" / "Wood.PNG") << "not really a png";
  std::ofstream(dir / "scene.json") << R"({"bsdfs": [{"name": "w", "type": "lambert", "albedo": "textures\\wood.png"}],
      "primitives": [{"type": "quad", "bsdf": "w"}]})";
  auto r = importTungsten(dir / "scene.json");
  ASSERT_TRUE(r.ok()) << r.error();
  for (const auto& w : r->warnings) EXPECT_EQ(w.find("not found"), std::string::npos) << w;
}

TEST(Tungsten, AConstantSkyUnderEmissionsIsLeftOutAsTungstenLeavesItOut) {
  // The spaceship's: Tungsten's reference shows black where a sky of 0.3 would be.
  auto outside = importTungsten(writeScene(R"({"primitives": [{"type": "quad", "emission": 1}],
      "emissions": [{"type": "constant", "radiance": 0.3, "sample": false}]})"));
  ASSERT_TRUE(outside.ok()) << outside.error();
  EXPECT_EQ(outside->scene.environment.type, EnvironmentType::Constant);
  EXPECT_EQ(outside->scene.environment.color, Vec3(0.0f));
  bool warned = false;
  for (const auto& w : outside->warnings) warned = warned || w.find("emissions[0]: a constant sky") != std::string::npos;
  EXPECT_TRUE(warned) << "the user is told what was left out and how to keep it";
  // As a primitive, the same sky lights the scene.
  auto inside = importTungsten(writeScene(R"({"primitives": [{"type": "quad", "emission": 1},
      {"type": "infinite_sphere", "emission": 0.3}]})"));
  ASSERT_TRUE(inside.ok()) << inside.error();
  EXPECT_EQ(inside->scene.environment.color, Vec3(0.3f));
}

TEST(Tungsten, ADielectricWithoutRefractionIsAFresnelReflectorOnly) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
      {"name": "coat", "type": "dielectric", "ior": 1.33, "albedo": 0.7, "enable_refraction": false},
      {"name": "frosted", "type": "rough_dielectric", "ior": 1.5, "roughness": 0.3, "enable_refraction": false},
      {"name": "glass", "type": "dielectric", "ior": 1.5}],
      "primitives": [{"type": "quad", "bsdf": "coat"}, {"type": "quad", "bsdf": "frosted"}, {"type": "quad", "bsdf": "glass"},
                     {"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  // A metal of index ior + 0i reflects the dielectric's F, tinted by the albedo as Tungsten's.
  const Material* coat = s.material(s.objects[0].material);
  EXPECT_EQ(coat->type, MaterialType::Conductor) << "reflects F and transmits nothing";
  EXPECT_EQ(coat->metal, "custom");
  EXPECT_EQ(coat->eta, Vec3(1.33f));
  EXPECT_EQ(coat->k, Vec3(0.0f));
  EXPECT_EQ(coat->albedo, Vec3(0.7f));
  const Material* frosted = s.material(s.objects[1].material);
  EXPECT_EQ(frosted->type, MaterialType::RoughConductor);
  EXPECT_EQ(frosted->roughness, 0.3f);
  EXPECT_EQ(frosted->eta, Vec3(1.5f));
  EXPECT_EQ(s.material(s.objects[2].material)->type, MaterialType::Dielectric);
  EXPECT_TRUE(s.material(s.objects[2].material)->tintsReflection);
  EXPECT_TRUE(r->warnings.empty()) << r->warnings.front();
}

// Tungsten's thin sheet has no albedo; its sigma_a absorbs along twice its thickness. Its
// interference is over a film of its thickness times 500 nm (0.5 by default). Saved natively,
// the absorption and the film stay.
TEST(Tungsten, AThinSheetAbsorbsAlongTwiceItsThicknessAndHasNoAlbedo) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
      {"name": "film", "type": "thinsheet", "ior": 1.3, "albedo": 0.3, "sigma_a": [1, 2, 3], "thickness": 0.25},
      {"name": "bubble", "type": "thinsheet", "enable_interference": true},
      {"name": "soap", "type": "thinsheet", "enable_interference": true, "thickness": 0.25}],
      "primitives": [{"type": "quad", "bsdf": "film"}, {"type": "quad", "bsdf": "bubble"}, {"type": "quad", "bsdf": "soap"},
      {"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  const Material* film = s.material(s.objects[0].material);
  EXPECT_EQ(film->type, MaterialType::ThinSheet);
  EXPECT_EQ(film->albedo, Vec3(1.0f));
  EXPECT_EQ(film->ior, 1.3f);
  EXPECT_EQ(film->coatingAbsorption, Vec3(0.5f, 1.0f, 1.5f));
  EXPECT_EQ(s.material(s.objects[1].material)->coatingAbsorption, Vec3(0.0f)) << "sigma_a defaults to 0";
  EXPECT_EQ(film->filmThickness, 0.0f) << "no interference unless asked";
  EXPECT_EQ(s.material(s.objects[1].material)->filmThickness, 250.0f);
  EXPECT_TRUE(s.material(s.objects[1].material)->tintsReflection) << "its interference drawn as Tungsten draws it";
  EXPECT_EQ(s.material(s.objects[2].material)->filmThickness, 125.0f);
  EXPECT_TRUE(r->warnings.empty()) << r->warnings.front();

  auto file = test::tempDir() / "scene.retile";
  ASSERT_TRUE(saveNativeScene(s, file).ok());
  auto back = loadNativeScene(file);
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back->scene.material(back->scene.objects[0].material)->coatingAbsorption, Vec3(0.5f, 1.0f, 1.5f));
  EXPECT_TRUE(back->scene.material(back->scene.objects[0].material)->albedo == Vec3(1.0f));
  EXPECT_EQ(back->scene.material(back->scene.objects[1].material)->filmThickness, 250.0f);
  EXPECT_TRUE(back->scene.material(back->scene.objects[1].material)->tintsReflection);

  // A textured albedo, which the sheet does not render, leaves no texture behind to be decoded
  // and packed; a texture something uses stays. A textured thickness is the sheet's roughness
  // texture, scaling what a thickness of 1 gives: sigma_a along twice it, a film of 500 nm.
  auto textured = importTungsten(writeScene(R"({"bsdfs": [
      {"name": "film", "type": "thinsheet", "albedo": {"type": "checker"}, "sigma_a": 0.5, "enable_interference": true,
       "thickness": {"type": "checker", "res_u": 3}},
      {"name": "floor", "type": "lambert", "albedo": {"type": "checker", "res_u": 5}}],
      "primitives": [{"type": "quad", "bsdf": "floor"}, {"type": "quad", "bsdf": "film"}, {"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(textured.ok()) << textured.error();
  EXPECT_TRUE(textured->warnings.empty()) << textured->warnings.front();
  ASSERT_EQ(textured->scene.textures.size(), 2u);
  const Material& floor = *textured->scene.material(textured->scene.objects[0].material);
  ASSERT_TRUE(textured->scene.texture(floor.albedoTexture));
  EXPECT_EQ(textured->scene.texture(floor.albedoTexture)->checkerResU, 5);
  const Material& sheet = *textured->scene.material(textured->scene.objects[1].material);
  ASSERT_NE(sheet.roughnessTexture, kNoNode);
  EXPECT_EQ(textured->scene.texture(sheet.roughnessTexture)->checkerResU, 3);
  EXPECT_EQ(sheet.coatingAbsorption, Vec3{1.0f});
  EXPECT_EQ(sheet.filmThickness, 500.0f);
  EXPECT_TRUE(textured->scene.textures[0].truncatedCells) << "a Tungsten checker counts its cells as Tungsten does";
  ASSERT_TRUE(saveNativeScene(textured->scene, file).ok());
  auto checkerBack = loadNativeScene(file);
  ASSERT_TRUE(checkerBack.ok()) << checkerBack.error();
  ASSERT_EQ(checkerBack->scene.textures.size(), 2u);
  EXPECT_TRUE(checkerBack->scene.textures[0].truncatedCells) << "and keeps counting so when saved natively";
}

// The spaceship's leathers ask for Beckmann: rendered with it (no warning); a Phong distribution
// still becomes GGX with a warning naming it. Every rough material takes Tungsten's separable
// Smith shadowing. Saved natively, distribution and shadowing stay.
TEST(Tungsten, BeckmannIsKeptAndPhongWarns) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
      {"name": "leather", "type": "rough_plastic", "distribution": "beckmann", "roughness": 0.4},
      {"name": "old", "type": "rough_conductor", "distribution": "phong", "roughness": 0.2}],
      "primitives": [{"type": "quad", "bsdf": "leather"}, {"type": "quad", "bsdf": "old"}, {"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  EXPECT_TRUE(s.material(s.objects[0].material)->beckmann);
  EXPECT_FALSE(s.material(s.objects[1].material)->beckmann);
  EXPECT_TRUE(s.material(s.objects[0].material)->separableShadowing);
  EXPECT_TRUE(s.material(s.objects[1].material)->separableShadowing);
  int phong = 0;
  for (const auto& w : r->warnings) {
    EXPECT_EQ(w.find("beckmann"), std::string::npos) << w;
    phong += w.find("'phong' is rendered as GGX") != std::string::npos;
  }
  EXPECT_EQ(phong, 1);
  auto file = test::tempDir() / "scene.retile";
  ASSERT_TRUE(saveNativeScene(s, file).ok());
  auto back = loadNativeScene(file);
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_TRUE(back->scene.material(back->scene.objects[0].material)->beckmann);
  EXPECT_TRUE(back->scene.material(back->scene.objects[1].material)->separableShadowing);
}

// Tungsten's thinlens camera: a lens of radius aperture_size focused focus_distance away, or on the
// origin of the primitive focus_pivot names; what is left out (cat's-eye vignetting, an aperture
// texture, a pivot that names nothing) is said. Saved natively, the lens stays; a pinhole's file
// does not mention one.
// The camera's tonemap is the view the scene is shown through: filmic as Filmic, Tungsten's default
// gamma as Standard, linear as Raw; Reinhard's, which we do not have, as Filmic with a warning.
TEST(Tungsten, TheCamerasTonemapIsTheScenesView) {
  const std::pair<const char*, const char*> cases[] = {
      {R"("tonemap": "filmic",)", "Filmic"}, {"", "Standard"}, {R"("tonemap": "linear",)", "Raw"}, {R"("tonemap": "reinhard",)", "Filmic"}};
  for (auto [tonemap, view] : cases) {
    auto r = importTungsten(
        writeScene(std::string(R"({"camera": {)") + tonemap + R"( "fov": 40}, "primitives": [{"type": "quad", "emission": 1}]})"));
    ASSERT_TRUE(r.ok()) << r.error();
    EXPECT_EQ(r->scene.settings.view, view) << tonemap;
    EXPECT_EQ(r->warnings.size(), std::string(view) == "Filmic" && std::string(tonemap).find("reinhard") != std::string::npos ? 1u : 0u)
        << tonemap;
  }
}

// Tungsten's sphere and disk are analytic; tessellated, ours keep their true areas (4 pi r^2 and
// pi r^2), so that as emitters they give the light Tungsten's give.
TEST(Tungsten, SpheresAndDisksKeepTheirTrueArea) {
  auto r = importTungsten(writeScene(R"({"primitives": [
      {"type": "sphere", "emission": 1, "transform": {"scale": 2}},
      {"type": "disk", "emission": 1, "transform": {"scale": 3}}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  ASSERT_EQ(s.objects.size(), 2u);
  const double expected[] = {4 * kPi * 4, kPi * 9};
  for (std::size_t k = 0; k < 2; ++k) {
    const Object& o = s.objects[k];
    const MeshGeometry& g = *s.mesh(o.mesh)->geometry;
    double area = 0;
    for (std::size_t i = 0; i + 2 < g.indices.size(); i += 3) {
      const Vec3 a = o.transform.transformPoint(g.positions[g.indices[i]]), b = o.transform.transformPoint(g.positions[g.indices[i + 1]]),
                 c = o.transform.transformPoint(g.positions[g.indices[i + 2]]);
      area += 0.5 * static_cast<double>(length(cross(b - a, c - a)));
    }
    EXPECT_NEAR(area, expected[k], 2e-5 * expected[k]) << (k == 0 ? "sphere" : "disk");
  }
  // And the sphere's uvs are Tungsten's: u = atan2(y, x) / 2 pi + 1/2, v = acos(z) / pi of the
  // point on the unit sphere (poles and the seam, where u is either end, left out).
  const MeshGeometry& sphere = *s.mesh(s.objects[0].mesh)->geometry;
  int checked = 0;
  for (std::size_t i = 0; i < sphere.positions.size(); ++i) {
    const Vec3 n = normalize(sphere.positions[i]);
    const Vec2 uv = sphere.uvs[i];
    if (std::abs(n.z) > 0.999f || uv.x < 1e-3f || uv.x > 1 - 1e-3f) continue;
    ASSERT_NEAR(uv.x, std::atan2(n.y, n.x) / (2 * kPi) + 0.5f, 1e-4) << i;
    ASSERT_NEAR(uv.y, std::acos(n.z) / kPi, 1e-4) << i;
    ++checked;
  }
  EXPECT_GT(checked, 4000);
}

// A disk's cone_angle narrows where Tungsten's disk emits (Disk::evalDirect): its emitter's
// material takes it as its emission cone. Wider than the hemisphere is said and taken as 90.
TEST(Tungsten, ADisksConeAngleIsItsEmissionCone) {
  const std::pair<const char*, float> cases[] = {{"", 90},
                                                 {R"(, "cone_angle": 90)", 90},
                                                 {R"(, "cone_angle": 120)", 90},
                                                 {R"(, "cone_angle": 30)", 30},
                                                 {R"(, "cone_angle": -30)", 30}};
  for (const auto& [cone, expected] : cases) {
    auto r = importTungsten(writeScene(std::string(R"({"primitives": [{"type": "disk", "emission": 1)") + cone + "}]}"));
    ASSERT_TRUE(r.ok()) << r.error();
    ASSERT_EQ(r->scene.objects.size(), 1u);
    const Material* m = r->scene.material(r->scene.objects[0].material);
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->emissionCone, expected) << cone;
    const bool said = std::any_of(r->warnings.begin(), r->warnings.end(),
                                  [](const std::string& w) { return w.find("cone_angle 120") != std::string::npos; });
    EXPECT_EQ(said, std::string(cone).find("120") != std::string::npos) << cone;
    // The native format keeps it.
    auto file = test::tempDir() / "cone.retile";
    ASSERT_TRUE(saveNativeScene(r->scene, file).ok());
    auto back = loadNativeScene(file);
    ASSERT_TRUE(back.ok()) << back.error();
    EXPECT_EQ(back->scene.material(back->scene.objects[0].material)->emissionCone, expected) << cone;
  }
}

// Tungsten takes a mesh's and a quad's front from their winding in world space; ours is the
// object's winding carried by the normal matrix. Under a mirroring transform the two differ
// unless the importer winds the mirrored one the other way: for every triangle, our front
// (normal matrix times the object-space winding normal) must point along Tungsten's (the winding
// normal of the transformed vertices), mirrored or not (two negative scales are not).
TEST(Tungsten, AMirroredMeshOrQuadFacesAsInTungsten) {
  auto file = writeScene(R"({"primitives": [
      {"type": "mesh", "file": "tri.obj"},
      {"type": "mesh", "file": "tri.obj", "transform": {"scale": [-1, 1, 1]}},
      {"type": "mesh", "file": "tri.obj", "transform": {"scale": [2, -1, -3], "rotation": [10, 20, 30]}},
      {"type": "mesh", "file": "tri.obj", "transform": [1, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 1]},
      {"type": "quad", "transform": {"scale": [1, -1, 1]}},
      {"type": "quad", "transform": {"scale": [-2, 1, 1], "rotation": [0, 0, 90]}},
      {"type": "quad", "emission": 1}]})");
  std::ofstream(file.parent_path() / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n";
  auto r = importTungsten(file);
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  ASSERT_EQ(s.objects.size(), 7u);
  // The file's triangles, as the unmirrored mesh keeps them.
  const MeshGeometry& original = *s.mesh(s.objects[0].mesh)->geometry;
  ASSERT_EQ(original.indices.size(), 6u);
  int mirrored = 0;
  for (std::size_t k = 0; k < s.objects.size(); ++k) {
    const Object& o = s.objects[k];
    SCOPED_TRACE(o.name);
    const Mat4& m = o.transform;
    const bool mirror = dot(cross(m.transformVector({1, 0, 0}), m.transformVector({0, 1, 0})), m.transformVector({0, 0, 1})) < 0;
    mirrored += mirror ? 1 : 0;
    const Mat4 normalMatrix = m.inverse().transposed();
    const MeshGeometry& g = *s.mesh(o.mesh)->geometry;
    ASSERT_FALSE(g.indices.empty());
    for (std::size_t i = 0; i + 2 < g.indices.size(); i += 3) {
      const Vec3 a = g.positions[g.indices[i]], b = g.positions[g.indices[i + 1]], c = g.positions[g.indices[i + 2]];
      const Vec3 ours = normalMatrix.transformVector(cross(b - a, c - a));
      // Tungsten's: a mesh's the file's triangle's, transformed; a quad's edge1 x edge0 (Quad.cpp).
      Vec3 tungstens;
      if (k < 4) {
        const Vec3 fa = original.positions[original.indices[i]], fb = original.positions[original.indices[i + 1]],
                   fc = original.positions[original.indices[i + 2]];
        tungstens = cross(m.transformVector(fb - fa), m.transformVector(fc - fa));
      } else {
        tungstens = cross(m.transformVector({0, 0, 1}), m.transformVector({1, 0, 0}));
        // Its shading normal is that one too.
        for (std::size_t v = i; v < i + 3 && !g.normals.empty(); ++v)
          EXPECT_GT(dot(normalMatrix.transformVector(g.normals[g.indices[v]]), tungstens), 0.0f) << "a quad's shading normal";
      }
      EXPECT_GT(dot(ours, tungstens), 0.0f) << "triangle " << i / 3;
    }
  }
  EXPECT_EQ(mirrored, 4) << "the test covers mirrored and unmirrored shapes";
  EXPECT_NE(s.objects[0].mesh, s.objects[1].mesh) << "a mirrored use takes a copy";
  EXPECT_EQ(s.objects[1].mesh, s.objects[3].mesh) << "one copy for every mirrored use";
  EXPECT_EQ(s.objects[0].mesh, s.objects[2].mesh) << "two negative scales do not mirror";
  std::set<NodeId> used;
  for (const Object& o : s.objects) used.insert(o.mesh);
  EXPECT_EQ(used.size(), s.meshes.size()) << "no mesh left unused (the quad's unmirrored one is used by the last quad)";

  // A file used only mirrored leaves no unmirrored mesh behind.
  auto only = writeScene(R"({"primitives": [{"type": "mesh", "file": "tri.obj", "transform": {"scale": [-1, 1, 1]}},
      {"type": "quad", "emission": 1, "transform": {"scale": [1, 1, -1]}}]})");
  std::ofstream(only.parent_path() / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  auto o2 = importTungsten(only);
  ASSERT_TRUE(o2.ok()) << o2.error();
  EXPECT_EQ(o2->scene.meshes.size(), 2u);
  EXPECT_EQ(o2->scene.objects[0].name, "tri") << "named after its file, as unmirrored";
}

// The analytic shapes carry Tungsten's uvs, so that a texture on them lies as in Tungsten: the
// quad's v runs against z, the cube's faces take their other two axes in turn, the cylinder's wall
// takes the angle atan2(z, x), and the disk's u is the angle about its normal in Tungsten's frame
// of it, v the distance from its centre over its radius. A disk is round whatever its scale. Each
// triangle still faces the way its normals do.
TEST(Tungsten, AnalyticShapesCarryTungstensUvs) {
  // The disk's matrix: a turn about a slanted axis, scaled 2 in x, 1 in y, 0.5 in z, moved.
  const Vec3 axis = normalize(Vec3{0.3f, 0.5f, 0.8f});
  const float angle = 0.7f, c = std::cos(angle), sn = std::sin(angle), k = 1 - c;
  const float rot[3][3] = {{c + axis.x * axis.x * k, axis.x * axis.y * k - axis.z * sn, axis.x * axis.z * k + axis.y * sn},
                           {axis.y * axis.x * k + axis.z * sn, c + axis.y * axis.y * k, axis.y * axis.z * k - axis.x * sn},
                           {axis.z * axis.x * k - axis.y * sn, axis.z * axis.y * k + axis.x * sn, c + axis.z * axis.z * k}};
  const float scale[3] = {2, 1, 0.5f};
  const Vec3 centre{1, -2, 3};
  std::string matrix;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const float v = i == 3 ? (j == 3 ? 1.0f : 0.0f) : j == 3 ? (i == 0 ? centre.x : i == 1 ? centre.y : centre.z) : rot[i][j] * scale[j];
      matrix += (matrix.empty() ? "" : ", ") + std::to_string(v);
    }
  auto r = importTungsten(writeScene(R"({"primitives": [{"type": "quad"}, {"type": "cube"}, {"type": "cylinder"},
      {"type": "disk", "transform": [)" +
                                     matrix + "]}]}"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  ASSERT_EQ(s.objects.size(), 4u);
  auto geometry = [&](std::size_t i) -> const MeshGeometry& { return *s.mesh(s.objects[i].mesh)->geometry; };
  auto coord = [](Vec3 p, int d) { return d == 0 ? p.x : d == 1 ? p.y : p.z; };
  const float eps = 1e-4f;
  for (std::size_t o = 0; o < 4; ++o) {
    const MeshGeometry& g = geometry(o);
    for (std::size_t i = 0; i + 2 < g.indices.size(); i += 3) {
      const Vec3 a = g.positions[g.indices[i]], b = g.positions[g.indices[i + 1]], cc = g.positions[g.indices[i + 2]];
      if (length(cross(b - a, cc - a)) < 1e-9f) continue;  // a lathe's degenerate triangles at a cap's centre
      ASSERT_GT(dot(cross(b - a, cc - a), g.normals[g.indices[i]] + g.normals[g.indices[i + 1]] + g.normals[g.indices[i + 2]]), 0)
          << o << " " << i;
    }
  }
  for (std::size_t i = 0; i < geometry(0).positions.size(); ++i) {
    const Vec3 p = geometry(0).positions[i];
    EXPECT_NEAR(geometry(0).uvs[i].x, p.x + 0.5f, eps);
    EXPECT_NEAR(geometry(0).uvs[i].y, 0.5f - p.z, eps);
  }
  for (std::size_t i = 0; i < geometry(1).positions.size(); ++i) {
    const Vec3 p = geometry(1).positions[i], n = geometry(1).normals[i];
    const int dim = std::abs(n.x) > 0.5f ? 0 : std::abs(n.y) > 0.5f ? 1 : 2;
    EXPECT_NEAR(geometry(1).uvs[i].x, coord(p, (dim + 1) % 3) + 0.5f, eps) << i;
    EXPECT_NEAR(geometry(1).uvs[i].y, coord(p, (dim + 2) % 3) + 0.5f, eps) << i;
  }
  int wall = 0, caps = 0;
  for (std::size_t i = 0; i < geometry(2).positions.size(); ++i) {
    const Vec3 p = geometry(2).positions[i], n = geometry(2).normals[i];
    const Vec2 uv = geometry(2).uvs[i];
    if (std::abs(n.y) > 0.5f) {
      EXPECT_NEAR(uv.x, p.x + 0.5f, eps) << i;
      EXPECT_NEAR(uv.y, p.z + 0.5f, eps) << i;
      ++caps;
    } else if (uv.x > 1e-3f && uv.x < 1 - 1e-3f) {
      EXPECT_NEAR(uv.x, std::atan2(p.z, p.x) / (2 * kPi) + 0.5f, eps) << i;
      EXPECT_NEAR(uv.y, p.y + 0.5f, eps) << i;
      ++wall;
    }
  }
  EXPECT_GT(wall, 100);
  EXPECT_GT(caps, 100);
  // Tungsten's disk, from its matrix: radius the larger of the x and z columns' lengths, normal
  // the y column, u from TangentFrame(normal), which starts from y or x, whichever is further
  // from the normal.
  const Vec3 n = normalize(Vec3{rot[0][1], rot[1][1], rot[2][1]});
  const float radius = 2;
  const Vec3 t0 = std::abs(n.x) > std::abs(n.y) ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
  const Vec3 bt = normalize(cross(n, t0)), tg = cross(bt, n);
  const Mat4& m = s.objects[3].transform;
  const MeshGeometry& disk = geometry(3);
  int checked = 0;
  for (std::size_t i = 0; i < disk.positions.size(); ++i) {
    const Vec3 d = m.transformPoint(disk.positions[i]) - centre;
    EXPECT_NEAR(dot(d, n), 0, 1e-4f) << i;
    EXPECT_LE(length(d), radius * 1.002f) << i;
    EXPECT_NEAR(disk.uvs[i].y, length(d) / radius, 2e-3f) << i;  // the rim is pushed out to the true area
    if (length(d) < 1e-3f || disk.uvs[i].x < 1e-3f || disk.uvs[i].x > 1 - 1e-3f) continue;
    EXPECT_NEAR(disk.uvs[i].x, std::atan2(dot(d, tg), dot(d, bt)) / (2 * kPi) + 0.5f, eps) << i;
    ++checked;
  }
  EXPECT_GT(checked, 40);
  EXPECT_GT(dot(normalize(m.transformVector({0, 1, 0})), n), 0.9999f);
}

// A bitmap's interpolate and clamp are how its texture is read; the same file read otherwise is
// another texture.
TEST(Tungsten, ABitmapKeepsItsInterpolationAndClamp) {
  auto r = importTungsten(writeScene(R"({"bsdfs": [
      {"name": "pixel", "type": "lambert", "albedo": {"type": "bitmap", "file": "t.png", "interpolate": false, "clamp": true}},
      {"name": "smooth", "type": "lambert", "albedo": "t.png"}],
      "primitives": [{"type": "quad", "bsdf": "pixel"}, {"type": "quad", "bsdf": "smooth"}, {"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  const Texture* pixel = s.texture(s.material(s.objects[0].material)->albedoTexture);
  const Texture* smooth = s.texture(s.material(s.objects[1].material)->albedoTexture);
  ASSERT_TRUE(pixel && smooth);
  EXPECT_NE(pixel->id, smooth->id);
  EXPECT_FALSE(pixel->interpolate);
  EXPECT_TRUE(pixel->clampToEdge);
  EXPECT_TRUE(smooth->interpolate);
  EXPECT_FALSE(smooth->clampToEdge);
}

// An integrator block as Bitterli's files have it says nothing; min_bounces and light sampling
// are the scene's settings; what changes the picture and is not rendered is said.
TEST(Tungsten, IntegratorSettingsThatAreNotRenderedAreSaid) {
  auto plain = importTungsten(writeScene(R"({"integrator": {"type": "path_tracer", "min_bounces": 0, "max_bounces": 64,
      "enable_light_sampling": true, "enable_volume_light_sampling": true, "enable_consistency_checks": false,
      "enable_two_sided_shading": true}, "primitives": [{"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(plain.ok()) << plain.error();
  EXPECT_TRUE(plain->warnings.empty()) << plain->warnings.front();
  EXPECT_EQ(plain->scene.settings.minBounces, 0);
  EXPECT_TRUE(plain->scene.settings.lightSampling);
  auto odd = importTungsten(writeScene(R"({"integrator": {"type": "bidirectional_path_tracer", "min_bounces": 2,
      "enable_light_sampling": false}, "primitives": [{"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(odd.ok()) << odd.error();
  ASSERT_EQ(odd->warnings.size(), 1u);
  EXPECT_NE(odd->warnings[0].find("bidirectional_path_tracer"), std::string::npos) << odd->warnings[0];
  EXPECT_EQ(odd->scene.settings.minBounces, 2);
  EXPECT_FALSE(odd->scene.settings.lightSampling);
  // Volume light sampling alone cannot be turned off here: said.
  auto volume = importTungsten(writeScene(R"({"integrator": {"enable_volume_light_sampling": false},
      "primitives": [{"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(volume.ok()) << volume.error();
  ASSERT_EQ(volume->warnings.size(), 1u);
  EXPECT_NE(volume->warnings[0].find("enable_volume_light_sampling"), std::string::npos) << volume->warnings[0];
  EXPECT_TRUE(volume->scene.settings.lightSampling);
}

// A mesh's backface_culling, which Bitterli's files write on every mesh (false but for a few),
// is the object's: each mesh its own. Tungsten's analytic shapes do not read the key.
TEST(Tungsten, AMeshsBackfaceCullingIsItsObjects) {
  auto file = writeScene(R"({"primitives": [
      {"type": "mesh", "file": "tri.obj", "backface_culling": true},
      {"type": "mesh", "file": "tri.obj", "backface_culling": false},
      {"type": "mesh", "file": "tri.obj"},
      {"type": "quad", "emission": 1, "backface_culling": true}]})");
  std::ofstream(file.parent_path() / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  auto r = importTungsten(file);
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_TRUE(r->warnings.empty()) << r->warnings.front();
  ASSERT_EQ(r->scene.objects.size(), 4u);
  EXPECT_TRUE(r->scene.objects[0].cullBackFaces);
  EXPECT_FALSE(r->scene.objects[1].cullBackFaces);
  EXPECT_FALSE(r->scene.objects[2].cullBackFaces);
  EXPECT_FALSE(r->scene.objects[3].cullBackFaces);
  EXPECT_EQ(r->scene.objects[0].mesh, r->scene.objects[1].mesh) << "one mesh, culled by one object only";

  // And it survives the native format.
  const auto saved = file.parent_path() / "culled.retile";
  ASSERT_TRUE(saveNativeScene(r->scene, saved).ok());
  auto back = loadNativeScene(saved);
  ASSERT_TRUE(back.ok()) << back.error();
  ASSERT_EQ(back->scene.objects.size(), 4u);
  EXPECT_TRUE(back->scene.objects[0].cullBackFaces);
  EXPECT_FALSE(back->scene.objects[1].cullBackFaces);
}

TEST(Tungsten, AThinLensCameraKeepsItsApertureAndFocus) {
  auto r = importTungsten(writeScene(R"({"camera": {"type": "thinlens", "fov": 40, "aperture_size": 0.02,
      "focus_distance": 3.5, "transform": {"position": [0, 1, 6], "look_at": [0, 1, 0], "up": [0, 1, 0]}},
      "primitives": [{"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(r->scene.camera.apertureRadius, 0.02f);
  EXPECT_EQ(r->scene.camera.focusDistance, 3.5f);
  EXPECT_TRUE(r->warnings.empty()) << r->warnings.front();

  auto pivot = importTungsten(writeScene(R"({"camera": {"type": "thinlens", "cateye": 0.5, "focus_pivot": "vase",
      "transform": {"position": [0, 1, 6], "look_at": [0, 1, 0], "up": [0, 1, 0]}},
      "primitives": [{"type": "quad", "emission": 1}, {"type": "cube", "name": "vase", "transform": {"position": [3, 1, 2]}}]})"));
  ASSERT_TRUE(pivot.ok()) << pivot.error();
  EXPECT_EQ(pivot->scene.camera.apertureRadius, 0.001f) << "Tungsten's default";
  EXPECT_NEAR(pivot->scene.camera.focusDistance, 5.0f, 1e-5f) << "from the camera to the vase's origin";
  ASSERT_EQ(pivot->warnings.size(), 1u);
  EXPECT_NE(pivot->warnings[0].find("cateye"), std::string::npos) << pivot->warnings[0];

  auto nowhere = importTungsten(writeScene(R"({"camera": {"type": "thinlens", "focus_pivot": "ghost", "focus_distance": 2},
      "primitives": [{"type": "quad", "emission": 1}]})"));
  ASSERT_TRUE(nowhere.ok()) << nowhere.error();
  EXPECT_EQ(nowhere->scene.camera.focusDistance, 2.0f);
  ASSERT_EQ(nowhere->warnings.size(), 1u);
  EXPECT_NE(nowhere->warnings[0].find("'ghost'"), std::string::npos) << nowhere->warnings[0];

  auto broken = importTungsten(writeScene(R"({"camera": {"type": "thinlens", "focus_distance": -1},
      "primitives": [{"type": "quad", "emission": 1}]})"));
  ASSERT_FALSE(broken.ok());
  EXPECT_NE(broken.error().find("focus_distance"), std::string::npos) << broken.error();

  auto file = test::tempDir() / "lens.retile";
  ASSERT_TRUE(saveNativeScene(r->scene, file).ok());
  auto back = loadNativeScene(file);
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back->scene.camera.apertureRadius, 0.02f);
  EXPECT_EQ(back->scene.camera.focusDistance, 3.5f);
  Scene pinhole = r->scene;
  pinhole.camera.apertureRadius = 0;
  ASSERT_TRUE(saveNativeScene(pinhole, file).ok());
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str().find("aperture_radius"), std::string::npos);
}

TEST(Tungsten, PowerBecomesRadianceByArea) {
  auto file = writeScene(R"({"primitives": [{"type": "quad", "transform": {"scale": [2, 1, 0.5]}, "power": 10}]})");
  auto r = importTungsten(file);
  ASSERT_TRUE(r.ok()) << r.error();
  const Material* m = r->scene.material(r->scene.objects[0].material);
  EXPECT_NEAR(m->emission.x, 10.0f / (kPi * 1.0f), 1e-4f);
}

// How many times the ray from p along d crosses `o`'s triangles, in the world.
int crossings(const Scene& s, const Object& o, Vec3 p, Vec3 d) {
  const MeshGeometry& g = *s.mesh(o.mesh)->geometry;
  const auto world = [&](std::size_t i) { return o.transform.transformPoint(g.positions[g.indices[i]]); };
  int n = 0;
  float t, u, v;
  for (std::size_t i = 0; i < g.indices.size(); i += 3)
    n += intersectTriangle(p, d, world(i), world(i + 1), world(i + 2), std::numeric_limits<float>::infinity(), &t, &u, &v);
  return n;
}

TEST(Tungsten, OurGlassAndIceSceneNestsEveryBodyInWhatItsIorSays) {
  // scenes/glass-ice/scene.json, the benchmark of long specular paths that Tungsten can time too
  // (scripts/performance.sh). Each dielectric's ior is the ratio of its two sides' indices, as
  // Tungsten reads it, so the scene means what it says only if each body lies wholly inside the
  // one its ior names as its outside: water in the glass, ice in the water, air in the ice.
  auto r = importTungsten(std::filesystem::path(RETILE_SOURCE_DIR) / "scenes" / "glass-ice" / "scene.json");
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_TRUE(r->warnings.empty()) << r->warnings.front();
  const Scene& s = r->scene;
  EXPECT_EQ(s.objects.size(), 11u);
  const double glass = 1.5, water = 1.33, ice = 1.31;
  std::map<std::string, double> ior = {
      {"Glass", glass}, {"WaterInGlass", water / glass}, {"IceInWater", ice / water}, {"BubbleInIce", 1.0 / ice}, {"IceInAir", ice}};
  std::map<std::string, std::vector<std::string>> outside = {
      {"WaterInGlass", {"Glass"}}, {"IceInWater", {"WaterInGlass"}}, {"BubbleInIce", {"IceInWater", "IceInAir"}}};
  int nested = 0;
  for (const Object& inner : s.objects) {
    const Material& m = *s.material(inner.material);
    if (ior.count(m.name)) {
      EXPECT_NEAR(m.ior, ior[m.name], 5e-4) << m.name;
    }
    if (!outside.count(m.name)) continue;
    // Inside the convex body of one object of the outer material: every vertex crosses its
    // surface an odd number of times on the way out (both shapes are convex, so that holds the
    // whole body), and none of another's of that material.
    int holders = 0;
    for (const Object& outer : s.objects) {
      const std::string& name = s.material(outer.material)->name;
      if (&outer == &inner || std::find(outside[m.name].begin(), outside[m.name].end(), name) == outside[m.name].end()) continue;
      const MeshGeometry& g = *s.mesh(inner.mesh)->geometry;
      int in = 0;
      for (Vec3 v : g.positions) in += crossings(s, outer, inner.transform.transformPoint(v), Vec3{0.31f, 0.87f, 0.38f}) % 2;
      EXPECT_TRUE(in == 0 || in == static_cast<int>(g.positions.size())) << inner.name << " straddles " << outer.name;
      holders += in > 0;
    }
    EXPECT_EQ(holders, 1) << inner.name << " (" << m.name << ")";
    ++nested;
  }
  EXPECT_EQ(nested, 6) << "the water, two ice cubes in it and three bubbles";
}

}  // namespace
}  // namespace retile
