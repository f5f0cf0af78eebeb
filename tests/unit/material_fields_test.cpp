// Every row of shaders/shared/material_fields.h reaches every user of it: the native writer and
// reader, validation, edits and the packer. A field added as a row is covered here with no
// test of its own for those paths.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "render/render_scene.h"
#include "retile/edit.h"
#include "retile/io.h"
#include "scene/primitives.h"
#include "scene/validate.h"

namespace retile {
namespace {

// A value inside the row's range, away from its default and its ends.
float inside(const MaterialScalar& f) {
  const float v = f.lo + 0.37f * (f.hi - f.lo);
  return v == f.fallback ? f.lo + 0.61f * (f.hi - f.lo) : v;
}

MaterialType firstTypeOf(const MaterialScalar& f) {
  for (int t = 0; t < kMaterialTypeCount; ++t)
    if (f.appliesTo(static_cast<MaterialType>(t))) return static_cast<MaterialType>(t);
  return MaterialType::Lambert;
}

TEST(MaterialFields, TheRowsAreConsistent) {
  std::set<std::string> keys, members;
  for (const MaterialScalar& f : kMaterialScalars) {
    SCOPED_TRACE(f.member);
    EXPECT_TRUE(keys.insert(f.key).second) << "a key names one field";
    EXPECT_TRUE(members.insert(f.member).second);
    EXPECT_LT(f.lo, f.hi);
    EXPECT_GE(f.fallback, f.lo);
    EXPECT_LE(f.fallback, f.hi);
    EXPECT_EQ(Material{}.*f.field, f.fallback) << "a new material holds the default";
    EXPECT_NE(f.types, 0u);
    EXPECT_GT(std::string(f.label).size(), 0u);
    EXPECT_EQ(f.texel < 0, f.component < 0);
    if (f.packed()) {
      EXPECT_LT(f.texel, gpu::kMaterialTexels);
      EXPECT_LE(f.component, 3);
    }
  }
}

TEST(MaterialFields, TwoFieldsShareASlotOnlyForDifferentTypes) {
  for (const MaterialScalar& a : kMaterialScalars) {
    for (const MaterialScalar& b : kMaterialScalars) {
      if (&a != &b && a.packed() && a.texel == b.texel && a.component == b.component) {
        EXPECT_EQ(a.types & b.types, 0u) << a.member << " and " << b.member;
      }
    }
  }
}

TEST(MaterialFields, EveryFieldIsWrittenAndReadBack) {
  Scene s = makeDefaultScene();
  Material& m = s.materials[0];
  for (const MaterialScalar& f : kMaterialScalars) m.*f.field = inside(f);
  const std::string text = nativeSceneToString(s);
  for (const MaterialScalar& f : kMaterialScalars) EXPECT_NE(text.find("\"" + std::string(f.key) + "\""), std::string::npos) << f.key;
  auto back = nativeSceneFromString(text, "fields.json", ".");
  ASSERT_TRUE(back.ok()) << back.error();
  const Material& r = back.value().scene.materials[0];
  for (const MaterialScalar& f : kMaterialScalars) EXPECT_EQ(r.*f.field, m.*f.field) << f.key;
}

TEST(MaterialFields, AFieldAtItsDefaultIsLeftOutOfTheFile) {
  Scene s = makeDefaultScene();
  for (Material& m : s.materials)
    for (const MaterialScalar& f : kMaterialScalars) m.*f.field = f.fallback;
  const std::string text = nativeSceneToString(s);
  for (const MaterialScalar& f : kMaterialScalars) EXPECT_EQ(text.find("\"" + std::string(f.key) + "\""), std::string::npos) << f.key;
}

TEST(MaterialFields, ValidationClampsEveryFieldToItsRangeAndSaysWhich) {
  for (const MaterialScalar& f : kMaterialScalars) {
    SCOPED_TRACE(f.member);
    for (float bad : {f.hi + 1.0f + std::abs(f.hi), f.lo - 1.0f - std::abs(f.lo), std::nanf("")}) {
      Scene s = makeDefaultScene();
      Material& m = s.materials[0];
      m.type = MaterialType::OrenNayar;  // the type whose roughness reaches the row's end
      m.*f.field = bad;
      std::vector<std::string> warnings;
      ASSERT_TRUE(validateScene(s, warnings).ok());
      const float now = s.materials[0].*f.field;
      EXPECT_EQ(now, std::isnan(bad) ? f.fallback : std::clamp(bad, f.lo, f.hi)) << bad;
      EXPECT_TRUE(std::any_of(warnings.begin(), warnings.end(), [&](const std::string& w) { return w.find(f.key) != std::string::npos; }))
          << bad;
    }
  }
}

TEST(MaterialFields, AnEditOutsideTheRangeIsRefusedAndNamesTheField) {
  for (const MaterialScalar& f : kMaterialScalars) {
    Document doc(makeDefaultScene());
    const auto v0 = doc.version();
    for (float bad : {f.hi + 1.0f + std::abs(f.hi), f.lo - 1.0f - std::abs(f.lo), std::nanf("")}) {
      Material m = doc.scene().materials[0];
      m.*f.field = bad;
      auto applied = doc.apply(SetMaterial{m});
      ASSERT_FALSE(applied.ok()) << f.member << " " << bad;
      EXPECT_NE(applied.error().find(f.key), std::string::npos) << applied.error();
    }
    Material m = doc.scene().materials[0];
    m.*f.field = inside(f);
    EXPECT_TRUE(doc.apply(SetMaterial{m}).ok()) << f.member;
    EXPECT_EQ(doc.version(), v0 + 1);
  }
}

TEST(MaterialFields, APackedFieldLandsInItsSlotForItsTypesClamped) {
  for (const MaterialScalar& f : kMaterialScalars) {
    if (!f.packed()) continue;
    SCOPED_TRACE(f.member);
    Material m;
    m.type = firstTypeOf(f);
    auto component = [&](const Material& x) {
      const gpu::vec4 t = packMaterial(x)[static_cast<std::size_t>(f.texel)];
      const float c[4] = {t.x, t.y, t.z, t.w};
      return c[f.component];
    };
    m.*f.field = inside(f);
    EXPECT_EQ(component(m), inside(f));
    m.*f.field = f.hi + 1.0f + std::abs(f.hi);
    EXPECT_EQ(component(m), f.hi);
    m.*f.field = std::nanf("");
    EXPECT_EQ(component(m), f.fallback);
  }
}

}  // namespace
}  // namespace retile
