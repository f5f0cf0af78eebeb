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
#include <QHBoxLayout>
#include <QHeaderView>
#include <QKeyEvent>
#include <QLabel>
#include <QMenuBar>
#include <QMessageBox>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QSlider>
#include <QSpinBox>
#include <QStatusBar>
#include <QTreeWidget>

#include <cmath>
#include <numeric>

#include "edit_command.h"
#include "retile/io.h"
#include "retile/log.h"

namespace retile::ui {

namespace {

constexpr int kIdRole = Qt::UserRole + 1;

QColor toQColor(Vec3 c, float scale = 1.0f) {
  auto ch = [&](float v) { return std::clamp(static_cast<int>(std::lround(v / scale * 255.0f)), 0, 255); };
  return QColor(ch(c.x), ch(c.y), ch(c.z));
}

Vec3 fromQColor(const QColor& c, float scale = 1.0f) {
  return Vec3{static_cast<float>(c.redF()), static_cast<float>(c.greenF()), static_cast<float>(c.blueF())} * scale;
}

}  // namespace

MainWindow::MainWindow(Scene scene, std::filesystem::path file, EditorOptions options, QWidget* parent)
    : QMainWindow(parent), options_(options), doc_(std::move(scene)), file_(std::move(file)) {
  setWindowTitle(file_.empty() ? tr("Retile - built-in scene") : tr("Retile - %1").arg(QString::fromStdString(file_.filename().string())));
  view_ = new FrameView(this);
  setCentralWidget(view_);
  buildDocks();
  buildMenus();
  status_ = new QLabel(this);
  statusBar()->addPermanentWidget(status_, 1);
  connect(view_, &FrameView::objectPicked, this, [this](quint64 id) { select(static_cast<NodeId>(id)); });
  connect(view_, &FrameView::focusPlaced, this, [this](QPointF p) {
    method_.focus = {FocusPoint{Vec2{static_cast<float>(p.x()), static_cast<float>(p.y())}, false}};
    engine_->submit(FocusCommand{method_.focus});
    log(tr("focus point at %1, %2").arg(p.x(), 0, 'f', 0).arg(p.y(), 0, 'f', 0));
  });
  // Camera navigation (Alt + left/middle/right, wheel) and moving the selection in the screen
  // plane; each whole drag is one undo step.
  connect(view_, &FrameView::dragFinished, this, [this] { ++dragCounter_; });
  connect(view_, &FrameView::orbitDragged, this, [this](QPointF d) {
    editCamera([d](Camera& c) {
      Vec3 offset = c.position - c.target;
      float yaw = static_cast<float>(-d.x() * 0.008), pitch = static_cast<float>(-d.y() * 0.008);
      Mat4 turn = Mat4::rotateY(yaw);
      offset = turn.transformPoint(offset);
      Vec3 right = normalize(cross(normalize(c.target - c.position), c.up));
      // Rodrigues' rotation of the offset about the camera's right axis.
      Vec3 tilted = offset * std::cos(pitch) + cross(right, offset) * std::sin(pitch) +
                    right * (dot(right, offset) * (1.0f - std::cos(pitch)));
      // Stay clear of the poles, where "up" would flip.
      if (std::abs(dot(normalize(tilted), Vec3{0, 1, 0})) < 0.97f) offset = tilted;
      c.position = c.target + offset;
    }, tr("Orbit"));
  });
  connect(view_, &FrameView::panDragged, this, [this](QPointF d) {
    editCamera([this, d](Camera& c) {
      Vec3 fwd = normalize(c.target - c.position);
      Vec3 right = normalize(cross(fwd, c.up)), up = cross(right, fwd);
      float k = 2.0f * length(c.target - c.position) * std::tan(c.verticalFov * 0.5f) / static_cast<float>(std::max(1, view_->height()));
      Vec3 move = right * static_cast<float>(-d.x() * k) + up * static_cast<float>(d.y() * k);
      c.position = c.position + move;
      c.target = c.target + move;
    }, tr("Pan"));
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
    Vec3 at = o->transform.transformPoint(Vec3{0.0f});
    float depth = std::max(0.01f, dot(at - c.position, fwd));
    float k = 2.0f * depth * std::tan(c.verticalFov * 0.5f) / static_cast<float>(frame->height);
    Object after = *o;
    after.transform = Mat4::translate(right * static_cast<float>(d.x() * k) - up * static_cast<float>(d.y() * k)) * o->transform;
    edit(SetObject{*o}, SetObject{after}, tr("Move %1").arg(QString::fromStdString(o->name)), dragCounter_ + 1);
  });
  setAcceptDrops(true);
  // Autosave every 5 minutes ($RETILE_AUTOSAVE_SECONDS overrides) to rotating recovery files.
  auto* autosaveTimer = new QTimer(this);
  int every = qEnvironmentVariableIsSet("RETILE_AUTOSAVE_SECONDS") ? qEnvironmentVariableIntValue("RETILE_AUTOSAVE_SECONDS") : 300;
  connect(autosaveTimer, &QTimer::timeout, this, [this] { autosave(); });
  autosaveTimer->start(std::max(1, every) * 1000);
  QDir().mkpath(recoveryDirectory());
  QFile lock(recoveryDirectory() + "/session.lock");
  if (lock.open(QIODevice::WriteOnly)) lock.write(QByteArray::number(QCoreApplication::applicationPid()));
  resize(1280, 800);
  startEngine(doc_.scene());
  rebuildOutliner();
  rebuildProperties();
}

MainWindow::~MainWindow() {
  if (engine_) engine_->stop();  // before any member the callback might touch goes away
}

void MainWindow::buildMenus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  file->addAction(tr("&Open..."), QKeySequence::Open, this, [this] {
    QString f = QFileDialog::getOpenFileName(this, tr("Open scene"), QString(),
                                             tr("Scenes (*.json *.retile *.gltf *.glb *.obj *.fbx *.ply *.dae);;All files (*)"));
    if (!f.isEmpty()) openFile(f.toStdString());
  });
  recentMenu_ = file->addMenu(tr("Open &Recent"));
  connect(recentMenu_, &QMenu::aboutToShow, this, [this] { rebuildRecentMenu(); });
  file->addAction(tr("&Save"), QKeySequence::Save, this, [this] {
    if (file_.empty() || file_.extension() != ".retile") {
      QString f = QFileDialog::getSaveFileName(this, tr("Save scene"), QString(), tr("Retile scenes (*.retile)"));
      if (!f.isEmpty()) saveTo(f.toStdString());
    } else {
      saveTo(file_);
    }
  });
  file->addAction(tr("Save &As..."), QKeySequence::SaveAs, this, [this] {
    QString f = QFileDialog::getSaveFileName(this, tr("Save scene as"), QString(), tr("Retile scenes (*.retile)"));
    if (!f.isEmpty()) saveTo(f.toStdString());
  });
  file->addSeparator();
  file->addAction(tr("&Quit"), QKeySequence::Quit, this, &QWidget::close);

