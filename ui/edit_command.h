// Undoable edits. Every change the editor makes to the scene is an EditCommand on the window's
// QUndoStack: redo applies the new value to the document and sends it to the render thread,
// undo does the same with the old value. Commands of one drag (same target, same drag id)
// merge into one undo step. GUI thread only.
#pragma once

#include <QUndoCommand>

#include <functional>
#include <utility>
#include <vector>

#include "retile/edit.h"

namespace retile::ui {

class EditCommand : public QUndoCommand {
 public:
  // `apply` applies an edit to the document and forwards it to the engine; it returns false (and
  // reports) when the document refuses the edit.
  using Apply = std::function<bool(const Edit&)>;
  // `dragId` > 0 lets consecutive commands of the same target and drag merge.
  EditCommand(Edit before, Edit after, const QString& text, Apply apply, int dragId = 0);
  // Several targets in one step (a multi-selection moved together): applied in order, undone in
  // reverse; a drag merges when it touches the same targets.
  EditCommand(std::vector<std::pair<Edit, Edit>> steps, const QString& text, Apply apply, int dragId = 0);

  void redo() override;
  void undo() override;
  int id() const override { return dragId_ > 0 ? 1 : -1; }
  bool mergeWith(const QUndoCommand* other) override;

 private:
  std::vector<std::pair<Edit, Edit>> steps_;  // before, after
  Apply apply_;
  int dragId_;
};

}  // namespace retile::ui
