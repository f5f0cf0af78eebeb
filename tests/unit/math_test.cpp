#include <gtest/gtest.h>

#include <random>

#include "core/files.h"
#include "render/render_scene.h"
#include "retile/math.h"

namespace retile {
namespace {

float axis(Vec3 v, int k) { return k == 0 ? v.x : k == 1 ? v.y : v.z; }

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

// Properties shows and edits an object's rotation and scale through decompose/compose.
TEST(Math, DecomposeAndComposeRoundTrip) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> angle(-179.0f, 179.0f), pitch(-89.0f, 89.0f), size(0.05f, 20.0f), at(-50.0f, 50.0f);
  for (int i = 0; i < 200; ++i) {
    Trs t;
    t.translation = {at(rng), at(rng), at(rng)};
    t.rotationDegrees = {angle(rng), pitch(rng), angle(rng)};
    t.scale = {size(rng), size(rng), size(rng)};
    if (i % 7 == 0) t.scale.x = -t.scale.x;  // mirrored
    const Mat4 m = compose(t);
    // The linear part's determinant is the scales' product: rotations keep volume and handedness.
    const double volume = double(t.scale.x) * t.scale.y * t.scale.z;
    EXPECT_NEAR(m.linearDeterminant(), volume, 1e-4 * std::abs(volume)) << i;
    const Trs back = decompose(m);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(axis(back.translation, k), axis(t.translation, k), 1e-3f);
      EXPECT_NEAR(axis(back.rotationDegrees, k), axis(t.rotationDegrees, k), 2e-2f) << i;
      EXPECT_NEAR(axis(back.scale, k), axis(t.scale, k), 1e-3f * std::abs(axis(t.scale, k)));
    }
    const Mat4 again = compose(back);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(again.m[r][c], m.m[r][c], 2e-4f * (1.0f + std::abs(m.m[r][c])));
  }
  // Gimbal lock (90 degrees about y): another triple, the same transform.
  Trs locked;
  locked.rotationDegrees = {30.0f, 90.0f, 10.0f};
  const Mat4 m = compose(locked), again = compose(decompose(m));
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(again.m[r][c], m.m[r][c], 1e-4f);
  // The identity reads as no rotation and unit scale.
  const Trs id = decompose(Mat4::identity());
  EXPECT_EQ(id.rotationDegrees.x, 0.0f);
  EXPECT_EQ(id.scale.y, 1.0f);
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
