// The method as an artist and a teacher meet it in the editor (issue 60): one test per defect a
// new user found, each failing on the editor before its fix.
#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDockWidget>
#include <QLabel>
#include <QLineEdit>
#include <QMenuBar>
#include <QScrollBar>
#include <QSettings>
#include <QSpinBox>
#include <QStatusBar>
#include <QTest>
#include <QTreeWidget>

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

#include "editor_support.h"
#include "fields.h"
#include "frame_view.h"
#include "live_chart.h"
#include "main_window.h"
#include "node_graph.h"
#include "retile/io.h"
#include "test_support.h"

namespace retile::ui {
namespace {

using test::makeWindow;
using test::meanSamples;
using test::objectNamed;
using test::waitForFrame;

// Types `text` into a number field as a user does: a click, the keys, then `finish`.
void typeInto(ScrubField* field, const QString& text, Qt::Key finish) {
  QTest::mouseClick(field, Qt::LeftButton, Qt::NoModifier, QPoint(6, field->height() / 2));
  QWidget* focus = QApplication::focusWidget();
  QTest::keyClick(focus, Qt::Key_A, Qt::ControlModifier);
  QTest::keyClicks(focus, text);
  QTest::keyClick(QApplication::focusWidget(), finish);
}

std::unique_ptr<MainWindow> activeWindow() {
  auto w = makeWindow();
  QApplication::setActiveWindow(w.get());
  EXPECT_TRUE(QTest::qWaitForWindowActive(w.get()));
  return w;
}

// 1. A material edit under the indirection policy was a plain spiral around the centre of all the
// material's objects, and the classes vanished during the pass.
TEST(EditorMethod, AMaterialEditServesTheMaterialsObjectsByTheirClasses) {
  auto w = makeWindow();  // 96 x 54, tiles of 8 below
  // A second object of the sphere's lacquer, at the other side of the picture.
  const NodeId sphere = objectNamed(w->scene(), "Glossy Sphere");
  const Object& s = *w->scene().object(sphere);
  Object twin = s;
  twin.id = w->scene().peekNextId();
  twin.name = "Twin";
  twin.transform = Mat4::translate({2.6f, 0.0f, -0.4f}) * s.transform;
  w->edit(RemoveNode{twin.id}, AddObject{twin}, "add twin");
  MethodSettings m;
  m.kind = MethodKind::Indirection;
  m.tileSize = 8;
  // A fixed Q long enough for the pass to span many frames: a slow GUI thread (CI, under ASan)
  // shows only the newest frame, and a short pass could be over between two it shows.
  m.quality = 64;
  m.indirectionFrames = 2;
  w->engine()->submit(MethodCommand{m});
  w->select(sphere);
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) {
    return f.method == "indirection" && !f.tileClass.empty() && f.mode == "refinement";
  })) << "the counters are gathered for the selection";
  // Where each object is seen, from the picture's object ids.
  const FrameRecord seen = *w->viewport()->frame();
  std::vector<char> ofSphere(seen.tileClass.size(), 0), ofTwin(seen.tileClass.size(), 0);
  for (int y = 0; y < seen.height; ++y)
    for (int x = 0; x < seen.width; ++x) {
      const auto id = seen.image->objectId[static_cast<std::size_t>(y * seen.width + x)];
      const auto t = static_cast<std::size_t>((y / seen.tileSize) * seen.cols + x / seen.tileSize);
      if (id == sphere) ofSphere[t] = 1;
      if (id == twin.id) ofTwin[t] = 1;
    }
  ASSERT_TRUE(std::count(ofTwin.begin(), ofTwin.end(), 1) > 0) << "the twin is in view";

  const Material before = *w->scene().material(s.material);
  Material rougher = before;
  rougher.roughness = 0.4f;
  w->edit(SetMaterial{before}, SetMaterial{rougher}, "roughness");
  ASSERT_TRUE(waitForFrame(
      *w, [&](const FrameRecord& f) { return f.documentVersion == w->documentVersion() && f.mode == "incremental" && f.queueLength > 0; }));
  const FrameRecord pass = *w->viewport()->frame();
  EXPECT_FALSE(pass.tileClass.empty()) << "the classes stay shown during the pass";
  // The tiles served first: every tile of both objects comes before any tile of neither.
  auto rank = [&](std::size_t t) { return pass.tilePriority[t] < 0 ? 1e9f : 1.0f - pass.tilePriority[t]; };
  float lastObject = 0, firstOther = 1e9f;
  for (std::size_t t = 0; t < pass.tilePriority.size(); ++t) {
    if (ofSphere[t] || ofTwin[t]) lastObject = std::max(lastObject, rank(t));
    else if (pass.tileClass[t] == 3) firstOther = std::min(firstOther, rank(t));
  }
  EXPECT_LT(lastObject, firstOther) << "both objects' tiles lead the queue";
}

