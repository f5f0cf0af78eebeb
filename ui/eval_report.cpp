#include "eval_report.h"

#include <QCategoryAxis>
#include <QChart>
#include <QChartView>
#include <QCoreApplication>
#include <QFile>
#include <QFont>
#include <QGraphicsLineItem>
#include <QGraphicsRectItem>
#include <QGraphicsSimpleTextItem>
#include <QLineSeries>
#include <QPainter>
#include <QPen>
#include <QScatterSeries>
#include <QSvgGenerator>
#include <QValueAxis>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "frame_view.h"
#include "retile/log.h"

namespace retile::ui {

namespace {

constexpr QSize kChartSize{900, 520};

// Ten colours that stay apart (Tableau 10); the default theme repeats after five.
QColor seriesColor(std::size_t i) {
  static const QRgb colors[] = {0x4e79a7, 0xf28e2b, 0xe15759, 0x76b7b2, 0x59a14f, 0xedc948, 0xb07aa1, 0xff9da7, 0x9c755f, 0xbab0ac};
  return QColor::fromRgb(colors[i % 10]);
}

const auto kNotReached = QStringLiteral("not reached");
constexpr double kMarkerSize = 11;
// The gap between a marker and a label beside it.
constexpr double kLabelGap = 2;
// Among the chart's own items (grid 2, axes 3, series 4, legend 5): the band over the grid and
// under the axes, the labels and their lines over the points.
constexpr double kBandZ = 2.5, kLabelZ = 4.5;
// The plot's width before the chart is laid out (the report's size, the legend on the right): the
// time axis's labels are chosen to stay apart at it.
constexpr double kPlotWidthGuess = 560;
// Closer than this, a time axis's labels run into each other ("900" "1000").
constexpr double kMinTickGapPx = 50;
// The log time axis reaches this factor beyond the data on either side.
constexpr double kLogPad = 1.1;

// The shortest text that states `v` exactly: ticks are round numbers (0.3, 250, 2000).
QString tickText(double v) {
  for (int decimals = 0; decimals < 6; ++decimals) {
    const double scaled = v * std::pow(10.0, decimals);
    if (std::abs(scaled - std::round(scaled)) < 1e-6 * std::max(1.0, std::abs(scaled))) return QString::number(v, 'f', decimals);
  }
  return QString::number(v, 'g', 6);
}

// About `count` ticks over [lo, hi], a step of 1, 2, 2.5 or 5 times a power of ten apart.
std::vector<double> linearTicks(double lo, double hi, int count) {
  const double raw = std::max(hi - lo, 1e-12) / count;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10 * decade;
  for (double m : {1.0, 2.0, 2.5, 5.0})
    if (m * decade >= raw) {
      step = m * decade;
      break;
    }
  std::vector<double> ticks;
  // Multiples of the step counted, not summed, so that 0.1 + 0.2 does not drift off 0.3.
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; ++k) ticks.push_back(k * step);
  return ticks;
}

// The ticks m * 10^k within [lo, hi] for each mantissa m.
std::vector<double> decadeTicks(double lo, double hi, std::initializer_list<double> mantissas) {
  std::vector<double> ticks;
  for (double k = std::floor(std::log10(lo)); k <= std::ceil(std::log10(hi)); ++k)
    for (double m : mantissas)
      if (const double v = m * std::pow(10.0, k); v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) ticks.push_back(v);
  return ticks;
}

// Ticks for a log axis over [lo, hi] (lo > 0): of several round sets (powers of ten; 1, 2, 5;
// 1, 2, 3, 5; 1 to 9; evenly spaced, coarse and fine), the one whose labels stay apart and leave the shortest
// stretch of the axis unlabelled (600 to 1000 alone left 1000 to 1800 bare; 750, 1000, ... 1750
// did not), so that a range of less than a decade is labelled across; where decades crowd, every
// other power of ten, or every third.
std::vector<double> logTicks(double lo, double hi) {
  const double pxPerDecade = kPlotWidthGuess / std::max(std::log10(hi / lo), 1e-9);
  const auto apart = [&](const std::vector<double>& t) {
    for (std::size_t i = 1; i < t.size(); ++i)
      if (std::log10(t[i] / t[i - 1]) * pxPerDecade < kMinTickGapPx) return false;
    return !t.empty();
  };
  const auto widestBare = [&](const std::vector<double>& t) {
    double widest = 0, from = lo;
    for (double v : t) widest = std::max(widest, std::log10(v / from)), from = v;
    return std::max(widest, std::log10(hi / from));
  };
  const std::vector<double> sets[] = {decadeTicks(lo, hi, {1}),
                                      decadeTicks(lo, hi, {1, 2, 5}),
                                      decadeTicks(lo, hi, {1, 2, 3, 5}),
                                      decadeTicks(lo, hi, {1, 2, 3, 4, 5, 6, 7, 8, 9}),
                                      linearTicks(lo, hi, 6),
                                      linearTicks(lo, hi, 10)};
  const std::vector<double>* best = nullptr;
  for (const auto& t : sets)
    if (apart(t) && (!best || widestBare(t) < widestBare(*best))) best = &t;
  if (best) return *best;
  for (std::size_t every = 2; every < sets[0].size(); ++every) {
    std::vector<double> thinned;
    for (std::size_t i = 0; i < sets[0].size(); i += every) thinned.push_back(sets[0][i]);
    if (apart(thinned)) return thinned;
  }
  return sets[0];
}

// An axis over [lo, hi] labelled at `ticks` alone, in the axis's units; on a log axis those are
// log10 of the values (Qt's log axis labels only the powers of its base: one label, "1000",
// across 300 to 1300 ms).
QCategoryAxis* tickedAxis(double lo, double hi, const std::vector<double>& ticks, bool log) {
  auto* axis = new QCategoryAxis;
  axis->setLabelsPosition(QCategoryAxis::AxisLabelsPositionOnValue);
  axis->setRange(log ? std::log10(lo) : lo, log ? std::log10(hi) : hi);
  axis->setStartValue(axis->min());
  for (double t : ticks) axis->append(tickText(t), log ? std::log10(t) : t);
  return axis;
}

// A value axis over the finite points, padded so no point sits on the frame.
void fitAxis(QValueAxis* axis, double lo, double hi) {
  if (!(lo <= hi)) lo = 0, hi = 1;
  double pad = (hi - lo) * 0.05;
  if (pad <= 0) pad = std::max(std::abs(hi) * 0.05, 0.5);
  axis->setRange(lo - pad, hi + pad);
  axis->applyNiceNumbers();
}

// The time axis of an error-against-time chart over the data's [lo, hi].
QCategoryAxis* timeAxis(double lo, double hi, bool log) {
  if (!(lo <= hi)) lo = 1, hi = 10;
  if (log) return tickedAxis(lo / kLogPad, hi * kLogPad, logTicks(lo / kLogPad, hi * kLogPad), true);
  const double pad = std::max((hi - lo) * 0.05, 0.5);
  return tickedAxis(lo - pad, hi + pad, linearTicks(lo - pad, hi + pad, 6), false);
}

std::unique_ptr<QChartView> laidOut(QChart* chart) {
  auto view = std::make_unique<QChartView>(chart);  // owns the chart from here
  view->setRenderHint(QPainter::Antialiasing);
  // The chart lays itself out when its view is shown and resized; shown off screen, never drawn
  // to a display.
  view->setAttribute(Qt::WA_DontShowOnScreen);
  view->resize(kChartSize);
  view->show();
  chart->resize(kChartSize);
  QCoreApplication::processEvents();
  return view;
}

Result<bool> writeChart(QChartView& view, const std::filesystem::path& base) {
  QChart* chart = view.chart();
  const QString png = QString::fromStdString(base.string() + ".png");
  const QString svg = QString::fromStdString(base.string() + ".svg");
  QImage image(kChartSize, QImage::Format_RGB32);
  image.fill(Qt::white);
  {
    QPainter p(&image);
    view.render(&p);
  }
  // Through a temporary name and a rename, as every file Retile writes.
  const QString tmpPng = png + ".tmp.png";
  if (!image.save(tmpPng, "PNG")) return Result<bool>::failure(cat("cannot write ", png.toStdString()));
  QFile::remove(png);
  if (!QFile::rename(tmpPng, png)) return Result<bool>::failure(cat("cannot write ", png.toStdString()));
  const QString tmpSvg = svg + ".tmp";
  {
    QSvgGenerator gen;
    gen.setFileName(tmpSvg);
    gen.setSize(kChartSize);
    gen.setViewBox(QRect(QPoint(0, 0), kChartSize));
    gen.setTitle(chart->title());
    QPainter p;
    if (!p.begin(&gen)) return Result<bool>::failure(cat("cannot write ", svg.toStdString()));
    view.render(&p);
  }
  QFile::remove(svg);
  if (!QFile::rename(tmpSvg, svg)) return Result<bool>::failure(cat("cannot write ", svg.toStdString()));
  return true;
}

QChart* newChart(const QString& title) {
  auto* chart = new QChart;
  chart->setTitle(title);
  QFont f = chart->titleFont();
  f.setPointSize(12);
  f.setBold(true);
  chart->setTitleFont(f);
  chart->legend()->setAlignment(Qt::AlignRight);
  chart->setAnimationOptions(QChart::NoAnimation);
  return chart;
}

// The speed-against-accuracy chart's time axis: round ticks over the times reached and, when a
// method never reached its target, a band beyond them where such methods are drawn.
struct TimeScale {
  std::vector<double> ticks;
  bool band = false;
  double bandStart = 0, axisEnd = 1;
  double bandCentre() const { return (bandStart + axisEnd) / 2; }
};

TimeScale timeScale(const std::vector<ChartPoint>& points) {
  double reachedEnd = 0, anyEnd = 0;
  TimeScale t;
  for (const ChartPoint& p : points) {
    t.band |= !p.reached;
    if (!std::isfinite(p.at.x())) continue;
    anyEnd = std::max(anyEnd, p.at.x());
    if (p.reached) reachedEnd = std::max(reachedEnd, p.at.x());
  }
  // With nothing reached, the runs' lengths (the bounds the points carry) span the axis, so the
  // band says how long the methods ran without reaching the target.
  const double end = 1.05 * (reachedEnd > 0 ? reachedEnd : anyEnd > 0 ? anyEnd : 1);
  t.ticks = linearTicks(0, end, 5);
  t.bandStart = t.band ? end * 1.04 : end;
  t.axisEnd = t.band ? t.bandStart + 0.3 * end : end;
  return t;
}

// A reached point is a filled disc; one that never reached its target an empty square, in the
// legend too.
QScatterSeries* markerSeries(const ChartPoint& p, const QColor& colour) {
  auto* s = new QScatterSeries;
  s->setColor(colour);
  s->setMarkerSize(kMarkerSize);
  if (!p.reached) {
    s->setMarkerShape(QScatterSeries::MarkerShapeRectangle);
    s->setBrush(Qt::NoBrush);
    s->setPen(QPen(colour, 2));
  }
  s->setName(!p.legend.isEmpty() ? p.legend : p.reached ? p.label : p.label + " (" + kNotReached + ")");
  return s;
}

struct Band {
  QRectF area;   // empty: every point reached
  QRectF title;  // where the words "not reached" stand
};

// The "not reached" band, right of the times: shaded, no time under it, titled at its top (on the
// axis Qt cuts the words to "not reac..." when a tick stands near).
Band drawBand(QChart* chart, QAbstractSeries* series, const TimeScale& t) {
  const QRectF plot = chart->plotArea();
  const double left = chart->mapToPosition(QPointF(t.bandStart, 0), series).x();
  Band band{QRectF(QPointF(left, plot.top()), plot.bottomRight()), {}};
  auto* shade = new QGraphicsRectItem(band.area, chart);
  shade->setBrush(QColor(236, 236, 236));
  shade->setPen(QPen(QColor(190, 190, 190), 1));
  shade->setZValue(kBandZ);
  auto* title = new QGraphicsSimpleTextItem(kNotReached, chart);
  QFont bold = title->font();
  bold.setBold(true);
  title->setFont(bold);
  title->setBrush(QColor(90, 90, 90));
  title->setZValue(kLabelZ);
  const QRectF text = title->boundingRect();
  title->setPos(band.area.center().x() - text.width() / 2, band.area.top() + 3);
  band.title = title->sceneBoundingRect();
  return band;
}

double area(const QRectF& r) { return r.isEmpty() ? 0 : r.width() * r.height(); }

// How much of a label at `spot` would be hidden or would hide something: the part outside its
// bounds, and the parts over the labels placed before it or over markers.
double overlap(const QRectF& spot, const QRectF& bounds, const std::vector<QRectF>& placed, const std::vector<QRectF>& obstacles) {
  double cost = area(spot) - area(spot & bounds);
  for (const auto* rects : {&placed, &obstacles})
    for (const QRectF& r : *rects) cost += area(spot & r);
  return cost;
}

// Where a label may go around its point, nearest first: beside it on the right, left, above,
// below, then on the diagonals, and again ring by ring, a line's height farther out each time.
std::vector<QRectF> labelSpots(const LabelRequest& l) {
  constexpr int kRings = 16;
  constexpr QPoint kDirections[] = {{1, 0}, {-1, 0}, {0, -1}, {0, 1}, {1, -1}, {1, 1}, {-1, -1}, {-1, 1}};
  const double w = l.size.width(), h = l.size.height(), r = kMarkerSize / 2 + kLabelGap;
  std::vector<QRectF> spots;
  for (int ring = 0; ring < kRings; ++ring)
    for (QPoint d : kDirections) {
      const QPointF centre(l.anchor.x() + d.x() * (r + w / 2 + ring * h), l.anchor.y() + d.y() * (r + h / 2 + ring * h));
      spots.emplace_back(centre - QPointF(w / 2, h / 2), l.size);
    }
  return spots;
}

QRectF markerBox(QPointF at) {
  const double half = kMarkerSize / 2 + 1;
  return QRectF(at - QPointF(half, half), QSizeF(2 * half, 2 * half));
}

// A line from a marker's edge to its label, when the label could not sit right beside it.
void drawLeader(QChart* chart, QPointF from, const QRectF& box, const QColor& colour) {
  const QPointF to(std::clamp(from.x(), box.left(), box.right()), std::clamp(from.y(), box.top(), box.bottom()));
  const QPointF d = to - from;
  const double length = std::hypot(d.x(), d.y());
  if (length < (kMarkerSize / 2 + kLabelGap) * 1.5) return;
  auto* line = new QGraphicsLineItem(QLineF(from + d * ((kMarkerSize / 2 + 1) / length), to), chart);
  line->setPen(QPen(colour, 1));
  line->setZValue(kLabelZ);
}

struct Marker {
  QScatterSeries* series;
  QString label;
  bool reached;
};

// The labels on the plot: markers that coincide share one ("spiral, change", a name a line where
// that is too wide); the rest each get their own, placed clear of every other label and marker,
// a reached one's among the times and a never reached one's in the band.
void labelMarkers(QChart* chart, const std::vector<Marker>& markers, const Band& band) {
  QRectF times = chart->plotArea();
  if (!band.area.isNull()) times.setRight(band.area.left() - 1);
  struct Group {
    QPointF at;
    QStringList names;
    const Marker* first;
  };
  std::vector<Group> groups;
  std::vector<QRectF> obstacles;
  if (!band.title.isNull()) obstacles.push_back(band.title);
  for (const Marker& m : markers) {
    const QPointF at = chart->mapToPosition(m.series->at(0), m.series);
    obstacles.push_back(markerBox(at));
    auto same = std::find_if(groups.begin(), groups.end(), [&](const Group& g) {
      return g.first->reached == m.reached && std::hypot(g.at.x() - at.x(), g.at.y() - at.y()) < 3;
    });
    if (same != groups.end()) same->names += m.label;
    else groups.push_back({at, {m.label}, &m});
  }
  std::vector<QGraphicsSimpleTextItem*> items;
  std::vector<LabelRequest> requests;
  for (const Group& g : groups) {
    const QRectF& bounds = g.first->reached ? times : band.area;
    auto* item = new QGraphicsSimpleTextItem(g.names.join(", "), chart);
    if (item->boundingRect().width() + 4 > bounds.width()) item->setText(g.names.join('\n'));
    item->setBrush(QColor(51, 51, 51));
    item->setZValue(kLabelZ);
    items.push_back(item);
    requests.push_back({g.at, item->boundingRect().size() + QSizeF(4, 2), bounds});
  }
  const std::vector<QRectF> boxes = placeLabels(requests, obstacles);
  for (std::size_t i = 0; i < groups.size(); ++i) {
    items[i]->setPos(boxes[i].center() - items[i]->boundingRect().center());
    drawLeader(chart, groups[i].at, boxes[i], groups[i].first->series->color());
  }
}

}  // namespace

