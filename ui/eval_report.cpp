#include "eval_report.h"

#include <QChart>
#include <QChartView>
#include <QCoreApplication>
#include <QFile>
#include <QFont>
#include <QLineSeries>
#include <QLogValueAxis>
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
  static const QRgb colors[] = {0x4e79a7, 0xf28e2b, 0xe15759, 0x76b7b2, 0x59a14f,
                                0xedc948, 0xb07aa1, 0xff9da7, 0x9c755f, 0xbab0ac};
  return QColor::fromRgb(colors[i % 10]);
}

// Axis range over the finite points, padded so no point sits on the frame.
void fitAxis(QAbstractAxis* axis, double lo, double hi, bool log) {
  if (!(lo <= hi)) lo = 0, hi = 1;
  if (log) {
    lo = std::max(lo, 1e-3);
    static_cast<QLogValueAxis*>(axis)->setRange(lo / 1.3, std::max(hi, lo) * 1.3);
    return;
  }
  double pad = (hi - lo) * 0.05;
  if (pad <= 0) pad = std::max(std::abs(hi) * 0.05, 0.5);
  auto* v = static_cast<QValueAxis*>(axis);
  v->setRange(lo - pad, hi + pad);
  v->applyNiceNumbers();
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

}  // namespace

std::unique_ptr<QChartView> lineChartView(const QString& title, const QString& xTitle, const QString& yTitle,
                                          const std::vector<ChartLine>& lines, bool logX) {
  QChart* chart = newChart(title);
  QAbstractAxis* x = logX ? static_cast<QAbstractAxis*>(new QLogValueAxis) : new QValueAxis;
  auto* y = new QValueAxis;
  x->setTitleText(xTitle);
  y->setTitleText(yTitle);
  if (logX) static_cast<QLogValueAxis*>(x)->setLabelFormat("%g");
  chart->addAxis(x, Qt::AlignBottom);
  chart->addAxis(y, Qt::AlignLeft);
  const double inf = std::numeric_limits<double>::infinity();
  double xlo = inf, xhi = -inf, ylo = inf, yhi = -inf;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const ChartLine& line = lines[i];
    auto* s = new QLineSeries;
    s->setName(line.name);
    // Denoised variants dashed, so a method and its denoised twin read as a pair.
    QPen pen(seriesColor(i), 2, line.name.contains("denoise") ? Qt::DashLine : Qt::SolidLine);
    s->setPen(pen);
    for (const QPointF& p : line.points) {
      if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || (logX && p.x() <= 0)) continue;
      s->append(p);
      xlo = std::min(xlo, p.x()), xhi = std::max(xhi, p.x());
      ylo = std::min(ylo, p.y()), yhi = std::max(yhi, p.y());
    }
    chart->addSeries(s);
    s->attachAxis(x);
    s->attachAxis(y);
  }
  fitAxis(x, xlo, xhi, logX);
  fitAxis(y, ylo, yhi, false);
  return laidOut(chart);
}

std::unique_ptr<QChartView> pointChartView(const QString& title, const QString& xTitle, const QString& yTitle,
                                           const std::vector<ChartPoint>& points) {
  QChart* chart = newChart(title);
  auto* x = new QValueAxis;
  auto* y = new QValueAxis;
  x->setTitleText(xTitle);
  y->setTitleText(yTitle);
  chart->addAxis(x, Qt::AlignBottom);
  chart->addAxis(y, Qt::AlignLeft);
  const double inf = std::numeric_limits<double>::infinity();
  double xlo = inf, xhi = -inf, ylo = inf, yhi = -inf;
  for (const ChartPoint& p : points)
    if (std::isfinite(p.at.x()) && std::isfinite(p.at.y()))
      xlo = std::min(xlo, p.at.x()), xhi = std::max(xhi, p.at.x()), ylo = std::min(ylo, p.at.y()), yhi = std::max(yhi, p.at.y());
  // A point whose label would fall on an earlier one's (within 4 % of the y span, 20 % of the x
  // span: labels are a line high but wide) shares that label ("spiral, change"): labels drawn on
  // top of each other could not be read. The legend lists every point anyway.
  const double spanX = std::max(xhi - std::min(xlo, 0.0), 1e-9), spanY = std::max(yhi - ylo, 1e-9);
  std::vector<QString> labels(points.size());
  std::vector<int> labelOwner(points.size(), -1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    labelOwner[i] = static_cast<int>(i);
    for (std::size_t j = 0; j < i; ++j)
      if (labelOwner[j] == static_cast<int>(j) && std::abs(points[i].at.x() - points[j].at.x()) < 0.2 * spanX &&
          std::abs(points[i].at.y() - points[j].at.y()) < 0.04 * spanY) {
        labelOwner[i] = static_cast<int>(j);
        break;
      }
    auto owner = static_cast<std::size_t>(labelOwner[i]);
    labels[owner] = labels[owner].isEmpty() ? points[i].label : labels[owner] + ", " + points[i].label;
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const ChartPoint& p = points[i];
    if (!std::isfinite(p.at.x()) || !std::isfinite(p.at.y())) continue;
    auto* s = new QScatterSeries;
    s->setColor(seriesColor(i));
    if (!p.reached) {  // an empty square: a bound, not a measurement
      s->setMarkerShape(QScatterSeries::MarkerShapeRectangle);
      s->setBrush(Qt::NoBrush);
      s->setPen(QPen(seriesColor(i), 2));
    }
    s->setName(p.legend.isEmpty() ? p.label : p.legend);
    s->setMarkerSize(11);
    s->append(p.at);
    s->setPointLabelsVisible(labelOwner[i] == static_cast<int>(i));
    s->setPointLabelsFormat(labels[i]);
    s->setPointLabelsClipping(false);
    chart->addSeries(s);
    s->attachAxis(x);
    s->attachAxis(y);
  }
  fitAxis(x, std::min(xlo, 0.0), xhi, false);
  static_cast<QValueAxis*>(x)->setMin(0);  // times are never negative
  fitAxis(y, ylo, yhi, false);
  return laidOut(chart);
}

Result<bool> writeLineChart(const std::filesystem::path& base, const QString& title, const QString& xTitle,
                            const QString& yTitle, const std::vector<ChartLine>& lines, bool logX) {
  return writeChart(*lineChartView(title, xTitle, yTitle, lines, logX), base);
}

Result<bool> writePointChart(const std::filesystem::path& base, const QString& title, const QString& xTitle,
                             const QString& yTitle, const std::vector<ChartPoint>& points) {
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

Result<bool> writeStrip(const std::filesystem::path& file, const std::vector<QString>& captions,
                        const std::vector<StripRow>& rows) {
  int cellW = 0, cellH = 0;
  for (const StripRow& r : rows)
    for (const QImage& c : r.cells) cellW = std::max(cellW, c.width()), cellH = std::max(cellH, c.height());
  if (rows.empty() || cellW == 0) return Result<bool>::failure(cat(file.string(), ": no frames to show"));
  const int labelW = 170, captionH = 24, gap = 4;
  const int cols = static_cast<int>(captions.size());
  QImage strip(labelW + cols * (cellW + gap), captionH + static_cast<int>(rows.size()) * (cellH + gap),
               QImage::Format_RGB32);
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