// 2. The denoised region never grew at the defaults: its 200 px threshold was wider than the
// default render. It is now a share of the image.
TEST(EditorMethod, AtTheDefaultsTheDenoisedRegionGrowsNestedAndLabelled) {
  auto w = std::make_unique<MainWindow>(makeDefaultScene(), std::filesystem::path());  // the defaults
  w->resize(1280, 800);
  w->show();
  auto* denoise = w->findChild<QCheckBox*>("denoise");
  ASSERT_TRUE(denoise);
  EXPECT_TRUE(denoise->isChecked()) << "the editor denoises by default";
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 4 && f.width > 100; }));
  const NodeId cup = objectNamed(w->scene(), "Cup");
  const Object o = *w->scene().object(cup);
  Object moved = o;
  moved.transform = Mat4::translate({0, 0.05f, 0}) * o.transform;
  w->edit(SetObject{o}, SetObject{moved}, "move");
  std::size_t most = 0;
  std::vector<DenoisedRegion> stack;
  ASSERT_TRUE(QTest::qWaitFor(
      [&] {
        auto f = w->viewport()->frame();
        if (f && f->mode == "incremental" && f->denoised.size() > most) {
          most = f->denoised.size();
          stack = f->denoised;
        }
        return most >= 3;
      },
      120000))
      << "the region grew " << most << " times";
  for (std::size_t i = 1; i < stack.size(); ++i) {
    const RegionRect &in = stack[i - 1].rect, &out = stack[i].rect;
    EXPECT_TRUE(in.x >= out.x && in.y >= out.y && in.x + in.width <= out.x + out.width && in.y + in.height <= out.y + out.height)
        << "nested: region " << i;
    EXPECT_GE(stack[i - 1].age, stack[i].age) << "each labelled with its age, the outer newer";
  }
}

// A teacher follows a pass frame by frame: Render > Step one frame (.) pauses and shows one
// frame more each time, the tiles it served among them.
TEST(EditorMethod, StepShowsAPassOneFrameAtATime) {
  auto w = makeWindow();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 3; }));
  auto* step = w->findChild<QAction*>("stepAction");
  ASSERT_TRUE(step);
  const NodeId cup = objectNamed(w->scene(), "Cup");
  const Object o = *w->scene().object(cup);
  Object moved = o;
  moved.transform = Mat4::translate({0, 0.05f, 0}) * o.transform;
  step->trigger();  // paused
  QTest::qWait(500);
  w->edit(SetObject{o}, SetObject{moved}, "move");
  const std::uint64_t before = w->viewport()->frame()->frame;
  QTest::qWait(400);  // past the preview's linger: the steps are the pass's full frames
  EXPECT_EQ(w->viewport()->frame()->frame, before) << "the edit alone renders nothing while paused";
  for (std::uint64_t k = 1; k <= 3; ++k) {
    step->trigger();
    ASSERT_TRUE(waitForFrame(
        *w, [&](const FrameRecord& f) { return f.frame == before + k; }, 20000))
        << "step " << k;
    QTest::qWait(300);
    const auto f = w->viewport()->frame();
    EXPECT_EQ(f->frame, before + k) << "one frame a step";
    EXPECT_EQ(f->mode, "incremental");
    EXPECT_FALSE(f->servedTiles.empty());
  }
  // The paused banner sits in the letterbox above the image, hiding no tile's numbers: its
  // amber text is there, and none lies inside the image below its border.
  FrameView* v = w->viewport();
  const QImage pic = v->composed();
  const QRect r = v->imageRect().toRect();
  auto amber = [&](int top, int bottom) {
    int n = 0;
    for (int y = std::max(0, top); y < std::min(pic.height(), bottom); ++y)
      for (int x = r.left() + 8; x < r.right() - 8; ++x) {
        const QColor c = pic.pixelColor(x, y);
        n += c.red() > 200 && c.green() > 140 && c.green() < 220 && c.blue() < 90;
      }
    return n;
  };
  ASSERT_GT(r.top(), 40) << "letterboxed";
  EXPECT_GT(amber(r.top() - 30, r.top() - 4), 20) << "the banner above the image";
  EXPECT_EQ(amber(r.top() + 8, r.top() + 30), 0) << "nothing of it over the image";
}

