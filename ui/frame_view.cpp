#include "frame_view.h"

#include <QDateTime>
#include <QMouseEvent>
#include <QPainter>
#include <QTimer>
#include <QWindow>

#include <algorithm>
#include <cmath>

#include "retile/color.h"
#include "vulkan_viewport.h"

namespace retile::ui {

QColor priorityColor(float priority) {
  // Violet (served last) through red and orange to yellow (served next): readable over dark and
  // light images alike, and never confused with the cyan outlines of served tiles.
  float t = std::clamp(priority, 0.0f, 1.0f);
  return QColor::fromHsvF(std::fmod(0.8f + 0.35f * t, 1.0f), 0.9f, 1.0f, 0.3f);
}

FrameView::FrameView(QWidget* parent) : QWidget(parent) {
  setMinimumSize(160, 90);
  setAttribute(Qt::WA_OpaquePaintEvent);
  setMouseTracking(true);  // the pixel inspector follows the cursor
  setFocusPolicy(Qt::StrongFocus);
  QString why;
  if (qEnvironmentVariable("RETILE_VIEWPORT") == "widget") {
    presentation_ = tr("widget (RETILE_VIEWPORT=widget)");
  } else if (VulkanViewport::sharedInstance(&why)) {
    vulkan_ = new VulkanViewport(this);
    container_ = QWidget::createWindowContainer(vulkan_, this);
    container_->setGeometry(rect());
    container_->setFocusPolicy(Qt::NoFocus);
    presentation_ = tr("Vulkan window");
    vulkan_->setFailureHandler([this](const QString& reason) { fallBackToWidget(reason); });
  } else {
    presentation_ = tr("widget (%1)").arg(why);
  }
}

void FrameView::fallBackToWidget(const QString& why) {
  if (!vulkan_) return;
  // The container owns the window: deleting it destroys the swapchain and Qt's device with it.
  container_->hide();
  container_->deleteLater();
  container_ = nullptr;
  vulkan_ = nullptr;
  presentation_ = tr("widget (%1)").arg(why);
  emit presentationChanged(presentation_);
  update();
}

void FrameView::setOverlays(const OverlaySettings& o) {
  overlays_ = o;
  refresh();
}

void FrameView::setPaused(bool paused) {
  paused_ = paused;
  refresh();
}

void FrameView::setDisplay(const DisplaySettings& d) {
  display_ = d;
  if (frame_ && frame_->image) image_ = toDisplay(*frame_->image);
  if (snapshotLinear_) snapshot_ = toDisplay(*snapshotLinear_);
  refresh();
}

QImage FrameView::toDisplay(const RenderImage& img) const {
  QImage q(img.width, img.height, QImage::Format_RGBA8888);
  auto config = ColorConfig::get();
  for (int y = 0; y < img.height; ++y)
    config->toDisplay8(img.shown().data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) * 3,
                       static_cast<std::size_t>(img.width), display_, q.scanLine(y));
  return q;
}

void FrameView::showFrame(std::shared_ptr<const FrameRecord> frame) {
  if (!frame || !frame->image) return;
  frame_ = std::move(frame);
  image_ = toDisplay(*frame_->image);
  if (!region_.isEmpty()) inspectRegion();
  refresh();
}

void FrameView::takeSnapshot() {
  if (!frame_ || !frame_->image) return;
  snapshotLinear_ = frame_->image;  // frames are immutable once published: sharing is enough
  snapshot_ = image_;
  showNotice(tr("Snapshot taken: B shows it, A the live render"));
}

void FrameView::showNotice(const QString& text, int ms) {
  notice_ = text;
  noticeUntil_ = QDateTime::currentMSecsSinceEpoch() + ms;
  refresh();
  QTimer::singleShot(ms + 20, this, [this] { refresh(); });  // and gone when its time is up
}

void FrameView::setCompare(Compare c) {
  compare_ = hasSnapshot() ? c : Compare::Off;
  refresh();
}

void FrameView::setWipe(double x) {
  wipe_ = std::clamp(x, 0.0, 1.0);
  refresh();
}

void FrameView::setTool(Tool t) {
  tool_ = t;
  refresh();
}

