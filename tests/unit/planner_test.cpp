// The planner without a GPU: what every policy traces first, the smooth prefix, automatic Q, and
// each scheduling defect the review of issue 11 found (each test fails on the old behaviour).
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <utility>

#include "schedule/planner.h"

namespace retile {
namespace {

constexpr NodeId kCup = 7, kTable = 8;

MethodSettings methodOf(MethodKind kind, int quality = 16, bool smooth = false) {
  MethodSettings m;
  m.kind = kind;
  m.tileSize = 16;
  m.quality = quality;
  m.smooth = smooth;
  m.staleCap = 4;
  m.indirectionFrames = 2;
  return m;
}

// A move of `object` whose projected centre goes from `from` to `to`; its screen rectangle is a
// `size`-pixel square around each.
EditFacts moveFacts(NodeId object, Vec2 from, Vec2 to, int size = 20) {
  EditFacts f;
  f.pointOfChange = to;
  f.object = object;
  f.moved = true;
  f.centreBefore = from;
  f.centreAfter = to;
  for (Vec2 c : {from, to}) f.screen.push_back({static_cast<int>(c.x) - size / 2, static_cast<int>(c.y) - size / 2, size, size});
  return f;
}

// Counts of an object seen directly in `direct`, shadowing `shadow`, reflected into `reflection`.
IndirectionCounts countsOf(const TileGrid& g, const std::vector<int>& direct, const std::vector<int>& shadow,
                           const std::vector<int>& reflection, const std::vector<int>& low = {}) {
  IndirectionCounts c;
  auto n = static_cast<std::size_t>(g.count());
  c.direct.assign(n, 0);
  c.reflection.assign(n, 0);
  c.shadow.assign(n, 0);
  for (int t : direct) c.direct[static_cast<std::size_t>(t)] = 50;
  for (int t : shadow) c.shadow[static_cast<std::size_t>(t)] = 120;
  for (int t : reflection) c.reflection[static_cast<std::size_t>(t)] = 120;
  for (int t : low) c.reflection[static_cast<std::size_t>(t)] = 15;  // M/12 < 15 < M/6
  return c;
}

// Gathers counters the way the session does: full frames until the planner has enough.
void gather(Planner& p, NodeId object, const IndirectionCounts& counts, Vec2 centre) {
  ASSERT_EQ(p.countTarget(), object);
  int frames = 0;
  while (p.countThisFrame(AccumMode::Refinement)) {
    ++frames;
    if (p.frameCounted()) break;
  }
  ASSERT_GT(frames, 0) << "the planner asked for counters";
  p.setCounts(object, counts, centre);
  ASSERT_TRUE(p.haveCounts());
}

std::int64_t pixelsOf(const TileGrid& g, const std::vector<int>& tiles) {
  std::int64_t px = 0;
  for (int t : tiles) px += g.rect(t).pixels();
  return px;
}

bool contains(const std::vector<int>& v, int t) { return std::find(v.begin(), v.end(), t) != v.end(); }

// Issue 60: a material edit was planned as a spiral around the centre of all its objects, its
// counters unused. Its objects' direct, reflected and shadow tiles now come first, as for a move.
TEST(Planner, AMaterialEditServesEveryObjectOfTheMaterialByItsClasses) {
  TileGrid g(320, 180, 16);  // 20 x 12 tiles
  constexpr NodeId kWood = 20;
  Planner p(g, methodOf(MethodKind::Indirection, 0));
  p.select(kTable);
  // The table at the left, a chair of the same wood at the right; the chair shadows the floor.
  const std::vector<int> table = {g.index(2, 8), g.index(3, 8)}, chair = {g.index(17, 3)};
  const std::vector<int> shadow = {g.index(17, 5)}, reflection = {g.index(10, 1)};
  IndirectionCounts group = countsOf(g, {table[0], table[1], chair[0]}, shadow, reflection);
  ASSERT_EQ(p.countTarget(), kTable);
  while (p.countThisFrame(AccumMode::Refinement) && !p.frameCounted()) {
  }
  p.setCounts(kTable, countsOf(g, table, {}, {}), Vec2{56, 136}, kWood, group);
  ASSERT_TRUE(p.haveCounts());

  // The session's facts of a material edit: one per object of the material on screen.
  auto each = [&](Vec2 centre) {
    EditFacts f;
    f.material = kWood;
    f.pointOfChange = centre;
    f.screen = {{static_cast<int>(centre.x) - 8, static_cast<int>(centre.y) - 8, 16, 16}};
    return f;
  };
  Plan plan = p.planBatch({each({56, 136}), each({280, 56})});
  ASSERT_EQ(plan.kind, PlanKind::Pass);
  const std::vector<int> first(plan.order.begin(), plan.order.begin() + plan.leading);
  for (int t : table) EXPECT_TRUE(contains(first, t)) << "the table's tiles are prioritized";
  for (int t : chair) EXPECT_TRUE(contains(first, t)) << "so are the chair's";
  for (int t : shadow) EXPECT_TRUE(contains(first, t)) << "and the shadow of the material's objects";
  for (int t : reflection) EXPECT_TRUE(contains(first, t)) << "and their reflections";
  EXPECT_LT(plan.leading, g.count() / 4) << "the rest of the image waits";
  ASSERT_FALSE(p.classes().empty()) << "the classes stay shown during the pass";
  EXPECT_EQ(p.classes()[static_cast<std::size_t>(shadow[0])], TileClass::High);
  // A material the counters do not describe: a spiral, as before.
  EditFacts other = each({56, 136});
  other.material = kWood + 1;
  Plan spiral = p.planBatch({other});
  EXPECT_EQ(spiral.order, spiralOrder(g, g.tileAt({56, 136})));
}

TEST(Planner, SpiralStartsAtThePointOfChangeAndRestartsEveryTile) {
  TileGrid g(320, 180, 16);
  Planner p(g, methodOf(MethodKind::Spiral, 32));
  Plan plan = p.planBatch({moveFacts(kCup, {100, 50}, {104, 50})});
  ASSERT_EQ(plan.kind, PlanKind::Pass);
  EXPECT_EQ(plan.order, spiralOrder(g, g.tileAt({104, 50})));
  EXPECT_EQ(plan.prioritized, g.count());
  EXPECT_EQ(plan.leading, 0) << "nothing ranks above the spiral";
  EXPECT_EQ(plan.quality, 32);
  EXPECT_FALSE(plan.smooth);
}

TEST(Planner, GlobalMethodAndCameraEditsResetEverything) {
  TileGrid g(320, 180, 16);
  Planner global(g, methodOf(MethodKind::Global));
  EXPECT_EQ(global.planBatch({moveFacts(kCup, {100, 50}, {104, 50})}).kind, PlanKind::GlobalUpdate);
  Planner spiral(g, methodOf(MethodKind::Spiral));
  EditFacts camera;
  camera.global = true;
  EXPECT_EQ(spiral.planBatch({moveFacts(kCup, {100, 50}, {104, 50}), camera}).kind, PlanKind::GlobalUpdate)
      << "a camera move anywhere in the batch";
}

TEST(Planner, SmoothPrefixIsTheTouchedTilesInSpiralOrder) {
  TileGrid g(320, 180, 16);
  Planner p(g, methodOf(MethodKind::Spiral, 16, true));
  Plan plan = p.planBatch({moveFacts(kCup, {100, 50}, {140, 50}, 20)});
  ASSERT_EQ(plan.kind, PlanKind::Pass);
  EXPECT_TRUE(plan.smooth);
  EXPECT_EQ(plan.staleCap, 4);
  // 20 px squares around x = 100 and 140 at y = 50: columns 5..6 and 8..9, rows 2..3.
  std::set<int> touched;
  for (int col : {5, 6, 8, 9})
    for (int row : {2, 3}) touched.insert(g.index(col, row));
  ASSERT_EQ(plan.prioritized, static_cast<int>(touched.size()));
  EXPECT_EQ(plan.leading, plan.prioritized);
  EXPECT_EQ(std::set<int>(plan.order.begin(), plan.order.begin() + plan.prioritized), touched);
  EXPECT_EQ(plan.order.size(), static_cast<std::size_t>(g.count()));
}

// A preview re-renders what the edit touched, not the pass: without the smooth transition too,
// where the pass itself ranks no tile first and restarts every one when it reaches it.
TEST(Planner, APreviewCoversTheTouchedTilesInServingOrder) {
  TileGrid g(320, 180, 16);
  for (bool smooth : {false, true}) {
    Planner p(g, methodOf(MethodKind::Spiral, 16, smooth));
    Plan plan = p.planBatch({moveFacts(kCup, {100, 50}, {140, 50}, 20)});
    ASSERT_EQ(plan.kind, PlanKind::Pass);
    std::set<int> touched;
    for (int col : {5, 6, 8, 9})
      for (int row : {2, 3}) touched.insert(g.index(col, row));
    EXPECT_EQ(std::set<int>(plan.preview.begin(), plan.preview.end()), touched) << "smooth " << smooth;
    EXPECT_EQ(plan.preview.size(), touched.size());
    std::vector<int> inOrder;
    for (int t : plan.order)
      if (touched.count(t)) inOrder.push_back(t);
    EXPECT_EQ(plan.preview, inOrder) << "in the pass's order";
  }
  // An edit with nothing on screen (a light) may change any tile: the preview covers what the
  // pass restarts, every tile without the smooth transition.
  Planner p(g, methodOf(MethodKind::Spiral, 16));
  EditFacts light;
  light.pointOfChange = {160, 90};
  Plan plan = p.planBatch({light});
  ASSERT_EQ(plan.kind, PlanKind::Pass);
  EXPECT_EQ(plan.preview, plan.order);
}

TEST(Planner, FocusInterleavesThePointOfChangeWithFocusPoints) {
  TileGrid g(320, 180, 16);
  MethodSettings m = methodOf(MethodKind::Focus);
  m.focus = {{{300, 170}, false}};
  Planner p(g, m);
  Plan plan = p.planBatch({moveFacts(kCup, {20, 20}, {24, 20})});
  ASSERT_GE(plan.order.size(), 2u);
  EXPECT_EQ(plan.order[0], g.tileAt({24, 20}));
  EXPECT_EQ(plan.order[1], g.tileAt({300, 170}));
  EXPECT_EQ(plan.order, interleavedSpirals(g, {g.tileAt({24, 20}), g.tileAt({300, 170})}));
}

TEST(Planner, OneBatchPrioritizesEveryPointOfChange) {
  // Defect: each edit of a batch restarted the pass, so only the last point of change led.
  TileGrid g(320, 180, 16);
  Planner p(g, methodOf(MethodKind::Spiral));
  EditFacts light;
  light.pointOfChange = {300, 160};
  Plan plan = p.planBatch({moveFacts(kCup, {20, 20}, {24, 20}), light});
  ASSERT_GE(plan.order.size(), 2u);
  EXPECT_EQ(std::set<int>(plan.order.begin(), plan.order.begin() + 2), (std::set<int>{g.tileAt({24, 20}), g.tileAt({300, 160})}));
  EXPECT_EQ(p.pointsOfChange().size(), 2u);
}

TEST(Planner, IndirectionOrdersClassesAndFitsAutomaticQToHighAndTouchedTiles) {
  TileGrid g(320, 180, 16);
  Planner p(g, methodOf(MethodKind::Indirection, 0));
  p.select(kCup);
  std::vector<int> direct = {g.index(5, 3), g.index(6, 3)};
  std::vector<int> shadow = {g.index(5, 5)};
  std::vector<int> low = {g.index(15, 8)};
  gather(p, kCup, countsOf(g, direct, shadow, {}, low), {88, 56});
  // A material edit: nothing moves; the touched rectangle is the cup's.
  EditFacts edit;
  edit.object = kCup;
  edit.pointOfChange = {88, 56};
  edit.centreBefore = edit.centreAfter = Vec2{88, 56};
  edit.screen = {{80, 48, 30, 8}, {80, 48, 30, 8}};
  Plan plan = p.planBatch({edit});
  ASSERT_EQ(plan.kind, PlanKind::Pass);
  std::vector<int> prior(plan.order.begin(), plan.order.begin() + plan.leading);
  for (int t : direct) EXPECT_TRUE(contains(prior, t));
  EXPECT_TRUE(contains(prior, shadow[0]));
  EXPECT_TRUE(contains(prior, low[0])) << "low tiles are prioritized too";
  EXPECT_EQ(prior.back(), low[0]) << "high, then middle, then low";
  std::vector<int> high;
  for (int t : prior)
    if (p.classes()[static_cast<std::size_t>(t)] == TileClass::High) high.push_back(t);
  EXPECT_LE(plan.quality * pixelsOf(g, high), g.pixels()) << "all high and touched tiles fit one frame";
  EXPECT_GT((plan.quality + 1) * pixelsOf(g, high), g.pixels()) << "at the largest Q that does";
}

// A material edit of an object whose screen rectangle holds far more than it shows (a backdrop, a
// plant, a cupboard behind a table): every tile of the rectangle was high, so automatic Q fell to
// what the whole rectangle allows (1 when it fills the image). Where the counters saw it is what
// such an edit changes directly; a move still takes its rectangles, as does an object the
// counters did not see.
TEST(Planner, AnEditThatLeavesTheObjectInPlacePrioritizesWhereItIsSeenNotItsRectangle) {
  TileGrid g(320, 180, 16);  // 20 x 12 tiles
  const std::vector<int> seen = {g.index(4, 4), g.index(5, 4), g.index(15, 9)};
  const std::vector<int> shadow = {g.index(4, 6)};
  auto planned = [&](const IndirectionCounts& counts, bool move) {
    Planner p(g, methodOf(MethodKind::Indirection, 0));
    p.select(kCup);
    gather(p, kCup, counts, {160, 90});
    EditFacts edit;
    edit.object = kCup;
    edit.pointOfChange = {160, 90};
    edit.centreBefore = Vec2{160, 90};
    edit.centreAfter = move ? Vec2{176, 90} : Vec2{160, 90};
    edit.moved = move;
    edit.screen = {{0, 0, 320, 180}};  // its rectangle fills the image
    Plan plan = p.planBatch({edit});
    std::vector<int> high;
    for (int t = 0; t < g.count(); ++t)
      if (p.classes()[static_cast<std::size_t>(t)] == TileClass::High) high.push_back(t);
    return std::pair{plan, high};
  };

  const auto [material, high] = planned(countsOf(g, seen, shadow, {}), false);
  ASSERT_EQ(material.kind, PlanKind::Pass);
  // Where it is seen, and the tiles around (a silhouette's sliver the counters' samples missed).
  std::set<int> around;
  for (int t : seen)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) around.insert(g.index(t % g.cols() + dx, t / g.cols() + dy));
  std::set<int> expected = around;
  expected.insert(shadow[0]);
  EXPECT_EQ(std::set<int>(high.begin(), high.end()), expected)
      << "high: where it is seen and what it shadows, not every tile of its rectangle (" << high.size() << " high)";
  EXPECT_EQ(material.leading, static_cast<int>(expected.size()));
  EXPECT_GE(material.quality, g.pixels() / pixelsOf(g, std::vector<int>(expected.begin(), expected.end())))
      << "automatic Q fits the tiles it is seen in";
  EXPECT_EQ(std::set<int>(material.preview.begin(), material.preview.end()), around) << "the preview re-renders where it is seen";

