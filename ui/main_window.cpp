#include "main_window.h"

#include <QAction>
#include <QActionGroup>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QColorDialog>
#include <QComboBox>
#include <QDateTime>
#include <QDir>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileInfo>
#include <QMimeData>
#include <QSettings>
#include <QStandardPaths>
#include <QTimer>
#include <QUrl>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QGroupBox>
#include <QScrollArea>
#include <QVBoxLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QKeyEvent>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QSlider>
#include <QScopedValueRollback>
#include <QScrollBar>
#include <QSpinBox>
#include <QStatusBar>
#include <QTreeWidget>

#include <cmath>
#include <numeric>
#include <optional>

#include "edit_command.h"
#include "fields.h"
#include "live_chart.h"
#include "method_panel.h"
#include "node_graph.h"
#include "retile/color.h"
#include "vulkan_viewport.h"
#include "retile/io.h"
#include "retile/log.h"

namespace retile::ui {

namespace {

constexpr int kIdRole = Qt::UserRole + 1;
constexpr int kKindRole = Qt::UserRole + 2;  // a PropertyTarget::Kind

QString inspectorHint() { return MainWindow::tr("Hover the image for linear values; Ctrl+drag a region for its mean, min and max."); }

}  // namespace

MainWindow::MainWindow(Scene scene, std::filesystem::path file, EditorOptions options, QWidget* parent)
    : QMainWindow(parent), options_(options), doc_(std::move(scene)), file_(std::move(file)) {
  view_ = new FrameView(this);
  setCentralWidget(view_);
  if (options_.keepLayout) options_.cameraFraming = QSettings().value("viewport/cameraFraming", options_.cameraFraming).toBool();
  buildDocks();
  buildMenus();
  // Left: the active tool (it carries over between selections), replaced for a while by a
  // message; right: the render's figures.
  toolLabel_ = new QLabel(this);
  toolLabel_->setObjectName("toolStatus");
  statusBar()->addWidget(toolLabel_);
  status_ = new QLabel(this);
  status_->setObjectName("renderStatus");
  statusBar()->addPermanentWidget(status_);
  showTool();
  for (PropertyPanel* p : {panel_, renderPanel_}) connect(p, &PropertyPanel::message, this, &MainWindow::notify);
  connectViewport();
  // The render size follows the viewport (docks moved, window resized), once the size settles:
  // every resize restarts the accumulation.
  resizeTimer_.setSingleShot(true);
  resizeTimer_.setInterval(150);
  connect(&resizeTimer_, &QTimer::timeout, this, [this] { updateRenderSize(); });
  connect(view_, &FrameView::resized, this, [this] { resizeTimer_.start(); });
  setAcceptDrops(true);
  startAutosave();
  connect(&undo_, &QUndoStack::cleanChanged, this, [this] { updateTitle(); });
  updateTitle();
  resize(1280, 800);
  if (options_.keepLayout) {
    QSettings settings;
    restoreGeometry(settings.value("window/geometry").toByteArray());
    restoreState(settings.value("window/docks").toByteArray());
  }
  startEngine(doc_.scene());
  applySceneView();
  rebuildOutliner();
  rebuildProperties();
  log(tr("viewport: %1").arg(view_->presentation()));
  connect(view_, &FrameView::presentationChanged, this,
          [this](const QString& p) { log(tr("viewport: presentation failed; now drawn as a %1").arg(p)); });
}

// Picking, focus points, the pixel inspector.
void MainWindow::connectViewport() {
  connect(view_, &FrameView::objectPicked, this, [this](quint64 id) { select(static_cast<NodeId>(id)); });
  connect(view_, &FrameView::objectToggled, this, [this](quint64 id) { toggleSelected(static_cast<NodeId>(id)); });
  connect(view_, &FrameView::focusPlaced, this, [this](QPointF p) {
    if (methodPanel_->focusMode() == MethodPanel::FocusMode::Cursor) return;  // the cursor places it
    const bool follows = methodPanel_->focusMode() == MethodPanel::FocusMode::Follows;
    // Up to three points: a fourth replaces the oldest.
    std::vector<FocusPoint> focus = methodPanel_->settings().focus;
    if (focus.size() >= 3) focus.erase(focus.begin());
    focus.push_back(FocusPoint{Vec2{static_cast<float>(p.x()), static_cast<float>(p.y())}, follows});
    methodPanel_->setFocus(focus);
    engine_->submit(FocusCommand{focus});
    log(tr("focus point %1 at %2, %3%4")
            .arg(focus.size())
            .arg(p.x(), 0, 'f', 0)
            .arg(p.y(), 0, 'f', 0)
            .arg(follows ? tr(", following the object") : QString()));
  });
  connect(view_, &FrameView::pixelInspected, this, [this](QPoint px, QVector3D c) {
    pixelText_ = tr("pixel %1, %2: R %3  G %4  B %5 (linear)")
                     .arg(px.x())
                     .arg(px.y())
                     .arg(c.x(), 0, 'f', 4)
                     .arg(c.y(), 0, 'f', 4)
                     .arg(c.z(), 0, 'f', 4);
    // What the pixel shows and how many samples it holds: where a pass stands, pixel by pixel.
    if (const auto samples = view_->samplesAt(px)) {
      const Object* o = doc_.scene().object(view_->objectAt(px));
      const QString what = o ? QString::fromStdString(o->name) : tr("background");
      const double n = std::round(*samples);
      pixelText_ += n == 1 ? tr("\n%1, 1 sample").arg(what) : tr("\n%1, %2 samples").arg(what).arg(n, 0, 'f', 0);
    }
    inspector_->setText(pixelText_ + (regionText_.isEmpty() ? QString() : "\n\n" + regionText_));
    // An eye-tracker stand-in: the focus point follows the cursor, at most ten times a second.
    if (methodPanel_->focusMode() == MethodPanel::FocusMode::Cursor && focusTimer_.elapsed() > 100) {
      focusTimer_.restart();
      methodPanel_->setFocus({FocusPoint{Vec2{px.x() + 0.5f, px.y() + 0.5f}, false}});
      engine_->submit(FocusCommand{methodPanel_->settings().focus});
    }
  });
  connect(view_, &FrameView::regionInspected, this, [this](QRect r, QVector3D mean, QVector3D lo, QVector3D hi) {
    auto v = [](QVector3D c) { return QString("%1  %2  %3").arg(c.x(), 0, 'f', 4).arg(c.y(), 0, 'f', 4).arg(c.z(), 0, 'f', 4); };
    regionText_ = tr("region %1x%2 at %3, %4\nmean %5\nmin  %6\nmax  %7")
                      .arg(r.width())
                      .arg(r.height())
                      .arg(r.x())
                      .arg(r.y())
                      .arg(v(mean), v(lo), v(hi));
    inspector_->setText((pixelText_.isEmpty() ? QString() : pixelText_ + "\n\n") + regionText_);
  });
  focusTimer_.start();
  connectDrags();
}

// Camera navigation, the selection moved in the screen plane or along the gizmo's arrows, turned
// and scaled; each whole drag is one undo step.
void MainWindow::connectDrags() {
  // Camera navigation (Alt + left/middle/right, wheel) and moving the selection in the screen
  // plane; each whole drag is one undo step.
  connect(view_, &FrameView::dragFinished, this, [this] { ++dragCounter_; });
  connect(view_, &FrameView::orbitDragged, this, [this](QPointF d) {
    editCamera(
        [d](Camera& c) {
          Vec3 offset = c.position - c.target;
          float yaw = static_cast<float>(-d.x() * 0.008), pitch = static_cast<float>(-d.y() * 0.008);
          Mat4 turn = Mat4::rotateY(yaw);
          offset = turn.transformPoint(offset);
          Vec3 right = normalize(cross(normalize(c.target - c.position), c.up));
          // Rodrigues' rotation of the offset about the camera's right axis.
          Vec3 tilted =
              offset * std::cos(pitch) + cross(right, offset) * std::sin(pitch) + right * (dot(right, offset) * (1.0f - std::cos(pitch)));
          // Stay clear of the poles, where "up" would flip.
          if (std::abs(dot(normalize(tilted), Vec3{0, 1, 0})) < 0.97f) offset = tilted;
          c.position = c.target + offset;
        },
        tr("Orbit"));
  });
  connect(view_, &FrameView::panDragged, this, [this](QPointF d) {
    editCamera(
        [this, d](Camera& c) {
          Vec3 fwd = normalize(c.target - c.position);
          Vec3 right = normalize(cross(fwd, c.up)), up = cross(right, fwd);
          float k = 2.0f * length(c.target - c.position) * std::tan(c.verticalFov * 0.5f) /
                    static_cast<float>(std::max(1.0, view_->imageRect().height()));
          Vec3 move = right * static_cast<float>(-d.x() * k) + up * static_cast<float>(d.y() * k);
          c.position = c.position + move;
          c.target = c.target + move;
        },
        tr("Pan"));
  });
  connect(view_, &FrameView::dollyDragged, this, [this](double a) {
    editCamera([a](Camera& c) { c.position = c.target + (c.position - c.target) * static_cast<float>(std::exp(-a)); }, tr("Dolly"));
  });
  connect(view_, &FrameView::objectDragged, this, [this](QPointF d) {
    const Object* o = doc_.scene().object(selection_);
    auto frame = view_->frame();
    if (!o || !frame) return;
    const Camera& c = doc_.scene().camera;
    Vec3 fwd = normalize(c.target - c.position);
    Vec3 right = normalize(cross(fwd, c.up)), up = cross(right, fwd);
    // The object follows the cursor at the depth of its bounds' centre, the point the gizmo and the
    // pivot use: imported meshes often sit far from their transform's origin. The rest of a
    // multi-selection moves with it.
    Vec3 at = pivot(*o);
    float depth = std::max(0.01f, dot(at - c.position, fwd));
    float k = 2.0f * depth * std::tan(c.verticalFov * 0.5f) / static_cast<float>(frame->height);
    const Mat4 move = Mat4::translate(right * static_cast<float>(d.x() * k) - up * static_cast<float>(d.y() * k));
    editSelected([&](Object& x) { x.transform = move * x.transform; }, tr("Move %1"));
  });
  connect(view_, &FrameView::renderRegionDrawn, this, [this](QRect r) {
    engine_->submit(RegionCommand{RegionRect{r.x(), r.y(), r.width(), r.height()}});
    log(tr("render region %1x%2 at %3, %4 (Render > Clear render region, or Ctrl+Alt+R)")
            .arg(r.width())
            .arg(r.height())
            .arg(r.x())
            .arg(r.y()));
  });
  // The gizmo: drag an arrow to move along a world axis; E and R turn and scale about the origin.
  connect(view_, &FrameView::axisDragged, this, [this](int axis, QPointF d) {
    const Object* o = doc_.scene().object(selection_);
    const FrameView::Gizmo& g = gizmo_;
    if (!o || !g.visible) return;
    const QPointF dir = g.axisEnd[axis] - g.origin;  // image pixels per gizmoLength_ world units
    const double len2 = dir.x() * dir.x() + dir.y() * dir.y();
    if (len2 < 1e-6) return;
    const float t = static_cast<float>((d.x() * dir.x() + d.y() * dir.y()) / len2) * gizmoLength_;
    Vec3 step{0.0f};
    (axis == 0 ? step.x : axis == 1 ? step.y : step.z) = t;
    editSelected([&](Object& x) { x.transform = Mat4::translate(step) * x.transform; }, tr("Move %2 along %1").arg(QChar('x' + axis)));
  });
  auto aboutOrigin = [this](const Mat4& m, const QString& what) {
    // A multi-selection turns and scales as a group, about the centre of its pivots.
    Vec3 at{0.0f};
    int n = 0;
    for (NodeId id : selected_)
      if (const Object* o = doc_.scene().object(id)) at = at + pivot(*o), ++n;
    if (n == 0) return;
    at = at / static_cast<float>(n);
    const Mat4 about = Mat4::translate(at) * m * Mat4::translate(at * -1.0f);
    editSelected([&](Object& x) { x.transform = about * x.transform; }, what);
  };
  connect(view_, &FrameView::rotateDragged, this,
          [aboutOrigin](double px) { aboutOrigin(Mat4::rotateY(static_cast<float>(px * 0.01)), tr("Rotate %1")); });
  connect(view_, &FrameView::scaleDragged, this, [aboutOrigin](double px) {
    const float s = static_cast<float>(std::exp(px * 0.005));
    aboutOrigin(Mat4::scale(Vec3{s, s, s}), tr("Scale %1"));
  });
}

MainWindow::~MainWindow() {
  if (engine_) engine_->stop();  // before any member the callback might touch goes away
}

void MainWindow::setRenderPaused(bool paused) {
  paused_ = paused;
  engine_->submit(PauseCommand{paused});
  view_->setPaused(paused);
  log(paused ? tr("paused: the accumulated samples are kept") : tr("resumed"));
}

void MainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  file->addAction(tr("&New (built-in scene)"), QKeySequence::New, this, [this] {
    if (!maybeSave()) return;
    replaceDocument(makeDefaultScene(), {});
    log(tr("new document from the built-in scene"));
  });
  file->addAction(tr("&Open..."), QKeySequence::Open, this, [this] {
    if (!maybeSave()) return;
    QString f = QFileDialog::getOpenFileName(this, tr("Open scene"), QString(),
                                             tr("Scenes (*.json *.retile *.gltf *.glb *.obj *.fbx *.ply *.dae);;All files (*)"));
    if (!f.isEmpty()) openFile(f.toStdString());
  });
  recentMenu_ = file->addMenu(tr("Open &Recent"));
  connect(recentMenu_, &QMenu::aboutToShow, this, [this] { rebuildRecentMenu(); });
  file->addAction(tr("&Save"), QKeySequence::Save, this, [this] {
    // Imported files (glTF, scene.json) are not overwritten in another format: ask for a .retile.
    if (file_.empty() || file_.extension() != ".retile") saveAs();
    else saveTo(file_);
  });
  // Spelled out: QKeySequence::SaveAs is empty on desktops without a key theme.
  file->addAction(tr("Save &As..."), QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_S), this, [this] { saveAs(); });
  // Not Ctrl+E: on X11 a focused text field takes it (end of line).
  file->addAction(tr("Save &Image..."), QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_E), this, [this] { saveImage(); });
  file->addSeparator();
  file->addAction(tr("&Quit"), QKeySequence::Quit, this, &QWidget::close);

  QMenu* editMenu = menuBar()->addMenu(tr("&Edit"));
  QAction* undo = undo_.createUndoAction(this, tr("&Undo"));
  undo->setShortcut(QKeySequence::Undo);
  QAction* redo = undo_.createRedoAction(this, tr("&Redo"));
  // Ctrl+Y as well as the platform's redo (Ctrl+Shift+Z here): artists bring either habit.
  QList<QKeySequence> redoKeys = QKeySequence::keyBindings(QKeySequence::Redo);
  for (const QKeySequence& k : {QKeySequence(Qt::CTRL | Qt::Key_Y), QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_Z)})
    if (!redoKeys.contains(k)) redoKeys << k;
  redo->setShortcuts(redoKeys);
  editMenu->addAction(undo);
  editMenu->addAction(redo);

  QMenu* viewMenu = menuBar()->addMenu(tr("&Overlays"));
  auto toggle = [&](const QString& name, bool OverlaySettings::*field) {
    QAction* a = viewMenu->addAction(name);
    a->setCheckable(true);
    a->setChecked(view_->overlays().*field);
    connect(a, &QAction::toggled, this, [this, field](bool on) {
      OverlaySettings o = view_->overlays();
      o.*field = on;
      view_->setOverlays(o);
    });
  };
  toggle(tr("Tile &priority heat map"), &OverlaySettings::priority);
  toggle(tr("&Indirection classes (high / middle / low)"), &OverlaySettings::classes);
  toggle(tr("Tile &order numbers"), &OverlaySettings::order);
  toggle(tr("&Samples per tile"), &OverlaySettings::samples);
  toggle(tr("Tiles served this &frame"), &OverlaySettings::served);
  toggle(tr("Point of change and &focus points"), &OverlaySettings::markers);
  toggle(tr("&Denoised regions"), &OverlaySettings::denoised);
  toggle(tr("&Reused and rejected histories"), &OverlaySettings::reuse);
  toggle(tr("&Legend"), &OverlaySettings::legend);

  QMenu* tools = menuBar()->addMenu(tr("&Tools"));
  auto* toolGroup = new QActionGroup(this);
  auto tool = [&](const QString& name, FrameView::Tool t, Qt::Key key) {
    QAction* a = tools->addAction(name, QKeySequence(key), this, [this, t] {
      view_->setTool(t);
      showTool();
    });
    a->setCheckable(true);
    a->setChecked(t == view_->tool());
    toolGroup->addAction(a);
  };
  tool(tr("&Select (Q)"), FrameView::Tool::Select, Qt::Key_Q);
  tool(tr("&Move (W): drag the selection or a gizmo arrow"), FrameView::Tool::Move, Qt::Key_W);
  tool(tr("&Rotate (E): drag turns about y"), FrameView::Tool::Rotate, Qt::Key_E);
  tool(tr("S&cale (R): drag scales"), FrameView::Tool::Scale, Qt::Key_R);

  QMenu* compare = menuBar()->addMenu(tr("&Compare"));
  compare->addAction(tr("Take &snapshot (B)"), QKeySequence(Qt::CTRL | Qt::Key_B), this, [this] {
    view_->takeSnapshot();
    log(tr("snapshot taken: B in the A/B compare"));
  });
  auto* modes = new QActionGroup(this);
  auto mode = [&, modes](const QString& name, FrameView::Compare c, const QKeySequence& key) {
    QAction* a = compare->addAction(name, key, this, [this, c, modes] {
      if (c == FrameView::Compare::Off && graph_ && graph_->mouseOver()) {
        // A acts on the panel under the mouse: over the node graph it frames the graph.
        graph_->frameAll();
        for (QAction* m : modes->actions()) m->setChecked(m->data().toInt() == static_cast<int>(view_->compare()));
        return;
      }
      if (!view_->hasSnapshot()) log(tr("compare: take a snapshot first (Ctrl+B)"));
      view_->setCompare(c);
    });
    a->setData(static_cast<int>(c));
    a->setCheckable(true);
    a->setChecked(c == FrameView::Compare::Off);
    modes->addAction(a);
  };
  mode(tr("&Live render (A)"), FrameView::Compare::Off, QKeySequence(Qt::Key_A));
  mode(tr("S&napshot (B)"), FrameView::Compare::Toggle, QKeySequence(Qt::Key_B));
  mode(tr("&Wipe A/B (drag the line)"), FrameView::Compare::Wipe, QKeySequence(Qt::SHIFT | Qt::Key_B));

  QMenu* render = menuBar()->addMenu(tr("&Render"));
  QMenu* scale = render->addMenu(tr("Render &resolution"));
  auto* scales = new QActionGroup(this);
  for (int k : {1, 2, 3, 4}) {
    QAction* a = scale->addAction(k == 1 ? tr("Full viewport") : tr("1/%1 of the viewport").arg(k));
    a->setCheckable(true);
    a->setChecked(k == options_.renderScale);
    scales->addAction(a);
    connect(a, &QAction::triggered, this, [this, k] {
      options_.renderScale = k;
      options_.initialRenderSize = QSize();
      updateRenderSize();
    });
  }
  QMenu* framing = render->addMenu(tr("&Framing"));
  auto* framings = new QActionGroup(this);
  for (bool camera : {false, true}) {
    QAction* a = framing->addAction(camera ? tr("As the scene's &resolution (letterboxed)") : tr("&Fill the viewport"));
    a->setObjectName(camera ? "framingCamera" : "framingViewport");
    a->setCheckable(true);
    a->setChecked(camera == options_.cameraFraming);
    framings->addAction(a);
    connect(a, &QAction::triggered, this, [this, camera] {
      options_.cameraFraming = camera;
      updateRenderSize();
    });
  }
  render->addAction(tr("&Clear render region"), QKeySequence(Qt::CTRL | Qt::ALT | Qt::Key_R), this, [this] {
    engine_->submit(RegionCommand{});
    log(tr("render region cleared: the whole image renders"));
  });
  QAction* pause = render->addAction(tr("&Pause / resume"));
  pause->setObjectName("pauseAction");
  pause->setShortcut(Qt::Key_Escape);
  connect(pause, &QAction::triggered, this, [this] { setRenderPaused(!paused_); });
  // A pass followed frame by frame: which tiles come next and how the denoised region grows.
  QAction* step = render->addAction(tr("&Step one frame (pauses)"));
  step->setObjectName("stepAction");
  step->setShortcut(Qt::Key_Period);
  connect(step, &QAction::triggered, this, [this] {
    if (!paused_) setRenderPaused(true);
    engine_->submit(StepCommand{1});
  });

  // Every panel, so that a closed one comes back (the docks exist by now).
  QMenu* windows = menuBar()->addMenu(tr("&Window"));
  windows->setObjectName("windowMenu");
  for (QDockWidget* d : findChildren<QDockWidget*>()) windows->addAction(d->toggleViewAction());
}

