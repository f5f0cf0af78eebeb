// The node graph over a document, driven the way an artist drives it: mouse drags on the viewport
// link and unlink, keys delete, duplicate, rename, copy and paste, Tab searches and creates. Each
// requested GraphEdit is applied to a Document (its afters in order) and the graph refreshed, as
// the main window does; undo is the befores in reverse order.
#include <QAbstractButton>
#include <QAction>
#include <QFontInfo>
#include <QApplication>
#include <QGraphicsPathItem>
#include <QGraphicsRectItem>
#include <QGraphicsScene>
#include <QLineEdit>
#include <QListWidget>
#include <QPainterPathStroker>
#include <QSignalSpy>
#include <QTest>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <sstream>

#include "editor_support.h"
#include "node_graph.h"
#include "retile/io.h"
#include "test_support.h"

namespace retile::ui {
namespace {

// Everything the graph can change, by id, so two scenes compare regardless of list order.
std::string describe(const Scene& s) {
  std::ostringstream out;
  auto sorted = [](auto nodes) {
    std::sort(nodes.begin(), nodes.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
    return nodes;
  };
  for (const Material& m : sorted(s.materials))
    out << "M" << m.id << " " << m.name << " " << static_cast<int>(m.type) << " " << m.albedo.x << " " << m.roughness << " "
        << m.albedoTexture << " " << m.roughnessTexture << " " << m.alphaTexture << " " << m.bumpTexture << " " << m.blendWith << "\n";
  for (const Object& o : sorted(s.objects)) out << "O" << o.id << " " << o.name << " " << o.mesh << " " << o.material << "\n";
  for (const Texture& t : sorted(s.textures)) out << "T" << t.id << " " << t.name << "\n";
  for (const Light& l : sorted(s.lights)) out << "L" << l.id << " " << l.name << "\n";
  out << "E" << static_cast<int>(s.environment.type) << " " << s.environment.map << "\n";
  return out.str();
}

template <class Node>
NodeId named(const std::vector<Node>& nodes, const std::string& name) {
  for (const Node& n : nodes)
    if (n.name == name) return n.id;
  return kNoNode;
}

class NodeGraph : public ::testing::Test {
 protected:
  void SetUp() override {
    view.resize(1000, 700);
    QObject::connect(&view, &NodeGraphView::editRequested, &view, [this](const GraphEdit& e) {
      for (const auto& [before, after] : e.steps) {
        auto r = doc.apply(after);
        EXPECT_TRUE(r.ok()) << e.text.toStdString() << ": " << (r.ok() ? std::string() : r.error());
      }
      edits.push_back(e);
      view.setDocument(doc.scene());
    });
    view.setDocument(doc.scene());
    view.show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));
  }

  void undo(const GraphEdit& e) {
    for (auto it = e.steps.rbegin(); it != e.steps.rend(); ++it) {
      auto r = doc.apply(it->first);
      EXPECT_TRUE(r.ok()) << "undo " << e.text.toStdString() << ": " << (r.ok() ? std::string() : r.error());
    }
    view.setDocument(doc.scene());
  }

  const Scene& scene() const { return doc.scene(); }
  QWidget* vp() { return view.viewport(); }
  QPoint at(QPointF scenePos) { return view.mapFromScene(scenePos); }
  QPoint header(NodeId id) { return at(view.nodePosition(id) + QPointF(95, 12)); }

  void drag(QPoint from, QPoint to, Qt::KeyboardModifiers mods = {}) {
    QTest::mousePress(vp(), Qt::LeftButton, mods, from);
    for (int i = 1; i <= 6; ++i) QTest::mouseMove(vp(), from + (to - from) * i / 6);
    QTest::mouseRelease(vp(), Qt::LeftButton, mods, to);
  }
  void click(NodeId id, Qt::KeyboardModifiers mods = {}) { QTest::mouseClick(vp(), Qt::LeftButton, mods, header(id)); }

  // The open inline rename editor (closed ones linger until their deferred delete), or null.
  QLineEdit* renameEditor() {
    QCoreApplication::processEvents();
    QLineEdit* open = nullptr;
    for (auto* e : view.findChildren<QLineEdit*>("nodeRename"))
      if (e->isVisible()) {
        EXPECT_FALSE(open) << "two rename editors open";
        open = e;
      }
    return open;
  }
  // The transient items: the dashed link that follows the mouse and the rubber band.
  bool dragLinkShown() {
    for (QGraphicsItem* i : view.scene()->items())
      if (auto* p = qgraphicsitem_cast<QGraphicsPathItem*>(i))
        if (p->isVisible() && p->pen().style() == Qt::DashLine) return true;
    return false;
  }
  // Links drawn thicker than the rest: the one a dropped node would be inserted into.
  int highlightedLinks() {
    int n = 0;
    for (QGraphicsItem* i : view.scene()->items())
      if (auto* p = qgraphicsitem_cast<QGraphicsPathItem*>(i))
        if (p->isVisible() && p->pen().style() == Qt::SolidLine && p->pen().widthF() > 3) ++n;
    return n;
  }
  // The middle of the link into `to`'s input (the curve is symmetric, so the middle of its ends).
  QPointF linkMiddle(NodeId to, const QString& input) {
    const NodeId from = view.linkSource(to, input);
    const QString output = input == "material" ? "material" : "texture";
    return (view.socketScenePos(from, output, true) + view.socketScenePos(to, input, false)) / 2;
  }
  // Inside every node's box, away from its sockets.
  QPoint body(NodeId id) { return at(view.nodePosition(id) + QPointF(95, 40)); }
  bool marqueeShown() {
    for (QGraphicsItem* i : view.scene()->items())
      if (auto* r = qgraphicsitem_cast<QGraphicsRectItem*>(i))
        if (r->isVisible()) return true;
    return false;
  }
  bool searchShown() {
    auto* search = view.findChild<QLineEdit*>("nodeSearch");
    return search && search->isVisible();
  }

