#include "node_graph.h"

#include <QApplication>
#include <QCursor>
#include <QFrame>
#include <QGraphicsPathItem>
#include <QGraphicsRectItem>
#include <QGraphicsScene>
#include <QKeyEvent>
#include <QLineEdit>
#include <QListWidget>
#include <QMouseEvent>
#include <QPainter>
#include <QPainterPathStroker>
#include <QRegularExpression>
#include <QScrollBar>
#include <QVBoxLayout>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>

namespace retile::ui {
namespace {

constexpr qreal kNodeWidth = 190;
constexpr qreal kHeaderH = 24;
constexpr qreal kSubtitleH = 18;
constexpr qreal kRowH = 20;
constexpr qreal kBottomPad = 8;
constexpr qreal kSocketR = 5.5;
constexpr qreal kColumnStep = kNodeWidth + 90;
constexpr qreal kRowGap = 24;

enum class NodeKind { Texture, Material, Object, Light, Camera, Settings };

int columnOf(NodeKind k) {
  switch (k) {
    case NodeKind::Texture: return 0;
    case NodeKind::Material: return 1;
    case NodeKind::Object: return 2;
    default: return 3;
  }
}

QColor headerColor(NodeKind k) {
  switch (k) {
    case NodeKind::Texture: return {176, 112, 40};
    case NodeKind::Material: return {52, 132, 82};
    case NodeKind::Object: return {52, 96, 168};
    case NodeKind::Light: return {168, 148, 36};
    case NodeKind::Camera: return {118, 80, 160};
    case NodeKind::Settings: return {92, 92, 104};
  }
  return Qt::gray;
}

// Sockets are coloured by what flows through them, so a compatible pair is recognisable at a glance.
QColor socketColor(const QString& socket) {
  return socket == QLatin1String("material") || socket == QLatin1String("blend") ? QColor(96, 210, 128) : QColor(236, 196, 72);
}

// A material's input that takes the material it blends with (Material::blendWith), below its
// texture inputs.
const QString kBlendInput = QStringLiteral("blend");

// A material node's texture inputs, top to bottom, and the fields they set.
struct TextureInput {
  const char* name;
  NodeId Material::*field;
};
constexpr TextureInput kTextureInputs[] = {{"albedo", &Material::albedoTexture},
                                           {"roughness", &Material::roughnessTexture},
                                           {"alpha", &Material::alphaTexture},
                                           {"bump", &Material::bumpTexture},
                                           {"emission", &Material::emissionTexture},
                                           {"blend ratio", &Material::blendRatioTexture}};

const QStringList& textureInputs() {
  static const QStringList inputs = [] {
    QStringList l;
    for (const TextureInput& t : kTextureInputs) l << QLatin1String(t.name);
    return l;
  }();
  return inputs;
}

bool isTextureInput(const QString& s) { return textureInputs().contains(s); }

NodeId Material::*textureSlot(const QString& input) {
  for (const TextureInput& t : kTextureInputs)
    if (input == QLatin1String(t.name)) return t.field;
  return nullptr;
}

// A link about to take a dropped node stands out from the others: thicker and brighter.
QPen linkPen(const QString& input, bool highlighted) {
  return highlighted ? QPen(socketColor(input).lighter(145), 5) : QPen(socketColor(input), 2.5);
}

QPainterPath linkPath(QPointF a, QPointF b) {
  QPainterPath p(a);
  const qreal dx = std::max<qreal>(40, std::abs(b.x() - a.x()) * 0.5);
  p.cubicTo(a + QPointF(dx, 0), b - QPointF(dx, 0), b);
  return p;
}

QColor displayColor(const Vec3& linear) {
  auto c = [](float v) { return static_cast<int>(std::lround(255 * std::pow(std::clamp(v, 0.0f, 1.0f), 1 / 2.2f))); };
  return {c(linear.x), c(linear.y), c(linear.z)};
}

// "Name", "Name.001", ...: Blender's convention, which artists already read as "a copy of Name".
template <class Node>
std::string uniqueName(const std::vector<Node>& nodes, std::string base) {
  static const QRegularExpression suffix(QStringLiteral("\\.\\d{3}$"));
  QString b = QString::fromStdString(base);
  b.remove(suffix);
  if (b.isEmpty()) b = QStringLiteral("Node");
  auto taken = [&](const std::string& n) {
    return std::any_of(nodes.begin(), nodes.end(), [&](const Node& x) { return x.name == n; });
  };
  if (!taken(b.toStdString())) return b.toStdString();
  for (int i = 1;; ++i) {
    std::string n = QStringLiteral("%1.%2").arg(b).arg(i, 3, 10, QLatin1Char('0')).toStdString();
    if (!taken(n)) return n;
  }
}

// Builds a GraphEdit against a working copy of the scene: every `after` is applied to the copy as it
// is added, so later steps see the earlier ones (their `before` values are right for undo, new ids
// do not collide) and a step the document would refuse aborts the whole edit here.
class EditBuilder {
 public:
  explicit EditBuilder(const Scene& s) : scene_(s) {}

