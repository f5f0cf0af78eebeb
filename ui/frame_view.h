// The viewport: composes the newest frame from the engine (through the display transform),
// scaled up to the widget, with the teaching overlays drawn from the frame record, and presents
// it through a QVulkanWindow where the platform has Vulkan surfaces, or paints it itself where it
// has not (Qt's offscreen platform). All viewport interaction lives here, whichever presents.
// GUI thread only; it never waits on rendering: showFrame() takes whatever the mailbox held.
#pragma once

#include <QImage>
#include <QVector3D>
#include <QWidget>

#include <algorithm>
#include <memory>
#include <optional>

#include "retile/image.h"
#include "retile/session.h"

namespace retile::ui {

class VulkanViewport;

struct OverlaySettings {
  bool priority = true;  // per-tile priority as a heat map
  bool order = false;    // the queue position as numbers
  bool samples = false;  // accumulated samples per tile
  bool served = true;    // tiles traced this frame, outlined
  bool markers = true;   // point of change and focus points
  bool legend = true;
  bool classes = false;  // indirection classes: high, middle, low (indirection methods only)
  bool denoised = true;  // the denoised regions' boundaries, labelled with their age
  bool reuse = true;     // verified reuse: tiles reusing their history, tiles whose history was rejected
};

class FrameView : public QWidget {
  Q_OBJECT
 public:
  explicit FrameView(QWidget* parent = nullptr);

  void showFrame(std::shared_ptr<const FrameRecord> frame);
  // Drops the frame shown (it was another scene's) and says `message` in its place until the
  // next frame comes.
  void clearFrame(const QString& message);
  QString waitingMessage() const { return frame_ ? QString() : waiting_; }
  const std::shared_ptr<const FrameRecord>& frame() const { return frame_; }
  OverlaySettings& overlays() { return overlays_; }
  void setOverlays(const OverlaySettings& o);
  void setPaused(bool paused);
  // What the pixel inspector reads: the image as shown (denoised, when it is) or the accumulation.
  enum class Inspect { Shown, Raw };
  void setInspect(Inspect what) { inspect_ = what; }
  // Forgets the inspected region (it belonged to another scene).
  void clearInspection();
  QRect inspectedRegion() const { return region_; }
  Inspect inspect() const { return inspect_; }
  // Display-only: exposure, gamma and OCIO view; the accumulated samples are untouched.
  void setDisplay(const DisplaySettings& d);
  const DisplaySettings& display() const { return display_; }
  // The image rectangle inside the widget (letterboxed to the frame's aspect).
  QRectF imageRect() const;

  // Snapshots for A/B comparison: B is the snapshot, A the live render. Toggle shows B instead of
  // A; wipe shows B left of a vertical line at `wipe` (0..1 of the image width), A right of it.
  enum class Compare { Off, Toggle, Wipe };
  void takeSnapshot();
  bool hasSnapshot() const { return !snapshot_.isNull(); }
  // A line over the top of the image for `ms`, confirming what a key did.
  void showNotice(const QString& text, int ms = 2500);
  QString notice() const { return notice_; }
  void setCompare(Compare c);
  Compare compare() const { return compare_; }
  void setWipe(double x);

  // Q/W/E/R: what a left drag on the selection does. The gizmo (image pixels) is the selection's
  // origin and the ends of its world x, y and z axes, placed by the owner from the camera.
  enum class Tool { Select, Move, Rotate, Scale };
  struct Gizmo {
    bool visible = false;
    QPointF origin;
    QPointF axisEnd[3];
    bool operator==(const Gizmo& o) const {
      return visible == o.visible && origin == o.origin && std::equal(axisEnd, axisEnd + 3, o.axisEnd);
    }
  };
  void setTool(Tool t);
  Tool tool() const { return tool_; }
  void setGizmo(const Gizmo& g);
  const Gizmo& gizmo() const { return gizmo_; }
  static constexpr double kRingRadiusX = 34, kRingRadiusY = 12;  // the rotate tool's ring, widget pixels
  // A point in the widget over an image position (the inverse of picking's mapping).
  QPointF widgetPoint(QPointF imagePixel) const { return toWidget(imagePixel); }
  // The shown frame at an image pixel: the object of its first hit (0: none) and the samples it
  // holds (none outside the image).
  quint64 objectAt(QPoint imagePixel) const;
  std::optional<double> samplesAt(QPoint imagePixel) const;

  // The presenting Vulkan window, or nullptr when this widget paints (and why, for the log).
  VulkanViewport* vulkanWindow() const { return vulkan_; }
  // The Vulkan window failed for good: from now on this widget paints the picture itself.
  void fallBackToWidget(const QString& why);
  QString presentation() const { return presentation_; }
  // The picture exactly as presented: image, overlays and banners at the widget's size.
  QImage composed() const;

