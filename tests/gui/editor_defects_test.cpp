// The editor as an artist meets it (issue 13): one test per defect found by trying it as a new
// user would, each failing on the editor before its fix.
#include <QAbstractAxis>
#include <QApplication>
#include <QChart>
#include <QCheckBox>
#include <QColorDialog>
#include <QComboBox>
#include <QDockWidget>
#include <QDir>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QFontMetricsF>
#include <QLabel>
#include <QLineEdit>
#include <QPlainTextEdit>
#include <QScrollBar>
#include <QSpinBox>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>
#include <QTreeWidget>
#include <QValueAxis>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "editor_support.h"
#include "fields.h"
#include "frame_view.h"
#include "live_chart.h"
#include "test_support.h"
#include "main_window.h"
#include "node_graph.h"
#include "retile/io.h"

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
  ASSERT_TRUE(QTest::qWaitFor(
      [&] {
        auto* field = w->findChild<ScrubField*>("position0");
        return field && std::abs(field->value() - moved) < 1e-3;
      },
      2000))
      << "the X field shows the new position";
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

// A textured albedo showed its colour as "Albedo": a white swatch above a wood texture read as the
// surface's colour, where the kernel multiplies the two.
TEST(EditorDefects, ATexturedAlbedoSaysItsColourMultipliesTheTexture) {
  auto w = makeWindow();
  auto albedoLabel = [&](const char* object) {
    w->select(objectNamed(w->scene(), object));
    QTest::qWait(50);  // the panel rebuilds
    auto* field = w->findChild<ColorField*>("albedo");
    if (!field) return QString("(no albedo field)");
    auto* form = qobject_cast<QFormLayout*>(field->parentWidget()->layout());
    auto* label = form ? qobject_cast<QLabel*>(form->labelForField(field)) : nullptr;
    return label ? label->text() : QString("(no label)");
  };
  const Material* checkered = w->scene().material(w->scene().object(objectNamed(w->scene(), "Checkered Box"))->material);
  ASSERT_NE(checkered->albedoTexture, kNoNode) << "the built-in scene's box is textured";
  EXPECT_EQ(albedoLabel("Checkered Box"), QString::fromUtf8("Albedo \u00d7 texture"));
  EXPECT_FALSE(w->findChild<ColorField*>("albedo")->toolTip().isEmpty());
  EXPECT_EQ(albedoLabel("Glossy Sphere"), QString("Albedo"));
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

// Brightly saturated pixels (the heat map's ramp, the classes' yellow) inside `box` of `img`.
int saturatedPixels(const QImage& img, const QRectF& box) {
  int n = 0;
  for (int y = static_cast<int>(box.top()); y < static_cast<int>(box.bottom()); ++y)
    for (int x = static_cast<int>(box.left()); x < static_cast<int>(box.right()); ++x) {
      if (!img.rect().contains(x, y)) continue;
      QColor c = img.pixelColor(x, y);
      n += c.hsvSaturationF() > 0.85 && c.valueF() > 0.85;
    }
  return n;
}

// 7 and 8. The classes' legend was cut off behind the main legend; the legend showed the heat
// map's colour ramp with the heat map off. The heat map itself tinted the whole picture while it
// refined, outside any pass.
TEST(EditorDefects, TheLegendExplainsWhatIsDrawnAndNothingElse) {
  auto w = makeWindow();
  w->resize(1280, 800);
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  FrameView* v = w->viewport();
  auto refining = std::make_shared<FrameRecord>(*v->frame());
  refining->mode = "refinement";
  refining->queueLength = 0;  // outside a pass there is no queue
  refining->queueServed = 0;
  auto inPass = std::make_shared<FrameRecord>(*refining);
  inPass->mode = "incremental";
  inPass->queueLength = 40;
  inPass->queueServed = 12;
  OverlaySettings o;
  o.priority = false;
  o.legend = true;
  o.denoised = false;  // its key is a saturated orange too
  o.reuse = false;
  v->setOverlays(o);
  v->showFrame(inPass);
  using Key = FrameView::LegendItem::Key;
  auto keyed = [&](Key k) {
    const auto items = v->legendItems();
    return std::any_of(items.begin(), items.end(), [k](const FrameView::LegendItem& i) { return i.key == k; });
  };
  QRectF box = v->legendRect();
  EXPECT_EQ(saturatedPixels(v->composed(), box), 0) << "no colour ramp without the heat map";
  EXPECT_FALSE(keyed(Key::Ramp));
  o.priority = true;
  v->setOverlays(o);
  box = v->legendRect();
  EXPECT_GT(saturatedPixels(v->composed(), box), 50) << "the ramp with it";
  auto lastLine = [&] { return v->legendItems().back().text; };
  EXPECT_TRUE(lastLine().endsWith("incremental: 12 of 40 tiles")) << lastLine().toStdString();
  v->showFrame(refining);
  EXPECT_FALSE(v->heatMapShown()) << "no heat map outside a pass";
  EXPECT_EQ(saturatedPixels(v->composed(), v->legendRect()), 0);
  EXPECT_TRUE(lastLine().endsWith("refinement: the whole image")) << "not \"0 of 0 tiles\": " << lastLine().toStdString();
  auto afterPass = std::make_shared<FrameRecord>(*refining);
  afterPass->queueLength = afterPass->queueServed = 40;  // the pass finished, its queue kept
  v->showFrame(afterPass);
  EXPECT_TRUE(lastLine().endsWith("refinement: the whole image")) << "not \"40 of 40 tiles\": " << lastLine().toStdString();
  // A global update (a camera or settings change) restarts every tile with no queue: no ramp.
  auto global = std::make_shared<FrameRecord>(*refining);
  global->mode = "global-update";
  v->showFrame(global);
  EXPECT_FALSE(v->heatMapShown()) << "no heat map in a global update";
  EXPECT_FALSE(keyed(Key::Ramp)) << "its key names tiles still to come, and there are none";
  EXPECT_EQ(saturatedPixels(v->composed(), v->legendRect()), 0);
  v->showFrame(refining);

  // No point of change before the first edit: neither its cross (drawn at the image's centre,
  // where nothing changed) nor its key. After one, both. The cross's colour around the point,
  // where the built-in scene shows grey glass.
  ASSERT_TRUE(refining->pointsOfChange.empty()) << "the first frames follow no edit";
  o.markers = true;
  v->setOverlays(o);
  auto crossPixels = [&](const FrameRecord& f) {
    const QImage img = v->composed();
    const QRectF r = v->imageRect();
    const QPointF at(r.x() + f.pointOfChange.x * r.width() / f.width, r.y() + f.pointOfChange.y * r.height() / f.height);
    int n = 0;
    for (int y = static_cast<int>(at.y()) - 12; y <= static_cast<int>(at.y()) + 12; ++y)
      for (int x = static_cast<int>(at.x()) - 12; x <= static_cast<int>(at.x()) + 12; ++x)
        n += img.rect().contains(x, y) && img.pixelColor(x, y) == FrameView::kChangeColor;
    return n;
  };
  EXPECT_FALSE(keyed(Key::Cross));
  EXPECT_EQ(crossPixels(*refining), 0) << "no cross where nothing changed";
  auto edited = std::make_shared<FrameRecord>(*refining);
  edited->pointsOfChange = {edited->pointOfChange};
  v->showFrame(edited);
  EXPECT_TRUE(keyed(Key::Cross));
  EXPECT_GT(crossPixels(*edited), 20) << "the cross at the point of change";
  v->showFrame(refining);

  // Indirection with counters: the classes' row is in the legend's one box, inside the image.
  MethodSettings m;
  m.kind = MethodKind::Indirection;
  m.quality = 0;
  m.indirectionFrames = 1;
  w->engine()->submit(MethodCommand{m});
  w->select(objectNamed(w->scene(), "Cup"));
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return !f.tileClass.empty(); }));
  v->showFrame(v->frame());
  o.classes = true;
  v->setOverlays(o);
  EXPECT_TRUE(keyed(Key::Hatch)) << "the classes are keyed";
  box = v->legendRect();
  EXPECT_TRUE(QRectF(v->rect()).contains(box)) << "the whole legend is in the viewport";
  EXPECT_FALSE(box.intersects(v->imageRect())) << "beside the image, not over it";
  EXPECT_GE(box.height(), v->layOutLegend(v->legendItems(), box.width()).height) << "and tall enough for its items";
}

