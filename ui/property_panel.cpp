#include "property_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QFileDialog>
#include <QLabel>
#include <QLineEdit>
#include <QToolButton>
#include <QSlider>
#include <QSpinBox>

#include <algorithm>
#include <cmath>

#include "fields.h"

namespace retile::ui {

namespace {

QColor toQColor(Vec3 c) {
  auto ch = [](float v) { return std::clamp(static_cast<int>(std::lround(v * 255.0f)), 0, 255); };
  return QColor(ch(c.x), ch(c.y), ch(c.z));
}

Vec3 fromQColor(const QColor& c) {
  return Vec3{static_cast<float>(c.redF()), static_cast<float>(c.greenF()), static_cast<float>(c.blueF())};
}

float& axisOf(Vec3& v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

// Colours above 1 (emission, bright skies) edit as a swatch of the normalised colour times a strength.
float peak(Vec3 c) { return std::max({c.x, c.y, c.z}); }

}  // namespace

// Adds typed rows to the form; each field's edits carry the panel's drag id while scrubbing.
class PropertyPanel::Builder {
 public:
  Builder(PropertyPanel* panel, QFormLayout* form) : p_(panel), form_(form) {}

  void header(const QString& text) {
    auto* l = new QLabel(QString("<b>%1</b>").arg(text.toHtmlEscaped()), p_->body_);
    form_->addRow(l);
  }
  QLabel* label(const QString& name, const QString& text) {
    auto* l = new QLabel(text, p_->body_);
    form_->addRow(name, l);
    return l;
  }

  ScrubField* number(const QString& name, const QString& objectName, double value, double min, double max, double def, int decimals,
                     std::function<void(double, int)> apply) {
    auto* f = new ScrubField(value, min, max, def, decimals, p_->body_);
    f->setObjectName(objectName);
    connectField(f, std::move(apply));
    form_->addRow(name, f);
    return f;
  }

  // A homogeneous medium's fields (a glass's or boundary's interior, the world's): absorption and
  // scattering per channel, never negative, and the phase function's asymmetry; labelled and
  // named by `prefix` and `key` ("Interior", "interior" gives "interiorAbsorption" and on), each
  // edit made through `edit` on the member of T it shows.
  template <class T>
  void medium(const QString& prefix, const QString& key, const T& target, Vec3 T::*absorption, Vec3 T::*scattering, float T::*anisotropy,
              const std::function<void(const QString&, int, const std::function<void(T&)>&)>& edit) {
    for (Vec3 T::*field : {absorption, scattering}) {
      const QString what =
          PropertyPanel::tr("%1 %2").arg(prefix, field == absorption ? PropertyPanel::tr("absorption") : PropertyPanel::tr("scattering"));
      vec3(
          what, key + (field == absorption ? "Absorption" : "Scattering"), target.*field, 0.01,
          [edit, what, field](int channel, double v, int drag) {
            edit(what, drag, [channel, v, field](T& x) { axisOf(x.*field, channel) = std::max(0.0f, static_cast<float>(v)); });
          },
          true);
    }
    const QString what = PropertyPanel::tr("%1 anisotropy").arg(prefix);
    number(what, key + "Anisotropy", target.*anisotropy, -0.99, 0.99, 0.0, 3, [edit, what, anisotropy](double v, int drag) {
      edit(what, drag, [v, anisotropy](T& x) { x.*anisotropy = static_cast<float>(v); });
    });
  }

  // Three fields labelled X, Y, Z, or R, G, B for a quantity per colour channel.
  QWidget* vec3(const QString& name, const QString& objectName, Vec3 value, double step, std::function<void(int, double, int)> apply,
                bool perChannel = false) {
    auto* row = new QWidget(p_->body_);
    auto* l = new QHBoxLayout(row);
    l->setContentsMargins(0, 0, 0, 0);
    const char* const kAxisName[3] = {perChannel ? "R" : "X", perChannel ? "G" : "Y", perChannel ? "B" : "Z"};
    static const QColor kAxisColor[3] = {QColor(220, 70, 70), QColor(70, 170, 70), QColor(80, 120, 230)};
    for (int axis = 0; axis < 3; ++axis) {
      // Labelled in the gizmo's axis colours, so a field reads without counting.
      auto* label = new QLabel(QString::fromLatin1(kAxisName[axis]), row);
      label->setStyleSheet(QString("color: %1; font-weight: bold;").arg(kAxisColor[axis].name()));
      label->setSizePolicy(QSizePolicy::Fixed, QSizePolicy::Preferred);
      l->addWidget(label);
      auto* f = new ScrubField(axisOf(value, axis), -1e5, 1e5, 0.0, 3, row);
      // Three to a row in a narrow panel: no arrows (the field is dragged or typed), and the
      // width shared out rather than sized for the longest number the range allows.
      f->setButtonSymbols(QAbstractSpinBox::NoButtons);
      f->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Fixed);
      f->setMinimumWidth(f->fontMetrics().horizontalAdvance("-000.000") + 8);
      f->setSingleStep(step);
      f->setObjectName(QString("%1%2").arg(objectName).arg(axis));
      connectField(f, [apply, axis](double v, int drag) { apply(axis, v, drag); });
      l->addWidget(f, 1);
    }
    form_->addRow(name, row);
    return row;
  }

  ColorField* color(const QString& name, const QString& objectName, Vec3 value, Vec3 def, std::function<void(Vec3, int)> apply) {
    auto* f = new ColorField(toQColor(value), toQColor(def), p_->body_);
    f->setObjectName(objectName);
    PropertyPanel* panel = p_;
    QObject::connect(f, &ColorField::previewed, f, [apply](QColor c) { apply(fromQColor(c), kPreview); });
    QObject::connect(f, &ColorField::committed, f, [apply](QColor c) { apply(fromQColor(c), kCommit); });
    QObject::connect(f, &ColorField::cancelled, f, [panel] { panel->cancelPreview(); });
    form_->addRow(name, f);
    return f;
  }