  QMenu* editMenu = menuBar()->addMenu(tr("&Edit"));
  QAction* undo = undo_.createUndoAction(this, tr("&Undo"));
  undo->setShortcut(QKeySequence::Undo);
  QAction* redo = undo_.createRedoAction(this, tr("&Redo"));
  redo->setShortcut(QKeySequence::Redo);
  editMenu->addAction(undo);
  editMenu->addAction(redo);
  // The panels show the undone value (not during a drag: rebuilding would drop the slider).
  connect(undo, &QAction::triggered, this, [this] { rebuildProperties(); });
  connect(redo, &QAction::triggered, this, [this] { rebuildProperties(); });

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
  toggle(tr("Tile &order numbers"), &OverlaySettings::order);
  toggle(tr("&Samples per tile"), &OverlaySettings::samples);
  toggle(tr("Tiles served this &frame"), &OverlaySettings::served);
  toggle(tr("Point of change and &focus points"), &OverlaySettings::markers);
  toggle(tr("&Legend"), &OverlaySettings::legend);

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
  QAction* pause = render->addAction(tr("&Pause / resume"));
  pause->setShortcut(Qt::Key_Escape);
  connect(pause, &QAction::triggered, this, [this] {
    paused_ = !paused_;
    engine_->submit(PauseCommand{paused_});
    view_->setPaused(paused_);
    log(paused_ ? tr("paused: the accumulated samples are kept") : tr("resumed"));
  });
}

