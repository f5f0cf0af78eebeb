#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <limits>
#include <thread>
#include <regex>

#include "core/files.h"
#include "retile/io.h"
#include "test_support.h"

namespace retile {
namespace {

void expectSameScene(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.meshes.size(), b.meshes.size());
  for (std::size_t i = 0; i < a.meshes.size(); ++i) {
    EXPECT_EQ(a.meshes[i].id, b.meshes[i].id);
    EXPECT_EQ(a.meshes[i].name, b.meshes[i].name);
    EXPECT_EQ(a.meshes[i].geometry->positions, b.meshes[i].geometry->positions);
    EXPECT_EQ(a.meshes[i].geometry->normals, b.meshes[i].geometry->normals);
    EXPECT_EQ(a.meshes[i].geometry->uvs, b.meshes[i].geometry->uvs);
    EXPECT_EQ(a.meshes[i].geometry->indices, b.meshes[i].geometry->indices);
  }
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    const Material &x = a.materials[i], &y = b.materials[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(x.albedo, y.albedo);
    EXPECT_EQ(x.albedoTexture, y.albedoTexture);
    EXPECT_EQ(x.roughness, y.roughness);
    EXPECT_EQ(x.emission, y.emission);
    EXPECT_EQ(x.metal, y.metal);
  }
  ASSERT_EQ(a.objects.size(), b.objects.size());
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].transform, b.objects[i].transform);
    EXPECT_EQ(a.objects[i].material, b.objects[i].material);
    EXPECT_EQ(a.objects[i].visible, b.objects[i].visible);
  }
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (std::size_t i = 0; i < a.lights.size(); ++i) {
    const Light &x = a.lights[i], &y = b.lights[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.type, y.type);
    EXPECT_EQ(x.color, y.color);
    EXPECT_EQ(x.intensity, y.intensity);
    EXPECT_EQ(x.position, y.position);
    EXPECT_EQ(x.direction, y.direction);
    EXPECT_EQ(x.spotAngle, y.spotAngle);
    EXPECT_EQ(x.spotBlend, y.spotBlend);
    EXPECT_EQ(x.visible, y.visible);
    EXPECT_EQ(x.angularRadius, y.angularRadius);
  }
  ASSERT_EQ(a.textures.size(), b.textures.size());
  EXPECT_EQ(a.camera.position, b.camera.position);
  EXPECT_EQ(a.camera.verticalFov, b.camera.verticalFov);
  EXPECT_EQ(a.environment.type, b.environment.type);
  EXPECT_EQ(a.settings.width, b.settings.width);
  EXPECT_EQ(a.peekNextId(), b.peekNextId());
}

// What a Tungsten file brought (its texture decoding and stand-in) survives a save as a native scene.
TEST(Native, TungstenTextureHandlingRoundTrips) {
  Scene s = makeDefaultScene();
  Texture t;
  t.id = s.newId();
  t.path = "wood.jpg";
  t.colorSpace = TextureColorSpace::Gamma22;
  t.whenMissing = MissingTexture::BlackAndWhite;
  s.textures.push_back(t);
  auto file = test::tempDir() / "scene.retile";
  ASSERT_TRUE(saveNativeScene(s, file).ok());
  auto back = loadNativeScene(file);
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back->scene.textures.back().colorSpace, TextureColorSpace::Gamma22);
  EXPECT_EQ(back->scene.textures.back().whenMissing, MissingTexture::BlackAndWhite);
}

// Files saved while the second way of each convention was called "tungsten" (and Gamma22
// "tungsten_gamma") read as they were saved.
TEST(Native, FilesThatNamedTheConventionsTungstenReadAsSaved) {
  const auto file = test::tempDir() / "old.retile";
  std::ofstream(file) << R"({"format": "retile-scene", "version": 1,
    "settings": {"filter_sampling": "tungsten", "shading": "tungsten", "roulette": "tungsten", "ray_offset": "tungsten"},
    "textures": [{"id": 1, "kind": "checker", "color_space": "tungsten_gamma", "when_missing": "tungsten", "cells": "tungsten"}],
    "materials": [{"id": 2, "type": "dielectric", "glass": "tungsten"}]})";
  auto r = loadNativeScene(file);
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  EXPECT_EQ(s.settings.filterSampling, FilterSampling::SteppedTable);
  EXPECT_EQ(s.settings.shading, ShadingConvention::Unchecked);
  EXPECT_EQ(s.settings.roulette, Roulette::LowThroughput);
  EXPECT_EQ(s.settings.rayOffset, RayOffset::FixedEpsilon);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].colorSpace, TextureColorSpace::Gamma22);
  EXPECT_EQ(s.textures[0].whenMissing, MissingTexture::BlackAndWhite);
  EXPECT_TRUE(s.textures[0].truncatedCells);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_TRUE(s.materials[0].tintsReflection);
}