// 3. The legend was cut off ("...") and keyed every class in one orange; letterboxed, it covered
// a third of the image.
TEST(EditorMethod, TheLegendNamesEveryMarkInItsOwnColourAndCoversNothing) {
  auto w = makeWindow();
  w->resize(1280, 800);  // the default window
  QTest::qWait(100);
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  FrameView* v = w->viewport();
  auto f = std::make_shared<FrameRecord>(*v->frame());
  f->mode = "incremental";
  f->method = "indirection+focus+smooth+denoise";
  f->tileClass.assign(static_cast<std::size_t>(f->cols * f->rows), 3);
  for (std::uint8_t c = 0; c < 3; ++c) f->tileClass[c] = c;
  f->focus = {Vec2{10, 10}};
  f->denoised = {{RegionRect{0, 0, 16, 16}, 3}};
  f->queueLength = 10;
  f->queueServed = 2;
  OverlaySettings o;
  o.classes = true;
  v->setOverlays(o);
  v->showFrame(f);
  std::vector<QColor> classes;
  bool focusKeyed = false, denoiseKeyed = false;
  for (const auto& item : v->legendItems()) {
    if (item.key == FrameView::LegendItem::Key::Hatch) classes.push_back(item.color);
    focusKeyed = focusKeyed || (item.key == FrameView::LegendItem::Key::Circle && item.color == FrameView::kFocusColor);
    denoiseKeyed = denoiseKeyed || item.key == FrameView::LegendItem::Key::Dashed;
  }
  ASSERT_EQ(classes.size(), 3u) << "high, middle and low each keyed";
  EXPECT_EQ(classes[0], FrameView::kClassColor[0]);
  EXPECT_EQ(classes[1], FrameView::kClassColor[1]);
  EXPECT_EQ(classes[2], FrameView::kClassColor[2]);
  EXPECT_TRUE(focusKeyed) << "the focus point keyed in the colour it is drawn in";
  EXPECT_TRUE(denoiseKeyed);
  auto restKeyed = [&] {
    const auto items = v->legendItems();
    return std::any_of(items.begin(), items.end(), [](const auto& i) { return i.text.startsWith("unhatched"); });
  };
  EXPECT_TRUE(restKeyed()) << "the tiles of no class, served last, are keyed too";
  auto allClassed = std::make_shared<FrameRecord>(*f);
  for (std::size_t t = 0; t < allClassed->tileClass.size(); ++t) allClassed->tileClass[t] = static_cast<std::uint8_t>(t % 3);
  v->showFrame(allClassed);
  EXPECT_FALSE(restKeyed()) << "and only when there are such tiles";
  v->showFrame(f);
  // The focus point as drawn has the colour its key has.
  const QImage pic = v->composed();
  const QPointF at = v->widgetPoint(QPointF(10, 10)) + QPointF(9, 0);  // on its ring
  bool ringFound = false;
  for (int dx = -2; dx <= 2 && !ringFound; ++dx) ringFound = pic.pixelColor(at.toPoint() + QPoint(dx, 0)) == FrameView::kFocusColor;
  EXPECT_TRUE(ringFound);
  // Nothing is cut off, and the legend lies beside the image, not over it.
  const QRectF strip = v->legendRect();
  ASSERT_FALSE(strip.isEmpty());
  EXPECT_FALSE(strip.intersects(v->imageRect()));
  const auto items = v->legendItems();
  const auto layout = v->layOutLegend(items, strip.width());
  EXPECT_LE(layout.height, strip.height()) << "the strip holds every item";
  QFontMetricsF fm(QFont(v->font().family(), 9));
  for (std::size_t i = 0; i < items.size(); ++i) {
    const double key = items[i].key == FrameView::LegendItem::Key::None ? 0 : FrameView::kLegendKey + 5;
    EXPECT_GE(layout.items[i].width() + 0.5, std::min(key + fm.horizontalAdvance(items[i].text), strip.width() - 12))
        << items[i].text.toStdString() << " is given its width";
    EXPECT_LE(layout.items[i].right(), strip.width());
  }
}

