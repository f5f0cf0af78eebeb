// The import boundary (scene/validate.h): no value from a file reaches the renderer unless the
// renderer can take it; what was repaired is said; a scene with nothing sane left is an error
// that names the file.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "retile/io.h"
#include "scene/primitives.h"
#include "scene/validate.h"
#include "test_support.h"

namespace retile {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

bool mentions(const std::vector<std::string>& warnings, const std::string& text) {
  for (const std::string& w : warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

// Two good triangles (a unit quad) and one of each kind of bad one.
std::shared_ptr<const MeshGeometry> hostileGeometry() {
  auto g = std::make_shared<MeshGeometry>();
  g->positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {kNaN, 0, 0}, {3e38f, 0, 0}, {0, -kInf, 0}, {1e30f, 1e30f, 1e30f}};
  g->indices = {0, 1, 2,  0, 2, 3,  // the quad
                0, 1, 4,            // a NaN vertex
                0, 5, 1,            // near the float limit
                6, 0, 1,            // an infinity
                0, 1, 99,           // past the vertex list
                7, 7, 7,            // absurd, and degenerate
                0, 1};              // two indices left over
  g->normals = {{0, 0, 1}};         // one normal for eight vertices
  return g;
}

TEST(Validate, DropsTrianglesWithBadVerticesOrIndicesAndTheVerticesNothingUses) {
  Scene s;
  addMeshObject(s, "Hostile", hostileGeometry(), Material{}, Mat4{});
  std::vector<std::string> warnings;
  ASSERT_TRUE(validateScene(s, warnings).ok());
  const MeshGeometry& g = *s.meshes[0].geometry;
  EXPECT_EQ(g.triangleCount(), 2u);
  EXPECT_EQ(g.positions.size(), 4u) << "unused vertices go, so the bounds hold only the quad";
  EXPECT_TRUE(g.normals.empty());
  Bounds3 b = g.bounds();
  EXPECT_EQ(b.lo, Vec3(0, 0, 0));
  EXPECT_EQ(b.hi, Vec3(1, 1, 0));
  for (std::uint32_t i : g.indices) EXPECT_LT(i, g.positions.size());
  EXPECT_TRUE(mentions(warnings, "mesh 'Hostile': 1 triangles name vertices past its 8"));
  EXPECT_TRUE(mentions(warnings, "mesh 'Hostile': 4 triangles have non-finite or absurd coordinates"));
  EXPECT_TRUE(mentions(warnings, "2 indices left over"));
  EXPECT_TRUE(mentions(warnings, "normals"));
}

TEST(Validate, ACameraFarOutOrLookingNowhereFramesTheScene) {
  for (Camera bad : {Camera{{0, 0, 6.7e23f}, {0, 0, 0}, {0, 1, 0}, 0.7f}, Camera{{0, 0, 5}, {0, 0, 5}, {0, 1, 0}, 0.7f},
                     Camera{{0, 0, 5}, {0, 0, 0}, {0, 0, 1}, 0.7f}, Camera{{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, kNaN},
                     Camera{{kNaN, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.7f}}) {
    Scene s;
    addMeshObject(s, "Cube", makeCube(), Material{}, Mat4::translate({10, 0, 0}));
    s.camera = bad;
    std::vector<std::string> warnings;
    ASSERT_TRUE(validateScene(s, warnings).ok());
    EXPECT_TRUE(mentions(warnings, "framing the scene")) << bad.position.z;
    EXPECT_TRUE(isFinite(s.camera.position));
    EXPECT_NEAR(s.camera.target.x, 10.0f, 1e-4f) << "looks at what the scene holds";
    EXPECT_GT(length(s.camera.position - s.camera.target), 1.0f);
  }
}

TEST(Validate, ValuesOutsideTheirRangesAreClampedOrReset) {
  Scene s;
  Material m;
  m.albedo = {kNaN, 0.5f, 0.5f};
  m.emission = {-1, 0, 0};
  m.roughness = kInf;
  m.ior = kNaN;
  m.alpha = 7;
  m.eta = {-1, 1, 1};
  m.emissionCone = 200;
  m.hairTilt = -60;
  addMeshObject(s, "Cube", makeCube(), m, Mat4{});
  m.emissionCone = kNaN;
  addMeshObject(s, "Cube 2", makeCube(), m, Mat4{});
  Light l;
  l.name = "Nowhere";
  l.position = {kNaN, 0, 0};
  s.lights.push_back(l);
  Light spot;
  spot.name = "Spot";
  spot.type = LightType::Spot;
  spot.spotAngle = 9;
  s.lights.push_back(spot);
  Light sun;
  sun.name = "Sun";
  sun.type = LightType::Directional;
  sun.angularRadius = kNaN;
  s.lights.push_back(sun);
  s.environment.color = {kInf, 0, 0};
  s.environment.mediumAbsorption = {kNaN, 0, 0};
  s.environment.mediumScattering = {1e9f, 0.5f, 0};
  s.environment.mediumAnisotropy = -3;
  s.settings.width = 0;
  s.settings.height = 1000000;
  s.settings.samplesPerPixel = -3;
  s.settings.filterWidth = kNaN;
  std::vector<std::string> warnings;
  ASSERT_TRUE(validateScene(s, warnings).ok());
  const Material& r = s.materials[0];
  EXPECT_EQ(r.albedo, Vec3(0.8f));
  EXPECT_EQ(r.emission, Vec3(0.0f));
  EXPECT_EQ(r.roughness, Material{}.roughness);
  EXPECT_EQ(r.ior, 1.5f);
  EXPECT_EQ(r.alpha, 1.0f);
  EXPECT_EQ(r.metal, "Cu");
  EXPECT_EQ(r.emissionCone, 90.0f);
  EXPECT_EQ(s.materials[1].emissionCone, 90.0f);
  EXPECT_TRUE(mentions(warnings, "material 'Cube': emission_cone was 200; now 90"));
  EXPECT_EQ(r.hairTilt, -45.0f);
  EXPECT_TRUE(mentions(warnings, "material 'Cube': hair_tilt was -60; now -45"));
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].name, "Spot");
  EXPECT_LE(s.lights[0].spotAngle, 1.5707964f);
  EXPECT_EQ(s.lights[1].angularRadius, 0.0f);
  EXPECT_EQ(s.environment.color, Vec3(0.0f));
  EXPECT_EQ(s.environment.mediumAbsorption, Vec3(0.0f));
  EXPECT_EQ(s.environment.mediumScattering, Vec3(kMaxExtinction, 0.5f, 0.0f)) << "capped, not reset";
  EXPECT_EQ(s.environment.mediumAnisotropy, -0.99f);
  EXPECT_TRUE(mentions(warnings, "environment medium scattering is above"));
  EXPECT_EQ(s.settings.width, 1);
  EXPECT_EQ(s.settings.height, kMaxImageSide);
  EXPECT_EQ(s.settings.samplesPerPixel, 1);
  EXPECT_EQ(s.settings.filterWidth, defaultFilterWidth(s.settings.pixelFilter));
  EXPECT_TRUE(mentions(warnings, "material 'Cube': albedo"));
  EXPECT_TRUE(mentions(warnings, "light 'Nowhere'"));
  EXPECT_TRUE(mentions(warnings, "image height was 1000000; now 16384"));
}

TEST(Validate, ASaneSceneIsLeftAsItIs) {
  Scene s = makeDefaultScene();
  std::vector<const MeshGeometry*> before;
  for (const Mesh& m : s.meshes) before.push_back(m.geometry.get());
  Camera camera = s.camera;
  std::vector<std::string> warnings;
  ASSERT_TRUE(validateScene(s, warnings).ok());
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  for (std::size_t i = 0; i < s.meshes.size(); ++i) EXPECT_EQ(s.meshes[i].geometry.get(), before[i]);
  EXPECT_EQ(s.camera.position, camera.position);
}

TEST(Validate, NothingSaneLeftIsAnErrorNamingTheFile) {
  // Every vertex out at the float limit, as an out-of-bounds read gives them.
  auto dir = test::tempDir();
  auto file = dir / "garbage.obj";
  std::ofstream(file) << "v 3e38 3e38 3e38\nv -3e38 1 1\nv 1e20 1e20 1e20\nf 1 2 3\n";
  auto r = importScene(file);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("garbage.obj"), std::string::npos) << r.error();
  EXPECT_NE(r.error().find("nothing to render"), std::string::npos) << r.error();

  // One sane triangle beside them: it opens, and says what it left out.
  auto mixed = dir / "mixed.obj";
  std::ofstream(mixed) << "v 3e38 3e38 3e38\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 2 3 4\n";
  auto m = importScene(mixed);
  ASSERT_TRUE(m.ok()) << m.error();
  EXPECT_EQ(m->scene.triangleCount(), 1u);
  EXPECT_TRUE(mentions(m->warnings, "mixed.obj"));
  EXPECT_TRUE(isFinite(m->scene.camera.position));
}

}  // namespace
}  // namespace retile