// 9. Tile order numbers and samples per tile printed on top of each other.
TEST(EditorDefects, OrderNumbersAndSampleCountsDoNotOverlap) {
  auto w = makeWindow();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  FrameView* v = w->viewport();
  OverlaySettings o;
  o.order = true;
  o.samples = true;
  v->setOverlays(o);
  for (double tile : {16.0, 24.0, 40.0, 96.0}) {
    SCOPED_TRACE(tile);
    FrameView::TileLabels l = v->tileLabels(QRectF(10, 10, tile, tile));
    EXPECT_FALSE(l.order.intersects(l.samples)) << "each label has its own part of the tile";
    QFontMetricsF fm(l.font);
    EXPECT_LE(fm.height(), l.order.height() + 1) << "a line of the font fits its part";
    EXPECT_TRUE(QRectF(10, 10, tile, tile).contains(l.order.united(l.samples)));
  }
}

// Where the image's size is not a multiple of the tile's, the last row and column of tiles are
// cut short: their numbers were placed as in a whole tile, below and beside the image.
TEST(EditorDefects, TileNumbersStayInsideTheImage) {
  auto w = makeWindow();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  FrameView* v = w->viewport();
  auto f = std::make_shared<FrameRecord>(*v->frame());
  // A tile size that leaves a thin last row and column.
  f->tileSize = 1;
  for (int t = 4; t <= 64; ++t)
    if (f->height % t > 0 && f->height % t < t / 4 && f->width % t > 0) {
      f->tileSize = t;
      break;
    }
  ASSERT_GT(f->tileSize, 1) << f->width << "x" << f->height;
  f->cols = (f->width + f->tileSize - 1) / f->tileSize;
  f->rows = (f->height + f->tileSize - 1) / f->tileSize;
  f->tileSamples.assign(static_cast<std::size_t>(f->cols * f->rows), 558.0f);
  f->tilePriority.assign(f->tileSamples.size(), 0.5f);
  f->queueLength = 2;
  f->mode = "incremental";
  v->showFrame(f);
  OverlaySettings o;
  // No legend: its strip grows with the numbers' keys, which would move the image.
  o.priority = o.served = o.markers = o.denoised = o.reuse = o.legend = false;
  v->setOverlays(o);
  const QImage bare = v->composed();
  o.samples = o.order = true;
  v->setOverlays(o);
  const QImage numbered = v->composed();
  ASSERT_EQ(bare.size(), numbered.size());
  const QRect image = v->imageRect().toAlignedRect();
  int outside = 0, inside = 0;
  for (int y = 0; y < bare.height(); ++y)
    for (int x = 0; x < bare.width(); ++x) {
      if (bare.pixel(x, y) == numbered.pixel(x, y)) continue;
      (image.contains(x, y) ? inside : outside)++;
    }
  EXPECT_GT(inside, 100) << "the numbers are drawn";
  EXPECT_EQ(outside, 0) << "none past the image's border (tile " << f->tileSize << ", image " << f->width << "x" << f->height << ")";
}