QDockWidget* MainWindow::addDock(const QString& title, const char* name, QWidget* content, Qt::DockWidgetArea area) {
  auto* dock = new QDockWidget(title, this);
  dock->setObjectName(name);  // saved layouts find docks by name
  dock->setWidget(content);
  addDockWidget(area, dock);
  return dock;
}

// Objects, materials, lights and the scene's singletons; picking in it selects, Ctrl+click adds,
// editing a name renames, the check box shows or hides.
QTreeWidget* MainWindow::buildOutliner() {
  outliner_ = new QTreeWidget(this);
  outliner_->setHeaderLabels({tr("Name"), tr("Material / kind")});
  outliner_->header()->setSectionResizeMode(0, QHeaderView::Stretch);
  outliner_->setSelectionMode(QAbstractItemView::ExtendedSelection);  // Ctrl+click adds objects
  connect(outliner_, &QTreeWidget::itemSelectionChanged, this, [this] {
    auto items = outliner_->selectedItems();
    if (items.isEmpty()) return;
    std::vector<NodeId> objects;
    for (QTreeWidgetItem* item : items)
      if (static_cast<PropertyTarget::Kind>(item->data(0, kKindRole).toInt()) == PropertyTarget::Kind::Object)
        objects.push_back(static_cast<NodeId>(item->data(0, kIdRole).toULongLong()));
    if (objects.size() > 1) {
      // The current item leads when it is one of them (the one just Ctrl+clicked).
      const auto current = static_cast<NodeId>(outliner_->currentItem() ? outliner_->currentItem()->data(0, kIdRole).toULongLong() : 0);
      selected_ = objects;
      selection_ = std::find(objects.begin(), objects.end(), current) != objects.end() ? current : objects.back();
      applySelection();
      return;
    }
    if (items.size() > 1) items = {outliner_->currentItem() ? outliner_->currentItem() : items[0]};
    bool ok = false;
    qulonglong id = items[0]->data(0, kIdRole).toULongLong(&ok);
    auto kind = static_cast<PropertyTarget::Kind>(items[0]->data(0, kKindRole).toInt());
    if (kind == PropertyTarget::Kind::Object) {
      if (!ok || !id || !doc_.scene().object(static_cast<NodeId>(id))) return;
      if (id != selection_ || selected_.size() > 1) select(static_cast<NodeId>(id));    // a plain click ends a multi-selection
      else panel_->setTarget({PropertyTarget::Kind::Object, static_cast<NodeId>(id)});  // back from the camera, say
    } else if (kind != PropertyTarget::Kind::None) {
      panel_->setTarget({kind, static_cast<NodeId>(id)});
    }
  });
  connect(outliner_, &QTreeWidget::itemChanged, this, [this](QTreeWidgetItem* item, int column) {
    NodeId id = static_cast<NodeId>(item->data(0, kIdRole).toULongLong());
    if (column != 0) return;
    const std::string name = item->text(0).toStdString();
    const bool shown = item->checkState(0) == Qt::Checked;
    if (const Material* m = doc_.scene().material(id)) {
      if (name.empty() || name == m->name) return;
      Material after = *m;
      after.name = name;
      edit(SetMaterial{*m}, SetMaterial{after}, tr("Rename material"));
      return;
    }
    if (const Light* l = doc_.scene().light(id)) {
      if ((name.empty() || name == l->name) && shown == l->visible) return;
      Light after = *l;
      if (!name.empty()) after.name = name;
      after.visible = shown;
      edit(SetLight{*l}, SetLight{after}, shown != l->visible ? tr("Show/hide %1").arg(item->text(0)) : tr("Rename light"));
      return;
    }
    const Object* o = doc_.scene().object(id);
    if (!o) return;
    Object after = *o;
    after.name = item->text(0).toStdString();
    after.visible = item->checkState(0) == Qt::Checked;
    if (after.name == o->name && after.visible == o->visible) return;
    edit(SetObject{*o}, SetObject{after}, after.visible != o->visible ? tr("Show/hide %1").arg(item->text(0)) : tr("Rename object"));
  });
  return outliner_;
}