void MainWindow::buildDocks() {
  outliner_ = new QTreeWidget(this);
  outliner_->setHeaderLabels({tr("Name"), tr("Kind")});
  outliner_->header()->setSectionResizeMode(0, QHeaderView::Stretch);
  connect(outliner_, &QTreeWidget::itemSelectionChanged, this, [this] {
    auto items = outliner_->selectedItems();
    if (items.isEmpty()) return;
    bool ok = false;
    qulonglong id = items[0]->data(0, kIdRole).toULongLong(&ok);
    if (ok && id && doc_.scene().object(static_cast<NodeId>(id)) && id != selection_) select(static_cast<NodeId>(id));
  });
  connect(outliner_, &QTreeWidget::itemChanged, this, [this](QTreeWidgetItem* item, int column) {
    NodeId id = static_cast<NodeId>(item->data(0, kIdRole).toULongLong());
    const Object* o = doc_.scene().object(id);
    if (!o || column != 0) return;
    Object after = *o;
    after.name = item->text(0).toStdString();
    after.visible = item->checkState(0) == Qt::Checked;
    if (after.name == o->name && after.visible == o->visible) return;
    edit(SetObject{*o}, SetObject{after}, after.visible != o->visible ? tr("Show/hide %1").arg(item->text(0)) : tr("Rename object"));
  });
  auto* outlinerDock = new QDockWidget(tr("Outliner"), this);
  outlinerDock->setObjectName("outliner");
  outlinerDock->setWidget(outliner_);
  addDockWidget(Qt::LeftDockWidgetArea, outlinerDock);

  properties_ = new QWidget(this);
  propertiesForm_ = new QFormLayout(properties_);
  auto* propDock = new QDockWidget(tr("Properties"), this);
  propDock->setObjectName("properties");
  propDock->setWidget(properties_);
  addDockWidget(Qt::RightDockWidgetArea, propDock);

  auto* methodPanel = new QWidget(this);
  auto* mf = new QFormLayout(methodPanel);
  methodBox_ = new QComboBox(methodPanel);
  for (const auto& n : methodNames()) methodBox_->addItem(QString::fromStdString(n));
  methodBox_->setCurrentText(methodName(method_.kind));
  tileBox_ = new QComboBox(methodPanel);
  for (int t : {8, 16, 32}) tileBox_->addItem(QString::number(t), t);
  tileBox_->setCurrentText(QString::number(method_.tileSize));
  qualityBox_ = new QSpinBox(methodPanel);
  qualityBox_->setRange(0, 4096);
  qualityBox_->setSpecialValueText(tr("auto"));
  qualityBox_->setValue(method_.quality);
  smoothBox_ = new QCheckBox(tr("smooth transition"), methodPanel);
  mf->addRow(tr("Method"), methodBox_);
  mf->addRow(tr("Tile size T"), tileBox_);
  mf->addRow(tr("Quality Q"), qualityBox_);
  mf->addRow(QString(), smoothBox_);
  connect(methodBox_, &QComboBox::currentTextChanged, this, [this] { sendMethod(); });
  connect(tileBox_, &QComboBox::currentIndexChanged, this, [this] { sendMethod(); });
  connect(qualityBox_, &QSpinBox::valueChanged, this, [this] { sendMethod(); });
  connect(smoothBox_, &QCheckBox::toggled, this, [this] { sendMethod(); });
  auto* methodDock = new QDockWidget(tr("Method"), this);
  methodDock->setObjectName("method");
  methodDock->setWidget(methodPanel);
  addDockWidget(Qt::RightDockWidgetArea, methodDock);

  log_ = new QPlainTextEdit(this);
  log_->setReadOnly(true);
  log_->setMaximumBlockCount(2000);
  auto* logDock = new QDockWidget(tr("Log"), this);
  logDock->setObjectName("log");
  logDock->setWidget(log_);
  addDockWidget(Qt::BottomDockWidgetArea, logDock);
}

void MainWindow::sendMethod() {
  MethodSettings m = method_;
  methodFromName(methodBox_->currentText().toStdString(), &m.kind);
  m.tileSize = tileBox_->currentData().toInt();
  m.quality = qualityBox_->value();
  m.smooth = smoothBox_->isChecked();
  if (m.quality == 0 && m.kind != MethodKind::Indirection && m.kind != MethodKind::IndirectionFocus) m.quality = 64;
  if (std::string bad = validateMethodSettings(m); !bad.empty()) {
    log(tr("method: %1").arg(QString::fromStdString(bad)));
    return;
  }
  method_ = m;
  engine_->submit(MethodCommand{method_});
  log(tr("method %1, T=%2, Q=%3%4").arg(methodName(m.kind)).arg(m.tileSize).arg(m.quality ? QString::number(m.quality) : tr("auto"),
                                                                                      m.smooth ? tr(", smooth") : QString()));
}

