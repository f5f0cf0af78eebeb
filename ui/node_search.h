// The node graph's Tab / right-click menu: a filter line over the node types it can create. Each
// type is found by its name and by what an artist would call what it makes ("checker" and
// "pattern" find the checker texture, "sun" the directional light, "lamp" every light): any case,
// any part of a word, every word typed. Up/Down move, Enter creates, Escape (or a click
// elsewhere: it is a popup) closes. It opens at the cursor but always wholly inside the window
// and the screen, moved up or left where it would stick out.
#pragma once

#include <QFrame>
#include <QString>
#include <QStringList>

#include <functional>
#include <vector>

class QLineEdit;
class QListWidget;
class QListWidgetItem;

namespace retile::ui {

struct CreatableType {
  QString name;          // what NodeGraphView::createNode takes
  QStringList synonyms;  // lower case
};
const std::vector<CreatableType>& creatableTypeTable();
// The word that made `type` match `filter` (its name, or the synonym when only a synonym does),
// or an empty string when it does not match. An empty filter matches by name.
QString searchMatch(const CreatableType& type, const QString& filter);

class NodeSearchPopup : public QFrame {
 public:
  NodeSearchPopup(QWidget* parent, std::function<void(const QString&)> chosen);
  void popupAt(QPoint global);

 protected:
  bool eventFilter(QObject* o, QEvent* e) override;

 private:
  QRect allowedArea() const;  // global coordinates: the window, within the screen
  void refilter(const QString& text);
  void step(int d);
  void activate(QListWidgetItem* item);

  std::function<void(const QString&)> chosen_;
  QLineEdit* filter_ = nullptr;
  QListWidget* list_ = nullptr;
};

}  // namespace retile::ui