// 10. At 1280x800 and 1600x1000 drop-downs and number fields lost their arrows; Q's "auto" was
// found only by stepping below 1; a typed Q applied at every digit.
TEST(EditorDefects, TheRenderSettingsFitAndQHasAnAutoSwitch) {
  auto w = makeWindow();
  for (QSize size : {QSize(1280, 800), QSize(1600, 1000)}) {
    SCOPED_TRACE(testing::Message() << size.width() << "x" << size.height());
    w->resize(size);
    QTest::qWait(200);  // the docks settle
    auto* dock = w->findChild<QDockWidget*>("renderSettings");
    ASSERT_TRUE(dock);
    dock->raise();
    QTest::qWait(50);
    int checked = 0;
    for (QComboBox* c : dock->findChildren<QComboBox*>()) {
      if (!c->isVisibleTo(dock)) continue;
      EXPECT_GE(c->width(), c->minimumSizeHint().width()) << c->objectName().toStdString();
      ++checked;
    }
    for (QAbstractSpinBox* b : dock->findChildren<QAbstractSpinBox*>()) {
      if (!b->isVisibleTo(dock)) continue;
      EXPECT_GE(b->width(), b->minimumSizeHint().width()) << b->objectName().toStdString();
      ++checked;
    }
    EXPECT_GT(checked, 5);
  }
  auto* method = w->findChild<QComboBox*>("method");
  auto* q = w->findChild<QSpinBox*>("quality");
  auto* qAuto = w->findChild<QCheckBox*>("qualityAuto");
  ASSERT_TRUE(method && q && qAuto);
  EXPECT_EQ(q->minimum(), 1);
  EXPECT_FALSE(qAuto->isEnabled()) << "automatic Q is the indirection methods'";
  method->setCurrentText("indirection");
  EXPECT_TRUE(qAuto->isEnabled());
  qAuto->setChecked(true);
  EXPECT_FALSE(q->isEnabled());
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.method == "indirection+denoise"; }));
  qAuto->setChecked(false);
  EXPECT_FALSE(q->keyboardTracking()) << "a typed value applies on Enter";
}

// 11 and 12. Ctrl+Shift+S did nothing; the title never showed the file's name or unsaved changes.
TEST(EditorDefects, SaveAsHasItsShortcutAndTheTitleShowsTheFileAndChanges) {
  auto w = makeWindow();
  QApplication::setActiveWindow(w.get());
  ASSERT_TRUE(QTest::qWaitForWindowActive(w.get()));
  EXPECT_TRUE(w->windowTitle().contains("built-in scene"));
  EXPECT_FALSE(w->isWindowModified());
  NodeId cup = objectNamed(w->scene(), "Cup");
  Object o = *w->scene().object(cup), renamed = o;
  renamed.name = "Teacup";
  w->edit(SetObject{o}, SetObject{renamed}, "rename");
  EXPECT_TRUE(w->isWindowModified()) << "unsaved changes are marked";
  QTemporaryDir dir;
  const QString path = dir.path() + "/cups";  // the dialog adds .retile
  // Answers the dialog when it is up; a dialog that does not close is rejected, so a failure
  // cannot hang the suite.
  bool dialogSeen = false, dialogClosed = false;
  QTimer poll;
  int polls = 0;
  QObject::connect(&poll, &QTimer::timeout, [&] {
    auto* dialog = qobject_cast<QFileDialog*>(QApplication::activeModalWidget());
    if (dialog && dialog->objectName() == "saveAsDialog" && !dialogSeen) {
      dialogSeen = true;
      dialog->setDirectory(dir.path());
      if (auto* name = dialog->findChild<QLineEdit*>("fileNameEdit")) name->setText("cups");
      static_cast<QDialog*>(dialog)->accept();  // QFileDialog::accept is protected
      dialogClosed = !dialog->isVisible();
      if (!dialogClosed) dialog->reject();
    } else if (dialog && ++polls > 100) {
      dialog->reject();
    }
  });
  poll.start(50);
  QTest::keyClick(w.get(), Qt::Key_S, Qt::ControlModifier | Qt::ShiftModifier);
  poll.stop();
  EXPECT_TRUE(dialogClosed) << "the dialog takes the name";
  EXPECT_TRUE(dialogSeen) << "Ctrl+Shift+S asks where to save";
  EXPECT_TRUE(QFile::exists(path + ".retile"));
  EXPECT_TRUE(w->windowTitle().startsWith("cups.retile")) << w->windowTitle().toStdString();
  EXPECT_FALSE(w->isWindowModified());
}

// 13. After File > Open or New the image was letterboxed (a fixed size), after a resize cropped.
TEST(EditorDefects, AfterNewTheImageFillsTheViewport) {
  EditorOptions o;  // the render size follows the viewport
  o.renderScale = 4;
  o.cameraFraming = false;
  auto w = std::make_unique<MainWindow>(makeDefaultScene(), std::filesystem::path(), o);
  w->resize(1200, 640);
  w->show();
  QTest::qWait(400);  // the docks and the render size settle
  QApplication::setActiveWindow(w.get());
  ASSERT_TRUE(QTest::qWaitForWindowActive(w.get()));
  QTest::keyClick(w.get(), Qt::Key_N, Qt::ControlModifier);  // a new document
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  FrameView* v = w->viewport();
  const double viewAspect = v->imageArea().width() / v->imageArea().height();
  const double imageAspect = static_cast<double>(v->frame()->width) / v->frame()->height;
  EXPECT_NEAR(imageAspect, viewAspect, 0.05 * viewAspect) << "the image has the viewport's shape";
  EXPECT_GT(v->imageRect().width(), 0.97 * v->imageArea().width());
  EXPECT_GT(v->imageRect().height(), 0.97 * v->imageArea().height());
}