void MainWindow::updateRenderSize() {
  QSize size = options_.initialRenderSize;
  if (size.isEmpty()) {
    QSize v = view_->size();
    size = QSize(std::max(64, v.width() / std::max(1, options_.renderScale)), std::max(36, v.height() / std::max(1, options_.renderScale)));
  }
  if (size == renderSize_) return;
  renderSize_ = size;
  if (engine_) engine_->submit(ResizeCommand{size.width(), size.height()});
}

void MainWindow::startEngine(Scene scene) {
  if (engine_) engine_->stop();
  QSize size = options_.initialRenderSize;
  if (size.isEmpty()) size = QSize(std::max(64, 1000 / std::max(1, options_.renderScale)), std::max(36, 560 / std::max(1, options_.renderScale)));
  renderSize_ = size;
  scene.settings.width = size.width();
  scene.settings.height = size.height();
  engine_ = std::make_unique<Engine>(std::move(scene), method_);
  engine_->setFrameCallback([this] { QMetaObject::invokeMethod(this, [this] { onFrame(); }, Qt::QueuedConnection); });
  engine_->start();
  fpsStart_ = QDateTime::currentMSecsSinceEpoch();
  framesSeen_ = 0;
}

void MainWindow::onFrame() {
  if (!engine_) return;
  auto frame = engine_->latestFrame();
  for (const auto& e : engine_->takeErrors()) log(QString::fromStdString(e));
  if (!frame) return;
  view_->showFrame(frame);
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
  status_->setText(tr("%1 fps | %2 spp | queue %3/%4 | %5 (%6) | %7x%8 | %9")
                       .arg(fps_, 0, 'f', 1)
                       .arg(spp, 0, 'f', 0)
                       .arg(frame->queueServed)
                       .arg(frame->queueLength)
                       .arg(QString::fromStdString(frame->method), QString::fromStdString(frame->mode))
                       .arg(frame->width)
                       .arg(frame->height)
                       .arg(QString::fromStdString(engine_->deviceName())));
}

void MainWindow::log(const QString& line) {
  log_->appendPlainText(QDateTime::currentDateTime().toString("HH:mm:ss  ") + line);
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
  engine_->submit(e, doc_.version());
  if (!std::holds_alternative<SetMaterial>(e)) rebuildOutliner();  // names, visibility, membership
  return true;
}

void MainWindow::edit(const Edit& before, const Edit& after, const QString& text, int dragId) {
  undo_.push(new EditCommand(before, after, text, [this](const Edit& e) { return applyToDocument(e); }, dragId));
}

void MainWindow::select(NodeId object) {
  if (object != kNoNode && !doc_.scene().object(object)) object = kNoNode;
  selection_ = object;
  view_->setSelected(object);
  engine_->submit(SelectCommand{object});
  {
    QSignalBlocker block(outliner_);
    outliner_->clearSelection();
    for (QTreeWidgetItemIterator it(outliner_); *it; ++it)
      if ((*it)->data(0, kIdRole).toULongLong() == object && object != kNoNode) (*it)->setSelected(true);
  }
  rebuildProperties();
}

void MainWindow::rebuildOutliner() {
  QSignalBlocker block(outliner_);
  outliner_->clear();
  const Scene& s = doc_.scene();
  auto group = [&](const QString& name) {
    auto* g = new QTreeWidgetItem(outliner_, {name, QString()});
    g->setExpanded(true);
    g->setFlags(Qt::ItemIsEnabled);
    return g;
  };
  QTreeWidgetItem* objects = group(tr("Objects"));
  for (const Object& o : s.objects) {
    auto* it = new QTreeWidgetItem(objects, {QString::fromStdString(o.name), tr("object")});
    it->setData(0, kIdRole, static_cast<qulonglong>(o.id));
    it->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable | Qt::ItemIsEditable | Qt::ItemIsUserCheckable);
    it->setCheckState(0, o.visible ? Qt::Checked : Qt::Unchecked);
    if (o.id == selection_) it->setSelected(true);
  }
  QTreeWidgetItem* materials = group(tr("Materials"));
  for (const Material& m : s.materials) {
    auto* it = new QTreeWidgetItem(materials, {QString::fromStdString(m.name), materialTypeName(m.type)});
    it->setData(0, kIdRole, static_cast<qulonglong>(m.id));
  }
  QTreeWidgetItem* lights = group(tr("Lights"));
  for (const Light& l : s.lights) {
    auto* it = new QTreeWidgetItem(lights, {QString::fromStdString(l.name), tr("light")});
    it->setData(0, kIdRole, static_cast<qulonglong>(l.id));
  }
  group(tr("Camera"));
}