  QComboBox* choice(const QString& name, const QString& objectName, const QStringList& items, int index, std::function<void(int)> apply) {
    auto* c = new QComboBox(p_->body_);
    c->setObjectName(objectName);
    c->addItems(items);
    c->setCurrentIndex(index);
    // Sized by its longest item ("diffuse_transmission"), the row would not fit beside a long
    // label in the dock and would wrap below its own label; the list still shows whole items.
    c->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
    c->setMinimumContentsLength(8);
    QObject::connect(c, &QComboBox::currentIndexChanged, c, [apply](int i) { apply(i); });
    form_->addRow(name, c);
    return c;
  }

  // "(none)" or one of `nodes` by name (all but `skip`), `current` chosen; `apply` gets the id picked.
  template <class Node>
  QComboBox* nodeChoice(const QString& name, const QString& objectName, const std::vector<Node>& nodes, NodeId current,
                        std::function<void(NodeId)> apply, NodeId skip = kNoNode) {
    QStringList names{PropertyPanel::tr("(none)")};
    std::vector<NodeId> ids{kNoNode};
    int index = 0;
    for (const Node& n : nodes) {
      if (n.id == skip) continue;
      if (n.id == current) index = static_cast<int>(ids.size());
      names << QString::fromStdString(n.name);
      ids.push_back(n.id);
    }
    return choice(name, objectName, names, index, [apply, ids](int i) {
      if (i >= 0 && i < static_cast<int>(ids.size())) apply(ids[static_cast<std::size_t>(i)]);
    });
  }

  QCheckBox* check(const QString& name, const QString& objectName, bool value, std::function<void(bool)> apply) {
    auto* c = new QCheckBox(p_->body_);
    c->setObjectName(objectName);
    c->setChecked(value);
    QObject::connect(c, &QCheckBox::toggled, c, [apply](bool on) { apply(on); });
    form_->addRow(name, c);
    return c;
  }

  void row(const QString& name, QWidget* w) { form_->addRow(name, w); }

  void connectField(ScrubField* f, std::function<void(double, int)> apply) {
    // The builder lives only while the panel builds: the connections capture the panel.
    PropertyPanel* panel = p_;
    QObject::connect(f, &ScrubField::edited, f, [panel, apply](double v, bool scrubbing) { apply(v, scrubbing ? panel->drag_ : 0); });
    QObject::connect(f, &ScrubField::refused, panel, &PropertyPanel::message);
    QObject::connect(f, &ScrubField::scrubFinished, f, [panel] {
      ++panel->drag_;
      if (panel->rebuildAfterScrub_) {
        panel->rebuildAfterScrub_ = false;
        panel->rebuildLater();
      }
    });
  }

 private:
  PropertyPanel* p_;
  QFormLayout* form_;
};

PropertyPanel::PropertyPanel(SceneRef scene, Push push, Preview preview, QWidget* parent)
    : QScrollArea(parent), scene_(std::move(scene)), push_(std::move(push)), preview_(std::move(preview)) {
  setWidgetResizable(true);
  setFrameShape(QFrame::NoFrame);
  setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);  // fields narrow to the dock instead
  rebuild();
}

void PropertyPanel::setTarget(PropertyTarget t) {
  target_ = t;
  rebuild();
}

void PropertyPanel::send(const Edit& before, const Edit& after, const QString& what, int drag) {
  if (drag == kPreview) {
    if (!previewBefore_) previewBefore_ = before;
    preview_(after);
  } else if (drag == kCommit) {
    push_(previewBefore_.value_or(before), after, what, 0);
    previewBefore_.reset();
  } else {
    push_(before, after, what, drag);
  }
}

void PropertyPanel::cancelPreview() {
  if (previewBefore_) preview_(*previewBefore_);
  previewBefore_.reset();
}

void PropertyPanel::rebuildLater(int drag) {
  // Not while a field is scrubbed (drag > 0: its drag id), which the rebuild would delete under
  // the mouse: when the scrub ends.
  if (drag > 0) {
    rebuildAfterScrub_ = true;
    return;
  }
  // Not from inside a field's signal: rebuilding deletes the field.
  if (rebuildQueued_) return;
  rebuildQueued_ = true;
  QMetaObject::invokeMethod(
      this,
      [this] {
        rebuildQueued_ = false;
        rebuild();
      },
      Qt::QueuedConnection);
}

bool PropertyPanel::shows(const Edit& e) const {
  using K = PropertyTarget::Kind;
  const NodeId id = editTarget(e);
  switch (target_.kind) {
    case K::Object: {
      if (id == target_.id) return true;
      const Object* o = scene_().object(target_.id);
      return o && (std::holds_alternative<SetMaterial>(e) || std::holds_alternative<RemoveNode>(e)) && id == o->material;
    }
    case K::Material:
    case K::Light: return id == target_.id;
    case K::Camera: return std::holds_alternative<SetCamera>(e);
    case K::Environment: return std::holds_alternative<SetEnvironment>(e);
    case K::Render: return std::holds_alternative<SetRenderSettings>(e);
    case K::None: return false;
  }
  return false;
}