// The viewport's view transform, exposure and gamma: display only, no sample is lost.
QGroupBox* MainWindow::buildDisplayBox(QWidget* parent) {
  auto* displayBox = new QGroupBox(tr("Display (viewport only)"), parent);
  auto* df = new QFormLayout(displayBox);
  auto* viewBox = new QComboBox(displayBox);
  displayView_ = viewBox;
  viewBox->setObjectName("displayView");
  try {
    for (const auto& v : ColorConfig::get()->views()) viewBox->addItem(QString::fromStdString(v));
  } catch (const std::exception& e) {
    log(tr("colour config: %1").arg(e.what()));
  }
  viewBox->setCurrentText(QString::fromStdString(view_->display().view));
  auto* exposure = new ScrubField(0.0, -16.0, 16.0, 0.0, 2, displayBox);
  exposure->setObjectName("exposure");
  exposure->setSuffix(tr(" stops"));
  auto* gamma = new ScrubField(1.0, 0.1, 5.0, 1.0, 2, displayBox);
  gamma->setObjectName("gamma");
  df->addRow(tr("View"), viewBox);
  df->addRow(tr("Exposure"), exposure);
  df->addRow(tr("Gamma"), gamma);
  auto applyDisplay = [this, viewBox, exposure, gamma] {
    DisplaySettings d;
    d.view = viewBox->currentText().toStdString();
    d.exposure = static_cast<float>(exposure->value());
    d.gamma = static_cast<float>(gamma->value());
    view_->setDisplay(d);
  };
  connect(viewBox, &QComboBox::currentTextChanged, this, applyDisplay);
  connect(exposure, &ScrubField::edited, this, applyDisplay);
  connect(gamma, &ScrubField::edited, this, applyDisplay);
  return displayBox;
}