void MainWindow::rebuildProperties() {
  while (propertiesForm_->rowCount() > 0) propertiesForm_->removeRow(0);
  const Scene& s = doc_.scene();
  const Object* o = s.object(selection_);
  if (!o) {
    propertiesForm_->addRow(new QLabel(tr("Click an object in the viewport or the outliner."), properties_));
    return;
  }
  propertiesForm_->addRow(tr("Object"), new QLabel(QString::fromStdString(o->name), properties_));
  // Position: moves the object, keeping its rotation and scale.
  Vec3 pos = o->transform.transformPoint(Vec3{0.0f});
  auto* posRow = new QWidget(properties_);
  auto* posLayout = new QHBoxLayout(posRow);
  posLayout->setContentsMargins(0, 0, 0, 0);
  for (int axis = 0; axis < 3; ++axis) {
    auto* spin = new QDoubleSpinBox(posRow);
    spin->setRange(-1e4, 1e4);
    spin->setDecimals(3);
    spin->setSingleStep(0.05);
    spin->setValue(axis == 0 ? pos.x : axis == 1 ? pos.y : pos.z);
    spin->setObjectName(QString("position%1").arg(axis));
    posLayout->addWidget(spin);
    connect(spin, &QDoubleSpinBox::valueChanged, this, [this, axis](double v) {
      const Object* cur = doc_.scene().object(selection_);
      if (!cur) return;
      Vec3 p = cur->transform.transformPoint(Vec3{0.0f});
      Vec3 d{0.0f};
      (axis == 0 ? d.x : axis == 1 ? d.y : d.z) = static_cast<float>(v) - (axis == 0 ? p.x : axis == 1 ? p.y : p.z);
      Object after = *cur;
      after.transform = Mat4::translate(d) * cur->transform;
      undo_.push(new EditCommand(SetObject{*cur}, SetObject{after}, tr("Move %1").arg(QString::fromStdString(cur->name)),
                                 [this](const Edit& e) { return applyToDocument(e); }));
    });
  }
  propertiesForm_->addRow(tr("Position"), posRow);

  const Material* m = s.material(o->material);
  if (!m) return;
  propertiesForm_->addRow(tr("Material"), new QLabel(QString::fromStdString(m->name), properties_));
  NodeId mid = m->id;
  auto materialEdit = [this, mid](const std::function<void(Material&)>& change, const QString& what, int dragId) {
    const Material* cur = doc_.scene().material(mid);
    if (!cur) return;
    Material after = *cur;
    change(after);
    undo_.push(new EditCommand(SetMaterial{*cur}, SetMaterial{after}, what, [this](const Edit& e) { return applyToDocument(e); }, dragId));
  };
  auto* type = new QComboBox(properties_);
  for (int t = 0; t < kMaterialTypeCount; ++t) type->addItem(materialTypeName(static_cast<MaterialType>(t)));
  type->setCurrentIndex(static_cast<int>(m->type));
  connect(type, &QComboBox::currentIndexChanged, this, [materialEdit](int i) {
    materialEdit([i](Material& x) { x.type = static_cast<MaterialType>(i); }, tr("Material type"), 0);
  });
  propertiesForm_->addRow(tr("Type"), type);

  auto* albedo = new QPushButton(properties_);
  albedo->setObjectName("albedo");
  QColor ac = toQColor(m->albedo);
  albedo->setStyleSheet(QString("background-color: %1").arg(ac.name()));
  albedo->setText(ac.name());
  connect(albedo, &QPushButton::clicked, this, [this, materialEdit, ac] {
    QColor c = QColorDialog::getColor(ac, this, tr("Albedo"));
    if (c.isValid()) materialEdit([c](Material& x) { x.albedo = fromQColor(c); }, tr("Albedo"), 0);
  });
  propertiesForm_->addRow(tr("Albedo"), albedo);

  // Roughness: a slider whose whole drag is one undo step, and a box for typed values.
  auto* roughRow = new QWidget(properties_);
  auto* rl = new QHBoxLayout(roughRow);
  rl->setContentsMargins(0, 0, 0, 0);
  auto* slider = new QSlider(Qt::Horizontal, roughRow);
  slider->setObjectName("roughnessSlider");
  slider->setRange(0, 1000);
  slider->setValue(static_cast<int>(std::lround(m->roughness * 1000)));
  auto* box = new QDoubleSpinBox(roughRow);
  box->setObjectName("roughness");
  box->setRange(0.0, 1.0);
  box->setDecimals(3);
  box->setSingleStep(0.01);
  box->setValue(m->roughness);
  rl->addWidget(slider, 1);
  rl->addWidget(box);
  connect(slider, &QSlider::sliderPressed, this, [this] { ++dragCounter_; });
  connect(slider, &QSlider::valueChanged, this, [this, slider, box, materialEdit](int v) {
    QSignalBlocker b(box);
    box->setValue(v / 1000.0);
    materialEdit([v](Material& x) { x.roughness = std::max(0.001f, v / 1000.0f); }, tr("Roughness"),
                 slider->isSliderDown() ? dragCounter_ : 0);
  });
  connect(box, &QDoubleSpinBox::valueChanged, this, [slider, materialEdit](double v) {
    QSignalBlocker b(slider);
    slider->setValue(static_cast<int>(std::lround(v * 1000)));
    materialEdit([v](Material& x) { x.roughness = std::max(0.001f, static_cast<float>(v)); }, tr("Roughness"), 0);
  });
  propertiesForm_->addRow(tr("Roughness"), roughRow);

  auto* ior = new QDoubleSpinBox(properties_);
  ior->setRange(1.0, 4.0);
  ior->setDecimals(3);
  ior->setSingleStep(0.01);
  ior->setValue(m->ior);
  connect(ior, &QDoubleSpinBox::valueChanged, this, [materialEdit](double v) {
    materialEdit([v](Material& x) { x.ior = static_cast<float>(v); }, tr("IOR"), 0);
  });
  propertiesForm_->addRow(tr("IOR"), ior);

  float strength = std::max({m->emission.x, m->emission.y, m->emission.z});
  auto* emission = new QDoubleSpinBox(properties_);
  emission->setRange(0.0, 1e5);
  emission->setDecimals(2);
  emission->setValue(strength);
  connect(emission, &QDoubleSpinBox::valueChanged, this, [materialEdit, m](double v) {
    Vec3 tint = std::max({m->emission.x, m->emission.y, m->emission.z}) > 0 ? m->emission : Vec3{1.0f};
    float peak = std::max({tint.x, tint.y, tint.z});
    materialEdit([v, tint, peak](Material& x) { x.emission = tint * static_cast<float>(v / peak); }, tr("Emission"), 0);
  });
  propertiesForm_->addRow(tr("Emission"), emission);
}

