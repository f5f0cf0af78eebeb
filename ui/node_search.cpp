#include "node_search.h"

#include <QKeyEvent>
#include <QLineEdit>
#include <QListWidget>
#include <QScreen>
#include <QVBoxLayout>

#include <algorithm>

namespace retile::ui {

const std::vector<CreatableType>& creatableTypeTable() {
  static const std::vector<CreatableType> types = {
      {QStringLiteral("Material"),
       {"surface", "shader", "bsdf", "diffuse", "lambert", "plastic", "metal", "conductor", "glass", "dielectric", "emitter"}},
      {QStringLiteral("Checker Texture"), {"texture", "checker", "checkerboard", "pattern", "grid", "uv"}},
      {QStringLiteral("Point Light"), {"lamp", "bulb", "omni"}},
      {QStringLiteral("Spot Light"), {"lamp", "cone", "spotlight"}},
      {QStringLiteral("Directional Light"), {"lamp", "sun", "distant", "parallel"}},
  };
  return types;
}

QString searchMatch(const CreatableType& type, const QString& filter) {
  const QStringList words = filter.split(QLatin1Char(' '), Qt::SkipEmptyParts);
  QString synonym;
  for (const QString& w : words) {
    if (type.name.contains(w, Qt::CaseInsensitive)) continue;
    auto it =
        std::find_if(type.synonyms.begin(), type.synonyms.end(), [&](const QString& s) { return s.contains(w, Qt::CaseInsensitive); });
    if (it == type.synonyms.end()) return {};
    synonym = *it;
  }
  return synonym.isEmpty() ? type.name : synonym;
}

NodeSearchPopup::NodeSearchPopup(QWidget* parent, std::function<void(const QString&)> chosen)
    : QFrame(parent, Qt::Popup), chosen_(std::move(chosen)) {
  setFrameShape(QFrame::StyledPanel);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(4, 4, 4, 4);
  layout->setSpacing(4);
  filter_ = new QLineEdit(this);
  filter_->setObjectName(QStringLiteral("nodeSearch"));
  filter_->setPlaceholderText(tr("Add node: type what it makes..."));
  list_ = new QListWidget(this);
  list_->setObjectName(QStringLiteral("nodeSearchList"));
  for (const CreatableType& t : creatableTypeTable()) {
    auto* item = new QListWidgetItem(t.name, list_);
    item->setData(Qt::UserRole, t.name);
  }
  layout->addWidget(filter_);
  layout->addWidget(list_);
  filter_->installEventFilter(this);
  QObject::connect(filter_, &QLineEdit::textChanged, this, [this](const QString& t) { refilter(t); });
  QObject::connect(filter_, &QLineEdit::returnPressed, this, [this] { activate(list_->currentItem()); });
  QObject::connect(list_, &QListWidget::itemClicked, this, [this](QListWidgetItem* i) { activate(i); });
}

QRect NodeSearchPopup::allowedArea() const {
  QWidget* window = parentWidget() ? parentWidget()->window() : nullptr;
  QRect area = window ? window->frameGeometry() : QRect();
  if (QScreen* s = window ? window->screen() : screen()) area = area.isValid() ? area & s->availableGeometry() : s->availableGeometry();
  return area;
}

void NodeSearchPopup::popupAt(QPoint global) {
  filter_->clear();
  refilter(QString());
  // Tall enough for every entry (a filter only hides some), unless the area is lower than that.
  const int rows = list_->sizeHintForRow(0) * list_->count() + 2 * list_->frameWidth();
  list_->setMinimumHeight(0);
  list_->setFixedHeight(rows);
  adjustSize();
  const QRect area = allowedArea();
  QSize size(std::max(240, sizeHint().width()), sizeHint().height());
  if (size.height() > area.height()) {
    list_->setFixedHeight(std::max(list_->sizeHintForRow(0), rows - (size.height() - area.height())));
    size.setHeight(area.height());
  }
  size.setWidth(std::min(size.width(), area.width()));
  resize(size);
  // Below and right of the cursor; above it where below would leave the window, then clamped.
  QPoint at = global;
  if (at.y() + size.height() > area.bottom() + 1) at.setY(global.y() - size.height());
  at.setX(std::clamp(at.x(), area.left(), area.right() + 1 - size.width()));
  at.setY(std::clamp(at.y(), area.top(), area.bottom() + 1 - size.height()));
  move(at);
  show();
  filter_->setFocus();
}

bool NodeSearchPopup::eventFilter(QObject* o, QEvent* e) {
  if (o == filter_ && e->type() == QEvent::KeyPress) {
    const int key = static_cast<QKeyEvent*>(e)->key();
    if (key == Qt::Key_Escape) {
      hide();
      return true;
    }
    if (key == Qt::Key_Down || key == Qt::Key_Up) {
      step(key == Qt::Key_Down ? 1 : -1);
      return true;
    }
  }
  return QFrame::eventFilter(o, e);
}

void NodeSearchPopup::refilter(const QString& text) {
  QListWidgetItem* first = nullptr;
  const std::vector<CreatableType>& types = creatableTypeTable();
  for (int i = 0; i < list_->count(); ++i) {
    QListWidgetItem* item = list_->item(i);
    const CreatableType& type = types[static_cast<std::size_t>(i)];
    const QString why = searchMatch(type, text.trimmed());
    item->setHidden(why.isEmpty());
    // Matched by a synonym only: say which, so the entry does not look like a wrong hit.
    item->setText(why.isEmpty() || why == type.name ? type.name : tr("%1 (%2)").arg(type.name, why));
    if (!why.isEmpty() && !first) first = item;
  }
  list_->setCurrentItem(first);
}

void NodeSearchPopup::step(int d) {
  const int n = list_->count();
  for (int i = list_->currentRow() + d; i >= 0 && i < n; i += d)
    if (!list_->item(i)->isHidden()) {
      list_->setCurrentRow(i);
      return;
    }
}

void NodeSearchPopup::activate(QListWidgetItem* item) {
  if (!item || item->isHidden()) return;
  const QString type = item->data(Qt::UserRole).toString();
  hide();
  chosen_(type);
}

}  // namespace retile::ui
