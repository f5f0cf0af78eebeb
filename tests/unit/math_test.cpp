#include <gtest/gtest.h>

#include <random>

#include "core/files.h"
#include "render/render_scene.h"
#include "retile/math.h"

namespace retile {
namespace {

TEST(Math, InverseOfComposedTransform) {
  Mat4 m = Mat4::translate({1, 2, 3}) * Mat4::rotateY(0.7f) * Mat4::rotateX(-0.3f) * Mat4::scale({2, 0.5f, 3});
  Mat4 r = m * m.inverse();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(r.m[i][j], i == j ? 1.0f : 0.0f, 1e-5f) << i << "," << j;
}

TEST(Math, SingularInverseIsZero) {
  Mat4 s = Mat4::scale({1, 0, 1});
  Mat4 inv = s.inverse();
  EXPECT_EQ(inv.m[0][0], 0.0f);
  EXPECT_EQ(inv.m[3][3], 0.0f);
}

TEST(Math, LookAtPointsForward) {
  Mat4 m = Mat4::lookAt({0, 0, 5}, {0, 0, 0}, {0, 1, 0});
  Vec3 forward = m.transformVector({0, 0, -1});
  EXPECT_NEAR(forward.z, -1.0f, 1e-6f);
  EXPECT_NEAR(m.transformPoint({0, 0, 0}).z, 5.0f, 1e-6f);
}

TEST(Math, HalfFloatRoundTrip) {
  for (float f : {0.0f, 1.0f, -2.5f, 0.1f, 65504.0f, 6.1e-5f, 1e-7f}) {
    float back = halfToFloat(floatToHalf(f));
    EXPECT_NEAR(back, f, std::abs(f) * 1e-3f + 6e-8f) << f;
  }
  EXPECT_TRUE(std::isinf(halfToFloat(floatToHalf(1e6f))));
}

TEST(Files, Base64RoundTrip) {
  std::mt19937 rng(3);
  for (std::size_t n : {0u, 1u, 2u, 3u, 4u, 100u, 1001u}) {
    std::vector<std::uint8_t> data(n);
    for (auto& b : data) b = static_cast<std::uint8_t>(rng());
    auto back = base64Decode(base64Encode(data.data(), data.size()));
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(back.value(), data);
  }
  EXPECT_FALSE(base64Decode("ab$d").ok());
}

}  // namespace
}  // namespace retile