QString MainWindow::recoveryDirectory() {
  QString base = qEnvironmentVariable("RETILE_RECOVERY_DIR");
  if (base.isEmpty()) base = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/recovery";
  return base;
}

QStringList MainWindow::recoveryCandidates() {
  QDir dir(recoveryDirectory());
  if (!dir.exists("session.lock")) return {};  // the last session closed cleanly
  QStringList out;
  for (const QFileInfo& f : dir.entryInfoList({"autosave-*.retile"}, QDir::Files, QDir::Time)) out << f.absoluteFilePath();
  return out;
}

bool MainWindow::autosave() {
  if (undo_.index() == autosavedIndex_ || undo_.isClean()) return false;
  QString file = recoveryDirectory() + QString("/autosave-%1.retile").arg(autosaveSlot_);
  auto r = saveNativeScene(doc_.scene(), file.toStdString());
  if (!r) {
    log(tr("autosave failed: %1").arg(QString::fromStdString(r.error())));
    return false;
  }
  autosaveSlot_ = (autosaveSlot_ + 1) % 3;
  autosavedIndex_ = undo_.index();
  log(tr("autosaved to %1").arg(file));
  return true;
}

void MainWindow::rememberRecent(const std::filesystem::path& file) {
  QSettings settings;
  QStringList recent = settings.value("recentFiles").toStringList();
  QString f = QString::fromStdString(std::filesystem::absolute(file).string());
  recent.removeAll(f);
  recent.prepend(f);
  while (recent.size() > 10) recent.removeLast();
  settings.setValue("recentFiles", recent);
}

