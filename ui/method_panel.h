// The Render settings' "Method" box: the policy, tile size T, quality Q or automatic, the smooth
// transition and its stale cap, how Shift+click places focus points, verified reuse, and the
// denoiser with its region threshold and soft borders. It owns the method the editor renders
// with: a change that validates is announced by changed(), one that does not by refused(). The
// focus points, which the viewport places, are kept with the rest. GUI thread only.
#pragma once

#include <QGroupBox>

#include <vector>

#include "retile/method.h"

class QCheckBox;
class QComboBox;
class QSpinBox;

namespace retile::ui {

class MethodPanel : public QGroupBox {
  Q_OBJECT
 public:
  explicit MethodPanel(MethodSettings initial, QWidget* parent = nullptr);

  const MethodSettings& settings() const { return settings_; }
  // What a Shift+click in the viewport does, or whether the cursor is the focus point.
  enum class FocusMode { Static, Follows, Cursor };
  FocusMode focusMode() const;
  void setFocus(std::vector<FocusPoint> focus) { settings_.focus = std::move(focus); }

 signals:
  void changed(const retile::MethodSettings& settings);
  void refused(const QString& why);
  void focusCleared();

 private:
  void read();  // the settings from the fields; enables what applies

  MethodSettings settings_;
  QComboBox* policy_ = nullptr;
  QComboBox* tile_ = nullptr;
  QSpinBox* quality_ = nullptr;
  QCheckBox* qualityAuto_ = nullptr;
  QCheckBox* smooth_ = nullptr;
  QSpinBox* staleCap_ = nullptr;
  QComboBox* focusMode_ = nullptr;
  QCheckBox* reuse_ = nullptr;
  QCheckBox* denoise_ = nullptr;
  QSpinBox* threshold_ = nullptr;
  QCheckBox* softBorders_ = nullptr;
};

}  // namespace retile::ui
