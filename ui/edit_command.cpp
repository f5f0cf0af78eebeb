#include "edit_command.h"

namespace retile::ui {

EditCommand::EditCommand(Edit before, Edit after, const QString& text, Apply apply, int dragId)
    : before_(std::move(before)), after_(std::move(after)), apply_(std::move(apply)), dragId_(dragId) {
  setText(text);
}

void EditCommand::redo() {
  if (!apply_(after_)) setObsolete(true);
}

void EditCommand::undo() { apply_(before_); }

bool EditCommand::mergeWith(const QUndoCommand* other) {
  const auto* o = dynamic_cast<const EditCommand*>(other);
  if (!o || o->dragId_ != dragId_ || dragId_ <= 0) return false;
  if (editCoalesceKey(o->after_) != editCoalesceKey(after_)) return false;
  after_ = o->after_;  // keep our `before`: the whole drag undoes at once
  return true;
}

}  // namespace retile::ui
