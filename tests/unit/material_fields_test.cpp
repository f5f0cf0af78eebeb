// Every row of shaders/shared/material_fields.h (scalars, colours, textures, choices) reaches every
// user of it: the native writer and reader, validation, edits and the packer. A field added as a
// row is covered here with no test of its own for those paths.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
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

// A colour inside the row's range, away from its default.
Vec3 inside(const MaterialColor& f) {
  const Vec3 v{0.25f, 0.5f, 0.75f};
  return v == f.fallback ? Vec3{0.5f, 0.25f, 0.125f} : v;
}

template <class Row>
MaterialType firstTypeOf(const Row& f) {
  for (int t = 0; t < kMaterialTypeCount; ++t)
    if (f.appliesTo(static_cast<MaterialType>(t))) return static_cast<MaterialType>(t);
  return MaterialType::Lambert;
}

// A new material of the first type the row applies to.
template <class Row>
Material ofFirstType(const Row& f) {
  Material m;
  m.type = firstTypeOf(f);
  return m;
}

template <class Row>
MaterialType firstTypeNotOf(const Row& f) {
  for (int t = 0; t < kMaterialTypeCount; ++t)
    if (!f.appliesTo(static_cast<MaterialType>(t))) return static_cast<MaterialType>(t);
  return MaterialType::Lambert;
}

float slot(const std::array<gpu::vec4, gpu::kMaterialTexels>& texels, int texel, int c) {
  const gpu::vec4 t = texels[static_cast<std::size_t>(texel)];
  const float v[4] = {t.x, t.y, t.z, t.w};
  return v[c];
}

int intSlot(const std::array<gpu::vec4, gpu::kMaterialTexels>& texels, int texel, int c) {
  return std::bit_cast<int>(slot(texels, texel, c));
}

