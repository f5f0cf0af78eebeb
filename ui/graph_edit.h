// The edits the node graph asks its owner for, and how it builds them. The graph never changes the
// document itself (see node_graph.h): each gesture becomes one GraphEdit, built step by step
// against a working copy of the scene so that every step sees the ones before it.
#pragma once

#include <QRegularExpression>
#include <QString>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "retile/edit.h"

namespace retile::ui {

// An edit the graph asks for: (before, after) pairs that form one undo step. Applying the afters
// in order does it; applying the befores in reverse order undoes it. Adding a node is
// (RemoveNode{id}, AddX{...}); removing is the reverse, preceded by steps that clear the references
// to the node (SetObject with material = kNoNode, ...) so that undo restores them.
struct GraphEdit {
  std::vector<std::pair<Edit, Edit>> steps;
  QString text;
};

// Builds a GraphEdit against a working copy of the scene: every `after` is applied to the copy as it
// is added, so later steps see the earlier ones (their `before` values are right for undo, new ids
// do not collide) and a step the document would refuse aborts the whole edit here.
class EditBuilder {
 public:
  explicit EditBuilder(const Scene& s) : scene_(s) {}

  const Scene& scene() const { return scene_; }
  bool ok() const { return ok_; }
  bool empty() const { return edit_.steps.empty(); }

  bool step(Edit before, Edit after);
  bool set(const Material& m);
  bool set(const Object& o);
  bool set(const Light& l);
  bool set(const Texture& t);
  NodeId newId() const;
  // Points `to`'s input ("material", "blend" or a texture input) at `from` (kNoNode clears it).
  // False when nothing changes or it is not allowed.
  bool assign(NodeId to, const QString& input, NodeId from);
  // Clears the references to the node first, so that undoing (befores in reverse) adds it back and
  // then restores them.
  bool remove(NodeId id);
  GraphEdit finish(const QString& text);

 private:
  Scene scene_;
  GraphEdit edit_;
  bool ok_ = true;
};

QString nameOf(const Scene& s, NodeId id);  // a node's name, or its id when it has none

// "Name", "Name.001", ...: Blender's convention, which artists already read as "a copy of Name".
template <class Node>
std::string uniqueName(const std::vector<Node>& nodes, std::string base) {
  static const QRegularExpression suffix(QStringLiteral("\\.\\d{3}$"));
  QString b = QString::fromStdString(base);
  b.remove(suffix);
  if (b.isEmpty()) b = QStringLiteral("Node");
  auto taken = [&](const std::string& n) { return std::any_of(nodes.begin(), nodes.end(), [&](const Node& x) { return x.name == n; }); };
  if (!taken(b.toStdString())) return b.toStdString();
  for (int i = 1;; ++i) {
    std::string n = QStringLiteral("%1.%2").arg(b).arg(i, 3, 10, QLatin1Char('0')).toStdString();
    if (!taken(n)) return n;
  }
}

}  // namespace retile::ui