  Document doc{makeDefaultScene()};
  NodeGraphView view;
  std::vector<GraphEdit> edits;
};

TEST_F(NodeGraph, LaysOutWhatFeedsWhatLeftToRightAndKeepsMovedNodesWhereTheyAre) {
  const NodeId checker = named(scene().textures, "Checker");
  const NodeId ground = named(scene().materials, "Ground");
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  for (const Material& m : scene().materials) EXPECT_TRUE(view.hasNode(m.id)) << m.name;
  for (const Object& o : scene().objects) EXPECT_TRUE(view.hasNode(o.id)) << o.name;
  EXPECT_TRUE(view.hasNode(NodeGraphView::kCameraNode));
  EXPECT_TRUE(view.hasNode(NodeGraphView::kSettingsNode));
  const NodeId checkered = named(scene().materials, "Checkered");
  const NodeId lacquer = scene().object(sphere)->material;
  EXPECT_LT(view.nodePosition(checker).x(), view.nodePosition(checkered).x()) << "a texture left of its material";
  EXPECT_LT(view.nodePosition(lacquer).x(), view.nodePosition(sphere).x()) << "a material left of its object";
  EXPECT_EQ(view.linkSource(sphere, "material"), lacquer);
  EXPECT_EQ(view.linkSource(checkered, "albedo"), checker);
  EXPECT_TRUE(view.hasNode(ground));

  // Drag the sphere's node by its header; the link follows and a refresh keeps the place.
  const QPointF before = view.nodePosition(sphere);
  drag(header(sphere), header(sphere) + QPoint(60, 30));
  const QPointF moved = view.nodePosition(sphere);
  EXPECT_GT(moved.x() - before.x(), 40);
  EXPECT_GT(moved.y() - before.y(), 20);
  EXPECT_TRUE(edits.empty()) << "moving a node is view state, not an edit";
  view.setDocument(scene());
  EXPECT_EQ(view.nodePosition(sphere), moved);
}

TEST_F(NodeGraph, DraggingSocketsLinksAndDraggingTheLinkOffUnlinks) {
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  const NodeId steel = named(scene().materials, "Brushed Steel");
  const NodeId lacquer = scene().object(sphere)->material;
  ASSERT_NE(steel, lacquer);

  drag(at(view.socketScenePos(steel, "material", true)), at(view.socketScenePos(sphere, "material", false)));
  ASSERT_EQ(edits.size(), 1u);
  EXPECT_EQ(scene().object(sphere)->material, steel) << "material output onto the object's input assigns it";
  EXPECT_EQ(view.linkSource(sphere, "material"), steel);

  // Pick the link up by its input end and drop it on empty space between the columns.
  const QPoint input = at(view.socketScenePos(sphere, "material", false));
  drag(input, input + QPoint(-40, 0));
  ASSERT_EQ(edits.size(), 2u);
  EXPECT_EQ(scene().object(sphere)->material, kNoNode) << "dragging a link off unlinks";
  EXPECT_EQ(view.linkSource(sphere, "material"), kNoNode);
  undo(edits.back());
  EXPECT_EQ(scene().object(sphere)->material, steel);

  // A texture onto a material's roughness input.
  const NodeId checker = named(scene().textures, "Checker");
  const NodeId ground = named(scene().materials, "Ground");
  drag(at(view.socketScenePos(checker, "texture", true)), at(view.socketScenePos(ground, "roughness", false)));
  EXPECT_EQ(scene().material(ground)->roughnessTexture, checker);
  EXPECT_EQ(scene().material(ground)->albedoTexture, kNoNode);

  // Moving a link's input end to another input is one step: roughness to alpha.
  drag(at(view.socketScenePos(ground, "roughness", false)), at(view.socketScenePos(ground, "alpha", false)));
  EXPECT_EQ(scene().material(ground)->roughnessTexture, kNoNode);
  EXPECT_EQ(scene().material(ground)->alphaTexture, checker);
  EXPECT_EQ(edits.back().steps.size(), 2u);
  undo(edits.back());
  EXPECT_EQ(scene().material(ground)->roughnessTexture, checker);
  EXPECT_EQ(scene().material(ground)->alphaTexture, kNoNode);

  // And to the bump input, below alpha.
  drag(at(view.socketScenePos(ground, "roughness", false)), at(view.socketScenePos(ground, "bump", false)));
  EXPECT_EQ(scene().material(ground)->roughnessTexture, kNoNode);
  EXPECT_EQ(scene().material(ground)->bumpTexture, checker);
  EXPECT_EQ(view.linkSource(ground, "bump"), checker);
  undo(edits.back());
  EXPECT_EQ(scene().material(ground)->bumpTexture, kNoNode);

  // Dropping a material on a texture input is refused: no edit.
  const std::size_t count = edits.size();
  drag(at(view.socketScenePos(steel, "material", true)), at(view.socketScenePos(ground, "albedo", false)));
  EXPECT_EQ(edits.size(), count);
  EXPECT_FALSE(view.link(steel, ground, "albedo"));
  EXPECT_FALSE(view.link(steel, sphere, "material")) << "already linked: nothing to do";
}

TEST_F(NodeGraph, AMaterialOntoAnothersBlendInputBlendsThem) {
  const NodeId steel = named(scene().materials, "Brushed Steel");
  const NodeId ground = named(scene().materials, "Ground");
  drag(at(view.socketScenePos(steel, "material", true)), at(view.socketScenePos(ground, "blend", false)));
  ASSERT_EQ(edits.size(), 1u);
  EXPECT_EQ(scene().material(ground)->blendWith, steel);
  EXPECT_FLOAT_EQ(scene().material(ground)->blendRatio, 0.5f) << "half and half to start with";
  EXPECT_EQ(view.linkSource(ground, "blend"), steel);
  EXPECT_FALSE(view.link(ground, ground, "blend")) << "not with itself";
  EXPECT_FALSE(view.link(named(scene().textures, "Checker"), ground, "blend")) << "a texture is no material";
  // Deleting the partner ends the blend, and undoing brings both back.
  const Scene before = scene();
  view.selectNodes({steel});
  QTest::keyClick(&view, Qt::Key_Delete);
  ASSERT_EQ(edits.size(), 2u);
  EXPECT_FALSE(scene().material(steel));
  EXPECT_EQ(scene().material(ground)->blendWith, kNoNode);
  undo(edits.back());
  EXPECT_EQ(describe(scene()), describe(before));
}

TEST_F(NodeGraph, ABoundaryHasNoInputs) {
  // A boundary is no surface (Tungsten's forward bsdf): no texture or blend would change it, so
  // its node shows no sockets for them and takes no link into one.
  const NodeId ground = named(scene().materials, "Ground");
  const NodeId checker = named(scene().textures, "Checker");
  EXPECT_NE(view.socketScenePos(ground, "albedo", false), view.nodePosition(ground)) << "a surface has its inputs";
  Material boundary = *scene().material(ground);
  boundary.type = MaterialType::Boundary;
  ASSERT_TRUE(doc.apply(SetMaterial{boundary}).ok());
  view.setDocument(doc.scene());
  EXPECT_EQ(view.socketScenePos(ground, "albedo", false), view.nodePosition(ground)) << "no albedo socket";
  EXPECT_EQ(view.socketScenePos(ground, "blend", false), view.nodePosition(ground)) << "no blend socket";
  EXPECT_FALSE(view.link(checker, ground, "albedo"));
  EXPECT_FALSE(view.link(named(scene().materials, "Brushed Steel"), ground, "blend"));
  EXPECT_TRUE(edits.empty());
}

// A material node offers the inputs its type reads: a lambert has no roughness for a texture to
// scale, so no socket for one, and no link is taken there. One its type stopped reading but that
// still holds a texture stays, so the link can be seen and taken off.
TEST_F(NodeGraph, AMaterialShowsTheInputsItsTypeReads) {
  const NodeId lambert = named(scene().materials, "Checkered");
  const NodeId rough = named(scene().materials, "Ground");
  const NodeId checker = named(scene().textures, "Checker");
  ASSERT_EQ(scene().material(lambert)->type, MaterialType::Lambert);
  ASSERT_EQ(scene().material(rough)->type, MaterialType::RoughPlastic);
  auto hasSocket = [&](NodeId id, const char* input) { return view.socketScenePos(id, input, false) != view.nodePosition(id); };
  EXPECT_FALSE(hasSocket(lambert, "roughness"));
  EXPECT_TRUE(hasSocket(lambert, "albedo"));
  EXPECT_TRUE(hasSocket(lambert, "bump"));
  EXPECT_TRUE(hasSocket(lambert, "blend"));
  EXPECT_FALSE(view.link(checker, lambert, "roughness"));
  EXPECT_TRUE(edits.empty());

  EXPECT_TRUE(hasSocket(rough, "roughness"));
  ASSERT_TRUE(view.link(checker, rough, "roughness"));
  Material changed = *scene().material(rough);
  changed.type = MaterialType::Lambert;
  ASSERT_TRUE(doc.apply(SetMaterial{changed}).ok());
  view.setDocument(doc.scene());
  EXPECT_TRUE(hasSocket(rough, "roughness")) << "its texture is still there";
  EXPECT_EQ(view.linkSource(rough, "roughness"), checker);
  ASSERT_TRUE(view.unlink(rough, "roughness"));
  EXPECT_EQ(scene().material(rough)->roughnessTexture, kNoNode);
  EXPECT_FALSE(hasSocket(rough, "roughness"));
  EXPECT_FALSE(view.link(checker, rough, "roughness"));
}

// A sheet has no roughness; its "roughness" texture is read as its thickness, and the node says
// so, while the socket keeps its name (links, the API).
TEST_F(NodeGraph, ASheetsRoughnessInputIsShownAsItsThickness) {
  const NodeId ground = named(scene().materials, "Ground");
  const NodeId checker = named(scene().textures, "Checker");
  EXPECT_EQ(view.socketLabel(ground, "roughness"), "roughness");
  Material sheet = *scene().material(ground);
  sheet.type = MaterialType::ThinSheet;
  ASSERT_TRUE(doc.apply(SetMaterial{sheet}).ok());
  view.setDocument(doc.scene());
  EXPECT_EQ(view.socketLabel(ground, "roughness"), "thickness");
  EXPECT_EQ(view.socketLabel(ground, "albedo"), "albedo");
  EXPECT_TRUE(view.link(checker, ground, "roughness"));
}

TEST_F(NodeGraph, DeleteRemovesTheSelectionAndTheBeforesRestoreEveryReference) {
  const Scene original = scene();
  const NodeId lacquer = named(scene().materials, "Red Lacquer");
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  click(lacquer);
  EXPECT_EQ(view.selectedNodes(), std::vector<NodeId>{lacquer});
  QTest::keyClick(&view, Qt::Key_Delete);
  ASSERT_EQ(edits.size(), 1u);
  EXPECT_FALSE(scene().material(lacquer));
  EXPECT_EQ(scene().object(sphere)->material, kNoNode);
  EXPECT_FALSE(view.hasNode(lacquer));
  undo(edits.back());
  EXPECT_EQ(describe(scene()), describe(original));
  EXPECT_EQ(view.linkSource(sphere, "material"), lacquer);

  // A texture and a material together, marquee-selected with the camera: the camera stays.
  const NodeId checker = named(scene().textures, "Checker");
  const NodeId checkered = named(scene().materials, "Checkered");
  view.selectNodes({checker, checkered, NodeGraphView::kCameraNode});
  QTest::keyClick(&view, Qt::Key_Delete);
  ASSERT_EQ(edits.size(), 2u);
  EXPECT_FALSE(scene().texture(checker));
  EXPECT_FALSE(scene().material(checkered));
  EXPECT_TRUE(view.hasNode(NodeGraphView::kCameraNode));
  undo(edits.back());
  EXPECT_EQ(describe(scene()), describe(original));

  view.selectNodes({NodeGraphView::kCameraNode, NodeGraphView::kSettingsNode});
  QTest::keyClick(&view, Qt::Key_Delete);
  EXPECT_EQ(edits.size(), 2u) << "camera and settings cannot be deleted";
}

TEST_F(NodeGraph, TabSearchCreatesNodesWithUnusedIds) {
  const std::size_t materials = scene().materials.size();
  const NodeId expected = scene().peekNextId();
  QTest::keyClick(&view, Qt::Key_Tab);
  auto* search = view.findChild<QLineEdit*>("nodeSearch");
  ASSERT_TRUE(search);
  EXPECT_TRUE(search->isVisible());
  QTest::keyClicks(search, "mat");
  auto* list = view.findChild<QListWidget*>("nodeSearchList");
  ASSERT_TRUE(list);
  int shown = 0;
  for (int i = 0; i < list->count(); ++i) shown += list->item(i)->isHidden() ? 0 : 1;
  EXPECT_EQ(shown, 1) << "the filter leaves only Material";
  QTest::keyClick(search, Qt::Key_Return);
  EXPECT_FALSE(search->isVisible());
  ASSERT_EQ(scene().materials.size(), materials + 1);
  const Material& made = scene().materials.back();
  EXPECT_EQ(made.id, expected);
  EXPECT_EQ(made.name, "Material");
  EXPECT_TRUE(view.hasNode(made.id));
  EXPECT_EQ(view.selectedNodes(), std::vector<NodeId>{made.id}) << "the new node is selected";

  // Right-click opens the same menu where the node will go; arrows pick among the matches.
  const QPoint where = vp()->rect().center();
  QTest::mouseClick(vp(), Qt::RightButton, {}, where);
  ASSERT_TRUE(search->isVisible());
  QTest::keyClicks(search, "light");
  QTest::keyClick(search, Qt::Key_Down);  // Light -> Spot Light
  QTest::keyClick(search, Qt::Key_Return);
  ASSERT_EQ(scene().lights.size(), 1u);
  EXPECT_EQ(scene().lights[0].type, LightType::Spot);
  EXPECT_GT(scene().lights[0].id, made.id);
  EXPECT_LT(QLineF(view.nodePosition(scene().lights[0].id), view.mapToScene(where)).length(), 2.0);

  const std::size_t count = edits.size();
  undo(edits.back());
  EXPECT_TRUE(scene().lights.empty());
  EXPECT_FALSE(view.createNode("Teapot", {}));
  EXPECT_EQ(edits.size(), count);
}

TEST_F(NodeGraph, F2RenamesInPlace) {
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  view.setSelectedObject(sphere);
  QTest::keyClick(&view, Qt::Key_F2);
  auto* editor = view.findChild<QLineEdit*>("nodeRename");
  ASSERT_TRUE(editor);
  EXPECT_EQ(editor->text(), "Glossy Sphere");
  editor->selectAll();
  QTest::keyClicks(editor, "Hero Sphere");
  QTest::keyClick(editor, Qt::Key_Return);
  ASSERT_EQ(edits.size(), 1u);
  EXPECT_EQ(scene().object(sphere)->name, "Hero Sphere");
  undo(edits.back());
  EXPECT_EQ(scene().object(sphere)->name, "Glossy Sphere");

  // Escape leaves the name alone.
  QTest::keyClick(&view, Qt::Key_F2);
  QCoreApplication::processEvents();
  editor = nullptr;
  for (auto* e : view.findChildren<QLineEdit*>("nodeRename"))
    if (e->isVisible()) editor = e;
  ASSERT_TRUE(editor);
  QTest::keyClicks(editor, "Oops");
  QTest::keyClick(editor, Qt::Key_Escape);
  EXPECT_EQ(edits.size(), 1u);
  EXPECT_EQ(scene().object(sphere)->name, "Glossy Sphere");
}

TEST_F(NodeGraph, ClickShiftAndCtrlSelectAndCtrlDDuplicates) {
  const NodeId lacquer = named(scene().materials, "Red Lacquer");
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  const NodeId cup = named(scene().objects, "Cup");
  QSignalSpy picked(&view, &NodeGraphView::objectSelected);
  click(cup);
  ASSERT_EQ(picked.count(), 1);
  EXPECT_EQ(picked.front().front().toULongLong(), cup);
  click(lacquer);
  EXPECT_EQ(view.selectedNodes(), std::vector<NodeId>{lacquer}) << "a click replaces the selection";
  click(sphere, Qt::ShiftModifier);
  click(cup, Qt::ShiftModifier);
  EXPECT_EQ(view.selectedNodes().size(), 3u) << "Shift adds";
  click(cup, Qt::ControlModifier);
  EXPECT_EQ(view.selectedNodes().size(), 2u) << "Ctrl toggles";
  view.setSelectedObject(cup);
  EXPECT_EQ(picked.count(), 3) << "selection from elsewhere does not echo back";
  view.selectNodes({lacquer, sphere});

  const NodeId next = scene().peekNextId();
  QTest::keyClick(&view, Qt::Key_D, Qt::ControlModifier);
  ASSERT_EQ(edits.size(), 1u);
  const NodeId lacquerCopy = named(scene().materials, "Red Lacquer.001");
  const NodeId sphereCopy = named(scene().objects, "Glossy Sphere.001");
  ASSERT_NE(lacquerCopy, kNoNode);
  ASSERT_NE(sphereCopy, kNoNode);
  EXPECT_GE(std::min(lacquerCopy, sphereCopy), next) << "new ids";
  EXPECT_NE(lacquerCopy, sphereCopy);
  EXPECT_EQ(scene().object(sphereCopy)->material, lacquer) << "a duplicated object keeps its material";
  EXPECT_EQ(scene().object(sphereCopy)->mesh, scene().object(sphere)->mesh);
  std::vector<NodeId> copies{lacquerCopy, sphereCopy};
  std::sort(copies.begin(), copies.end());
  EXPECT_EQ(view.selectedNodes(), copies) << "the copies are selected";
  EXPECT_EQ(view.nodePosition(sphereCopy), view.nodePosition(sphere) + QPointF(30, 30));
  undo(edits.back());
  EXPECT_FALSE(scene().material(lacquerCopy));
  EXPECT_FALSE(scene().object(sphereCopy));
}

TEST_F(NodeGraph, MarqueeSelectsAndFAndAFrame) {
  const NodeId checker = named(scene().textures, "Checker");
  const QPointF p = view.nodePosition(checker);
  drag(at(p + QPointF(-30, -15)), at(p + QPointF(100, 30)));
  EXPECT_EQ(view.selectedNodes(), std::vector<NodeId>{checker}) << "the rubber band selects what it touches";
  const NodeId ground = named(scene().materials, "Ground");
  const QPointF g = view.nodePosition(ground);
  drag(at(g + QPointF(-20, -10)), at(g + QPointF(40, 20)), Qt::ShiftModifier);
  EXPECT_EQ(view.selectedNodes().size(), 2u) << "Shift + rubber band adds";

  view.selectNodes({checker});
  const qreal zoomAll = view.transform().m11();
  QTest::keyClick(&view, Qt::Key_F);
  EXPECT_GT(view.transform().m11(), zoomAll * 1.2) << "framing one node zooms in";
  const QPoint centre = at(p + QPointF(95, 30));
  EXPECT_LT((centre - vp()->rect().center()).manhattanLength(), 20) << "around it";

  view.resize(1400, 1000);  // room for the whole graph at a legible zoom (else A keeps the selection in view)
  QTest::keyClick(&view, Qt::Key_A);
  const QRectF visible = view.mapToScene(vp()->rect()).boundingRect();
  for (const Object& o : scene().objects) EXPECT_TRUE(visible.contains(view.nodePosition(o.id))) << o.name;
  EXPECT_TRUE(visible.contains(view.nodePosition(NodeGraphView::kSettingsNode)));
}

TEST_F(NodeGraph, CopyPasteMakesCopiesWithNewIds) {
  const NodeId ceramic = named(scene().materials, "Ceramic");
  click(ceramic);
  QTest::keyClick(&view, Qt::Key_C, Qt::ControlModifier);
  QTest::keyClick(&view, Qt::Key_V, Qt::ControlModifier);
  QTest::keyClick(&view, Qt::Key_V, Qt::ControlModifier);
  ASSERT_EQ(edits.size(), 2u);
  const NodeId a = named(scene().materials, "Ceramic.001"), b = named(scene().materials, "Ceramic.002");
  ASSERT_NE(a, kNoNode);
  ASSERT_NE(b, kNoNode);
  EXPECT_NE(a, b);
  EXPECT_EQ(scene().material(a)->type, scene().material(ceramic)->type);
  EXPECT_NE(view.nodePosition(a), view.nodePosition(b)) << "pastes do not stack on each other";
}

TEST_F(NodeGraph, RenameEditorKeepsItsKeysFromTheGraphAndTheWindow) {
  // The main window pauses the render on Escape; the editor's Escape and Return are its own.
  view.activateWindow();
  ASSERT_TRUE(QTest::qWaitForWindowActive(&view));
  QAction pause, other;
  pause.setShortcut(Qt::Key_Escape);
  other.setShortcut(Qt::Key_Return);
  view.addAction(&pause);
  view.addAction(&other);
  QSignalSpy paused(&pause, &QAction::triggered), returned(&other, &QAction::triggered);
  QTest::keyClick(&view, Qt::Key_Escape);
  ASSERT_EQ(paused.count(), 1) << "the window shortcut works outside the editor";

  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  view.setSelectedObject(sphere);
  QTest::keyClick(&view, Qt::Key_F2);
  QLineEdit* editor = renameEditor();
  ASSERT_TRUE(editor);
  QTest::keyClicks(editor, "Oops");
  QTest::keyClick(editor, Qt::Key_D, Qt::ControlModifier);
  EXPECT_TRUE(edits.empty()) << "Ctrl+D in the editor does not duplicate the node";
  QTest::keyClick(editor, Qt::Key_F2);
  EXPECT_EQ(renameEditor(), editor) << "F2 in the editor does not restart the rename";
  EXPECT_EQ(QApplication::focusWidget(), editor);
  QTest::keyClick(editor, Qt::Key_Escape);
  EXPECT_EQ(paused.count(), 1) << "Escape cancels the rename instead of pausing";
  EXPECT_FALSE(renameEditor());
  EXPECT_TRUE(edits.empty());
  EXPECT_EQ(scene().object(sphere)->name, "Glossy Sphere");

  QTest::keyClick(&view, Qt::Key_F2);
  editor = renameEditor();
  ASSERT_TRUE(editor);
  editor->selectAll();
  QTest::keyClicks(editor, "Hero Sphere");
  QTest::keyClick(editor, Qt::Key_Return);
  EXPECT_EQ(returned.count(), 0) << "Return commits the rename";
  ASSERT_EQ(edits.size(), 1u);
  EXPECT_EQ(scene().object(sphere)->name, "Hero Sphere");
  EXPECT_FALSE(renameEditor());
}

TEST_F(NodeGraph, AnOwnerEchoingTheObjectSelectionKeepsAMultiSelection) {
  // The main window answers objectSelected with setSelectedObject, as for the outliner and viewport.
  QObject::connect(&view, &NodeGraphView::objectSelected, &view, [this](quint64 id) { view.setSelectedObject(static_cast<NodeId>(id)); });
  const NodeId lacquer = named(scene().materials, "Red Lacquer");
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  const NodeId cup = named(scene().objects, "Cup");
  click(lacquer);
  click(sphere, Qt::ShiftModifier);
  std::vector<NodeId> pair{lacquer, sphere};
  std::sort(pair.begin(), pair.end());
  EXPECT_EQ(view.selectedNodes(), pair) << "Shift-click on an object node adds it";

  // Dragging the group by the object's node moves both.
  const QPointF lacquerAt = view.nodePosition(lacquer), sphereAt = view.nodePosition(sphere);
  drag(header(sphere), header(sphere) + QPoint(60, 40));
  EXPECT_EQ(view.selectedNodes(), pair);
  EXPECT_GT(view.nodePosition(sphere).x() - sphereAt.x(), 40);
  EXPECT_GT(view.nodePosition(lacquer).x() - lacquerAt.x(), 40) << "the material moves with the object";

  // From elsewhere, an object not in the selection still replaces it.
  view.setSelectedObject(cup);
  EXPECT_EQ(view.selectedNodes(), std::vector<NodeId>{cup});
  view.setSelectedObject(kNoNode);
  EXPECT_TRUE(view.selectedNodes().empty());
}

TEST_F(NodeGraph, ASecondButtonDuringADragDoesNotEndOrLeaveIt) {
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  const NodeId steel = named(scene().materials, "Brushed Steel");
  const QPoint from = at(view.socketScenePos(steel, "material", true));
  const QPoint to = at(view.socketScenePos(sphere, "material", false));
  const QPoint mid = (from + to) / 2;
  QTest::mousePress(vp(), Qt::LeftButton, {}, from);
  QTest::mouseMove(vp(), mid);
  QTest::mousePress(vp(), Qt::RightButton, {}, mid);
  QTest::mouseRelease(vp(), Qt::RightButton, {}, mid);
  EXPECT_FALSE(searchShown()) << "no node menu in the middle of a link drag";
  EXPECT_TRUE(dragLinkShown()) << "the link is still being dragged";
  QTest::mouseMove(vp(), to);
  QTest::mouseRelease(vp(), Qt::LeftButton, {}, to);
  EXPECT_FALSE(dragLinkShown());
  ASSERT_EQ(edits.size(), 1u);
  EXPECT_EQ(scene().object(sphere)->material, steel) << "the left release still links";

  // A drag whose release never arrived (a modal dialog took it) ends at the next press of its button.
  const NodeId lacquer = named(scene().materials, "Red Lacquer");
  QTest::mousePress(vp(), Qt::LeftButton, {}, at(view.socketScenePos(lacquer, "material", true)));
  QTest::mouseMove(vp(), mid);
  ASSERT_TRUE(dragLinkShown());
  QTest::mousePress(vp(), Qt::LeftButton, {}, header(sphere));
  EXPECT_FALSE(dragLinkShown()) << "the stale link drag is dropped";
  QTest::mouseRelease(vp(), Qt::LeftButton, {}, header(sphere));
  EXPECT_EQ(edits.size(), 1u) << "without linking";
  EXPECT_EQ(view.selectedNodes(), std::vector<NodeId>{sphere}) << "the new press is a click on the sphere";
}

TEST_F(NodeGraph, AMiddleClickDuringARubberBandNeitherPansNorEndsIt) {
  const NodeId checker = named(scene().textures, "Checker");
  const QPointF p = view.nodePosition(checker);
  const QPoint a = at(p + QPointF(-30, -15)), b = at(p + QPointF(100, 30));
  const QTransform t = view.viewportTransform();
  QTest::mousePress(vp(), Qt::LeftButton, {}, a);
  QTest::mouseMove(vp(), (a + b) / 2);
  QTest::mousePress(vp(), Qt::MiddleButton, {}, (a + b) / 2);
  QTest::mouseMove(vp(), b);
  QTest::mouseRelease(vp(), Qt::MiddleButton, {}, b);
  EXPECT_EQ(view.viewportTransform().dx(), t.dx()) << "no pan";
  EXPECT_EQ(view.viewportTransform().dy(), t.dy()) << "no pan";
  EXPECT_TRUE(marqueeShown());
  QTest::mouseRelease(vp(), Qt::LeftButton, {}, b);
  EXPECT_FALSE(marqueeShown());
  EXPECT_EQ(view.selectedNodes(), std::vector<NodeId>{checker});
}

TEST_F(NodeGraph, GesturesBeforeTheOwnersQueuedRefreshBuildOnEachOther) {
  // The main window refreshes the graph through a queued call; so does this owner.
  QObject::disconnect(&view, &NodeGraphView::editRequested, nullptr, nullptr);
  QObject::connect(&view, &NodeGraphView::editRequested, &view, [this](const GraphEdit& e) {
    for (const auto& [before, after] : e.steps) {
      auto r = doc.apply(after);
      EXPECT_TRUE(r.ok()) << e.text.toStdString() << ": " << (r.ok() ? std::string() : r.error());
    }
    edits.push_back(e);
    QMetaObject::invokeMethod(
        &view, [this] { view.setDocument(doc.scene()); }, Qt::QueuedConnection);
  });
  const std::size_t materials = scene().materials.size();
  ASSERT_TRUE(view.createNode("Material", {0, 0}));
  ASSERT_TRUE(view.createNode("Material", {0, 300}));
  ASSERT_EQ(scene().materials.size(), materials + 2) << "the second node took a fresh id";
  const Material& first = scene().materials[materials];
  const Material& second = scene().materials[materials + 1];
  EXPECT_NE(first.id, second.id);
  EXPECT_NE(first.name, second.name);
  const NodeId made = second.id;

  // The second rename's before is the first's after: undoing it alone brings the first back.
  ASSERT_TRUE(view.renameNode(made, "First"));
  ASSERT_TRUE(view.renameNode(made, "Second"));
  EXPECT_EQ(scene().material(made)->name, "Second");
  ASSERT_EQ(edits.back().steps.size(), 1u);
  ASSERT_TRUE(doc.apply(edits.back().steps.front().first).ok());
  EXPECT_EQ(scene().material(made)->name, "First");

  QCoreApplication::processEvents();
  EXPECT_EQ(describe(view.document()), describe(scene()));
  EXPECT_TRUE(view.hasNode(made));
  EXPECT_EQ(view.nodePosition(made), QPointF(0, 300));
}

TEST_F(NodeGraph, OpeningAnotherFileForgetsTheOldDocumentsIds) {
  // Copy a textured material, keep a selection and a rename open, then open a file whose ids coincide.
  const NodeId checkered = named(scene().materials, "Checkered");
  const NodeId checker = named(scene().textures, "Checker");
  ASSERT_EQ(scene().material(checkered)->albedoTexture, checker);
  view.activateWindow();
  ASSERT_TRUE(QTest::qWaitForWindowActive(&view));
  click(checkered);
  QTest::keyClick(&view, Qt::Key_C, Qt::ControlModifier);
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  view.selectNodes({checkered, sphere});
  QTest::keyClick(&view, Qt::Key_F2);
  QLineEdit* editor = renameEditor();
  ASSERT_TRUE(editor);
  QTest::keyClicks(editor, "Typed before opening");

  Scene other = makeDefaultScene();
  for (Texture& t : other.textures)
    if (t.id == checker) t.name = "Bricks";  // another file's texture that happens to share the id
  doc = Document(std::move(other));
  view.setDocument(doc.scene());  // what MainWindow::replaceDocument does
  view.resetLayout();
  EXPECT_TRUE(view.selectedNodes().empty()) << "the old selection's ids mean other nodes now";
  EXPECT_FALSE(renameEditor()) << "the rename was of the old document's node";
  view.setFocus();
  QCoreApplication::processEvents();
  EXPECT_TRUE(edits.empty()) << "nothing renamed in the new document";

  // The copied material pastes into the new file, without the old file's texture.
  ASSERT_TRUE(view.paste());
  const NodeId pasted = named(scene().materials, "Checkered.001");
  ASSERT_NE(pasted, kNoNode);
  EXPECT_EQ(scene().material(pasted)->albedoTexture, kNoNode);
}

TEST_F(NodeGraph, DroppingANodeOnALinkItFitsInsertsIt) {
  const Scene original = scene();
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  const NodeId steel = named(scene().materials, "Brushed Steel");
  const NodeId lacquer = scene().object(sphere)->material;
  const NodeId panel = named(scene().objects, "Steel Panel");
  ASSERT_NE(lacquer, steel);
  ASSERT_EQ(scene().object(panel)->material, steel);

  // Carry the steel material onto the lacquer -> sphere link: the link lights up before the release.
  const QPoint from = body(steel), to = at(linkMiddle(sphere, "material"));
  QTest::mousePress(vp(), Qt::LeftButton, {}, from);
  for (int i = 1; i <= 6; ++i) QTest::mouseMove(vp(), from + (to - from) * i / 6);
  EXPECT_EQ(highlightedLinks(), 1) << "the link the node would go into stands out";
  QTest::mouseRelease(vp(), Qt::LeftButton, {}, to);
  EXPECT_EQ(highlightedLinks(), 0);
  ASSERT_EQ(edits.size(), 1u);
  EXPECT_EQ(edits.back().text, "Insert Brushed Steel into Glossy Sphere.material");
  EXPECT_EQ(edits.back().steps.size(), 1u);
  EXPECT_EQ(scene().object(sphere)->material, steel) << "the link's input now takes the dropped node";
  EXPECT_EQ(view.linkSource(sphere, "material"), steel);
  EXPECT_EQ(scene().object(panel)->material, steel) << "the node's own links stay";
  EXPECT_LT(QLineF(view.mapToScene(body(steel)), view.mapToScene(to)).length(), 4.0) << "it stays where dropped";
  undo(edits.back());
  EXPECT_EQ(describe(scene()), describe(original));
  EXPECT_EQ(view.linkSource(sphere, "material"), lacquer);

  // A texture onto a texture -> material link; a new checker, since the one there is the link's source.
  const NodeId checker = named(scene().textures, "Checker");
  const NodeId checkered = named(scene().materials, "Checkered");
  ASSERT_EQ(view.linkSource(checkered, "albedo"), checker);
  // Below it, in the clear.
  ASSERT_TRUE(view.createNode("Checker Texture", view.nodePosition(checker) + QPointF(0, 200)));
  const NodeId made = scene().textures.back().id;
  drag(body(made), at(linkMiddle(checkered, "albedo")));
  ASSERT_EQ(edits.size(), 3u);
  EXPECT_EQ(scene().material(checkered)->albedoTexture, made);
  EXPECT_EQ(edits.back().text, "Insert Checker.001 into Checkered.albedo");

  // The source of the link it is dropped on has nothing to insert.
  drag(body(made), body(made) + QPoint(10, 10));
  EXPECT_EQ(edits.size(), 3u);
}

TEST_F(NodeGraph, DroppingANodeOnALinkThatDoesNotTakeItOnlyMovesIt) {
  const Scene original = scene();
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  const NodeId checker = named(scene().textures, "Checker");
  const QPoint from = body(checker), to = at(linkMiddle(sphere, "material"));
  QTest::mousePress(vp(), Qt::LeftButton, {}, from);
  for (int i = 1; i <= 6; ++i) QTest::mouseMove(vp(), from + (to - from) * i / 6);
  EXPECT_EQ(highlightedLinks(), 0) << "a texture does not fit an object's material input";
  QTest::mouseRelease(vp(), Qt::LeftButton, {}, to);
  EXPECT_TRUE(edits.empty());
  EXPECT_EQ(describe(scene()), describe(original));
  EXPECT_LT(QLineF(view.mapToScene(body(checker)), view.mapToScene(to)).length(), 4.0) << "but it moved";
}

TEST_F(NodeGraph, DraggingASelectionOverALinkOnlyMovesIt) {
  const Scene original = scene();
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  const NodeId steel = named(scene().materials, "Brushed Steel");
  const NodeId cup = named(scene().objects, "Cup");
  ASSERT_LT(steel, cup) << "steel leads the selection, so inserting 'the first moved node' would insert it";
  click(cup);
  click(steel, Qt::ShiftModifier);
  ASSERT_EQ(view.selectedNodes().size(), 2u);
  const QPointF cupAt = view.nodePosition(cup);
  const QPoint from = body(steel), to = at(linkMiddle(sphere, "material"));
  QTest::mousePress(vp(), Qt::LeftButton, {}, from);
  for (int i = 1; i <= 6; ++i) QTest::mouseMove(vp(), from + (to - from) * i / 6);
  EXPECT_EQ(highlightedLinks(), 0) << "a group is not inserted";
  QTest::mouseRelease(vp(), Qt::LeftButton, {}, to);
  EXPECT_TRUE(edits.empty());
  EXPECT_EQ(describe(scene()), describe(original));
  EXPECT_LT(QLineF(view.mapToScene(body(steel)), view.mapToScene(to)).length(), 4.0);
  EXPECT_NE(view.nodePosition(cup), cupAt) << "the whole selection moved";
}

// The living room as a new user met it (issue 60, point 12): a window of 1600 x 1000 with the
// graph in its dock along the bottom, about 230 pixels high.
class NodeGraphArtist : public ::testing::Test {
 protected:
  void SetUp() override {
    window.resize(1600, 1000);
    view = new NodeGraphView(&window);
    view->setGeometry(0, 1000 - 230, 1600, 230);
  }
  // False (the test then skips) when ../shared is absent.
  bool openLivingRoom() {
    const auto file = retile::test::sharedPath("scenes/living-room/scene.json");
    if (file.empty()) return false;
    auto imported = importScene(file);
    EXPECT_TRUE(imported.ok());
    if (!imported.ok()) return false;
    room = imported.value().scene;
    view->setDocument(room);
    window.show();
    EXPECT_TRUE(QTest::qWaitForWindowExposed(&window));
    return true;
  }
  // How tall the nodes' titles are on screen, in pixels (the painter draws them in the view's font).
  double titlePixels() const { return QFontInfo(view->font()).pixelSize() * view->transform().m11(); }
  QRectF visible() const { return view->mapToScene(view->viewport()->rect()).boundingRect(); }
  // Every link's curve keeps off the boxes of the nodes it does not join.
  void expectNoLinkCrossesANode(const char* where) {
    QPainterPathStroker stroker;
    stroker.setWidth(1);
    int links = 0;
    for (QGraphicsItem* i : view->scene()->items()) {
      auto* link = qgraphicsitem_cast<QGraphicsPathItem*>(i);
      if (!link || !link->isVisible() || link->pen().style() != Qt::SolidLine) continue;
      ++links;
      const QPainterPath stroke = stroker.createStroke(link->path());
      const QPointF ends[] = {link->path().pointAtPercent(0), link->path().pointAtPercent(1)};
      for (QGraphicsItem* n : view->scene()->items()) {
        if (n->type() != QGraphicsItem::UserType + 1) continue;
        const QRectF box = n->mapRectToScene(QRectF(0, 0, 190, n->boundingRect().height() - 4));
        const QRectF near = box.adjusted(-8, -8, 8, 8);
        if (near.contains(ends[0]) || near.contains(ends[1])) continue;  // a node the link joins
        EXPECT_FALSE(stroke.intersects(box)) << where << ": a link from " << ends[0].x() << ", " << ends[0].y() << " to " << ends[1].x()
                                             << ", " << ends[1].y() << " crosses the node at " << box.x() << ", " << box.y();
      }
    }
    EXPECT_GT(links, 0) << where;
  }
  // With RETILE_GRAPH_SHOTS=DIR, what the graph shows is saved there for a person to look at.
  void shoot(const char* name) {
    if (const char* dir = std::getenv("RETILE_GRAPH_SHOTS")) view->grab().save(QString::fromLocal8Bit(dir) + "/" + name + ".png");
  }

