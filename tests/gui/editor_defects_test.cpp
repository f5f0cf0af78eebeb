// The editor as an artist meets it (issue 13): one test per defect found by trying it as a new
// user would, each failing on the editor before its fix.
#include <QApplication>
#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QLabel>
#include <QSpinBox>
#include <QTest>
#include <QTreeWidget>

#include <gtest/gtest.h>

#include "editor_support.h"
#include "fields.h"
#include "frame_view.h"
#include "main_window.h"

namespace retile::ui {
namespace {

using test::makeWindow;
using test::objectNamed;
using test::pointShowing;
using test::waitForFrame;

QTreeWidgetItem* outlinerItem(MainWindow& w, const QString& text) {
  auto* tree = w.findChild<QTreeWidget*>();
  for (QTreeWidgetItemIterator it(tree); *it; ++it)
    if ((*it)->text(0) == text) return *it;
  return nullptr;
}

// 1. Properties showed the old position after a drag in the viewport.
TEST(EditorDefects, PropertiesFollowADragInTheViewport) {
  auto w = makeWindow();
  NodeId cup = objectNamed(w->scene(), "Cup");
  w->select(cup);
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 3; }));
  auto* x = w->findChild<ScrubField*>("position0");
  ASSERT_TRUE(x);
  const double before = x->value();
  // Drag the gizmo's x arrow halfway along it, to the right.
  FrameView* v = w->viewport();
  const FrameView::Gizmo& g = v->gizmo();
  ASSERT_TRUE(g.visible);
  QPoint on = v->widgetPoint((g.origin + g.axisEnd[0]) / 2).toPoint();
  QTest::mousePress(v, Qt::LeftButton, Qt::NoModifier, on);
  for (int i = 1; i <= 4; ++i) QTest::mouseMove(v, on + QPoint(10 * i, 0));
  QTest::mouseRelease(v, Qt::LeftButton, Qt::NoModifier, on + QPoint(40, 0));
  const double moved = w->scene().object(cup)->transform.transformPoint(Vec3{0.0f}).x;
  ASSERT_GT(std::abs(moved - before), 0.05) << "the drag moved the cup";
  ASSERT_TRUE(QTest::qWaitFor([&] {
    auto* field = w->findChild<ScrubField*>("position0");
    return field && std::abs(field->value() - moved) < 1e-3;
  }, 2000)) << "the X field shows the new position";
}

// 2. After scrubbing a field, Ctrl+Z and the A/B keys went to the field, not the window.
TEST(EditorDefects, ShortcutsWorkAfterScrubbingAField) {
  auto w = makeWindow();
  QApplication::setActiveWindow(w.get());  // shortcuts go to the active window
  ASSERT_TRUE(QTest::qWaitForWindowActive(w.get()));
  NodeId sphere = objectNamed(w->scene(), "Glossy Sphere");
  w->select(sphere);
  auto* rough = w->findChild<ScrubField*>("roughness");
  ASSERT_TRUE(rough);
  const NodeId material = w->scene().object(sphere)->material;
  const float before = w->scene().material(material)->roughness;
  QPoint c(6, rough->height() / 2);
  QTest::mousePress(rough, Qt::LeftButton, Qt::NoModifier, c);
  for (int i = 1; i <= 10; ++i) QTest::mouseMove(rough, c + QPoint(3 * i, 0));
  QTest::mouseRelease(rough, Qt::LeftButton, Qt::NoModifier, c + QPoint(30, 0));
  ASSERT_GT(w->scene().material(material)->roughness, before + 0.1f);
  // The key goes wherever the keyboard focus is, as a user's would.
  QWidget* focus = QApplication::focusWidget() ? QApplication::focusWidget() : w.get();
  QTest::keyClick(focus, Qt::Key_Z, Qt::ControlModifier);
  EXPECT_FLOAT_EQ(w->scene().material(material)->roughness, before) << "Ctrl+Z undid the scrub";
  // B (show the snapshot) reaches the viewport's compare menu, not the field.
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 1; }));
  w->viewport()->takeSnapshot();
  ASSERT_TRUE(w->viewport()->hasSnapshot());
  focus = QApplication::focusWidget() ? QApplication::focusWidget() : w.get();
  QTest::keyClick(focus, Qt::Key_B);
  EXPECT_EQ(w->viewport()->compare(), FrameView::Compare::Toggle);

  // While typing, the field keeps its keys: Ctrl+Z edits the text, not the document.
  rough = w->findChild<ScrubField*>("roughness");
  QTest::mouseClick(rough, Qt::LeftButton, Qt::NoModifier, c);
  QTest::keyClicks(QApplication::focusWidget(), "0.7");
  const int steps = w->undoStack()->index();
  QTest::keyClick(QApplication::focusWidget(), Qt::Key_Z, Qt::ControlModifier);
  EXPECT_EQ(w->undoStack()->index(), steps) << "no undo while typing";
}

