// Helpers shared by the test suites: locating ../shared, building tiny scenes in code, image
// statistics. Tests that need ../shared call sharedPathOrSkip, which skips with a message.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "retile/image.h"
#include "retile/scene.h"

namespace retile::test {

// The first object of that name, kNoNode if none.
inline NodeId objectNamed(const Scene& s, const std::string& name) {
  for (const Object& o : s.objects)
    if (o.name == name) return o.id;
  return kNoNode;
}

std::filesystem::path sharedDir();
// The path under ../shared, or an empty path when the folder is absent (then the test must skip).
std::filesystem::path sharedPath(const std::string& relative);

#define RETILE_SHARED_OR_SKIP(var, relative)       \
  auto var = ::retile::test::sharedPath(relative); \
  if (var.empty()) GTEST_SKIP() << "skipped: ../shared/" << (relative) << " is not present";

std::filesystem::path tempDir();  // a fresh directory per test

// Adds a texture read from `file` (named after it) to the scene.
NodeId addFileTexture(Scene& s, const std::filesystem::path& file, TextureColorSpace space);

// Writes an 8-bit RGB image (binary PPM, which OpenImageIO reads as 8 bits a channel): rgb holds
// width * height pixels of three bytes, row 0 at the top.
void writePpm(const std::filesystem::path& file, int width, int height, const std::vector<std::uint8_t>& rgb);

// A comma-decimal locale (de_DE.UTF-8), compiled once by localedef into a folder of its own, so
// the tests need neither root nor a locale the machine happens to have. Point LOCPATH at the
// folder and set LC_ALL=de_DE.UTF-8 to run a child under it. Empty, with `error` set, when
// localedef is missing (scripts/setup-debian.sh installs the `locales` package it needs).
std::filesystem::path commaLocaleDir(std::string* error);

// Switches this process's C locale to de_DE.UTF-8 for the object's lifetime, as Qt does at start-up
// from the environment, and checks that the C library now reads "0,5" as a half.
class ScopedCommaLocale {
 public:
  ScopedCommaLocale();
  ~ScopedCommaLocale();
  ScopedCommaLocale(const ScopedCommaLocale&) = delete;
  ScopedCommaLocale& operator=(const ScopedCommaLocale&) = delete;
  bool active() const { return error_.empty(); }
  const std::string& error() const { return error_; }

 private:
  std::string previous_;
  std::string error_;
};

// Scene building blocks.
NodeId addMaterial(Scene& s, Material m);
NodeId addMeshObject(Scene& s, const std::string& name, std::shared_ptr<const MeshGeometry> g, NodeId material, const Mat4& transform);
Scene emptyScene(int width, int height);

// Image statistics over the pixels where `mask` is true (all when empty).
double meanLuminance(const RenderImage& img, int x0, int y0, int x1, int y1);
bool allFinite(const RenderImage& img);

}  // namespace retile::test
