#include "node_graph.h"

#include <QApplication>
#include <QButtonGroup>
#include <QCursor>
#include <QGraphicsPathItem>
#include <QGraphicsRectItem>
#include <QGraphicsScene>
#include <QHBoxLayout>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QMouseEvent>
#include <QPainter>
#include <QPainterPathStroker>
#include <QScrollBar>
#include <QToolButton>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>

#include "graph_items.h"
#include "graph_layout.h"
#include "node_search.h"

namespace retile::ui {
namespace {

// An inline editor that can be cancelled with Escape (QLineEdit alone only knows "finished").
// Every key typed into it is its own: QLineEdit lets Escape, Return and keys it has no use for
// through, as shortcut overrides to the window (Escape pauses the render) and as key presses to
// its parent, the graph (Ctrl+D would duplicate, F2 restart the rename).
class RenameEdit : public QLineEdit {
 public:
  using QLineEdit::QLineEdit;
  std::function<void()> cancelled;

 protected:
  bool event(QEvent* e) override {
    if (e->type() == QEvent::ShortcutOverride) {
      const int key = static_cast<QKeyEvent*>(e)->key();
      if (key == Qt::Key_Escape || key == Qt::Key_Return || key == Qt::Key_Enter) {
        e->accept();
        return true;
      }
    }
    return QLineEdit::event(e);
  }
  void keyPressEvent(QKeyEvent* e) override {
    if (e->key() == Qt::Key_Escape && cancelled) {
      cancelled();
      return;
    }
    QLineEdit::keyPressEvent(e);
    e->accept();
  }
};

}  // namespace

NodeGraphView::NodeGraphView(QWidget* parent) : QGraphicsView(parent) {
  auto* s = new QGraphicsScene(this);
  // A large fixed scene rect: panning is not bounded by where the nodes happen to be.
  s->setSceneRect(-50000, -50000, 100000, 100000);
  setScene(s);
  setRenderHint(QPainter::Antialiasing, true);
  setViewportUpdateMode(QGraphicsView::FullViewportUpdate);
  setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  setVerticalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  setTransformationAnchor(QGraphicsView::AnchorUnderMouse);
  setDragMode(QGraphicsView::NoDrag);
  setFocusPolicy(Qt::StrongFocus);
  setMinimumSize(200, 150);

  // The two transient items outlive rebuilds; everything else is recreated by setDocument.
  dragLink_ = s->addPath(QPainterPath(), QPen(QColor(240, 240, 240), 2.5, Qt::DashLine));
  dragLink_->setZValue(kDragLinkZ);
  dragLink_->hide();
  marquee_ = s->addRect(QRectF(), QPen(QColor(255, 168, 40), 1, Qt::DashLine), QColor(255, 168, 40, 36));
  marquee_->setZValue(kMarqueeZ);
  marquee_->hide();
  buildScopeBar();
}

void NodeGraphView::buildScopeBar() {
  // In the corner of the graph itself, so that it comes wherever the graph is docked.
  scopeBar_ = new QWidget(this);
  scopeBar_->setObjectName(QStringLiteral("graphScopeBar"));
  scopeBar_->setAutoFillBackground(true);
  auto* row = new QHBoxLayout(scopeBar_);
  row->setContentsMargins(6, 3, 6, 3);
  row->setSpacing(4);
  row->addWidget(new QLabel(tr("Show:"), scopeBar_));
  auto* group = new QButtonGroup(scopeBar_);
  auto button = [&](const QString& text, const char* name, Scope scope, const QString& tip) {
    auto* b = new QToolButton(scopeBar_);
    b->setText(text);
    b->setObjectName(QLatin1String(name));
    b->setCheckable(true);
    b->setToolTip(tip);
    b->setFocusPolicy(Qt::NoFocus);  // the keys stay with the graph
    group->addButton(b);
    row->addWidget(b);
    connect(b, &QToolButton::clicked, this, [this, scope] { setScope(scope); });
    return b;
  };
  showSelection_ = button(tr("Selection"), "graphShowSelection", Scope::Selection,
                          tr("The selected objects, their materials and those materials' textures"));
  showAll_ = button(tr("All"), "graphShowAll", Scope::All, tr("Every node of the scene (A frames as much as is legible)"));
  scopeNote_ = new QLabel(scopeBar_);
  scopeNote_->setObjectName(QStringLiteral("graphScopeNote"));
  row->addWidget(scopeNote_);
  updateScopeBar();
}

void NodeGraphView::updateScopeBar() {
  showSelection_->setChecked(scope_ == Scope::Selection);
  showAll_->setChecked(scope_ == Scope::All);
  QString note;
  if (scope_ == Scope::Selection && roots_.empty()) note = tr("nothing selected: every node");
  else if (focused() && roots_.size() == 1) note = tr("%1 and its material").arg(nameOf(scene_, roots_.front()));
  else if (focused()) note = tr("%n objects and their materials", nullptr, static_cast<int>(roots_.size()));
  scopeNote_->setText(note);
  scopeNote_->setVisible(!note.isEmpty());
  scopeBar_->adjustSize();
  scopeBar_->move(viewport()->geometry().topLeft());
}

void NodeGraphView::resizeEvent(QResizeEvent* e) {
  QGraphicsView::resizeEvent(e);
  if (scopeBar_) scopeBar_->move(viewport()->geometry().topLeft());
}

NodeGraphView::~NodeGraphView() = default;

QStringList NodeGraphView::creatableTypes() {
  QStringList names;
  for (const CreatableType& t : creatableTypeTable()) names << t.name;
  return names;
}

void NodeGraphView::setDocument(const Scene& scene) {
  scene_ = scene;
  ++documentCount_;
  hasDocument_ = true;
  rebuild();
  if (!framed_ && isVisible()) {
    framed_ = true;
    frameAll();
  }
}

void NodeGraphView::resetLayout() {
  // The new file's ids may coincide with the old one's, so nothing held by id may carry over: a
  // kept selection would pick unrelated nodes, an open rename would rename one on its focus loss,
  // and a pasted material would link to whatever texture now has its old texture's id. The copied
  // materials and lights themselves stay: pasting them into another file is useful.
  if (QLineEdit* open = rename_) static_cast<RenameEdit&>(*open).cancelled();
  pendingSelection_.clear();
  setSelection({});
  for (Material& m : copiedMaterials_) {
    for (NodeId* t : m.textureSlots()) *t = kNoNode;
    m.blendWith = kNoNode;
  }
  pasteCount_ = 0;
  positions_.clear();
  roots_.clear();
  pendingRoots_.clear();
  rootsPending_ = false;
  shown_.clear();
  focusPositions_.clear();
  rebuild();
  frameAll();
}

bool NodeGraphView::exists(NodeId id) const { return scene_.material(id) || scene_.object(id) || scene_.light(id) || scene_.texture(id); }

void NodeGraphView::rebuild() {
  std::vector<NodeId> selection;
  for (NodeId id : pendingSelection_)
    if (exists(id)) selection.push_back(id);
  if (selection.empty()) selection = selectedNodes();
  if (focused()) {
    // What was shown stays (a texture unlinked a moment ago is still there to link again), nodes
    // just made join it, and whatever any of them is made of comes along.
    std::vector<NodeId> seeds;
    for (NodeId id : roots_) seeds.push_back(id);
    for (NodeId id : shown_) seeds.push_back(id);
    for (NodeId id : pendingSelection_) seeds.push_back(id);
    std::erase_if(seeds, [this](NodeId id) { return !exists(id); });
    shown_ = neighbourhood(scene_, seeds);
  }
  pendingSelection_.clear();

  for (Link& l : links_) delete l.item;
  links_.clear();
  for (auto& [id, n] : nodes_) delete n;
  nodes_.clear();

  const std::vector<GraphNodeItem*> order = addNodes();
  placeNodes(order);
  addLinks(order);
  setSelection(selection);
  updateLinkPaths();
  updateScopeBar();
}

std::vector<GraphNodeItem*> NodeGraphView::addNodes() {
  std::vector<GraphNodeItem*> order;
  const bool all = !focused();
  auto add = [&](NodeId id, NodeKind kind, const std::string& title, const QString& subtitle) {
    auto* n = new GraphNodeItem(id, kind);
    n->title = QString::fromStdString(title);
    n->subtitle = subtitle;
    scene()->addItem(n);
    nodes_[id] = n;
    order.push_back(n);
    return n;
  };
  for (const Texture& t : scene_.textures) {
    if (!all && !shown_.count(t.id)) continue;
    QString sub;
    switch (t.kind) {
      case TextureKind::File: sub = tr("File: %1").arg(QString::fromStdString(t.path.filename().string())); break;
      case TextureKind::Embedded: sub = tr("Embedded %1").arg(QString::fromStdString(t.encodedFormat)); break;
      case TextureKind::Checker: sub = tr("Checker %1x%2").arg(t.checkerResU).arg(t.checkerResV); break;
    }
    GraphNodeItem* n = add(t.id, NodeKind::Texture, t.name, sub);
    n->output = QStringLiteral("texture");
    if (t.kind == TextureKind::Checker) n->swatch = displayColor(t.checkerOn);
  }
  for (const Material& m : scene_.materials) {
    if (!all && !shown_.count(m.id)) continue;
    QString sub = QString::fromLatin1(materialTypeName(m.type));
    if (m.emissive()) sub += tr(", emissive");
    GraphNodeItem* n = add(m.id, NodeKind::Material, m.name, sub);
    // A boundary is no surface: no texture or blend would change what it renders. Other types
    // show the inputs their type reads, and any other that still holds a texture (the type was
    // changed), so that its link can be seen and taken off.
    if (m.type != MaterialType::Boundary) {
      for (const QString& input : textureInputs())
        if (textureInputApplies(input, m.type) || m.*textureSlot(input) != kNoNode) n->inputs << input;
      n->inputs << kBlendInput;
      if (roughnessSlotIsThickness(m.type)) {
        n->labels.resize(n->inputs.size());
        n->labels[n->inputs.indexOf(QLatin1String("roughness"))] = QStringLiteral("thickness");
      }
    }
    n->output = QStringLiteral("material");
    // An emitter shows its light's hue; its albedo is usually black.
    const float peak = std::max({m.emission.x, m.emission.y, m.emission.z});
    n->swatch = displayColor(m.emissive() ? m.emission / peak : m.albedo);
  }
  for (const Object& o : scene_.objects) {
    if (!all && !shown_.count(o.id)) continue;
    const Mesh* mesh = scene_.mesh(o.mesh);
    QString sub = mesh ? tr("Mesh: %1").arg(QString::fromStdString(mesh->name)) : tr("No mesh");
    if (!o.visible) sub += tr(" (hidden)");
    add(o.id, NodeKind::Object, o.name, sub)->inputs = {QStringLiteral("material")};
  }
  if (all) {
    const Camera& c = scene_.camera;
    const double fov = static_cast<double>(c.verticalFov) * 180.0 / kPi;
    // With a lens, the distance in focus (the subtitle has room for little more).
    add(kCameraNode, NodeKind::Camera, tr("Camera").toStdString(),
        c.apertureRadius > 0 ? tr("%1\u00b0, in focus at %2").arg(fov, 0, 'f', 1).arg(static_cast<double>(c.focusDistance), 0, 'g', 3)
                             : tr("Field of view %1\u00b0").arg(fov, 0, 'f', 1));
    const RenderSettings& r = scene_.settings;
    add(kSettingsNode, NodeKind::Settings, tr("Render Settings").toStdString(),
        tr("%1x%2, %3 spp, %4 bounces").arg(r.width).arg(r.height).arg(r.samplesPerPixel).arg(r.maxBounces));
  }
  for (const Light& l : scene_.lights) {
    if (!all && !shown_.count(l.id)) continue;
    static const char* const types[] = {"Point", "Spot", "Directional"};
    const QLatin1String type(types[static_cast<int>(l.type)]);
    const QString sub = tr("%1 light, intensity %2").arg(type).arg(l.intensity);
    GraphNodeItem* n = add(l.id, NodeKind::Light, l.name, sub);
    n->swatch = displayColor(l.color);
  }
  return order;
}

void NodeGraphView::placeNodes(const std::vector<GraphNodeItem*>& order) {
  std::unordered_map<NodeId, QPointF>& at = positions();
  if (at.empty()) {
    // The panel's shape (a wide strip below the viewport, unless the artist made it otherwise).
    const double aspect = height() > 50 ? static_cast<double>(width()) / height() : 4.0;
    at = focused() ? layOutNeighbourhood(scene_, order, roots_) : layOutIslands(scene_, order, aspect);
  }
  // Nodes seen before keep their place; new ones go in a row below all of them, in columns by
  // kind, where they cover nothing.
  qreal bottom = 0;
  for (GraphNodeItem* n : order)
    if (auto it = at.find(n->id); it != at.end()) {
      n->setPos(it->second);
      bottom = std::max(bottom, it->second.y() + n->height());
    }
  std::map<int, qreal> next;  // per column kind: the top of its next new node
  for (GraphNodeItem* n : order) {
    if (at.count(n->id)) continue;
    const int c = columnOf(n->kind);
    auto y = next.try_emplace(c, bottom + 2 * kRowGap).first;
    const QPointF p(c * kColumnStep, y->second);
    y->second += n->height() + kRowGap;
    at[n->id] = p;
    n->setPos(p);
  }
}

void NodeGraphView::addLinks(const std::vector<GraphNodeItem*>& order) {
  for (const GraphNodeItem* n : order)
    for (const auto& [from, input] : linksInto(scene_, n->id)) {
      if (!nodes_.count(from)) continue;
      auto* item = new GraphLinkItem;
      item->setPen(linkPen(input, LinkLook::Normal));
      scene()->addItem(item);
      links_.push_back({from, n->id, input, item});
    }
}

void NodeGraphView::updateLinkPaths() {
  for (const Link& l : links_) {
    const GraphNodeItem* a = nodes_.at(l.from);
    const GraphNodeItem* b = nodes_.at(l.to);
    l.item->setPath(linkPath(a->mapToScene(a->outputPos()), b->mapToScene(b->inputPos(b->inputs.indexOf(l.input)))));
  }
}

void NodeGraphView::setSelection(const std::vector<NodeId>& ids) {
  const std::set<NodeId> want(ids.begin(), ids.end());
  for (auto& [id, n] : nodes_) {
    n->setSelected(want.count(id) > 0);
    n->setZValue(n->isSelected() ? kSelectedNodeZ : kNodeZ);
  }
  highlightLink(nullptr);
}

void NodeGraphView::setSelectedObject(NodeId id) {
  auto it = nodes_.find(id);
  if (it != nodes_.end() && it->second->isSelected()) return;
  setSelection(id != kNoNode && it != nodes_.end() ? std::vector<NodeId>{id} : std::vector<NodeId>{});
  // What the artist picked in the viewport comes into view here, at the zoom the graph has.
  if (it != nodes_.end()) ensureVisible(it->second->sceneBoundingRect(), 40, 30);
}

void NodeGraphView::selectNodes(const std::vector<NodeId>& ids) { setSelection(ids); }

void NodeGraphView::followSelection(const std::vector<NodeId>& objects) {
  std::vector<NodeId> roots;
  for (NodeId id : objects)
    if (scene_.object(id) && std::find(roots.begin(), roots.end(), id) == roots.end()) roots.push_back(id);
  // Rebuilding under a gesture would pull its nodes away: a click here that selected an object
  // shows that object's graph when the button comes up.
  if (mouseDown_ && QGuiApplication::mouseButtons() != Qt::NoButton) {
    pendingRoots_ = roots;
    rootsPending_ = true;
    return;
  }
  rootsPending_ = false;
  if (roots == roots_) return;
  roots_ = roots;
  shown_.clear();
  focusPositions_.clear();
  if (scope_ == Scope::Selection) {
    rebuild();
    frameAll();
  } else {
    updateScopeBar();
  }
}

void NodeGraphView::setScope(Scope scope) {
  scope_ = scope;
  rebuild();
  frameAll();
}

qreal NodeGraphView::legibleZoom() const {
  constexpr qreal kLegiblePixels = 9;
  return kLegiblePixels / std::max(1, QFontInfo(font()).pixelSize());
}

std::vector<NodeId> NodeGraphView::selectedNodes() const {
  std::vector<NodeId> ids;
  for (const auto& [id, n] : nodes_)
    if (n->isSelected()) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

bool NodeGraphView::hasNode(NodeId id) const { return nodes_.count(id) > 0; }

QPointF NodeGraphView::nodePosition(NodeId id) const {
  auto it = nodes_.find(id);
  return it == nodes_.end() ? QPointF() : it->second->pos();
}

QPointF NodeGraphView::socketScenePos(NodeId id, const QString& socket, bool output) const {
  auto it = nodes_.find(id);
  if (it == nodes_.end()) return {};
  const GraphNodeItem* n = it->second;
  if (output) return n->output == socket ? n->mapToScene(n->outputPos()) : n->pos();
  const auto i = n->inputs.indexOf(socket);
  return i < 0 ? n->pos() : n->mapToScene(n->inputPos(i));
}

QString NodeGraphView::socketLabel(NodeId id, const QString& input) const {
  auto it = nodes_.find(id);
  if (it == nodes_.end()) return {};
  const auto i = it->second->inputs.indexOf(input);
  return i < 0 ? QString() : it->second->label(i);
}

GraphNodeItem* NodeGraphView::nodeAt(QPointF scenePos) const {
  for (QGraphicsItem* item : scene()->items(scenePos))
    if (auto* n = qgraphicsitem_cast<GraphNodeItem*>(item))
      if (QRectF(0, 0, kNodeWidth, n->height()).contains(n->mapFromScene(scenePos))) return n;
  return nullptr;
}

NodeGraphView::SocketHit NodeGraphView::socketAt(QPointF scenePos) const {
  // A few pixels of slack however far out the view is zoomed: sockets are small targets.
  const qreal radius = std::max(kSocketR + 3, 10 / std::max(0.01, transform().m11()));
  SocketHit best;
  qreal bestDist = radius;
  auto consider = [&](GraphNodeItem* n, QPointF local, const QString& name, bool output) {
    const qreal d = QLineF(n->mapFromScene(scenePos), local).length();
    if (d <= bestDist) {
      bestDist = d;
      best = {n, name, output};
    }
  };
  for (const auto& [id, n] : nodes_) {
    if (!n->output.isEmpty()) consider(n, n->outputPos(), n->output, true);
    for (qsizetype i = 0; i < n->inputs.size(); ++i) consider(n, n->inputPos(i), n->inputs[i], false);
  }
  return best;
}

const NodeGraphView::Link* NodeGraphView::linkInto(NodeId to, const QString& input) const {
  for (const Link& l : links_)
    if (l.to == to && l.input == input) return &l;
  return nullptr;
}

NodeId NodeGraphView::linkSource(NodeId to, const QString& input) const {
  const Link* l = linkInto(to, input);
  return l ? l->from : kNoNode;
}

bool NodeGraphView::accepts(NodeId from, NodeId to, const QString& input) const {
  if (input == QLatin1String("material")) return scene_.material(from) && scene_.object(to);
  const Material* m = scene_.material(to);
  if (!m || m->type == MaterialType::Boundary) return false;  // a boundary has no inputs
  if (input == kBlendInput) return from != to && scene_.material(from);
  return textureInputApplies(input, m->type) && scene_.texture(from);
}

const NodeGraphView::Link* NodeGraphView::insertTarget() const {
  // A lone node only: a group carried across a link is being moved out of the way.
  if (moveStart_.size() != 1) return nullptr;
  auto it = nodes_.find(moveStart_.front().first);
  if (it == nodes_.end()) return nullptr;
  const GraphNodeItem* n = it->second;
  // Slightly inside the box: a node dropped overlapping a neighbour only touches the neighbour's
  // link where it leaves the output socket on the box's edge, and that is not a drop on the link.
  const QRectF body = n->mapRectToScene(QRectF(0, 0, kNodeWidth, n->height()).adjusted(2, 2, -2, -2));
  // The stroke, not the path: an open curve's path also "contains" the area between it and its chord.
  QPainterPathStroker stroker;
  stroker.setWidth(1);
  const Link* best = nullptr;
  qreal bestDist = std::numeric_limits<qreal>::max();
  for (const Link& l : links_) {
    // The node's own links move with it and always touch its box.
    if (l.from == n->id || l.to == n->id || !accepts(n->id, l.to, l.input)) continue;
    const QPainterPath path = l.item->path();
    if (!stroker.createStroke(path).intersects(body)) continue;
    // Several links under one box: the one passing closest to its middle is the one aimed at.
    qreal dist = std::numeric_limits<qreal>::max();
    for (int i = 0; i <= 32; ++i) dist = std::min(dist, QLineF(body.center(), path.pointAtPercent(i / 32.0)).length());
    if (dist < bestDist) {
      bestDist = dist;
      best = &l;
    }
  }
  return best;
}

void NodeGraphView::highlightLink(const Link* target) {
  // In the whole graph, the selection's links stand out of the bundle: the others fade.
  std::set<NodeId> selected;
  if (!focused())
    for (const auto& [id, n] : nodes_)
      if (n->isSelected()) selected.insert(id);
  // Every link, not just the previous target: a refresh in the middle of a drag rebuilds the items.
  for (const Link& l : links_) {
    const bool faded = !selected.empty() && !selected.count(l.from) && !selected.count(l.to);
    const LinkLook look = &l == target ? LinkLook::Highlighted : faded ? LinkLook::Faded : LinkLook::Normal;
    l.item->setPen(linkPen(l.input, look));
    l.item->setZValue(kLinkZ + (look == LinkLook::Faded ? 0 : 1));
  }
}

bool NodeGraphView::request(GraphEdit edit, const Scene& result) {
  if (edit.steps.empty()) return false;
  const unsigned count = documentCount_;
  emit editRequested(edit);
  // The main window refreshes through a queued setDocument; until it arrives, a second gesture
  // (two quick creates, two renames) would build on the old scene, reusing an id or taking stale
  // befores. Show the result now; the owner's refresh brings the same scene. An owner that
  // refreshed synchronously has already said what the document is.
  if (documentCount_ == count) {
    scene_ = result;
    rebuild();
  }
  return true;
}

bool NodeGraphView::link(NodeId from, NodeId to, const QString& input) {
  if (!accepts(from, to, input)) return false;
  EditBuilder b(scene_);
  if (!b.assign(to, input, from)) return false;
  return request(b.finish(tr("Link %1 to %2 %3").arg(nameOf(scene_, from), nameOf(scene_, to), input)), b.scene());
}

bool NodeGraphView::unlink(NodeId to, const QString& input) {
  const Link* l = linkInto(to, input);
  if (!l) return false;
  EditBuilder b(scene_);
  if (!b.assign(to, input, kNoNode)) return false;
  return request(b.finish(tr("Unlink %1 %2").arg(nameOf(scene_, to), input)), b.scene());
}

bool NodeGraphView::insertDropped(const Link& target) {
  const NodeId node = moveStart_.front().first, to = target.to;
  const QString input = target.input;  // `target` goes with the rebuild that request() may do
  EditBuilder b(scene_);
  if (!b.assign(to, input, node)) return false;
  return request(b.finish(tr("Insert %1 into %2.%3").arg(nameOf(scene_, node), nameOf(scene_, to), input)), b.scene());
}

bool NodeGraphView::createNode(const QString& type, QPointF scenePos) {
  EditBuilder b(scene_);
  const NodeId id = b.newId();
  if (type == QLatin1String("Material")) {
    Material m;
    m.id = id;
    m.name = uniqueName(scene_.materials, "Material");
    b.step(RemoveNode{id}, AddMaterial{m});
  } else if (type == QLatin1String("Checker Texture")) {
    // A checker: a file texture needs a path, and a checker shows the uv layout right away.
    Texture t;
    t.id = id;
    t.name = uniqueName(scene_.textures, "Checker");
    t.kind = TextureKind::Checker;
    b.step(RemoveNode{id}, AddTexture{t});
  } else if (type.endsWith(QLatin1String("Light"))) {
    Light l;
    l.id = id;
    if (type == QLatin1String("Spot Light")) l.type = LightType::Spot;
    else if (type == QLatin1String("Directional Light")) l.type = LightType::Directional;
    else if (type != QLatin1String("Point Light")) return false;
    l.name = uniqueName(scene_.lights, type.toStdString());
    // Above the middle of the scene, where a new light is visible in the default view.
    const Bounds3 bounds = scene_.worldBounds();
    l.position = bounds.empty() ? Vec3{0.0f, 2.0f, 0.0f} : Vec3{bounds.center().x, bounds.hi.y + 1.0f, bounds.center().z};
    l.intensity = l.type == LightType::Directional ? 1.0f : 5.0f;
    b.step(RemoveNode{id}, AddLight{l});
  } else {
    return false;
  }
  if (!b.ok()) return false;
  positions()[id] = scenePos;
  pendingSelection_ = {id};
  return request(b.finish(tr("Add %1").arg(type)), b.scene());
}

bool NodeGraphView::deleteSelected() {
  std::vector<GraphNodeItem*> chosen;
  for (auto& [id, n] : nodes_)
    if (n->isSelected() && n->deletable()) chosen.push_back(n);
  if (chosen.empty()) return false;
  // Users before what they use: a deleted object needs no material reassignment first.
  auto rank = [](NodeKind k) { return k == NodeKind::Object ? 0 : k == NodeKind::Light ? 1 : k == NodeKind::Material ? 2 : 3; };
  std::sort(chosen.begin(), chosen.end(), [&](const GraphNodeItem* a, const GraphNodeItem* b) {
    return rank(a->kind) != rank(b->kind) ? rank(a->kind) < rank(b->kind) : a->id < b->id;
  });
  EditBuilder b(scene_);
  for (const GraphNodeItem* n : chosen)
    if (!b.remove(n->id)) return false;
  const QString text =
      chosen.size() == 1 ? tr("Delete %1").arg(nameOf(scene_, chosen.front()->id)) : tr("Delete %1 nodes").arg(chosen.size());
  return request(b.finish(text), b.scene());
}

bool NodeGraphView::duplicateSelected() {
  EditBuilder b(scene_);
  std::vector<NodeId> made;
  const QPointF offset(30, 30);
  for (NodeId id : selectedNodes()) {
    const NodeId copyId = b.newId();
    if (const Material* m = scene_.material(id)) {
      Material c = *m;
      c.id = copyId;
      c.name = uniqueName(b.scene().materials, c.name);
      if (!b.step(RemoveNode{copyId}, AddMaterial{c})) return false;
    } else if (const Object* o = scene_.object(id)) {
      Object c = *o;
      c.id = copyId;
      c.name = uniqueName(b.scene().objects, c.name);
      if (!b.step(RemoveNode{copyId}, AddObject{c})) return false;
    } else if (const Light* l = scene_.light(id)) {
      Light c = *l;
      c.id = copyId;
      c.name = uniqueName(b.scene().lights, c.name);
      if (!b.step(RemoveNode{copyId}, AddLight{c})) return false;
    } else {
      continue;
    }
    positions()[copyId] = nodePosition(id) + offset;
    made.push_back(copyId);
  }
  if (made.empty()) return false;
  pendingSelection_ = made;
  return request(
      b.finish(made.size() == 1 ? tr("Duplicate %1").arg(nameOf(b.scene(), made.front())) : tr("Duplicate %1 nodes").arg(made.size())),
      b.scene());
}

void NodeGraphView::copySelected() {
  copiedMaterials_.clear();
  copiedLights_.clear();
  copiedPositions_.clear();
  std::vector<QPointF> lightPositions;
  for (NodeId id : selectedNodes()) {
    if (const Material* m = scene_.material(id)) {
      copiedMaterials_.push_back(*m);
      copiedPositions_.push_back(nodePosition(id));
    } else if (const Light* l = scene_.light(id)) {
      copiedLights_.push_back(*l);
      lightPositions.push_back(nodePosition(id));
    }
  }
  copiedPositions_.insert(copiedPositions_.end(), lightPositions.begin(), lightPositions.end());
  pasteCount_ = 0;
}

bool NodeGraphView::paste() {
  if (copiedMaterials_.empty() && copiedLights_.empty()) return false;
  EditBuilder b(scene_);
  std::vector<NodeId> made;
  const QPointF offset = QPointF(40, 40) * (pasteCount_ + 1);
  std::size_t k = 0;
  for (Material m : copiedMaterials_) {
    m.id = b.newId();
    m.name = uniqueName(b.scene().materials, m.name);
    // The copy may come from before its textures were deleted: keep only what still exists.
    for (NodeId* t : m.textureSlots())
      if (*t != kNoNode && !scene_.texture(*t)) *t = kNoNode;
    if (m.blendWith != kNoNode && !scene_.material(m.blendWith)) m.blendWith = kNoNode;  // likewise its partner
    if (!b.step(RemoveNode{m.id}, AddMaterial{m})) return false;
    positions()[m.id] = copiedPositions_[k++] + offset;
    made.push_back(m.id);
  }
  for (Light l : copiedLights_) {
    l.id = b.newId();
    l.name = uniqueName(b.scene().lights, l.name);
    if (!b.step(RemoveNode{l.id}, AddLight{l})) return false;
    positions()[l.id] = copiedPositions_[k++] + offset;
    made.push_back(l.id);
  }
  ++pasteCount_;
  pendingSelection_ = made;
  return request(b.finish(tr("Paste %n node(s)", nullptr, static_cast<int>(made.size()))), b.scene());
}

bool NodeGraphView::renameNode(NodeId id, const QString& name) {
  const std::string n = name.trimmed().toStdString();
  if (n.empty()) return false;
  EditBuilder b(scene_);
  bool changed = false;
  auto rename = [&](auto node) {
    if (!node || node->name == n) return;
    auto c = *node;
    c.name = n;
    changed = b.set(c);
  };
  rename(scene_.material(id));
  rename(scene_.object(id));
  rename(scene_.light(id));
  rename(scene_.texture(id));
  if (!changed) return false;
  return request(b.finish(tr("Rename %1 to %2").arg(nameOf(scene_, id), name.trimmed())), b.scene());
}

void NodeGraphView::startRename(NodeId id) {
  auto it = nodes_.find(id);
  // One editor at a time: the open one keeps what has been typed into it (and the focus).
  if (it == nodes_.end() || !it->second->deletable() || rename_) return;
  const GraphNodeItem* n = it->second;
  auto* editor = new RenameEdit(viewport());
  editor->setObjectName(QStringLiteral("nodeRename"));
  editor->setText(n->title);
  editor->selectAll();
  QRect r = mapFromScene(n->mapToScene(QRectF(0, 0, kNodeWidth, kHeaderH))).boundingRect();
  r.setHeight(std::max(r.height(), editor->sizeHint().height()));
  editor->setGeometry(r);
  rename_ = editor;
  // Finished fires on Enter and again on the focus loss that hiding causes: act once.
  auto done = std::make_shared<bool>(false);
  auto close = [this, editor, done] {
    *done = true;
    rename_ = nullptr;
    editor->hide();
    editor->deleteLater();
    setFocus();
  };
  editor->cancelled = close;
  connect(editor, &QLineEdit::editingFinished, this, [this, editor, id, done, close] {
    if (*done) return;
    const QString text = editor->text();
    close();
    renameNode(id, text);
  });
  editor->show();
  editor->setFocus();
}

void NodeGraphView::openNodeSearch(QPointF scenePos) {
  searchScenePos_ = scenePos;
  if (!search_)
    search_ = new NodeSearchPopup(this, [this](const QString& type) {
      createNode(type, searchScenePos_);
      setFocus();
    });
  search_->popupAt(viewport()->mapToGlobal(mapFromScene(scenePos)));
}

void NodeGraphView::frameRect(QRectF r, const QRectF& focus) {
  if (r.isEmpty() || viewport()->width() < 2) return;
  r.adjust(-40, -40, 40, 40);
  // The buttons in the corner cover the top of the viewport: frame below them.
  const qreal top = scopeBar_->height();
  const QSizeF view(viewport()->width(), std::max(1.0, viewport()->height() - top));
  // Framing a single small node should not blow it up past a readable size, nor framing a big
  // graph shrink it past one.
  const qreal zoom = std::clamp(std::min(view.width() / r.width(), view.height() / r.height()), legibleZoom(), 1.5);
  setTransform(QTransform::fromScale(zoom, zoom));
  centerOn(framingCentre(r, focus.adjusted(-40, -40, 40, 40), view / zoom) - QPointF(0, top / 2 / zoom));
}

void NodeGraphView::frameSelected() {
  QRectF r;
  for (const auto& [id, n] : nodes_)
    if (n->isSelected()) r |= n->sceneBoundingRect();
  if (r.isEmpty()) frameAll();
  else frameRect(r, r);
}

void NodeGraphView::frameAll() {
  QRectF r, focus;
  for (const auto& [id, n] : nodes_) r |= n->sceneBoundingRect();
  // What stays in view when not everything fits: the selection's objects and their materials,
  // else the graph's selected nodes, else its top-left corner, where the first column starts.
  for (NodeId id : roots_) {
    const Object* o = scene_.object(id);
    for (NodeId n : {id, o ? o->material : kNoNode})
      if (nodes_.count(n)) focus |= nodes_.at(n)->sceneBoundingRect();
  }
  if (focus.isEmpty())
    for (const auto& [id, n] : nodes_)
      if (n->isSelected()) focus |= n->sceneBoundingRect();
  if (focus.isEmpty()) focus = QRectF(r.topLeft(), QSizeF(1, 1));
  frameRect(r, focus);
}

void NodeGraphView::showEvent(QShowEvent* e) {
  QGraphicsView::showEvent(e);
  if (!framed_ && hasDocument_) {
    framed_ = true;
    frameAll();
  }
}

namespace {

// Keys the graph handles while it has focus, even when a window action uses the same shortcut.
bool graphKey(const QKeyEvent* k) {
  const auto mods = k->modifiers() & ~Qt::KeypadModifier;
  if (mods == Qt::ControlModifier) return k->key() == Qt::Key_D || k->key() == Qt::Key_C || k->key() == Qt::Key_V;
  if (mods == Qt::NoModifier)
    return k->key() == Qt::Key_Tab || k->key() == Qt::Key_F2 || k->key() == Qt::Key_Delete || k->key() == Qt::Key_Backspace;
  return false;
}

bool framingKey(const QKeyEvent* k) {
  return (k->modifiers() & ~Qt::KeypadModifier) == Qt::NoModifier && (k->key() == Qt::Key_F || k->key() == Qt::Key_A);
}

}  // namespace

bool NodeGraphView::mouseOver() const {
  return isVisible() && (viewport()->underMouse() || viewport()->rect().contains(viewport()->mapFromGlobal(QCursor::pos())));
}

bool NodeGraphView::event(QEvent* e) {
  // F and A frame the panel under the mouse: here while the mouse is over the graph, the
  // viewport's framing and compare otherwise, wherever the keyboard focus is.
  if (e->type() == QEvent::ShortcutOverride &&
      (graphKey(static_cast<QKeyEvent*>(e)) || (framingKey(static_cast<QKeyEvent*>(e)) && mouseOver()) ||
       (drag_ == Drag::Link && static_cast<QKeyEvent*>(e)->key() == Qt::Key_Escape))) {
    e->accept();
    return true;
  }
  // Tab would move the focus before keyPressEvent sees it.
  if (e->type() == QEvent::KeyPress) {
    auto* k = static_cast<QKeyEvent*>(e);
    if (k->key() == Qt::Key_Tab && (k->modifiers() & ~Qt::KeypadModifier) == Qt::NoModifier) {
      QPoint at = viewport()->mapFromGlobal(QCursor::pos());
      if (!viewport()->rect().contains(at)) at = viewport()->rect().center();
      openNodeSearch(mapToScene(at));
      return true;
    }
  }
  return QGraphicsView::event(e);
}

void NodeGraphView::keyPressEvent(QKeyEvent* e) {
  const auto mods = e->modifiers() & ~Qt::KeypadModifier;
  if (mods == Qt::ControlModifier) {
    switch (e->key()) {
      case Qt::Key_D: duplicateSelected(); return;
      case Qt::Key_C: copySelected(); return;
      case Qt::Key_V: paste(); return;
      default: break;
    }
  } else if (mods == Qt::NoModifier) {
    switch (e->key()) {
      case Qt::Key_F:
      case Qt::Key_A:
        if (!mouseOver()) break;  // the window frames the viewport
        if (e->key() == Qt::Key_F) frameSelected();
        else frameAll();
        return;
      case Qt::Key_Delete:
      case Qt::Key_Backspace: deleteSelected(); return;
      case Qt::Key_F2:
        for (NodeId id : selectedNodes())
          if (nodes_.at(id)->deletable()) {
            startRename(id);
            return;
          }
        return;
      case Qt::Key_Escape:
        if (drag_ == Drag::Link) {
          drag_ = Drag::None;
          dragLink_->hide();
          for (Link& l : links_) l.item->show();
          return;
        }
        break;
      default: break;
    }
  }
  QGraphicsView::keyPressEvent(e);
}

void NodeGraphView::mousePressEvent(QMouseEvent* e) {
  // A second button in the middle of a drag would start another gesture over the first one's state
  // and leave its dashed link or rubber band on screen: the drag owns the mouse until it ends.
  if (drag_ != Drag::None && e->button() != dragButton_) {
    e->accept();
    return;
  }
  if (drag_ != Drag::None) {
    // The dragging button pressed again: its release went elsewhere (a modal dialog took it). Drop
    // the stale drag without acting on it rather than ignore the mouse from now on.
    drag_ = Drag::None;
    dragLink_->hide();
    marquee_->hide();
    for (Link& l : links_) l.item->show();
    highlightLink(nullptr);
  }
  setFocus(Qt::MouseFocusReason);
  dragButton_ = e->button();
  pressPos_ = lastPos_ = e->pos();
  pressScene_ = mapToScene(e->pos());
  pressModifiers_ = e->modifiers();
  moved_ = false;
  pressedNode_ = kNoNode;
  if (e->button() == Qt::MiddleButton || (e->button() == Qt::LeftButton && (e->modifiers() & Qt::AltModifier))) {
    drag_ = Drag::Pan;
    return;
  }
  if (e->button() == Qt::RightButton) {
    drag_ = Drag::None;
    openNodeSearch(pressScene_);
    return;
  }
  if (e->button() != Qt::LeftButton) return;
  mouseDown_ = true;  // until this button's release: see followSelection

  // Sockets first: they stick out of the node boxes, and a press on one never selects.
  const SocketHit s = socketAt(pressScene_);
  if (s.node && s.output) {
    linkFrom_ = s.node->id;
    detachedTo_ = kNoNode;
    drag_ = Drag::Link;
    dragLink_->setPath(linkPath(s.node->mapToScene(s.node->outputPos()), pressScene_));
    dragLink_->show();
    return;
  }
  if (s.node) {
    for (Link& l : links_)
      if (l.to == s.node->id && l.input == s.socket) {
        // Picking up a link by its input end: drop it elsewhere to move it, on nothing to unlink.
        linkFrom_ = l.from;
        detachedTo_ = l.to;
        detachedInput_ = l.input;
        l.item->hide();
        const GraphNodeItem* from = nodes_.at(l.from);
        dragLink_->setPath(linkPath(from->mapToScene(from->outputPos()), pressScene_));
        dragLink_->show();
        drag_ = Drag::Link;
        return;
      }
  }

  if (GraphNodeItem* n = nodeAt(pressScene_)) {
    pressedNode_ = n->id;
    if (e->modifiers() & Qt::ControlModifier) {
      n->setSelected(!n->isSelected());
      setSelection(selectedNodes());  // restacks
      drag_ = Drag::None;
      return;
    }
    if (e->modifiers() & Qt::ShiftModifier) {
      std::vector<NodeId> ids = selectedNodes();
      ids.push_back(n->id);
      setSelection(ids);
    } else if (!n->isSelected()) {
      setSelection({n->id});
    }
    if (n->kind == NodeKind::Object) emit objectSelected(n->id);
    moveStart_.clear();
    for (NodeId id : selectedNodes()) moveStart_.emplace_back(id, nodes_.at(id)->pos());
    drag_ = Drag::Move;
    return;
  }

  // A click on empty canvas keeps the selection (it is often the viewport's object); a marquee
  // drag replaces it, or adds to it with Shift or Ctrl.
  marqueeBase_.clear();
  if (e->modifiers() & (Qt::ShiftModifier | Qt::ControlModifier)) marqueeBase_ = selectedNodes();
  marquee_->setRect(QRectF(pressScene_, QSizeF()));
  marquee_->show();
  drag_ = Drag::Marquee;
}

void NodeGraphView::mouseMoveEvent(QMouseEvent* e) {
  const QPointF sp = mapToScene(e->pos());
  if ((e->pos() - pressPos_).manhattanLength() >= QApplication::startDragDistance()) moved_ = true;
  switch (drag_) {
    case Drag::None: QGraphicsView::mouseMoveEvent(e); break;
    case Drag::Pan: {
      const QPoint d = e->pos() - lastPos_;
      horizontalScrollBar()->setValue(horizontalScrollBar()->value() - d.x());
      verticalScrollBar()->setValue(verticalScrollBar()->value() - d.y());
      break;
    }
    case Drag::Link: {
      auto it = nodes_.find(linkFrom_);
      if (it == nodes_.end()) break;
      QPointF end = sp;
      // Snap onto a socket that would take the link, so the artist sees it will connect.
      const SocketHit t = socketAt(sp);
      if (t.node && !t.output && accepts(linkFrom_, t.node->id, t.socket))
        end = t.node->mapToScene(t.node->inputPos(t.node->inputs.indexOf(t.socket)));
      dragLink_->setPath(linkPath(it->second->mapToScene(it->second->outputPos()), end));
      break;
    }
    case Drag::Move: {
      if (!moved_) break;
      const QPointF d = sp - pressScene_;
      for (const auto& [id, start] : moveStart_) {
        auto it = nodes_.find(id);
        if (it == nodes_.end()) continue;
        it->second->setPos(start + d);
        positions()[id] = start + d;
      }
      updateLinkPaths();
      highlightLink(insertTarget());  // what a release here would do
      break;
    }
    case Drag::Marquee: {
      if (!moved_) break;  // still a click
      const QRectF r = QRectF(pressScene_, sp).normalized();
      marquee_->setRect(r);
      std::vector<NodeId> ids = marqueeBase_;
      for (const auto& [id, n] : nodes_)
        if (n->sceneBoundingRect().intersects(r)) ids.push_back(id);
      setSelection(ids);
      break;
    }
  }
  lastPos_ = e->pos();
}

void NodeGraphView::mouseReleaseEvent(QMouseEvent* e) {
  if (e->button() != dragButton_) return;  // another button than the one dragging: see mousePressEvent
  const Drag d = drag_;
  drag_ = Drag::None;
  mouseDown_ = false;
  switch (d) {
    case Drag::None:
    case Drag::Pan: break;
    case Drag::Link: finishLinkDrag(mapToScene(e->pos())); break;
    case Drag::Move: {
      // A click (no drag) on one of several selected nodes selects just it.
      if (!moved_ && !(pressModifiers_ & (Qt::ShiftModifier | Qt::ControlModifier)) && nodes_.count(pressedNode_))
        setSelection({pressedNode_});
      const Link* target = moved_ ? insertTarget() : nullptr;
      highlightLink(nullptr);
      if (target) insertDropped(*target);
      break;
    }
    case Drag::Marquee: marquee_->hide(); break;
  }
  if (rootsPending_) followSelection(pendingRoots_);
}

void NodeGraphView::finishLinkDrag(QPointF scenePos) {
  dragLink_->hide();
  // Shown again before any edit: a refused edit leaves the graph as it was, an applied one rebuilds it.
  for (Link& l : links_) l.item->show();
  const NodeId from = linkFrom_, oldTo = detachedTo_;
  const QString oldInput = detachedInput_;
  linkFrom_ = detachedTo_ = kNoNode;
  const SocketHit t = socketAt(scenePos);
  const bool onTarget = t.node && !t.output && accepts(from, t.node->id, t.socket);
  if (oldTo == kNoNode) {
    if (onTarget) link(from, t.node->id, t.socket);
    return;
  }
  if (!onTarget) {
    unlink(oldTo, oldInput);
    return;
  }
  if (t.node->id == oldTo && t.socket == oldInput) return;
  // Moving a link is one undo step: clear the old input, then set the new one.
  EditBuilder b(scene_);
  b.assign(oldTo, oldInput, kNoNode);
  if (!b.assign(t.node->id, t.socket, from)) return;
  request(b.finish(tr("Move link to %1 %2").arg(nameOf(scene_, t.node->id), t.socket)), b.scene());
}

void NodeGraphView::mouseDoubleClickEvent(QMouseEvent* e) {
  const QPointF sp = mapToScene(e->pos());
  if (e->button() == Qt::LeftButton && drag_ == Drag::None && !socketAt(sp).node)
    if (GraphNodeItem* n = nodeAt(sp)) {
      startRename(n->id);
      return;
    }
  mousePressEvent(e);
}

void NodeGraphView::wheelEvent(QWheelEvent* e) {
  const qreal current = transform().m11();
  const qreal wanted = std::clamp(current * std::pow(1.0015, e->angleDelta().y()), 0.15, 3.0);
  scale(wanted / current, wanted / current);
  e->accept();
}

void NodeGraphView::drawBackground(QPainter* p, const QRectF& rect) {
  p->fillRect(rect, QColor(36, 36, 40));
  const qreal step = 24;
  if (transform().m11() * step < 6) return;  // a dense grid is noise
  const qreal left = std::floor(rect.left() / step) * step, top = std::floor(rect.top() / step) * step;
  const QPen minor(QColor(44, 44, 50), 0), major(QColor(54, 54, 62), 0);
  for (qreal x = left; x < rect.right(); x += step) {
    p->setPen(std::fmod(std::abs(x), step * 5) < 0.5 ? major : minor);
    p->drawLine(QPointF(x, rect.top()), QPointF(x, rect.bottom()));
  }
  for (qreal y = top; y < rect.bottom(); y += step) {
    p->setPen(std::fmod(std::abs(y), step * 5) < 0.5 ? major : minor);
    p->drawLine(QPointF(rect.left(), y), QPointF(rect.right(), y));
  }
}

}  // namespace retile::ui