std::unique_ptr<QChartView> lineChartView(const QString& title, const QString& xTitle, const QString& yTitle,
                                          const std::vector<ChartLine>& lines, bool logX) {
  QChart* chart = newChart(title);
  const double inf = std::numeric_limits<double>::infinity();
  double xlo = inf, xhi = -inf, ylo = inf, yhi = -inf;
  std::vector<QLineSeries*> series;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const ChartLine& line = lines[i];
    auto* s = new QLineSeries;
    s->setName(line.name);
    // Denoised variants dashed, so a method and its denoised twin read as a pair.
    QPen pen(seriesColor(i), 2, line.name.contains("denoise") ? Qt::DashLine : Qt::SolidLine);
    s->setPen(pen);
    for (const QPointF& p : line.points) {
      if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || (logX && p.x() <= 0)) continue;
      s->append(logX ? std::log10(p.x()) : p.x(), p.y());
      xlo = std::min(xlo, p.x()), xhi = std::max(xhi, p.x());
      ylo = std::min(ylo, p.y()), yhi = std::max(yhi, p.y());
    }
    chart->addSeries(s);
    series.push_back(s);
  }
  QCategoryAxis* x = timeAxis(xlo, xhi, logX);
  auto* y = new QValueAxis;
  x->setTitleText(xTitle);
  y->setTitleText(yTitle);
  chart->addAxis(x, Qt::AlignBottom);
  chart->addAxis(y, Qt::AlignLeft);
  for (QLineSeries* s : series) s->attachAxis(x), s->attachAxis(y);
  fitAxis(y, ylo, yhi);
  return laidOut(chart);
}