  const Scene& scene() const { return scene_; }
  bool ok() const { return ok_; }
  bool empty() const { return edit_.steps.empty(); }

  bool step(Edit before, Edit after) {
    if (!ok_) return false;
    if (!applyEdit(scene_, after).ok()) {
      ok_ = false;
      return false;
    }
    edit_.steps.emplace_back(std::move(before), std::move(after));
    return true;
  }

  bool set(const Material& m) {
    const Material* old = scene_.material(m.id);
    return old && step(SetMaterial{*old}, SetMaterial{m});
  }
  bool set(const Object& o) {
    const Object* old = scene_.object(o.id);
    return old && step(SetObject{*old}, SetObject{o});
  }
  bool set(const Light& l) {
    const Light* old = scene_.light(l.id);
    return old && step(SetLight{*old}, SetLight{l});
  }
  bool set(const Texture& t) {
    const Texture* old = scene_.texture(t.id);
    return old && step(SetTexture{*old}, SetTexture{t});
  }

  NodeId newId() const {
    NodeId id = scene_.peekNextId();
    while (scene_.mesh(id) || scene_.material(id) || scene_.object(id) || scene_.light(id) || scene_.texture(id)) ++id;
    return id;
  }

  // Points `to`'s input at `from` (kNoNode clears it). False when nothing changes or it is not allowed.
  bool assign(NodeId to, const QString& input, NodeId from) {
    if (input == QLatin1String("material")) {
      const Object* o = scene_.object(to);
      if (!o || (from != kNoNode && !scene_.material(from)) || o->material == from) return false;
      Object c = *o;
      c.material = from;
      return set(c);
    }
    if (input == kBlendInput) {
      const Material* m = scene_.material(to);
      if (!m || from == to || (from != kNoNode && !scene_.material(from)) || m->blendWith == from) return false;
      Material c = *m;
      c.setBlendWith(from);
      return set(c);
    }
    NodeId Material::*slot = textureSlot(input);
    const Material* m = scene_.material(to);
    if (!slot || !m || (from != kNoNode && !scene_.texture(from)) || m->*slot == from) return false;
    Material c = *m;
    c.*slot = from;
    return set(c);
  }

  // Clears the references to the node first, so that undoing (befores in reverse) adds it back and
  // then restores them.
  bool remove(NodeId id) {
    if (const Object* o = scene_.object(id)) return step(AddObject{*o}, RemoveNode{id});
    if (const Light* l = scene_.light(id)) return step(AddLight{*l}, RemoveNode{id});
    if (const Material* m = scene_.material(id)) {
      Material copy = *m;
      std::vector<NodeId> users;
      for (const Object& o : scene_.objects)
        if (o.material == id) users.push_back(o.id);
      for (NodeId u : users)
        if (!assign(u, QStringLiteral("material"), kNoNode)) return false;
      std::vector<NodeId> blends;
      for (const Material& b : scene_.materials)
        if (b.blendWith == id) blends.push_back(b.id);
      for (NodeId b : blends)
        if (!assign(b, kBlendInput, kNoNode)) return false;
      return step(AddMaterial{copy}, RemoveNode{id});
    }
    if (const Texture* t = scene_.texture(id)) {
      Texture copy = *t;
      std::vector<std::pair<NodeId, QString>> users;
      for (const Material& m : scene_.materials)
        for (const QString& slot : textureInputs())
          if (m.*textureSlot(slot) == id) users.emplace_back(m.id, slot);
      for (const auto& [m, slot] : users)
        if (!assign(m, slot, kNoNode)) return false;
      if (scene_.environment.map == id) {
        Environment env = scene_.environment;
        env.map = kNoNode;
        env.type = EnvironmentType::Constant;  // what RemoveNode does; stated so undo restores the type
        if (!step(SetEnvironment{scene_.environment}, SetEnvironment{env})) return false;
      }
      return step(AddTexture{copy}, RemoveNode{id});
    }
    return false;
  }