// 15. The live chart was cramped: labels "...", plots about 40 px tall.
TEST(EditorDefects, TheLiveChartHasRoomForItsPlotsAndLabels) {
  auto w = makeWindow();
  w->resize(1280, 800);
  auto* chartDock = w->findChild<QDockWidget*>("chartDock");
  ASSERT_TRUE(chartDock);
  chartDock->raise();
  QTest::qWait(300);
  auto* chart = w->findChild<LiveChart*>();
  ASSERT_TRUE(chart);
  ASSERT_EQ(chart->charts().size(), 2u);
  for (QChart* c : chart->charts()) {
    EXPECT_GE(c->plotArea().height(), 80) << "the plot";
    for (QAbstractAxis* a : c->axes()) EXPECT_FALSE(a->labelsTruncated()) << "no label is cut to ...";
  }
  // Its time axis counts from the editor's opening: in the first minute it starts at 0 (it showed
  // "-9 s" to "51 s", times before the editor opened), and spans the minute the legend names.
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 3; }));
  QTest::qWait(100);
  ASSERT_GT(chart->throughputPoints(), 0);
  for (QChart* c : chart->charts())
    for (QAbstractAxis* a : c->axes(Qt::Horizontal)) {
      auto* time = qobject_cast<QValueAxis*>(a);
      ASSERT_TRUE(time);
      EXPECT_EQ(time->min(), 0.0);
      EXPECT_EQ(time->max(), 60.0);
    }
}

// The frame-time axis was fitted to the first frame, which waits about a second for the trace
// kernel to compile: for a minute every other frame lay flat along the bottom.
TEST(EditorDefects, TheLiveChartsFrameTimesAreNotFlattenedByAKernelCompile) {
  auto msAxisMax = [](bool flagged) {
    LiveChart chart;
    FrameRecord f;
    f.samples = 1000;
    f.frameMs = 1100;
    f.compiledKernel = flagged;
    chart.addFrame(f);
    f.compiledKernel = false;
    for (double ms : {40.0, 55.0, 45.0}) {
      f.frameMs = ms;
      chart.addFrame(f);
    }
    for (QAbstractAxis* a : chart.charts().front()->axes(Qt::Vertical))
      if (a->alignment() == Qt::AlignRight) return qobject_cast<QValueAxis*>(a)->max();
    return -1.0;
  };
  EXPECT_NEAR(msAxisMax(true), 55 * 1.15, 1e-6) << "fitted to the frames after the compile";
  EXPECT_NEAR(msAxisMax(false), 1100 * 1.15, 1e-6) << "a slow frame of its own still shows";
}

// 16. The log did not follow new entries, and a missing file was reported twice.
TEST(EditorDefects, TheLogFollowsNewEntriesAndSaysEachWarningOnce) {
  RETILE_SHARED_OR_SKIP(room, "scenes/living-room/scene.json");
  auto w = makeWindow();
  auto* logDock = w->findChild<QDockWidget*>("log");
  ASSERT_TRUE(logDock);
  logDock->raise();
  ASSERT_TRUE(w->openFile(room)) << w->lastError().toStdString();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  QTest::qWait(100);
  auto* log = qobject_cast<QPlainTextEdit*>(logDock->widget());
  ASSERT_TRUE(log);
  const QStringList lines = log->toPlainText().split('\n');
  QStringList warnings;
  for (const QString& line : lines)
    if (line.contains("warning:")) warnings << line.mid(line.indexOf("warning:"));
  ASSERT_FALSE(warnings.isEmpty()) << "the room's sky map is missing";
  EXPECT_EQ(warnings.removeDuplicates(), 0) << "each warning once";
  // Each missing file once, in one set of words: the import says what stands in for it (the
  // scene's upload said it again, and said the sky map was "shown as a checker" while the
  // sky was a constant).
  for (const char* missing : {"leaf.png", "Sky 19.exr"})
    EXPECT_EQ(warnings.filter(missing).size(), 1) << missing << " in:\n" << warnings.join('\n').toStdString();
  for (int i = 0; i < 60; ++i) w->log(QString("entry %1").arg(i));
  QScrollBar* bar = log->verticalScrollBar();
  EXPECT_EQ(bar->value(), bar->maximum()) << "the newest entry shows";
}

// 14. Outliner: Ground, then Camera, then Ground again left Properties on the camera.
TEST(EditorDefects, OutlinerAndPropertiesStayInStep) {
  auto w = makeWindow();
  auto* tree = w->findChild<QTreeWidget*>();
  ASSERT_TRUE(tree);
  QTreeWidgetItem* ground = outlinerItem(*w, "Ground");
  QTreeWidgetItem* camera = outlinerItem(*w, "Camera");
  ASSERT_TRUE(ground && camera);
  tree->setCurrentItem(ground, 0, QItemSelectionModel::ClearAndSelect);  // a plain click
  EXPECT_TRUE(w->findChild<ScrubField*>("position0")) << "the object's fields";
  tree->setCurrentItem(camera, 0, QItemSelectionModel::ClearAndSelect);
  EXPECT_TRUE(w->findChild<ScrubField*>("cameraPosition0")) << "the camera's fields";
  ground = outlinerItem(*w, "Ground");
  tree->setCurrentItem(ground, 0, QItemSelectionModel::ClearAndSelect);  // a plain click
  EXPECT_TRUE(w->findChild<ScrubField*>("position0")) << "back to the object";
  EXPECT_FALSE(w->findChild<ScrubField*>("cameraPosition0"));
}

