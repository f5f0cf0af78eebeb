// The real viewport under an X server (xvfb-run): the editor presents through a QVulkanWindow on
// lavapipe, what the window shows is the frame FrameView composed (grabbed from the swapchain and
// compared), and input on the Vulkan window reaches the viewport (a click picks an object).
#include <QApplication>
#include <QKeyEvent>
#include <QLineEdit>
#include <QMenu>
#include <QMenuBar>
#include <QPixmap>
#include <QPointer>
#include <QScreen>
#include <QStandardPaths>
#include <QTemporaryDir>
#include <QTest>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "editor_support.h"
#include "main_window.h"
#include "vulkan_viewport.h"

namespace retile::ui {
namespace {

using test::makeWindow;
using test::waitForFrame;

TEST(VulkanViewport, ShowsTheComposedFrame) {
  auto w = makeWindow();
  VulkanViewport* vw = w->viewport()->vulkanWindow();
  ASSERT_TRUE(vw) << "expected Vulkan presentation on " << QGuiApplication::platformName().toStdString() << ": "
                  << w->viewport()->presentation().toStdString();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(vw, 20000));
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 3; }));
  // Hold the picture still while grabbing: no new frames.
  w->engine()->submit(PauseCommand{true});
  QTest::qWait(500);
  QApplication::processEvents();
  ASSERT_TRUE(vw->isValid());
  const QImage expected = w->viewport()->composed().convertToFormat(QImage::Format_RGB32);
  // What the X server shows in the window (the swapchain's presented image), not a re-render.
  const QImage shown = vw->screen()->grabWindow(vw->winId()).toImage().convertToFormat(QImage::Format_RGB32);
  ASSERT_FALSE(shown.isNull()) << "the window could not be read back";
  ASSERT_EQ(shown.size(), expected.size());
  double diff = 0, mean = 0, meanSq = 0;
  const QRectF r = w->viewport()->imageRect();
  int n = 0;
  for (int y = 0; y < shown.height(); ++y)
    for (int x = 0; x < shown.width(); ++x) {
      QRgb a = shown.pixel(x, y), b = expected.pixel(x, y);
      diff += std::abs(qRed(a) - qRed(b)) + std::abs(qGreen(a) - qGreen(b)) + std::abs(qBlue(a) - qBlue(b));
      if (r.contains(x, y)) {
        double l = qGray(a);
        mean += l;
        meanSq += l * l;
        ++n;
      }
    }
  diff /= 3.0 * shown.width() * shown.height();
  if (!qEnvironmentVariableIsEmpty("RETILE_TEST_DUMP")) {
    shown.save(qEnvironmentVariable("RETILE_TEST_DUMP") + "/shown.png");
    expected.save(qEnvironmentVariable("RETILE_TEST_DUMP") + "/expected.png");
  }
  mean /= n;
  const double stddev = std::sqrt(std::max(0.0, meanSq / n - mean * mean));
  EXPECT_LT(diff, 1.5) << "mean absolute difference per channel (of 255) between the swapchain and the composed picture";
  EXPECT_GT(stddev, 10.0) << "the window shows an image, not a flat fill";
}

TEST(VulkanViewport, AClickOnTheVulkanWindowPicksAnObject) {
  auto w = makeWindow();
  VulkanViewport* vw = w->viewport()->vulkanWindow();
  ASSERT_TRUE(vw);
  ASSERT_TRUE(QTest::qWaitForWindowExposed(vw, 20000));
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  auto frame = w->viewport()->frame();
  NodeId sphere = kNoNode;
  for (const auto& o : w->scene().objects)
    if (o.name == "Glossy Sphere") sphere = o.id;
  ASSERT_NE(sphere, kNoNode);
  // The sphere's pixel nearest its centroid in the object-id output.
  const auto& ids = frame->image->objectId;
  double sx = 0, sy = 0;
  int count = 0;
  for (int y = 0; y < frame->height; ++y)
    for (int x = 0; x < frame->width; ++x)
      if (ids[static_cast<std::size_t>(y * frame->width + x)] == sphere) sx += x, sy += y, ++count;
  ASSERT_GT(count, 0);
  const QRectF r = w->viewport()->imageRect();
  QPoint at(static_cast<int>(r.x() + (sx / count + 0.5) * r.width() / frame->width),
            static_cast<int>(r.y() + (sy / count + 0.5) * r.height() / frame->height));
  QTest::mouseClick(vw, Qt::LeftButton, Qt::NoModifier, at);
  EXPECT_TRUE(QTest::qWaitFor([&] { return w->selection() == sphere; }, 5000)) << "the click reached the viewport";
}