  GraphEdit finish(const QString& text) {
    edit_.text = text;
    return std::move(edit_);
  }

 private:
  Scene scene_;
  GraphEdit edit_;
  bool ok_ = true;
};

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

// One node: a rounded box with a coloured header, a subtitle line and one row per socket (inputs on
// the left, the output on the right of the first row). Plain data; the view lays it out and rebuilds it.
class GraphNodeItem : public QGraphicsItem {
 public:
  enum { Type = UserType + 1 };

  GraphNodeItem(NodeId nodeId, NodeKind nodeKind) : id(nodeId), kind(nodeKind) {
    setFlag(ItemIsSelectable);
    setZValue(1);
  }
  int type() const override { return Type; }

  qreal height() const {
    const auto rows = std::max<qsizetype>(inputs.size(), output.isEmpty() ? 0 : 1);
    return kHeaderH + kSubtitleH + static_cast<qreal>(rows) * kRowH + kBottomPad;
  }
  QRectF boundingRect() const override {
    return {-kSocketR - 2, -2, kNodeWidth + 2 * kSocketR + 4, height() + 4};
  }
  QPointF inputPos(qsizetype i) const { return {0, kHeaderH + kSubtitleH + (static_cast<qreal>(i) + 0.5) * kRowH}; }
  QPointF outputPos() const { return {kNodeWidth, kHeaderH + kSubtitleH + 0.5 * kRowH}; }
  bool deletable() const { return kind != NodeKind::Camera && kind != NodeKind::Settings; }

  void paint(QPainter* p, const QStyleOptionGraphicsItem*, QWidget*) override {
    p->setRenderHint(QPainter::Antialiasing, true);
    const QRectF body(0, 0, kNodeWidth, height());
    QPainterPath shape;
    shape.addRoundedRect(body, 7, 7);
    p->fillPath(shape, QColor(50, 50, 56, 240));
    p->save();
    p->setClipRect(QRectF(0, 0, kNodeWidth, kHeaderH));
    p->fillPath(shape, headerColor(kind));
    p->restore();
    p->setBrush(Qt::NoBrush);
    p->setPen(isSelected() ? QPen(QColor(255, 168, 40), 2.4) : QPen(QColor(18, 18, 20), 1));
    p->drawPath(shape);

    QFont titleFont = p->font();
    titleFont.setBold(true);
    p->setFont(titleFont);
    p->setPen(Qt::white);
    const qreal swatchSpace = swatch.isValid() ? 22 : 0;
    const QRectF titleRect(8, 0, kNodeWidth - 16 - swatchSpace, kHeaderH);
    p->drawText(titleRect, Qt::AlignVCenter | Qt::AlignLeft,
                QFontMetricsF(titleFont).elidedText(title, Qt::ElideRight, titleRect.width()));
    if (swatch.isValid()) {
      p->setPen(QPen(QColor(20, 20, 20), 1));
      p->setBrush(swatch);
      p->drawRoundedRect(QRectF(kNodeWidth - 22, 5, 14, 14), 3, 3);
      p->setBrush(Qt::NoBrush);
    }

    QFont small = p->font();
    small.setBold(false);
    small.setPointSizeF(std::max(6.0, small.pointSizeF() * 0.88));
    p->setFont(small);
    p->setPen(QColor(178, 178, 186));
    const QRectF subRect(8, kHeaderH, kNodeWidth - 16, kSubtitleH);
    p->drawText(subRect, Qt::AlignVCenter | Qt::AlignLeft,
                QFontMetricsF(small).elidedText(subtitle, Qt::ElideRight, subRect.width()));

    auto socket = [&](QPointF c, const QString& name) {
      p->setPen(QPen(QColor(18, 18, 20), 1.2));
      p->setBrush(socketColor(name));
      p->drawEllipse(c, kSocketR, kSocketR);
      p->setBrush(Qt::NoBrush);
    };
    for (qsizetype i = 0; i < inputs.size(); ++i) {
      const QPointF c = inputPos(i);
      socket(c, inputs[i]);
      p->setPen(QColor(222, 222, 228));
      p->drawText(QRectF(12, c.y() - kRowH / 2, kNodeWidth / 2, kRowH), Qt::AlignVCenter | Qt::AlignLeft, label(i));
    }
    if (!output.isEmpty()) {
      const QPointF c = outputPos();
      socket(c, output);
      p->setPen(QColor(222, 222, 228));
      p->drawText(QRectF(kNodeWidth / 2, c.y() - kRowH / 2, kNodeWidth / 2 - 12, kRowH),
                  Qt::AlignVCenter | Qt::AlignRight, output);
    }
  }

