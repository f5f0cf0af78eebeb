#include <gtest/gtest.h>

#include <cmath>

#include "retile/edit.h"
#include "scene/synthetic.h"
#include "test_support.h"

namespace retile {
namespace {

TEST(DefaultScene, HasWhatLookDevNeeds) {
  Scene s = makeDefaultScene();
  auto named = [&](const std::string& n) {
    for (const auto& o : s.objects)
      if (o.name == n) return &o;
    return static_cast<const Object*>(nullptr);
  };
  ASSERT_TRUE(named("Ground"));
  ASSERT_TRUE(named("Cup"));
  ASSERT_TRUE(named("Glossy Sphere"));
  ASSERT_TRUE(named("Checkered Box"));
  const Object* light = named("Area Light");
  ASSERT_TRUE(light);
  EXPECT_TRUE(s.material(light->material)->emissive());
  EXPECT_TRUE(s.material(named("Checkered Box")->material)->albedoTexture != kNoNode);
  EXPECT_EQ(s.environment.type, EnvironmentType::Sky);
  // Ids are unique across every kind of node.
  std::vector<NodeId> ids;
  for (auto& m : s.meshes) ids.push_back(m.id);
  for (auto& m : s.materials) ids.push_back(m.id);
  for (auto& o : s.objects) ids.push_back(o.id);
  for (auto& t : s.textures) ids.push_back(t.id);
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end());
}

// Filter importance sampling draws each sample's offset from the filter's inverse CDF.
TEST(PixelFilter, WarpsAreInverseCdfs) {
  constexpr int kSegments = 32;
  for (int f = 0; f < kPixelFilterCount; ++f) {
    const auto filter = static_cast<PixelFilter>(f);
    SCOPED_TRACE(pixelFilterName(filter));
    PixelFilter parsed;
    ASSERT_TRUE(parsePixelFilter(pixelFilterName(filter), &parsed));
    EXPECT_EQ(parsed, filter);
    const float width = defaultFilterWidth(filter);
    const std::vector<float> w = pixelFilterWarp(filter, width, kSegments);
    ASSERT_EQ(w.size(), static_cast<std::size_t>(kSegments) + 1);
    EXPECT_FLOAT_EQ(w.front(), -0.5f * width);
    EXPECT_FLOAT_EQ(w.back(), 0.5f * width);
    for (int i = 0; i < kSegments; ++i) EXPECT_LT(w[i], w[i + 1]) << "monotone";
    for (int i = 0; i <= kSegments; ++i) EXPECT_NEAR(w[i], -w[kSegments - i], 1e-3f) << "symmetric";
  }
  // The box spreads samples evenly over the pixel; the tent's CDF inverts in closed form.
  const std::vector<float> box = pixelFilterWarp(PixelFilter::Box, 1.0f, kSegments);
  for (int i = 0; i <= kSegments; ++i) EXPECT_NEAR(box[i], -0.5f + static_cast<float>(i) / kSegments, 1e-4f);
  const std::vector<float> tent = pixelFilterWarp(PixelFilter::Tent, 2.0f, kSegments);
  for (int i = 0; i <= kSegments; ++i) {
    const double u = static_cast<double>(i) / kSegments;
    const double exact = u < 0.5 ? -1.0 + std::sqrt(2.0 * u) : 1.0 - std::sqrt(2.0 * (1.0 - u));
    EXPECT_NEAR(tent[i], exact, 2e-3) << u;
  }
  // Blackman-Harris is narrow: most samples within a third of its half-width of the centre.
  const std::vector<float> bh = pixelFilterWarp(PixelFilter::BlackmanHarris, 1.5f, kSegments);
  EXPECT_LT(bh[kSegments * 3 / 4], 0.75f / 3);
  PixelFilter unknown;
  EXPECT_FALSE(parsePixelFilter("mitchell", &unknown));
}

// Tungsten's table: the tent's weights 1 - k/31 at steps k = 0..30 sum to 16, so the CDF at step i
// is (i - i (i - 1) / 62) / 16; the Gaussian's is exp(-2 x^2) - exp(-8) over 2 px, most of it near
// the centre.
TEST(PixelFilters, TungstenTableIsTungstens) {
  const std::vector<float> tent = steppedFilterCdf(PixelFilter::Tent);
  ASSERT_EQ(tent.size(), static_cast<std::size_t>(kSteppedFilterSteps) - 1);
  for (int i = 1; i < kSteppedFilterSteps; ++i)
    EXPECT_NEAR(tent[static_cast<std::size_t>(i) - 1], (i - i * (i - 1) / 62.0) / 16.0, 1e-5) << i;
  const std::vector<float> gauss = steppedFilterCdf(PixelFilter::Gaussian);
  for (std::size_t i = 1; i < gauss.size(); ++i) EXPECT_GT(gauss[i], gauss[i - 1]) << "monotone";
  EXPECT_GT(gauss[14], 0.9f) << "weight at 1 px: exp(-2), at 2 px: none";
  EXPECT_LT(gauss.back(), 1.0f);
}

TEST(Document, EditsAdvanceTheVersionAndReportWhatChanged) {
  Document doc(makeDefaultScene());
  auto v0 = doc.version();
  Object cup = doc.scene().objects[1];
  cup.transform = Mat4::translate({0, 0.1f, 0}) * cup.transform;
  auto r = doc.apply(SetObject{cup});
  ASSERT_TRUE(r.ok()) << r.error();
  EXPECT_EQ(doc.version(), v0 + 1);
  EXPECT_TRUE(r.value() & kUpdateInstances);
  EXPECT_FALSE(r.value() & kUpdateGeometry);
  EXPECT_EQ(doc.scene().object(cup.id)->transform, cup.transform);

  Material m = doc.scene().materials[0];
  m.roughness = 0.5f;
  r = doc.apply(SetMaterial{m});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value(), static_cast<std::uint32_t>(kUpdateMaterials));

