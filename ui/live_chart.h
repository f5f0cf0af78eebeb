// The live chart dock: samples per second and frame time over the last minute, and, once a
// reference of the current scene state has been rendered (on demand, off the GUI thread), the
// viewport's error against it over time.
//
// Ownership and threads: GUI thread only, except the reference render, which runs on a thread
// this widget owns and joins (it is cancelled when the widget goes away or a new one starts).
// Its result comes back to the GUI thread as a queued call.
#pragma once

#include <QWidget>

#include <atomic>
#include <deque>
#include <memory>
#include <thread>
#include <vector>

#include "retile/session.h"

class QChart;
class QChartView;
class QLineSeries;
class QValueAxis;
class QLabel;
class QPushButton;

namespace retile::ui {

class LiveChart : public QWidget {
  Q_OBJECT
 public:
  explicit LiveChart(QWidget* parent = nullptr);
  ~LiveChart() override;

  // Adds a published frame. The error series grows only while the frame shows the document
  // version the reference was rendered from.
  void addFrame(const FrameRecord& frame);
  // Renders a reference of `scene` (at its settings' size) with `spp` samples per pixel.
  void renderReference(const Scene& scene, std::uint64_t documentVersion, int spp);
  bool hasReference() const { return !reference_.empty(); }
  // Forgets the reference and its error (another scene was opened); a render under way is cancelled.
  void reset();
  double lastError() const { return lastError_; }
  int errorPoints() const;
  int throughputPoints() const;
  // The two charts (throughput, error), for their layout.
  const std::vector<QChart*>& charts() const { return charts_; }

 signals:
  void referenceRequested();  // the button: the owner calls renderReference with its document
  void referenceReady();

 private:
  void trim(double now);

  QLineSeries* samplesPerSecond_ = nullptr;
  QLineSeries* frameMs_ = nullptr;
  std::deque<bool> msCompiled_;  // per frameMs_ point: its frame compiled a kernel
  QLineSeries* error_ = nullptr;
  QValueAxis* timeAxis_ = nullptr;
  QValueAxis* rateAxis_ = nullptr;
  QValueAxis* msAxis_ = nullptr;
  QValueAxis* errTimeAxis_ = nullptr;
  QValueAxis* errAxis_ = nullptr;
  std::vector<QChart*> charts_;
  QLabel* status_ = nullptr;
  QPushButton* referenceButton_ = nullptr;
  qint64 start_ = 0;
  std::vector<float> reference_;
  int refWidth_ = 0, refHeight_ = 0;
  std::uint64_t refVersion_ = 0;
  double lastError_ = -1;
  std::thread worker_;
  std::shared_ptr<std::atomic<bool>> cancel_;
};

}  // namespace retile::ui
