// retile eval's pure parts: method labels, the built-in scenarios on any scene, which frames a
// plan scores against which state, and the summary's time to the target.
#include <gtest/gtest.h>

#include <cmath>
#include <variant>

#include "retile/eval.h"

namespace retile::eval {
namespace {

TEST(Eval, MethodLabelsParseAsTheReportNamesThem) {
  auto m = parseMethodLabel("spiral+smooth+denoise");
  ASSERT_TRUE(m) << m.error();
  EXPECT_EQ(m->kind, MethodKind::Spiral);
  EXPECT_TRUE(m->smooth);
  EXPECT_TRUE(m->denoise);
  EXPECT_EQ(methodLabel(m.value()), "spiral+smooth+denoise");
  auto ind = parseMethodLabel("indirection+focus");
  ASSERT_TRUE(ind);
  EXPECT_EQ(ind->kind, MethodKind::IndirectionFocus);
  EXPECT_EQ(ind->quality, 0) << "indirection takes automatic Q, as the editor offers it";
  EXPECT_FALSE(parseMethodLabel("teleport"));
  EXPECT_FALSE(parseMethodLabel("spiral+sharpen"));
  for (const auto& label : defaultMethods()) {
    auto d = parseMethodLabel(label);
    ASSERT_TRUE(d) << label;
    EXPECT_EQ(methodLabel(d.value()), label);
  }
}

TEST(Eval, BuiltInScenariosFitTheSceneAndSayWhatTheyLeaveOut) {
  Scene scene = makeDefaultScene();
  scene.settings.width = 96;
  scene.settings.height = 54;
  std::vector<std::string> skipped;
  auto cases = builtInScenarios(scene, Options::quick(), {}, &skipped);
  ASSERT_EQ(cases.size(), 5u);
  EXPECT_TRUE(skipped.empty());
  const Object* subject = scene.object(pickSubject(scene));
  ASSERT_NE(subject, nullptr);
  EXPECT_FALSE(scene.material(subject->material)->emissive());
  for (const Case& c : cases) {
    auto plan = planScenario(c.script, scene, 5);
    ASSERT_TRUE(plan) << c.name << ": " << plan.error();
    EXPECT_GT(plan->lastEditFrame, 0) << c.name << " edits something";
  }
  // Only the named ones.
  EXPECT_EQ(builtInScenarios(scene, Options::quick(), {"light"}, &skipped).size(), 1u);

  // A scene with nothing to move or light: the camera scenario alone, and the reasons.
  Scene empty;
  empty.settings = scene.settings;
  skipped.clear();
  auto left = builtInScenarios(empty, Options::quick(), {}, &skipped);
  ASSERT_EQ(left.size(), 1u);
  EXPECT_EQ(left[0].name, "camera");
  EXPECT_EQ(skipped.size(), 4u);
}

// Scenes from other tools often leave objects unnamed, or name them alike: the scenarios then
// name objects by id, and still edit the right one.
TEST(Eval, ScenariosFitScenesWhoseObjectsHaveNoNames) {
  Scene scene = makeDefaultScene();
  scene.settings.width = 96;
  scene.settings.height = 54;
  for (Object& o : scene.objects) o.name.clear();
  std::vector<std::string> skipped;
  auto cases = builtInScenarios(scene, Options::quick(), {}, &skipped);
  EXPECT_EQ(cases.size(), 5u) << (skipped.empty() ? "" : skipped[0]);
  const NodeId subject = pickSubject(scene);
  ASSERT_NE(subject, kNoNode);
  for (const Case& c : cases) {
    auto plan = planScenario(c.script, scene, 5);
    ASSERT_TRUE(plan) << c.name << ": " << plan.error();
    if (c.name == "fig6" || c.name == "drag") {
      ASSERT_FALSE(plan->frames.empty());
      const Edit& e = plan->frames[0].edits.at(0);
      ASSERT_TRUE(std::holds_alternative<SetObject>(e));
      EXPECT_EQ(std::get<SetObject>(e).object.id, subject) << c.name << " moves the picked object";
    }
  }
}

TEST(Eval, APlanScoresTheFirstEveryKthAndEveryRestingFrame) {
  Scene scene = makeDefaultScene();
  scene.settings.width = 96;
  scene.settings.height = 54;
  Options o = Options::quick();
  o.moveFrames = 12;
  o.restFrames = 5;
  auto cases = builtInScenarios(scene, o, {"fig6", "material"}, nullptr);
  ASSERT_EQ(cases.size(), 2u);
  auto move = planScenario(cases[0].script, scene, 5);
  ASSERT_TRUE(move);
  ASSERT_EQ(move->frames.size(), 17u);
  EXPECT_EQ(move->lastEditFrame, 12);
  std::vector<int> scored;
  for (std::size_t i = 0; i < move->frames.size(); ++i)
    if (move->frames[i].state >= 0) scored.push_back(static_cast<int>(i) + 1);
  EXPECT_EQ(scored, (std::vector<int>{1, 5, 10, 12, 13, 14, 15, 16, 17}));
  // One state per distinct scene: frames 1, 5, 10 and 12 show different positions; the rest
  // share frame 12's.
  EXPECT_EQ(move->states.size(), 4u);
  EXPECT_EQ(move->frames[16].state, move->frames[11].state);
  EXPECT_NE(move->selection, kNoNode) << "selected before converging";

  auto material = planScenario(cases[1].script, scene, 5);
  ASSERT_TRUE(material);
  EXPECT_EQ(material->lastEditFrame, 1);
  EXPECT_EQ(material->states.size(), 1u) << "every frame shows the edited material";
  EXPECT_NE(References::key(material->states[0], 64), References::key(material->start, 64));
  EXPECT_EQ(References::key(material->start, 64), References::key(scene, 64)) << "keyed by content";
  EXPECT_NE(References::key(scene, 64), References::key(scene, 128));
}

TEST(Eval, TimeToTargetIsWhenTheErrorStaysBelowIt) {
  eval::Run run;
  const double errors[] = {0.5, 0.1, 0.015, 0.03, 0.019, 0.018, NAN, 0.01};
  for (int i = 0; i < 8; ++i) {
    FrameScore s;
    s.frame = i + 1;
    s.ms = 10.0 * (i + 1);
    if (!std::isnan(errors[i])) {
      s.psnr = 20 + i;
      s.relRmse = errors[i];
      s.relRmseAffected = errors[i];
    }
    run.frames.push_back(s);
  }
  Summary s = summarize(run, 0.02);
  EXPECT_EQ(s.framesToTarget, 5) << "frame 3 went under, frame 4 back over";
  EXPECT_DOUBLE_EQ(s.msToTarget, 50.0);
  EXPECT_DOUBLE_EQ(s.psnrAt[0], 20.0);
  EXPECT_TRUE(std::isnan(s.psnrAt[2])) << "the run has no frame 100";
  EXPECT_EQ(summarize(run, 0.001).framesToTarget, -1);
}

TEST(Eval, RelativeRmseWithAMaskScoresOnlyMaskedPixels) {
  const int w = 8, h = 8;
  std::vector<float> ref(w * h * 3, 1.0f), img = ref;
  std::vector<std::uint8_t> mask(w * h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < 4; ++x) {
      mask[y * w + x] = 1;
      for (int c = 0; c < 3; ++c) img[(y * w + x) * 3 + c] = 1.1f;  // the masked half is 10 % off
    }
  EXPECT_NEAR(relativeRmse(img, ref, w, h, 4, mask.data()), 0.1, 1e-5);
  EXPECT_NEAR(relativeRmse(img, ref, w, h, 4), std::sqrt(0.01 / 2), 1e-5);
  for (auto& m : mask) m = !m;
  EXPECT_NEAR(relativeRmse(img, ref, w, h, 4, mask.data()), 0.0, 1e-6);
}

}  // namespace
}  // namespace retile::eval