void MainWindow::rebuildRecentMenu() {
  recentMenu_->clear();
  QSettings settings;
  for (const QString& f : settings.value("recentFiles").toStringList()) {
    QAction* a = recentMenu_->addAction(f, this, [this, f] { openFile(f.toStdString()); });
    a->setEnabled(QFileInfo::exists(f));  // greyed when the file has gone
  }
  if (recentMenu_->isEmpty()) recentMenu_->addAction(tr("(none yet)"))->setEnabled(false);
}

void MainWindow::dragEnterEvent(QDragEnterEvent* e) {
  if (e->mimeData()->hasUrls()) e->acceptProposedAction();
}

void MainWindow::dropEvent(QDropEvent* e) {
  for (const QUrl& url : e->mimeData()->urls())
    if (url.isLocalFile()) {
      openFile(url.toLocalFile().toStdString());
      return;
    }
}

bool MainWindow::openFile(const std::filesystem::path& file) {
  auto r = importScene(file);
  if (!r) {
    showError(tr("Cannot open scene"), QString::fromStdString(r.error()));
    return false;
  }
  doc_ = Document(std::move(r->scene));
  file_ = file;
  undo_.clear();
  selection_ = kNoNode;
  setWindowTitle(tr("Retile - %1").arg(QString::fromStdString(file.filename().string())));
  for (const auto& w : r->warnings) log(tr("warning: %1").arg(QString::fromStdString(w)));
  startEngine(doc_.scene());
  rebuildOutliner();
  rebuildProperties();
  log(tr("opened %1").arg(QString::fromStdString(file.string())));
  rememberRecent(file);
  return true;
}

bool MainWindow::saveTo(const std::filesystem::path& file) {
  auto r = saveNativeScene(doc_.scene(), file);
  if (!r) {
    showError(tr("Cannot save"), QString::fromStdString(r.error()));
    return false;
  }
  file_ = file;
  undo_.setClean();
  rememberRecent(file);
  log(tr("saved %1").arg(QString::fromStdString(file.string())));
  return true;
}

void MainWindow::closeEvent(QCloseEvent* e) {
  if (!undo_.isClean() && !qEnvironmentVariableIsSet("RETILE_NO_PROMPTS")) {
    auto answer = QMessageBox::question(this, tr("Unsaved changes"), tr("Save the changes before closing?"),
                                        QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
    if (answer == QMessageBox::Cancel) {
      e->ignore();
      return;
    }
    if (answer == QMessageBox::Save) {
      QString f = QFileDialog::getSaveFileName(this, tr("Save scene"), QString(), tr("Retile scenes (*.retile)"));
      if (f.isEmpty() || !saveTo(f.toStdString())) {
        e->ignore();
        return;
      }
    }
  }
  if (engine_) engine_->stop();
  // A clean close: no recovery is offered next time.
  QDir dir(recoveryDirectory());
  for (const QString& f : dir.entryList({"autosave-*.retile", "session.lock"}, QDir::Files)) dir.remove(f);
  e->accept();
}

void MainWindow::keyPressEvent(QKeyEvent* e) {
  if (e->key() == Qt::Key_F && !(e->modifiers() & Qt::ControlModifier)) {
    frameSelected();
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
  editCamera([&](Camera& c) {
    Vec3 fwd = normalize(c.target - c.position);
    float radius = 0.5f * length(b.extent());
    float dist = radius / std::sin(0.5f * c.verticalFov) * 1.1f;
    c.target = b.center();
    c.position = c.target - fwd * dist;
  }, tr("Frame selected"));
  ++dragCounter_;
}

void MainWindow::resizeEvent(QResizeEvent* e) {
  QMainWindow::resizeEvent(e);
  updateRenderSize();
}

}  // namespace retile::ui
