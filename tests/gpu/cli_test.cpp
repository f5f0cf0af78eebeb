// The command line as a user runs it, in a child process: here under a comma-decimal locale, where
// every fractional number in the scene file, on the command line and in the output must still be
// read and written with '.'.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "core/files.h"
#include "core/process.h"
#include "io/image_io.h"
#include "retile/io.h"
#include "test_support.h"

namespace retile {
namespace {

// Sets LC_ALL and LOCPATH for the children started while it lives.
class CommaLocaleEnvironment {
 public:
  explicit CommaLocaleEnvironment(const std::filesystem::path& dir) {
    ::setenv("LOCPATH", dir.c_str(), 1);
    ::setenv("LC_ALL", "de_DE.UTF-8", 1);
  }
  ~CommaLocaleEnvironment() { ::unsetenv("LC_ALL"); }
};

TEST(Cli, ImportAndRenderUnderACommaDecimalLocale) {
  RETILE_SHARED_OR_SKIP(scene, "scenes/cornell-box/scene.json");
  std::string error;
  std::filesystem::path locales = test::commaLocaleDir(&error);
  ASSERT_FALSE(locales.empty()) << error;
  CommaLocaleEnvironment env(locales);
  ChildLimits limits;
  limits.timeout = std::chrono::minutes(5);

  ChildResult imported = runChild(RETILE_CLI_PATH, {"import", scene.string()}, limits);
  ASSERT_EQ(imported.exitCode, 0) << imported.err;
  EXPECT_NE(imported.out.find("8 objects"), std::string::npos) << imported.out;

  std::filesystem::path out = test::tempDir() / "box.exr";
  ChildResult rendered = runChild(RETILE_CLI_PATH,
                                  {"render", scene.string(), "--size", "24x24", "--spp", "2", "--exposure", "0.5",
                                   "--out", out.string()},
                                  limits);
  ASSERT_EQ(rendered.exitCode, 0) << rendered.err;
  auto image = readImageRaw(out);
  ASSERT_TRUE(image.ok()) << image.error();
  ASSERT_EQ(image->width, 24);
  double mean = 0;
  for (std::size_t i = 0; i < image->rgba.size(); i += 4) mean += image->rgba[i + 1];
  EXPECT_GT(mean / (24 * 24), 0.05) << "the box is lit: its light's fractional coordinates were read";

  ChildResult comma = runChild(RETILE_CLI_PATH, {"render", scene.string(), "--exposure", "0,5"}, limits);
  EXPECT_EQ(comma.exitCode, 2);
  EXPECT_NE(comma.err.find("'0,5' is not a number"), std::string::npos) << comma.err;
}

// `retile eval --quick` as a reviewer runs it: every default method through three scenarios, a
// report that opens offline, and references that a second run takes from disk.
TEST(Cli, EvalQuickWritesTheReportAndCachesReferences) {
  const std::filesystem::path out = test::tempDir() / "eval";
  ChildLimits limits;
  limits.timeout = std::chrono::minutes(10);
  ChildResult run = runChild(RETILE_CLI_PATH, {"eval", "default", "--quick", "--scenarios", "fig6,material,light",
                                               "--out-dir", out.string()},
                             limits);
  ASSERT_EQ(run.exitCode, 0) << run.err;
  for (const char* f : {"index.html", "metrics.csv", "summary.csv"}) EXPECT_TRUE(std::filesystem::exists(out / f)) << f;

  auto metrics = readFile(out / "metrics.csv");
  ASSERT_TRUE(metrics) << metrics.error();
  EXPECT_EQ(metrics->rfind("scenario,scene,method,frame,ms,samples,rmse,psnr,ssim,psnr_hvs_m,rmse_affected,rmse_rest", 0), 0u);
  for (const char* m : {",global,", ",spiral,", ",focus,", ",indirection,", ",global+denoise,"})
    for (const char* sc : {"fig6,", "material,", "light,"})
      EXPECT_NE(metrics->find(std::string("\n") + sc + "default" + m), std::string::npos) << sc << m;

  // Nine charts, each a PNG with something drawn on it and an SVG beside it.
  int charts = 0;
  for (const auto& e : std::filesystem::directory_iterator(out / "charts")) {
    if (e.path().extension() != ".png") continue;
    ++charts;
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(e.path()).replace_extension(".svg"))) << e.path();
    auto img = readImageRaw(e.path());
    ASSERT_TRUE(img.ok()) << img.error();
    // Text and grid are grey; the methods' lines and points are the only colour. A line chart
    // has thousands of such pixels, the speed-against-accuracy chart 550 to 700 (its points
    // overlap more or less as the timings fall); a chart drawn without its layout (a view never
    // shown) shrinks into a corner of the page.
    std::size_t coloured = 0;
    for (std::size_t i = 0; i < img->rgba.size(); i += 4)
      coloured += std::max({std::abs(img->rgba[i] - img->rgba[i + 1]), std::abs(img->rgba[i + 1] - img->rgba[i + 2]),
                            std::abs(img->rgba[i] - img->rgba[i + 2])}) > 0.25f;
    EXPECT_GT(coloured, 250u) << e.path() << ": methods drawn, not a blank chart";
  }
  EXPECT_EQ(charts, 9);
  EXPECT_TRUE(std::filesystem::exists(out / "strips" / "default-fig6.png"));
  auto page = readFile(out / "index.html");
  ASSERT_TRUE(page);
  EXPECT_NE(page->find("charts/default-fig6-tradeoff.png"), std::string::npos);

  // Again, one scenario: every reference comes from disk.
  ChildResult again = runChild(RETILE_CLI_PATH, {"eval", "--quick", "--methods", "spiral", "--scenarios", "material",
                                                 "--out-dir", out.string()},
                               limits);
  ASSERT_EQ(again.exitCode, 0) << again.err;
  EXPECT_NE(again.err.find("references: 0 rendered, 2 reused"), std::string::npos) << again.err;
}

}  // namespace
}  // namespace retile
