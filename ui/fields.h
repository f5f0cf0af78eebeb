// Parameter editors with the conventions artists bring from Blender, Houdini and Katana: drag a
// number field to scrub (Shift: ten times finer), click to type, Enter commits, Esc cancels,
// "Reset to default" on the context menu; a colour swatch whose whole dialog session is one edit.
// A typed value is read as a number in the user's locale or in C's (1e3, -2.5, 0,5 under de_DE);
// one outside the field's range is clamped and one that is no finite number is refused, each
// said in a tooltip at the field and by refused().
// A field keeps the keyboard only while a value is typed into it: after a scrub, Ctrl+Z, B and
// the other shortcuts go to the window.
// GUI thread only. Each field owns nothing but its widgets; the caller turns its signals into
// undoable edits (a scrub reports its start and end so a whole drag becomes one undo step).
#pragma once

#include <QColor>
#include <QDoubleSpinBox>
#include <QPushButton>

#include <optional>

namespace retile::ui {

class ScrubField : public QDoubleSpinBox {
  Q_OBJECT
 public:
  ScrubField(double value, double min, double max, double defaultValue, int decimals, QWidget* parent = nullptr);
  double defaultValue() const { return default_; }
  bool scrubbing() const { return scrubbing_; }
  // What the last typed value was refused or clamped for; empty when it was taken as typed.
  QString lastRefusal() const { return lastRefusal_; }
  // A typed text as a number (the locale's form, else C's), or nullopt; NaN and infinities parse.
  static std::optional<double> parse(const QString& text);

 signals:
  // A committed value: typed and entered, stepped, reset, or one step of a scrub.
  void edited(double value, bool scrubbing);
  void scrubFinished();
  // A typed value was refused (not a finite number) or clamped to the range: why, in words.
  void refused(const QString& why);

 protected:
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void keyPressEvent(QKeyEvent* e) override;
  void focusInEvent(QFocusEvent* e) override;
  void focusOutEvent(QFocusEvent* e) override;
  bool event(QEvent* e) override;
  void contextMenuEvent(QContextMenuEvent* e) override;
  QValidator::State validate(QString& text, int& pos) const override;
  double valueFromText(const QString& text) const override;

 private:
  void commit(double v);
  // Takes what was typed (Enter, or the focus leaving while typing): clamped or refused with a word.
  void commitTyped();
  void refuse(const QString& why);
  std::optional<double> typedValue(const QString& text) const;
  QString shownText(double v) const;  // the line edit's text for v, as the spin box shows it

  double default_;
  double committed_;  // the value Esc returns to
  bool pressed_ = false, scrubbing_ = false;
  QPoint pressAt_;
  int lastX_ = 0;
  bool silent_ = false;
  bool typing_ = false;  // a value is being typed: the field keeps Ctrl+Z, letters and the like
  QString lastRefusal_;
};

class ColorField : public QPushButton {
  Q_OBJECT
 public:
  ColorField(QColor value, QColor defaultValue, QWidget* parent = nullptr);
  QColor color() const { return color_; }
  void setColor(QColor c);

 signals:
  // While the dialog is open, each colour tried (to show, not to keep); then, when it closes,
  // committed (accepted with another colour, or reset from the menu) or cancelled (the tried colours
  // are to be taken back: nothing was changed).
  void previewed(QColor color);
  void committed(QColor color);
  void cancelled();

 protected:
  void contextMenuEvent(QContextMenuEvent* e) override;

 private:
  QColor color_, default_;
};

}  // namespace retile::ui
