// The command line's option helpers (app/cli_options.cpp) on a CLI11 App of their own: numbers read
// the same under a comma-decimal locale as under C (CLI11's own conversion would not: it calls
// strtold), whole numbers in decimal only, and every refusal names the option.
#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "cli.h"
#include "cli11.h"
#include "test_support.h"

namespace retile {
namespace {

struct Parsed {
  double exposure = 0;
  int spp = 1;
  std::optional<int> bounces;
  std::optional<double> target;
  cli::ImageSize size{4, 4};
  std::string error;  // the ParseError's message, empty when the line was accepted
};

Parsed parse(const std::string& line) {
  Parsed p;
  CLI::App app;
  cli::addNumber(app, "--exposure", &p.exposure, -64, 64, "stops");
  cli::addInt(app, "--spp", &p.spp, 1, 1 << 20, "samples per pixel");
  cli::addInt(app, "--max-bounces", &p.bounces, 0, 1024, "longest path", "the scene's");
  cli::addNumber(app, "--target", &p.target, 1e-6, 10, "relative RMSE", "0.02");
  cli::addSize(app, &p.size, "image size");
  try {
    app.parse(line);
  } catch (const CLI::ParseError& e) {
    p.error = e.what();
  }
  return p;
}

TEST(CliOptions, ReadsNumbersTheSameUnderACommaDecimalLocale) {
  test::ScopedCommaLocale comma;
  ASSERT_TRUE(comma.active()) << comma.error();
  Parsed p = parse("--exposure 0.5 --target 2.5e-2 --spp 010 --size 32x18 --max-bounces 0");
  ASSERT_EQ(p.error, "");
  EXPECT_EQ(p.exposure, 0.5);
  EXPECT_EQ(p.target, 0.025);
  EXPECT_EQ(p.spp, 10) << "decimal, not octal as strtoll in base 0 reads it";
  EXPECT_EQ(p.size.width, 32);
  EXPECT_EQ(p.size.height, 18);
  EXPECT_EQ(p.bounces, 0);
  EXPECT_EQ(parse("--exposure 0,5").error, "--exposure: '0,5' is not a number");
}

TEST(CliOptions, OptionsNotGivenKeepTheirDefaults) {
  Parsed p = parse("--exposure=-1.25");
  ASSERT_EQ(p.error, "");
  EXPECT_EQ(p.exposure, -1.25);
  EXPECT_EQ(p.spp, 1);
  EXPECT_FALSE(p.bounces.has_value());
  EXPECT_FALSE(p.target.has_value());
  EXPECT_EQ(p.size.width, 4);
}

TEST(CliOptions, RefusesMalformedAndOutOfRangeValuesNamingTheOption) {
  EXPECT_EQ(parse("--spp abc").error, "--spp: 'abc' is not a whole number");
  EXPECT_EQ(parse("--spp 0x10").error, "--spp: '0x10' is not a whole number");
  EXPECT_EQ(parse("--spp 2.5").error, "--spp: '2.5' is not a whole number");
  EXPECT_EQ(parse("--spp 0").error, "--spp: 0 is outside 1..1048576");
  EXPECT_EQ(parse("--spp 1048577").error, "--spp: 1048577 is outside 1..1048576");
  EXPECT_EQ(parse("--max-bounces 1025").error, "--max-bounces: 1025 is outside 0..1024");
  EXPECT_EQ(parse("--exposure 65").error, "--exposure: 65 is outside -64..64");
  EXPECT_EQ(parse("--exposure nan").error, "--exposure: 'nan' is not a number");
  EXPECT_EQ(parse("--target 0").error, "--target: 0 is outside 1e-06..10");
  EXPECT_EQ(parse("--size 32").error, "--size: '32' is not WIDTHxHEIGHT");
  EXPECT_EQ(parse("--size 0x18").error, "--size: width 0 is outside 1..16384");
  EXPECT_EQ(parse("--size 32x16385").error, "--size: height 16385 is outside 1..16384");
}

TEST(CliOptions, HelpGivesEachOptionItsRangeAndDefault) {
  Parsed p;
  CLI::App app;
  cli::addInt(app, "--spp", &p.spp, 1, 1 << 20, "samples per pixel");
  cli::addInt(app, "--max-bounces", &p.bounces, 0, 1024, "longest path", "the scene's");
  cli::addSize(app, &p.size, "image size");
  const std::string help = app.help();
  EXPECT_NE(help.find("--spp N"), std::string::npos) << help;
  EXPECT_NE(help.find("samples per pixel (1..1048576; default: 1)"), std::string::npos) << help;
  EXPECT_NE(help.find("longest path (0..1024; default: the scene's)"), std::string::npos) << help;
  EXPECT_NE(help.find("--size WxH"), std::string::npos) << help;
  EXPECT_NE(help.find("(each side 1..16384; default: 4x4)"), std::string::npos) << help;
}

}  // namespace
}  // namespace retile
