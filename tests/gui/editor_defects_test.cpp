// The editor as an artist meets it (issue 13): one test per defect found by trying it as a new
// user would, each failing on the editor before its fix.
#include <QApplication>
#include <QCheckBox>
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