std::vector<QRectF> placeLabels(const std::vector<LabelRequest>& labels, const std::vector<QRectF>& obstacles) {
  std::vector<QRectF> placed;
  for (const LabelRequest& label : labels) {
    QRectF best;
    double bestCost = std::numeric_limits<double>::infinity();
    for (const QRectF& spot : labelSpots(label)) {
      const double cost = overlap(spot, label.bounds, placed, obstacles);
      if (cost < bestCost) best = spot, bestCost = cost;
      if (cost <= 0) break;
    }
    placed.push_back(best);
  }
  return placed;
}

std::unique_ptr<QChartView> pointChartView(const QString& title, const QString& xTitle, const QString& yTitle,
                                           const std::vector<ChartPoint>& points) {
  QChart* chart = newChart(title);
  const TimeScale scale = timeScale(points);
  QCategoryAxis* x = tickedAxis(0, scale.axisEnd, scale.ticks, false);
  auto* y = new QValueAxis;
  x->setTitleText(xTitle);
  y->setTitleText(yTitle);
  chart->addAxis(x, Qt::AlignBottom);
  chart->addAxis(y, Qt::AlignLeft);
  const double inf = std::numeric_limits<double>::infinity();
  double ylo = inf, yhi = -inf;
  std::vector<Marker> markers;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const ChartPoint& p = points[i];
    const double at = p.reached ? p.at.x() : scale.bandCentre();
    if (!std::isfinite(at) || !std::isfinite(p.at.y())) continue;
    QScatterSeries* s = markerSeries(p, seriesColor(i));
    s->append(at, p.at.y());
    chart->addSeries(s);
    s->attachAxis(x);
    s->attachAxis(y);
    markers.push_back({s, p.label, p.reached});
    ylo = std::min(ylo, p.at.y()), yhi = std::max(yhi, p.at.y());
  }
  fitAxis(y, ylo, yhi);
  auto view = laidOut(chart);
  if (markers.empty()) return view;
  Band band;
  if (scale.band) band = drawBand(chart, markers[0].series, scale);
  labelMarkers(chart, markers, band);
  return view;
}

