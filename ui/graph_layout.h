// Where the node graph's nodes go, and which nodes a selection's view holds. A selection's
// neighbourhood (the Selection scope: an object, its material, that material's textures and the
// material it blends with) is laid out in columns by distance from the selection, each node beside
// what it feeds, so that every link runs level or nearly so across one gap between columns and
// crosses no node; the whole graph (the All scope) is a set of such islands side by side. (A
// layout in columns by kind had links from the first material column to the last object column
// run across every column between, through the sockets at their height.)
#pragma once

#include <QPointF>
#include <QRectF>
#include <QSizeF>
#include <QString>

#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

#include "retile/scene.h"

namespace retile::ui {

class GraphNodeItem;
using NodePositions = std::unordered_map<NodeId, QPointF>;

// The links into a node, as (source, input) in the order its sockets are drawn: an object's
// material; a material's textures, then the material it blends with (a boundary has none).
std::vector<std::pair<NodeId, QString>> linksInto(const Scene& s, NodeId id);

// Every node, as islands: each set of nodes joined by links (a material with its textures and
// objects, and whatever blends or shares a texture with it) laid out as layOutNeighbourhood does,
// with what nothing in it takes (the objects) on the right; nodes without links in a column per
// kind. The islands go on shelves, the tallest first, to about a panel's `aspect` (width / height).
// Links then run within an island from one column to the next and cross no node.
NodePositions layOutIslands(const Scene& s, const std::vector<GraphNodeItem*>& nodes, double aspect);

// The roots and what they are made of, transitively: an object's material, a material's textures
// and the material it blends with.
std::set<NodeId> neighbourhood(const Scene& s, const std::vector<NodeId>& roots);

// The roots in the rightmost column; every other node one column left of the furthest of its
// consumers, level with the socket it feeds where the column has room. Nodes that feed none of
// the others (say, one just created) go with the roots.
NodePositions layOutNeighbourhood(const Scene& s, const std::vector<GraphNodeItem*>& nodes, const std::vector<NodeId>& roots);

// The centre of a view `view` across (scene units) over nodes that span `all`: the middle of
// `all` where it fits; where it does not, `focus` (its top-left part if it is too big itself) with
// as much of `all` around it as the view takes, never empty canvas beyond `all`'s edges.
QPointF framingCentre(const QRectF& all, const QRectF& focus, QSizeF view);

}  // namespace retile::ui
