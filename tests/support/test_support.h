// Helpers shared by the test suites: locating ../shared, building tiny scenes in code, image
// statistics. Tests that need ../shared call sharedPathOrSkip, which skips with a message.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "retile/image.h"
#include "retile/scene.h"

namespace retile::test {

std::filesystem::path sharedDir();
// The path under ../shared, or an empty path when the folder is absent (then the test must skip).
std::filesystem::path sharedPath(const std::string& relative);

#define RETILE_SHARED_OR_SKIP(var, relative)                                                   \
  auto var = ::retile::test::sharedPath(relative);                                             \
  if (var.empty()) GTEST_SKIP() << "skipped: ../shared/" << (relative) << " is not present";

std::filesystem::path tempDir();  // a fresh directory per test

// Scene building blocks.
NodeId addMaterial(Scene& s, Material m);
NodeId addMeshObject(Scene& s, const std::string& name, std::shared_ptr<const MeshGeometry> g, NodeId material,
                     const Mat4& transform);
Scene emptyScene(int width, int height);

// Image statistics over the pixels where `mask` is true (all when empty).
double meanLuminance(const RenderImage& img, int x0, int y0, int x1, int y1);
bool allFinite(const RenderImage& img);

}  // namespace retile::test
