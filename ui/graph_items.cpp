#include "graph_items.h"

#include <QFontMetricsF>
#include <QPainter>
#include <QPainterPathStroker>

#include <algorithm>
#include <cmath>

namespace retile::ui {
namespace {

constexpr qreal kEndDotR = kSocketR - 2;  // inside the socket's ring, which stays visible around it

// A material's texture inputs are its texture rows (material_fields.h), named by their labels
// without " texture": "albedo", "blend ratio".
QString inputName(const MaterialTexture& t) { return QString::fromLatin1(t.label).toLower().remove(QStringLiteral(" texture")); }

}  // namespace

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

QColor socketColor(const QString& socket) {
  return socket == QLatin1String("material") || socket == kBlendInput ? QColor(96, 210, 128) : QColor(236, 196, 72);
}

QColor displayColor(const Vec3& linear) {
  auto c = [](float v) { return static_cast<int>(std::lround(255 * std::pow(std::clamp(v, 0.0f, 1.0f), 1 / 2.2f))); };
  return {c(linear.x), c(linear.y), c(linear.z)};
}

const QStringList& textureInputs() {
  static const QStringList inputs = [] {
    QStringList l;
    for (const MaterialTexture& t : kMaterialTextures) l << inputName(t);
    return l;
  }();
  return inputs;
}

NodeId Material::*textureSlot(const QString& input) {
  // textureInputs() lists the rows' names in the rows' order.
  const qsizetype i = textureInputs().indexOf(input);
  return i < 0 ? nullptr : kMaterialTextures[static_cast<std::size_t>(i)].field;
}

bool textureInputApplies(const QString& input, MaterialType t) {
  const qsizetype i = textureInputs().indexOf(input);
  return i >= 0 && kMaterialTextures[static_cast<std::size_t>(i)].appliesTo(t);
}

GraphNodeItem::GraphNodeItem(NodeId nodeId, NodeKind nodeKind) : id(nodeId), kind(nodeKind) {
  setFlag(ItemIsSelectable);
  setZValue(kNodeZ);
}

qreal GraphNodeItem::height() const {
  const auto rows = std::max<qsizetype>(inputs.size(), output.isEmpty() ? 0 : 1);
  return kHeaderH + kSubtitleH + static_cast<qreal>(rows) * kRowH + kBottomPad;
}

QRectF GraphNodeItem::boundingRect() const { return {-kSocketR - 2, -2, kNodeWidth + 2 * kSocketR + 4, height() + 4}; }

void GraphNodeItem::paint(QPainter* p, const QStyleOptionGraphicsItem*, QWidget*) {
  p->setRenderHint(QPainter::Antialiasing, true);
  QPainterPath shape;
  shape.addRoundedRect(body(), 7, 7);
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
  p->drawText(titleRect, Qt::AlignVCenter | Qt::AlignLeft, QFontMetricsF(titleFont).elidedText(title, Qt::ElideRight, titleRect.width()));
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
  p->drawText(subRect, Qt::AlignVCenter | Qt::AlignLeft, QFontMetricsF(small).elidedText(subtitle, Qt::ElideRight, subRect.width()));

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
    p->drawText(QRectF(kNodeWidth / 2, c.y() - kRowH / 2, kNodeWidth / 2 - 12, kRowH), Qt::AlignVCenter | Qt::AlignRight, output);
  }
}

QPen linkPen(const QString& input, LinkLook look) {
  switch (look) {
    case LinkLook::Highlighted: return QPen(socketColor(input).lighter(145), 5);
    case LinkLook::Faded: {
      QColor c = socketColor(input);
      c.setAlpha(70);
      return QPen(c, 2);
    }
    case LinkLook::Normal: break;
  }
  return QPen(socketColor(input), 2.5);
}

QPainterPath linkPath(QPointF a, QPointF b) {
  QPainterPath p(a);
  const qreal dx = std::max<qreal>(40, std::abs(b.x() - a.x()) * 0.5);
  p.cubicTo(a + QPointF(dx, 0), b - QPointF(dx, 0), b);
  return p;
}

GraphLinkItem::GraphLinkItem() { setZValue(kLinkZ); }

QRectF GraphLinkItem::boundingRect() const {
  const qreal m = std::max(kEndDotR + 1, pen().widthF() / 2 + 2);
  return path().boundingRect().adjusted(-m, -m, m, m);
}

QPainterPath GraphLinkItem::shape() const {
  QPainterPathStroker stroker;
  stroker.setWidth(pen().widthF() + 4);
  return stroker.createStroke(path());
}

void GraphLinkItem::paint(QPainter* p, const QStyleOptionGraphicsItem*, QWidget*) {
  p->setRenderHint(QPainter::Antialiasing, true);
  const QPainterPath& curve = path();
  const QPen line = pen();
  // The casing parts the link from the node text it crosses.
  QColor casing(22, 22, 26, line.color().alpha() * 3 / 4);
  p->setPen(QPen(casing, line.widthF() + 2.5, Qt::SolidLine, Qt::RoundCap));
  p->drawPath(curve);
  p->setPen(line);
  p->drawPath(curve);
  p->setPen(QPen(casing, 1.2));
  p->setBrush(line.color());
  p->drawEllipse(curve.pointAtPercent(0), kEndDotR, kEndDotR);
  p->drawEllipse(curve.pointAtPercent(1), kEndDotR, kEndDotR);
}

}  // namespace retile::ui
