// Scenario scripts: the shipped ones parse and play on the default scene; broken ones name the
// file, the step and the problem.
#include <gtest/gtest.h>

#include <filesystem>

#include "retile/scenario.h"

namespace retile {
namespace {

std::filesystem::path scripts() { return std::filesystem::path(RETILE_SOURCE_DIR) / "resources" / "scripts"; }

TEST(Scenario, ShippedScriptsPlayOnTheDefaultScene) {
  int found = 0;
  for (const auto& e : std::filesystem::directory_iterator(scripts())) {
    SCOPED_TRACE(e.path().string());
    auto sc = loadScenario(e.path());
    ASSERT_TRUE(sc.ok()) << sc.error();
    Scene scene = makeDefaultScene();
    NodeId selection = kNoNode;
    for (const auto& step : sc->steps)
      for (int f = 0; f < step.frames; ++f) {
        auto edits = stepEdits(step, f, scene, selection);
        ASSERT_TRUE(edits.ok()) << edits.error();
        if (edits->select) selection = *edits->select;
        for (const auto& edit : edits->edits) ASSERT_TRUE(applyEdit(scene, edit).ok());
      }
    ++found;
  }
  EXPECT_GE(found, 3);
  auto fig6 = loadScenario(scripts() / "default-fig6-move-cup.json");
  ASSERT_TRUE(fig6.ok());
  EXPECT_EQ(fig6->converge, 1024);
  EXPECT_EQ(fig6->totalFrames(), 200) << "100 frames of motion, 100 at rest";
}

TEST(Scenario, MoveStepsMoveTheSelectionEveryFrame) {
  auto sc = parseScenario(R"({"steps": [{"select": "Cup"}, {"move": [0, 0.005, 0], "frames": 100}]})", "t.json");
  ASSERT_TRUE(sc.ok()) << sc.error();
  Scene scene = makeDefaultScene();
  NodeId cup = kNoNode;
  for (const auto& o : scene.objects)
    if (o.name == "Cup") cup = o.id;
  Vec3 start = scene.object(cup)->transform.transformPoint(Vec3{0.0f});
  auto sel = stepEdits(sc->steps[0], 0, scene, kNoNode);
  ASSERT_TRUE(sel.ok());
  ASSERT_EQ(*sel->select, cup);
  for (int f = 0; f < 100; ++f) {
    auto e = stepEdits(sc->steps[1], f, scene, cup);
    ASSERT_TRUE(e.ok());
    ASSERT_EQ(e->edits.size(), 1u);
    ASSERT_TRUE(applyEdit(scene, e->edits[0]).ok());
  }
  Vec3 end = scene.object(cup)->transform.transformPoint(Vec3{0.0f});
  EXPECT_NEAR(end.y - start.y, 0.5f, 1e-4f);
}

TEST(Scenario, BrokenScriptsSayWhereAndWhat) {
  struct Case {
    const char* text;
    const char* expect;
  } cases[] = {
      {"{", "t.json"},
      {"[]", "JSON object"},
      {R"({"steps": 3})", "\"steps\" must be an array"},
      {R"({"steps": [{"jump": 1}]})", "steps[0]: unknown step"},
      {R"({"steps": [{"wait": -4}]})", "steps[0]: wait"},
      {R"({"steps": [{"move": [0, "x", 0]}]})", "steps[0]: move"},
      {R"({"steps": [{"wait": 1}, {"material": "m"}]})", "steps[1]: a material step needs"},
      {R"({"steps": [{"focus": [{"pixel": [1, 2]}, {"pixel": [1, 2]}, {"pixel": [1, 2]}, {"pixel": [1, 2]}]}]})", "up to 3"},
      {R"({"converge": -1, "steps": []})", "converge"},
  };
  for (const auto& c : cases) {
    auto sc = parseScenario(c.text, "t.json");
    ASSERT_FALSE(sc.ok()) << c.text;
    EXPECT_NE(sc.error().find("t.json"), std::string::npos) << sc.error();
    EXPECT_NE(sc.error().find(c.expect), std::string::npos) << sc.error();
  }
  auto ok = parseScenario(R"({"steps": [{"select": "Nobody"}]})", "t.json");
  ASSERT_TRUE(ok.ok());
  auto e = stepEdits(ok->steps[0], 0, makeDefaultScene(), kNoNode);
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.error().find("Nobody"), std::string::npos);
}

TEST(Scenario, RelativeRmseIsZeroForEqualImagesAndScalesWithError) {
  std::vector<float> a(16 * 8 * 3, 0.5f), b = a;
  EXPECT_EQ(relativeRmse(a, b, 16, 8, 4), 0.0);
  for (float& v : b) v = 0.55f;
  EXPECT_NEAR(relativeRmse(b, a, 16, 8, 1), 0.1, 1e-6);
  EXPECT_TRUE(std::isnan(relativeRmse(a, std::vector<float>(3), 16, 8, 1))) << "mismatched sizes";
}

}  // namespace
}  // namespace retile