// 3. The rotate ring and the scale handles could not be grabbed: the press picked what was behind.
TEST(EditorDefects, TheGizmosRotateAndScaleHandlesTakeThePress) {
  auto w = makeWindow();
  NodeId cup = objectNamed(w->scene(), "Cup");
  w->select(cup);
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 3; }));
  FrameView* v = w->viewport();
  auto drag = [&](QPoint from) {
    QTest::mousePress(v, Qt::LeftButton, Qt::NoModifier, from);
    for (int i = 1; i <= 4; ++i) QTest::mouseMove(v, from + QPoint(8 * i, 0));
    QTest::mouseRelease(v, Qt::LeftButton, Qt::NoModifier, from + QPoint(32, 0));
  };
  const Mat4 start = w->scene().object(cup)->transform;
  // The ring's rightmost point: the background or another object lies behind it.
  v->setTool(FrameView::Tool::Rotate);
  QPoint ring = (v->widgetPoint(v->gizmo().origin) + QPointF(FrameView::kRingRadiusX, 0)).toPoint();
  drag(ring);
  const Mat4 turned = w->scene().object(cup)->transform;
  EXPECT_GT(std::abs(turned.m[0][2] - start.m[0][2]), 0.05f) << "the cup turned about y";
  EXPECT_EQ(w->selection(), cup) << "the press did not pick another object";
  // The scale tool's box at the end of the x axis.
  v->setTool(FrameView::Tool::Scale);
  const FrameView::Gizmo& g = v->gizmo();
  QPoint box = v->widgetPoint(g.axisEnd[0]).toPoint();
  const float before = length(Vec3{turned.m[0][0], turned.m[1][0], turned.m[2][0]});
  drag(box);
  const Mat4 scaled = w->scene().object(cup)->transform;
  EXPECT_GT(length(Vec3{scaled.m[0][0], scaled.m[1][0], scaled.m[2][0]}), before * 1.05f) << "the cup grew";
  EXPECT_EQ(w->selection(), cup);
}

QColorDialog* openColorDialog(MainWindow& w, const char* field) {
  auto* swatch = w.findChild<ColorField*>(field);
  if (!swatch) return nullptr;
  swatch->click();
  return w.findChild<QColorDialog*>();
}