// 4. Switching the policy or the denoiser, or adding an unlinked texture, threw the samples away.
TEST(EditorMethod, SettingsThatChangeNoPixelKeepEverySample) {
  auto w = makeWindow();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.mode == "refinement" && f.frame >= 12; }));
  auto keeps = [&](const char* what, const std::function<void()>& change) {
    const double before = meanSamples(*w->viewport()->frame());
    change();
    const std::uint64_t after = w->viewport()->frame()->frame + 3;
    ASSERT_TRUE(waitForFrame(*w, [&](const FrameRecord& f) { return f.frame >= after; }));
    EXPECT_GE(meanSamples(*w->viewport()->frame()), before) << what << " kept the samples";
  };
  keeps("the policy", [&] { w->findChild<QComboBox*>("method")->setCurrentText("focus"); });
  keeps("the denoiser", [&] { w->findChild<QCheckBox*>("denoise")->toggle(); });
  keeps("a texture node", [&] { ASSERT_TRUE(w->graph()->createNode("Checker Texture", QPointF(0, 0))); });
  keeps("a material's name", [&] {
    const Material m = w->scene().materials.front();
    Material renamed = m;
    renamed.name = "Renamed";
    w->edit(SetMaterial{m}, SetMaterial{renamed}, "rename");
  });
  keeps("the tile size", [&] {
    for (QComboBox* c : w->findChildren<QComboBox*>())
      if (c->findText("32") >= 0 && c->count() == 3) c->setCurrentText("32");
  });
  // The threshold applies once typed, not at every key.
  auto* threshold = w->findChild<QSpinBox*>("denoiseThreshold");
  ASSERT_TRUE(threshold);
  EXPECT_FALSE(threshold->keyboardTracking());
}

// 5. At the defaults the picture was a quarter of the viewport's resolution, too soft to judge a
// material. It now renders coarse only while edits come, then refines at twice the resolution.
TEST(EditorMethod, EditsPreviewCoarseAndRestRefinesSharper) {
  auto w = std::make_unique<MainWindow>(makeDefaultScene(), std::filesystem::path());  // the defaults
  w->resize(1280, 800);
  w->show();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 3 && f.width > 100; }));
  const QRectF area = w->viewport()->imageArea();
  const FrameRecord first = *w->viewport()->frame();
  EXPECT_GE(first.width, static_cast<int>(area.width() / 2) - 2) << "half the viewport's width at rest";
  const NodeId cup = objectNamed(w->scene(), "Cup");
  Object o = *w->scene().object(cup);
  bool previewed = false;
  for (int i = 1; i <= 6; ++i) {  // a drag
    Object moved = o;
    moved.transform = Mat4::translate({0.01f * i, 0, 0}) * o.transform;
    w->edit(SetObject{*w->scene().object(cup)}, SetObject{moved}, "drag", 77);
    ASSERT_TRUE(QTest::qWaitFor([&] { return w->viewport()->frame()->documentVersion == w->documentVersion(); }, 20000));
    previewed = previewed || w->viewport()->frame()->block > 1;
  }
  EXPECT_TRUE(previewed) << "frames of a drag are previews";
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.block == 1 && f.mode == "incremental"; }))
      << "at rest the pass runs again at full resolution";
  // The heat map tints the tiles still to come, never one already re-rendered.
  const FrameRecord rest = *w->viewport()->frame();
  FrameView* v = w->viewport();
  for (int t = 0; t < rest.cols * rest.rows; ++t) {
    const auto i = static_cast<std::size_t>(t);
    if (rest.tilePriority[i] < 0) continue;
    const auto rank = static_cast<std::size_t>(std::lround((1.0f - rest.tilePriority[i]) * static_cast<float>(rest.queueLength - 1)));
    if (rank < rest.queueServed) {
      EXPECT_FALSE(v->heatMapOn(t)) << "tile " << t << " was re-rendered";
    }
  }
}

