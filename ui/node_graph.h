// The node graph: a QGraphicsView over the document drawn as nodes (textures | materials | objects,
// then camera, render settings and lights) with links for assignments (a material to an object, a
// texture to a material's albedo, roughness or alpha). The view never changes the document itself:
// every gesture that would (link, unlink, create, delete, duplicate, rename, paste, drop a node on a
// link) becomes a GraphEdit handed to the owner through editRequested, which applies it as one undo
// step and calls setDocument again. Node positions and the selection are view state, kept by id
// across refreshes.
//
// What it shows (the "Show: Selection | All" buttons in its corner): by default the selection's
// material graph, the editor's selected objects with their materials, those materials' textures
// and the materials they blend with, laid out as a small graph of its own; with nothing selected,
// or under All, every node in wrapped columns by kind. A big graph framed whole would shrink its
// text to a few pixels, so framing never zooms out past legibleZoom(): what does not fit is
// panned to, and framing keeps the selection (or the top-left corner) in view. Nodes made while
// a selection is shown (Tab, Ctrl+D, paste) join it until the selection changes.
//
// Dropping a node on a link inserts it: a lone node dragged (left button) and released with its box
// over a link whose input takes the node's output (a material over a material -> object link, a
// texture over a texture -> material link) becomes that input's source. There are no pass-through
// nodes, so the old source simply loses the link. The link is highlighted while a release would do this.
//
// Ownership: the view keeps a copy of the scene it shows (meshes are shared, so the copy is cheap)
// and owns its graphics items; items are rebuilt on every setDocument, so nothing outside the view
// holds them. GUI thread only.
#pragma once

#include <QGraphicsView>
#include <QPointer>
#include <QString>

#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

#include "graph_edit.h"
#include "retile/edit.h"

class QAbstractButton;
class QGraphicsPathItem;
class QGraphicsRectItem;
class QLabel;
class QLineEdit;

namespace retile::ui {

class GraphLinkItem;
class GraphNodeItem;
class NodeSearchPopup;

class NodeGraphView : public QGraphicsView {
  Q_OBJECT
 public:
  // Camera and render settings are singletons without a NodeId; their nodes use these.
  static constexpr NodeId kCameraNode = ~NodeId{0};
  static constexpr NodeId kSettingsNode = ~NodeId{0} - 1;

  explicit NodeGraphView(QWidget* parent = nullptr);
  ~NodeGraphView() override;

  // Brings the graph up to date with the document (call after every applied edit). Keeps node
  // positions and the selection by id; nodes seen for the first time go in a row below all the others.
  void setDocument(const Scene& scene);
  const Scene& document() const { return scene_; }
  // Forgets the remembered positions and lays everything out again (after opening a file, whose
  // ids may coincide with the old document's). Everything else held by id goes too: the selection,
  // the followed selection, an open rename and the copied materials' texture links.
  void resetLayout();
  // From the outliner or the viewport: selects the object's node (kNoNode: nothing) without emitting.
  // An object already among the selected nodes leaves the selection alone: the owner echoes
  // objectSelected back here, and that must not undo a Shift-click or break up a group drag.
  void setSelectedObject(NodeId id);
  void selectNodes(const std::vector<NodeId>& ids);  // programmatic, without emitting
  // The objects selected in the editor (viewport, outliner, or this graph through objectSelected):
  // what the Selection scope shows. A change shows and frames the new selection's material graph
  // (after the mouse button is released, when it comes from a click here); the same selection
  // again changes nothing.
  void followSelection(const std::vector<NodeId>& objects);
  enum class Scope { Selection, All };
  void setScope(Scope scope);  // what the buttons in the corner set; frames what it shows
  Scope scope() const { return scope_; }
  // The least zoom framing goes down to: node titles at least 9 pixels tall on screen.
  qreal legibleZoom() const;
  std::vector<NodeId> selectedNodes() const;
  bool hasNode(NodeId id) const;  // shown now (see the top: the Selection scope shows a few)

  // The gestures, callable from menus and tests. Each returns false when there is nothing to do or
  // the edit would be refused; otherwise it has emitted editRequested.
  // link(material, object, "material"); link(texture, material, "albedo" | "roughness" | "alpha").
  bool link(NodeId from, NodeId to, const QString& input);
  bool unlink(NodeId to, const QString& input);
  NodeId linkSource(NodeId to, const QString& input) const;  // kNoNode when the input is free
  // "Material", "Checker Texture", "Point Light", "Spot Light", "Directional Light".
  bool createNode(const QString& type, QPointF scenePos);
  static QStringList creatableTypes();
  bool deleteSelected();     // camera and settings nodes stay
  bool duplicateSelected();  // materials, objects, lights
  void copySelected();       // materials and lights
  bool paste();
  bool renameNode(NodeId id, const QString& name);
  // The id the next created node takes: the document's next id (Document::apply(AddX) reserves it,
  // so the owner need not). Several nodes made in one edit take consecutive ids from here.
  NodeId nextNewId() const { return scene_.peekNextId(); }

  QPointF nodePosition(NodeId id) const;  // scene coordinates of the node's top-left; (0, 0) if absent
  QPointF socketScenePos(NodeId id, const QString& socket, bool output) const;
  // The name drawn beside an input ("thickness" for a sheet's "roughness"); empty if it has none.
  QString socketLabel(NodeId id, const QString& input) const;