// A coat whose index is at or below 1 is no coat, in a file as in the panel: it reads as the
// field's "none" (1) without a warning; a coat above 1 reads as written.
TEST(Native, ACoatIndexOfOneOrLessReadsAsNoCoatWithoutAWarning) {
  const auto file = test::tempDir() / "coats.retile";
  std::ofstream(file) << R"({"format": "retile-scene", "version": 1,
    "materials": [{"id": 1, "type": "lambert", "coat_ior": 0}, {"id": 2, "type": "lambert", "coat_ior": 0.6},
                  {"id": 3, "type": "lambert", "coat_ior": 1.3}]})";
  auto r = loadNativeScene(file);
  ASSERT_TRUE(r.ok()) << r.error();
  ASSERT_EQ(r->scene.materials.size(), 3u);
  EXPECT_EQ(r->scene.materials[0].coatIor, 1.0f);
  EXPECT_EQ(r->scene.materials[1].coatIor, 1.0f);
  EXPECT_FALSE(r->scene.materials[1].coated());
  EXPECT_EQ(r->scene.materials[2].coatIor, 1.3f);
  for (const std::string& w : r->warnings) EXPECT_EQ(w.find("coat_ior"), std::string::npos) << w;
}

TEST(Native, DefaultSceneRoundTripsLosslessly) {
  Scene s = makeDefaultScene();
  s.settings.pixelFilter = PixelFilter::BlackmanHarris;
  s.settings.filterWidth = 1.75f;
  s.settings.filterSampling = FilterSampling::SteppedTable;
  s.settings.shading = ShadingConvention::Unchecked;
  s.settings.roulette = Roulette::LowThroughput;
  s.settings.rayOffset = RayOffset::FixedEpsilon;
  s.settings.minBounces = 2;
  s.settings.lightSampling = false;
  s.settings.view = "Filmic";
  s.materials[0].separableShadowing = true;
  s.materials[0].tintsReflection = true;
  ASSERT_FALSE(s.textures.empty());
  s.textures[0].interpolate = false;
  s.textures[0].clampToEdge = true;
  s.materials[0].bumpTexture = s.textures[0].id;
  s.materials[0].bumpStrength = -2.5f;
  s.materials[0].emissionTexture = s.textures[0].id;
  s.materials[0].coatingAbsorption = Vec3{0.1f, 0.2f, 0.3f};
  ASSERT_GE(s.materials.size(), 2u);
  s.materials[0].blendWith = s.materials[1].id;
  s.materials[0].blendRatio = 0.25f;
  s.materials[0].transmittance = 0.35f;
  s.materials[0].diffuseRatio = 0.45f;
  s.materials[0].interiorAbsorption = Vec3{0.4f, 0.5f, 0.6f};
  s.materials[0].interiorScattering = Vec3{1.5f, 2.5f, 3.5f};
  s.materials[0].interiorAnisotropy = -0.25f;
  s.materials[0].coatIor = 1.45f;
  s.materials[0].coatRoughness = 0.07f;
  s.materials[0].coatAbsorption = Vec3{0.01f, 0.02f, 0.03f};
  s.materials[0].blendRatioTexture = s.textures[0].id;
  s.materials[1].type = MaterialType::Boundary;
  s.environment.orientation = Mat4::rotateZ(0.3f) * Mat4::rotateX(-1.2f);
  s.environment.rotation = 0.7f;
  s.environment.mediumAbsorption = Vec3{0.01f, 0.02f, 0.03f};
  s.environment.mediumScattering = Vec3{0.2f, 0.1f, 0.05f};
  s.environment.mediumAnisotropy = 0.35f;
  s.lights.push_back(Light{s.newId(), "Key", LightType::Spot, {1, 0.9f, 0.8f}, 3.5f, {1, 2, 3}, {0, -1, 0}, 0.4f, 0.2f, true});
  s.lights.push_back(Light{s.newId(), "Sun", LightType::Directional, {1, 1, 1}, 2.0f, {}, {0, -1, 1}, 0.5f, 0.1f, true, 0.01f});
  auto dir = test::tempDir();
  auto file = dir / "scene.retile";
  ASSERT_TRUE(saveNativeScene(s, file).ok());
  auto back = loadNativeScene(file);
  ASSERT_TRUE(back.ok()) << back.error();
  expectSameScene(s, back->scene);
  ASSERT_EQ(back->scene.lights.size(), 2u);
  EXPECT_EQ(back->scene.lights[0].type, LightType::Spot);
  EXPECT_EQ(back->scene.lights[1].angularRadius, 0.01f);
  EXPECT_EQ(back->scene.lights[0].intensity, 3.5f);
  EXPECT_EQ(back->scene.settings.pixelFilter, PixelFilter::BlackmanHarris);
  EXPECT_EQ(back->scene.settings.filterWidth, 1.75f);
  EXPECT_EQ(back->scene.settings.filterSampling, FilterSampling::SteppedTable);
  EXPECT_EQ(back->scene.settings.shading, ShadingConvention::Unchecked);
  EXPECT_EQ(back->scene.settings.roulette, Roulette::LowThroughput);
  EXPECT_EQ(back->scene.settings.rayOffset, RayOffset::FixedEpsilon);
  EXPECT_EQ(back->scene.settings.minBounces, 2);
  EXPECT_FALSE(back->scene.settings.lightSampling);
  EXPECT_EQ(back->scene.settings.view, "Filmic");
  EXPECT_FALSE(back->scene.textures[0].interpolate);
  EXPECT_TRUE(back->scene.textures[0].clampToEdge);
  EXPECT_TRUE(back->scene.materials[0].separableShadowing);
  EXPECT_TRUE(back->scene.materials[0].tintsReflection);
  EXPECT_EQ(back->scene.materials[0].bumpTexture, s.textures[0].id);
  EXPECT_EQ(back->scene.materials[0].bumpStrength, -2.5f);
  EXPECT_EQ(back->scene.materials[0].emissionTexture, s.textures[0].id);
  EXPECT_EQ(back->scene.materials[0].coatingAbsorption, Vec3(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(back->scene.materials[0].blendWith, s.materials[1].id);
  EXPECT_EQ(back->scene.materials[0].blendRatioTexture, s.textures[0].id);
  EXPECT_EQ(back->scene.materials[0].blendRatio, 0.25f);
  EXPECT_EQ(back->scene.materials[0].transmittance, 0.35f);
  EXPECT_EQ(back->scene.materials[0].diffuseRatio, 0.45f);
  EXPECT_EQ(back->scene.materials[0].interiorAbsorption, Vec3(0.4f, 0.5f, 0.6f));
  EXPECT_EQ(back->scene.materials[0].interiorScattering, Vec3(1.5f, 2.5f, 3.5f));
  EXPECT_FLOAT_EQ(back->scene.materials[0].interiorAnisotropy, -0.25f);
  EXPECT_EQ(back->scene.materials[1].type, MaterialType::Boundary);
  EXPECT_EQ(back->scene.materials[0].coatIor, 1.45f);
  EXPECT_EQ(back->scene.materials[0].coatRoughness, 0.07f);
  EXPECT_EQ(back->scene.materials[0].coatAbsorption, Vec3(0.01f, 0.02f, 0.03f));
  EXPECT_EQ(back->scene.environment.orientation, s.environment.orientation);
  EXPECT_EQ(back->scene.environment.rotation, 0.7f);
  EXPECT_EQ(back->scene.environment.mediumAbsorption, Vec3(0.01f, 0.02f, 0.03f));
  EXPECT_EQ(back->scene.environment.mediumScattering, Vec3(0.2f, 0.1f, 0.05f));
  EXPECT_EQ(back->scene.environment.mediumAnisotropy, 0.35f);
  // Saving what was loaded gives the same bytes.
  EXPECT_EQ(nativeSceneToString(s), nativeSceneToString(back->scene));
}

TEST(Native, NewScenesUseBlackmanHarrisAndOlderFilesKeepTheBox) {
  EXPECT_EQ(makeDefaultScene().settings.pixelFilter, PixelFilter::BlackmanHarris);
  EXPECT_EQ(makeDefaultScene().settings.filterWidth, 1.5f);
  // A file saved before the pixel filter existed was rendered with a box: it still is.
  std::string text = nativeSceneToString(makeDefaultScene());
  text = std::regex_replace(text, std::regex(R"("pixel_filter": "[a-z_]+",\s*)"), "");
  text = std::regex_replace(text, std::regex(R"(,\s*"filter_width": [0-9.]+)"), "");
  ASSERT_EQ(text.find("filter"), std::string::npos) << text;
  auto dir = test::tempDir();
  std::ofstream(dir / "old.retile") << text;
  auto old = loadNativeScene(dir / "old.retile");
  ASSERT_TRUE(old.ok()) << old.error() << "\n" << text;
  EXPECT_EQ(old->scene.settings.pixelFilter, PixelFilter::Box);
  EXPECT_EQ(old->scene.settings.filterWidth, 1.0f);
}

TEST(Native, FailedSaveKeepsTheOldFile) {
  auto dir = test::tempDir();
  auto file = dir / "scene.retile";
  ASSERT_TRUE(saveNativeScene(makeDefaultScene(), file).ok());
  auto before = readFile(file);
  // A directory in the way of the temporary file's rename target is not possible to create
  // portably, so make the directory read-only: the save must fail and leave the file intact.
  std::filesystem::permissions(dir, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
  Scene changed = makeDefaultScene();
  changed.settings.width = 123;
  auto r = saveNativeScene(changed, file);
  std::filesystem::permissions(dir, std::filesystem::perms::owner_all);
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: directory permissions do not stop writes";
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(readFile(file).value(), before.value());
}

// A NaN that reached the document (no importer or panel lets one in, but an edit could) is not
// written: JSON cannot hold it, and the file would not read back. The save names the value and
// leaves the file as it was.
TEST(Native, ASceneWithANonFiniteValueIsNotSaved) {
  auto file = test::tempDir() / "scene.retile";
  ASSERT_TRUE(saveNativeScene(makeDefaultScene(), file).ok());
  auto before = readFile(file);
  Scene s = makeDefaultScene();
  s.materials[1].roughness = std::numeric_limits<float>::quiet_NaN();
  auto r = saveNativeScene(s, file);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("scene.retile"), std::string::npos) << r.error();
  EXPECT_NE(r.error().find("materials[1].roughness is not a finite number"), std::string::npos) << r.error();
  EXPECT_EQ(readFile(file).value(), before.value());
}

// kill -9 in the middle of a save: a child process writes a file of 48 MB (a scene with a dense
// mesh or big embedded textures) over the old one again and again, alternating two contents, and
// is killed at moments spread over a write's length. Every time the file holds one whole content,
// never a torn mix: the bytes go to a temporary beside it, then one rename. (Writing in place
// fails this at once.) The same writer saves scenes and autosaves.
TEST(Native, KillDuringASaveLeavesAWholeFile) {
  auto dir = test::tempDir();
  auto file = dir / "scene.retile";
  const std::string a(48u << 20, 'a'), b(32u << 20, 'b');
  ASSERT_TRUE(writeFileAtomic(file, a).ok());
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(writeFileAtomic(dir / "timing.retile", a).ok());
  const auto writeTime = std::chrono::steady_clock::now() - start;
  int leftovers = 0;
  for (int trial = 0; trial < 8; ++trial) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      for (int i = 0;; ++i) (void)writeFileAtomic(file, i % 2 ? b : a);
    }
    std::this_thread::sleep_for(writeTime + writeTime * trial / 8);
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status));
    auto bytes = readFile(file);
    ASSERT_TRUE(bytes.ok()) << bytes.error();
    EXPECT_TRUE(bytes.value() == a || bytes.value() == b) << "trial " << trial << ": " << bytes->size() << " bytes";
    for (const auto& entry : std::filesystem::directory_iterator(dir))
      leftovers += entry.path().filename().string().rfind(".scene.tmp", 0) == 0;
  }
  // Temporaries left behind show the kills landed mid-write (they are hidden files; the recovery
  // offer lists only autosave-*.retile).
  EXPECT_GT(leftovers, 0);
}

