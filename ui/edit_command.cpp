#include "edit_command.h"

namespace retile::ui {

EditCommand::EditCommand(Edit before, Edit after, const QString& text, Apply apply, int dragId)
    : EditCommand(std::vector<std::pair<Edit, Edit>>{{std::move(before), std::move(after)}}, text, std::move(apply), dragId) {}

EditCommand::EditCommand(std::vector<std::pair<Edit, Edit>> steps, const QString& text, Apply apply, int dragId)
    : steps_(std::move(steps)), apply_(std::move(apply)), dragId_(dragId) {
  setText(text);
}

void EditCommand::redo() {
  bool applied = false;
  for (const auto& [before, after] : steps_) applied = apply_(after) || applied;
  if (!applied) setObsolete(true);
}

void EditCommand::undo() {
  for (auto it = steps_.rbegin(); it != steps_.rend(); ++it) apply_(it->first);
}

bool EditCommand::mergeWith(const QUndoCommand* other) {
  const auto* o = dynamic_cast<const EditCommand*>(other);
  if (!o || o->dragId_ != dragId_ || dragId_ <= 0 || o->steps_.size() != steps_.size()) return false;
  for (std::size_t i = 0; i < steps_.size(); ++i)
    if (editCoalesceKey(o->steps_[i].second) != editCoalesceKey(steps_[i].second)) return false;
  // Keep our befores: the whole drag undoes at once.
  for (std::size_t i = 0; i < steps_.size(); ++i) steps_[i].second = o->steps_[i].second;
  return true;
}

}  // namespace retile::ui