  // What input i is called on this node: its socket's name unless `labels` renames it.
  QString label(qsizetype i) const { return i < labels.size() && !labels[i].isEmpty() ? labels[i] : inputs[i]; }

  NodeId id;
  NodeKind kind;
  QString title, subtitle;
  QStringList inputs;
  QStringList labels;  // shown instead of inputs' names where not empty (the sockets keep them)
  QString output;
  QColor swatch;  // invalid: none
};

// The Tab / right-click menu: a filter line over the creatable types. Up/Down move, Enter creates,
// Escape (or a click elsewhere: it is a popup) closes.
class NodeSearchPopup : public QFrame {
 public:
  NodeSearchPopup(QWidget* parent, std::function<void(const QString&)> chosen)
      : QFrame(parent, Qt::Popup), chosen_(std::move(chosen)) {
    setFrameShape(QFrame::StyledPanel);
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(4, 4, 4, 4);
    layout->setSpacing(4);
    filter_ = new QLineEdit(this);
    filter_->setObjectName(QStringLiteral("nodeSearch"));
    filter_->setPlaceholderText(NodeGraphView::tr("Add node..."));
    list_ = new QListWidget(this);
    list_->setObjectName(QStringLiteral("nodeSearchList"));
    list_->addItems(NodeGraphView::creatableTypes());
    layout->addWidget(filter_);
    layout->addWidget(list_);
    resize(220, 170);
    filter_->installEventFilter(this);
    QObject::connect(filter_, &QLineEdit::textChanged, this, [this](const QString& t) { refilter(t); });
    QObject::connect(filter_, &QLineEdit::returnPressed, this, [this] { activate(list_->currentItem()); });
    QObject::connect(list_, &QListWidget::itemClicked, this, [this](QListWidgetItem* i) { activate(i); });
  }

  void popupAt(QPoint global) {
    filter_->clear();
    refilter(QString());
    move(global);
    show();
    filter_->setFocus();
  }

 protected:
  bool eventFilter(QObject* o, QEvent* e) override {
    if (o == filter_ && e->type() == QEvent::KeyPress) {
      const int key = static_cast<QKeyEvent*>(e)->key();
      if (key == Qt::Key_Escape) {
        hide();
        return true;
      }
      if (key == Qt::Key_Down || key == Qt::Key_Up) {
        step(key == Qt::Key_Down ? 1 : -1);
        return true;
      }
    }
    return QFrame::eventFilter(o, e);
  }

 private:
  void refilter(const QString& text) {
    QListWidgetItem* first = nullptr;
    for (int i = 0; i < list_->count(); ++i) {
      QListWidgetItem* item = list_->item(i);
      const bool match = item->text().contains(text.trimmed(), Qt::CaseInsensitive);
      item->setHidden(!match);
      if (match && !first) first = item;
    }
    list_->setCurrentItem(first);
  }
  void step(int d) {
    const int n = list_->count();
    for (int i = list_->currentRow() + d; i >= 0 && i < n; i += d)
      if (!list_->item(i)->isHidden()) {
        list_->setCurrentRow(i);
        return;
      }
  }
  void activate(QListWidgetItem* item) {
    if (!item || item->isHidden()) return;
    const QString type = item->text();
    hide();
    chosen_(type);
  }

