// The viewport's Vulkan presentation: a QVulkanWindow that shows the picture FrameView composes
// (the engine's frame through the display transform, with the overlays) on a Vulkan swapchain.
// Used where the platform has Vulkan surfaces (xcb, wayland); Qt's offscreen platform has none,
// and FrameView then paints the same picture itself.
//
// Ownership and threads: FrameView owns the window (through its window container) and is its
// only caller; GUI thread only. Qt calls the renderer on the GUI thread too, so the picture
// needs no lock. Input events are forwarded to FrameView, which owns all viewport interaction.
#pragma once

#include <QImage>
#include <QVulkanWindow>

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

 protected:
  bool event(QEvent* e) override;

 private:
  QWidget* target_;
  QImage picture_;
};

}  // namespace retile::ui