  // The world's medium alone leaves the sky as it was: nothing to decode and pack again.
  Environment fog = doc.scene().environment;
  fog.mediumScattering = Vec3{0.1f};
  r = doc.apply(SetEnvironment{fog});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value(), static_cast<std::uint32_t>(kUpdateMaterials)) << "the kernel's medium code and the suns' visibility";
  fog.intensity *= 2;
  r = doc.apply(SetEnvironment{fog});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.value(), static_cast<std::uint32_t>(kUpdateEnvironment)) << "the sky alone, no lights or instances";
}

TEST(Document, BadEditsAreRefusedAndChangeNothing) {
  Document doc(makeDefaultScene());
  auto v0 = doc.version();
  Object o = doc.scene().objects[0];
  o.transform.m[0][0] = std::nanf("");
  EXPECT_FALSE(doc.apply(SetObject{o}).ok());
  Object missing = doc.scene().objects[0];
  missing.id = 999999;
  EXPECT_FALSE(doc.apply(SetObject{missing}).ok());
  Object dangling = doc.scene().objects[0];
  dangling.material = 424242;
  EXPECT_FALSE(doc.apply(SetObject{dangling}).ok());
  Camera c = doc.scene().camera;
  c.verticalFov = 0;
  EXPECT_FALSE(doc.apply(SetCamera{c}).ok());
  c = doc.scene().camera;
  c.apertureRadius = -0.1f;
  EXPECT_FALSE(doc.apply(SetCamera{c}).ok());
  c.apertureRadius = 0.1f;
  c.focusDistance = 0;
  EXPECT_FALSE(doc.apply(SetCamera{c}).ok());
  RenderSettings rs;
  rs.width = 0;
  EXPECT_FALSE(doc.apply(SetRenderSettings{rs}).ok());
  for (Vec3 bad : {Vec3{-0.1f, 0, 0}, Vec3{2e6f, 0, 0}, Vec3{std::nanf(""), 0, 0}}) {
    Environment e = doc.scene().environment;
    e.mediumAbsorption = bad;
    EXPECT_FALSE(doc.apply(SetEnvironment{e}).ok()) << bad.x;
    Material m = doc.scene().materials[0];
    m.interiorScattering = bad;
    EXPECT_FALSE(doc.apply(SetMaterial{m}).ok()) << bad.x;
  }
  Environment skew = doc.scene().environment;
  skew.mediumAnisotropy = 1;
  EXPECT_FALSE(doc.apply(SetEnvironment{skew}).ok());
  Material blend = doc.scene().materials[0];
  blend.blendWith = blend.id;
  EXPECT_FALSE(doc.apply(SetMaterial{blend}).ok()) << "not with itself";
  blend.blendWith = 424242;
  EXPECT_FALSE(doc.apply(SetMaterial{blend}).ok()) << "not with a material that does not exist";
  for (float cone : {-10.0f, 91.0f, std::nanf("")}) {
    Material m = doc.scene().materials[0];
    m.emissionCone = cone;
    EXPECT_FALSE(doc.apply(SetMaterial{m}).ok()) << cone;
  }
  for (float tilt : {-46.0f, 50.0f, std::nanf("")}) {
    Material m = doc.scene().materials[0];
    m.hairTilt = tilt;
    EXPECT_FALSE(doc.apply(SetMaterial{m}).ok()) << "hair tilt " << tilt;
  }
  EXPECT_EQ(doc.version(), v0);
}

