#include <gtest/gtest.h>

#include <limits>

#include "core/json.h"

namespace retile::json {
namespace {

TEST(Json, ParsesNestedValues) {
  auto v = parse(R"({"a": [1, 2.5, -3e2], "b": {"c": "x\ny\u00e9"}, "d": true, "e": null})");
  ASSERT_TRUE(v.ok()) << v.error();
  const Value* a = v->find("a");
  ASSERT_TRUE(a && a->isArray());
  EXPECT_EQ(a->asArray().size(), 3u);
  EXPECT_DOUBLE_EQ(a->asArray()[2].asNumber(), -300.0);
  EXPECT_EQ(v->find("b")->find("c")->asString(), "x\ny\xc3\xa9");
  EXPECT_TRUE(v->find("d")->asBool());
  EXPECT_TRUE(v->find("e")->isNull());
}

TEST(Json, ErrorsNameLineAndColumn) {
  auto v = parse("{\n  \"a\": [1, 2,\n  ]\n}");
  ASSERT_FALSE(v.ok());
  EXPECT_NE(v.error().find("line 3"), std::string::npos) << v.error();
}

TEST(Json, RejectsHostileInput) {
  EXPECT_FALSE(parse(std::string(10000, '[')).ok());  // nesting bomb
  EXPECT_FALSE(parse("{\"a\": 1e999}").ok());         // overflow to infinity
  EXPECT_FALSE(parse("\"unterminated").ok());
  EXPECT_FALSE(parse("{\"a\": \"\\ud800\"}").ok());  // lone surrogate
  EXPECT_FALSE(parse("[1, 2] trailing").ok());
  EXPECT_FALSE(parse("").ok());
  EXPECT_FALSE(parse(std::string("\"a\0b\"", 5)).ok());  // control character in a string
}

TEST(Json, WriteRoundTripsFloatsExactly) {
  Value v(Object{});
  v.set("f", 0.1f);
  v.set("d", 1.0 / 3.0);
  v.set("s", "quote \" backslash \\ tab \t");
  auto back = parse(write(v));
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(static_cast<float>(back->find("f")->asNumber()), 0.1f);
  EXPECT_EQ(back->find("d")->asNumber(), 1.0 / 3.0);
  EXPECT_EQ(back->find("s")->asString(), "quote \" backslash \\ tab \t");
}

// JSON has no NaN or infinity: the writer's output must still parse, and a caller can find where
// such a number sits before writing.
TEST(Json, NonFiniteNumbersWriteAsNullAndCanBeFound) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  Value material(Object{});
  material.set("albedo", fromVec3(Vec3{2.0f, static_cast<float>(nan), 0.0f}));
  Value first(Object{});
  Array materials;
  materials.push_back(std::move(first));
  materials.push_back(std::move(material));
  Value v(Object{});
  v.set("fine", 1.5);
  v.set("materials", std::move(materials));
  EXPECT_EQ(firstNonFinite(v), "materials[1].albedo[1]");
  auto back = parse(write(v));
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_TRUE(back->find("materials")->asArray()[1].find("albedo")->asArray()[1].isNull());
  EXPECT_EQ(write(Value(-inf), false), "null");
  EXPECT_EQ(firstNonFinite(Value(inf)), "the value");
  EXPECT_EQ(firstNonFinite(back.value()), "");
}

TEST(Json, LenientVectorReaders) {
  Vec3 v;
  EXPECT_TRUE(toVec3(Value(0.5), &v));
  EXPECT_EQ(v, Vec3(0.5f, 0.5f, 0.5f));
  EXPECT_TRUE(toVec3(parse("[1, 2, 3]").value(), &v));
  EXPECT_EQ(v, Vec3(1, 2, 3));
  EXPECT_FALSE(toVec3(parse("[1, 2]").value(), &v));
  EXPECT_FALSE(toVec3(Value("x"), &v));
}

}  // namespace
}  // namespace retile::json