Result<bool> writeLineChart(const std::filesystem::path& base, const QString& title, const QString& xTitle, const QString& yTitle,
                            const std::vector<ChartLine>& lines, bool logX) {
  return writeChart(*lineChartView(title, xTitle, yTitle, lines, logX), base);
}

Result<bool> writePointChart(const std::filesystem::path& base, const QString& title, const QString& xTitle, const QString& yTitle,
                             const std::vector<ChartPoint>& points) {
  return writeChart(*pointChartView(title, xTitle, yTitle, points), base);
}

QImage frameWithOverlays(const FrameRecord& frame, int scale) {
  if (!frame.image) return {};
  FrameView view;
  OverlaySettings o;
  o.legend = false;
  view.setOverlays(o);
  view.resize(frame.width * scale, frame.height * scale);
  view.showFrame(std::make_shared<const FrameRecord>(frame));
  return view.composed();
}

Result<bool> writeStrip(const std::filesystem::path& file, const std::vector<QString>& captions, const std::vector<StripRow>& rows) {
  int cellW = 0, cellH = 0;
  for (const StripRow& r : rows)
    for (const QImage& c : r.cells) cellW = std::max(cellW, c.width()), cellH = std::max(cellH, c.height());
  if (rows.empty() || cellW == 0) return Result<bool>::failure(cat(file.string(), ": no frames to show"));
  const int labelW = 170, captionH = 24, gap = 4;
  const int cols = static_cast<int>(captions.size());
  QImage strip(labelW + cols * (cellW + gap), captionH + static_cast<int>(rows.size()) * (cellH + gap), QImage::Format_RGB32);
  strip.fill(QColor(24, 24, 28));
  QPainter p(&strip);
  p.setPen(Qt::white);
  for (int c = 0; c < cols; ++c)
    p.drawText(QRect(labelW + c * (cellW + gap), 0, cellW, captionH), Qt::AlignCenter, captions[static_cast<std::size_t>(c)]);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const int y = captionH + static_cast<int>(r) * (cellH + gap);
    p.drawText(QRect(6, y, labelW - 12, cellH), Qt::AlignVCenter | Qt::AlignLeft | Qt::TextWordWrap, rows[r].label);
    for (std::size_t c = 0; c < rows[r].cells.size() && static_cast<int>(c) < cols; ++c)
      p.drawImage(QPoint(labelW + static_cast<int>(c) * (cellW + gap), y), rows[r].cells[c]);
  }
  p.end();
  const QString tmp = QString::fromStdString(file.string() + ".tmp.png");
  if (!strip.save(tmp, "PNG")) return Result<bool>::failure(cat("cannot write ", file.string()));
  QFile::remove(QString::fromStdString(file.string()));
  if (!QFile::rename(tmp, QString::fromStdString(file.string()))) return Result<bool>::failure(cat("cannot write ", file.string()));
  return true;
}

}  // namespace retile::ui