  std::function<void(const QString&)> chosen_;
  QLineEdit* filter_ = nullptr;
  QListWidget* list_ = nullptr;
};

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
  dragLink_->setZValue(3);
  dragLink_->hide();
  marquee_ = s->addRect(QRectF(), QPen(QColor(255, 168, 40), 1, Qt::DashLine), QColor(255, 168, 40, 36));
  marquee_->setZValue(4);
  marquee_->hide();
}

NodeGraphView::~NodeGraphView() = default;

QStringList NodeGraphView::creatableTypes() {
  return {QStringLiteral("Material"), QStringLiteral("Texture"), QStringLiteral("Light"), QStringLiteral("Spot Light"),
          QStringLiteral("Directional Light")};
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
  rebuild();
  frameAll();
}

void NodeGraphView::rebuild() {
  std::vector<NodeId> selection;
  for (NodeId id : pendingSelection_)
    if (scene_.material(id) || scene_.object(id) || scene_.light(id) || scene_.texture(id)) selection.push_back(id);
  if (selection.empty()) selection = selectedNodes();
  pendingSelection_.clear();

  for (Link& l : links_) delete l.item;
  links_.clear();
  for (auto& [id, n] : nodes_) delete n;
  nodes_.clear();

  std::vector<GraphNodeItem*> order;
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
    QString sub = QString::fromLatin1(materialTypeName(m.type));
    if (m.emissive()) sub += tr(", emissive");
    GraphNodeItem* n = add(m.id, NodeKind::Material, m.name, sub);
    // A boundary is no surface: no texture or blend would change what it renders.
    if (m.type != MaterialType::Boundary) {
      n->inputs = textureInputs();
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
    const Mesh* mesh = scene_.mesh(o.mesh);
    QString sub = mesh ? tr("Mesh: %1").arg(QString::fromStdString(mesh->name)) : tr("No mesh");
    if (!o.visible) sub += tr(" (hidden)");
    add(o.id, NodeKind::Object, o.name, sub)->inputs = {QStringLiteral("material")};
  }
  {
    const Camera& c = scene_.camera;
    const double fov = static_cast<double>(c.verticalFov) * 180.0 / kPi;
    // With a lens, the distance in focus (the subtitle has room for little more).
    add(kCameraNode, NodeKind::Camera, tr("Camera").toStdString(),
        c.apertureRadius > 0
            ? tr("%1\u00b0, in focus at %2").arg(fov, 0, 'f', 1).arg(static_cast<double>(c.focusDistance), 0, 'g', 3)
            : tr("Field of view %1\u00b0").arg(fov, 0, 'f', 1));
    const RenderSettings& r = scene_.settings;
    add(kSettingsNode, NodeKind::Settings, tr("Render Settings").toStdString(),
        tr("%1x%2, %3 spp, %4 bounces").arg(r.width).arg(r.height).arg(r.samplesPerPixel).arg(r.maxBounces));
  }
  for (const Light& l : scene_.lights) {
    static const char* const types[] = {"Point", "Spot", "Directional"};
    const QLatin1String type(types[static_cast<int>(l.type)]);
    const QString sub = tr("%1 light, intensity %2").arg(type).arg(l.intensity);
    GraphNodeItem* n = add(l.id, NodeKind::Light, l.name, sub);
    n->swatch = displayColor(l.color);
  }

  if (positions_.empty()) layOut(order);
  // Nodes seen before keep their place; new ones go below the lowest node of their kind's last column.
  std::map<int, QPointF> below;  // per column kind: where the next node goes
  for (GraphNodeItem* n : order) {
    auto it = positions_.find(n->id);
    if (it == positions_.end()) continue;
    n->setPos(it->second);
    const int c = columnOf(n->kind);
    const QPointF bottom(it->second.x(), it->second.y() + n->height() + kRowGap);
    auto b = below.find(c);
    if (b == below.end() || bottom.x() > b->second.x() + kNodeWidth ||
        (std::abs(bottom.x() - b->second.x()) < kNodeWidth && bottom.y() > b->second.y()))
      below[c] = bottom;
  }
  for (GraphNodeItem* n : order) {
    if (positions_.count(n->id)) continue;
    const int c = columnOf(n->kind);
    auto b = below.find(c);
    const QPointF p = b != below.end() ? b->second : QPointF(c * kColumnStep, 0);
    below[c] = QPointF(p.x(), p.y() + n->height() + kRowGap);
    positions_[n->id] = p;
    n->setPos(p);
  }

  auto addLink = [&](NodeId from, NodeId to, const QString& input) {
    if (!nodes_.count(from) || !nodes_.count(to)) return;
    auto* item = scene()->addPath(QPainterPath(), linkPen(input, false));
    item->setZValue(0);
    links_.push_back({from, to, input, item});
  };
  for (const Object& o : scene_.objects)
    if (o.material != kNoNode) addLink(o.material, o.id, QStringLiteral("material"));
  for (const Material& m : scene_.materials) {
    if (m.type == MaterialType::Boundary) continue;  // no inputs to draw its links to
    for (const QString& slot : textureInputs())
      if (m.*textureSlot(slot) != kNoNode) addLink(m.*textureSlot(slot), m.id, slot);
    if (m.blendWith != kNoNode) addLink(m.blendWith, m.id, kBlendInput);
  }

  setSelection(selection);
  updateLinkPaths();
}

void NodeGraphView::layOut(const std::vector<GraphNodeItem*>& nodes) {
  // Columns by kind (textures, materials, objects, the rest), each in the order of what it feeds,
  // so that links run mostly level: materials as the scene lists them, objects by their material,
  // textures by the first material that uses them. A kind too tall for the panel's shape wraps
  // into more columns; a big scene (the living room has about 90 nodes) fills the panel instead of
  // making one thin column.
  std::unordered_map<NodeId, std::size_t> materialRank, textureRank;
  for (std::size_t i = 0; i < scene_.materials.size(); ++i) {
    const Material& m = scene_.materials[i];
    materialRank[m.id] = i;
    for (NodeId t : m.textures())
      if (t != kNoNode && !textureRank.count(t)) textureRank[t] = i;
  }
  auto rank = [&](const GraphNodeItem* n) -> std::size_t {
    constexpr std::size_t kLast = std::numeric_limits<std::size_t>::max();
    switch (n->kind) {
      case NodeKind::Texture: {
        auto it = textureRank.find(n->id);
        return it == textureRank.end() ? kLast : it->second;
      }
      case NodeKind::Object: {
        const Object* o = scene_.object(n->id);
        auto it = o ? materialRank.find(o->material) : materialRank.end();
        return it == materialRank.end() ? kLast : it->second;
      }
      default: return 0;
    }
  };
  std::array<std::vector<GraphNodeItem*>, 4> columns;
  for (GraphNodeItem* n : nodes) columns[static_cast<std::size_t>(columnOf(n->kind))].push_back(n);
  double area = 0, tallest = 0;
  for (auto& column : columns) {
    std::stable_sort(column.begin(), column.end(),
                     [&](const GraphNodeItem* a, const GraphNodeItem* b) { return rank(a) < rank(b); });
    for (const GraphNodeItem* n : column) {
      area += (n->height() + kRowGap) * kColumnStep;
      tallest = std::max<double>(tallest, n->height() + kRowGap);
    }
  }
  // The panel's shape (a wide strip below the viewport, unless the artist made it otherwise).
  const double aspect = std::clamp(height() > 50 ? static_cast<double>(width()) / height() : 4.0, 1.0, 8.0);
  const double maxHeight = std::max({std::sqrt(area / aspect), 4.0 * tallest, 400.0});
  qreal x = 0;
  for (const auto& column : columns) {
    if (column.empty()) continue;
    qreal y = 0;
    for (GraphNodeItem* n : column) {
      if (y > 0 && y + n->height() > maxHeight) {
        x += kColumnStep;
        y = 0;
      }
      positions_[n->id] = QPointF(x, y);
      y += n->height() + kRowGap;
    }
    x += kColumnStep + kRowGap;  // a little more room between kinds than between a kind's columns
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
    n->setZValue(n->isSelected() ? 2 : 1);
  }
}

void NodeGraphView::setSelectedObject(NodeId id) {
  auto it = nodes_.find(id);
  if (it != nodes_.end() && it->second->isSelected()) return;
  setSelection(id != kNoNode && it != nodes_.end() ? std::vector<NodeId>{id} : std::vector<NodeId>{});
  // What the artist picked in the viewport comes into view here, at the zoom the graph has.
  if (it != nodes_.end()) ensureVisible(it->second->sceneBoundingRect(), 40, 30);
}

void NodeGraphView::selectNodes(const std::vector<NodeId>& ids) { setSelection(ids); }

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
  return isTextureInput(input) && scene_.texture(from);
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
  // Every link, not just the previous target: a refresh in the middle of a drag rebuilds the items.
  for (const Link& l : links_) l.item->setPen(linkPen(l.input, &l == target));
}