// A scene with many materials and objects, like an imported room (the living room has about 90
// nodes), made here so the test needs no shared file.
Scene manyNodes(int pairs) {
  Scene s = makeDefaultScene();
  const Object model = s.objects.front();
  for (int i = 0; i < pairs; ++i) {
    Material m;
    m.id = s.newId();
    m.name = "Material " + std::to_string(i);
    s.materials.push_back(m);
    Object o = model;
    o.id = s.newId();
    o.name = "Object " + std::to_string(i);
    o.material = m.id;
    s.objects.push_back(o);
  }
  return s;
}

// 4. The living room's graph was a thin column and a bundle of links: big graphs are laid out
// in about the panel's shape, each material beside what it is on (node_graph_test.cpp checks that
// the links then cross no node).
TEST(EditorDefects, ABigGraphIsLaidOutInThePanelsShape) {
  NodeGraphView view;
  view.resize(1200, 260);  // the graph panel below the viewport
  view.show();
  const Scene s = manyNodes(40);
  view.setDocument(s);
  double minX = 1e9, maxX = -1e9, minY = 1e9, maxY = -1e9;
  std::set<std::pair<int, int>> places;
  auto span = [&](NodeId id) {
    const QPointF p = view.nodePosition(id);
    minX = std::min(minX, p.x()), maxX = std::max(maxX, p.x());
    minY = std::min(minY, p.y()), maxY = std::max(maxY, p.y());
    EXPECT_TRUE(places.insert({static_cast<int>(p.x()), static_cast<int>(p.y())}).second) << "one node per place";
  };
  for (const Texture& t : s.textures) span(t.id);
  for (const Material& m : s.materials) span(m.id);
  for (const Object& o : s.objects) {
    span(o.id);
    if (o.material != kNoNode) {
      EXPECT_LT(view.nodePosition(o.material).x(), view.nodePosition(o.id).x()) << o.name << ": its material, then it";
    }
  }
  EXPECT_GT(maxX - minX, 2.0 * (maxY - minY)) << "wider than tall, like the panel: " << maxX - minX << " x " << maxY - minY;
}

// 4. Picking an object in the viewport brings its node into the graph's view; a click on empty
// canvas keeps the selection.
TEST(EditorDefects, TheGraphShowsWhatThePickSelectsAndAnEmptyClickKeepsIt) {
  NodeGraphView view;
  view.resize(600, 240);
  view.show();
  const Scene s = manyNodes(40);
  view.setDocument(s);
  view.scale(2.5, 2.5);  // zoomed in, as an artist working on a few nodes
  const NodeId last = s.objects.back().id;
  view.setSelectedObject(last);
  const QPoint at = view.mapFromScene(view.nodePosition(last) + QPointF(20, 10));
  EXPECT_TRUE(view.viewport()->rect().contains(at)) << "the picked object's node is in view";
  ASSERT_EQ(view.selectedNodes(), std::vector<NodeId>{last});
  QPoint empty(-1, -1);
  for (int y = 5; y < view.viewport()->height() && empty.x() < 0; y += 10)
    for (int x = 5; x < view.viewport()->width(); x += 10)
      if (!view.itemAt(QPoint(x, y))) {
        empty = QPoint(x, y);
        break;
      }
  ASSERT_GE(empty.x(), 0);
  QTest::mouseClick(view.viewport(), Qt::LeftButton, Qt::NoModifier, empty);
  EXPECT_EQ(view.selectedNodes(), std::vector<NodeId>{last}) << "a click on empty canvas keeps the selection";
}

// 4. F and A act on the panel under the mouse, wherever the keyboard focus is.
TEST(EditorDefects, FAndAActOnThePanelUnderTheMouse) {
  auto w = makeWindow();
  w->resize(1280, 800);
  QApplication::setActiveWindow(w.get());
  ASSERT_TRUE(QTest::qWaitForWindowActive(w.get()));
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  NodeGraphView* graph = w->graph();
  FrameView* v = w->viewport();
  graph->scale(4, 4);
  const double zoomed = graph->transform().m11();
  QTest::mouseMove(graph->viewport(), graph->viewport()->rect().center());
  ASSERT_TRUE(graph->mouseOver());
  v->setFocus();  // the keyboard on the viewport, the mouse over the graph
  QTest::keyClick(v, Qt::Key_A);
  EXPECT_LT(graph->transform().m11(), zoomed) << "A frames the whole graph";
  EXPECT_EQ(v->compare(), FrameView::Compare::Off);

  w->select(objectNamed(w->scene(), "Cup"));
  const Camera camera = w->scene().camera;
  graph->scale(3, 3);
  const double before = graph->transform().m11();
  QTest::keyClick(v, Qt::Key_F);
  EXPECT_NE(graph->transform().m11(), before) << "F frames the graph's selection";
  EXPECT_EQ(length(w->scene().camera.position - camera.position), 0.0f) << "and leaves the camera";

  QTest::mouseMove(v, v->rect().center());
  ASSERT_FALSE(graph->mouseOver());
  graph->setFocus();  // the keyboard on the graph, the mouse over the viewport
  const double graphZoom = graph->transform().m11();
  QTest::keyClick(graph, Qt::Key_F);
  EXPECT_GT(length(w->scene().camera.position - camera.position), 1e-4f) << "F frames the viewport's selection";
  EXPECT_EQ(graph->transform().m11(), graphZoom);
}