void MainWindow::buildDocks() {
  auto* outlinerDock = addDock(tr("Outliner"), "outliner", buildOutliner(), Qt::LeftDockWidgetArea);

  // Each panel's edits name it (`who`, the member that holds it): it shows them already, and
  // rebuilding it would drop the field being scrubbed; the other panel, which may show the same
  // thing (the render settings), rebuilds.
  auto pushFrom = [this](PropertyPanel* const* who) {
    return [this, who](const Edit& before, const Edit& after, const QString& text, int dragId) {
      QScopedValueRollback<PropertyPanel*> fromPanel(panelEdit_, *who);
      edit(before, after, text, dragId);
    };
  };
  auto sceneRef = [this]() -> const Scene& { return doc_.scene(); };
  // A colour tried in the dialog: shown in the document and the render, not an undo step.
  auto previewFrom = [this](PropertyPanel* const* who) {
    return [this, who](const Edit& e) {
      QScopedValueRollback<PropertyPanel*> fromPanel(panelEdit_, *who);
      applyToDocument(e);
    };
  };
  panel_ = new PropertyPanel(sceneRef, pushFrom(&panel_), previewFrom(&panel_), this);
  panel_->setObjectName("propertyPanel");
  auto* propDock = addDock(tr("Properties"), "properties", panel_, Qt::RightDockWidgetArea);

  // Render settings: the method and its parameters, the display transform (display only: no
  // samples are lost), and the scene's render settings.
  auto* settingsPanel = new QWidget(this);
  auto* sl = new QVBoxLayout(settingsPanel);
  methodPanel_ = new MethodPanel(editorMethod(), settingsPanel);
  connect(methodPanel_, &MethodPanel::changed, this, [this](const MethodSettings& m) {
    engine_->submit(MethodCommand{m});
    log(tr("method %1, T=%2, Q=%3%4")
            .arg(QString::fromStdString(methodLabel(m)))
            .arg(m.tileSize)
            .arg(m.quality ? QString::number(m.quality) : tr("auto"),
                 m.denoise ? tr(", denoise threshold %1 % of the image").arg(std::lround(m.denoiseThreshold * 100)) : QString()));
  });
  connect(methodPanel_, &MethodPanel::refused, this, [this](const QString& why) { log(tr("method: %1").arg(why)); });
  connect(methodPanel_, &MethodPanel::focusCleared, this, [this] {
    engine_->submit(FocusCommand{{}});
    log(tr("focus points cleared"));
  });
  sl->addWidget(methodPanel_);

  sl->addWidget(buildDisplayBox(settingsPanel));

  renderPanel_ = new PropertyPanel(sceneRef, pushFrom(&renderPanel_), previewFrom(&renderPanel_), settingsPanel);
  renderPanel_->setTarget({PropertyTarget::Kind::Render, kNoNode});
  renderPanel_->setMinimumHeight(130);
  sl->addWidget(renderPanel_, 1);
  // Scrolls rather than forcing the window taller than small screens.
  auto* settingsScroll = new QScrollArea(this);
  settingsScroll->setWidgetResizable(true);
  settingsScroll->setFrameShape(QFrame::NoFrame);
  settingsScroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  settingsScroll->setWidget(settingsPanel);
  auto* methodDock = addDock(tr("Render settings"), "renderSettings", settingsScroll, Qt::LeftDockWidgetArea);

  // The pixel inspector: linear values under the cursor; Ctrl+drag a region for its statistics.
  auto* inspectorPanel = new QWidget(this);
  auto* il = new QVBoxLayout(inspectorPanel);
  auto* inspectSource = new QComboBox(inspectorPanel);
  inspectSource->setObjectName("inspectSource");
  inspectSource->addItems({tr("Read the image as shown"), tr("Read the raw accumulation")});
  inspectSource->setToolTip(tr("With denoising the image shown is a view; the accumulated samples are kept as they are"));
  connect(inspectSource, &QComboBox::currentIndexChanged, this,
          [this](int i) { view_->setInspect(i == 1 ? FrameView::Inspect::Raw : FrameView::Inspect::Shown); });
  inspector_ = new QLabel(inspectorHint(), inspectorPanel);
  inspector_->setObjectName("inspector");
  inspector_->setWordWrap(true);
  inspector_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  inspector_->setAlignment(Qt::AlignTop | Qt::AlignLeft);
  il->addWidget(inspectSource);
  il->addWidget(inspector_, 1);
  auto* inspectorDock = addDock(tr("Pixel inspector"), "inspectorDock", inspectorPanel, Qt::LeftDockWidgetArea);
  tabifyDockWidget(methodDock, inspectorDock);
  methodDock->raise();

  log_ = new QPlainTextEdit(this);
  log_->setReadOnly(true);
  log_->setMaximumBlockCount(2000);
  auto* logDock = addDock(tr("Log"), "log", log_, Qt::BottomDockWidgetArea);

  graph_ = new NodeGraphView(this);
  graph_->setObjectName("nodeGraph");
  graph_->setDocument(doc_.scene());
  connect(graph_, &NodeGraphView::editRequested, this, [this](const GraphEdit& g) {
    // One undo step for the whole gesture (a delete clears references before removing).
    undo_.beginMacro(g.text);
    for (const auto& [before, after] : g.steps) edit(before, after, g.text);
    undo_.endMacro();
    panel_->rebuild();
  });
  connect(graph_, &NodeGraphView::objectSelected, this, [this](quint64 id) { select(static_cast<NodeId>(id)); });
  auto* graphDock = addDock(tr("Node graph"), "nodeGraphDock", graph_, Qt::BottomDockWidgetArea);

  chart_ = new LiveChart(this);
  chart_->setObjectName("liveChart");
  connect(chart_, &LiveChart::referenceRequested, this, [this] {
    Scene s = doc_.scene();
    s.settings.width = renderSize_.width();
    s.settings.height = renderSize_.height();
    chart_->renderReference(s, doc_.version(), 256);
    log(tr("rendering a 256 spp reference of the current state in the background"));
  });
  auto* chartDock = addDock(tr("Live chart"), "chartDock", chart_, Qt::BottomDockWidgetArea);
  tabifyDockWidget(graphDock, chartDock);
  tabifyDockWidget(graphDock, logDock);
  graphDock->raise();
  // The viewport keeps most of the window; the panels take what they need.
  // (After the first layout: before it, the docks have no sizes to take from.)
  // Every drop-down and number field keeps its arrows: they shrink to a few characters (the
  // text elides) before the panel gets narrower than they need.
  for (QComboBox* c : settingsPanel->findChildren<QComboBox*>()) {
    c->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
    c->setMinimumContentsLength(6);
  }
  QTimer::singleShot(0, this, [this, outlinerDock, propDock, graphDock, settingsScroll] {
    const int left =
        std::max(330, settingsScroll->widget()->minimumSizeHint().width() + settingsScroll->verticalScrollBar()->sizeHint().width() + 8);
    resizeDocks({outlinerDock, propDock}, {left, 360}, Qt::Horizontal);
    resizeDocks({graphDock}, {230}, Qt::Vertical);
    graph_->frameAll();
  });
}