void FrameView::setGizmo(const Gizmo& g) {
  // Called after every frame: compose again only when the gizmo moved.
  if (g == gizmo_) return;
  gizmo_ = g;
  refresh();
}

QPointF FrameView::toWidget(QPointF px) const {
  QRectF r = imageRect();
  if (!frame_) return r.topLeft();
  return {r.x() + px.x() * r.width() / frame_->width, r.y() + px.y() * r.height() / frame_->height};
}

void FrameView::drawGizmo(QPainter& p) const {
  if (!gizmo_.visible || tool_ == Tool::Select || !frame_) return;
  static const QColor axisColor[3] = {QColor(240, 70, 70), QColor(90, 220, 90), QColor(80, 140, 255)};
  const QPointF o = toWidget(gizmo_.origin);
  p.setRenderHint(QPainter::Antialiasing, true);
  if (tool_ == Tool::Rotate) {
    p.setPen(QPen(axisColor[1], 2.5));
    p.setBrush(Qt::NoBrush);
    p.drawEllipse(o, kRingRadiusX, kRingRadiusY);
    p.drawText(o + QPointF(kRingRadiusX + 4, 4), tr("drag: turn about y"));
    return;
  }
  for (int a = 0; a < 3; ++a) {
    const QPointF e = toWidget(gizmo_.axisEnd[a]);
    p.setPen(QPen(axisColor[a], 2.5));
    p.drawLine(o, e);
    p.setBrush(axisColor[a]);
    if (tool_ == Tool::Scale) {
      p.drawRect(QRectF(e - QPointF(4, 4), QSizeF(8, 8)));
    } else {
      QPointF d = e - o;
      double len = std::hypot(d.x(), d.y());
      if (len < 1) continue;
      QPointF u = d / len, n(-u.y(), u.x());
      QPolygonF head({e + u * 9, e + n * 5, e - n * 5});
      p.drawPolygon(head);
    }
  }
  p.setBrush(Qt::white);
  p.setPen(Qt::NoPen);
  p.drawEllipse(o, 3.5, 3.5);
}

QRectF FrameView::imageRect() const {
  if (image_.isNull()) return rect();
  double s = std::min(width() / static_cast<double>(image_.width()), height() / static_cast<double>(image_.height()));
  double w = image_.width() * s, h = image_.height() * s;
  return {(width() - w) / 2, (height() - h) / 2, w, h};
}

QImage FrameView::composed() const {
  const qreal dpr = devicePixelRatioF();
  QImage pic(size() * dpr, QImage::Format_RGB32);
  pic.setDevicePixelRatio(dpr);
  QPainter p(&pic);
  compose(p, rect());
  return pic;
}

void FrameView::refresh() {
  if (vulkan_) vulkan_->setPicture(composed());
  else update();
}

void FrameView::resizeEvent(QResizeEvent*) {
  if (container_) container_->setGeometry(rect());
  refresh();
  emit resized();
}

void FrameView::paintEvent(QPaintEvent*) {
  if (vulkan_) return;  // the Vulkan window covers the widget
  QPainter p(this);
  compose(p, rect());
}