void PropertyPanel::rebuild() {
  // A fresh body each time: rows of the old target must not outlive it (their lambdas hold ids).
  body_ = new QWidget;
  form_ = new QFormLayout(body_);
  form_->setFieldGrowthPolicy(QFormLayout::AllNonFixedFieldsGrow);
  // A row too wide for the dock (a long label beside three channels) puts its label above its
  // field, rather than the panel cutting the last channel off (it scrolls only vertically).
  form_->setRowWrapPolicy(QFormLayout::WrapLongRows);
  Builder b(this, form_);
  const Scene& s = scene_();
  switch (target_.kind) {
    case PropertyTarget::Kind::Object:
      if (const Object* o = s.object(target_.id)) {
        buildObject(b, *o);
        if (const Material* m = s.material(o->material)) buildMaterial(b, *m);
      }
      break;
    case PropertyTarget::Kind::Material:
      if (const Material* m = s.material(target_.id)) buildMaterial(b, *m);
      break;
    case PropertyTarget::Kind::Light:
      if (const Light* l = s.light(target_.id)) buildLight(b, *l);
      break;
    case PropertyTarget::Kind::Camera: buildCamera(b); break;
    case PropertyTarget::Kind::Environment: buildEnvironment(b); break;
    case PropertyTarget::Kind::Render: buildRender(b); break;
    case PropertyTarget::Kind::None: break;
  }
  if (form_->rowCount() == 0)
    form_->addRow(new QLabel(tr("Click an object in the viewport, or anything in the outliner or the node graph."), body_));
  setWidget(body_);  // deletes the previous body
}

void PropertyPanel::buildObject(Builder& b, const Object& o) {
  const NodeId id = o.id;
  auto edit = nodeEdit<Object, SetObject>(id, [](const Scene& sc, NodeId i) { return sc.object(i); });
  b.header(tr("Object: %1").arg(QString::fromStdString(o.name)));
  // Position is the object's pivot (objectPivot: where the gizmo sits); moving keeps its rotation
  // and scale, and a turn or scale, here or with the gizmo, keeps its position.
  const Scene& scene = scene_();
  b.vec3(tr("Position"), "position", objectPivot(scene, o), 0.01, [this, edit](int axis, double v, int drag) {
    edit(tr("Move"), drag, [&](Object& x) {
      Vec3 d{0.0f};
      Vec3 at = objectPivot(scene_(), x);
      axisOf(d, axis) = static_cast<float>(v) - axisOf(at, axis);
      x.transform = Mat4::translate(d) * x.transform;
    });
  });
  // A sheared transform (rare in imported files) loses its shear when one of these is edited.
  auto aboutPivot = [this](Object& x, const std::function<void(Trs&)>& change) {
    const Vec3 at = objectPivot(scene_(), x);
    Trs t = decompose(x.transform);
    change(t);
    x.transform = compose(t);
    x.transform = Mat4::translate(at - objectPivot(scene_(), x)) * x.transform;
  };
  const Trs trs = decompose(o.transform);
  b.vec3(tr("Rotation"), "rotation", trs.rotationDegrees, 1.0, [edit, aboutPivot](int axis, double v, int drag) {
    edit(tr("Rotate"), drag, [&](Object& x) { aboutPivot(x, [&](Trs& t) { axisOf(t.rotationDegrees, axis) = static_cast<float>(v); }); });
  });
  b.vec3(tr("Scale"), "scale", trs.scale, 0.01, [edit, aboutPivot](int axis, double v, int drag) {
    edit(tr("Scale"), drag, [&](Object& x) {
      // Never zero: a flat object cannot be scaled back up.
      const double magnitude = std::max(std::abs(v), 1e-4);
      aboutPivot(x, [&](Trs& t) { axisOf(t.scale, axis) = static_cast<float>(v < 0 ? -magnitude : magnitude); });
    });
  });
  b.nodeChoice(tr("Material"), "materialAssignment", scene_().materials, o.material,
               [edit](NodeId m) { edit(tr("Assign material"), 0, [m](Object& x) { x.material = m; }); });
  // A room's walls culled, the camera outside sees in through them (a Tungsten mesh's
  // backface_culling).
  b.check(tr("Front faces only"), "cullBackFaces", o.cullBackFaces, [edit](bool on) {
     edit(on ? tr("Cull back faces") : tr("Show back faces"), 0, [on](Object& x) { x.cullBackFaces = on; });
   })->setToolTip(tr("Rays pass through the object's back faces, shadow rays too: a wall seen from behind is not there"));
}

namespace {
// What decides which of a material's fields the panel shows: an edit that changes it rebuilds it.
auto fieldsShown(const Material& m) { return std::tuple{m.type, m.coated(), m.filmThickness > 0, m.emissive(), m.blendWith != kNoNode}; }
}  // namespace

