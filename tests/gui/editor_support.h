// Shared by the editor's test suites (offscreen and under Xvfb): a window on the built-in scene at
// a small fixed render size, and waiting for the frame record to reach a state.
#pragma once

#include <QTest>

#include <functional>
#include <memory>

#include "main_window.h"

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

}  // namespace retile::ui::test