// 6. Esc in a number field paused the render and kept the typed value.
TEST(EditorMethod, EscInANumberFieldCancelsTheTyping) {
  auto w = activeWindow();
  w->select(objectNamed(w->scene(), "Glossy Sphere"));
  auto* rough = w->findChild<ScrubField*>("roughness");
  ASSERT_TRUE(rough);
  const double before = rough->value();
  const int steps = w->undoStack()->index();
  typeInto(rough, "0.7", Qt::Key_Escape);
  EXPECT_DOUBLE_EQ(rough->value(), before) << "Esc takes the typed value back";
  EXPECT_FALSE(w->paused()) << "the render was not paused";
  w->outliner()->setFocus();  // a click elsewhere
  QTest::qWait(20);
  EXPECT_EQ(w->undoStack()->index(), steps) << "nothing was committed";
  EXPECT_DOUBLE_EQ(w->findChild<ScrubField*>("roughness")->value(), before);
  // Outside a field, Esc still pauses.
  QTest::keyClick(w.get(), Qt::Key_Escape);
  EXPECT_TRUE(w->paused());
}

// 7. An emission strength of 0 lost the light's colour.
TEST(EditorMethod, AZeroEmissionStrengthKeepsTheColour) {
  auto w = makeWindow();
  const NodeId light = objectNamed(w->scene(), "Area Light");
  const NodeId mat = w->scene().object(light)->material;
  Material orange = *w->scene().material(mat);
  orange.emission = Vec3{1.0f, 180.0f / 255, 60.0f / 255};
  orange.emissionStrength = 17.0f;
  w->edit(SetMaterial{*w->scene().material(mat)}, SetMaterial{orange}, "orange");
  w->select(light);
  for (double s : {17.0, 0.0, 17.0}) {
    auto* strength = w->findChild<ScrubField*>("emission");
    ASSERT_TRUE(strength);
    emit strength->edited(s, false);
    QTest::qWait(20);
  }
  ASSERT_TRUE(QTest::qWaitFor([&] { return w->findChild<ColorField*>("emissionColor") != nullptr; }, 2000));
  EXPECT_EQ(w->findChild<ColorField*>("emissionColor")->color().name(), QString("#ffb43c"));
  const Material& now = *w->scene().material(mat);
  EXPECT_NEAR(now.radiance().x, 17.0f, 1e-3f);
  EXPECT_NEAR(now.radiance().z / now.radiance().x, 60.0f / 255, 1e-3f);
}

// 8. 1e30 became 130, -1e30 -130; "abc" and "nan" were dropped without a word.
TEST(EditorMethod, ANumberFieldReadsWhatTheParserReadsAndSaysWhyItRefuses) {
  auto w = activeWindow();
  w->select(objectNamed(w->scene(), "Area Light"));
  auto field = [&] { return w->findChild<ScrubField*>("emission"); };
  ASSERT_TRUE(field());
  typeInto(field(), "1e30", Qt::Key_Return);
  EXPECT_DOUBLE_EQ(field()->value(), field()->maximum()) << "clamped to the largest";
  EXPECT_TRUE(field()->lastRefusal().contains("outside")) << field()->lastRefusal().toStdString();
  EXPECT_TRUE(w->statusBar()->currentMessage().contains("outside")) << "said where it is seen";
  typeInto(field(), "2.5e1", Qt::Key_Return);
  EXPECT_DOUBLE_EQ(field()->value(), 25.0);
  EXPECT_TRUE(field()->lastRefusal().isEmpty());
  typeInto(field(), "-1e30", Qt::Key_Return);
  EXPECT_DOUBLE_EQ(field()->value(), field()->minimum());
  for (const char* bad : {"abc", "nan"}) {
    typeInto(field(), "12", Qt::Key_Return);
    typeInto(field(), bad, Qt::Key_Return);
    EXPECT_DOUBLE_EQ(field()->value(), 12.0) << bad << " is refused";
    EXPECT_FALSE(field()->lastRefusal().isEmpty()) << bad << " gets a word";
  }
  EXPECT_TRUE(ScrubField::parse("0,5").has_value() || QLocale().decimalPoint() != ',');
}