void PropertyPanel::fieldRows(Builder& b, const Material& m, MaterialPlace place) {
  const NodeId id = m.id;
  auto edit = nodeEdit<Material, SetMaterial>(id, [](const Scene& sc, NodeId i) { return sc.material(i); });
  for (const MaterialScalar& f : kMaterialScalars) {
    if (f.place != place || !f.appliesTo(m.type)) continue;
    const QString label = tr(f.label);
    const QString title = *f.unit ? tr("%1 (%2)").arg(label, tr(f.unit)) : label;
    ScrubField* row = b.number(title, f.member, m.*f.field, f.lo, f.hi, f.fallback, f.decimals,
                               [this, id, edit, label, field = f.field](double v, int drag) {
                                 const Material* cur = scene_().material(id);
                                 if (!cur) return;
                                 const auto shown = fieldsShown(*cur);
                                 edit(label, drag, [v, field](Material& x) { x.*field = static_cast<float>(v); });
                                 const Material* now = scene_().material(id);
                                 if (now && fieldsShown(*now) != shown) rebuildLater(drag);
                               });
    if (*f.atLo) row->setSpecialValueText(tr(f.atLo));
    if (*f.tip) row->setToolTip(tr(f.tip));
  }
  for (const MaterialColor& f : kMaterialColors) {
    if (f.place != place || !f.appliesTo(m.type)) continue;
    const QString label = tr(f.label);
    const auto field = f.field;
    QWidget* row = f.widget == ColorWidget::Swatch
                       ? b.color(label, f.member, m.*field, f.fallback,
                                 [edit, label, field](Vec3 c, int drag) { edit(label, drag, [c, field](Material& x) { x.*field = c; }); })
                       : b.vec3(
                             label, f.member, m.*field, 0.01,
                             [edit, label, field](int channel, double v, int drag) {
                               edit(label, drag, [channel, v, field](Material& x) {
                                 axisOf(x.*field, channel) = std::max(0.0f, static_cast<float>(v));
                               });
                             },
                             true);
    if (*f.tip && row) row->setToolTip(tr(f.tip));
  }
  for (const MaterialChoice& f : kMaterialChoices) {
    if (f.place != place || !f.appliesTo(m.type)) continue;
    const QString label = tr(f.label);
    const auto field = f.field;
    QWidget* row = b.choice(label, f.key, {tr(f.offLabel), tr(f.onLabel)}, m.*field ? 1 : 0,
                            [edit, label, field](int i) { edit(label, 0, [i, field](Material& x) { x.*field = i == 1; }); });
    if (*f.tip && row) row->setToolTip(tr(f.tip));
  }
}

void PropertyPanel::roughnessRows(Builder& b, const Material& m) {
  const NodeId id = m.id;
  auto edit = nodeEdit<Material, SetMaterial>(id, [](const Scene& sc, NodeId i) { return sc.material(i); });
  const Material defaults;
  // A slider as well as the field: the gesture look-dev artists use most.
  auto* row = new QWidget(body_);
  auto* l = new QHBoxLayout(row);
  l->setContentsMargins(0, 0, 0, 0);
  auto* slider = new QSlider(Qt::Horizontal, row);
  slider->setObjectName("roughnessSlider");
  slider->setRange(0, 1000);
  slider->setValue(static_cast<int>(std::lround(m.roughness * 1000)));
  auto* field = new ScrubField(m.roughness, 0.0, 1.0, defaults.roughness, 3, row);
  field->setObjectName("roughness");
  field->setSizePolicy(QSizePolicy::Fixed, QSizePolicy::Fixed);
  field->setFixedWidth(72);
  l->addWidget(slider, 1);
  l->addWidget(field);
  QObject::connect(slider, &QSlider::valueChanged, slider, [this, slider, field, edit](int v) {
    QSignalBlocker block(field);
    field->setValue(v / 1000.0);
    edit(tr("Roughness"), slider->isSliderDown() ? drag_ : 0, [v](Material& x) { x.roughness = std::max(0.001f, v / 1000.0f); });
  });
  QObject::connect(slider, &QSlider::sliderReleased, slider, [this] { ++drag_; });
  b.connectField(field, [slider, edit](double v, int drag) {
    QSignalBlocker block(slider);
    slider->setValue(static_cast<int>(std::lround(v * 1000)));
    edit(tr("Roughness"), drag, [v](Material& x) { x.roughness = std::max(0.001f, static_cast<float>(v)); });
  });
  form_->addRow(tr("Roughness"), row);
  fieldRows(b, m, MaterialPlace::Rough);
}

void PropertyPanel::textureRows(Builder& b, const Material& m) {
  auto edit = nodeEdit<Material, SetMaterial>(m.id, [](const Scene& sc, NodeId i) { return sc.material(i); });
  // Texture slots: which texture feeds each input, and for file textures the file itself.
  for (const MaterialTexture& f : kMaterialTextures) {
    if (f.place != MaterialPlace::Surface || !f.appliesTo(m.type)) continue;
    const auto field = f.field;
    const char* label = field == &Material::roughnessTexture && roughnessSlotIsThickness(m.type) ? "Thickness texture" : f.label;
    b.nodeChoice(tr(label), f.member, scene_().textures, m.*field, [this, edit, field](NodeId t) {
      edit(tr("Assign texture"), 0, [t, field](Material& x) { x.*field = t; });
      rebuildLater();
    });
    const Texture* tex = scene_().texture(m.*field);
    if (tex && tex->kind == TextureKind::File) texturePath(b, *tex, QString("%1Path").arg(f.member));
    if (field == &Material::bumpTexture && tex) fieldRows(b, m, MaterialPlace::Bumped);
  }
}