namespace {

QString nameOf(const Scene& s, NodeId id) {
  if (const auto* n = s.material(id)) return QString::fromStdString(n->name);
  if (const auto* n = s.object(id)) return QString::fromStdString(n->name);
  if (const auto* n = s.light(id)) return QString::fromStdString(n->name);
  if (const auto* n = s.texture(id)) return QString::fromStdString(n->name);
  return QString::number(id);
}

}  // namespace

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
  return request(b.finish(tr("Insert %1 into %2.%3").arg(nameOf(scene_, node), nameOf(scene_, to), input)),
                 b.scene());
}

bool NodeGraphView::createNode(const QString& type, QPointF scenePos) {
  EditBuilder b(scene_);
  const NodeId id = b.newId();
  if (type == QLatin1String("Material")) {
    Material m;
    m.id = id;
    m.name = uniqueName(scene_.materials, "Material");
    b.step(RemoveNode{id}, AddMaterial{m});
  } else if (type == QLatin1String("Texture")) {
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
    else if (type != QLatin1String("Light")) return false;
    l.name = uniqueName(scene_.lights, l.type == LightType::Point ? "Light" : type.toStdString());
    // Above the middle of the scene, where a new light is visible in the default view.
    const Bounds3 bounds = scene_.worldBounds();
    l.position = bounds.empty() ? Vec3{0.0f, 2.0f, 0.0f}
                                : Vec3{bounds.center().x, bounds.hi.y + 1.0f, bounds.center().z};
    l.intensity = l.type == LightType::Directional ? 1.0f : 5.0f;
    b.step(RemoveNode{id}, AddLight{l});
  } else {
    return false;
  }
  if (!b.ok()) return false;
  positions_[id] = scenePos;
  pendingSelection_ = {id};
  return request(b.finish(tr("Add %1").arg(type)), b.scene());
}