  const auto [move, movedHigh] = planned(countsOf(g, seen, shadow, {}), true);
  EXPECT_EQ(static_cast<int>(movedHigh.size()), g.count()) << "a move takes its rectangles: where it was and is";
  EXPECT_EQ(move.quality, 1);

  const auto [shown, shownHigh] = planned(countsOf(g, {}, {}, {}), false);
  EXPECT_EQ(static_cast<int>(shownHigh.size()), g.count()) << "counters that did not see it: its rectangle";
  EXPECT_EQ(shown.quality, 1);
}

TEST(Planner, IndirectionDragMovesDirectTilesKeepsShadowsAndEveryClass) {
  // Defects: shadow tiles moved with the object's screen motion; middle and low tiles fell out of
  // the prioritized prefix; automatic Q counted the high tiles only, so the touched tiles did not
  // fit a frame (ghosting).
  TileGrid g(320, 180, 16);
  Planner p(g, methodOf(MethodKind::Indirection, 0));
  p.select(kCup);
  std::vector<int> direct = {g.index(5, 3), g.index(6, 3)};
  int shadowTile = g.index(5, 8), middleTile = g.index(12, 3), lowTile = g.index(15, 8);
  IndirectionCounts c = countsOf(g, direct, {shadowTile}, {}, {lowTile});
  c.reflection[static_cast<std::size_t>(middleTile)] = 30;  // M/6 < 30 < M/3
  gather(p, kCup, c, {96, 56});
  Vec2 at{96, 56};
  Plan plan;
  for (int frame = 0; frame < 40; ++frame) {  // 2 px a frame to the right: 80 px, five tiles
    Vec2 next{at.x + 2, at.y};
    plan = p.planBatch({moveFacts(kCup, at, next, 24)});
    at = next;
    ASSERT_EQ(plan.kind, PlanKind::Pass);
  }
  std::vector<int> prior(plan.order.begin(), plan.order.begin() + plan.leading);
  EXPECT_TRUE(contains(prior, g.index(10, 3)) && contains(prior, g.index(11, 3))) << "the direct tiles moved 5 columns";
  EXPECT_FALSE(contains(prior, g.index(5, 3))) << "replaced, not added";
  EXPECT_TRUE(contains(prior, shadowTile)) << "the shadow on the floor stays where it is";
  EXPECT_FALSE(contains(prior, g.index(10, 8))) << "and is not shifted with the object";
  EXPECT_TRUE(contains(prior, middleTile));
  EXPECT_TRUE(contains(prior, lowTile));
  // The tiles the last move touched (24 px around x = 174 and 176) are high and fit one frame.
  std::vector<int> high;
  for (int t : prior)
    if (p.classes()[static_cast<std::size_t>(t)] == TileClass::High) high.push_back(t);
  for (int t : {g.tileAt({163, 45}), g.tileAt({187, 67})}) EXPECT_TRUE(contains(high, t)) << t;
  EXPECT_LE(plan.quality * pixelsOf(g, high), g.pixels());
}

TEST(Planner, IndirectionPlusFocusRanksClassesThenFocusSpirals) {
  TileGrid g(320, 180, 16);
  MethodSettings m = methodOf(MethodKind::IndirectionFocus, 0);
  m.focus = {{{300, 170}, false}};
  Planner p(g, m);
  p.select(kCup);
  std::vector<int> direct = {g.index(2, 2)};
  gather(p, kCup, countsOf(g, direct, {}, {}), {40, 40});
  EditFacts edit;
  edit.object = kCup;
  edit.pointOfChange = {40, 40};
  edit.centreBefore = edit.centreAfter = Vec2{40, 40};
  Plan plan = p.planBatch({edit});
  ASSERT_EQ(plan.leading, 1);
  EXPECT_EQ(plan.order[0], direct[0]);
  // After the classes, the point of change's and the focus point's spirals take turns.
  EXPECT_EQ(plan.order[1], g.tileAt({300, 170}));
  std::vector<int> rest;
  for (int t : interleavedSpirals(g, {g.tileAt({40, 40}), g.tileAt({300, 170})}))
    if (t != direct[0]) rest.push_back(t);
  EXPECT_EQ(std::vector<int>(plan.order.begin() + 1, plan.order.end()), rest);
}

TEST(Planner, CountersDescribeTheEditsTargetNotTheSelection) {
  // Defect: a light edit while the cup was selected prioritized the cup's tiles.
  TileGrid g(320, 180, 16);
  Planner p(g, methodOf(MethodKind::Indirection, 0));
  p.select(kCup);
  gather(p, kCup, countsOf(g, {g.index(2, 2)}, {}, {}), {40, 40});
  EditFacts light;  // no object: a light or the environment
  light.pointOfChange = {300, 160};
  Plan plan = p.planBatch({light});
  EXPECT_EQ(plan.order, spiralOrder(g, g.tileAt({300, 160}))) << "the cup's tiles are not the light's";
  EXPECT_TRUE(p.classes().empty());
  EXPECT_EQ(p.countTarget(), kCup) << "a light has no counters; the cup's stay for its next edit";
  // An edit of the table: its own counters are gathered once the edit settles.
  Plan table = p.planBatch({moveFacts(kTable, {200, 100}, {204, 100})});
  EXPECT_EQ(table.order.front(), g.tileAt({204, 100}));
  EXPECT_EQ(p.countTarget(), kTable);
  EXPECT_FALSE(p.countThisFrame(AccumMode::Refinement)) << "not while the pass runs";
  p.planQuiet(false);
  EXPECT_TRUE(p.countThisFrame(AccumMode::Refinement)) << "once it settled";
  EXPECT_FALSE(p.countThisFrame(AccumMode::Incremental)) << "over full frames only";
}

TEST(Planner, FollowingFocusPointsMoveWithTheObjectNotThePointOfChange) {
  // Defect: after a resize (or camera move, or global update) the previous point of change was
  // the image centre, so the first edit moved following points by (point of change - centre).
  TileGrid g(320, 180, 16);
  MethodSettings m = methodOf(MethodKind::Focus);
  m.focus = {{{50, 50}, true}, {{300, 20}, false}};
  Planner p(g, m);
  p.setGrid(TileGrid(320, 180, 16));  // a resize
  EditFacts camera;
  camera.global = true;
  p.planBatch({camera});
  p.planBatch({moveFacts(kCup, {250, 140}, {260, 135})});
  ASSERT_EQ(p.focus().size(), 2u);
  EXPECT_EQ(p.focus()[0].pixel, (Vec2{60, 45})) << "moved by the cup's own motion (+10, -5)";
  EXPECT_EQ(p.focus()[1].pixel, (Vec2{300, 20})) << "a static point stays";
  // A material edit moves nothing.
  EditFacts material = moveFacts(kCup, {260, 135}, {260, 135});
  material.moved = false;
  p.planBatch({material});
  EXPECT_EQ(p.focus()[0].pixel, (Vec2{60, 45}));
}

TEST(Planner, ChangeTracesTheSpiralDuringADragAndProbesOnceItStops) {
  // Defect: every edit re-armed the probe, so each frame of a drag was a probe and nothing
  // accumulated.
  TileGrid g(96, 54, 16);
  Planner p(g, methodOf(MethodKind::Change, 16));
  Vec2 at{40, 20};
  for (int frame = 0; frame < 100; ++frame) {
    Plan plan = p.planBatch({moveFacts(kCup, at, {at.x, at.y + 0.2f})});
    at.y += 0.2f;
    ASSERT_EQ(plan.kind, PlanKind::Pass) << "frame " << frame;
    EXPECT_EQ(plan.order.front(), g.tileAt(at));
  }
  EXPECT_EQ(p.planQuiet(true).kind, PlanKind::Probe) << "the first frame without an edit";
  EXPECT_EQ(p.planQuiet(true).kind, PlanKind::None) << "once";
}

TEST(Planner, ChangeOrdersByDifferenceAndHonoursTheSmoothTransition) {
  // Defect: the change policy passed every tile as prioritized, ignoring --smooth.
  TileGrid g(96, 54, 16);  // 6 x 4 tiles
  for (bool smooth : {false, true}) {
    SCOPED_TRACE(smooth ? "smooth" : "not smooth");
    Planner p(g, methodOf(MethodKind::Change, 16, smooth));
    p.planBatch({moveFacts(kCup, {8, 8}, {8, 8}, 4)});  // touches tile 0 only
    ASSERT_EQ(p.planQuiet(true).kind, PlanKind::Probe);
    std::vector<float> diff(static_cast<std::size_t>(g.count()), 0.05f);  // the probe's noise
    diff[10] = 0.9f;
    diff[17] = 0.5f;
    Plan plan = p.planFromProbe(diff);
    ASSERT_EQ(plan.kind, PlanKind::Pass);
    EXPECT_EQ(plan.order[0], 10);
    EXPECT_EQ(plan.order[1], 17);
    EXPECT_EQ(plan.smooth, smooth);
    EXPECT_EQ(plan.leading, 3) << "the two changed tiles and the touched one";
    EXPECT_EQ(plan.order[2], 0);
    EXPECT_EQ(plan.prioritized, smooth ? 3 : g.count()) << "restart: the leading tiles with smooth, else all";
  }
}

TEST(Planner, ObjectFillingTheScreenGivesQOfOneAndOffScreenTheDefault) {
  TileGrid g(96, 54, 16);
  Planner p(g, methodOf(MethodKind::Indirection, 0));
  p.select(kCup);
  std::vector<int> all;
  for (int t = 0; t < g.count(); ++t) all.push_back(t);
  gather(p, kCup, countsOf(g, all, {}, {}), {48, 27});
  EditFacts edit;
  edit.object = kCup;
  edit.pointOfChange = {48, 27};
  edit.screen = {{0, 0, 96, 54}};
  EXPECT_EQ(p.planBatch({edit}).quality, 1);

  Planner off(g, methodOf(MethodKind::Indirection, 0));
  off.select(kCup);
  gather(off, kCup, countsOf(g, {}, {}, {}), {500, 500});
  EditFacts gone;
  gone.object = kCup;
  gone.pointOfChange = {500, 500};
  EXPECT_EQ(off.planBatch({gone}).quality, Planner::kDefaultAutomaticQuality);
}

}  // namespace
}  // namespace retile
