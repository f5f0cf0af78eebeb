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

// Tungsten's "gamma_correct" (Gamma22): floor(255 (v/255)^2.2) / 255, its decoding table,
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
  t.colorSpace = TextureColorSpace::Gamma22;
  // As linear floats, decoded the way the shader decodes them.
  auto linear = [&] {
    auto texture = loadTexture(t, file.parent_path());
    EXPECT_TRUE(texture.ok()) << texture.error();
    return texture.ok() ? std::move(texture.value()).toLinear() : LinearImage{};
  };
  const LinearImage decoded = linear();
  const LinearImage* img = &decoded;
  ASSERT_EQ(img->width, 6);
  const float expected[] = {0, 0, 1, 12, 55, 255};
  for (int i = 0; i < 6; ++i) {
    EXPECT_FLOAT_EQ(img->rgba[static_cast<std::size_t>(i) * 4] * 255.0f, expected[i]) << i;
    EXPECT_EQ(img->rgba[static_cast<std::size_t>(i) * 4 + 3], 1.0f) << "alpha as stored";
  }
  t.colorSpace = TextureColorSpace::SRGB;
  const LinearImage srgb = linear();
  ASSERT_EQ(srgb.width, 6);
  EXPECT_NEAR(srgb.rgba[3 * 4] * 255.0f, 13.08f, 0.01f);
}

// 8-bit sources stay bytes (a quarter of the memory of halves), with the curve the shader decodes
// them by; decoded, they are what the colour configuration made of them before. Every byte value
// of an sRGB texture decodes to the config's value (within 2.5e-4 of it, less than a half float's
// rounding: the config's linear segment is continuous with the power, a slope of 12.923 where
// the standard's is 12.92); Tungsten's gamma is applied to the bytes (its
// table is 8-bit); a 16-bit source becomes floats.
TEST(Color, EightBitTexturesKeepTheirBytes) {
  const auto file = test::tempDir() / "all-bytes.ppm";
  std::vector<std::uint8_t> rgb;
  for (int v = 0; v < 256; ++v)
    rgb.insert(rgb.end(), {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(255 - v), static_cast<std::uint8_t>(v / 2)});
  test::writePpm(file, 256, 1, rgb);
  Texture t;
  t.kind = TextureKind::File;
  t.path = file;
  t.colorSpace = TextureColorSpace::SRGB;  // OpenImageIO tags PPM files Rec709, which Auto takes as linear
  auto img = loadTexture(t, file.parent_path());
  ASSERT_TRUE(img.ok()) << img.error();
  ASSERT_TRUE(img->eightBit());
  EXPECT_EQ(img->curve, TextureImage::Curve::SRGB);
  ASSERT_EQ(img->rgba8.size(), 256u * 4);
  for (std::size_t v = 0; v < 256; ++v) {
    EXPECT_EQ(img->rgba8[v * 4], v);
    EXPECT_EQ(img->rgba8[v * 4 + 1], 255 - v);
    EXPECT_EQ(img->rgba8[v * 4 + 3], 255) << "no alpha in the file";
  }
  std::vector<float> config(256 * 4);
  for (std::size_t v = 0; v < 256; ++v)
    for (std::size_t c = 0; c < 3; ++c) config[v * 4 + c] = static_cast<float>(img->rgba8[v * 4 + c]) / 255.0f;
  ColorConfig::get()->srgbToLinear(config.data(), 256);
  LinearImage linear = std::move(img.value()).toLinear();
  ASSERT_EQ(linear.rgba.size(), config.size());
  for (std::size_t i = 0; i < config.size(); ++i) {
    if (i % 4 == 3) continue;
    EXPECT_NEAR(linear.rgba[i], config[i], 2.5e-4f * config[i] + 1e-9f) << "texel " << i / 4 << ", channel " << i % 4;
  }

  t.colorSpace = TextureColorSpace::Gamma22;
  auto tungsten = loadTexture(t, file.parent_path());
  ASSERT_TRUE(tungsten.ok() && tungsten->eightBit());
  EXPECT_EQ(tungsten->curve, TextureImage::Curve::Linear);
  EXPECT_EQ(tungsten->rgba8[64 * 4], 12) << "floor(255 (64/255)^2.2)";
  EXPECT_EQ(tungsten->rgba8[255 * 4], 255);

  const auto deep = test::tempDir() / "sixteen.ppm";
  {
    std::ofstream out(deep, std::ios::binary);
    out << "P6\n1 1\n65535\n";
    for (int c = 0; c < 3; ++c) out << static_cast<char>(0x80) << static_cast<char>(0);
  }
  t.path = deep;
  t.colorSpace = TextureColorSpace::Linear;
  auto sixteen = loadTexture(t, deep.parent_path());
  ASSERT_TRUE(sixteen.ok()) << sixteen.error();
  EXPECT_FALSE(sixteen->eightBit());
  ASSERT_EQ(sixteen->rgba.size(), 4u);
  EXPECT_NEAR(sixteen->rgba[0], 32768.0f / 65535.0f, 1e-6f);
}

// A half EXR (Tungsten's references are) holds values below half's smallest normal, 6.1e-5, as
// denormals; OpenImageIO converts them correctly only when the thread keeps denormals, and
// the editor's threads flush them (flushDenormals). Read with them flushed, as the CLI reads.
// Four pixels are converted in this thread whatever the reader's thread count: this checks
// KeepDenormals, not that the conversion stays off OpenImageIO's pool (threads(1)).
// An 8-bit file is sRGB-encoded under Auto whatever else its reader calls it: OpenImageIO tags a
// PPM "Rec709", a transfer curve, which was read as linear light.
TEST(Color, AnEightBitFileIsEncodedUnlessItSaysLinear) {
  const auto file = test::tempDir() / "grey.ppm";
  test::writePpm(file, 1, 1, {128, 128, 128});
  Texture t;
  t.kind = TextureKind::File;
  t.path = file;
  t.colorSpace = TextureColorSpace::Auto;
  auto img = loadTexture(t, file.parent_path());
  ASSERT_TRUE(img.ok()) << img.error();
  const LinearImage linear = std::move(img.value()).toLinear();
  ASSERT_EQ(linear.rgba.size(), 4u);
  EXPECT_NEAR(linear.rgba[0], srgbCurve(128.0f / 255.0f), 2.5e-4f) << "not " << 128.0f / 255.0f;
}

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
