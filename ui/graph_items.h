// What the node graph draws: the node boxes, the links between their sockets, and the sockets
// themselves (which inputs a node kind has and which document field each sets). Shared by the
// view (node_graph.cpp), its layouts (graph_layout.cpp) and its edits (graph_edit.cpp).
//
// Stacking: every link is drawn above every node. A link that ran behind the nodes disappeared
// under any box in its way and seemed to end at whatever socket sat at that height; above them it
// visibly crosses the box, and the dot at each end marks the sockets it really joins.
#pragma once

#include <QColor>
#include <QGraphicsItem>
#include <QGraphicsPathItem>
#include <QPen>
#include <QString>
#include <QStringList>

#include "retile/scene.h"

namespace retile::ui {

inline constexpr qreal kNodeWidth = 190;
inline constexpr qreal kHeaderH = 24;
inline constexpr qreal kSubtitleH = 18;
inline constexpr qreal kRowH = 20;
inline constexpr qreal kBottomPad = 8;
inline constexpr qreal kSocketR = 5.5;
inline constexpr qreal kColumnStep = kNodeWidth + 90;
inline constexpr qreal kRowGap = 24;

// Z values: nodes, then the selected nodes, then links, then what a gesture draws.
inline constexpr qreal kNodeZ = 1, kSelectedNodeZ = 2, kLinkZ = 3, kDragLinkZ = 5, kMarqueeZ = 6;

enum class NodeKind { Texture, Material, Object, Light, Camera, Settings };

int columnOf(NodeKind k);  // textures | materials | objects | the rest, left to right
QColor headerColor(NodeKind k);
// Sockets are coloured by what flows through them, so a compatible pair is recognisable at a glance.
QColor socketColor(const QString& socket);
QColor displayColor(const Vec3& linear);

// A material's input that takes the material it blends with (Material::blendWith), below its
// texture inputs.
inline const QString kBlendInput = QStringLiteral("blend");
// A material node's texture inputs, top to bottom ("albedo", "roughness", ...).
const QStringList& textureInputs();
NodeId Material::*textureSlot(const QString& input);  // null for a name that is not a texture input
// Whether a texture in `input` changes how a material of type `t` renders (its row's types): a
// lambert has no roughness for a texture to scale.
bool textureInputApplies(const QString& input, MaterialType t);

// One node: a rounded box with a coloured header, a subtitle line and one row per socket (inputs on
// the left, the output on the right of the first row). Plain data; the view lays it out and rebuilds it.
class GraphNodeItem : public QGraphicsItem {
 public:
  enum { Type = UserType + 1 };

  GraphNodeItem(NodeId nodeId, NodeKind nodeKind);
  int type() const override { return Type; }

  qreal height() const;
  QRectF boundingRect() const override;
  QRectF body() const { return {0, 0, kNodeWidth, height()}; }
  QPointF inputPos(qsizetype i) const { return {0, kHeaderH + kSubtitleH + (static_cast<qreal>(i) + 0.5) * kRowH}; }
  QPointF outputPos() const { return {kNodeWidth, kHeaderH + kSubtitleH + 0.5 * kRowH}; }
  bool deletable() const { return kind != NodeKind::Camera && kind != NodeKind::Settings; }
  // What input i is called on this node: its socket's name unless `labels` renames it.
  QString label(qsizetype i) const { return i < labels.size() && !labels[i].isEmpty() ? labels[i] : inputs[i]; }

  void paint(QPainter* p, const QStyleOptionGraphicsItem*, QWidget*) override;

  NodeId id;
  NodeKind kind;
  QString title, subtitle;
  QStringList inputs;
  QStringList labels;  // shown instead of inputs' names where not empty (the sockets keep them)
  QString output;
  QColor swatch;  // invalid: none
};

// How a link is drawn: as usual; faded, when a selection exists and the link touches none of it
// (the selection's own links stand out of a big graph); highlighted, when a node dropped now
// would be inserted into it (thicker and brighter).
enum class LinkLook { Normal, Faded, Highlighted };
QPen linkPen(const QString& input, LinkLook look);
// The curve from an output socket at `a` to an input socket at `b`: it leaves and enters level,
// so its ends point into their sockets.
QPainterPath linkPath(QPointF a, QPointF b);

// A link, drawn above the nodes (see the top) over a dark casing, with a dot on each end.
class GraphLinkItem : public QGraphicsPathItem {
 public:
  GraphLinkItem();
  QRectF boundingRect() const override;
  QPainterPath shape() const override;  // the stroke: the area a curve encloses with its chord is no part of it
  void paint(QPainter* p, const QStyleOptionGraphicsItem*, QWidget*) override;
};

}  // namespace retile::ui