TEST(Document, RemovingANodeClearsReferences) {
  Document doc(makeDefaultScene());
  NodeId tex = doc.scene().textures[0].id;
  auto r = doc.apply(RemoveNode{tex});
  ASSERT_TRUE(r.ok()) << r.error();
  for (const auto& m : doc.scene().materials) EXPECT_NE(m.albedoTexture, tex);
  EXPECT_FALSE(doc.apply(RemoveNode{tex}).ok());
  Material blend = doc.scene().materials[0];
  blend.blendWith = doc.scene().materials[1].id;
  ASSERT_TRUE(doc.apply(SetMaterial{blend}).ok());
  ASSERT_TRUE(doc.apply(RemoveNode{blend.blendWith}).ok());
  EXPECT_EQ(doc.scene().material(blend.id)->blendWith, kNoNode) << "a blend with a removed material ends";
}

TEST(Document, CoalesceKeysSeparateTargetsAndKinds) {
  Scene s = makeDefaultScene();
  Edit a = SetObject{s.objects[0]};
  Edit b = SetObject{s.objects[0]};
  Edit c = SetObject{s.objects[1]};
  Edit d = SetMaterial{s.materials[0]};
  EXPECT_EQ(editCoalesceKey(a), editCoalesceKey(b));
  EXPECT_NE(editCoalesceKey(a), editCoalesceKey(c));
  EXPECT_NE(editCoalesceKey(a), editCoalesceKey(d));
}

// The benchmark room: close to the asked triangle count at every size, many separate objects
// (not one blob), every position finite, the same room every time.
TEST(Synthetic, FurnishedRoomHasTheTrianglesAskedForInManyObjects) {
  for (std::uint64_t n : {20000ull, 200000ull}) {
    const Scene s = makeFurnishedRoom(n);
    EXPECT_NEAR(static_cast<double>(s.triangleCount()), static_cast<double>(n), 0.15 * static_cast<double>(n));
    EXPECT_GT(s.objects.size(), 100u);
    std::size_t biggest = 0;
    for (const Mesh& m : s.meshes) {
      biggest = std::max(biggest, m.geometry->triangleCount());
      for (const Vec3& p : m.geometry->positions) ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
    }
    EXPECT_LT(static_cast<double>(biggest), 0.3 * static_cast<double>(s.triangleCount())) << "no mesh holds most of it";
  }
  EXPECT_EQ(makeFurnishedRoom(20000).meshes.back().geometry->positions, makeFurnishedRoom(20000).meshes.back().geometry->positions);
}

}  // namespace
}  // namespace retile