// 9. Ctrl+Y did not redo.
TEST(EditorMethod, CtrlYRedoes) {
  auto w = activeWindow();
  const NodeId cup = objectNamed(w->scene(), "Cup");
  Object o = *w->scene().object(cup), moved = o;
  moved.transform = Mat4::translate({0.2f, 0, 0}) * o.transform;
  w->edit(SetObject{o}, SetObject{moved}, "move");
  w->undoStack()->undo();
  EXPECT_EQ(w->scene().object(cup)->transform, o.transform);
  QTest::keyClick(w.get(), Qt::Key_Y, Qt::ControlModifier);
  EXPECT_EQ(w->scene().object(cup)->transform, moved.transform) << "Ctrl+Y redid the move";
}

// 10. An environment edit re-expanded Objects, scrolled the outliner to the top and deselected.
TEST(EditorMethod, TheOutlinerKeepsItsStateAcrossEdits) {
  auto w = makeWindow();
  w->resize(1000, 420);
  QTreeWidget* tree = w->outliner();
  QTreeWidgetItem* objects = tree->topLevelItem(0);
  ASSERT_EQ(objects->text(0), "Objects");
  objects->setExpanded(false);
  QTreeWidgetItem* environment = nullptr;
  for (QTreeWidgetItemIterator it(tree); *it; ++it)
    if ((*it)->text(0) == "Environment") environment = *it;
  ASSERT_TRUE(environment);
  tree->setCurrentItem(environment, 0, QItemSelectionModel::ClearAndSelect);
  tree->verticalScrollBar()->setValue(tree->verticalScrollBar()->maximum());
  const int scrolled = tree->verticalScrollBar()->value();
  Environment e = w->scene().environment, brighter = e;
  brighter.intensity = e.intensity * 1.5f;
  w->edit(SetEnvironment{e}, SetEnvironment{brighter}, "brighter");
  QTest::qWait(50);  // the outliner rebuilds after the edit
  EXPECT_FALSE(tree->topLevelItem(0)->isExpanded()) << "Objects stays folded";
  ASSERT_EQ(tree->selectedItems().size(), 1);
  EXPECT_EQ(tree->selectedItems().front()->text(0), "Environment") << "the pick stays";
  EXPECT_EQ(tree->verticalScrollBar()->value(), scrolled) << "and so does the scroll";
}

// 11. Turning or scaling an object moved its Position; the active tool was not said.
TEST(EditorMethod, TurningAndScalingKeepThePositionAndTheToolIsShown) {
  auto w = activeWindow();
  const NodeId cup = objectNamed(w->scene(), "Cup");
  w->select(cup);
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  auto position = [&] {
    Vec3 p;
    for (int a = 0; a < 3; ++a)
      (a == 0 ? p.x : a == 1 ? p.y : p.z) = static_cast<float>(w->findChild<ScrubField*>(QString("position%1").arg(a))->value());
    return p;
  };
  const Vec3 before = position();
  QTest::keyClick(w.get(), Qt::Key_E);
  EXPECT_TRUE(w->findChild<QLabel*>("toolStatus")->text().contains("Rotate")) << "the status bar names the tool";
  FrameView* v = w->viewport();
  const QPoint on = v->widgetPoint(v->gizmo().origin).toPoint() + QPoint(int(FrameView::kRingRadiusX), 0);
  QTest::mousePress(v, Qt::LeftButton, Qt::NoModifier, on);
  for (int i = 1; i <= 6; ++i) QTest::mouseMove(v, on + QPoint(20 * i, 0));
  QTest::mouseRelease(v, Qt::LeftButton, Qt::NoModifier, on + QPoint(120, 0));
  ASSERT_GT(std::abs(decompose(w->scene().object(cup)->transform).rotationDegrees.y), 10.0f) << "the drag turned the cup";
  ASSERT_TRUE(QTest::qWaitFor([&] { return w->findChild<ScrubField*>("position0") != nullptr; }, 2000));
  EXPECT_LT(length(position() - before), 2e-3f) << "its position stays";
  // The Rotation field turns it about the same point.
  emit w->findChild<ScrubField*>("rotation1")->edited(45.0, false);
  ASSERT_TRUE(QTest::qWaitFor([&] { return w->findChild<ScrubField*>("position0") != nullptr; }, 2000));
  EXPECT_LT(length(objectPivot(w->scene(), *w->scene().object(cup)) - before), 2e-3f);
  QTest::keyClick(w.get(), Qt::Key_R);
  EXPECT_TRUE(w->findChild<QLabel*>("toolStatus")->text().contains("Scale"));
}