// Day-one expectations: Ctrl+B says what it did; X/Y/Z labels and rotation and scale fields in
// Properties; the outliner scrolls to an object picked in the viewport.
TEST(EditorDefects, SnapshotFeedbackTransformFieldsAndOutlinerScroll) {
  auto w = makeWindow();
  QApplication::setActiveWindow(w.get());
  ASSERT_TRUE(QTest::qWaitForWindowActive(w.get()));
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  QTest::keyClick(w.get(), Qt::Key_B, Qt::ControlModifier);
  EXPECT_TRUE(w->viewport()->notice().contains("Snapshot")) << "Ctrl+B confirms it took the snapshot";

  const NodeId cup = objectNamed(w->scene(), "Cup");
  w->select(cup);
  ASSERT_TRUE(QTest::qWaitFor([&] { return w->findChild<ScrubField*>("rotation1") != nullptr; }, 2000));
  auto* panel = w->findChild<ScrubField*>("position0")->parentWidget();
  int axisLabels = 0;
  for (QLabel* l : panel->findChildren<QLabel*>()) axisLabels += l->text() == "X" || l->text() == "Y" || l->text() == "Z";
  EXPECT_EQ(axisLabels, 3) << "the position row labels its fields";
  const Vec3 origin = w->scene().object(cup)->transform.transformPoint(Vec3{0.0f});
  emit w->findChild<ScrubField*>("rotation1")->edited(90.0, false);  // typed and entered
  Trs t = decompose(w->scene().object(cup)->transform);
  EXPECT_NEAR(t.rotationDegrees.y, 90.0f, 1e-3f);
  ASSERT_TRUE(QTest::qWaitFor([&] { return w->findChild<ScrubField*>("scale0") != nullptr; }, 2000));
  emit w->findChild<ScrubField*>("scale0")->edited(2.0, false);
  t = decompose(w->scene().object(cup)->transform);
  EXPECT_NEAR(t.scale.x, 2.0f, 1e-4f);
  EXPECT_NEAR(t.rotationDegrees.y, 90.0f, 1e-3f) << "scaling keeps the rotation";
  EXPECT_LT(length(w->scene().object(cup)->transform.transformPoint(Vec3{0.0f}) - origin), 1e-4f) << "and the position";
  w->undoStack()->undo();
  w->undoStack()->undo();
  t = decompose(w->scene().object(cup)->transform);
  EXPECT_NEAR(t.rotationDegrees.y, 0.0f, 1e-3f) << "each is an undo step";

  // A long outliner: the picked object scrolls into view.
  w->resize(1000, 500);
  ASSERT_TRUE(w->openFile([&] {
    const auto file = retile::test::tempDir() / "many.retile";
    EXPECT_TRUE(saveNativeScene(manyNodes(60), file).ok());
    return file;
  }()));
  QTest::qWait(100);
  auto* tree = w->findChild<QTreeWidget*>();
  const NodeId last = objectNamed(w->scene(), "Object 59");
  w->select(last);
  QTreeWidgetItem* item = outlinerItem(*w, "Object 59");
  ASSERT_TRUE(item);
  EXPECT_TRUE(tree->viewport()->rect().intersects(tree->visualItemRect(item))) << "the outliner shows the pick";
}

// Day one: Ctrl+click selects several objects (in the viewport and the outliner); a drag moves
// them all as one undo step.
TEST(EditorDefects, CtrlClickSelectsSeveralObjectsAndADragMovesThemTogether) {
  auto w = makeWindow();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  FrameView* v = w->viewport();
  const NodeId sphere = objectNamed(w->scene(), "Glossy Sphere"), cup = objectNamed(w->scene(), "Cup");
  w->select(sphere);
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 3; }));
  const QPoint onCup = pointShowing(*v, cup), onSphere = pointShowing(*v, sphere);
  ASSERT_GE(onCup.x(), 0);
  ASSERT_GE(onSphere.x(), 0);
  QTest::mouseClick(v, Qt::LeftButton, Qt::ControlModifier, onCup);
  EXPECT_EQ(w->selectedObjects(), (std::vector<NodeId>{sphere, cup}));
  EXPECT_EQ(w->selection(), cup) << "the last picked leads (gizmo, Properties)";
  int outlinedObjects = 0;
  for (QTreeWidgetItem* item : w->findChild<QTreeWidget*>()->selectedItems())
    outlinedObjects += item->text(0) == "Cup" || item->text(0) == "Glossy Sphere";
  EXPECT_EQ(outlinedObjects, 2) << "the outliner shows both";

  const Vec3 sphereAt = w->scene().object(sphere)->transform.translation();
  const Vec3 cupAt = w->scene().object(cup)->transform.translation();
  const int step = std::max(10, static_cast<int>(v->imageRect().width() / 20));
  QTest::mousePress(v, Qt::LeftButton, Qt::NoModifier, onSphere);
  for (int i = 1; i <= 4; ++i) QTest::mouseMove(v, onSphere + QPoint(step * i, 0));
  QTest::mouseRelease(v, Qt::LeftButton, Qt::NoModifier, onSphere + QPoint(4 * step, 0));
  const Vec3 sphereMoved = w->scene().object(sphere)->transform.translation() - sphereAt;
  const Vec3 cupMoved = w->scene().object(cup)->transform.translation() - cupAt;
  EXPECT_GT(length(sphereMoved), 0.05f) << "dragging one selected object";
  EXPECT_LT(length(cupMoved - sphereMoved), 1e-5f) << "moves the other by as much";
  w->undoStack()->undo();
  EXPECT_LT(length(w->scene().object(sphere)->transform.translation() - sphereAt), 1e-5f);
  EXPECT_LT(length(w->scene().object(cup)->transform.translation() - cupAt), 1e-5f) << "one undo step for both";

  QTest::mouseClick(v, Qt::LeftButton, Qt::ControlModifier, onCup);
  EXPECT_EQ(w->selectedObjects(), std::vector<NodeId>{sphere}) << "Ctrl+click again takes it out";
  EXPECT_EQ(w->selection(), sphere);
  w->select(cup);
  EXPECT_EQ(w->selectedObjects(), std::vector<NodeId>{cup}) << "a plain pick selects just it";

  // In the outliner: Ctrl+click adds, a plain click on the leading object selects just it.
  auto* tree = w->findChild<QTreeWidget*>();
  tree->setCurrentItem(outlinerItem(*w, "Glossy Sphere"), 0, QItemSelectionModel::Select);
  EXPECT_EQ(w->selectedObjects(), (std::vector<NodeId>{cup, sphere}));
  tree->setCurrentItem(outlinerItem(*w, "Glossy Sphere"), 0, QItemSelectionModel::ClearAndSelect);
  EXPECT_EQ(w->selectedObjects(), std::vector<NodeId>{sphere});
}

