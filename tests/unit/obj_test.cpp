#include <gtest/gtest.h>

#include <fstream>

#include "retile/io.h"
#include "test_support.h"

namespace retile {
namespace {

std::filesystem::path writeText(const std::string& name, const std::string& text) {
  auto p = test::tempDir() / name;
  std::ofstream(p) << text;
  return p;
}

TEST(Obj, ReadsPolygonsNegativeIndicesAndAttributes) {
  auto p = writeText("quad.obj",
                     "# a quad as one polygon, indexed backwards\n"
                     "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                     "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                     "vn 0 0 1\n"
                     "f -4/-4/-1 -3/-3/-1 -2/-2/-1 -1/-1/-1\n");
  std::vector<std::string> w;
  auto g = readObjGeometry(p, &w);
  ASSERT_TRUE(g.ok()) << g.error();
  EXPECT_EQ(g->triangleCount(), 2u);
  EXPECT_EQ(g->positions.size(), 4u);
  ASSERT_EQ(g->uvs.size(), 4u);
  EXPECT_EQ(g->normals[0], Vec3(0, 0, 1));
  EXPECT_TRUE(w.empty());
}

TEST(Obj, DropsNanVerticesWithAWarning) {
  auto p = writeText("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nv 1 1 inf\nf 1 2 3\nf 2 4 5\n");
  std::vector<std::string> w;
  auto g = readObjGeometry(p, &w);
  ASSERT_TRUE(g.ok()) << g.error();
  EXPECT_EQ(g->triangleCount(), 1u);
  for (const Vec3& v : g->positions) EXPECT_TRUE(isFinite(v));
  ASSERT_FALSE(w.empty());
  EXPECT_NE(w[0].find("NaN"), std::string::npos) << w[0];
}

// Found by fuzz_obj: a face skipped for an out-of-range index had already added its other
// vertices, an infinite one among them, which no triangle used and nothing removed, so the mesh's
// bounds (camera framing, the BVH's root) were infinite.
TEST(Obj, VerticesOfSkippedFacesDoNotReachTheBounds) {
  auto p = writeText("skipped.obj", "v inf -inf 8\nv 0 1 0\nv 1 0 0\nv 0 0 1\nf 1 2 99\nf 2 3 4\n");
  std::vector<std::string> w;
  auto g = readObjGeometry(p, &w);
  ASSERT_TRUE(g.ok()) << g.error();
  EXPECT_EQ(g->triangleCount(), 1u);
  EXPECT_EQ(g->positions.size(), 3u);
  Bounds3 b = g->bounds();
  EXPECT_TRUE(isFinite(b.lo) && isFinite(b.hi));
}

TEST(Obj, BadInputsFailWithTheFileName) {
  for (const char* text : {"v 1 2\nf 1 2 3\n", "v 0 0 0\nf 1 x 3\n", "", "f 1 2 3\n"}) {
    auto p = writeText("bad.obj", text);
    auto g = readObjGeometry(p, nullptr);
    ASSERT_FALSE(g.ok()) << text;
    EXPECT_NE(g.error().find("bad.obj"), std::string::npos) << g.error();
  }
}

}  // namespace
}  // namespace retile
