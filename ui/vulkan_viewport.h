// The viewport's Vulkan presentation: a QVulkanWindow that shows the picture FrameView composes
// (the engine's frame through the display transform, with the overlays) on a Vulkan swapchain.
// Used where the platform has Vulkan surfaces (xcb, wayland); Qt's offscreen platform has none,
// and FrameView then paints the same picture itself.
//
// Ownership and threads: FrameView owns the window (through its window container) and is its
// only caller; GUI thread only. Qt calls the renderer on the GUI thread too, so the picture
// needs no lock. Input events are forwarded to FrameView, which owns all viewport interaction.
#pragma once

#include <QElapsedTimer>
#include <QImage>
#include <QTimer>
#include <QVulkanWindow>

#include <functional>

class QWidget;

namespace retile::ui {

class VulkanViewport : public QVulkanWindow {
 public:
  // `eventTarget` receives the window's mouse, wheel and key events (same coordinates: the
  // container fills it).
  explicit VulkanViewport(QWidget* eventTarget);

  // The process's Vulkan instance for Qt windows, or nullptr (with the reason) when the platform
  // cannot present with Vulkan. Created once and kept for the process's lifetime: windows may
  // outlive any single owner, and destroying an instance after the platform plugin is gone crashes.
  static QVulkanInstance* sharedInstance(QString* why = nullptr);

  // A new picture in Format_RGB32; shown at the next frame (stretched to the swapchain).
  void setPicture(QImage picture);
  const QImage& picture() const { return picture_; }
  QVulkanWindowRenderer* createRenderer() override;

  // Presentation failed for good (device lost, a Vulkan call of ours failed, Vulkan never started,
  // or the swapchain stopped presenting while pictures waited): `handler` is called once, queued,
  // so the owner may delete this window. The renderer and the watchdog call fail(); so do tests.
  void setFailureHandler(std::function<void(const QString&)> handler) { onFailure_ = std::move(handler); }
  void fail(const QString& why);
  bool failed() const { return failed_; }
  void framePresented();  // the renderer recorded a frame

 protected:
  bool event(QEvent* e) override;

 private:
  void watch();
  QWidget* target_;
  QImage picture_;
  std::function<void(const QString&)> onFailure_;
  bool failed_ = false;
  QTimer watchdog_;
  QElapsedTimer waiting_;     // since the oldest picture not yet presented (invalid: none waits)
  QElapsedTimer notStarted_;  // since the window was exposed without valid presentation
};

}  // namespace retile::ui