  QWidget window;
  NodeGraphView* view = nullptr;
  Scene room;
};

// 1. Framing all ~90 nodes shrank their text to 5 pixels: framing stops at a legible zoom.
TEST_F(NodeGraphArtist, TheLivingRoomsGraphIsLegibleByDefault) {
  if (!openLivingRoom()) GTEST_SKIP() << "skipped: ../shared/scenes/living-room is not present";
  shoot("living-room-default");
  EXPECT_GE(titlePixels(), 9.0) << "as opened";
  view->frameAll();
  EXPECT_GE(titlePixels(), 9.0) << "after A";
  view->setScope(NodeGraphView::Scope::All);
  EXPECT_GE(titlePixels(), 9.0) << "showing everything";
  shoot("living-room-all");
}

// 2. The graph shows what the artist works on: the selection's object, its material and that
// material's textures and blend partner, legibly, and nothing else to tangle with.
TEST_F(NodeGraphArtist, TheGraphShowsTheSelectionsMaterialGraph) {
  if (!openLivingRoom()) GTEST_SKIP() << "skipped: ../shared/scenes/living-room is not present";
  // An object whose material has a texture and blends with another, if the room has one.
  const Object* chosen = nullptr;
  int best = -1;
  for (const Object& o : room.objects) {
    const Material* m = room.material(o.material);
    if (!m) continue;
    int score = 0;
    for (NodeId t : m->textures()) score += t != kNoNode ? 1 : 0;
    score += m->blendWith != kNoNode ? 2 : 0;
    if (score > best) best = score, chosen = &o;
  }
  ASSERT_TRUE(chosen);
  const Material& material = *room.material(chosen->material);
  view->followSelection({chosen->id});
  view->setSelectedObject(chosen->id);
  shoot("living-room-selection");
  EXPECT_GE(titlePixels(), 9.0);
  std::vector<NodeId> expected{chosen->id, material.id};
  for (NodeId t : material.textures())
    if (t != kNoNode) expected.push_back(t);
  if (material.blendWith != kNoNode) expected.push_back(material.blendWith);
  for (NodeId id : expected) {
    EXPECT_TRUE(view->hasNode(id)) << id;
    EXPECT_TRUE(visible().contains(view->nodePosition(id) + QPointF(20, 10))) << id << " is in view";
  }
  std::size_t shown = 0;
  for (QGraphicsItem* i : view->scene()->items()) shown += i->type() == QGraphicsItem::UserType + 1 ? 1 : 0;
  EXPECT_LE(shown, 12u) << "the neighbourhood, not the room's " << room.objects.size() << " objects";
  EXPECT_FALSE(view->hasNode(NodeGraphView::kCameraNode));

  expectNoLinkCrossesANode("the selection's graph");
  // Everything is a click away, and nothing selected shows everything.
  auto* showAll = view->findChild<QAbstractButton*>("graphShowAll");
  ASSERT_TRUE(showAll);
  QTest::mouseClick(showAll, Qt::LeftButton);
  EXPECT_EQ(view->scope(), NodeGraphView::Scope::All);
  EXPECT_TRUE(view->hasNode(NodeGraphView::kCameraNode));
  expectNoLinkCrossesANode("the whole graph");
  EXPECT_TRUE(visible().contains(view->nodePosition(chosen->id) + QPointF(20, 10))) << "the selection stays in view";
  view->setScope(NodeGraphView::Scope::Selection);
  view->followSelection({});
  for (const Object& o : room.objects) EXPECT_TRUE(view->hasNode(o.id)) << o.name;
  EXPECT_GE(titlePixels(), 9.0);
}

// 2. In the editor: picking an object shows its material graph, legibly.
TEST(NodeGraphInEditor, PickingAnObjectShowsItsMaterialGraph) {
  auto w = test::makeWindow();
  w->resize(1600, 1000);
  ASSERT_TRUE(QTest::qWaitForWindowExposed(w.get()));
  NodeGraphView* graph = w->graph();
  const NodeId cup = test::objectNamed(w->scene(), "Cup");
  const NodeId material = w->scene().object(cup)->material;
  w->select(cup);
  const QRectF shown = graph->mapToScene(graph->viewport()->rect()).boundingRect();
  EXPECT_TRUE(shown.contains(graph->nodePosition(material) + QPointF(20, 10))) << "the cup's material is in view";
  EXPECT_GE(QFontInfo(graph->font()).pixelSize() * graph->transform().m11(), 9.0);
  EXPECT_FALSE(graph->hasNode(test::objectNamed(w->scene(), "Glossy Sphere"))) << "another object's node";
}

// 3. Links ran behind nodes and seemed plugged into whatever socket sat at their height: they
// are drawn above every node and end at their own sockets.
TEST_F(NodeGraphArtist, LinksAreDrawnAboveNodesAndEndAtTheirSockets) {
  if (!openLivingRoom()) GTEST_SKIP() << "skipped: ../shared/scenes/living-room is not present";
  view->setScope(NodeGraphView::Scope::All);
  view->selectNodes({room.objects.front().id, room.materials.front().id});  // selected nodes are raised
  double topNode = -1e9;
  std::vector<const QGraphicsPathItem*> links;
  for (QGraphicsItem* i : view->scene()->items()) {
    if (i->type() == QGraphicsItem::UserType + 1) topNode = std::max(topNode, i->zValue());
    auto* p = qgraphicsitem_cast<QGraphicsPathItem*>(i);
    if (p && p->isVisible() && p->pen().style() == Qt::SolidLine) links.push_back(p);
  }
  auto drawn = [&](NodeId from, const QString& output, NodeId to, const QString& input) {
    const QPointF a = view->socketScenePos(from, output, true), b = view->socketScenePos(to, input, false);
    for (const QGraphicsPathItem* p : links)
      if (QLineF(p->path().pointAtPercent(0), a).length() < 0.5 && QLineF(p->path().pointAtPercent(1), b).length() < 0.5) return p;
    return static_cast<const QGraphicsPathItem*>(nullptr);
  };
  int checked = 0;
  for (const Object& o : room.objects) {
    if (o.material == kNoNode) continue;
    const QGraphicsPathItem* p = drawn(o.material, "material", o.id, "material");
    ASSERT_TRUE(p) << o.name << "'s material link ends at its socket";
    EXPECT_GT(p->zValue(), topNode) << o.name << "'s material link is drawn above the nodes";
    ++checked;
  }
  for (const Material& m : room.materials)
    if (m.albedoTexture != kNoNode && m.type != MaterialType::Boundary) {
      const QGraphicsPathItem* p = drawn(m.albedoTexture, "texture", m.id, "albedo");
      ASSERT_TRUE(p) << m.name << "'s albedo link";
      EXPECT_GT(p->zValue(), topNode);
      ++checked;
    }
  EXPECT_GT(checked, 20);
}

// 4. The Tab list was cut off at the window's bottom: it opens within the window.
TEST_F(NodeGraphArtist, TheNodeSearchStaysInsideTheWindow) {
  Document doc{makeDefaultScene()};
  view->setDocument(doc.scene());
  window.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&window));
  const QRect inside = window.frameGeometry();
  const QRect vp = view->viewport()->rect();
  for (QPoint corner : {vp.bottomLeft() + QPoint(4, -4), vp.bottomRight() + QPoint(-4, -4), vp.center()}) {
    view->openNodeSearch(view->mapToScene(corner));
    auto* search = view->findChild<QLineEdit*>("nodeSearch");
    ASSERT_TRUE(search && search->isVisible());
    QWidget* popup = search->window();
    const QRect spans = popup->frameGeometry();
    EXPECT_TRUE(inside.contains(spans)) << "opened at " << corner.x() << ", " << corner.y() << ": the list spans " << spans.x() << ", "
                                        << spans.y() << " to " << spans.right() << ", " << spans.bottom();
    auto* list = view->findChild<QListWidget*>("nodeSearchList");
    ASSERT_TRUE(list);
    int rows = 0;
    for (int i = 0; i < list->count(); ++i) rows += list->item(i)->isHidden() ? 0 : 1;
    EXPECT_GE(list->viewport()->height(), rows * list->sizeHintForRow(0)) << "every entry shows without scrolling";
    popup->hide();
  }
}

