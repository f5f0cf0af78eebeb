#include "frame_view.h"

#include <QDateTime>
#include <QFontMetricsF>
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

const QColor FrameView::kServedColor(80, 220, 255);
const QColor FrameView::kChangeColor(255, 60, 60);
const QColor FrameView::kFocusColor(80, 255, 120);
const QColor FrameView::kDenoisedColor = QColor::fromHsvF(0.08, 1.0, 1.0);
const QColor FrameView::kReusedColor(90, 230, 120);
const QColor FrameView::kRejectedColor(255, 70, 70);
// Red, yellow and blue: apart from each other and from the heat map's ramp they lie over.
const QColor FrameView::kClassColor[3] = {QColor(255, 40, 40), QColor(255, 200, 0), QColor(60, 140, 255)};

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
  const QRectF area = imageArea();
  overlays_ = o;
  refresh();
  if (imageArea() != area) emit resized();  // the legend's strip took or gave back room
}

void FrameView::clearInspection() {
  region_ = {};
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

void FrameView::clearFrame(const QString& message) {
  frame_.reset();
  image_ = QImage();
  outlineOf_ = nullptr;
  waiting_ = message;
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

QRectF FrameView::imageArea() const {
  const QRectF legend = legendRect();
  return QRectF(0, 0, width(), legend.isEmpty() ? height() : legend.top());
}

QRectF FrameView::imageRect() const {
  const QRectF area = imageArea();
  if (image_.isNull()) return area;
  double s = std::min(area.width() / image_.width(), area.height() / image_.height());
  double w = image_.width() * s, h = image_.height() * s;
  return {area.x() + (area.width() - w) / 2, area.y() + (area.height() - h) / 2, w, h};
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
    p.drawText(area, Qt::AlignCenter | Qt::TextWordWrap, waiting_.isEmpty() ? tr("Starting the renderer...") : waiting_);
    drawNotice(p, imageArea());
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
  if (overlays_.legend) drawLegend(p);
  drawGizmo(p);
  drawNotice(p, r);
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
    // Above the image where the letterbox leaves room, so that it hides no tile's numbers while
    // a pass is stepped through; else over the image's top edge.
    const double line = QFontMetricsF(p.font()).height() + 8;
    const QRectF band = r.top() - area.top() >= line ? QRectF(r.left(), r.top() - line, r.width(), line) : r.adjusted(10, 8, -10, -8);
    p.drawText(band, Qt::AlignTop | Qt::AlignRight, tr("PAUSED (Esc resumes, . steps a frame)"));
  }
}

void FrameView::drawNotice(QPainter& p, const QRectF& r) const {
  if (notice_.isEmpty() || QDateTime::currentMSecsSinceEpoch() >= noticeUntil_) return;
  // A short confirmation where the artist is looking (Ctrl+B has no other visible effect).
  // As wide as its text, up to the image's width, where it wraps.
  const QFont noticeFont(font().family(), 10, QFont::Bold);
  p.setFont(noticeFont);
  const QFontMetricsF fm(noticeFont);
  const double maxWidth = std::max(120.0, r.width() - 24);
  const QRectF text = fm.boundingRect(QRectF(0, 0, maxWidth, 1000), Qt::AlignCenter | Qt::TextWordWrap, notice_);
  const QRectF box(r.center().x() - text.width() / 2 - 12, r.y() + 12, text.width() + 24, text.height() + 10);
  p.fillRect(box, QColor(0, 0, 0, 190));
  p.setPen(Qt::white);
  p.drawText(box, Qt::AlignCenter | Qt::TextWordWrap, notice_);
}

void FrameView::drawOverlays(QPainter& p, const QRectF& r) const {
  if (!frame_) return;
  const FrameRecord& f = *frame_;
  if (!selection_.empty() && f.image) {
    // Outlined pixel by pixel from the frame's object ids: what was picked (the gizmo sits at its
    // pivot, which may lie outside it), and which objects a move will take along.
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
    for (int t = 0; t < tiles; ++t)
      if (heatMapOn(t)) p.fillRect(tileRect(t), priorityColor(f.tilePriority[static_cast<std::size_t>(t)]));
  }
  if (overlays_.classes && static_cast<int>(f.tileClass.size()) == tiles) {
    // Hatched, so they read on top of the heat map: what the selected object touches directly
    // (high), through reflections or shadows (middle), and barely (low).
    for (int t = 0; t < tiles; ++t) {
      int c = f.tileClass[static_cast<std::size_t>(t)];
      if (c > 2) continue;
      p.fillRect(tileRect(t), QBrush(kClassColor[c], Qt::BDiagPattern));
      p.setPen(QPen(kClassColor[c], 1.5));
      p.drawRect(tileRect(t).adjusted(1, 1, -1, -1));
    }
  }
  const TileLabels labels = tileLabels(tileRect(0));
  const QFontMetricsF metrics(labels.font);
  // `box` is the label's place in a whole tile, moved to `tile`: an edge tile that the image's
  // border cuts short keeps only the part inside it. A label that does not fit is left out rather
  // than overprinted (or printed past the image).
  auto label = [&](const QRectF& box, const QRectF& tile, Qt::Alignment align, const QString& text) {
    const QRectF inside = box.intersected(tile);
    if (metrics.horizontalAdvance(text) > inside.width() || labels.font.pixelSize() > inside.height()) return;
    p.setFont(labels.font);  // the denoised regions' labels, drawn between, set their own
    p.drawText(inside, align, text);
  };
  if (overlays_.order && static_cast<int>(f.tilePriority.size()) == tiles && f.queueLength > 1) {
    p.setPen(Qt::white);
    for (int t = 0; t < tiles; ++t) {
      float pr = f.tilePriority[static_cast<std::size_t>(t)];
      if (pr < 0) continue;
      int rank = static_cast<int>(std::lround((1.0f - pr) * static_cast<float>(f.queueLength - 1))) + 1;
      label(labels.order.translated(tileRect(t).topLeft() - tileRect(0).topLeft()), tileRect(t), labels.orderAlign, QString::number(rank));
    }
  }
  if (overlays_.samples && static_cast<int>(f.tileSamples.size()) == tiles) {
    p.setPen(QColor(180, 255, 180));
    for (int t = 0; t < tiles; ++t)
      label(labels.samples.translated(tileRect(t).topLeft() - tileRect(0).topLeft()), tileRect(t), labels.samplesAlign,
            QString::number(static_cast<int>(f.tileSamples[static_cast<std::size_t>(t)])));
  }
  if (overlays_.served && static_cast<int>(f.servedTiles.size()) < tiles) {
    p.setPen(QPen(kServedColor, 1.5));
    p.setBrush(Qt::NoBrush);
    for (int t : f.servedTiles) p.drawRect(tileRect(t).adjusted(0.5, 0.5, -0.5, -0.5));
  }
  if (overlays_.denoised && !f.denoised.empty()) {
    // Newest (outermost) brightest; each boundary labelled with the frames since it was denoised.
    const auto n = static_cast<int>(f.denoised.size());
    for (int i = 0; i < n; ++i) {
      const DenoisedRegion& d = f.denoised[static_cast<std::size_t>(i)];
      QColor c = QColor::fromHsvF(kDenoisedColor.hsvHueF(), 0.25 + 0.75 * (i + 1) / n, 1.0);
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
    const QColor keep = kReusedColor, drop = kRejectedColor;
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
        p.fillRect(box, QBrush(drop, Qt::DiagCrossPattern));
        p.setPen(QPen(drop, 1.0));
        p.setBrush(Qt::NoBrush);
        p.drawRect(box.adjusted(1, 1, -1, -1));
        const std::uint64_t at = t < static_cast<int>(f.tileRejectedAt.size()) ? f.tileRejectedAt[static_cast<std::size_t>(t)] : 0;
        if (at > 0 && f.frame >= at) label(box.adjusted(2, 1, -2, -1), box, Qt::AlignLeft | Qt::AlignBottom, QString::number(f.frame - at));
      }
    }
  }
  if (overlays_.markers) {
    // Before the first edit (and after a resize) nothing has changed: a cross at the image's
    // centre would name a point of change that is not there.
    if (!f.pointsOfChange.empty()) {
      QPointF poc(r.x() + f.pointOfChange.x * sx, r.y() + f.pointOfChange.y * sy);
      p.setPen(QPen(kChangeColor, 2.5));
      p.drawLine(poc + QPointF(-10, 0), poc + QPointF(10, 0));
      p.drawLine(poc + QPointF(0, -10), poc + QPointF(0, 10));
    }
    p.setPen(QPen(kFocusColor, 2.5));
    for (const Vec2& fp : f.focus) p.drawEllipse(QPointF(r.x() + fp.x * sx, r.y() + fp.y * sy), 9, 9);
  }
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

std::vector<FrameView::LegendItem> FrameView::legendItems(bool everything) const {
  using K = LegendItem::Key;
  std::vector<LegendItem> items;
  if (!frame_ && !everything) return items;
  static const FrameRecord none;
  const FrameRecord& f = frame_ ? *frame_ : none;
  const int tiles = f.cols * f.rows;
  if (everything ? overlays_.priority : heatMapShown()) items.push_back({K::Ramp, Qt::white, tr("tiles still to come: next ... last")});
  if (overlays_.served && (everything || (!f.servedTiles.empty() && static_cast<int>(f.servedTiles.size()) < tiles)))
    items.push_back({K::Outline, kServedColor, tr("traced this frame")});
  if (overlays_.markers) {
    if (everything || !f.pointsOfChange.empty()) items.push_back({K::Cross, kChangeColor, tr("point of change")});
    if (everything || !f.focus.empty()) items.push_back({K::Circle, kFocusColor, tr("focus point")});
  }
  if (overlays_.classes && (everything || !f.tileClass.empty())) {
    const QString what[3] = {tr("high: seen, or strongly reflected"), tr("middle: reflections, shadows"), tr("low: faint traces")};
    for (int c = 0; c < 3; ++c)
      if (everything || std::find(f.tileClass.begin(), f.tileClass.end(), c) != f.tileClass.end())
        items.push_back({K::Hatch, kClassColor[c], what[c]});
    // The tiles of no class are the rest, served last: without a key they read as unclassified.
    constexpr std::uint8_t kRest = 3;  // FrameRecord::tileClass
    if (everything || std::find(f.tileClass.begin(), f.tileClass.end(), kRest) != f.tileClass.end())
      items.push_back({K::None, QColor(200, 200, 200), tr("unhatched: the object does not reach it")});
  }
  if (overlays_.order && (everything || f.queueLength > 1)) items.push_back({K::None, Qt::white, tr("numbers: place in the queue")});
  if (overlays_.samples) items.push_back({K::None, QColor(180, 255, 180), tr("numbers: samples per pixel")});
  if (overlays_.denoised && (everything || !f.denoised.empty()))
    items.push_back({K::Dashed, kDenoisedColor, tr("denoised region (frames since)")});
  if (overlays_.reuse && (everything || f.reusedTiles > 0))
    items.push_back({K::Corner, kReusedColor, tr("%n tile(s) reusing their history", nullptr, everything ? 9999 : f.reusedTiles)});
  if (overlays_.reuse && (everything || f.rejectedTiles > 0))
    items.push_back(
        {K::CrossHatch, kRejectedColor, tr("%n history(ies) rejected, frames since", nullptr, everything ? 9999 : f.rejectedTiles)});
  // The strip's height must not follow the method (a new one would resize the render): the
  // longest label stands in for it.
  const QString method = everything ? QStringLiteral("indirection+focus+smooth+denoise+reuse") : QString::fromStdString(f.method);
  const QString mode = everything ? QStringLiteral("global-update") : QString::fromStdString(f.mode);
  // Outside a pass the whole image takes the frame's samples: "0 of 0 tiles" read as if nothing
  // were traced, and the finished pass's "170 of 170 tiles" as if it were still the plan.
  if (!everything && !f.inPass()) items.push_back({K::None, QColor(200, 200, 200), tr("%1, %2: the whole image").arg(method, mode)});
  else
    items.push_back({K::None, QColor(200, 200, 200),
                     tr("%1, %2: %3 of %4 tiles")
                         .arg(method, mode)
                         .arg(everything ? 99999 : static_cast<qulonglong>(f.queueServed))
                         .arg(everything ? 99999 : static_cast<qulonglong>(f.queueLength))});
  return items;
}

QFont FrameView::legendFont() const { return QFont(font().family(), 9); }

FrameView::LegendLayout FrameView::layOutLegend(const std::vector<LegendItem>& items, double width) const {
  // Items flow left to right and wrap; an item wider than the strip wraps its own words.
  const QFontMetricsF fm(legendFont());
  const double line = std::max(fm.height(), kLegendKey) + 4;
  const double inner = std::max(40.0, width - 2 * kLegendPad);
  LegendLayout l;
  double x = 0, y = kLegendPad, rowHeight = line;
  for (const LegendItem& item : items) {
    const double key = item.key == LegendItem::Key::None ? 0 : kLegendKey + 5;
    double w = key + fm.horizontalAdvance(item.text), h = line;
    if (w > inner) {
      w = inner;
      h = std::max(line, fm.boundingRect(QRectF(0, 0, inner - key, 1e4), Qt::TextWordWrap, item.text).height() + 4);
    }
    if (x > 0 && x + w > inner) {
      x = 0;
      y += rowHeight;
      rowHeight = line;
    }
    l.items.emplace_back(kLegendPad + x, y, w, h);
    rowHeight = std::max(rowHeight, h);
    x += w + kLegendGap;
  }
  l.height = items.empty() ? 0 : y + rowHeight + kLegendPad;
  return l;
}

QRectF FrameView::legendRect() const {
  if (!overlays_.legend) return {};
  // Never more than half the widget: a tiny viewport keeps its picture.
  const double h = std::min(layOutLegend(legendItems(true), width()).height, height() / 2.0);
  return QRectF(0, height() - h, width(), h);
}

bool FrameView::heatMapShown() const {
  // Outside a pass (refining, or a global update restarting every tile) every tile has the same
  // standing: a heat map would only tint the picture, and its key would name tiles still to come.
  return overlays_.priority && frame_ && frame_->inPass();
}

bool FrameView::heatMapOn(int tile) const {
  if (!heatMapShown()) return false;
  const FrameRecord& f = *frame_;
  const auto t = static_cast<std::size_t>(tile);
  if (t >= f.tilePriority.size() || f.tilePriority[t] < 0 || f.queueLength == 0) return false;
  // Its place in the queue, from its priority (1 at the head falling to 0 at the end).
  const auto rank = static_cast<std::size_t>(std::lround((1.0f - f.tilePriority[t]) * static_cast<float>(f.queueLength - 1)));
  return rank >= f.queueServed && std::find(f.servedTiles.begin(), f.servedTiles.end(), tile) == f.servedTiles.end();
}

void FrameView::drawLegend(QPainter& p) const {
  using K = LegendItem::Key;
  const QRectF strip = legendRect();
  if (strip.isEmpty()) return;
  p.save();
  p.setClipRect(strip);
  p.fillRect(strip, QColor(20, 20, 24));
  p.setFont(legendFont());
  const std::vector<LegendItem> items = legendItems();
  const LegendLayout layout = layOutLegend(items, strip.width());
  p.setRenderHint(QPainter::Antialiasing, true);
  for (std::size_t i = 0; i < items.size(); ++i) {
    const LegendItem& item = items[i];
    const QRectF at = layout.items[i].translated(strip.topLeft());
    const QRectF key(at.x(), at.y() + 2, kLegendKey, kLegendKey - 4);
    const QPointF c = key.center();
    p.setBrush(Qt::NoBrush);
    p.setPen(QPen(item.color, 2.0));
    switch (item.key) {
      case K::None: break;
      case K::Ramp: {
        QLinearGradient g(key.topLeft(), key.topRight());
        for (int s = 0; s <= 4; ++s) {
          QColor rc = priorityColor(1.0f - s / 4.0f);
          rc.setAlphaF(1.0);
          g.setColorAt(s / 4.0, rc);
        }
        p.fillRect(key, g);
        break;
      }
      case K::Outline: p.drawRect(key.adjusted(1, 1, -1, -1)); break;
      case K::Cross:
        p.drawLine(c - QPointF(6, 0), c + QPointF(6, 0));
        p.drawLine(c - QPointF(0, 6), c + QPointF(0, 6));
        break;
      case K::Circle: p.drawEllipse(c, 5.5, 5.5); break;
      case K::Hatch:
      case K::CrossHatch:
        p.fillRect(key, QBrush(item.color, item.key == K::Hatch ? Qt::BDiagPattern : Qt::DiagCrossPattern));
        p.setPen(QPen(item.color, 1.5));
        p.drawRect(key.adjusted(1, 1, -1, -1));
        break;
      case K::Dashed:
        p.setPen(QPen(item.color, 2.0, Qt::DashLine));
        p.drawRect(key.adjusted(1, 1, -1, -1));
        break;
      case K::Corner:
        p.setPen(Qt::NoPen);
        p.setBrush(item.color);
        p.drawPolygon(QPolygonF({key.topRight(), key.topRight() + QPointF(-8, 0), key.topRight() + QPointF(0, 8)}));
        p.setPen(QPen(QColor(160, 160, 160), 1.0));
        p.setBrush(Qt::NoBrush);
        p.drawRect(key.adjusted(0.5, 0.5, -0.5, -0.5));
        break;
    }
    const double keyWidth = item.key == K::None ? 0 : kLegendKey + 5;
    p.setPen(item.key == K::Ramp ? QColor(230, 230, 230) : item.color);
    p.drawText(at.adjusted(keyWidth, 0, 0, 0), Qt::AlignLeft | Qt::AlignTop | Qt::TextWordWrap, item.text);
  }
  p.restore();
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
      const float* c =
          inspected(img).data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x)) * 3;
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
      if (frame_ && r.width() > 0)
        emit axisDragged(dragAxis_, QPointF(d.x() * frame_->width / r.width(), d.y() * frame_->height / r.height()));
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
        emit focusPlaced(
            QPointF((regionStart_.x() - r.x()) / r.width() * frame_->width, (regionStart_.y() - r.y()) / r.height() * frame_->height));
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

std::optional<std::size_t> FrameView::pixelIndex(QPoint imagePixel) const {
  if (!frame_ || !frame_->image || imagePixel.x() < 0 || imagePixel.y() < 0 || imagePixel.x() >= frame_->image->width ||
      imagePixel.y() >= frame_->image->height)
    return std::nullopt;
  return static_cast<std::size_t>(imagePixel.y()) * static_cast<std::size_t>(frame_->image->width) +
         static_cast<std::size_t>(imagePixel.x());
}

quint64 FrameView::objectAt(QPoint imagePixel) const {
  const auto i = pixelIndex(imagePixel);
  return i && *i < frame_->image->objectId.size() ? static_cast<quint64>(frame_->image->objectId[*i]) : 0;
}

std::optional<double> FrameView::samplesAt(QPoint imagePixel) const {
  const auto i = pixelIndex(imagePixel);
  if (!i || *i >= frame_->image->sampleCount.size()) return std::nullopt;
  return frame_->image->sampleCount[*i];
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
