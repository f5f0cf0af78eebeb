#include "fields.h"

#include <QColorDialog>
#include <QContextMenuEvent>
#include <QKeyEvent>
#include <QLineEdit>
#include <QLocale>
#include <QMenu>
#include <QMouseEvent>
#include <QStyle>
#include <QStyleOptionSpinBox>
#include <QToolTip>

#include <algorithm>
#include <cmath>
#include <limits>

namespace retile::ui {

ScrubField::ScrubField(double value, double min, double max, double defaultValue, int decimals, QWidget* parent)
    : QDoubleSpinBox(parent), default_(defaultValue), committed_(value) {
  setRange(min, max);
  setDecimals(decimals);
  setSingleStep(std::pow(10.0, -std::min(decimals, 2)));
  setKeyboardTracking(false);  // typing does not edit until Enter (or focus leaves)
  setValue(value);
  setCursor(Qt::SizeHorCursor);
  // The range's widest text would make vector rows wider than a dock: let the layout decide.
  setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
  setMinimumWidth(56);
  setToolTip(tr("Drag to scrub (Shift: finer), click to type, Enter commits, Esc cancels; right-click resets"));
  // The line edit eats mouse presses; watch them on the spin box instead.
  lineEdit()->setAttribute(Qt::WA_TransparentForMouseEvents, true);
  connect(this, &QDoubleSpinBox::valueChanged, this, [this](double v) {
    if (!silent_) commit(v);
  });
}

void ScrubField::commit(double v) {
  committed_ = v;
  emit edited(v, scrubbing_);
}

void ScrubField::mousePressEvent(QMouseEvent* e) {
  if (e->button() != Qt::LeftButton) return QDoubleSpinBox::mousePressEvent(e);
  // The arrows keep their usual behaviour.
  QStyleOptionSpinBox opt;
  initStyleOption(&opt);
  const auto hit = style()->hitTestComplexControl(QStyle::CC_SpinBox, &opt, e->position().toPoint(), this);
  if (hit == QStyle::SC_SpinBoxUp || hit == QStyle::SC_SpinBoxDown) return QDoubleSpinBox::mousePressEvent(e);
  pressed_ = true;
  pressAt_ = e->position().toPoint();
  lastX_ = pressAt_.x();
}

void ScrubField::mouseMoveEvent(QMouseEvent* e) {
  if (!pressed_) return QDoubleSpinBox::mouseMoveEvent(e);
  const int x = e->position().toPoint().x();
  if (!scrubbing_ && std::abs(x - pressAt_.x()) < 4) return;
  scrubbing_ = true;
  const double step = singleStep() * ((e->modifiers() & Qt::ShiftModifier) ? 0.1 : 1.0);
  const int dx = x - lastX_;
  lastX_ = x;
  if (dx != 0) setValue(value() + dx * step);
}

void ScrubField::mouseReleaseEvent(QMouseEvent* e) {
  if (!pressed_) return QDoubleSpinBox::mouseReleaseEvent(e);
  pressed_ = false;
  if (scrubbing_) {
    scrubbing_ = false;
    emit scrubFinished();
    clearFocus();  // the keyboard goes back to the window: Ctrl+Z undoes the scrub
    return;
  }
  // A click without a drag: type a value.
  typing_ = true;
  lineEdit()->setFocus();
  lineEdit()->selectAll();
}

bool ScrubField::event(QEvent* e) {
  if (e->type() == QEvent::ShortcutOverride) {
    // Outside typing, shortcuts (Ctrl+Z, B, A, W...) win over the spin box's own key handling.
    if (!typing_) {
      e->ignore();
      return true;
    }
    // While typing, Esc cancels the typing and Enter commits it: neither may reach the window's
    // shortcuts (Esc pauses the render there).
    const int key = static_cast<QKeyEvent*>(e)->key();
    if (key == Qt::Key_Escape || key == Qt::Key_Return || key == Qt::Key_Enter) {
      e->accept();
      return true;
    }
  }
  return QDoubleSpinBox::event(e);
}

std::optional<double> ScrubField::parse(const QString& text) {
  const QString t = text.trimmed();
  bool ok = false;
  double v = QLocale().toDouble(t, &ok);
  if (!ok) v = QLocale::c().toDouble(t, &ok);
  if (!ok) {
    // Qt's readers give no NaN or infinity back: name them, so the refusal says what they are.
    const QString lower = t.toLower();
    if (lower == "nan" || lower == "-nan") return std::numeric_limits<double>::quiet_NaN();
    if (lower == "inf" || lower == "+inf" || lower == "infinity") return std::numeric_limits<double>::infinity();
    if (lower == "-inf" || lower == "-infinity") return -std::numeric_limits<double>::infinity();
    return std::nullopt;
  }
  return v;
}

// A field whose lowest value means none of its effect shows a word there (specialValueText), and
// the word reads back as that value: Esc, a refusal and the typed word keep it.
std::optional<double> ScrubField::typedValue(const QString& text) const {
  if (!specialValueText().isEmpty() && text.trimmed().compare(specialValueText(), Qt::CaseInsensitive) == 0) return minimum();
  return parse(text);
}

QString ScrubField::shownText(double v) const {
  return !specialValueText().isEmpty() && v == minimum() ? specialValueText() : prefix() + textFromValue(v) + suffix();
}

QValidator::State ScrubField::validate(QString& text, int&) const {
  // Anything may be typed; it is judged once committed, with a word when it is refused.
  const QString typed = text.mid(prefix().size(), text.size() - prefix().size() - suffix().size());
  const auto v = typedValue(typed);
  return v && std::isfinite(*v) && *v >= minimum() && *v <= maximum() ? QValidator::Acceptable : QValidator::Intermediate;
}

double ScrubField::valueFromText(const QString& text) const {
  const auto v = typedValue(text);
  return v && std::isfinite(*v) ? std::clamp(*v, minimum(), maximum()) : value();
}

void ScrubField::refuse(const QString& why) {
  lastRefusal_ = why;
  QToolTip::showText(mapToGlobal(QPoint(0, height())), why, this, {}, 5000);
  emit refused(why);
}

void ScrubField::commitTyped() {
  const QString typed = cleanText();
  const auto v = typedValue(typed);
  const QString shown = shownText(committed_);
  if (!v || !std::isfinite(*v)) {
    refuse(v ? tr("%1 is not a finite number: kept %2").arg(typed, shown) : tr("\"%1\" is not a number: kept %2").arg(typed, shown));
    silent_ = true;
    setValue(committed_);
    lineEdit()->setText(shown);  // setValue rewrites nothing when the value is the same
    silent_ = false;
    return;
  }
  lastRefusal_.clear();
  const double clamped = std::clamp(*v, minimum(), maximum());
  if (clamped != *v)
    refuse(tr("%1 is outside %2 to %3: set to %4").arg(typed, textFromValue(minimum()), textFromValue(maximum()), textFromValue(clamped)));
  if (clamped == value()) lineEdit()->setText(shownText(clamped));
  else setValue(clamped);
}

void ScrubField::keyPressEvent(QKeyEvent* e) {
  if (e->key() == Qt::Key_Escape) {
    silent_ = true;
    setValue(committed_);  // drops the typed text
    lineEdit()->setText(shownText(committed_));
    silent_ = false;
    typing_ = false;
    clearFocus();
    return;
  }
  if (e->key() == Qt::Key_Return || e->key() == Qt::Key_Enter) {
    if (typing_) commitTyped();
    typing_ = false;
    return;
  }
  // A digit, a sign or an editing key from the keyboard starts typing (Tab brings the focus here).
  if (!e->text().isEmpty() || e->key() == Qt::Key_Backspace || e->key() == Qt::Key_Delete) typing_ = true;
  QDoubleSpinBox::keyPressEvent(e);
}

void ScrubField::focusInEvent(QFocusEvent* e) {
  committed_ = value();
  QDoubleSpinBox::focusInEvent(e);
}

void ScrubField::focusOutEvent(QFocusEvent* e) {
  // Leaving the field takes what was typed, as Enter does.
  if (typing_) commitTyped();
  typing_ = false;
  QDoubleSpinBox::focusOutEvent(e);
}

void ScrubField::contextMenuEvent(QContextMenuEvent* e) {
  QMenu menu(this);
  QAction* reset = menu.addAction(tr("Reset to default (%1)").arg(default_));
  if (menu.exec(e->globalPos()) == reset) setValue(default_);
}

ColorField::ColorField(QColor value, QColor defaultValue, QWidget* parent) : QPushButton(parent), default_(defaultValue) {
  setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
  setMinimumWidth(56);
  setColor(value);
  connect(this, &QPushButton::clicked, this, [this] {
    // Non-modal: the render follows the dialog's colour live; the session is one undo step, or
    // none when cancelled. The dialog belongs to the window, not to this field, so the swatch's
    // style sheet does not paint the dialog in the swatch colour.
    auto* dialog = new QColorDialog(color_, window());
    dialog->setAttribute(Qt::WA_DeleteOnClose);
    dialog->setObjectName("colorDialog");
    connect(this, &QObject::destroyed, dialog, &QWidget::close);
    const QColor start = color_;
    connect(dialog, &QColorDialog::currentColorChanged, this, [this](const QColor& c) {
      if (!c.isValid() || c == color_) return;
      setColor(c);
      emit previewed(c);
    });
    connect(dialog, &QColorDialog::finished, this, [this, start](int result) {
      if (result == QDialog::Accepted && color_ != start) {
        emit committed(color_);
      } else {
        setColor(start);
        emit cancelled();
      }
    });
    dialog->open();
  });
}

void ColorField::setColor(QColor c) {
  color_ = c;
  setText(c.name());
  // Readable text on any swatch.
  setStyleSheet(QString("background-color: %1; color: %2").arg(c.name(), c.lightnessF() > 0.55 ? "black" : "white"));
}

void ColorField::contextMenuEvent(QContextMenuEvent* e) {
  QMenu menu(this);
  QAction* reset = menu.addAction(tr("Reset to default (%1)").arg(default_.name()));
  if (menu.exec(e->globalPos()) == reset && default_ != color_) {
    setColor(default_);
    emit committed(default_);
  }
}

}  // namespace retile::ui
