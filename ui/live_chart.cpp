#include "live_chart.h"

#include <QChart>
#include <QGraphicsLayout>
#include <QChartView>
#include <QDateTime>
#include <QLabel>
#include <QLineSeries>
#include <QPushButton>
#include <QSpinBox>
#include <QValueAxis>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

#include "retile/render.h"
#include "retile/scenario.h"

namespace retile::ui {

namespace {

constexpr double kWindowSeconds = 60.0;

// The bottom dock is wide and short: no chart titles or axis titles (the legend says what each
// line is), small labels and few ticks, so the plot gets the height and no label is cut to "...".
QChartView* makeView(QChart* chart, QWidget* parent) {
  chart->setMargins(QMargins(0, 0, 0, 0));
  chart->layout()->setContentsMargins(0, 0, 0, 0);
  chart->legend()->setAlignment(Qt::AlignTop);
  QFont small = chart->legend()->font();
  small.setPointSizeF(std::max(7.0, small.pointSizeF() - 1));
  chart->legend()->setFont(small);
  chart->setBackgroundRoundness(0);
  for (QAbstractAxis* axis : chart->axes()) {
    axis->setLabelsFont(small);
    if (auto* value = qobject_cast<QValueAxis*>(axis)) value->setTickCount(4);
  }
  auto* v = new QChartView(chart, parent);
  v->setRenderHint(QPainter::Antialiasing);
  v->setMinimumHeight(150);
  return v;
}

// `skip`: points the axis is not fitted to (they run off the top).
void fitY(QLineSeries* s, QValueAxis* axis, double floor, const std::deque<bool>& skip = {}) {
  double hi = floor;
  const QList<QPointF> points = s->points();
  for (qsizetype i = 0; i < points.size(); ++i)
    if (static_cast<std::size_t>(i) >= skip.size() || !skip[static_cast<std::size_t>(i)]) hi = std::max(hi, points[i].y());
  axis->setRange(0, hi * 1.15);
}

}  // namespace

LiveChart::LiveChart(QWidget* parent) : QWidget(parent) {
  start_ = QDateTime::currentMSecsSinceEpoch();
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(2, 2, 2, 2);

  auto* chart = new QChart;
  samplesPerSecond_ = new QLineSeries(chart);
  samplesPerSecond_->setName(tr("M samples/s (left)"));
  frameMs_ = new QLineSeries(chart);
  frameMs_->setName(tr("frame ms (right), last minute"));
  chart->addSeries(samplesPerSecond_);
  chart->addSeries(frameMs_);
  timeAxis_ = new QValueAxis(chart);
  timeAxis_->setLabelFormat("%.0f s");
  timeAxis_->setRange(0, kWindowSeconds);
  rateAxis_ = new QValueAxis(chart);
  msAxis_ = new QValueAxis(chart);
  chart->addAxis(timeAxis_, Qt::AlignBottom);
  chart->addAxis(rateAxis_, Qt::AlignLeft);
  chart->addAxis(msAxis_, Qt::AlignRight);
  samplesPerSecond_->attachAxis(timeAxis_);
  samplesPerSecond_->attachAxis(rateAxis_);
  frameMs_->attachAxis(timeAxis_);
  frameMs_->attachAxis(msAxis_);
  // Side by side: the bottom dock is wide and short.
  auto* charts = new QHBoxLayout;
  layout->addLayout(charts, 1);

  auto* errChart = new QChart;
  error_ = new QLineSeries(errChart);
  error_->setName(tr("relative RMSE against the reference (4x4 blocks)"));
  errChart->addSeries(error_);
  errTimeAxis_ = new QValueAxis(errChart);
  errTimeAxis_->setRange(0, kWindowSeconds);
  errTimeAxis_->setLabelFormat("%.0f s");
  errAxis_ = new QValueAxis(errChart);
  errAxis_->setLabelFormat("%.3f");
  errChart->addAxis(errTimeAxis_, Qt::AlignBottom);
  errChart->addAxis(errAxis_, Qt::AlignLeft);
  error_->attachAxis(errTimeAxis_);
  error_->attachAxis(errAxis_);
  charts->addWidget(makeView(chart, this), 1);
  charts->addWidget(makeView(errChart, this), 1);
  charts_ = {chart, errChart};

  auto* row = new QHBoxLayout;
  referenceButton_ = new QPushButton(tr("Render reference"), this);
  referenceButton_->setObjectName("renderReference");
  referenceButton_->setToolTip(
      tr("Renders the current scene state at the viewport's size in the background; the error "
         "chart then follows the viewport against it until the next edit."));
  status_ = new QLabel(tr("No reference yet."), this);
  status_->setWordWrap(true);
  row->addWidget(referenceButton_);
  row->addWidget(status_, 1);
  layout->addLayout(row);
  connect(referenceButton_, &QPushButton::clicked, this, &LiveChart::referenceRequested);
}

LiveChart::~LiveChart() {
  if (cancel_) *cancel_ = true;
  if (worker_.joinable()) worker_.join();
}

void LiveChart::reset() {
  if (cancel_) *cancel_ = true;
  if (worker_.joinable()) worker_.join();  // cancelled: it stops at its next frame
  reference_.clear();
  refVersion_ = 0;
  lastError_ = -1;
  error_->clear();
  referenceButton_->setEnabled(true);
  status_->setText(tr("No reference yet."));
}

int LiveChart::errorPoints() const { return static_cast<int>(error_->count()); }
int LiveChart::throughputPoints() const { return static_cast<int>(samplesPerSecond_->count()); }

void LiveChart::trim(double now) {
  for (QLineSeries* s : {samplesPerSecond_, frameMs_, error_}) {
    int drop = 0;
    while (drop < s->count() && s->at(drop).x() < now - kWindowSeconds) ++drop;
    if (drop > 0) s->removePoints(0, drop);
    if (s == frameMs_) msCompiled_.erase(msCompiled_.begin(), msCompiled_.begin() + drop);
  }
  // Seconds since the editor opened; in the first minute the window starts at 0 and fills, so
  // that no time before the editor opened is shown.
  const double from = std::max(0.0, now - kWindowSeconds);
  timeAxis_->setRange(from, from + kWindowSeconds);
  errTimeAxis_->setRange(from, from + kWindowSeconds);
}

void LiveChart::addFrame(const FrameRecord& frame) {
  const double now = (QDateTime::currentMSecsSinceEpoch() - start_) / 1000.0;
  if (frame.frameMs > 0 && frame.samples > 0) {
    samplesPerSecond_->append(now, static_cast<double>(frame.samples) / (frame.frameMs * 1000.0));
    frameMs_->append(now, frame.frameMs);
    msCompiled_.push_back(frame.compiledKernel);
  }
  if (!reference_.empty() && frame.image && frame.documentVersion == refVersion_ && frame.width == refWidth_ &&
      frame.height == refHeight_) {
    lastError_ = relativeRmse(frame.image->shown(), reference_, refWidth_, refHeight_, 4);
    if (std::isfinite(lastError_)) error_->append(now, lastError_);
    status_->setText(tr("Reference of version %1: relative RMSE %2").arg(refVersion_).arg(lastError_, 0, 'f', 4));
  } else if (!reference_.empty() && frame.documentVersion != refVersion_) {
    status_->setText(
        tr("The scene changed since the reference (version %1, now %2): render a new one.").arg(refVersion_).arg(frame.documentVersion));
  }
  trim(now);
  fitY(samplesPerSecond_, rateAxis_, 0.01);
  // A frame that compiled a kernel (about a second on lavapipe) would flatten the minute's
  // frame times to the axis's floor.
  fitY(frameMs_, msAxis_, 1.0, msCompiled_);
  fitY(error_, errAxis_, 0.01);
}

void LiveChart::renderReference(const Scene& scene, std::uint64_t documentVersion, int spp) {
  if (cancel_) *cancel_ = true;
  if (worker_.joinable()) worker_.join();
  cancel_ = std::make_shared<std::atomic<bool>>(false);
  referenceButton_->setEnabled(false);
  status_->setText(tr("Rendering a %1 spp reference of version %2...").arg(spp).arg(documentVersion));
  auto cancel = cancel_;
  // The thread owns its copy of the scene and its own renderer; it touches this widget only
  // through queued calls, which Qt drops if the widget is gone.
  worker_ = std::thread([this, scene, documentVersion, spp, cancel] {
    std::vector<float> color;
    QString failure;
    int w = scene.settings.width, h = scene.settings.height;
    try {
      Renderer r;
      r.setScene(scene);
      RenderRequest req;
      req.width = w;
      req.height = h;
      req.samplesPerPixel = spp;
      req.seed = 0x7e5e;
      RenderImage img = r.render(req, [&](int, int) { return !*cancel; });
      color = std::move(img.color);
    } catch (const std::exception& e) {
      failure = QString::fromUtf8(e.what());
    }
    if (*cancel) return;
    QMetaObject::invokeMethod(
        this,
        [this, color = std::move(color), failure, w, h, documentVersion, cancel]() mutable {
          if (*cancel) return;  // reset() or a newer request came after the render ended
          referenceButton_->setEnabled(true);
          if (!failure.isEmpty()) {
            status_->setText(tr("Reference failed: %1").arg(failure));
            return;
          }
          reference_ = std::move(color);
          refWidth_ = w;
          refHeight_ = h;
          refVersion_ = documentVersion;
          error_->clear();
          status_->setText(tr("Reference of version %1 ready.").arg(documentVersion));
          emit referenceReady();
        },
        Qt::QueuedConnection);
  });
}

}  // namespace retile::ui