bool NodeGraphView::deleteSelected() {
  std::vector<GraphNodeItem*> chosen;
  for (auto& [id, n] : nodes_)
    if (n->isSelected() && n->deletable()) chosen.push_back(n);
  if (chosen.empty()) return false;
  // Users before what they use: a deleted object needs no material reassignment first.
  auto rank = [](NodeKind k) {
    return k == NodeKind::Object ? 0 : k == NodeKind::Light ? 1 : k == NodeKind::Material ? 2 : 3;
  };
  std::sort(chosen.begin(), chosen.end(), [&](const GraphNodeItem* a, const GraphNodeItem* b) {
    return rank(a->kind) != rank(b->kind) ? rank(a->kind) < rank(b->kind) : a->id < b->id;
  });
  EditBuilder b(scene_);
  for (const GraphNodeItem* n : chosen)
    if (!b.remove(n->id)) return false;
  const QString text = chosen.size() == 1 ? tr("Delete %1").arg(nameOf(scene_, chosen.front()->id))
                                          : tr("Delete %1 nodes").arg(chosen.size());
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
    positions_[copyId] = nodePosition(id) + offset;
    made.push_back(copyId);
  }
  if (made.empty()) return false;
  pendingSelection_ = made;
  return request(b.finish(made.size() == 1 ? tr("Duplicate %1").arg(nameOf(b.scene(), made.front()))
                                            : tr("Duplicate %1 nodes").arg(made.size())),
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
    positions_[m.id] = copiedPositions_[k++] + offset;
    made.push_back(m.id);
  }
  for (Light l : copiedLights_) {
    l.id = b.newId();
    l.name = uniqueName(b.scene().lights, l.name);
    if (!b.step(RemoveNode{l.id}, AddLight{l})) return false;
    positions_[l.id] = copiedPositions_[k++] + offset;
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

void NodeGraphView::frameRect(QRectF r) {
  if (r.isEmpty() || viewport()->width() < 2) return;
  r.adjust(-40, -40, 40, 40);
  fitInView(r, Qt::KeepAspectRatio);
  // Framing a single small node should not blow it up past a readable size.
  if (transform().m11() > 1.5) {
    setTransform(QTransform::fromScale(1.5, 1.5));
    centerOn(r.center());
  }
}

void NodeGraphView::frameSelected() {
  QRectF r;
  for (const auto& [id, n] : nodes_)
    if (n->isSelected()) r |= n->sceneBoundingRect();
  if (r.isEmpty()) frameAll();
  else frameRect(r);
}

void NodeGraphView::frameAll() {
  QRectF r;
  for (const auto& [id, n] : nodes_) r |= n->sceneBoundingRect();
  frameRect(r);
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
  if (mods == Qt::ControlModifier)
    return k->key() == Qt::Key_D || k->key() == Qt::Key_C || k->key() == Qt::Key_V;
  if (mods == Qt::NoModifier)
    return k->key() == Qt::Key_Tab || k->key() == Qt::Key_F2 || k->key() == Qt::Key_Delete ||
           k->key() == Qt::Key_Backspace;
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
        positions_[id] = start + d;
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
