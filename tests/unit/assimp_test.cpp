// Assimp runs in a child process: crashes, hangs and bad files become messages.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "retile/io.h"
#include "test_support.h"

namespace retile {
namespace {

TEST(Assimp, CornellObjWithMtlEmissionAsLight) {
  RETILE_SHARED_OR_SKIP(file, "scenes/cornell-box/cornell-box.obj");
  auto r = importScene(file);
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  EXPECT_EQ(s.triangleCount(), 36u);
  int emissive = 0;
  for (const auto& o : s.objects) {
    const Material* m = s.material(o.material);
    if (m && m->emissive()) {
      ++emissive;
      EXPECT_EQ(m->emission, Vec3(17, 12, 4));
    }
  }
  EXPECT_EQ(emissive, 1);
  // No camera in the file: the front view that frames the opening, as in the box's pbrt scene.
  EXPECT_NEAR(s.camera.position.z, 6.8f, 0.05f);
  EXPECT_NEAR(s.camera.position.y, 1.0f, 0.05f);
  EXPECT_EQ(s.settings.width, s.settings.height);
}

TEST(Assimp, AnEmissionMapIsTheEmissionTexture) {
  // OBJ's map_Ke (glTF's emissiveTexture arrives the same way, as Assimp's emissive texture).
  auto dir = test::tempDir();
  std::ofstream(dir / "sign.mtl") << "newmtl neon\nKd 0 0 0\nKe 2 2 2\nmap_Ke glow.png\n";
  std::ofstream(dir / "sign.obj") << "mtllib sign.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl neon\nf 1/1 2/2 3/3\n";
  auto r = importScene(dir / "sign.obj");
  ASSERT_TRUE(r.ok()) << r.error();
  const Material* neon = nullptr;
  for (const auto& m : r->scene.materials)
    if (m.name == "neon") neon = &m;
  ASSERT_TRUE(neon);
  const Material& m = *neon;
  EXPECT_EQ(m.emission, Vec3(2.0f));
  ASSERT_NE(m.emissionTexture, kNoNode);
  const Texture* t = r->scene.texture(m.emissionTexture);
  ASSERT_TRUE(t);
  EXPECT_EQ(t->path.filename(), "glow.png");
}

// glTF's clear coat (KHR_materials_clearcoat) becomes the material's coat, its perceptual
// roughness squared; a factor under a half leaves the material uncoated.
TEST(Assimp, AGltfClearCoatIsTheMaterialsCoat) {
  auto dir = test::tempDir();
  const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::ofstream(dir / "tri.bin", std::ios::binary).write(reinterpret_cast<const char*>(tri), sizeof tri);
  std::ofstream(dir / "car.gltf") << R"({"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_materials_clearcoat"],
    "materials": [
      {"name": "paint", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1], "metallicFactor": 0, "roughnessFactor": 0.5},
       "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1, "clearcoatRoughnessFactor": 0.3}}},
      {"name": "faint", "pbrMetallicRoughness": {"metallicFactor": 0},
       "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 0.2}}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]},
               {"primitives": [{"attributes": {"POSITION": 0}, "material": 1}]}],
    "nodes": [{"mesh": 0}, {"mesh": 1}], "scenes": [{"nodes": [0, 1]}], "scene": 0,
    "buffers": [{"byteLength": 36, "uri": "tri.bin"}], "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]})";
  auto r = importScene(dir / "car.gltf");
  ASSERT_TRUE(r.ok()) << r.error();
  const Material *paint = nullptr, *faint = nullptr;
  for (const auto& m : r->scene.materials) {
    if (m.name == "paint") paint = &m;
    if (m.name == "faint") faint = &m;
  }
  ASSERT_TRUE(paint && faint);
  EXPECT_EQ(paint->type, MaterialType::RoughPlastic);
  EXPECT_FLOAT_EQ(paint->coatIor, 1.5f);
  EXPECT_NEAR(paint->coatRoughness, 0.09f, 1e-6f);
  EXPECT_FALSE(faint->coated());
}

// glTF's transmission (KHR_materials_transmission) is glass, and its volume
// (KHR_materials_volume) what fills it: white light turns attenuationColor after
// attenuationDistance, an absorption of -ln(color) / distance. A thin-walled volume (thickness 0)
// fills nothing.
TEST(Assimp, AGltfVolumeFillsItsGlass) {
  auto dir = test::tempDir();
  const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::ofstream(dir / "tri.bin", std::ios::binary).write(reinterpret_cast<const char*>(tri), sizeof tri);
  std::ofstream(dir / "wine.gltf") << R"({"asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume"],
    "materials": [
      {"name": "wine", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0},
       "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                      "KHR_materials_volume": {"thicknessFactor": 1, "attenuationDistance": 0.5, "attenuationColor": [0.5, 0.25, 1]}}},
      {"name": "sheet", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0},
       "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                      "KHR_materials_volume": {"attenuationDistance": 0.5, "attenuationColor": [0.5, 0.25, 1]}}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]},
               {"primitives": [{"attributes": {"POSITION": 0}, "material": 1}]}],
    "nodes": [{"mesh": 0}, {"mesh": 1}], "scenes": [{"nodes": [0, 1]}], "scene": 0,
    "buffers": [{"byteLength": 36, "uri": "tri.bin"}], "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}]})";
  auto r = importScene(dir / "wine.gltf");
  ASSERT_TRUE(r.ok()) << r.error();
  const Material *wine = nullptr, *sheet = nullptr;
  for (const auto& m : r->scene.materials) {
    if (m.name == "wine") wine = &m;
    if (m.name == "sheet") sheet = &m;
  }
  ASSERT_TRUE(wine && sheet);
  EXPECT_EQ(wine->type, MaterialType::Dielectric);
  EXPECT_NEAR(wine->interiorAbsorption.x, 2 * std::log(2.0f), 1e-5f);
  EXPECT_NEAR(wine->interiorAbsorption.y, 2 * std::log(4.0f), 1e-5f);
  EXPECT_NEAR(wine->interiorAbsorption.z, 0.0f, 1e-6f);
  EXPECT_EQ(sheet->type, MaterialType::Dielectric);
  EXPECT_FALSE(sheet->filled()) << "thin-walled";
}

TEST(Assimp, CrashingFileIsReportedNotFatal) {
  RETILE_SHARED_OR_SKIP(file, "corpus/malformed/other/assimp-malformed_zero_numvertices/malformed_zero_numvertices.md2");
  auto r = importScene(file);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("malformed_zero_numvertices.md2"), std::string::npos) << r.error();
  EXPECT_NE(r.error().find("crashed"), std::string::npos) << r.error();
}

TEST(Assimp, HangIsStoppedByTheTimeLimit) {
  // A worker that sleeps stands in for an importer that never returns.
  auto dir = test::tempDir();
  auto fake = dir / "sleepy-worker";
  std::ofstream(fake) << "#!/bin/sh\nsleep 30\n";
  std::filesystem::permissions(fake, std::filesystem::perms::owner_all);
  auto model = dir / "model.ply";
  std::ofstream(model) << "ply\n";
  ::setenv("RETILE_IMPORT_WORKER", fake.c_str(), 1);
  ImportOptions o;
  o.assimpTimeout = std::chrono::milliseconds(500);
  auto start = std::chrono::steady_clock::now();
  auto r = importScene(model, o);
  ::unsetenv("RETILE_IMPORT_WORKER");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("did not finish"), std::string::npos) << r.error();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
}

TEST(Assimp, GarbageFileFailsCleanly) {
  auto dir = test::tempDir();
  auto f = dir / "garbage.fbx";
  std::ofstream(f) << "this is not an FBX file at all";
  auto r = importScene(f);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("garbage.fbx"), std::string::npos) << r.error();
}

TEST(Assimp, MemoryLimitStopsABlowUp) {
#if defined(RETILE_ASAN)
  GTEST_SKIP() << "an AddressSanitizer build sets no address-space limit on the worker (core/process.cpp)";
#endif
  RETILE_SHARED_OR_SKIP(file, "scenes/bunny/bunny.obj");
  ImportOptions o;
  o.assimpMemoryLimit = std::uint64_t(64) << 20;  // far too little for the bunny
  auto r = importScene(file, o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("bunny.obj"), std::string::npos) << r.error();
}

}  // namespace
}  // namespace retile