// A click on an object's node selects the object in the editor, which answers with the selection;
// the graph shows the object's material graph once the button is up, not under the mouse.
TEST_F(NodeGraph, AClickedObjectsGraphIsShownWhenTheButtonIsUp) {
  QObject::connect(&view, &NodeGraphView::objectSelected, &view, [this](quint64 id) {
    view.followSelection({static_cast<NodeId>(id)});  // what MainWindow::applySelection does
    view.setSelectedObject(static_cast<NodeId>(id));
  });
  const NodeId sphere = named(scene().objects, "Glossy Sphere");
  const NodeId cup = named(scene().objects, "Cup");
  const QPoint from = header(sphere);
  QTest::mousePress(vp(), Qt::LeftButton, {}, from);
  QTest::mouseMove(vp(), from + QPoint(30, 20));
  EXPECT_TRUE(view.hasNode(cup)) << "nothing rebuilt under the mouse";
  QTest::mouseRelease(vp(), Qt::LeftButton, {}, from + QPoint(30, 20));
  EXPECT_FALSE(view.hasNode(cup));
  EXPECT_TRUE(view.hasNode(scene().object(sphere)->material));
  EXPECT_EQ(view.selectedNodes(), std::vector<NodeId>{sphere});
  // Made while the sphere's graph is shown, a node joins it; a new selection starts afresh.
  ASSERT_TRUE(view.createNode("Checker Texture", view.mapToScene(vp()->rect().center())));
  const NodeId made = scene().textures.back().id;
  EXPECT_TRUE(view.hasNode(made));
  view.followSelection({cup});
  EXPECT_FALSE(view.hasNode(made));
  EXPECT_FALSE(view.hasNode(sphere));
  EXPECT_TRUE(view.hasNode(cup));
}