QSize MainWindow::desiredRenderSize() const {
  QSize base = options_.initialRenderSize;
  if (base.isEmpty()) {
    // The viewport's size (and so its aspect: the image fills it) at the render scale.
    const QSize v = view_->imageArea().size().toSize();
    const int k = std::max(1, options_.renderScale);
    base = QSize(std::max(64, v.width() / k), std::max(36, v.height() / k));
  }
  const RenderSettings& r = doc_.scene().settings;
  if (!options_.cameraFraming) return base;
  // The largest image of the scene's aspect within that; the view letterboxes it.
  const double aspect = static_cast<double>(r.width) / r.height;
  int w = base.width(), h = static_cast<int>(std::lround(w / aspect));
  if (h > base.height()) {
    h = base.height();
    w = static_cast<int>(std::lround(h * aspect));
  }
  return QSize(std::max(16, w), std::max(16, h));
}

void MainWindow::updateRenderSize() {
  const QSize size = desiredRenderSize();
  if (size != renderSize_) {
    renderSize_ = size;
    if (engine_) engine_->submit(ResizeCommand{size.width(), size.height()});
  }
  // The render settings show the viewport's size and framing (in place: this may run inside a
  // panel's drag).
  for (PropertyPanel* p : {panel_, renderPanel_})
    if (p) p->setRenderSize(renderSize_, options_.cameraFraming);
}

