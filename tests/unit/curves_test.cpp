// Strands: Tungsten's curves, their files, and the tubes they are drawn as.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "io/curve_reader.h"
#include "retile/io.h"
#include "retile/log.h"
#include "scene/curves.h"
#include "test_support.h"

namespace retile {
namespace {

using Strand = std::vector<Vec3>;

CurveSet strands(const std::vector<Strand>& list, float radius) {
  CurveSet c;
  for (const Strand& s : list) {
    for (const Vec3& p : s) {
      c.positions.push_back(p);
      c.radii.push_back(radius);
    }
    c.ends.push_back(static_cast<std::uint32_t>(c.positions.size()));
  }
  return c;
}

template <typename T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

// Yuksel's .hair: the header, then segments, points and (optionally) thickness.
std::string hairFile(const std::vector<Strand>& list, const std::vector<float>* thickness, float defaultThickness = 0.5f) {
  std::string out = "HAIR";
  std::uint32_t points = 0;
  for (const Strand& s : list) points += static_cast<std::uint32_t>(s.size());
  put(out, static_cast<std::uint32_t>(list.size()));
  put(out, points);
  put(out, static_cast<std::uint32_t>(1u | 2u | (thickness ? 4u : 0u)));
  put(out, std::uint32_t(0));
  put(out, defaultThickness);
  put(out, 0.0f);
  for (int i = 0; i < 3; ++i) put(out, 1.0f);
  out.append(88, '\0');
  for (const Strand& s : list) put(out, static_cast<std::uint16_t>(s.size() - 1));
  for (const Strand& s : list)
    for (const Vec3& p : s) put(out, p);
  if (thickness)
    for (float t : *thickness) put(out, t);
  return out;
}

// Tungsten's .fiber: the 40-byte header, then num_vertices, position and width attributes.
std::string fiberFile(const std::vector<Strand>& list, float width) {
  std::string out;
  const unsigned char magic[8] = {0x80, 0xBF, 0x80, 0x46, 0x49, 0x42, 0x45, 0x52};
  out.append(reinterpret_cast<const char*>(magic), 8);
  std::uint64_t vertices = 0;
  for (const Strand& s : list) vertices += s.size();
  put(out, std::uint16_t(1));
  put(out, std::uint16_t(0));
  put(out, std::uint32_t(0));
  put(out, std::uint64_t(40));
  put(out, vertices);
  put(out, static_cast<std::uint64_t>(list.size()));
  auto attribute = [&](const std::string& name, std::uint64_t bytes, bool perCurve, std::uint8_t type, std::uint8_t count) {
    put(out, static_cast<std::uint64_t>(20 + name.size() + 1));
    put(out, bytes);
    put(out, static_cast<std::uint16_t>(perCurve ? 1 : 0));
    put(out, type);
    put(out, count);
    out.append(name);
    out.push_back('\0');
  };
  attribute("num_vertices", 2 * list.size(), true, 3, 1);
  for (const Strand& s : list) put(out, static_cast<std::uint16_t>(s.size()));
  attribute("position", 12 * vertices, false, 8, 3);
  for (const Strand& s : list)
    for (const Vec3& p : s) put(out, p);
  attribute("width", 4, false, 8, 1);  // one value: Tungsten repeats the last for the rest
  put(out, width);
  put(out, std::uint64_t(0));
  return out;
}

std::filesystem::path write(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

TEST(Curves, ATubeFollowsItsSplineOutwardAndClosed) {
  // One straight strand along +x and one bent one: the tube runs from the midpoint of the first
  // two nodes to that of the last two, every triangle faces away from the axis (the caps along
  // it), and each side is as far out as the widened radius.
  const float r = 0.1f;
  CurveSet c = strands({{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}}, {{0, 2, 0}, {1, 2, 0}, {1, 3, 0}, {2, 4, 1}, {2, 5, 3}}}, r);
  CurveTubeOptions options;
  options.sides = 5;
  options.subdivisions = 3;
  CurveTubes t = makeCurveTubes(c, options);
  EXPECT_EQ(t.strandsKept, 2u);
  EXPECT_EQ(t.subdivisions, 3);
  const MeshGeometry& g = t.geometry;
  // Sections: 2 pieces x 3 and 3 pieces x 3; two triangles per side each, three per cap.
  EXPECT_EQ(g.triangleCount(), (6u + 9u) * 10u + 4u * 3u);
  Bounds3 b = g.bounds();
  const float widened = r * kPi / (5 * std::sin(kPi / 5));
  EXPECT_NEAR(b.lo.x, 0.5f, 1e-5f);
  // The last cap, the last five vertices: centred between the bent strand's last two nodes.
  Vec3 centre{0.0f};
  for (std::size_t v = g.positions.size() - 5; v < g.positions.size(); ++v) centre += g.positions[v] * 0.2f;
  EXPECT_NEAR(centre.x, 2.0f, 1e-5f);
  EXPECT_NEAR(centre.y, 4.5f, 1e-5f);
  EXPECT_NEAR(centre.z, 2.0f, 1e-5f);
  for (std::size_t i = 0; i < g.indices.size(); i += 3) {
    const std::uint32_t a = g.indices[i], bb = g.indices[i + 1], cc = g.indices[i + 2];
    const Vec3 n = cross(g.positions[bb] - g.positions[a], g.positions[cc] - g.positions[a]);
    const Vec3 smooth = g.normals[a] + g.normals[bb] + g.normals[cc];
    EXPECT_GT(dot(n, smooth), 0) << "triangle " << i / 3 << " faces inward";
  }
  // The straight strand's side vertices all lie at the widened radius from the x axis.
  for (std::size_t v = 0; v < 4 * 5; ++v) {
    const Vec3 p = g.positions[v];
    EXPECT_NEAR(std::sqrt(p.y * p.y + p.z * p.z), widened, 1e-5f);
  }
  // u runs along the strand on every face, across the seam too, where v jumps back (Material::Hair
  // takes the fibre's direction from it): dp/du of the straight strand's 60 side triangles points
  // along +x.
  for (std::size_t tri = 0; tri < 60; ++tri) {
    const std::uint32_t* k = &g.indices[tri * 3];
    const Vec3 e1 = g.positions[k[1]] - g.positions[k[0]], e2 = g.positions[k[2]] - g.positions[k[0]];
    const Vec2 a = g.uvs[k[0]], b1 = g.uvs[k[1]], b2 = g.uvs[k[2]];
    const float du1 = b1.x - a.x, dv1 = b1.y - a.y, du2 = b2.x - a.x, dv2 = b2.y - a.y;
    const float det = du1 * dv2 - du2 * dv1;
    ASSERT_NE(det, 0.0f) << "triangle " << tri;
    const Vec3 dpdu = (e1 * dv2 - e2 * dv1) / det;
    EXPECT_GT(dpdu.x, 0.99f * length(dpdu)) << "triangle " << tri;
  }
  // A strand of two nodes is no spline piece: nothing.
  EXPECT_EQ(makeCurveTubes(strands({{{0, 0, 0}, {1, 0, 0}}}, r)).strandsKept, 0u);
}

TEST(Curves, OverTheBudgetTheSubdivisionsGoThenStrands) {
  std::vector<Strand> list(10, Strand{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}});
  for (std::size_t i = 0; i < list.size(); ++i)
    for (Vec3& p : list[i]) p.z = static_cast<float>(i);
  CurveSet c = strands(list, 0.1f);
  CurveTubeOptions options;  // four sides, two subdivisions: 3 x 2 x 8 + 4 = 52 triangles a strand
  EXPECT_EQ(makeCurveTubes(c, options).geometry.triangleCount(), 520u);
  options.maxTriangles = 400;  // one subdivision: 28 a strand, 280
  CurveTubes one = makeCurveTubes(c, options);
  EXPECT_EQ(one.subdivisions, 1);
  EXPECT_EQ(one.strandsKept, 10u);
  options.maxTriangles = 250;  // three sides: 3 x 6 + 2 = 20 a strand, 200
  CurveTubes three = makeCurveTubes(c, options);
  EXPECT_EQ(three.sides, 3);
  EXPECT_EQ(three.strandsKept, 10u);
  EXPECT_EQ(three.geometry.triangleCount(), 200u);
  options.maxTriangles = 100;  // every other strand: 5 of 10
  CurveTubes few = makeCurveTubes(c, options);
  EXPECT_EQ(few.strandsKept, 5u);
  EXPECT_EQ(few.strandsUsable, 10u);
  EXPECT_EQ(few.geometry.triangleCount(), 100u);
}

TEST(Curves, ThicknessAndTaperAsTungstenHasThem) {
  CurveSet c = strands({{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}}, 0.3f);
  applyCurveThickness(c, nullptr, false);
  EXPECT_EQ(c.radii, (std::vector<float>{0.3f, 0.3f, 0.3f}));
  const float thickness = 0.2f;
  applyCurveThickness(c, &thickness, true);
  // 1 - (k - 0.5) / (n - 1) for k = 0, 1, 2 of 3 nodes: 1.25, 0.75, 0.25.
  EXPECT_FLOAT_EQ(c.radii[0], 0.25f);
  EXPECT_FLOAT_EQ(c.radii[1], 0.15f);
  EXPECT_FLOAT_EQ(c.radii[2], 0.05f);
}

TEST(Curves, HairAndFiberFilesAreRead) {
  auto dir = test::tempDir();
  const std::vector<Strand> list{{{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, {{1, 0, 0}, {1, 1, 0}, {1, 2, 0}, {1, 3, 0}}};
  const std::vector<float> thickness{0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f};
  std::vector<std::string> warnings;
  auto hair = readCurves(write(dir / "a.hair", hairFile(list, &thickness)), &warnings);
  ASSERT_TRUE(hair.ok()) << hair.error();
  EXPECT_EQ(hair->ends, (std::vector<std::uint32_t>{3, 7}));
  EXPECT_EQ(hair->positions[5], Vec3(1, 2, 0));
  EXPECT_EQ(hair->radii, thickness);
  auto plain = readCurves(write(dir / "b.hair", hairFile(list, nullptr, 0.25f)), &warnings);
  ASSERT_TRUE(plain.ok()) << plain.error();
  EXPECT_EQ(plain->radii, std::vector<float>(7, 0.25f)) << "the header's default thickness";
  auto fiber = readCurves(write(dir / "c.fiber", fiberFile(list, 0.05f)), &warnings);
  ASSERT_TRUE(fiber.ok()) << fiber.error();
  EXPECT_EQ(fiber->ends, (std::vector<std::uint32_t>{3, 7}));
  EXPECT_EQ(fiber->positions[6], Vec3(1, 3, 0));
  EXPECT_EQ(fiber->radii, std::vector<float>(7, 0.05f)) << "one width, repeated as in Tungsten";
  EXPECT_TRUE(warnings.empty());

  // A strand with a NaN is dropped, a negative radius is 0, each said.
  std::vector<Strand> bad = list;
  bad[0][1].y = std::nanf("");
  std::vector<float> negative = thickness;
  negative[6] = -1;
  auto cleaned = readCurves(write(dir / "d.hair", hairFile(bad, &negative)), &warnings);
  ASSERT_TRUE(cleaned.ok()) << cleaned.error();
  EXPECT_EQ(cleaned->ends, (std::vector<std::uint32_t>{4}));
  EXPECT_EQ(cleaned->radii.back(), 0.0f);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("d.hair: dropped 1 strands"), std::string::npos) << warnings[0];
}

TEST(Curves, BrokenFilesFailWithTheFileAndTheProblem) {
  auto dir = test::tempDir();
  const std::vector<Strand> list{{{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}};
  const std::string good = hairFile(list, nullptr);
  std::string lying = good;
  const std::uint32_t points = 1000000;
  std::memcpy(lying.data() + 8, &points, 4);  // more points than the file holds
  std::string overrun = good;
  const std::uint16_t segments = 40;
  std::memcpy(overrun.data() + 128, &segments, 2);  // a strand longer than the points
  std::string fiber = fiberFile(list, 0.1f);
  const std::uint64_t vertices = std::uint64_t(1) << 40;
  std::memcpy(fiber.data() + 24, &vertices, 8);
  struct Case {
    std::string name, bytes, expect;
  } cases[] = {
      {"short.hair", good.substr(0, 100), "truncated header"},
      {"lying.hair", lying, "truncated"},
      {"overrun.hair", overrun, "need more than the 3 points"},
      {"wrong.hair", "HAIX" + good.substr(4), "no HAIR signature"},
      {"huge.fiber", fiber, "cannot fit"},
      {"cut.fiber", fiberFile(list, 0.1f).substr(0, 70), "runs past the end"},
      {"strands.txt", good, "unsupported curve format"},
  };
  for (const Case& c : cases) {
    auto r = readCurves(write(dir / c.name, c.bytes), nullptr);
    ASSERT_FALSE(r.ok()) << c.name;
    EXPECT_NE(r.error().find(c.name), std::string::npos) << r.error();
    EXPECT_NE(r.error().find(c.expect), std::string::npos) << r.error();
  }
}

TEST(Curves, TungstenCurvesImportAsTubesOfHair) {
  auto dir = test::tempDir();
  std::vector<Strand> list;
  for (int i = 0; i < 400; ++i) list.push_back({{float(i), 0, 0}, {float(i), 1, 0}, {float(i), 2, 0}, {float(i), 3, 0}});
  write(dir / "hair.hair", hairFile(list, nullptr, 0.02f));
  std::ofstream(dir / "scene.json")
      << R"({"bsdfs": [{"name": "brown", "type": "hair", "melanin_ratio": 0.25, "melanin_concentration": 2, "roughness": 0.2, "scale_angle": 3.5}],
      "primitives": [{"type": "curves", "name": "fur", "file": "hair.hair", "bsdf": "brown", "transform": {"scale": 2}},
                     {"type": "curves", "name": "half", "file": "hair.hair", "bsdf": "brown", "subsample": 0.5, "curve_thickness": 0.01},
                     {"type": "curves", "name": "plain", "file": "hair.hair"},
                     {"type": "curves", "name": "gone", "file": "missing.hair"}]})";
  auto r = importTungsten(dir / "scene.json");
  ASSERT_TRUE(r.ok()) << r.error();
  const Scene& s = r->scene;
  auto object = [&](const std::string& name) -> const Object* {
    for (const Object& o : s.objects)
      if (o.name == name) return &o;
    return nullptr;
  };
  const Object* fur = object("fur");
  const Object* half = object("half");
  const Object* plain = object("plain");
  ASSERT_TRUE(fur && half && plain);
  EXPECT_FALSE(object("gone"));
  std::string all;
  for (const std::string& w : r->warnings) all += w + "\n";
  EXPECT_NE(all.find("curve file 'missing.hair' not found"), std::string::npos) << all;

  // Four sides, two subdivisions: 2 x 2 x 8 + 4 = 36 triangles a strand.
  EXPECT_EQ(s.mesh(fur->mesh)->geometry->triangleCount(), 400u * 36u);
  const std::size_t kept = s.mesh(half->mesh)->geometry->triangleCount() / 36u;
  EXPECT_GT(kept, 150u) << "about half the strands";
  EXPECT_LT(kept, 250u);

  // Tungsten's hair: its roughness and tilt, the melanin's absorption per unit of radius (the
  // same for every curves that names it: one material); the tubes cull their back faces, so
  // that what a fibre scatters leaves it.
  const Material* m = s.material(fur->material);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->type, MaterialType::Hair);
  EXPECT_FLOAT_EQ(m->roughness, 0.2f);
  EXPECT_FLOAT_EQ(m->hairTilt, 3.5f);
  const Vec3 sigma = (Vec3{0.419f, 0.697f, 1.37f} * 0.75f + Vec3{0.187f, 0.4f, 1.05f} * 0.25f) * 2.0f;
  EXPECT_NEAR(m->coatingAbsorption.x, sigma.x, 1e-5f);
  EXPECT_NEAR(m->coatingAbsorption.z, sigma.z, 1e-5f);
  EXPECT_EQ(half->material, fur->material);
  EXPECT_TRUE(fur->cullBackFaces && half->cullBackFaces && plain->cullBackFaces);
  // Without a bsdf, Tungsten's default hair: ratio 0.5, concentration 0.25, tilt 2.
  const Material* d = s.material(plain->material);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->type, MaterialType::Hair);
  EXPECT_FLOAT_EQ(d->hairTilt, 2.0f);
  EXPECT_NEAR(d->coatingAbsorption.x, 0.25f * (0.419f + 0.187f) / 2, 1e-5f);

  // The native format keeps hair.
  auto saved = test::tempDir() / "hair.retile";
  ASSERT_TRUE(saveNativeScene(s, saved).ok());
  auto back = loadNativeScene(saved);
  ASSERT_TRUE(back.ok()) << back.error();
  const Material* again = back->scene.material(fur->material);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->type, MaterialType::Hair);
  EXPECT_FLOAT_EQ(again->hairTilt, 3.5f);
  EXPECT_EQ(again->coatingAbsorption, m->coatingAbsorption);
}

}  // namespace
}  // namespace retile
