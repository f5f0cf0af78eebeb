// Numbers in files and on the command line do not depend on the process locale. Qt sets the C
// locale from the environment, so an artist under de_DE.UTF-8 runs the whole engine with ',' as the
// decimal point: every test here runs its reader or writer under that locale and compares with
// the C locale.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <regex>
#include <string>

#include "core/files.h"
#include "core/json.h"
#include "core/numbers.h"
#include "retile/io.h"
#include "test_support.h"

namespace retile {
namespace {

#define RETILE_COMMA_LOCALE(var) \
  test::ScopedCommaLocale var;   \
  ASSERT_TRUE(var.active()) << var.error();

TEST(Numbers, UnderflowReadsAsZeroAndOverflowAsInfinity) {
  EXPECT_EQ(numbers::toFloat("1e-50"), 0.0f);
  EXPECT_EQ(numbers::toFloat("-0.00000000000000000000000000000000000000000000000001"), -0.0f);
  EXPECT_TRUE(std::signbit(*numbers::toFloat("-1e-50")));
  EXPECT_EQ(numbers::toDouble("1e-400"), 0.0);
  EXPECT_EQ(numbers::toFloat("1e39"), INFINITY);
  EXPECT_EQ(numbers::toFloat("-123456789e40"), -INFINITY);
  EXPECT_EQ(numbers::toDouble("1e400"), INFINITY);
  EXPECT_EQ(numbers::toDouble("1e-99999999999999999999"), 0.0) << "an exponent too long for a long";
  // Found by fuzz_json: digits before an exponent at the limit of a long overflowed their sum.
  const std::string digits(800, '5');
  EXPECT_EQ(numbers::toDouble(digits + "e9223372036854775807"), INFINITY);
  EXPECT_EQ(numbers::toDouble("0." + std::string(800, '0') + "1e-9223372036854775808"), 0.0);
  EXPECT_EQ(numbers::toFloat("1e-40"), 1e-40f) << "a float denormal is representable";
  EXPECT_FALSE(numbers::toDouble("0,5"));
  EXPECT_FALSE(numbers::toDouble("1.5 "));
  EXPECT_FALSE(numbers::toDouble(""));
  EXPECT_FALSE(numbers::toDouble("abc"));
}

TEST(Numbers, WritesTheShortestFormThatReadsBack) {
  EXPECT_EQ(numbers::format(0.1f), "0.1");
  EXPECT_EQ(numbers::format(0.1), "0.1");
  EXPECT_EQ(numbers::format(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(numbers::format(1920), "1920");
  EXPECT_EQ(numbers::format(-2.5e-7f), "-2.5e-07");
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::uint32_t> bits;
  for (int i = 0; i < 20000; ++i) {
    float f;
    std::uint32_t b = bits(rng);
    std::memcpy(&f, &b, sizeof f);
    if (!std::isfinite(f)) continue;
    auto back = numbers::toFloat(numbers::format(f));
    ASSERT_TRUE(back) << numbers::format(f);
    EXPECT_EQ(*back, f) << numbers::format(f);
    double d = std::ldexp(static_cast<double>(b), -20) + 1.0 / 7.0;
    EXPECT_EQ(numbers::toDouble(numbers::format(d)), d) << numbers::format(d);
  }
}

TEST(Numbers, ReadAndWriteTheSameUnderACommaDecimalLocale) {
  RETILE_COMMA_LOCALE(comma);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", 0.5);
  ASSERT_STREQ(buf, "0,5") << "the locale is active: the C library writes a comma";
  EXPECT_EQ(numbers::toDouble("0.5"), 0.5);
  EXPECT_FALSE(numbers::toDouble("0,5"));
  EXPECT_EQ(numbers::format(0.5f), "0.5");
}

TEST(Json, ReadsAndWritesFractionsUnderACommaDecimalLocale) {
  std::string text = R"({"a": [0.5, -1.25e-3, 2], "b": 0.1})";
  std::string inC = json::write(json::parse(text).value());
  RETILE_COMMA_LOCALE(comma);
  auto v = json::parse(text);
  ASSERT_TRUE(v.ok()) << v.error();
  EXPECT_EQ(v->find("a")->asArray()[0].asNumber(), 0.5);
  EXPECT_EQ(v->find("a")->asArray()[1].asNumber(), -1.25e-3);
  EXPECT_EQ(json::write(v.value()), inC);
  EXPECT_EQ(json::write(json::Value(0.1f)), "0.1\n");
}

TEST(NativeScene, SavedUnderACommaDecimalLocaleReadsBackIdenticalUnderC) {
  Scene scene = makeDefaultScene();
  std::filesystem::path file = test::tempDir() / "comma.retile";
  {
    RETILE_COMMA_LOCALE(comma);
    ASSERT_TRUE(saveNativeScene(scene, file).ok());
  }
  std::string saved = readFile(file).value();
  EXPECT_FALSE(std::regex_search(saved, std::regex(R"(\d,\d)"))) << "no comma decimals in the file";
  auto back = loadNativeScene(file);
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(nativeSceneToString(back->scene), nativeSceneToString(scene));
  EXPECT_EQ(nativeSceneToString(back->scene), saved);
}

TEST(Import, EverySharedSceneOpensTheSameUnderACommaDecimalLocale) {
  RETILE_SHARED_OR_SKIP(scenes, "scenes");
  for (const char* name :
       {"cornell-box/scene.json", "cornell-box/cornell-box.obj", "living-room/scene.json", "spaceship/scene.json", "bunny/bunny.obj"}) {
    SCOPED_TRACE(name);
    auto inC = importScene(scenes / name);
    test::ScopedCommaLocale comma;
    ASSERT_TRUE(comma.active()) << comma.error();
    auto inComma = importScene(scenes / name);
    ASSERT_EQ(inComma.ok(), inC.ok()) << (inComma.ok() ? inC.error() : inComma.error());
    if (inC.ok()) EXPECT_TRUE(nativeSceneToString(inComma->scene) == nativeSceneToString(inC->scene));
    else EXPECT_EQ(inComma.error(), inC.error());
  }
}

TEST(Obj, AnUnderflowingCoordinateReadsAsZeroAndKeepsTheTriangle) {
  auto p = test::tempDir() / "tiny.obj";
  std::ofstream(p) << "v 1e-50 0 0\nv 1.5 -1e-60 0\nv 0 1 +0.25e-45\nf 1 2 3\n";
  RETILE_COMMA_LOCALE(comma);
  std::vector<std::string> w;
  auto g = readObjGeometry(p, &w);
  ASSERT_TRUE(g.ok()) << g.error();
  ASSERT_EQ(g->triangleCount(), 1u);
  EXPECT_EQ(g->positions[0], Vec3(0, 0, 0));
  EXPECT_EQ(g->positions[1], Vec3(1.5f, 0, 0)) << "read with '.' as the decimal point";
  EXPECT_TRUE(w.empty()) << w.front();
}

}  // namespace
}  // namespace retile