void PropertyPanel::buildMaterial(Builder& b, const Material& m) {
  const NodeId id = m.id;
  auto edit = nodeEdit<Material, SetMaterial>(id, [](const Scene& sc, NodeId i) { return sc.material(i); });
  const Material defaults;
  b.header(tr("Material: %1").arg(QString::fromStdString(m.name)));
  QStringList types;
  for (int t = 0; t < kMaterialTypeCount; ++t) types << materialTypeName(static_cast<MaterialType>(t));
  b.choice(tr("Type"), "materialType", types, static_cast<int>(m.type), [this, edit](int i) {
    edit(tr("Material type"), 0, [i](Material& x) {
      const auto type = static_cast<MaterialType>(i);
      // A sheet reads that texture as its thickness, other types as their roughness: one meaning
      // does not carry over to the other (undo brings the texture back with the type).
      if (roughnessSlotIsThickness(type) != roughnessSlotIsThickness(x.type)) x.roughnessTexture = kNoNode;
      x.type = type;
    });
    rebuildLater();  // the type decides which fields apply
  });
  // A boundary has no surface, and hair's colour is its pigment's absorption.
  if (m.type != MaterialType::Boundary && m.type != MaterialType::Hair) {
    // With a texture the colour multiplies it (trace.comp fetchMaterial): a white swatch beside a
    // wood texture read as the surface's colour.
    const bool textured = m.albedoTexture != kNoNode;
    ColorField* albedo = b.color(textured ? tr("Albedo \u00d7 texture") : tr("Albedo"), "albedo", m.albedo, defaults.albedo,
                                 [edit](Vec3 c, int drag) { edit(tr("Albedo"), drag, [c](Material& x) { x.albedo = c; }); });
    if (textured) albedo->setToolTip(tr("Multiplies the albedo texture (below) pixel by pixel"));
  }
  if (hasRoughness(m.type)) roughnessRows(b, m);  // smooth types ignore roughness: no field that does nothing
  fieldRows(b, m, MaterialPlace::Surface);
  if (!isTransmissiveType(m.type)) {
    if (m.coated()) {
      fieldRows(b, m, MaterialPlace::Coated);
    }
  }
  if (holdsMedium(m.type))
    b.medium<Material>(tr("Interior"), "interior", m, &Material::interiorAbsorption, &Material::interiorScattering,
                       &Material::interiorAnisotropy, edit);
  if (m.type == MaterialType::Boundary) return;  // no surface: no texture, emission, alpha or blend applies
  if (isGlassType(m.type))
    b.choice(tr("Glass"), "glassConvention", {tr("Physical"), tr("Tinted reflection (Tungsten)")}, m.tintsReflection ? 1 : 0,
             [edit](int i) { edit(tr("Glass"), 0, [i](Material& x) { x.tintsReflection = i == 1; }); });
  if (m.type == MaterialType::Plastic || m.type == MaterialType::RoughPlastic || m.type == MaterialType::ThinSheet ||
      m.type == MaterialType::Hair) {
    const QString label = m.type == MaterialType::ThinSheet ? tr("Absorption")
                          : m.type == MaterialType::Hair    ? tr("Pigment absorption")
                                                            : tr("Coating absorption");
    QWidget* w = b.vec3(
        label, "coatingAbsorption", m.coatingAbsorption, 0.01,
        [edit, label](int channel, double v, int drag) {
          edit(label, drag, [channel, v](Material& x) { axisOf(x.coatingAbsorption, channel) = std::max(0.0f, static_cast<float>(v)); });
        },
        true);
    if (m.type == MaterialType::Hair)
      w->setToolTip(
          tr("Per unit of the fibre's radius. Eumelanin (brown to black) absorbs about 0.42, 0.70, 1.37 per unit of "
             "concentration, pheomelanin (red to blond) 0.19, 0.40, 1.05"));
  }
  if (m.type == MaterialType::ThinSheet && m.filmThickness > 0)
    b.choice(tr("Interference"), "interferenceConvention", {tr("Physical"), tr("Squared (Tungsten)")}, m.tintsReflection ? 1 : 0,
             [edit](int i) { edit(tr("Interference"), 0, [i](Material& x) { x.tintsReflection = i == 1; }); })
        ->setToolTip(tr("Tungsten's form, for scenes made for it, shows a few per cent of the physical colours"));
  if (m.type == MaterialType::Conductor || m.type == MaterialType::RoughConductor) {
    QStringList metals;
    for (const auto& n : conductorNames()) metals << QString::fromStdString(n);
    b.choice(tr("Metal"), "metal", metals, std::max(0, static_cast<int>(metals.indexOf(QString::fromStdString(m.metal)))),
             [edit, metals](int i) {
               std::string name = metals.value(i).toStdString();
               edit(tr("Metal"), 0, [&](Material& x) {
                 x.metal = name;
                 conductorIor(name, &x.eta, &x.k);
               });
             });
  }
  textureRows(b, m);
  emissionRows(b, m);
  blendRows(b, m);
}

void PropertyPanel::emissionRows(Builder& b, const Material& m) {
  const NodeId id = m.id;
  auto edit = nodeEdit<Material, SetMaterial>(id, [](const Scene& sc, NodeId i) { return sc.material(i); });

  // Shown as a swatch (the colour, normalised: files give radiance above 1) and a strength, the
  // peak of the radiance; each edit keeps the other, a strength of 0 included.
  auto tintOf = [](const Material& x) { return peak(x.emission) > 0 ? x.emission * (1.0f / peak(x.emission)) : Vec3{1.0f}; };
  auto strengthOf = [](const Material& x) { return peak(x.emission) * x.emissionStrength; };
  b.color(tr("Emission colour"), "emissionColor", tintOf(m), Vec3{1.0f}, [this, id, edit, strengthOf](Vec3 c, int drag) {
    const Material* cur = scene_().material(id);
    if (!cur) return;
    const bool was = cur->emissive();
    const float s = strengthOf(*cur);
    edit(tr("Emission colour"), drag, [c, s](Material& x) {
      x.emission = c;
      x.emissionStrength = s;
    });
    const Material* now = scene_().material(id);
    if (drag != kPreview && now && now->emissive() != was) rebuildLater();  // black: no cone to show
  });
  b.number(tr("Emission"), "emission", strengthOf(m), 0.0, 1e5, 0.0, 2, [this, id, edit, tintOf](double v, int drag) {
    const Material* cur = scene_().material(id);
    if (!cur) return;
    const bool was = cur->emissive();
    const Vec3 t = tintOf(*cur);
    edit(tr("Emission"), drag, [t, v](Material& x) {
      x.emission = t;
      x.emissionStrength = static_cast<float>(v);
    });
    if (was != (v > 0)) rebuildLater(drag);  // the cone shows only while it emits
  });
  if (m.emissive()) fieldRows(b, m, MaterialPlace::Emissive);
}