void FrameView::compose(QPainter& p, const QRect& area) const {
  p.fillRect(area, QColor(32, 32, 36));
  if (image_.isNull()) {
    p.setPen(Qt::lightGray);
    p.drawText(area, Qt::AlignCenter, tr("Starting the renderer..."));
    return;
  }
  QRectF r = imageRect();
  p.setRenderHint(QPainter::SmoothPixmapTransform, true);
  const bool snapshotUsable = !snapshot_.isNull() && snapshot_.size() == image_.size();
  if (compare_ == Compare::Toggle && snapshotUsable) {
    p.drawImage(r, snapshot_);
  } else if (compare_ == Compare::Wipe && snapshotUsable) {
    // Left of the line: the snapshot (B); right: the live render (A).
    const double split = std::round(wipe_ * image_.width());
    const double sx = r.width() / image_.width();
    p.drawImage(QRectF(r.x(), r.y(), split * sx, r.height()), snapshot_, QRectF(0, 0, split, image_.height()));
    p.drawImage(QRectF(r.x() + split * sx, r.y(), r.width() - split * sx, r.height()), image_,
                QRectF(split, 0, image_.width() - split, image_.height()));
  } else {
    p.drawImage(r, image_);
  }
  drawOverlays(p, r);
  drawGizmo(p);
  if (!notice_.isEmpty() && QDateTime::currentMSecsSinceEpoch() < noticeUntil_) {
    // A short confirmation where the artist is looking (Ctrl+B has no other visible effect).
    p.setFont(QFont(font().family(), 10, QFont::Bold));
    const QRectF box(r.center().x() - 180, r.y() + 12, 360, 26);
    p.fillRect(box, QColor(0, 0, 0, 190));
    p.setPen(Qt::white);
    p.drawText(box, Qt::AlignCenter, notice_);
  }
  if (compare_ != Compare::Off && snapshotUsable) {
    p.setFont(QFont(font().family(), 11, QFont::Bold));
    p.setPen(QColor(255, 255, 255));
    if (compare_ == Compare::Wipe) {
      const double x = r.x() + wipe_ * r.width();
      p.setPen(QPen(QColor(255, 255, 255), 2));
      p.drawLine(QPointF(x, r.top()), QPointF(x, r.bottom()));
      p.drawText(QRectF(x - 60, r.y() + 6, 52, 18), Qt::AlignRight, tr("B"));
      p.drawText(QRectF(x + 8, r.y() + 6, 52, 18), Qt::AlignLeft, tr("A"));
    } else {
      p.drawText(r.adjusted(10, 8, -10, -8), Qt::AlignTop | Qt::AlignLeft, tr("B: snapshot"));
    }
  }
  if (frame_) {
    // The render region: what the record says the engine renders, and the one being drawn.
    const double sx = r.width() / frame_->width, sy = r.height() / frame_->height;
    auto toRect = [&](QRect q) { return QRectF(r.x() + q.x() * sx, r.y() + q.y() * sy, q.width() * sx, q.height() * sy); };
    const RegionRect& rr = frame_->region;
    p.setBrush(Qt::NoBrush);
    if (!rr.empty()) {
      QRectF box = toRect(QRect(rr.x, rr.y, rr.width, rr.height));
      p.setPen(QPen(QColor(255, 150, 30), 2, Qt::DashLine));
      p.drawRect(box);
      p.setFont(QFont(font().family(), 9, QFont::Bold));
      p.drawText(box.adjusted(4, 2, -4, -2), Qt::AlignTop | Qt::AlignLeft, tr("render region"));
    }
    if (!draft_.isEmpty()) {
      p.setPen(QPen(QColor(255, 150, 30), 1.5));
      p.drawRect(toRect(draft_));
    }
  }
  if (!region_.isEmpty() && frame_) {
    const double sx = r.width() / frame_->width, sy = r.height() / frame_->height;
    p.setPen(QPen(QColor(255, 255, 255), 1, Qt::DashLine));
    p.setBrush(Qt::NoBrush);
    p.drawRect(QRectF(r.x() + region_.x() * sx, r.y() + region_.y() * sy, region_.width() * sx, region_.height() * sy));
  }
  if (paused_) {
    p.setPen(QPen(QColor(255, 190, 40), 4));
    p.drawRect(r.adjusted(2, 2, -2, -2));
    p.setFont(QFont(font().family(), 14, QFont::Bold));
    p.drawText(r.adjusted(10, 8, -10, -8), Qt::AlignTop | Qt::AlignRight, tr("PAUSED (Esc resumes)"));
  }
}