void MainWindow::startEngine(Scene scene) {
  if (engine_) engine_->stop();
  const QSize size = desiredRenderSize();
  renderSize_ = size;
  scene.settings.width = size.width();
  scene.settings.height = size.height();
  EngineOptions engineOptions;
  engineOptions.documentVersion = doc_.version();
  engineOptions.previewBlock = options_.previewBlock;
  engine_ = std::make_unique<Engine>(std::move(scene), methodPanel_->settings(), engineOptions);
  // Until the new scene's first frame (its BVH built and uploaded: seconds for a million
  // triangles), neither the viewport nor the status bar may go on showing the old one's.
  view_->clearFrame(tr("Preparing %1 for the renderer...").arg(documentName()));
  status_->setText(tr("preparing %1").arg(documentName()));
  engine_->setFrameCallback([this] {
    QMetaObject::invokeMethod(
        this, [this] { onFrame(); }, Qt::QueuedConnection);
  });
  engine_->start();
  fpsStart_ = QDateTime::currentMSecsSinceEpoch();
  framesSeen_ = 0;
}

void MainWindow::onFrame() {
  if (!engine_) return;
  auto frame = engine_->latestFrame();
  for (const auto& e : engine_->takeErrors()) {
    // A missing file the import reported comes back from the scene's upload in other words.
    const std::string warning = "warning: ";
    if (e.starts_with(warning) && importReported(e.substr(warning.size()), importWarnings_)) continue;
    log(QString::fromStdString(e));
  }
  if (!frame) return;
  view_->showFrame(frame);
  updateGizmo();
  chart_->addFrame(*frame);
  ++framesSeen_;
  qint64 now = QDateTime::currentMSecsSinceEpoch();
  if (now - fpsStart_ > 1000) {
    fps_ = framesSeen_ * 1000.0 / static_cast<double>(now - fpsStart_);
    fpsStart_ = now;
    framesSeen_ = 0;
  }
  double spp = frame->tileSamples.empty() ? 0.0
                                          : std::accumulate(frame->tileSamples.begin(), frame->tileSamples.end(), 0.0) /
                                                static_cast<double>(frame->tileSamples.size());
  const QString mode = QString::fromStdString(frame->mode) + (frame->block > 1 ? tr(", preview 1/%1").arg(frame->block) : QString());
  const QString queue = frame->inPass() ? tr("queue %1/%2").arg(frame->queueServed).arg(frame->queueLength) : tr("whole image");
  status_->setText(tr("%1 fps | %2 spp | %3 | %4 (%5) | %6x%7 | %8")
                       .arg(fps_, 0, 'f', 1)
                       .arg(spp, 0, 'f', 0)
                       .arg(queue)
                       .arg(QString::fromStdString(frame->method), mode)
                       .arg(frame->width)
                       .arg(frame->height)
                       .arg(QString::fromStdString(engine_->deviceName())));
}

void MainWindow::log(const QString& line) {
  // A warning said again (the scene uploaded again, a device replaced) is logged once.
  if (line.startsWith("warning: ")) {
    if (loggedWarnings_.contains(line)) return;
    loggedWarnings_.insert(line);
  }
  log_->appendPlainText(QDateTime::currentDateTime().toString("HH:mm:ss  ") + line);
  log_->verticalScrollBar()->setValue(log_->verticalScrollBar()->maximum());  // the newest entry shows
}

void MainWindow::showError(const QString& title, const QString& message) {
  lastError_ = message;
  log(title + ": " + message);
  // Non-blocking: the window keeps working (and rendering) while the message is up.
  auto* box = new QMessageBox(QMessageBox::Warning, title, message, QMessageBox::Ok, this);
  box->setAttribute(Qt::WA_DeleteOnClose);
  box->open();
}

bool MainWindow::applyToDocument(const Edit& e) {
  auto r = doc_.apply(e);
  if (!r) {
    showError(tr("Edit refused"), QString::fromStdString(r.error()));
    return false;
  }
  // The engine renders at the viewport's size; the document keeps the scene's own resolution,
  // which is saved and which `retile render` renders.
  if (const auto* settings = std::get_if<SetRenderSettings>(&e)) {
    updateRenderSize();  // framed as the scene, the viewport's image follows its resolution
    SetRenderSettings atViewport = *settings;
    atViewport.settings.width = renderSize_.width();
    atViewport.settings.height = renderSize_.height();
    // A new resolution alone reaches the engine as the settings it has, which restart nothing.
    engine_->submit(Edit{atViewport}, doc_.version());
  } else {
    engine_->submit(e, doc_.version());
  }
  // Names, visibility, membership, materials shown beside objects. Deferred: the edit may come
  // from the outliner's own itemChanged, whose item a rebuild deletes.
  if (!outlinerRefreshQueued_) {
    outlinerRefreshQueued_ = true;
    QMetaObject::invokeMethod(
        this,
        [this] {
          outlinerRefreshQueued_ = false;
          rebuildOutliner();
        },
        Qt::QueuedConnection);
  }
  refreshGraph();
  // Everything else that changes what the panel shows (a drag in the viewport, the node graph,
  // undo and redo) refreshes it.
  for (PropertyPanel* p : {panel_, renderPanel_})
    if (p != panelEdit_ && p->shows(e)) p->rebuildLater();
  return true;
}

