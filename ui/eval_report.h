// The pictures of `retile eval`'s report: charts drawn with Qt Charts and written as PNG and SVG,
// and strips of frames with the editor's tile and denoise overlays (FrameView). Needs a
// QApplication (the offscreen platform will do); GUI thread only.
#pragma once

#include <QChartView>
#include <QImage>
#include <QPointF>
#include <QRectF>
#include <QSizeF>
#include <QString>

#include <filesystem>
#include <memory>
#include <vector>

#include "retile/error.h"
#include "retile/session.h"

namespace retile::ui {

struct ChartLine {
  QString name;
  std::vector<QPointF> points;
};

struct ChartPoint {
  QString label;   // on the plot (points drawn at one spot share one label)
  QString legend;  // in the legend; empty: the label, with "(not reached)" when not reached
  QPointF at;
  // false: `at`'s x is a bound (the run's length), not a time measured; the point is drawn in a
  // "not reached" band beyond the times, and its x only sizes the time axis when nothing reached.
  bool reached = true;
};

// A label to place beside the point it names (a chart marker centred at `anchor`), `size` big,
// within `bounds`.
struct LabelRequest {
  QPointF anchor;
  QSizeF size;
  QRectF bounds;
};

// Boxes for `labels`, in order: each the first spot going round its point and ever farther out
// (right, left, above, below, then the diagonals) that stays within its bounds and clear of the
// boxes placed before it and of `obstacles` (the markers); failing that, the spot that overlaps
// least. The same every run, so that the report's charts are.
std::vector<QRectF> placeLabels(const std::vector<LabelRequest>& labels, const std::vector<QRectF>& obstacles);

// Writes `base`.png and `base`.svg: a line per entry (error against time, one per method).
Result<bool> writeLineChart(const std::filesystem::path& base, const QString& title, const QString& xTitle, const QString& yTitle,
                            const std::vector<ChartLine>& lines, bool logX = false);
// The same with one labelled point per entry (the speed-against-accuracy chart).
Result<bool> writePointChart(const std::filesystem::path& base, const QString& title, const QString& xTitle, const QString& yTitle,
                             const std::vector<ChartPoint>& points);

// The same charts laid out at the report's size in a view never shown on screen, for a test to
// look at what the files would show.
std::unique_ptr<QChartView> lineChartView(const QString& title, const QString& xTitle, const QString& yTitle,
                                          const std::vector<ChartLine>& lines, bool logX = false);
std::unique_ptr<QChartView> pointChartView(const QString& title, const QString& xTitle, const QString& yTitle,
                                           const std::vector<ChartPoint>& points);

// A frame as the viewport shows it with the tile overlays (served tiles, priorities, markers,
// denoised regions), `scale` times the image size, without the legend.
QImage frameWithOverlays(const FrameRecord& frame, int scale);

// A grid of pictures: a row per method (label on the left), a column per chosen frame (caption
// above), written as PNG.
struct StripRow {
  QString label;
  std::vector<QImage> cells;
};
Result<bool> writeStrip(const std::filesystem::path& file, const std::vector<QString>& captions, const std::vector<StripRow>& rows);

}  // namespace retile::ui
