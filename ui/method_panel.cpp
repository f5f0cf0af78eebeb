#include "method_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QPushButton>
#include <QSpinBox>

#include <cmath>

namespace retile::ui {

namespace {

bool automaticQualityApplies(MethodKind k) { return k == MethodKind::Indirection || k == MethodKind::IndirectionFocus; }

QCheckBox* checkBox(const QString& text, const char* name, bool on, const QString& tip, QWidget* parent) {
  auto* c = new QCheckBox(text, parent);
  c->setObjectName(name);
  c->setChecked(on);
  c->setToolTip(tip);
  return c;
}

// A typed value applies on Enter, not at every digit.
QSpinBox* spinBox(const char* name, int lo, int hi, int value, const QString& tip, QWidget* parent) {
  auto* s = new QSpinBox(parent);
  s->setObjectName(name);
  s->setRange(lo, hi);
  s->setValue(value);
  s->setKeyboardTracking(false);
  s->setToolTip(tip);
  return s;
}

}  // namespace

MethodPanel::MethodPanel(MethodSettings initial, QWidget* parent) : QGroupBox(tr("Method"), parent), settings_(std::move(initial)) {
  const MethodSettings& m = settings_;
  policy_ = new QComboBox(this);
  policy_->setObjectName("method");
  for (const auto& n : methodNames()) policy_->addItem(QString::fromStdString(n));
  policy_->setCurrentText(methodName(m.kind));
  tile_ = new QComboBox(this);
  for (int t : {8, 16, 32}) tile_->addItem(QString::number(t), t);
  tile_->setCurrentText(QString::number(m.tileSize));
  quality_ = spinBox("quality", 1, 4096, std::max(1, m.quality), tr("Samples per pixel of a served tile"), this);
  qualityAuto_ = checkBox(tr("auto"), "qualityAuto", m.quality == 0,
                          tr("Indirection methods: the largest Q at which every high-priority tile fits in one frame"), this);
  auto* qualityRow = new QWidget(this);
  auto* ql = new QHBoxLayout(qualityRow);
  ql->setContentsMargins(0, 0, 0, 0);
  ql->addWidget(quality_, 1);
  ql->addWidget(qualityAuto_);
  smooth_ = checkBox(tr("smooth transition"), "smooth", m.smooth, QString(), this);
  staleCap_ =
      spinBox("staleCap", 1, 4096, m.staleCap,
              tr("Stale samples kept per pixel by the smooth transition: the old image weighs C/(C+n) after n fresh samples"), this);
  focusMode_ = new QComboBox(this);
  focusMode_->setObjectName("focusMode");
  focusMode_->addItems({tr("Shift+click: static point"), tr("Shift+click: follows the object"), tr("follows the cursor")});
  focusMode_->setToolTip(
      tr("Focus points (up to 3) for the focus methods. Shift+click adds one; 'follows the cursor' "
         "stands in for an eye tracker."));
  auto* clearFocus = new QPushButton(tr("Clear focus points"), this);
  reuse_ = checkBox(tr("reuse verified samples"), "reuse", m.reuse,
                    tr("After an edit, a re-rendered tile keeps its converged samples while a test finds the fresh ones "
                       "in agreement with them, and drops them for good the moment they disagree. Not with the "
                       "global method."),
                    this);
  denoise_ = checkBox(tr("denoise"), "denoise", m.denoise,
                      tr("Show the image denoised: the whole frame during refinement, a growing region during a pass. "
                         "The samples themselves are untouched (the pixel inspector can read either)."),
                      this);
  threshold_ = spinBox("denoiseThreshold", 0, 100, static_cast<int>(std::lround(m.denoiseThreshold * 100)),
                       tr("The denoised region is re-sized when its width (height) has grown by more than this "
                          "share of the image's width (height)"),
                       this);
  threshold_->setSuffix(tr(" % of the image"));
  softBorders_ = checkBox(tr("soft borders"), "softBorders", m.softBorders,
                          tr("Blend the seams between fresh and stale tiles and between denoised regions over a few pixels"), this);
  auto* form = new QFormLayout(this);
  form->addRow(tr("Policy"), policy_);
  form->addRow(tr("Tile size T"), tile_);
  form->addRow(tr("Quality Q"), qualityRow);
  form->addRow(QString(), smooth_);
  form->addRow(tr("Stale cap C"), staleCap_);
  form->addRow(tr("Focus"), focusMode_);
  form->addRow(QString(), clearFocus);
  form->addRow(QString(), reuse_);
  form->addRow(QString(), denoise_);
  form->addRow(tr("Denoise threshold"), threshold_);
  form->addRow(QString(), softBorders_);

  for (QComboBox* c : {policy_, tile_}) connect(c, &QComboBox::currentIndexChanged, this, [this] { read(); });
  for (QSpinBox* s : {quality_, staleCap_, threshold_}) connect(s, &QSpinBox::valueChanged, this, [this] { read(); });
  for (QCheckBox* c : {qualityAuto_, smooth_, reuse_, denoise_, softBorders_}) connect(c, &QCheckBox::toggled, this, [this] { read(); });
  connect(clearFocus, &QPushButton::clicked, this, [this] {
    settings_.focus.clear();
    emit focusCleared();
  });
  // What applies to the initial settings is enabled, without announcing them.
  quality_->setEnabled(m.quality != 0);
  qualityAuto_->setEnabled(automaticQualityApplies(m.kind));
  reuse_->setEnabled(m.kind != MethodKind::Global);
  staleCap_->setEnabled(m.smooth);
  threshold_->setEnabled(m.denoise);
  softBorders_->setEnabled(m.denoise);
}

MethodPanel::FocusMode MethodPanel::focusMode() const { return static_cast<FocusMode>(focusMode_->currentIndex()); }

void MethodPanel::read() {
  MethodSettings m = settings_;
  methodFromName(policy_->currentText().toStdString(), &m.kind);
  m.tileSize = tile_->currentData().toInt();
  qualityAuto_->setEnabled(automaticQualityApplies(m.kind));
  m.quality = automaticQualityApplies(m.kind) && qualityAuto_->isChecked() ? 0 : quality_->value();
  quality_->setEnabled(m.quality != 0);
  m.smooth = smooth_->isChecked();
  m.staleCap = staleCap_->value();
  m.denoise = denoise_->isChecked();
  m.reuse = reuse_->isChecked() && m.kind != MethodKind::Global;
  reuse_->setEnabled(m.kind != MethodKind::Global);
  m.denoiseThreshold = threshold_->value() / 100.0;
  m.softBorders = softBorders_->isChecked();
  staleCap_->setEnabled(m.smooth);
  threshold_->setEnabled(m.denoise);
  softBorders_->setEnabled(m.denoise);
  if (std::string bad = validateMethodSettings(m); !bad.empty()) {
    emit refused(QString::fromStdString(bad));
    return;
  }
  settings_ = m;
  emit changed(settings_);
}

}  // namespace retile::ui
