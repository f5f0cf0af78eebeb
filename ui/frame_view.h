// The viewport as a plain widget: paints the newest frame from the engine, scaled up to the
// widget, with the teaching overlays drawn from the frame record. Works on every Qt platform
// (offscreen included). GUI thread only; it never waits on rendering: newFrame() takes whatever
// the mailbox holds.
#pragma once

#include <QImage>
#include <QWidget>

#include <memory>

#include "retile/session.h"

namespace retile::ui {

struct OverlaySettings {
  bool priority = true;   // per-tile priority as a heat map
  bool order = false;     // the queue position as numbers
  bool samples = false;   // accumulated samples per tile
  bool served = true;     // tiles traced this frame, outlined
  bool markers = true;    // point of change and focus points
  bool legend = true;
};

class FrameView : public QWidget {
  Q_OBJECT
 public:
  explicit FrameView(QWidget* parent = nullptr);

  void showFrame(std::shared_ptr<const FrameRecord> frame);
  const std::shared_ptr<const FrameRecord>& frame() const { return frame_; }
  OverlaySettings& overlays() { return overlays_; }
  void setOverlays(const OverlaySettings& o);
  void setPaused(bool paused);
  // The image rectangle inside the widget (letterboxed to the frame's aspect).
  QRectF imageRect() const;

 signals:
  void objectPicked(quint64 object);  // 0: nothing under the cursor
  void focusPlaced(QPointF imagePixel);
  // Drags, in widget pixels since the last event. A drag starts with a press and ends with the
  // release (dragFinished), so a whole drag can be one undo step.
  void orbitDragged(QPointF delta);       // Alt + left
  void panDragged(QPointF delta);         // Alt + middle
  void dollyDragged(double amount);       // Alt + right, or the wheel (positive: closer)
  void objectDragged(QPointF imageDelta);  // left drag starting on the selection: image pixels
  void dragFinished();

 protected:
  void paintEvent(QPaintEvent*) override;
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;

 private:
  void drawOverlays(QPainter& p, const QRectF& r) const;

  std::shared_ptr<const FrameRecord> frame_;
  QImage image_;
  OverlaySettings overlays_;
  bool paused_ = false;
  enum class Drag { None, Orbit, Pan, Dolly, Object } drag_ = Drag::None;
  QPointF last_;
  quint64 selected_ = 0;

 public:
  void setSelected(quint64 object) { selected_ = object; }
};

// The heat map's colour for a priority in [0, 1] (1: served first).
QColor priorityColor(float priority);

}  // namespace retile::ui
