#include "graph_layout.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "graph_items.h"

namespace retile::ui {

std::vector<std::pair<NodeId, QString>> linksInto(const Scene& s, NodeId id) {
  std::vector<std::pair<NodeId, QString>> in;
  if (const Object* o = s.object(id)) {
    if (o->material != kNoNode) in.emplace_back(o->material, QStringLiteral("material"));
  } else if (const Material* m = s.material(id); m && m->type != MaterialType::Boundary) {
    for (const QString& slot : textureInputs())
      if (m->*textureSlot(slot) != kNoNode) in.emplace_back(m->*textureSlot(slot), slot);
    if (m->blendWith != kNoNode) in.emplace_back(m->blendWith, kBlendInput);
  }
  return in;
}

namespace {

constexpr qreal kIslandGapX = 150, kIslandGapY = 60;

struct Island {
  std::vector<GraphNodeItem*> nodes;
  NodePositions at;
  QSizeF size;
};

QSizeF extent(const std::vector<GraphNodeItem*>& nodes, const NodePositions& at) {
  QSizeF size;
  for (const GraphNodeItem* n : nodes) {
    const QPointF p = at.at(n->id);
    size = size.expandedTo(QSizeF(p.x() + kNodeWidth, p.y() + n->height()));
  }
  return size;
}

// The nodes joined by links, each set in the order of `nodes`: a material with its textures, the
// objects it is on, the materials it blends with, and so on through every link.
std::vector<std::vector<GraphNodeItem*>> connected(const Scene& s, const std::vector<GraphNodeItem*>& nodes) {
  std::unordered_map<NodeId, std::size_t> index;
  for (std::size_t i = 0; i < nodes.size(); ++i) index[nodes[i]->id] = i;
  std::vector<std::size_t> parent(nodes.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (std::size_t i = 0; i < nodes.size(); ++i)
    for (const auto& [source, input] : linksInto(s, nodes[i]->id))
      if (auto it = index.find(source); it != index.end()) parent[find(i)] = find(it->second);
  std::vector<std::vector<GraphNodeItem*>> sets;
  std::unordered_map<std::size_t, std::size_t> setOf;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    auto [it, fresh] = setOf.emplace(find(i), sets.size());
    if (fresh) sets.emplace_back();
    sets[it->second].push_back(nodes[i]);
  }
  return sets;
}

}  // namespace

NodePositions layOutIslands(const Scene& s, const std::vector<GraphNodeItem*>& nodes, double aspect) {
  std::vector<Island> islands;
  std::map<int, Island> loners;  // per column kind: nodes with no link, one column each
  for (std::vector<GraphNodeItem*>& set : connected(s, nodes)) {
    if (set.size() == 1) {
      Island& column = loners[columnOf(set.front()->kind)];
      column.at[set.front()->id] = QPointF(0, column.size.height());
      column.size = QSizeF(kNodeWidth, column.size.height() + set.front()->height() + kRowGap);
      column.nodes.push_back(set.front());
      continue;
    }
    // What nothing else in the island takes (objects, mostly) goes on the right.
    std::set<NodeId> fed;
    for (const GraphNodeItem* n : set)
      for (const auto& [source, input] : linksInto(s, n->id)) fed.insert(source);
    std::vector<NodeId> roots;
    for (const GraphNodeItem* n : set)
      if (!fed.count(n->id)) roots.push_back(n->id);
    Island island{set, layOutNeighbourhood(s, set, roots), {}};
    island.size = extent(island.nodes, island.at);
    islands.push_back(std::move(island));
  }
  for (auto& [kind, column] : loners) islands.push_back(std::move(column));

  // Shelves of islands, the tallest first (each shelf is as tall as its first island, so the
  // others fill it best), about as wide for their height as the panel is.
  std::stable_sort(islands.begin(), islands.end(), [](const Island& a, const Island& b) { return a.size.height() > b.size.height(); });
  double area = 0, widest = 0;
  for (const Island& i : islands) {
    area += (i.size.width() + kIslandGapX) * (i.size.height() + kIslandGapY);
    widest = std::max(widest, i.size.width());
  }
  const double width = std::max(widest, std::sqrt(area * std::clamp(aspect, 1.0, 8.0)));
  struct Shelf {
    qreal y, height, x;
  };
  std::vector<Shelf> shelves;
  NodePositions at;
  for (const Island& i : islands) {
    auto shelf = std::find_if(shelves.begin(), shelves.end(),
                              [&](const Shelf& f) { return f.x + i.size.width() <= width && i.size.height() <= f.height; });
    if (shelf == shelves.end()) {
      const qreal y = shelves.empty() ? 0 : shelves.back().y + shelves.back().height + kIslandGapY;
      shelves.push_back({y, i.size.height(), 0});
      shelf = shelves.end() - 1;
    }
    for (const GraphNodeItem* n : i.nodes) at[n->id] = i.at.at(n->id) + QPointF(shelf->x, shelf->y);
    shelf->x += i.size.width() + kIslandGapX;
  }
  return at;
}

std::set<NodeId> neighbourhood(const Scene& s, const std::vector<NodeId>& roots) {
  std::set<NodeId> found;
  std::vector<NodeId> todo(roots.begin(), roots.end());
  while (!todo.empty()) {
    const NodeId id = todo.back();
    todo.pop_back();
    if (!found.insert(id).second) continue;
    for (const auto& [source, input] : linksInto(s, id)) todo.push_back(source);
  }
  return found;
}

NodePositions layOutNeighbourhood(const Scene& s, const std::vector<GraphNodeItem*>& nodes, const std::vector<NodeId>& roots) {
  std::unordered_map<NodeId, GraphNodeItem*> byId;
  for (GraphNodeItem* n : nodes) byId[n->id] = n;
  // Distance from the roots along the longest chain of links, so that a node sits left of every
  // node it feeds; bounded by the node count, which a cycle of blends would otherwise exceed.
  std::unordered_map<NodeId, int> depth;
  for (NodeId r : roots)
    if (byId.count(r)) depth[r] = 0;
  // Objects that share a material next to each other, in the order the scene lists the materials.
  std::unordered_map<NodeId, std::size_t> materialRank;
  for (std::size_t i = 0; i < s.materials.size(); ++i) materialRank[s.materials[i].id] = i;
  auto rank = [&](const GraphNodeItem* n) {
    const Object* o = s.object(n->id);
    auto it = o ? materialRank.find(o->material) : materialRank.end();
    return it == materialRank.end() ? s.materials.size() : it->second;
  };
  const int limit = static_cast<int>(nodes.size());
  for (bool changed = true; changed;) {
    changed = false;
    for (const auto& [id, d] : std::map<NodeId, int>(depth.begin(), depth.end()))
      for (const auto& [source, input] : linksInto(s, id))
        if (byId.count(source) && d < limit && (!depth.count(source) || depth[source] < d + 1)) {
          depth[source] = d + 1;
          changed = true;
        }
  }
  int deepest = 0;
  std::map<int, std::vector<GraphNodeItem*>> columns;
  for (GraphNodeItem* n : nodes) {
    const int d = depth.count(n->id) ? depth[n->id] : 0;
    deepest = std::max(deepest, d);
    columns[d].push_back(n);
  }

  NodePositions at;
  // Where each node would like its top: its output level with the highest input it feeds in a
  // column already placed (columns go right to left, the roots' first, stacked in order).
  std::unordered_map<NodeId, qreal> wanted;
  for (const auto& [d, column] : columns) {
    std::vector<GraphNodeItem*> order = column;
    if (d == 0)
      std::stable_sort(order.begin(), order.end(), [&](const GraphNodeItem* a, const GraphNodeItem* b) { return rank(a) < rank(b); });
    std::stable_sort(order.begin(), order.end(), [&](const GraphNodeItem* a, const GraphNodeItem* b) {
      return (wanted.count(a->id) ? wanted[a->id] : 0) < (wanted.count(b->id) ? wanted[b->id] : 0);
    });
    qreal y = 0;
    for (GraphNodeItem* n : order) {
      if (wanted.count(n->id)) y = std::max(y, wanted[n->id]);
      const QPointF p((deepest - d) * kColumnStep, y);
      at[n->id] = p;
      y += n->height() + kRowGap;
      for (const auto& [source, input] : linksInto(s, n->id)) {
        auto it = byId.find(source);
        if (it == byId.end()) continue;
        const qreal level = p.y() + n->inputPos(n->inputs.indexOf(input)).y() - it->second->outputPos().y();
        if (!wanted.count(source) || level < wanted[source]) wanted[source] = level;
      }
    }
  }
  return at;
}

QPointF framingCentre(const QRectF& all, const QRectF& focus, QSizeF view) {
  auto axis = [](qreal lo, qreal hi, qreal focusLo, qreal focusHi, qreal span) {
    if (hi - lo <= span) return (lo + hi) / 2;
    const qreal c = focusHi - focusLo <= span ? (focusLo + focusHi) / 2 : focusLo + span / 2;
    return std::clamp(c, lo + span / 2, hi - span / 2);
  };
  return {axis(all.left(), all.right(), focus.left(), focus.right(), view.width()),
          axis(all.top(), all.bottom(), focus.top(), focus.bottom(), view.height())};
}

}  // namespace retile::ui