void PropertyPanel::blendRows(Builder& b, const Material& m) {
  const NodeId id = m.id;
  auto edit = nodeEdit<Material, SetMaterial>(id, [](const Scene& sc, NodeId i) { return sc.material(i); });

  // A blend with another material (Tungsten's mixed bsdf): this one's share, the other's the rest.
  b.nodeChoice(
      tr("Blend with"), "blendWith", scene_().materials, m.blendWith,
      [this, edit](NodeId other) {
        edit(tr("Blend with"), 0, [other](Material& x) { x.setBlendWith(other); });
        rebuildLater();
      },
      id);
  if (m.blendWith != kNoNode) {
    b.number(tr("Blend ratio"), "blendRatio", m.blendRatio, 0.0, 1.0, 0.5, 3,
             [edit](double v, int drag) { edit(tr("Blend ratio"), drag, [v](Material& x) { x.blendRatio = static_cast<float>(v); }); });
    // A mask that varies the ratio over the surface (the mean of its channels scales it).
    b.nodeChoice(tr("Blend ratio texture"), "blendRatioTexture", scene_().textures, m.blendRatioTexture, [this, edit](NodeId t) {
      edit(tr("Assign texture"), 0, [t](Material& x) { x.blendRatioTexture = t; });
      rebuildLater();
    });
    const Texture* tex = scene_().texture(m.blendRatioTexture);
    if (tex && tex->kind == TextureKind::File) texturePath(b, *tex, "blendRatioTexturePath");
  }
}

void PropertyPanel::texturePath(Builder& b, const Texture& t, const QString& objectName) {
  auto* row = new QWidget(body_);
  auto* l = new QHBoxLayout(row);
  l->setContentsMargins(0, 0, 0, 0);
  auto* path = new QLineEdit(QString::fromStdString(t.path.string()), row);
  path->setObjectName(objectName);
  path->setToolTip(tr("The texture's file (relative paths resolve against the scene's folder); Enter applies"));
  auto* browse = new QToolButton(row);
  browse->setText("...");
  l->addWidget(path, 1);
  l->addWidget(browse);
  const NodeId id = t.id;
  auto apply = [this, id](const QString& file) {
    const Texture* cur = scene_().texture(id);
    if (!cur || file.toStdString() == cur->path.string()) return;
    Texture after = *cur;
    after.path = file.toStdString();
    send(SetTexture{*cur}, SetTexture{after}, tr("Texture file"), 0);
  };
  QObject::connect(path, &QLineEdit::returnPressed, path, [path, apply] { apply(path->text()); });
  QObject::connect(browse, &QToolButton::clicked, browse, [this, path, apply] {
    QString f = QFileDialog::getOpenFileName(this, tr("Texture file"), path->text(),
                                             tr("Images (*.png *.jpg *.jpeg *.exr *.hdr *.tif *.tiff *.tga *.bmp);;All files (*)"));
    if (f.isEmpty()) return;
    path->setText(f);
    apply(f);
  });
  b.row(tr("  file (%1)").arg(QString::fromStdString(t.name)), row);
}

void PropertyPanel::buildLight(Builder& b, const Light& l) {
  const NodeId id = l.id;
  auto edit = nodeEdit<Light, SetLight>(id, [](const Scene& sc, NodeId i) { return sc.light(i); });
  const Light defaults;
  b.header(tr("Light: %1").arg(QString::fromStdString(l.name)));
  b.choice(tr("Type"), "lightType", {tr("point"), tr("spot"), tr("directional")}, static_cast<int>(l.type), [this, edit](int i) {
    edit(tr("Light type"), 0, [i](Light& x) { x.type = static_cast<LightType>(i); });
    rebuildLater();
  });
  b.color(tr("Colour"), "lightColor", l.color, defaults.color,
          [edit](Vec3 c, int drag) { edit(tr("Light colour"), drag, [c](Light& x) { x.color = c; }); });
  b.number(tr("Intensity"), "intensity", l.intensity, 0.0, 1e6, defaults.intensity, 3,
           [edit](double v, int drag) { edit(tr("Light intensity"), drag, [v](Light& x) { x.intensity = static_cast<float>(v); }); });
  if (l.type != LightType::Directional)
    b.vec3(tr("Position"), "lightPosition", l.position, 0.01, [edit](int axis, double v, int drag) {
      edit(tr("Move light"), drag, [&](Light& x) { axisOf(x.position, axis) = static_cast<float>(v); });
    });
  if (l.type != LightType::Point)
    b.vec3(tr("Direction"), "lightDirection", l.direction, 0.01, [edit](int axis, double v, int drag) {
      edit(tr("Aim light"), drag, [&](Light& x) {
        Vec3 d = x.direction;
        axisOf(d, axis) = static_cast<float>(v);
        if (length(d) > 1e-6f) x.direction = d;  // a zero direction is refused, not sent
      });
    });
  if (l.type == LightType::Directional)
    b.number(tr("Sun angular radius"), "angularRadius", degrees(l.angularRadius), 0.0, 90.0, degrees(defaults.angularRadius), 2,
             [edit](double v, int drag) {
               edit(tr("Sun angular radius"), drag, [v](Light& x) { x.angularRadius = radians(static_cast<float>(v)); });
             });
  if (l.type == LightType::Spot) {
    b.number(tr("Cone half angle"), "spotAngle", degrees(l.spotAngle), 0.5, 89.0, degrees(defaults.spotAngle), 1,
             [edit](double v, int drag) { edit(tr("Spot angle"), drag, [v](Light& x) { x.spotAngle = radians(static_cast<float>(v)); }); });
    b.number(tr("Blend"), "spotBlend", l.spotBlend, 0.0, 1.0, defaults.spotBlend, 3,
             [edit](double v, int drag) { edit(tr("Spot blend"), drag, [v](Light& x) { x.spotBlend = static_cast<float>(v); }); });
  }
}