// 5. The colour dialog painted itself in the swatch's colour (white text on lime).
TEST(EditorDefects, TheColourDialogKeepsItsOwnColours) {
  auto w = makeWindow();
  NodeId sphere = objectNamed(w->scene(), "Glossy Sphere");
  const NodeId material = w->scene().object(sphere)->material;
  Material lime = *w->scene().material(material);
  lime.albedo = Vec3{0.0f, 1.0f, 0.0f};
  w->edit(SetMaterial{*w->scene().material(material)}, SetMaterial{lime}, "lime");
  w->select(sphere);
  QTest::qWait(50);  // the panel rebuilds after the edit
  QColorDialog* dialog = openColorDialog(*w, "albedo");
  ASSERT_TRUE(dialog);
  ASSERT_TRUE(QTest::qWaitForWindowExposed(dialog));
  QImage shot = dialog->grab().toImage();
  int limePixels = 0;
  for (int y = 0; y < shot.height(); ++y)
    for (int x = 0; x < shot.width(); ++x) {
      QColor c = shot.pixelColor(x, y);
      limePixels += c.green() > 240 && c.red() < 20 && c.blue() < 20;
    }
  EXPECT_LT(limePixels, shot.width() * shot.height() / 10) << "only the colour's own preview is lime";
  dialog->reject();
}

// 6. Cancelling the colour dialog left an empty undo step and cleared Redo.
TEST(EditorDefects, CancellingTheColourDialogLeavesTheUndoHistoryAsItWas) {
  auto w = makeWindow();
  NodeId sphere = objectNamed(w->scene(), "Glossy Sphere");
  const NodeId material = w->scene().object(sphere)->material;
  w->select(sphere);
  // Something to redo.
  Material rougher = *w->scene().material(material);
  rougher.roughness = 0.8f;
  w->edit(SetMaterial{*w->scene().material(material)}, SetMaterial{rougher}, "rougher");
  w->undoStack()->undo();
  ASSERT_TRUE(w->undoStack()->canRedo());
  const int count = w->undoStack()->count(), index = w->undoStack()->index();
  const Vec3 start = w->scene().material(material)->albedo;
  QTest::qWait(50);
  QColorDialog* dialog = openColorDialog(*w, "albedo");
  ASSERT_TRUE(dialog);
  dialog->setCurrentColor(QColor(255, 0, 0));
  EXPECT_GT(w->scene().material(material)->albedo.x, 0.99f) << "the tried colour shows";
  dialog->reject();
  EXPECT_EQ(w->scene().material(material)->albedo, start) << "cancel takes it back";
  EXPECT_EQ(w->undoStack()->count(), count) << "no undo step";
  EXPECT_EQ(w->undoStack()->index(), index);
  EXPECT_TRUE(w->undoStack()->canRedo()) << "and Redo still works";

  // Accepting after trying several colours is one step from the colour before the dialog.
  dialog = openColorDialog(*w, "albedo");
  ASSERT_TRUE(dialog);
  dialog->setCurrentColor(QColor(255, 0, 0));
  dialog->setCurrentColor(QColor(0, 0, 255));
  dialog->accept();
  EXPECT_GT(w->scene().material(material)->albedo.z, 0.99f);
  EXPECT_EQ(w->undoStack()->index(), index + 1);
  w->undoStack()->undo();
  EXPECT_EQ(w->scene().material(material)->albedo, start);
}

// 14. Outliner: Ground, then Camera, then Ground again left Properties on the camera.
TEST(EditorDefects, OutlinerAndPropertiesStayInStep) {
  auto w = makeWindow();
  auto* tree = w->findChild<QTreeWidget*>();
  ASSERT_TRUE(tree);
  QTreeWidgetItem* ground = outlinerItem(*w, "Ground");
  QTreeWidgetItem* camera = outlinerItem(*w, "Camera");
  ASSERT_TRUE(ground && camera);
  tree->setCurrentItem(ground);
  EXPECT_TRUE(w->findChild<ScrubField*>("position0")) << "the object's fields";
  tree->setCurrentItem(camera);
  EXPECT_TRUE(w->findChild<ScrubField*>("cameraPosition0")) << "the camera's fields";
  ground = outlinerItem(*w, "Ground");
  tree->setCurrentItem(ground);
  EXPECT_TRUE(w->findChild<ScrubField*>("position0")) << "back to the object";
  EXPECT_FALSE(w->findChild<ScrubField*>("cameraPosition0"));
}

}  // namespace
}  // namespace retile::ui
