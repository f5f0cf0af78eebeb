// Creates the Vulkan renderer for GPU tests, or skips the test with the reason when the machine has
// no Vulkan device; in CI (CI set, as .ci/run does) a missing device fails instead, since CI
// always has lavapipe. Any other failure (a shader that does not compile) throws and fails.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "retile/render.h"

namespace retile::test {

std::unique_ptr<Renderer> makeRenderer(std::string* whyNot, const RendererOptions& options = {});
// The same renderer entering every instance through its record, never packed direct
// (RendererOptions::directReferences off): the other traversal, for tests that run both.
std::unique_ptr<Renderer> makeRecordsRenderer(std::string* whyNot);
bool requireDevice();  // CI is set: no device is a failure

#define RETILE_RENDERER_OR_SKIP(var)                                                              \
  std::string var##_why;                                                                          \
  auto var = ::retile::test::makeRenderer(&var##_why);                                            \
  if (!var && ::retile::test::requireDevice()) FAIL() << "no Vulkan device in CI: " << var##_why; \
  if (!var) GTEST_SKIP() << "skipped: no Vulkan device: " << var##_why;

// A camera at the origin looking down -z with the given vertical field of view.
Camera frontCamera(float verticalFovDegrees = 40.0f);

}  // namespace retile::test