  void openNodeSearch(QPointF scenePos);  // the Tab / right-click menu
  void startRename(NodeId id);            // the F2 inline editor; nothing while one is open
  void frameSelected();                   // F (all when nothing is selected)
  void frameAll();                        // A: everything shown, as far as legibleZoom allows
  bool mouseOver() const;                 // F and A act on the graph only then

 signals:
  void editRequested(const retile::ui::GraphEdit& edit);  // the owner applies it as one undo step
  void objectSelected(quint64 id);                        // the user selected an object's node

 protected:
  bool event(QEvent* e) override;
  void keyPressEvent(QKeyEvent* e) override;
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void mouseDoubleClickEvent(QMouseEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;
  void showEvent(QShowEvent* e) override;
  void resizeEvent(QResizeEvent* e) override;
  void drawBackground(QPainter* p, const QRectF& rect) override;

 private:
  struct Link {
    NodeId from = kNoNode, to = kNoNode;
    QString input;
    GraphLinkItem* item = nullptr;
  };
  struct SocketHit {
    GraphNodeItem* node = nullptr;
    QString socket;
    bool output = false;
  };
  enum class Drag { None, Link, Move, Marquee, Pan };

  void rebuild();
  bool focused() const { return scope_ == Scope::Selection && !roots_.empty(); }
  // The positions of what is shown: the selection's graph and the whole one are laid out apart.
  std::unordered_map<NodeId, QPointF>& positions() { return focused() ? focusPositions_ : positions_; }
  bool exists(NodeId id) const;            // a material, object, light or texture of the document
  std::vector<GraphNodeItem*> addNodes();  // the items of what is shown, in column order
  void placeNodes(const std::vector<GraphNodeItem*>& order);
  void addLinks(const std::vector<GraphNodeItem*>& order);
  void buildScopeBar();
  void updateScopeBar();
  GraphNodeItem* nodeAt(QPointF scenePos) const;
  SocketHit socketAt(QPointF scenePos) const;
  const Link* linkInto(NodeId to, const QString& input) const;
  bool accepts(NodeId from, NodeId to, const QString& input) const;
  // The link the node being moved would be inserted into if released now, or null (see the top).
  const Link* insertTarget() const;
  void highlightLink(const Link* target);  // null: none; the rest are faded when away from the selection
  bool insertDropped(const Link& target);  // re-points target's input to the moved node
  void updateLinkPaths();
  void finishLinkDrag(QPointF scenePos);
  void setSelection(const std::vector<NodeId>& ids);
  // Emits the edit; `result` is the scene it makes (the EditBuilder's), shown until the owner's
  // setDocument arrives so that a second gesture before then builds on the first.
  bool request(GraphEdit edit, const Scene& result);
  // Frames `r` as closely as legibleZoom() and a cap on zooming in allow; when it does not fit,
  // `focus` is what stays in view.
  void frameRect(QRectF r, const QRectF& focus);

  Scene scene_;
  unsigned documentCount_ = 0;  // setDocument calls, to tell whether the owner refreshed synchronously
  bool hasDocument_ = false;
  bool framed_ = false;
  std::unordered_map<NodeId, GraphNodeItem*> nodes_;
  std::unordered_map<NodeId, QPointF> positions_;       // the whole graph's
  std::unordered_map<NodeId, QPointF> focusPositions_;  // the selection's graph's
  Scope scope_ = Scope::Selection;
  std::vector<NodeId> roots_;         // the editor's selected objects
  std::set<NodeId> shown_;            // what the Selection scope shows of them, and nodes made since
  std::vector<NodeId> pendingRoots_;  // a selection that arrived during a mouse gesture
  bool rootsPending_ = false;
  bool mouseDown_ = false;
  QWidget* scopeBar_ = nullptr;
  QAbstractButton* showSelection_ = nullptr;
  QAbstractButton* showAll_ = nullptr;
  QLabel* scopeNote_ = nullptr;
  std::vector<Link> links_;
  std::vector<NodeId> pendingSelection_;  // nodes an edit creates, selected once they appear

  Drag drag_ = Drag::None;
  Qt::MouseButton dragButton_ = Qt::NoButton;  // only its release ends the drag
  QPoint pressPos_, lastPos_;                  // viewport pixels
  QPointF pressScene_;
  NodeId pressedNode_ = kNoNode;
  bool moved_ = false;
  Qt::KeyboardModifiers pressModifiers_;
  std::vector<std::pair<NodeId, QPointF>> moveStart_;
  NodeId linkFrom_ = kNoNode;    // the output end of the link being dragged
  NodeId detachedTo_ = kNoNode;  // a picked-up link's old input, or kNoNode for a new link
  QString detachedInput_;
  QGraphicsPathItem* dragLink_ = nullptr;
  QGraphicsRectItem* marquee_ = nullptr;
  std::vector<NodeId> marqueeBase_;  // the selection a Shift/Ctrl marquee adds to

  NodeSearchPopup* search_ = nullptr;
  QPointF searchScenePos_;
  QPointer<QLineEdit> rename_;  // while a rename is open (null once it is closed)

  std::vector<Material> copiedMaterials_;
  std::vector<Light> copiedLights_;
  std::vector<QPointF> copiedPositions_;  // materials then lights
  int pasteCount_ = 0;
};

}  // namespace retile::ui