void FrameView::drawOverlays(QPainter& p, const QRectF& r) const {
  if (!frame_) return;
  const FrameRecord& f = *frame_;
  if (selection_.size() > 1 && f.image) {
    // Outlined pixel by pixel from the frame's object ids: which objects a move will take along.
    if (outlineOf_ != f.image.get()) {
      outlineOf_ = f.image.get();
      const auto& ids = f.image->objectId;
      outline_ = QImage(f.width, f.height, QImage::Format_ARGB32_Premultiplied);
      outline_.fill(Qt::transparent);
      auto selected = [&](int x, int y) {
        if (x < 0 || y < 0 || x >= f.width || y >= f.height) return false;
        const quint64 id = ids[static_cast<std::size_t>(y) * static_cast<std::size_t>(f.width) + static_cast<std::size_t>(x)];
        return id != 0 && std::find(selection_.begin(), selection_.end(), id) != selection_.end();
      };
      if (ids.size() == static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height))
        for (int y = 0; y < f.height; ++y)
          for (int x = 0; x < f.width; ++x)
            if (selected(x, y) && !(selected(x - 1, y) && selected(x + 1, y) && selected(x, y - 1) && selected(x, y + 1)))
              outline_.setPixel(x, y, qRgb(255, 160, 40));
    }
    p.drawImage(r, outline_);
  }
  const double sx = r.width() / f.width, sy = r.height() / f.height;
  auto tileRect = [&](int t) {
    int c = t % f.cols, row = t / f.cols;
    double x0 = c * f.tileSize, y0 = row * f.tileSize;
    double x1 = std::min<double>(x0 + f.tileSize, f.width), y1 = std::min<double>(y0 + f.tileSize, f.height);
    return QRectF(r.x() + x0 * sx, r.y() + y0 * sy, (x1 - x0) * sx, (y1 - y0) * sy);
  };
  const int tiles = f.cols * f.rows;
  if (heatMapShown() && static_cast<int>(f.tilePriority.size()) == tiles) {
    for (int t = 0; t < tiles; ++t) {
      float pr = f.tilePriority[static_cast<std::size_t>(t)];
      if (pr < 0) continue;
      p.fillRect(tileRect(t), priorityColor(pr));
    }
  }
  if (overlays_.classes && static_cast<int>(f.tileClass.size()) == tiles) {
    // Hatched, so they read on top of the heat map: what the selected object touches directly
    // (high), through reflections or shadows (middle), and barely (low).
    static const QColor classColor[3] = {QColor(255, 40, 40), QColor(255, 200, 0), QColor(60, 140, 255)};
    for (int t = 0; t < tiles; ++t) {
      int c = f.tileClass[static_cast<std::size_t>(t)];
      if (c > 2) continue;
      p.fillRect(tileRect(t), QBrush(classColor[c], Qt::BDiagPattern));
      p.setPen(QPen(classColor[c], 1.5));
      p.drawRect(tileRect(t).adjusted(1, 1, -1, -1));
    }
  }
  const TileLabels labels = tileLabels(tileRect(0));
  p.setFont(labels.font);
  const QFontMetricsF metrics(labels.font);
  auto label = [&](const QRectF& box, Qt::Alignment align, const QString& text) {
    // A label that does not fit its share of the tile is left out rather than overprinted.
    if (metrics.horizontalAdvance(text) <= box.width()) p.drawText(box, align, text);
  };
  if (overlays_.order && static_cast<int>(f.tilePriority.size()) == tiles && f.queueLength > 1) {
    p.setPen(Qt::white);
    for (int t = 0; t < tiles; ++t) {
      float pr = f.tilePriority[static_cast<std::size_t>(t)];
      if (pr < 0) continue;
      int rank = static_cast<int>(std::lround((1.0f - pr) * static_cast<float>(f.queueLength - 1))) + 1;
      label(labels.order.translated(tileRect(t).topLeft() - tileRect(0).topLeft()), labels.orderAlign, QString::number(rank));
    }
  }
  if (overlays_.samples && static_cast<int>(f.tileSamples.size()) == tiles) {
    p.setPen(QColor(180, 255, 180));
    for (int t = 0; t < tiles; ++t)
      label(labels.samples.translated(tileRect(t).topLeft() - tileRect(0).topLeft()), labels.samplesAlign,
            QString::number(static_cast<int>(f.tileSamples[static_cast<std::size_t>(t)])));
  }
  if (overlays_.served && static_cast<int>(f.servedTiles.size()) < tiles) {
    p.setPen(QPen(QColor(80, 220, 255), 1.5));
    p.setBrush(Qt::NoBrush);
    for (int t : f.servedTiles) p.drawRect(tileRect(t).adjusted(0.5, 0.5, -0.5, -0.5));
  }
  if (overlays_.denoised && !f.denoised.empty()) {
    // Newest (outermost) brightest; each boundary labelled with the frames since it was denoised.
    const auto n = static_cast<int>(f.denoised.size());
    for (int i = 0; i < n; ++i) {
      const DenoisedRegion& d = f.denoised[static_cast<std::size_t>(i)];
      QColor c = QColor::fromHsvF(0.08, 0.25 + 0.75 * (i + 1) / n, 1.0);
      QRectF rr(r.x() + d.rect.x * sx, r.y() + d.rect.y * sy, d.rect.width * sx, d.rect.height * sy);
      p.setPen(QPen(c, 2.0, Qt::DashLine));
      p.setBrush(Qt::NoBrush);
      p.drawRect(rr.adjusted(1, 1, -1, -1));
      QFont lf(font().family(), 8);
      p.setFont(lf);
      p.setPen(c);
      p.drawText(rr.adjusted(4, 3 + 11 * (i % 2), -4, -3), Qt::AlignTop | Qt::AlignLeft, tr("%1").arg(d.age));
    }
  }
  if (overlays_.reuse && static_cast<int>(f.tileReuse.size()) == tiles) {
    // Reusing: a green corner mark, so the picture stays readable; rejected: red hatching with
    // the frames since the rejection.
    const QColor keep(90, 230, 120), drop(255, 70, 70);
    for (int t = 0; t < tiles; ++t) {
      const QRectF box = tileRect(t);
      const auto state = f.tileReuse[static_cast<std::size_t>(t)];
      if (state == 1) {
        const double k = std::min(box.width(), box.height()) * 0.3;
        QPolygonF corner({box.topRight(), box.topRight() + QPointF(-k, 0), box.topRight() + QPointF(0, k)});
        p.setPen(Qt::NoPen);
        p.setBrush(keep);
        p.drawPolygon(corner);
      } else if (state == 2) {
        p.fillRect(box, QBrush(drop, Qt::FDiagPattern));
        p.setPen(QPen(drop, 1.0));
        p.setBrush(Qt::NoBrush);
        p.drawRect(box.adjusted(1, 1, -1, -1));
        const std::uint64_t at = t < static_cast<int>(f.tileRejectedAt.size()) ? f.tileRejectedAt[static_cast<std::size_t>(t)] : 0;
        if (at > 0 && f.frame >= at) label(box.adjusted(2, 1, -2, -1), Qt::AlignLeft | Qt::AlignBottom, QString::number(f.frame - at));
      }
    }
  }
  if (overlays_.markers) {
    QPointF poc(r.x() + f.pointOfChange.x * sx, r.y() + f.pointOfChange.y * sy);
    p.setPen(QPen(QColor(255, 60, 60), 2.5));
    p.drawLine(poc + QPointF(-10, 0), poc + QPointF(10, 0));
    p.drawLine(poc + QPointF(0, -10), poc + QPointF(0, 10));
    p.setPen(QPen(QColor(80, 255, 120), 2.5));
    for (const Vec2& fp : f.focus) p.drawEllipse(QPointF(r.x() + fp.x * sx, r.y() + fp.y * sy), 9, 9);
  }
  if (overlays_.legend) drawLegend(p, r);
}