// A single pick is outlined too: only the gizmo showed, at the object's pivot, which in a scene
// of meshes modelled in world space (the kitchen's) lies far from what was picked.
TEST(EditorDefects, ThePickedObjectIsOutlined) {
  auto w = makeWindow();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  FrameView* v = w->viewport();
  OverlaySettings o;  // only the outline: the denoised regions' dashes are orange too
  o.priority = o.served = o.markers = o.denoised = o.reuse = o.legend = false;
  v->setOverlays(o);
  auto outlined = [&] {
    const QImage img = v->composed();
    int n = 0;
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x) {
        const QColor c = img.pixelColor(x, y);  // qRgb(255, 160, 40), blended where it is scaled
        n += c.red() > 215 && std::abs(c.green() - 160) < 40 && c.blue() < 90;
      }
    return n;
  };
  EXPECT_EQ(outlined(), 0) << "nothing picked";
  const NodeId sphere = objectNamed(w->scene(), "Glossy Sphere");
  w->select(sphere);
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 4; }));
  const int one = outlined();
  EXPECT_GT(one, 40) << "the sphere's silhouette";
  w->select(kNoNode);
  EXPECT_EQ(outlined(), 0);
}

// File > Save Image writes what the viewport shows: an artist had no way to keep a picture from
// the editor. PNG through the viewport's view and exposure, EXR linear; a bad name is an error.
TEST(EditorDefects, TheViewportsPictureSavesAsAnImage) {
  auto w = makeWindow();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 3 && f.image; }));
  QTemporaryDir dir;
  ASSERT_TRUE(dir.isValid());
  const std::filesystem::path base = dir.path().toStdString();
  auto meanOf = [](const QImage& img) {
    double sum = 0;
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x) sum += qGray(img.pixel(x, y));
    return sum / std::max(1, img.width() * img.height());
  };
  ASSERT_TRUE(w->saveImageTo(base / "shown.png")) << w->lastError().toStdString();
  const QImage shown(QString::fromStdString((base / "shown.png").string()));
  ASSERT_FALSE(shown.isNull());
  const FrameRecord& f = *w->viewport()->frame();
  EXPECT_EQ(shown.width(), f.image->width);
  EXPECT_EQ(shown.height(), f.image->height);
  EXPECT_GT(meanOf(shown), 20.0) << "the lit scene";
  DisplaySettings darker = w->viewport()->display();
  darker.exposure -= 2;
  w->viewport()->setDisplay(darker);
  ASSERT_TRUE(w->saveImageTo(base / "darker.png"));
  EXPECT_LT(meanOf(QImage(QString::fromStdString((base / "darker.png").string()))), 0.75 * meanOf(shown)) << "as the viewport shows it";

  ASSERT_TRUE(w->saveImageTo(base / "linear.exr"));
  std::ifstream exr(base / "linear.exr", std::ios::binary);
  char magic[4] = {};
  exr.read(magic, 4);
  EXPECT_EQ(std::string(magic, 4), std::string("\x76\x2f\x31\x01", 4)) << "an OpenEXR file";
  EXPECT_FALSE(w->saveImageTo(base / "picture.tiff"));
  EXPECT_TRUE(w->lastError().contains(".exr or .png")) << w->lastError().toStdString();

  // Save Image asks, in the folder of the last image saved (the working directory before),
  // with a name to take. The dialog is read and rejected; one that stays is rejected later, so
  // a failure cannot hang the suite.
  QString folder, name;
  QTimer poll;
  int polls = 0;
  QObject::connect(&poll, &QTimer::timeout, [&] {
    auto* dialog = qobject_cast<QFileDialog*>(QApplication::activeModalWidget());
    if (dialog && dialog->objectName() == "saveImageDialog" && folder.isEmpty()) {
      folder = dialog->directory().absolutePath();
      if (!dialog->selectedFiles().isEmpty()) name = QFileInfo(dialog->selectedFiles().front()).fileName();
      dialog->reject();
    } else if (dialog && ++polls > 100) {
      dialog->reject();
    }
  });
  poll.start(50);
  EXPECT_FALSE(w->saveImage()) << "rejected";
  poll.stop();
  EXPECT_EQ(folder, QDir(dir.path()).absolutePath()) << "the last image's folder";
  EXPECT_EQ(name, "retile.exr") << "the built-in scene's picture";
}