// 5. "checker" found nothing, though "Texture" made a checker: the search knows what each entry makes.
TEST_F(NodeGraph, TheSearchFindsANodeByWhatItMakes) {
  const std::size_t textures = scene().textures.size();
  QTest::keyClick(&view, Qt::Key_Tab);
  auto* search = view.findChild<QLineEdit*>("nodeSearch");
  auto* list = view.findChild<QListWidget*>("nodeSearchList");
  ASSERT_TRUE(search && list);
  auto matches = [&](const char* text) {
    search->clear();
    QTest::keyClicks(search, text);
    QStringList shown;
    for (int i = 0; i < list->count(); ++i)
      if (!list->item(i)->isHidden()) shown << list->item(i)->text();
    return shown;
  };
  EXPECT_EQ(matches("sun").size(), 1) << "a synonym: the directional light";
  EXPECT_EQ(matches("LAMP").size(), 3) << "every light, whatever the case";
  EXPECT_EQ(matches("tex").size(), 1);
  const QStringList checker = matches("checker");
  ASSERT_EQ(checker.size(), 1) << "the texture the entry makes is a checker";
  QTest::keyClick(search, Qt::Key_Return);
  ASSERT_EQ(scene().textures.size(), textures + 1);
  EXPECT_EQ(scene().textures.back().kind, TextureKind::Checker);
}

}  // namespace
}  // namespace retile::ui
