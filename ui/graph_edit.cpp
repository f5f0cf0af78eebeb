#include "graph_edit.h"

#include "graph_items.h"

namespace retile::ui {

bool EditBuilder::step(Edit before, Edit after) {
  if (!ok_) return false;
  if (!applyEdit(scene_, after).ok()) {
    ok_ = false;
    return false;
  }
  edit_.steps.emplace_back(std::move(before), std::move(after));
  return true;
}

bool EditBuilder::set(const Material& m) {
  const Material* old = scene_.material(m.id);
  return old && step(SetMaterial{*old}, SetMaterial{m});
}
bool EditBuilder::set(const Object& o) {
  const Object* old = scene_.object(o.id);
  return old && step(SetObject{*old}, SetObject{o});
}
bool EditBuilder::set(const Light& l) {
  const Light* old = scene_.light(l.id);
  return old && step(SetLight{*old}, SetLight{l});
}
bool EditBuilder::set(const Texture& t) {
  const Texture* old = scene_.texture(t.id);
  return old && step(SetTexture{*old}, SetTexture{t});
}

NodeId EditBuilder::newId() const {
  NodeId id = scene_.peekNextId();
  while (scene_.mesh(id) || scene_.material(id) || scene_.object(id) || scene_.light(id) || scene_.texture(id)) ++id;
  return id;
}

bool EditBuilder::assign(NodeId to, const QString& input, NodeId from) {
  if (input == QLatin1String("material")) {
    const Object* o = scene_.object(to);
    if (!o || (from != kNoNode && !scene_.material(from)) || o->material == from) return false;
    Object c = *o;
    c.material = from;
    return set(c);
  }
  if (input == kBlendInput) {
    const Material* m = scene_.material(to);
    if (!m || from == to || (from != kNoNode && !scene_.material(from)) || m->blendWith == from) return false;
    Material c = *m;
    c.setBlendWith(from);
    return set(c);
  }
  NodeId Material::*slot = textureSlot(input);
  const Material* m = scene_.material(to);
  if (!slot || !m || (from != kNoNode && !scene_.texture(from)) || m->*slot == from) return false;
  Material c = *m;
  c.*slot = from;
  return set(c);
}

bool EditBuilder::remove(NodeId id) {
  if (const Object* o = scene_.object(id)) return step(AddObject{*o}, RemoveNode{id});
  if (const Light* l = scene_.light(id)) return step(AddLight{*l}, RemoveNode{id});
  if (const Material* m = scene_.material(id)) {
    Material copy = *m;
    std::vector<NodeId> users;
    for (const Object& o : scene_.objects)
      if (o.material == id) users.push_back(o.id);
    for (NodeId u : users)
      if (!assign(u, QStringLiteral("material"), kNoNode)) return false;
    std::vector<NodeId> blends;
    for (const Material& b : scene_.materials)
      if (b.blendWith == id) blends.push_back(b.id);
    for (NodeId b : blends)
      if (!assign(b, kBlendInput, kNoNode)) return false;
    return step(AddMaterial{copy}, RemoveNode{id});
  }
  if (const Texture* t = scene_.texture(id)) {
    Texture copy = *t;
    std::vector<std::pair<NodeId, QString>> users;
    for (const Material& m : scene_.materials)
      for (const QString& slot : textureInputs())
        if (m.*textureSlot(slot) == id) users.emplace_back(m.id, slot);
    for (const auto& [m, slot] : users)
      if (!assign(m, slot, kNoNode)) return false;
    if (scene_.environment.map == id) {
      Environment env = scene_.environment;
      env.map = kNoNode;
      env.type = EnvironmentType::Constant;  // what RemoveNode does; stated so undo restores the type
      if (!step(SetEnvironment{scene_.environment}, SetEnvironment{env})) return false;
    }
    return step(AddTexture{copy}, RemoveNode{id});
  }
  return false;
}

GraphEdit EditBuilder::finish(const QString& text) {
  edit_.text = text;
  return std::move(edit_);
}

QString nameOf(const Scene& s, NodeId id) {
  if (const auto* n = s.material(id)) return QString::fromStdString(n->name);
  if (const auto* n = s.object(id)) return QString::fromStdString(n->name);
  if (const auto* n = s.light(id)) return QString::fromStdString(n->name);
  if (const auto* n = s.texture(id)) return QString::fromStdString(n->name);
  return QString::number(id);
}

}  // namespace retile::ui