// The temporaries a killed save leaves behind go with the next save of the same file once they
// are older than any save can take; a recent one (a save running now) and other files stay.
TEST(Native, ASaveRemovesTheTemporariesOfKilledSaves) {
  auto dir = test::tempDir() / "stale";
  std::filesystem::create_directories(dir);
  auto file = dir / "scene.retile";
  auto stale = dir / ".scene.tmp1a2b3c.retile", recent = dir / ".scene.tmp4d5e6f.retile";
  auto otherScene = dir / ".other.tmp123456.retile", notOurs = dir / ".scene.tmp.keep";
  for (const auto& p : {stale, recent, otherScene, notOurs}) std::ofstream(p) << "partial";
  const auto old = std::filesystem::file_time_type::clock::now() - std::chrono::hours(1);
  for (const auto& p : {stale, otherScene, notOurs}) std::filesystem::last_write_time(p, old);
  ASSERT_TRUE(writeFileAtomic(file, "whole").ok());
  EXPECT_FALSE(std::filesystem::exists(stale));
  EXPECT_TRUE(std::filesystem::exists(recent));
  EXPECT_TRUE(std::filesystem::exists(otherScene)) << "another file's temporaries are its own saves' business";
  EXPECT_TRUE(std::filesystem::exists(notOurs));
  EXPECT_TRUE(std::filesystem::exists(file));
}

