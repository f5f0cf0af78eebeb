// The properties dock: typed editors for whatever the outliner, viewport or node graph points at
// (an object with its material, a material, a light, the camera, the environment, the render
// settings). Every change is an undoable edit pushed through the owner; a scrub or a colour
// dialog session is one undo step. GUI thread only; the panel holds no scene state of its own:
// it reads the owner's document whenever it builds or edits.
#pragma once

#include <QLabel>
#include <QPointer>
#include <QScrollArea>

#include <functional>
#include <optional>

#include "retile/edit.h"

class QFormLayout;

namespace retile::ui {

struct PropertyTarget {
  enum class Kind { None, Object, Material, Light, Camera, Environment, Render } kind = Kind::None;
  NodeId id = kNoNode;
  bool operator==(const PropertyTarget&) const = default;
};

class PropertyPanel : public QScrollArea {
  Q_OBJECT
 public:
  // `push` applies an edit as an undo step; edits with the same dragId > 0 merge.
  using Push = std::function<void(const Edit& before, const Edit& after, const QString& text, int dragId)>;
  using SceneRef = std::function<const Scene&()>;
  // `preview` shows an edit without making it an undo step (a colour tried in the dialog).
  using Preview = std::function<void(const Edit&)>;
  PropertyPanel(SceneRef scene, Push push, Preview preview, QWidget* parent = nullptr);

  void setTarget(PropertyTarget t);
  PropertyTarget target() const { return target_; }
  // Rebuilds the editors from the document (after undo, redo or a structural change).
  void rebuild();
  // Once, after the current event: edits arriving in a burst (a drag) rebuild the panel once.
  // From a field's edit, pass its drag id: while the field is scrubbed, the rebuild waits for the
  // scrub to end.
  void rebuildLater(int drag = 0);
  // Whether `e` changes something the panel shows (its target, or an object's material).
  bool shows(const Edit& e) const;
  // The engine's render size and how it was chosen, shown beside the scene's own resolution.
  // Updates the line in place: a rebuild would drop a field being dragged (a drag of the scene's
  // resolution, framed as the scene, resizes the render at every step).
  void setRenderSize(QSize s, bool cameraFraming = false);

 signals:
  // Something the user should read: a typed value refused or clamped (the owner shows it).
  void message(const QString& text);

 private:
  class Builder;
  // An editor of node `id`: reads the node from the document when called (never a stale copy),
  // applies `change` and pushes Wrap{before} -> Wrap{after} as an undoable edit.
  template <class Node, class Wrap, class Get>
  auto nodeEdit(NodeId id, Get get) {
    return [this, id, get](const QString& what, int drag, const std::function<void(Node&)>& change) {
      const Node* cur = get(scene_(), id);
      if (!cur) return;
      Node after = *cur;
      change(after);
      send(Wrap{*cur}, Wrap{after}, what, drag);
    };
  }
  // Drag ids of a colour dialog's session: tried colours are previewed, the last one committed as
  // one step from the colour before the dialog.
  static constexpr int kPreview = -1, kCommit = -2;
  void send(const Edit& before, const Edit& after, const QString& what, int drag);
  void cancelPreview();
  void buildObject(Builder& b, const Object& o);
  void buildMaterial(Builder& b, const Material& m);
  // The rows of material_fields.h (scalars, colours, choices) shown at `place` for m's type, each
  // edited as one undoable step.
  void fieldRows(Builder& b, const Material& m, MaterialPlace place);
  // The rest of a material's rows, by what they set.
  void roughnessRows(Builder& b, const Material& m);
  void textureRows(Builder& b, const Material& m);
  void emissionRows(Builder& b, const Material& m);
  void blendRows(Builder& b, const Material& m);
  void buildLight(Builder& b, const Light& l);
  void texturePath(Builder& b, const Texture& t, const QString& objectName);
  void buildCamera(Builder& b);
  void buildEnvironment(Builder& b);
  void buildRender(Builder& b);
  QString viewportText() const;

  SceneRef scene_;
  Push push_;
  Preview preview_;
  std::optional<Edit> previewBefore_;  // the value before a colour dialog's first preview
  PropertyTarget target_;
  QSize renderSize_;
  bool cameraFraming_ = false;
  QPointer<QLabel> viewportLine_;  // in the render settings, while they are shown
  QWidget* body_ = nullptr;
  QFormLayout* form_ = nullptr;
  int drag_ = 1000000;  // drag ids of this panel: far from the viewport's
  bool rebuildQueued_ = false;
  bool rebuildAfterScrub_ = false;  // a field asked for a rebuild while it was scrubbed
};

}  // namespace retile::ui