bool mentions(const std::vector<std::string>& warnings, const char* key) {
  return std::any_of(warnings.begin(), warnings.end(), [&](const std::string& w) { return w.find(key) != std::string::npos; });
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

TEST(MaterialFields, TheColourTextureAndChoiceRowsAreConsistent) {
  std::set<std::string> keys;
  for (const MaterialScalar& f : kMaterialScalars) keys.insert(f.key);
  for (const MaterialColor& f : kMaterialColors) {
    SCOPED_TRACE(f.member);
    EXPECT_TRUE(keys.insert(f.key).second) << "a key names one field";
    EXPECT_EQ(Material{}.*f.field, f.fallback) << "a new material holds the default";
    EXPECT_TRUE(f.inRange(f.fallback));
    // A medium's rows cap it where the kernel's sums of extinction stay finite.
    if (f.field == &Material::interiorAbsorption || f.field == &Material::interiorScattering) {
      EXPECT_EQ(f.hi, kMaxExtinction);
    }
    EXPECT_NE(f.types, 0u);
    EXPECT_LT(f.texel, gpu::kMaterialTexels);
  }
  for (const MaterialTexture& f : kMaterialTextures) {
    SCOPED_TRACE(f.member);
    EXPECT_TRUE(keys.insert(f.key).second);
    EXPECT_EQ(Material{}.*f.field, kNoNode);
    EXPECT_GE(f.texel, 0);
    EXPECT_LT(f.texel, gpu::kMaterialTexels);
    EXPECT_LE(f.component, 3);
  }
  for (const MaterialChoice& f : kMaterialChoices) {
    SCOPED_TRACE(f.member);
    EXPECT_TRUE(keys.insert(f.key).second);
    EXPECT_FALSE(Material{}.*f.field);
    EXPECT_STRNE(f.off, f.on);
  }
  EXPECT_EQ(std::size(kMaterialTextures), Material::kTextureCount);
}

TEST(MaterialFields, TwoFieldsShareASlotOnlyForDifferentTypes) {
  for (const MaterialScalar& a : kMaterialScalars) {
    for (const MaterialScalar& b : kMaterialScalars) {
      if (&a != &b && a.packed() && a.texel == b.texel && a.component == b.component) {
        EXPECT_EQ(a.types & b.types, 0u) << a.member << " and " << b.member;
      }
    }
    // packMaterial writes -1 to a texture's slot for the types it does not apply to: the slot is
    // the texture's alone.
    for (const MaterialTexture& t : kMaterialTextures)
      EXPECT_FALSE(a.packed() && a.texel == t.texel && a.component == t.component) << a.member << " and " << t.member;
    for (const MaterialColor& c : kMaterialColors)
      if (a.packed() && a.texel == c.texel && a.component < 3) {
        EXPECT_EQ(a.types & c.types, 0u) << a.member << " and " << c.member;
      }
  }
  for (const MaterialTexture& a : kMaterialTextures)
    for (const MaterialTexture& b : kMaterialTextures)
      if (&a != &b) {
        EXPECT_FALSE(a.texel == b.texel && a.component == b.component) << a.member << " and " << b.member;
      }
  for (const MaterialTexture& t : kMaterialTextures)
    for (const MaterialColor& c : kMaterialColors)
      EXPECT_FALSE(c.packed() && c.texel == t.texel && t.component < 3) << c.member << " and " << t.member;
}

TEST(MaterialFields, EveryFieldIsWrittenAndReadBack) {
  Scene s = makeDefaultScene();
  Material& m = s.materials[0];
  ASSERT_FALSE(s.textures.empty());
  for (const MaterialScalar& f : kMaterialScalars) m.*f.field = inside(f);
  for (const MaterialColor& f : kMaterialColors) m.*f.field = inside(f);
  for (const MaterialTexture& f : kMaterialTextures) m.*f.field = s.textures[0].id;
  for (const MaterialChoice& f : kMaterialChoices) m.*f.field = true;
  const std::string text = nativeSceneToString(s);
  auto keyed = [&](const char* key) { return text.find("\"" + std::string(key) + "\"") != std::string::npos; };
  for (const MaterialScalar& f : kMaterialScalars) EXPECT_TRUE(keyed(f.key)) << f.key;
  for (const MaterialColor& f : kMaterialColors) EXPECT_TRUE(keyed(f.key)) << f.key;
  for (const MaterialTexture& f : kMaterialTextures) EXPECT_TRUE(keyed(f.key)) << f.key;
  for (const MaterialChoice& f : kMaterialChoices) EXPECT_TRUE(keyed(f.key)) << f.key;
  auto back = nativeSceneFromString(text, "fields.json", ".");
  ASSERT_TRUE(back.ok()) << back.error();
  const Material& r = back.value().scene.materials[0];
  EXPECT_EQ(r, m);
}

TEST(MaterialFields, AFieldAtItsDefaultIsLeftOutOfTheFile) {
  Scene s = makeDefaultScene();
  for (Material& m : s.materials) {
    for (const MaterialScalar& f : kMaterialScalars) m.*f.field = f.fallback;
    for (const MaterialColor& f : kMaterialColors) m.*f.field = f.fallback;
    for (const MaterialTexture& f : kMaterialTextures) m.*f.field = kNoNode;
    for (const MaterialChoice& f : kMaterialChoices) m.*f.field = false;
  }
  const std::string text = nativeSceneToString(s);
  auto keyed = [&](const char* key) { return text.find("\"" + std::string(key) + "\"") != std::string::npos; };
  for (const MaterialScalar& f : kMaterialScalars) EXPECT_FALSE(keyed(f.key)) << f.key;
  for (const MaterialColor& f : kMaterialColors) EXPECT_FALSE(keyed(f.key)) << f.key;
  for (const MaterialTexture& f : kMaterialTextures) EXPECT_FALSE(keyed(f.key)) << f.key;
  for (const MaterialChoice& f : kMaterialChoices) EXPECT_FALSE(keyed(f.key)) << f.key;
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
    Material m = ofFirstType(f);
    auto at = [&](const Material& x) { return slot(packMaterial(x), f.texel, f.component); };
    m.*f.field = inside(f);
    EXPECT_EQ(at(m), inside(f)) << f.member;
    m.*f.field = f.hi + 1.0f + std::abs(f.hi);
    EXPECT_EQ(at(m), f.hi) << f.member;
    m.*f.field = std::nanf("");
    EXPECT_EQ(at(m), f.fallback) << f.member;
  }
}

TEST(MaterialFields, ValidationClampsEveryColourAndSaysWhich) {
  for (const MaterialColor& f : kMaterialColors) {
    SCOPED_TRACE(f.member);
    for (const Vec3 bad : {Vec3{-0.5f, 0.2f, 0.2f}, Vec3{0.1f, 2.0f * f.hi, 0.3f}, Vec3{std::nanf(""), 0.0f, 0.0f}}) {
      Scene s = makeDefaultScene();
      s.materials[0].*f.field = bad;
      std::vector<std::string> warnings;
      ASSERT_TRUE(validateScene(s, warnings).ok());
      const Vec3 now = s.materials[0].*f.field;
      EXPECT_TRUE(f.inRange(now));
      EXPECT_EQ(now, std::isnan(bad.x) ? f.fallback : f.clamp(bad));
      EXPECT_TRUE(mentions(warnings, f.key));
    }
  }
}

TEST(MaterialFields, AColourEditOutsideTheRangeIsRefusedAndNamesTheField) {
  for (const MaterialColor& f : kMaterialColors) {
    Document doc(makeDefaultScene());
    for (const Vec3 bad : {Vec3{-0.5f, 0.2f, 0.2f}, Vec3{0.1f, 2.0f * f.hi, 0.3f}, Vec3{std::nanf(""), 0.0f, 0.0f}}) {
      Material m = doc.scene().materials[0];
      m.*f.field = bad;
      auto applied = doc.apply(SetMaterial{m});
      ASSERT_FALSE(applied.ok()) << f.member;
      EXPECT_NE(applied.error().find(f.key), std::string::npos) << applied.error();
    }
    Material m = doc.scene().materials[0];
    m.*f.field = inside(f);
    EXPECT_TRUE(doc.apply(SetMaterial{m}).ok()) << f.member;
  }
}

