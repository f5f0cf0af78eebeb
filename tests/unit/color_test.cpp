#include <gtest/gtest.h>

#include <fstream>

#include "core/process.h"
#include "io/image_io.h"
#include "retile/color.h"
#include "retile/scene.h"
#include "test_support.h"

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

// Tungsten's "gamma_correct" (TungstenGamma): floor(255 (v/255)^2.2) / 255, its decoding table,
// against entries of that table; sRGB gives other values (64 -> 13, not 12; 21 -> 1.9, not 1).
TEST(Color, TungstenGammaTexturesDecodeWithTungstensTable) {
  const auto file = test::tempDir() / "ramp.ppm";
  {
    std::ofstream out(file, std::ios::binary);
    out << "P6\n6 1\n255\n";
    for (unsigned char v : {0, 20, 21, 64, 128, 255}) out << v << v << v;
  }
  Texture t;
  t.kind = TextureKind::File;
  t.path = file;
  t.colorSpace = TextureColorSpace::TungstenGamma;
  auto img = loadTextureImage(t, file.parent_path());
  ASSERT_TRUE(img.ok()) << img.error();
  ASSERT_EQ(img->width, 6);
  const float expected[] = {0, 0, 1, 12, 55, 255};
  for (int i = 0; i < 6; ++i) {
    EXPECT_FLOAT_EQ(img->rgba[static_cast<std::size_t>(i) * 4] * 255.0f, expected[i]) << i;
    EXPECT_EQ(img->rgba[static_cast<std::size_t>(i) * 4 + 3], 1.0f) << "alpha as stored";
  }
  t.colorSpace = TextureColorSpace::SRGB;
  auto srgb = loadTextureImage(t, file.parent_path());
  ASSERT_TRUE(srgb.ok());
  EXPECT_NEAR(srgb->rgba[3 * 4] * 255.0f, 13.08f, 0.01f);
}

// A half EXR (Tungsten's references are) holds values below half's smallest normal, 6.1e-5, as
// denormals; OpenImageIO converts them correctly only when the thread keeps denormals, and
// the editor's threads flush them (flushDenormals). Read with them flushed, as the CLI reads.
// Four pixels are converted in this thread whatever the reader's thread count: this checks
// KeepDenormals, not that the conversion stays off OpenImageIO's pool (threads(1)).
TEST(Color, HalfExrReadsValuesBelowHalfsSmallestNormal) {
  RenderImage im;
  im.width = 4;
  im.height = 1;
  im.color = {2.6e-5f, 2.6e-5f, 2.6e-5f, 8e-7f, 8e-7f, 8e-7f, 3e-6f, 3e-6f, 3e-6f, 0.25f, 0.25f, 0.25f};
  const auto file = test::tempDir() / "dark-half.exr";
  ASSERT_TRUE(writeRenderImage(im, file, {}).ok());
  KeepDenormals restore;  // the test's own flags, put back at the end
  flushDenormals();
  auto back = readImageRaw(file);
  ASSERT_TRUE(back.ok()) << back.error();
  ASSERT_EQ(back->width, 4);
  for (std::size_t p = 0; p < 4; ++p)
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_NEAR(back->rgba[4 * p + c], im.color[3 * p + c], 2e-3f * im.color[3 * p + c] + 6e-8f) << "pixel " << p;
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