// 13. Opening another scene kept the inspector's region and readout and the chart's reference.
TEST(EditorMethod, OpeningASceneForgetsTheOldScenesInspectionAndReference) {
  auto w = makeWindow();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  FrameView* v = w->viewport();
  const QPoint a = v->widgetPoint(QPointF(10, 10)).toPoint(), b = v->widgetPoint(QPointF(40, 30)).toPoint();
  QTest::mousePress(v, Qt::LeftButton, Qt::ControlModifier, a);
  QTest::mouseMove(v, b);
  QTest::mouseRelease(v, Qt::LeftButton, Qt::ControlModifier, b);
  ASSERT_FALSE(v->inspectedRegion().isEmpty());
  w->chart()->renderReference(w->scene(), w->documentVersion(), 1);
  ASSERT_TRUE(QTest::qWaitFor([&] { return w->chart()->hasReference(); }, 60000));
  ASSERT_TRUE(w->findChild<QLabel*>("inspector")->text().contains("\nmean"));
  const auto file = retile::test::tempDir() / "other.retile";
  ASSERT_TRUE(saveNativeScene(makeDefaultScene(), file).ok());
  ASSERT_TRUE(w->openFile(file));
  EXPECT_TRUE(v->inspectedRegion().isEmpty());
  EXPECT_FALSE(w->findChild<QLabel*>("inspector")->text().contains("\nmean")) << "no readout of the old region";
  EXPECT_FALSE(w->chart()->hasReference());
}

// 14. A file opened from the command line missed Open Recent; load warnings reached only the Log
// tab; a closed panel could not be brought back.
TEST(EditorMethod, OpenedFilesAreRecentWarningsAreSeenAndPanelsComeBack) {
  auto w = makeWindow();
  Scene s = makeDefaultScene();
  Texture missing;
  missing.id = s.newId();
  missing.name = "Gone";
  missing.path = "/nonexistent/gone.png";
  s.textures.push_back(missing);
  s.materials.front().albedoTexture = missing.id;
  const auto file = retile::test::tempDir() / "warned.retile";
  ASSERT_TRUE(saveNativeScene(s, file).ok());
  auto loaded = importScene(file);
  ASSERT_TRUE(loaded.ok());
  auto* logDock = w->findChild<QDockWidget*>("log");
  w->findChild<QDockWidget*>("nodeGraphDock")->raise();
  w->opened(file, {"texture 'Gone': /nonexistent/gone.png is missing"});  // as the command line reports it
  EXPECT_TRUE(QSettings().value("recentFiles").toStringList().contains(QString::fromStdString(std::filesystem::absolute(file).string())));
  EXPECT_TRUE(w->viewport()->notice().contains("warning")) << w->viewport()->notice().toStdString();
  EXPECT_TRUE(w->statusBar()->currentMessage().contains("warning"));
  EXPECT_FALSE(logDock->visibleRegion().isEmpty()) << "the Log is raised";
  auto* graphDock = w->findChild<QDockWidget*>("nodeGraphDock");
  EXPECT_TRUE(QTest::qWaitFor([&] { return !graphDock->visibleRegion().isEmpty(); }, 2000)) << "the node graph stays in view beside it";
  EXPECT_FALSE(logDock->visibleRegion().isEmpty());

  graphDock->close();
  QMenu* windows = w->menuBar()->findChild<QMenu*>("windowMenu");
  ASSERT_TRUE(windows);
  QAction* back = nullptr;
  for (QAction* a : windows->actions())
    if (a->text().contains("Node graph")) back = a;
  ASSERT_TRUE(back);
  back->trigger();
  EXPECT_TRUE(graphDock->isVisible());
}

}  // namespace
}  // namespace retile::ui