Vec3 MainWindow::pivot(const Object& o) const { return objectPivot(doc_.scene(), o); }

void MainWindow::updateGizmo() {
  FrameView::Gizmo g;
  const Object* o = doc_.scene().object(selection_);
  auto frame = view_->frame();
  if (o && frame) {
    const Camera& c = doc_.scene().camera;
    const Vec3 at = pivot(*o);
    // A fixed share of the view: arrows keep their on-screen size as the camera moves.
    gizmoLength_ = 0.12f * length(at - c.position) * std::tan(c.verticalFov * 0.5f) * 2.0f;
    auto origin = projectToImage(c, frame->width, frame->height, at);
    if (origin && gizmoLength_ > 0) {
      g.visible = true;
      g.origin = QPointF(origin->x, origin->y);
      for (int a = 0; a < 3; ++a) {
        Vec3 e{0.0f};
        (a == 0 ? e.x : a == 1 ? e.y : e.z) = gizmoLength_;
        auto end = projectToImage(c, frame->width, frame->height, at + e);
        g.axisEnd[a] = end ? QPointF(end->x, end->y) : g.origin;
      }
    }
  }
  gizmo_ = g;
  view_->setGizmo(g);
}

void MainWindow::refreshGraph() {
  // Coalesced: a drag applies an edit per mouse move, the graph needs only the last state.
  if (graphRefreshQueued_ || !graph_) return;
  graphRefreshQueued_ = true;
  QMetaObject::invokeMethod(
      this,
      [this] {
        graphRefreshQueued_ = false;
        graph_->setDocument(doc_.scene());
      },
      Qt::QueuedConnection);
}

void MainWindow::edit(const Edit& before, const Edit& after, const QString& text, int dragId) {
  undo_.push(new EditCommand(
      before, after, text, [this](const Edit& e) { return applyToDocument(e); }, dragId));
}

void MainWindow::select(NodeId object) {
  if (object != kNoNode && !doc_.scene().object(object)) object = kNoNode;
  selected_.clear();
  if (object != kNoNode) selected_.push_back(object);
  selection_ = object;
  applySelection();
}

void MainWindow::toggleSelected(NodeId object) {
  if (!doc_.scene().object(object)) return;
  auto it = std::find(selected_.begin(), selected_.end(), object);
  if (it != selected_.end()) {
    selected_.erase(it);
    selection_ = selected_.empty() ? kNoNode : selected_.back();  // the last picked leads
  } else {
    selected_.push_back(object);
    selection_ = object;
  }
  applySelection();
}

void MainWindow::applySelection() {
  // Objects an edit or a new document removed drop out.
  std::erase_if(selected_, [this](NodeId id) { return !doc_.scene().object(id); });
  if (!doc_.scene().object(selection_)) selection_ = selected_.empty() ? kNoNode : selected_.back();
  view_->setSelection(std::vector<quint64>(selected_.begin(), selected_.end()), selection_);
  // The engine's indirection counters and the gizmo follow the last picked object.
  engine_->submit(SelectCommand{selection_});
  if (graph_) {
    graph_->followSelection(selected_);
    if (selected_.size() > 1) graph_->selectNodes(selected_);
    else graph_->setSelectedObject(selection_);
  }
  updateGizmo();
  if (selection_ != kNoNode) panel_->setTarget({PropertyTarget::Kind::Object, selection_});
  else if (panel_->target().kind == PropertyTarget::Kind::Object) panel_->setTarget({});
  {
    QSignalBlocker block(outliner_);
    outliner_->clearSelection();
    for (QTreeWidgetItemIterator it(outliner_); *it; ++it) {
      const auto id = static_cast<NodeId>((*it)->data(0, kIdRole).toULongLong());
      if (static_cast<PropertyTarget::Kind>((*it)->data(0, kKindRole).toInt()) != PropertyTarget::Kind::Object ||
          std::find(selected_.begin(), selected_.end(), id) == selected_.end())
        continue;
      (*it)->setSelected(true);
      if (id == selection_) outliner_->scrollToItem(*it);  // an object picked in the viewport shows in a long list
    }
  }
}

void MainWindow::editSelected(const std::function<void(Object&)>& change, const QString& what) {
  std::vector<std::pair<Edit, Edit>> steps;
  QString name;
  for (NodeId id : selected_) {
    const Object* o = doc_.scene().object(id);
    if (!o) continue;
    Object after = *o;
    change(after);
    steps.emplace_back(SetObject{*o}, SetObject{after});
    name = QString::fromStdString(o->name);
  }
  if (steps.empty()) return;
  const QString target = steps.size() == 1 ? name : tr("%n objects", nullptr, static_cast<int>(steps.size()));
  undo_.push(new EditCommand(
      std::move(steps), what.arg(target), [this](const Edit& e) { return applyToDocument(e); }, dragCounter_ + 1));
}