TEST(MaterialFields, APackedColourLandsInItsTexelForItsTypesClamped) {
  for (const MaterialColor& f : kMaterialColors) {
    if (!f.packed()) continue;
    SCOPED_TRACE(f.member);
    auto at = [&](const Material& x) {
      const auto t = packMaterial(x);
      return Vec3{slot(t, f.texel, 0), slot(t, f.texel, 1), slot(t, f.texel, 2)};
    };
    Material m = ofFirstType(f);
    m.*f.field = inside(f);
    EXPECT_EQ(at(m), inside(f));
    m.*f.field = Vec3{-1.0f, 2.0f * f.hi, 0.5f};
    EXPECT_EQ(at(m), (Vec3{0.0f, f.hi, 0.5f}));
    m.type = firstTypeNotOf(f);
    m.*f.field = inside(f);
    if (!f.appliesTo(m.type)) {
      EXPECT_NE(at(m), inside(f)) << "not packed for a type it does not apply to";
    }
  }
}

TEST(MaterialFields, ATexturesIndexLandsInItsSlotForItsTypes) {
  const NodeId texture = 77;
  auto index = [&](NodeId t) { return t == texture ? 5 : -1; };
  for (const MaterialTexture& f : kMaterialTextures) {
    SCOPED_TRACE(f.member);
    Material m;
    m.type = firstTypeOf(f);
    m.*f.field = texture;
    EXPECT_EQ(intSlot(packMaterial(m, index, 3), f.texel, f.component), 5);
    EXPECT_EQ(intSlot(packMaterial(m, {}, 3), f.texel, f.component), -1) << "no textures loaded: none";
    m.*f.field = kNoNode;
    EXPECT_EQ(intSlot(packMaterial(m, index, 3), f.texel, f.component), -1);
    m.*f.field = texture;
    m.type = firstTypeNotOf(f);
    if (!f.appliesTo(m.type)) {
      EXPECT_EQ(intSlot(packMaterial(m, index, 3), f.texel, f.component), -1) << "a type it does not apply to";
    }
  }
  // What has no effect is not packed: a bump of strength 0, a ratio without a blend.
  Material m;
  m.bumpTexture = m.blendRatioTexture = texture;
  m.bumpStrength = 0;
  const auto t = packMaterial(m, index, -1);
  const auto slotOf = [](NodeId Material::*field) {
    for (const MaterialTexture& f : kMaterialTextures)
      if (f.field == field) return std::pair{f.texel, f.component};
    return std::pair{0, 0};
  };
  EXPECT_EQ(intSlot(t, slotOf(&Material::bumpTexture).first, slotOf(&Material::bumpTexture).second), -1);
  EXPECT_EQ(intSlot(t, slotOf(&Material::blendRatioTexture).first, slotOf(&Material::blendRatioTexture).second), -1);
}

TEST(MaterialFields, AChoiceSetsItsFlagForItsTypesOnly) {
  auto typeWord = [](const Material& m) { return intSlot(packMaterial(m), 0, 3); };
  for (const MaterialChoice& f : kMaterialChoices) {
    SCOPED_TRACE(f.member);
    Material m;
    m.type = firstTypeOf(f);
    const int off = typeWord(m);
    EXPECT_EQ(off & gpu::kMatTypeBits, static_cast<int>(m.type));
    m.*f.field = true;
    const int on = typeWord(m);
    EXPECT_EQ(on & gpu::kMatTypeBits, static_cast<int>(m.type));
    EXPECT_EQ(on & ~off, f.flag);
    EXPECT_EQ(f.flag & gpu::kMatTypeBits, 0) << "a flag is not a type";
    m.type = firstTypeNotOf(f);
    if (!f.appliesTo(m.type)) {
      EXPECT_EQ(typeWord(m) & ~gpu::kMatTypeBits, 0);
    }
  }
}

TEST(MaterialFields, AnUnknownChoiceInAFileIsAProblemNamingTheKey) {
  for (const MaterialChoice& f : kMaterialChoices) {
    Scene s = makeDefaultScene();
    std::string text = nativeSceneToString(s);
    const std::size_t pos = text.find("\"name\"", text.find("\"materials\""));
    ASSERT_NE(pos, std::string::npos);
    text.insert(pos, "\"" + std::string(f.key) + "\": \"sideways\", ");
    auto back = nativeSceneFromString(text, "choice.json", ".");
    const bool named = back.ok() ? mentions(back.value().warnings, f.key) : back.error().find(f.key) != std::string::npos;
    EXPECT_TRUE(named) << f.key;
  }
}

}  // namespace
}  // namespace retile