void PropertyPanel::buildCamera(Builder& b) {
  auto edit = [this](const QString& what, int drag, const std::function<void(Camera&)>& change) {
    Camera after = scene_().camera;
    change(after);
    send(SetCamera{scene_().camera}, SetCamera{after}, what, drag);
  };
  const Camera& c = scene_().camera;
  b.header(tr("Camera"));
  b.vec3(tr("Position"), "cameraPosition", c.position, 0.01, [edit](int axis, double v, int drag) {
    edit(tr("Camera position"), drag, [&](Camera& x) { axisOf(x.position, axis) = static_cast<float>(v); });
  });
  b.vec3(tr("Looks at"), "cameraTarget", c.target, 0.01, [edit](int axis, double v, int drag) {
    edit(tr("Camera target"), drag, [&](Camera& x) { axisOf(x.target, axis) = static_cast<float>(v); });
  });
  b.number(tr("Vertical field of view"), "fov", degrees(c.verticalFov), 1.0, 170.0, 40.0, 1, [edit](double v, int drag) {
    edit(tr("Field of view"), drag, [v](Camera& x) { x.verticalFov = radians(static_cast<float>(v)); });
  });
  // Depth of field: a lens of this radius, sharp at the focus distance (0: a pinhole).
  b.number(tr("Aperture radius"), "apertureRadius", c.apertureRadius, 0.0, 10.0, 0.0, 4,
           [edit](double v, int drag) { edit(tr("Aperture radius"), drag, [v](Camera& x) { x.apertureRadius = static_cast<float>(v); }); });
  b.number(tr("Focus distance"), "focusDistance", c.focusDistance, 0.001, 1e5, 1.0, 3,
           [edit](double v, int drag) { edit(tr("Focus distance"), drag, [v](Camera& x) { x.focusDistance = static_cast<float>(v); }); });
}

void PropertyPanel::buildEnvironment(Builder& b) {
  auto edit = [this](const QString& what, int drag, const std::function<void(Environment&)>& change) {
    Environment after = scene_().environment;
    change(after);
    send(SetEnvironment{scene_().environment}, SetEnvironment{after}, what, drag);
  };
  const Environment& e = scene_().environment;
  const Environment defaults;
  b.header(tr("Environment"));
  QStringList types{tr("constant"), tr("map"), tr("sky")};
  if (e.type != EnvironmentType::Map && e.map == kNoNode) types.removeAt(1);
  int index = e.type == EnvironmentType::Constant ? 0 : e.type == EnvironmentType::Sky ? types.size() - 1 : 1;
  b.choice(tr("Type"), "environmentType", types, index, [this, edit, types](int i) {
    QString t = types.value(i);
    EnvironmentType type = t == tr("sky") ? EnvironmentType::Sky : t == tr("map") ? EnvironmentType::Map : EnvironmentType::Constant;
    edit(tr("Environment type"), 0, [type](Environment& x) { x.type = type; });
    rebuildLater();
  });
  b.number(tr("Intensity"), "environmentIntensity", e.intensity, 0.0, 1e4, defaults.intensity, 3, [edit](double v, int drag) {
    edit(tr("Environment intensity"), drag, [v](Environment& x) { x.intensity = static_cast<float>(v); });
  });
  if (e.type != EnvironmentType::Sky) {
    b.color(tr("Colour"), "environmentColor", e.color, Vec3{1.0f},
            [edit](Vec3 c, int drag) { edit(tr("Environment colour"), drag, [c](Environment& x) { x.color = c; }); });
  }
  if (e.type == EnvironmentType::Map)
    b.number(tr("Rotation"), "environmentRotation", degrees(e.rotation), -360.0, 360.0, 0.0, 1, [edit](double v, int drag) {
      edit(tr("Environment rotation"), drag, [v](Environment& x) { x.rotation = radians(static_cast<float>(v)); });
    });
  if (e.type == EnvironmentType::Sky) {
    b.color(tr("Zenith"), "zenith", e.zenith, defaults.zenith,
            [edit](Vec3 c, int drag) { edit(tr("Sky zenith"), drag, [c](Environment& x) { x.zenith = c; }); });
    b.color(tr("Horizon"), "horizon", e.horizon, defaults.horizon,
            [edit](Vec3 c, int drag) { edit(tr("Sky horizon"), drag, [c](Environment& x) { x.horizon = c; }); });
    b.color(tr("Ground"), "ground", e.ground, defaults.ground,
            [edit](Vec3 c, int drag) { edit(tr("Sky ground"), drag, [c](Environment& x) { x.ground = c; }); });
  }
  // The medium filling the world (fog), as a glass's or boundary's interior.
  b.medium<Environment>(tr("Medium"), "medium", e, &Environment::mediumAbsorption, &Environment::mediumScattering,
                        &Environment::mediumAnisotropy, edit);
}