void MainWindow::rebuildOutliner() {
  // A rebuild follows every edit: it must not undo what the user did to the list (groups folded,
  // where it was scrolled, the environment or a material picked in it).
  using Key = QPair<int, qulonglong>;  // kind, id
  auto keyOf = [](const QTreeWidgetItem* it) { return Key(it->data(0, kKindRole).toInt(), it->data(0, kIdRole).toULongLong()); };
  QSet<QString> folded;
  for (int i = 0; i < outliner_->topLevelItemCount(); ++i)
    if (!outliner_->topLevelItem(i)->isExpanded()) folded << outliner_->topLevelItem(i)->text(0);
  QSet<Key> picked;
  for (const QTreeWidgetItem* it : outliner_->selectedItems()) picked << keyOf(it);
  const bool hasCurrent = outliner_->currentItem() != nullptr;
  const Key current = hasCurrent ? keyOf(outliner_->currentItem()) : Key(-1, 0);
  const int scrolled = outliner_->verticalScrollBar()->value();

  QSignalBlocker block(outliner_);
  outliner_->clear();
  const Scene& s = doc_.scene();
  auto group = [&](const QString& name) {
    auto* g = new QTreeWidgetItem(outliner_, {name, QString()});
    g->setExpanded(!folded.contains(name));
    g->setFlags(Qt::ItemIsEnabled);
    return g;
  };
  std::vector<QTreeWidgetItem*> items;
  auto item = [&](QTreeWidgetItem* parent, const QString& name, const QString& kind, PropertyTarget::Kind k, NodeId id) {
    auto* it = new QTreeWidgetItem(parent, {name, kind});
    if (id != kNoNode) it->setData(0, kIdRole, static_cast<qulonglong>(id));
    it->setData(0, kKindRole, static_cast<int>(k));
    items.push_back(it);
    return it;
  };
  QTreeWidgetItem* objects = group(tr("Objects"));
  for (const Object& o : s.objects) {
    // Imported objects are often named after their mesh files: the material says what they are.
    const Material* m = s.material(o.material);
    auto* it = item(objects, QString::fromStdString(o.name), m ? QString::fromStdString(m->name) : tr("object"),
                    PropertyTarget::Kind::Object, o.id);
    it->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable | Qt::ItemIsEditable | Qt::ItemIsUserCheckable);
    it->setCheckState(0, o.visible ? Qt::Checked : Qt::Unchecked);
  }
  QTreeWidgetItem* materials = group(tr("Materials"));
  for (const Material& m : s.materials)
    item(materials, QString::fromStdString(m.name), materialTypeName(m.type), PropertyTarget::Kind::Material, m.id)
        ->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable | Qt::ItemIsEditable);
  QTreeWidgetItem* lights = group(tr("Lights"));
  for (const Light& l : s.lights) {
    auto* it = item(lights, QString::fromStdString(l.name), tr("light"), PropertyTarget::Kind::Light, l.id);
    it->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable | Qt::ItemIsEditable | Qt::ItemIsUserCheckable);
    it->setCheckState(0, l.visible ? Qt::Checked : Qt::Unchecked);
  }
  QTreeWidgetItem* scene = group(tr("Scene"));
  item(scene, tr("Camera"), QString(), PropertyTarget::Kind::Camera, kNoNode);
  item(scene, tr("Environment"), QString(), PropertyTarget::Kind::Environment, kNoNode);
  item(scene, tr("Render settings"), QString(), PropertyTarget::Kind::Render, kNoNode);

  // Selected objects are the window's selection; anything else stays picked as it was.
  for (QTreeWidgetItem* it : items) {
    const Key k = keyOf(it);
    const bool object = k.first == static_cast<int>(PropertyTarget::Kind::Object);
    const bool selected =
        object ? std::find(selected_.begin(), selected_.end(), static_cast<NodeId>(k.second)) != selected_.end() : picked.contains(k);
    if (selected) it->setSelected(true);
    if (hasCurrent && current == k) outliner_->setCurrentItem(it, 0, QItemSelectionModel::NoUpdate);
  }
  outliner_->doItemsLayout();  // the scroll bar's range, before its old value is put back
  outliner_->verticalScrollBar()->setValue(scrolled);
}

void MainWindow::rebuildProperties() {
  panel_->setRenderSize(renderSize_, options_.cameraFraming);
  panel_->rebuild();
  renderPanel_->setRenderSize(renderSize_, options_.cameraFraming);
  renderPanel_->rebuild();
}

void MainWindow::notify(const QString& text) {
  statusBar()->showMessage(text, 8000);
  log(text);
}

void MainWindow::showTool() {
  QString name;
  switch (view_->tool()) {
    case FrameView::Tool::Select: name = tr("Select (Q): click picks"); break;
    case FrameView::Tool::Move: name = tr("Move (W): drag the selection or an arrow"); break;
    case FrameView::Tool::Rotate: name = tr("Rotate (E): drag turns about the selection's centre"); break;
    case FrameView::Tool::Scale: name = tr("Scale (R): drag scales about the selection's centre"); break;
  }
  toolLabel_->setText(tr("Tool: %1").arg(name));
}

void MainWindow::replaceDocument(Scene scene, const std::filesystem::path& file) {
  doc_ = Document(std::move(scene));
  file_ = file;
  undo_.clear();
  selection_ = kNoNode;
  selected_.clear();
  methodPanel_->setFocus({});
  updateTitle();
  loggedWarnings_.clear();
  importWarnings_.clear();
  startEngine(doc_.scene());
  applySceneView();
  rebuildOutliner();
  panel_->setTarget({});
  rebuildProperties();
  graph_->setDocument(doc_.scene());
  graph_->resetLayout();
  // The inspector's region and readout and the chart's reference described the old scene.
  view_->clearInspection();
  pixelText_.clear();
  regionText_.clear();
  inspector_->setText(inspectorHint());
  chart_->reset();
}

void MainWindow::applySceneView() {
  const std::string& view = doc_.scene().settings.view;
  if (view.empty() || !displayView_) return;
  const int i = displayView_->findText(QString::fromStdString(view));
  if (i < 0) {
    log(tr("the scene asks for the view '%1', which the colour configuration does not have").arg(QString::fromStdString(view)));
    return;
  }
  displayView_->setCurrentIndex(i);
  log(tr("view: %1, as the scene asks").arg(displayView_->currentText()));
}

void MainWindow::closeEvent(QCloseEvent* e) {
  if (!maybeSave()) {
    e->ignore();
    return;
  }
  if (engine_) engine_->stop();
  if (options_.keepLayout) {
    QSettings settings;
    settings.setValue("window/geometry", saveGeometry());
    settings.setValue("window/docks", saveState());
    settings.setValue("viewport/cameraFraming", options_.cameraFraming);
  }
  // A clean close: no recovery is offered next time.
  QDir dir(recoveryDirectory());
  for (const QString& f : dir.entryList({"autosave-*.retile", "session.lock"}, QDir::Files)) dir.remove(f);
  e->accept();
}

void MainWindow::keyPressEvent(QKeyEvent* e) {
  if (e->key() == Qt::Key_F && !(e->modifiers() & Qt::ControlModifier)) {
    if (graph_ && graph_->mouseOver()) graph_->frameSelected();  // the panel under the mouse
    else frameSelected();
    return;
  }
  QMainWindow::keyPressEvent(e);
}

void MainWindow::editCamera(const std::function<void(Camera&)>& change, const QString& what) {
  Camera before = doc_.scene().camera, after = before;
  change(after);
  if (!isFinite(after.position) || !isFinite(after.target) || length(after.position - after.target) < 1e-4f) return;
  edit(SetCamera{before}, SetCamera{after}, what, dragCounter_ + 1);
}

void MainWindow::frameSelected() {
  const Object* o = doc_.scene().object(selection_);
  const Mesh* m = o ? doc_.scene().mesh(o->mesh) : nullptr;
  if (!m || !m->geometry) return;
  Bounds3 b = transformBounds(o->transform, m->geometry->bounds());
  if (b.empty()) return;
  editCamera(
      [&](Camera& c) {
        Vec3 fwd = normalize(c.target - c.position);
        float radius = 0.5f * length(b.extent());
        float dist = radius / std::sin(0.5f * c.verticalFov) * 1.1f;
        c.target = b.center();
        c.position = c.target - fwd * dist;
      },
      tr("Frame selected"));
  ++dragCounter_;
}

void MainWindow::resizeEvent(QResizeEvent* e) {
  QMainWindow::resizeEvent(e);
  resizeTimer_.start();
}

}  // namespace retile::ui
