#include <gtest/gtest.h>

#include "retile/color.h"

namespace retile {
namespace {

TEST(Color, ShippedConfigLoadsWithBothViews) {
  auto cfg = ColorConfig::get();
  auto views = cfg->views();
  EXPECT_NE(std::find(views.begin(), views.end(), "Standard"), views.end());
  EXPECT_NE(std::find(views.begin(), views.end(), "Filmic"), views.end());
}

TEST(Color, SrgbTextureDecodesToLinear) {
  float px[8] = {0.5f, 0.04045f, 1.0f, 0.25f, 0.0f, 0.73536f, 0.2f, 1.0f};
  ColorConfig::get()->srgbToLinear(px, 2);
  EXPECT_NEAR(px[0], 0.214041f, 1e-5f);
  EXPECT_NEAR(px[1], 0.003131f, 1e-5f);
  EXPECT_NEAR(px[2], 1.0f, 1e-6f);
  EXPECT_EQ(px[3], 0.25f) << "alpha is untouched";
  EXPECT_NEAR(px[5], 0.5f, 1e-4f);
}

TEST(Color, DisplayViews) {
  auto cfg = ColorConfig::get();
  float grey[3] = {0.18f, 0.18f, 0.18f}, out[3];
  DisplaySettings standard;
  cfg->toDisplayFloat(grey, 1, standard, out);
  EXPECT_NEAR(out[0], 0.4614f, 1e-3f);  // sRGB encoding of 0.18
  DisplaySettings filmic;
  filmic.view = "Filmic";
  float bright[3] = {16.0f, 16.0f, 16.0f};
  cfg->toDisplayFloat(bright, 1, filmic, out);
  EXPECT_GT(out[0], 0.9f);
  EXPECT_LE(out[0], 1.0f) << "the filmic view rolls highlights off below white";
  DisplaySettings brighter;
  brighter.exposure = 1;
  cfg->toDisplayFloat(grey, 1, brighter, out);
  EXPECT_NEAR(out[0], 0.6343f, 1e-3f);  // sRGB encoding of 0.36
  std::uint8_t rgba[4];
  cfg->toDisplay8(grey, 1, standard, rgba);
  EXPECT_EQ(rgba[0], 118);
  EXPECT_EQ(rgba[3], 255);
}

}  // namespace
}  // namespace retile
