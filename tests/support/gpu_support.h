// Creates the Vulkan renderer for GPU tests, or skips the test with the reason when no Vulkan
// device is available (the project's CI always has lavapipe).
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "retile/render.h"

namespace retile::test {

std::unique_ptr<Renderer> makeRenderer(std::string* whyNot);

#define RETILE_RENDERER_OR_SKIP(var)                                    \
  std::string var##_why;                                                \
  auto var = ::retile::test::makeRenderer(&var##_why);                  \
  if (!var) GTEST_SKIP() << "skipped: no Vulkan device: " << var##_why;

// A camera at the origin looking down -z with the given vertical field of view.
Camera frontCamera(float verticalFovDegrees = 40.0f);

}  // namespace retile::test