FrameView::TileLabels FrameView::tileLabels(const QRectF& tile) const {
  // With both labels on, the order takes the top half of the tile and the samples the bottom half.
  TileLabels l;
  const bool both = overlays_.order && overlays_.samples;
  const QRectF inner = tile.adjusted(2, 1, -2, -1);
  const double h = both ? inner.height() / 2 : inner.height();
  l.font = QFont(font().family());
  l.font.setPixelSize(std::max(6, static_cast<int>(std::min(h * 0.8, tile.height() / 3.2))));
  l.order = both ? QRectF(inner.x(), inner.y(), inner.width(), h) : inner;
  l.samples = both ? QRectF(inner.x(), inner.y() + h, inner.width(), h) : inner;
  l.orderAlign = both ? Qt::AlignLeft | Qt::AlignTop : Qt::AlignCenter;
  l.samplesAlign = Qt::AlignRight | Qt::AlignBottom;
  return l;
}

// One row per overlay that is on, so nothing is explained that is not drawn and the box grows
// with its rows instead of other boxes stacking over it.
std::vector<FrameView::LegendRow> FrameView::legendRows() const {
  std::vector<LegendRow> rows;
  if (!frame_) return rows;
  const FrameRecord& f = *frame_;
  if (heatMapShown()) rows.push_back({Qt::white, tr("served first  ...  last (tile priority)"), true});
  if (overlays_.served) rows.push_back({QColor(80, 220, 255), tr("outlined: tiles traced this frame")});
  if (overlays_.markers) rows.push_back({QColor(255, 90, 90), tr("+ point of change    o focus point")});
  if (overlays_.classes && !f.tileClass.empty())
    rows.push_back({QColor(255, 200, 0), tr("hatched: indirection classes high / middle / low")});
  if (overlays_.denoised && !f.denoised.empty())
    rows.push_back({QColor::fromHsvF(0.08, 1.0, 1.0),
                    tr("dashed: %n denoised region(s), labelled frames since", nullptr, static_cast<int>(f.denoised.size()))});
  if (overlays_.reuse && !f.tileReuse.empty()) {
    rows.push_back({QColor(90, 230, 120), tr("corner: %n tile(s) reusing their history", nullptr, f.reusedTiles)});
    rows.push_back({QColor(255, 70, 70), tr("hatched: %n history(ies) rejected, frames since", nullptr, f.rejectedTiles)});
  }
  rows.push_back({Qt::lightGray, tr("%1, %2: %3/%4 tiles").arg(QString::fromStdString(f.method), QString::fromStdString(f.mode))
                                     .arg(f.queueServed).arg(f.queueLength)});
  return rows;
}

