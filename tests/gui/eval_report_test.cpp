// The charts of `retile eval`'s report as a reader meets them (issue 60, point 15): each test
// failed on the charts before their fix.
#include <QCategoryAxis>
#include <QChart>
#include <QGraphicsScene>
#include <QGraphicsSimpleTextItem>
#include <QLogValueAxis>
#include <QRegularExpression>
#include <QScatterSeries>
#include <QValueAxis>
#include <QXYSeries>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "eval_report.h"

namespace retile::ui {
namespace {

// The texts drawn on a chart besides Qt Charts' own (which are QGraphicsTextItems): the points'
// labels and whatever names a region of the plot.
std::vector<QGraphicsSimpleTextItem*> plotTexts(QChartView& view) {
  std::vector<QGraphicsSimpleTextItem*> out;
  for (QGraphicsItem* item : view.scene()->items())
    if (auto* text = qgraphicsitem_cast<QGraphicsSimpleTextItem*>(item); text && text->isVisible()) out.push_back(text);
  return out;
}

struct Tick {
  double at;  // in the axis's units
  QString text;
};

// The ticks an axis writes a label under, whatever kind of axis it is.
std::vector<Tick> labelledTicks(QAbstractAxis* axis) {
  std::vector<Tick> out;
  if (auto* c = qobject_cast<QCategoryAxis*>(axis)) {
    for (const QString& label : c->categoriesLabels())
      if (c->endValue(label) >= c->min() && c->endValue(label) <= c->max()) out.push_back({c->endValue(label), label});
  } else if (auto* l = qobject_cast<QLogValueAxis*>(axis)) {
    const double first = std::ceil(std::log(l->min()) / std::log(l->base()) - 1e-9);
    for (double v = std::pow(l->base(), first); v <= l->max(); v *= l->base())
      out.push_back({v, QString::number(v)});  // the report's format is %g
  } else if (auto* v = qobject_cast<QValueAxis*>(axis)) {
    for (int i = 0; i < v->tickCount(); ++i) {
      const double at = v->min() + (v->max() - v->min()) * i / std::max(v->tickCount() - 1, 1);
      out.push_back({at, QString::number(at)});
    }
  }
  return out;
}

std::optional<double> number(const QString& text) {
  bool ok = false;
  const double v = text.toDouble(&ok);
  return ok ? std::optional<double>(v) : std::nullopt;
}

QScatterSeries* seriesNamed(QChart* chart, const QString& prefix) {
  for (QAbstractSeries* s : chart->series())
    if (auto* scatter = qobject_cast<QScatterSeries*>(s); scatter && scatter->name().startsWith(prefix)) return scatter;
  return nullptr;
}

QPointF markerAt(QChart* chart, QScatterSeries* s) { return chart->mapToPosition(s->at(0), s); }

ChartPoint point(const QString& method, double ms, double psnr, bool reached = true) {
  ChartPoint p;
  p.label = method;
  p.at = QPointF(ms, psnr);
  p.reached = reached;
  return p;
}

// `retile eval --quick`'s drag scenario on the built-in scene (2026-12): five methods within
// 80 ms and 0.1 dB of each other, two of them the same point, four never reaching the target.
std::vector<ChartPoint> dragTradeoff() {
  return {point("global", 960, 15.44, false),      point("spiral", 1070, 23.20),        point("focus", 990, 23.19, false),
          point("indirection", 990, 18.40, false), point("change", 1070, 23.20),        point("spiral+smooth", 994, 23.20),
          point("global+denoise", 903, 20.68),     point("spiral+denoise", 900, 26.94), point("spiral+reuse", 1050, 23.27, false)};
}

// The labels of "spiral, focus, spiral+reuse" were drawn over those of "change, spiral+smooth".
TEST(EvalReport, LabelsOfNearbyPointsDoNotOverlapEachOtherOrThePoints) {
  const std::vector<ChartPoint> points = dragTradeoff();
  auto view = pointChartView("drag", "time (ms)", "PSNR (dB)", points);
  QChart* chart = view->chart();
  std::vector<QRectF> markers;
  for (QAbstractSeries* s : chart->series())
    if (auto* scatter = qobject_cast<QScatterSeries*>(s))
      markers.push_back(QRectF(markerAt(chart, scatter) - QPointF(5, 5), QSizeF(10, 10)));
  std::vector<QRectF> boxes;
  QStringList named;
  for (QGraphicsSimpleTextItem* t : plotTexts(*view)) {
    boxes.push_back(t->sceneBoundingRect());
    named += t->text().split(QRegularExpression(", |\n"));  // names that share a label
  }
  for (const ChartPoint& p : points) EXPECT_TRUE(named.contains(p.label)) << p.label.toStdString() << " is labelled on the plot";
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    for (std::size_t j = i + 1; j < boxes.size(); ++j) EXPECT_FALSE(boxes[i].intersects(boxes[j])) << i << " and " << j;
    for (const QRectF& m : markers) EXPECT_FALSE(boxes[i].intersects(m)) << "label " << i << " covers a point";
    EXPECT_TRUE(chart->plotArea().contains(boxes[i])) << "label " << i << " stays on the plot";
  }
}

TEST(EvalReport, PlacedLabelsAroundAClusterStayApartAndWithinBounds) {
  const QRectF bounds(0, 0, 600, 400);
  std::vector<LabelRequest> labels;
  std::vector<QRectF> markers;
  for (QPointF at : {QPointF(300, 200), QPointF(302, 201), QPointF(305, 199), QPointF(310, 200), QPointF(296, 203), QPointF(300, 215),
                     QPointF(590, 5)}) {
    labels.push_back({at, QSizeF(90, 16), bounds});
    markers.push_back(QRectF(at - QPointF(5, 5), QSizeF(10, 10)));
  }
  const std::vector<QRectF> boxes = placeLabels(labels, markers);
  ASSERT_EQ(boxes.size(), labels.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    EXPECT_TRUE(bounds.contains(boxes[i])) << i;
    for (std::size_t j = i + 1; j < boxes.size(); ++j) EXPECT_FALSE(boxes[i].intersects(boxes[j])) << i << " and " << j;
    for (const QRectF& m : markers) EXPECT_FALSE(boxes[i].intersects(m)) << i;
  }
  EXPECT_EQ(placeLabels(labels, markers), boxes) << "the same layout every time";
}

// Never-reached methods were drawn at the run's length, on the time axis, as hollow squares that
// all looked alike: read as a time measured.
TEST(EvalReport, ANotReachedPointLiesBeyondTheTimesAndSaysNotReached) {
  auto view =
      pointChartView("t", "time (ms)", "PSNR (dB)", {point("fast", 100, 20), point("slow", 200, 22), point("never", 250, 18, false)});
  QChart* chart = view->chart();
  QScatterSeries* never = seriesNamed(chart, "never");
  QScatterSeries* slow = seriesNamed(chart, "slow");
  ASSERT_TRUE(never && slow);
  const QPointF at = markerAt(chart, never);
  EXPECT_GT(at.x(), markerAt(chart, slow).x() + 20) << "beyond every time reached";
  QAbstractAxis* x = chart->axes(Qt::Horizontal).at(0);
  bool said = false;
  for (const Tick& t : labelledTicks(x)) {
    const double px = chart->mapToPosition(QPointF(t.at, 0), never).x();
    if (number(t.text)) {
      EXPECT_LT(px, at.x() - 20) << "the time " << t.text.toStdString() << " is not under the point";
    }
    said |= t.text.contains("not reached") && std::abs(px - at.x()) < 6;
  }
  for (QGraphicsSimpleTextItem* t : plotTexts(*view)) {
    const QRectF box = t->sceneBoundingRect();
    said |= t->text().contains("not reached") && box.left() <= at.x() && box.right() >= at.x();
  }
  EXPECT_TRUE(said) << "the words \"not reached\" stand over or under the point";
}

// The PSNR-against-time charts labelled one tick ("1000") on their log time axis.
TEST(EvalReport, ALogTimeAxisLabelsSeveralTicksAcrossTheData) {
  for (auto [lo, hi] :
       {std::pair{30.0, 3000.0}, std::pair{300.0, 1300.0}, std::pair{660.0, 1700.0}, std::pair{900.0, 1100.0}, std::pair{0.5, 2e5}}) {
    SCOPED_TRACE(testing::Message() << lo << " to " << hi << " ms");
    ChartLine line{"spiral", {}};
    for (int i = 0; i <= 20; ++i) line.points.emplace_back(lo * std::pow(hi / lo, i / 20.0), 20 + i * 0.5);
    auto view = lineChartView("t", "time (ms)", "PSNR (dB)", {line}, true);
    QChart* chart = view->chart();
    auto* series = qobject_cast<QXYSeries*>(chart->series().at(0));
    ASSERT_TRUE(series);
    const double left = chart->mapToPosition(series->at(0), series).x();
    const double right = chart->mapToPosition(series->at(series->count() - 1), series).x();
    std::vector<double> labelled{left, right};
    int within = 0;
    for (const Tick& t : labelledTicks(chart->axes(Qt::Horizontal).at(0))) {
      const std::optional<double> ms = number(t.text);
      ASSERT_TRUE(ms) << t.text.toStdString();
      within += *ms >= lo && *ms <= hi;
      // A label tells the truth: the line's points before its time are drawn left of it.
      const double px = chart->mapToPosition(QPointF(t.at, 0), series).x();
      if (px > left && px < right) labelled.push_back(px);
      for (int i = 0; i < series->count(); ++i)
        if (const double pointMs = line.points[static_cast<std::size_t>(i)].x(); std::abs(pointMs - *ms) > 1e-6 * *ms) {
          EXPECT_EQ(pointMs < *ms, chart->mapToPosition(series->at(i), series).x() < px)
              << "point " << i << " against the tick " << t.text.toStdString();
        }
    }
    EXPECT_GE(within, 3);
    EXPECT_LE(within, 12) << "not so many that they crowd";
    std::sort(labelled.begin(), labelled.end());
    for (std::size_t i = 1; i < labelled.size(); ++i)
      EXPECT_LT(labelled[i] - labelled[i - 1], 0.4 * (right - left)) << "no long stretch of the data without a label";
  }
}

}  // namespace
}  // namespace retile::ui