// A menu's shortcut reaches its action while a text field has the focus: on X11 a line edit
// takes Ctrl+E (end of line) and Ctrl+K (delete to the end) for itself, and Save Image's Ctrl+E
// did nothing after a field of the properties panel was clicked. Here, under xcb, where those
// bindings hold.
TEST(EditorKeys, NoMenuShortcutIsAKeyATextFieldTakes) {
  auto w = makeWindow();
  auto* field = new QLineEdit(w.get());
  field->setText("1.000");
  int checked = 0;
  std::function<void(const QList<QAction*>&)> visit = [&](const QList<QAction*>& actions) {
    for (QAction* a : actions) {
      if (a->menu()) visit(a->menu()->actions());
      for (const QKeySequence& k : a->shortcuts()) {
        if (k.isEmpty()) continue;
        const QKeyCombination c = k[0];
        // Plain and shifted keys are text, and a field's own undo, redo and clipboard keys mean
        // there what they mean in the window: those the field may take.
        if (!(c.keyboardModifiers() & (Qt::ControlModifier | Qt::AltModifier | Qt::MetaModifier))) continue;
        bool sameMeaning = false;
        for (auto standard :
             {QKeySequence::Undo, QKeySequence::Redo, QKeySequence::Copy, QKeySequence::Cut, QKeySequence::Paste, QKeySequence::SelectAll})
          sameMeaning = sameMeaning || QKeySequence::keyBindings(standard).contains(k);
        if (sameMeaning) continue;
        QKeyEvent e(QEvent::ShortcutOverride, c.key(), c.keyboardModifiers());
        e.ignore();
        QCoreApplication::sendEvent(field, &e);
        EXPECT_FALSE(e.isAccepted()) << a->text().toStdString() << " (" << k.toString().toStdString()
                                     << ") is taken by a focused text field";
        ++checked;
      }
    }
  };
  visit(w->menuBar()->actions());
  EXPECT_GE(checked, 8) << "the menus' Ctrl and Alt shortcuts";
}

// Fault: presentation fails after start (here as the renderer reports Qt's lost device, with
// the same call; lavapipe never loses one). The viewport falls back to drawing the picture as a
// widget: the Vulkan window goes, frames keep arriving, and the screen shows the composed picture.
TEST(VulkanViewport, AFailedPresentationFallsBackToTheWidget) {
  auto w = makeWindow();
  QPointer<VulkanViewport> vw = w->viewport()->vulkanWindow();
  ASSERT_TRUE(vw);
  ASSERT_TRUE(QTest::qWaitForWindowExposed(vw, 20000));
  ASSERT_TRUE(waitForFrame(*w, [](const FrameRecord& f) { return f.frame >= 2; }));
  vw->fail(QStringLiteral("the Vulkan device was lost"));
  ASSERT_TRUE(QTest::qWaitFor([&] { return vw.isNull(); }, 5000)) << "the Vulkan window is destroyed";
  EXPECT_EQ(w->viewport()->vulkanWindow(), nullptr);
  EXPECT_TRUE(w->viewport()->presentation().startsWith("widget (the Vulkan device was lost"))
      << w->viewport()->presentation().toStdString();
  const std::uint64_t before = w->engine()->framesRendered();
  ASSERT_TRUE(waitForFrame(*w, [&](const FrameRecord&) { return w->engine()->framesRendered() > before + 2; })) << "rendering goes on";
  w->engine()->submit(PauseCommand{true});
  QTest::qWait(500);
  QApplication::processEvents();
  FrameView* view = w->viewport();
  const QPoint at = view->mapTo(w.get(), QPoint(0, 0));
  const QImage shown =
      w->screen()->grabWindow(w->winId(), at.x(), at.y(), view->width(), view->height()).toImage().convertToFormat(QImage::Format_RGB32);
  const QImage expected = view->composed().convertToFormat(QImage::Format_RGB32);
  ASSERT_EQ(shown.size(), expected.size());
  double diff = 0;
  for (int y = 0; y < shown.height(); ++y)
    for (int x = 0; x < shown.width(); ++x) {
      QRgb a = shown.pixel(x, y), b = expected.pixel(x, y);
      diff += std::abs(qRed(a) - qRed(b)) + std::abs(qGreen(a) - qGreen(b)) + std::abs(qBlue(a) - qBlue(b));
    }
  EXPECT_LT(diff / (3.0 * shown.width() * shown.height()), 1.5) << "the screen shows the widget's picture";
}

}  // namespace
}  // namespace retile::ui

int main(int argc, char** argv) {
  qputenv("RETILE_NO_PROMPTS", "1");
  QTemporaryDir recovery;
  qputenv("RETILE_RECOVERY_DIR", recovery.path().toUtf8());
  QStandardPaths::setTestModeEnabled(true);
  if (qEnvironmentVariableIsEmpty("DISPLAY") && qEnvironmentVariableIsEmpty("WAYLAND_DISPLAY")) {
    std::fprintf(stderr, "gui_vulkan_tests needs a display: run it under xvfb-run (ctest does)\n");
    return 1;
  }
  QApplication app(argc, argv);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