QRectF FrameView::legendRect(const QRectF& r) const {
  double height = 8;
  for (const LegendRow& row : legendRows()) height += row.gradient ? kLegendLine + 12 : kLegendLine;
  // Narrower in a narrow viewport (the rows are elided), never outside the image.
  const double width = std::max(120.0, std::min(kLegendWidth, r.width() - 16));
  return QRectF(r.x() + 8, std::max(r.y() + 8, r.bottom() - height - 8), width, height);
}

bool FrameView::heatMapShown() const {
  // Outside a pass every tile has the same standing: a heat map would only tint the picture.
  return overlays_.priority && frame_ && frame_->mode != "refinement";
}

void FrameView::drawLegend(QPainter& p, const QRectF& r) const {
  const std::vector<LegendRow> rows = legendRows();
  QFont lf(font().family(), 9);
  p.setFont(lf);
  const QRectF box = legendRect(r);
  const double lineH = kLegendLine, width = box.width();
  p.fillRect(box, QColor(0, 0, 0, 170));
  double y = box.y() + 5;
  for (const LegendRow& row : rows) {
    if (row.gradient) {
      const double ramp = std::min(140.0, width - 20);
      QLinearGradient g(box.x() + 10, 0, box.x() + 10 + ramp, 0);
      for (int i = 0; i <= 10; ++i) {
        QColor c = priorityColor(1.0f - i / 10.0f);
        c.setAlphaF(1.0);
        g.setColorAt(i / 10.0, c);
      }
      p.fillRect(QRectF(box.x() + 10, y + 2, ramp, 9), g);
      y += 12;
    }
    p.setPen(row.color);
    p.drawText(QRectF(box.x() + 10, y, width - 14, lineH),
               p.fontMetrics().elidedText(row.text, Qt::ElideRight, static_cast<int>(width - 14)));
    y += lineH;
  }
}

QPoint FrameView::imagePixel(QPointF pos) const {
  QRectF r = imageRect();
  if (!frame_ || r.width() <= 0) return {-1, -1};
  double u = (pos.x() - r.x()) / r.width(), v = (pos.y() - r.y()) / r.height();
  if (u < 0 || v < 0 || u >= 1 || v >= 1) return {-1, -1};
  return {std::clamp(static_cast<int>(u * frame_->width), 0, frame_->width - 1),
          std::clamp(static_cast<int>(v * frame_->height), 0, frame_->height - 1)};
}

