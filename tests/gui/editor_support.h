// Shared by the editor's test suites (offscreen and under Xvfb): a window on the built-in scene at
// a small fixed render size, and waiting for the frame record to reach a state.
#pragma once

#include <QTest>

#include <functional>
#include <memory>
#include <numeric>
#include <string>

#include "frame_view.h"
#include "main_window.h"
#include "test_support.h"

namespace retile::ui::test {

inline std::unique_ptr<MainWindow> makeWindow() {
  EditorOptions o;
  o.initialRenderSize = QSize(96, 54);
  auto w = std::make_unique<MainWindow>(makeDefaultScene(), std::filesystem::path(), o);
  w->resize(1000, 700);
  w->show();
  return w;
}

// Spins the event loop until the newest frame the viewport shows satisfies `pred`.
inline bool waitForFrame(MainWindow& w, const std::function<bool(const FrameRecord&)>& pred, int ms = 60000) {
  return QTest::qWaitFor([&] { return w.viewport()->frame() && pred(*w.viewport()->frame()); }, ms);
}

using retile::test::objectNamed;

// Selects the object named `name`, which shows it and its material in the properties panel, and
// returns the material.
inline NodeId selectWithMaterial(MainWindow& w, const std::string& name) {
  const NodeId object = objectNamed(w.scene(), name);
  w.select(object);
  return w.scene().object(object)->material;
}

// The mean of a frame's samples per tile.
inline double meanSamples(const FrameRecord& f) {
  if (f.tileSamples.empty()) return 0.0;
  return std::accumulate(f.tileSamples.begin(), f.tileSamples.end(), 0.0) / static_cast<double>(f.tileSamples.size());
}

// A widget point over a pixel of the viewport's newest frame that shows `object`; (-1, -1) if none.
inline QPoint pointShowing(const FrameView& v, NodeId object) {
  auto frame = v.frame();
  QRectF r = v.imageRect();
  for (int y = 0; y < frame->height; ++y)
    for (int x = 0; x < frame->width; ++x)
      if (frame->image->objectId[static_cast<std::size_t>(y * frame->width + x)] == object)
        return QPoint(static_cast<int>(r.x() + (x + 0.5) * r.width() / frame->width),
                      static_cast<int>(r.y() + (y + 0.5) * r.height() / frame->height));
  return QPoint(-1, -1);
}

}  // namespace retile::ui::test