TEST(Native, SaveOverADirectoryFailsCleanly) {
  auto dir = test::tempDir();
  auto target = dir / "scene.retile";
  std::filesystem::create_directories(target / "inside");
  auto r = saveNativeScene(makeDefaultScene(), target);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("scene.retile"), std::string::npos) << r.error();
  EXPECT_TRUE(std::filesystem::is_directory(target / "inside"));
  // No temporary file is left behind.
  int entries = 0;
  for (auto& e : std::filesystem::directory_iterator(dir)) entries += e.path() != target;
  EXPECT_EQ(entries, 0);
}

TEST(Native, BrokenFilesGiveClearErrors) {
  auto dir = test::tempDir();
  struct Case {
    const char* text;
    const char* expect;
  } cases[] = {
      {"not json", "not valid JSON"},
      {"{\"format\": \"something-else\"}", "not a Retile scene"},
      {"{\"format\": \"retile-scene\", \"version\": 99}", "newer Retile"},
      {"{\"format\": \"retile-scene\", \"version\": 1, \"meshes\": [{\"id\": 1, \"positions\": \"@@@\"}]}", "meshes[0].positions"},
      {"{\"format\": \"retile-scene\", \"version\": 1, \"objects\": [{\"id\": 1, \"mesh\": 7}]}", "missing mesh"},
      {"{\"format\": \"retile-scene\", \"version\": 1, \"materials\": [{\"id\": 1, \"type\": \"glitter\"}]}", "unknown value 'glitter'"},
      {"{\"format\": \"retile-scene\", \"version\": 1, \"meshes\": [{\"id\": 1}, {\"id\": 1}]}", "not unique"},
      {"{\"format\": \"retile-scene\", \"version\": 1, \"settings\": {\"width\": 1e9}}", "outside 1..16384"},
      {"{\"format\": \"retile-scene\", \"version\": 1, \"settings\": {\"ray_offset\": \"sideways\"}}",
       "settings.ray_offset: unknown ray_offset 'sideways' (robust, fixed_epsilon)"},
  };
  int i = 0;
  for (const Case& c : cases) {
    auto file = dir / ("broken" + std::to_string(i++) + ".retile");
    std::ofstream(file) << c.text;
    auto r = loadNativeScene(file);
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_NE(r.error().find(file.filename().string()), std::string::npos) << r.error();
    EXPECT_NE(r.error().find(c.expect), std::string::npos) << r.error();
  }
}

TEST(Native, MissingFileIsAnError) {
  auto r = importScene("/nonexistent/scene.retile");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().find("not found"), std::string::npos);
}

}  // namespace
}  // namespace retile