void FrameView::inspectRegion() {
  if (!frame_ || !frame_->image || region_.isEmpty()) return;
  const RenderImage& img = *frame_->image;
  QRect rr = region_.intersected(QRect(0, 0, img.width, img.height));
  if (rr.isEmpty()) return;
  double sum[3] = {0, 0, 0};
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int y = rr.top(); y <= rr.bottom(); ++y)
    for (int x = rr.left(); x <= rr.right(); ++x) {
      const float* c = inspected(img).data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x)) * 3;
      for (int k = 0; k < 3; ++k) {
        sum[k] += c[k];
        lo[k] = std::min(lo[k], c[k]);
        hi[k] = std::max(hi[k], c[k]);
      }
    }
  const double n = static_cast<double>(rr.width()) * rr.height();
  emit regionInspected(rr, QVector3D(static_cast<float>(sum[0] / n), static_cast<float>(sum[1] / n), static_cast<float>(sum[2] / n)),
                       QVector3D(lo[0], lo[1], lo[2]), QVector3D(hi[0], hi[1], hi[2]));
}

void FrameView::mousePressEvent(QMouseEvent* e) {
  last_ = e->position();
  setFocus();
  if (compare_ == Compare::Wipe && e->button() == Qt::LeftButton && !(e->modifiers() & Qt::AltModifier)) {
    QRectF r = imageRect();
    if (std::abs(e->position().x() - (r.x() + wipe_ * r.width())) < 8) {
      drag_ = Drag::Wipe;
      return;
    }
  }
  if ((e->modifiers() & Qt::ControlModifier) && e->button() == Qt::LeftButton) {
    drag_ = Drag::Region;
    regionStart_ = e->position();
    region_ = QRect();  // a Ctrl+click without a drag clears the region
    refresh();
    return;
  }
  if (e->modifiers() & Qt::AltModifier) {
    drag_ = e->button() == Qt::LeftButton ? Drag::Orbit : e->button() == Qt::MiddleButton ? Drag::Pan : Drag::Dolly;
    return;
  }
  if (!frame_ || !frame_->image || e->button() != Qt::LeftButton) return;
  // The gizmo's handles take the press before whatever lies behind them.
  if (gizmo_.visible && tool_ != Tool::Select) {
    const QPointF o = toWidget(gizmo_.origin), pos = e->position();
    if (tool_ == Tool::Rotate) {
      // The ring (drawn 34 x 12 px about the origin) and the band around it.
      const double ex = (pos.x() - o.x()) / kRingRadiusX, ey = (pos.y() - o.y()) / kRingRadiusY;
      if (std::hypot(ex, ey) < 1.5) {
        drag_ = Drag::Rotate;
        return;
      }
    } else {
      for (int a = 0; a < 3; ++a) {
        const QPointF d = toWidget(gizmo_.axisEnd[a]) - o;
        const double len2 = d.x() * d.x() + d.y() * d.y();
        if (len2 < 4) continue;
        const double t = std::clamp(((pos.x() - o.x()) * d.x() + (pos.y() - o.y()) * d.y()) / len2, 0.0, 1.0);
        // Move: an arrow drags along its world axis; Scale: any axis or its box scales.
        const double minT = tool_ == Tool::Move ? 0.25 : 0.0;
        if (t > minT && std::hypot(pos.x() - (o.x() + t * d.x()), pos.y() - (o.y() + t * d.y())) < 7) {
          drag_ = tool_ == Tool::Move ? Drag::Axis : Drag::Scale;
          dragAxis_ = a;
          return;
        }
      }
    }
  }
  const QPoint px = imagePixel(e->position());
  if (px.x() < 0) return;
  if (e->modifiers() & Qt::ShiftModifier) {
    // A click places a focus point; a drag draws a render region (decided on release).
    drag_ = Drag::RenderRegion;
    regionStart_ = e->position();
    draft_ = QRect();
    return;
  }
  const quint64 id = objectAt(px);
  // Pressing on the selection starts moving it; anywhere else picks.
  if (id != 0 && std::find(selection_.begin(), selection_.end(), id) != selection_.end() && tool_ != Tool::Select) {
    drag_ = tool_ == Tool::Rotate ? Drag::Rotate : tool_ == Tool::Scale ? Drag::Scale : Drag::Object;
    return;
  }
  emit objectPicked(id);
}