  // The legend: one item per kind of mark on screen, each led by its key (the mark as drawn, in
  // its colour), laid out in a strip below the image that the image never shares, so that it
  // covers nothing however small the image, and wrapped, never cut, to the viewport's width.
  struct LegendItem {
    enum class Key { None, Ramp, Outline, Cross, Circle, Hatch, CrossHatch, Dashed, Corner };
    Key key = Key::None;
    QColor color;  // of the mark and of its words
    QString text;
  };
  // What is drawn now (the frame and the overlays that are on): nothing explained that is not drawn.
  std::vector<LegendItem> legendItems() const { return legendItems(false); }
  // Where each item goes in a strip `width` wide (from its top left), and the strip's height.
  struct LegendLayout {
    std::vector<QRectF> items;
    double height = 0;
  };
  LegendLayout layOutLegend(const std::vector<LegendItem>& items, double width) const;
  // The strip in widget pixels (empty with the legend off). Its height is what every item the
  // overlays can draw would need, so the image does not jump as marks come and go.
  QRectF legendRect() const;
  // Where the image may go: the widget above the legend strip.
  QRectF imageArea() const;
  // The marks' colours, shared by the drawing and its legend.
  static const QColor kServedColor, kChangeColor, kFocusColor, kDenoisedColor, kReusedColor, kRejectedColor;
  static const QColor kClassColor[3];  // high, middle, low
  // The priority heat map is drawn: it is on and the frame belongs to a pass. It tints only the
  // tiles the pass has yet to reach, so the re-rendered ones can be judged as they come.
  bool heatMapShown() const;
  bool heatMapOn(int tile) const;
  static constexpr double kLegendPad = 6, kLegendKey = 16, kLegendGap = 16;  // widget pixels
  struct TileLabels {
    QFont font;
    QRectF order, samples;
    Qt::Alignment orderAlign, samplesAlign;
  };
  TileLabels tileLabels(const QRectF& tile) const;

 signals:
  void presentationChanged(const QString& presentation);  // the viewport fell back to the widget
  void objectPicked(quint64 object);                      // 0: nothing under the cursor
  void objectToggled(quint64 object);                     // Ctrl+click on an object: into or out of the selection
  void focusPlaced(QPointF imagePixel);
  // Drags, in widget pixels since the last event. A drag starts with a press and ends with the
  // release (dragFinished), so a whole drag can be one undo step.
  void orbitDragged(QPointF delta);                // Alt + left
  void panDragged(QPointF delta);                  // Alt + middle
  void dollyDragged(double amount);                // Alt + right, or the wheel (positive: closer)
  void objectDragged(QPointF imageDelta);          // Move tool, left drag starting on the selection: image pixels
  void axisDragged(int axis, QPointF imageDelta);  // Move tool, drag of a gizmo arrow
  void rotateDragged(double pixels);               // Rotate tool: horizontal drag turns about world y
  void scaleDragged(double pixels);                // Scale tool: horizontal drag scales uniformly
  void dragFinished();
  void resized();
  // Pixel inspector: linear values under the cursor, and the statistics of a Ctrl+drag region
  // (image pixels, inclusive-exclusive).
  void pixelInspected(QPoint pixel, QVector3D linear);
  // Shift+drag: a render region in image pixels (Shift+click without a drag: focusPlaced).
  void renderRegionDrawn(QRect region);
  void regionInspected(QRect region, QVector3D mean, QVector3D min, QVector3D max);

 protected:
  void paintEvent(QPaintEvent*) override;
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;
  void resizeEvent(QResizeEvent* e) override;

 private:
  void refresh();
  void compose(QPainter& p, const QRect& area) const;
  void drawOverlays(QPainter& p, const QRectF& r) const;
  void drawLegend(QPainter& p) const;
  // `everything`: every item the overlays that are on can draw, whatever the frame shows (the
  // strip's height is made for them).
  std::vector<LegendItem> legendItems(bool everything) const;
  QFont legendFont() const;
  QImage toDisplay(const RenderImage& img) const;
  const std::vector<float>& inspected(const RenderImage& img) const { return inspect_ == Inspect::Raw ? img.color : img.shown(); }
  QPoint imagePixel(QPointF widgetPos) const;
  std::optional<std::size_t> pixelIndex(QPoint imagePixel) const;  // into the shown frame's image; none outside it
  void inspectRegion();

  std::shared_ptr<const FrameRecord> frame_;
  QImage image_;
  OverlaySettings overlays_;
  DisplaySettings display_;
  bool paused_ = false;
  Inspect inspect_ = Inspect::Shown;
  enum class Drag { None, Orbit, Pan, Dolly, Object, Axis, Rotate, Scale, Region, RenderRegion, Wipe } drag_ = Drag::None;
  QRect draft_;  // a render region being drawn (image pixels)
  int dragAxis_ = 0;
  Tool tool_ = Tool::Move;
  Gizmo gizmo_;
  QPointF toWidget(QPointF imagePixel) const;
  void drawGizmo(QPainter& p) const;
  QPointF last_, regionStart_;
  QRect region_;                             // the inspected region in image pixels
  quint64 selected_ = 0;                     // the primary selection
  std::vector<quint64> selection_;           // all selected objects
  mutable QImage outline_;                   // the multi-selection's outline, at the frame's resolution
  mutable const void* outlineOf_ = nullptr;  // the image record it was made for
  std::shared_ptr<const RenderImage> snapshotLinear_;
  QImage snapshot_;
  Compare compare_ = Compare::Off;
  QString notice_;
  qint64 noticeUntil_ = 0;
  QString waiting_;  // said while there is no frame
  void drawNotice(QPainter& p, const QRectF& r) const;
  double wipe_ = 0.5;
  VulkanViewport* vulkan_ = nullptr;
  QWidget* container_ = nullptr;
  QString presentation_;

 public:
  void setSelected(quint64 object) { setSelection(object ? std::vector<quint64>{object} : std::vector<quint64>{}, object); }
  // Every selected object (a drag on any of them moves them all) and the one that leads; with
  // more than one, each is outlined.
  void setSelection(std::vector<quint64> objects, quint64 primary);
  const std::vector<quint64>& selection() const { return selection_; }
};

// The heat map's colour for a priority in [0, 1] (1: served first).
QColor priorityColor(float priority);

}  // namespace retile::ui