// The pixel inspector names what a pixel shows and the samples it holds (a teacher pointing at a
// tile in a pass, an artist at a noisy spot).
TEST(EditorDefects, TheInspectorSaysWhatAPixelShowsAndItsSamples) {
  auto w = makeWindow();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 3 && f.image; }));
  FrameView* v = w->viewport();
  auto* inspector = w->findChild<QLabel*>("inspector");
  ASSERT_TRUE(inspector);
  // Inside the sphere, five pixels from any other object: an edge pixel's first hit changes
  // from frame to frame with the pixel's jittered samples.
  const NodeId sphere = objectNamed(w->scene(), "Glossy Sphere");
  const auto frame = v->frame();  // held: the view may take a newer one meanwhile
  const FrameRecord& f = *frame;
  auto shows = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < f.width && y < f.height && f.image->objectId[static_cast<std::size_t>(y * f.width + x)] == sphere;
  };
  QPoint inside(-1, -1);
  for (int y = 0; y < f.height && inside.x() < 0; ++y)
    for (int x = 0; x < f.width && inside.x() < 0; ++x) {
      bool all = true;
      for (int dy = -5; dy <= 5 && all; ++dy)
        for (int dx = -5; dx <= 5 && all; ++dx) all = shows(x + dx, y + dy);
      if (all) inside = QPoint(x, y);
    }
  ASSERT_GE(inside.x(), 0) << "the sphere is in view";
  const QRectF r = v->imageRect();
  const QPoint onSphere(static_cast<int>(r.x() + (inside.x() + 0.5) * r.width() / f.width),
                        static_cast<int>(r.y() + (inside.y() + 0.5) * r.height() / f.height));
  QTest::mouseMove(v, onSphere);
  const QStringList lines = inspector->text().split('\n');
  ASSERT_GE(lines.size(), 2) << inspector->text().toStdString();
  EXPECT_TRUE(lines[1].startsWith("Glossy Sphere, ")) << lines[1].toStdString();
  EXPECT_TRUE(lines[1].endsWith(" samples")) << lines[1].toStdString();
  EXPECT_GE(lines[1].section(", ", 1).section(' ', 0, 0).toInt(), 1) << lines[1].toStdString();
}

// The pixel filter, how it is drawn and Tungsten's other conventions are render settings:
// chosen in Properties, each reaches the engine as one undo step and restarts the accumulation.
TEST(EditorDefects, ThePixelFilterIsARenderSettingWithUndo) {
  auto w = makeWindow();
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  QTreeWidgetItem* settings = outlinerItem(*w, "Render settings");
  ASSERT_TRUE(settings);
  w->findChild<QTreeWidget*>()->setCurrentItem(settings, 0, QItemSelectionModel::ClearAndSelect);
  auto* filter = w->findChild<QComboBox*>("pixelFilter");
  ASSERT_TRUE(filter);
  EXPECT_EQ(filter->currentIndex(), static_cast<int>(PixelFilter::BlackmanHarris)) << "a new scene's, as Blender's";
  filter->setCurrentIndex(static_cast<int>(PixelFilter::Tent));
  EXPECT_EQ(w->scene().settings.pixelFilter, PixelFilter::Tent);
  EXPECT_EQ(w->scene().settings.filterWidth, 2.0f) << "at its usual width";
  const std::uint64_t version = w->documentVersion();
  ASSERT_TRUE(waitForFrame(*w, [&](const FrameRecord& f) { return f.documentVersion == version; }));
  w->undoStack()->undo();
  EXPECT_EQ(w->scene().settings.pixelFilter, PixelFilter::BlackmanHarris);
  EXPECT_EQ(w->scene().settings.filterWidth, 1.5f);
  // Drawn as Tungsten draws it (what Tungsten files bring): a setting like the others.
  auto* sampling = w->findChild<QComboBox*>("filterSampling");
  ASSERT_TRUE(sampling);
  EXPECT_EQ(sampling->currentIndex(), static_cast<int>(FilterSampling::Exact));
  sampling->setCurrentIndex(static_cast<int>(FilterSampling::SteppedTable));
  EXPECT_EQ(w->scene().settings.filterSampling, FilterSampling::SteppedTable);
  w->undoStack()->undo();
  EXPECT_EQ(w->scene().settings.filterSampling, FilterSampling::Exact);
  // So are the other conventions Tungsten files bring: its shading normals, its Russian roulette
  // and where its rays leave a surface. Each is another trace kernel: switching it must reach the
  // renderer and be rendered, and undo must bring ours back.
  auto switchToTungsten = [&](const char* name, auto field) {
    SCOPED_TRACE(name);
    auto* box = w->findChild<QComboBox*>(name);
    ASSERT_TRUE(box);
    EXPECT_EQ(box->currentIndex(), 0) << "ours, in a new scene";
    box->setCurrentIndex(1);
    EXPECT_EQ(static_cast<int>(w->scene().settings.*field), 1);
    const std::uint64_t switched = w->documentVersion();
    ASSERT_TRUE(waitForFrame(*w, [&](const FrameRecord& f) { return f.documentVersion == switched; }));
    w->undoStack()->undo();
    EXPECT_EQ(static_cast<int>(w->scene().settings.*field), 0);
  };
  switchToTungsten("shading", &RenderSettings::shading);
  switchToTungsten("roulette", &RenderSettings::roulette);
  switchToTungsten("rayOffset", &RenderSettings::rayOffset);
}

}  // namespace
}  // namespace retile::ui