void FrameView::mouseMoveEvent(QMouseEvent* e) {
  QPointF d = e->position() - last_;
  last_ = e->position();
  QPoint px = imagePixel(e->position());
  if (px.x() >= 0 && frame_ && frame_->image) {
    const float* c = inspected(*frame_->image).data() +
                     (static_cast<std::size_t>(px.y()) * static_cast<std::size_t>(frame_->width) + static_cast<std::size_t>(px.x())) * 3;
    emit pixelInspected(px, QVector3D(c[0], c[1], c[2]));
  }
  switch (drag_) {
    case Drag::Region: {
      QPoint a = imagePixel(regionStart_), b = imagePixel(e->position());
      if (a.x() >= 0 && b.x() >= 0) {
        region_ = QRect(a, b).normalized();
        inspectRegion();
        refresh();
      }
      break;
    }
    case Drag::RenderRegion: {
      QPoint a = imagePixel(regionStart_), b = imagePixel(e->position());
      if (a.x() >= 0 && b.x() >= 0) {
        draft_ = QRect(a, b).normalized();
        refresh();
      }
      break;
    }
    case Drag::Wipe: {
      QRectF r = imageRect();
      if (r.width() > 0) setWipe((e->position().x() - r.x()) / r.width());
      break;
    }
    case Drag::Orbit: emit orbitDragged(d); break;
    case Drag::Pan: emit panDragged(d); break;
    case Drag::Dolly: emit dollyDragged(-d.y() / 200.0); break;
    case Drag::Rotate: emit rotateDragged(d.x()); break;
    case Drag::Scale: emit scaleDragged(d.x()); break;
    case Drag::Axis: {
      QRectF r = imageRect();
      if (frame_ && r.width() > 0) emit axisDragged(dragAxis_, QPointF(d.x() * frame_->width / r.width(), d.y() * frame_->height / r.height()));
      break;
    }
    case Drag::Object: {
      QRectF r = imageRect();
      if (frame_ && r.width() > 0) emit objectDragged(QPointF(d.x() * frame_->width / r.width(), d.y() * frame_->height / r.height()));
      break;
    }
    case Drag::None: break;
  }
}

void FrameView::mouseReleaseEvent(QMouseEvent* e) {
  if (drag_ == Drag::RenderRegion) {
    drag_ = Drag::None;
    const QPointF d = e->position() - regionStart_;
    if (std::hypot(d.x(), d.y()) < 4 || draft_.width() < 2 || draft_.height() < 2) {
      QRectF r = imageRect();
      if (frame_ && r.width() > 0)
        emit focusPlaced(QPointF((regionStart_.x() - r.x()) / r.width() * frame_->width,
                                 (regionStart_.y() - r.y()) / r.height() * frame_->height));
    } else {
      emit renderRegionDrawn(draft_);
    }
    draft_ = QRect();
    refresh();
    return;
  }
  if (drag_ == Drag::Region) {
    // Ctrl+click (no drag) on an object adds it to the selection or takes it out.
    const QPointF d = e->position() - regionStart_;
    if (const quint64 id = objectAt(imagePixel(regionStart_)); std::hypot(d.x(), d.y()) < 4 && id != 0) {
      drag_ = Drag::None;
      emit objectToggled(id);
      return;
    }
  }
  if (drag_ != Drag::None && drag_ != Drag::Region && drag_ != Drag::Wipe) emit dragFinished();
  drag_ = Drag::None;
}

quint64 FrameView::objectAt(QPoint imagePixel) const {
  if (!frame_ || !frame_->image || imagePixel.x() < 0 || imagePixel.y() < 0) return 0;
  const auto& ids = frame_->image->objectId;
  const std::size_t i =
      static_cast<std::size_t>(imagePixel.y()) * static_cast<std::size_t>(frame_->width) + static_cast<std::size_t>(imagePixel.x());
  return i < ids.size() ? static_cast<quint64>(ids[i]) : 0;
}

void FrameView::setSelection(std::vector<quint64> objects, quint64 primary) {
  selection_ = std::move(objects);
  selected_ = primary;
  outlineOf_ = nullptr;
  refresh();
}

void FrameView::wheelEvent(QWheelEvent* e) {
  emit dollyDragged(e->angleDelta().y() / 1200.0);
  emit dragFinished();
}

}  // namespace retile::ui