void PropertyPanel::buildRender(Builder& b) {
  auto edit = [this](const QString& what, int drag, const std::function<void(RenderSettings&)>& change) {
    RenderSettings before = scene_().settings, after = before;
    change(after);
    send(SetRenderSettings{before}, SetRenderSettings{after}, what, drag);
  };
  const RenderSettings& r = scene_().settings;
  b.header(tr("Render settings"));
  b.number(tr("Max bounces"), "maxBounces", r.maxBounces, 0, 1024, RenderSettings{}.maxBounces, 0,
           [edit](double v, int drag) { edit(tr("Max bounces"), drag, [v](RenderSettings& x) { x.maxBounces = static_cast<int>(v); }); });
  // Light that arrives in fewer bounces is left out: 1 hides the lights seen directly.
  b.number(tr("Min bounces"), "minBounces", r.minBounces, 0, 1024, RenderSettings{}.minBounces, 0,
           [edit](double v, int drag) { edit(tr("Min bounces"), drag, [v](RenderSettings& x) { x.minBounces = static_cast<int>(v); }); });
  // Off, only paths that hit a light see it (Tungsten's enable_light_sampling false): noisier, and
  // point, spot and sun lights without a disc go dark.
  b.check(tr("Light sampling"), "lightSampling", r.lightSampling, [edit](bool on) {
    edit(on ? tr("Light sampling on") : tr("Light sampling off"), 0, [on](RenderSettings& x) { x.lightSampling = on; });
  });
  b.number(tr("Seed"), "seed", r.seed, 0, 1e9, 0, 0,
           [edit](double v, int drag) { edit(tr("Seed"), drag, [v](RenderSettings& x) { x.seed = static_cast<std::uint32_t>(v); }); });
  QStringList filters{tr("Box"), tr("Tent"), tr("Gaussian"), tr("Blackman-Harris")};
  b.choice(tr("Pixel filter"), "pixelFilter", filters, static_cast<int>(r.pixelFilter), [this, edit](int i) {
    if (i < 0 || i >= kPixelFilterCount) return;
    edit(tr("Pixel filter"), 0, [i](RenderSettings& x) {
      x.pixelFilter = static_cast<PixelFilter>(i);
      x.filterWidth = defaultFilterWidth(x.pixelFilter);  // each filter at its usual width
    });
    rebuildLater();  // the width field shows the new default
  });
  b.number(
      tr("Filter width (px)"), "filterWidth", r.filterWidth, 0.5, 8.0, defaultFilterWidth(r.pixelFilter), 2,
      [edit](double v, int drag) { edit(tr("Filter width"), drag, [v](RenderSettings& x) { x.filterWidth = static_cast<float>(v); }); });
  // Tungsten scene files come with Tungsten's way of drawing its tent and Gaussian, so they converge
  // to the picture their author saw; any scene may switch.
  b.choice(tr("Filter sampling"), "filterSampling", {tr("Exact"), tr("Stepped table (Tungsten)")}, static_cast<int>(r.filterSampling),
           [edit](int i) {
             if (i < 0 || i > 1) return;
             edit(tr("Filter sampling"), 0, [i](RenderSettings& x) { x.filterSampling = static_cast<FilterSampling>(i); });
           });
  // Tungsten scene files come with its shading-normal convention too (see ShadingConvention).
  b.choice(tr("Shading normals"), "shading", {tr("Consistent"), tr("Unchecked (Tungsten)")}, static_cast<int>(r.shading), [edit](int i) {
    if (i < 0 || i > 1) return;
    edit(tr("Shading normals"), 0, [i](RenderSettings& x) { x.shading = static_cast<ShadingConvention>(i); });
  });
  // And with its Russian roulette, so that a sample is the same work as in Tungsten (see Roulette).
  b.choice(tr("Russian roulette"), "roulette", {tr("Standard"), tr("Low throughput (Tungsten)")}, static_cast<int>(r.roulette),
           [edit](int i) {
             if (i < 0 || i > 1) return;
             edit(tr("Russian roulette"), 0, [i](RenderSettings& x) { x.roulette = static_cast<Roulette>(i); });
           });
  // And with where its rays leave a surface, which decides what leaks through cracks (see RayOffset).
  b.choice(tr("Ray offset"), "rayOffset", {tr("Robust"), tr("Skip 0.0005 units (Tungsten)")}, static_cast<int>(r.rayOffset), [edit](int i) {
    if (i < 0 || i > 1) return;
    edit(tr("Ray offset"), 0, [i](RenderSettings& x) { x.rayOffset = static_cast<RayOffset>(i); });
  });
  // The scene's own image: what `retile render` renders and the framing the viewport can show.
  b.number(tr("Width (px)"), "resolutionWidth", r.width, 1, kMaxImageSide, RenderSettings{}.width, 0,
           [edit](double v, int drag) { edit(tr("Resolution"), drag, [v](RenderSettings& x) { x.width = static_cast<int>(v); }); });
  b.number(tr("Height (px)"), "resolutionHeight", r.height, 1, kMaxImageSide, RenderSettings{}.height, 0,
           [edit](double v, int drag) { edit(tr("Resolution"), drag, [v](RenderSettings& x) { x.height = static_cast<int>(v); }); });
  // The viewport converges for as long as it is left; `retile render` stops here.
  b.number(tr("Samples per pixel"), "samplesPerPixel", r.samplesPerPixel, 1, 1048576, RenderSettings{}.samplesPerPixel, 0,
           [edit](double v, int drag) {
             edit(tr("Samples per pixel"), drag, [v](RenderSettings& x) { x.samplesPerPixel = static_cast<int>(v); });
           });
  // How the viewport's image was sized (Render > Framing, Render > Render resolution).
  viewportLine_ = b.label(tr("Viewport"), viewportText());
}

QString PropertyPanel::viewportText() const {
  return tr("%1 x %2, %3")
      .arg(renderSize_.width())
      .arg(renderSize_.height())
      .arg(cameraFraming_ ? tr("framed as the scene") : tr("filling the view"));
}

void PropertyPanel::setRenderSize(QSize s, bool cameraFraming) {
  renderSize_ = s;
  cameraFraming_ = cameraFraming;
  if (viewportLine_) viewportLine_->setText(viewportText());
}

}  // namespace retile::ui
