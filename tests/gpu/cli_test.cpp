// The command line as a user runs it, in a child process: here under a comma-decimal locale, where
// every fractional number in the scene file, on the command line and in the output must still be
// read and written with '.'.
#include <gtest/gtest.h>

#include <cstdlib>

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

}  // namespace
}  // namespace retile
