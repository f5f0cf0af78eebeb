// The packed BVH agrees with brute-force intersection: the GPU traverses the same layout.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <utility>

#include "render/bvh.h"
#include "retile/io.h"
#include "test_support.h"

namespace retile {
namespace {

struct Soup {
  std::vector<Vec3> verts;  // 3 per triangle, input order
};

RayHit bruteForce(const Soup& s, Vec3 o, Vec3 d) {
  RayHit best;
  best.t = 1e30f;
  for (std::size_t i = 0; i < s.verts.size() / 3; ++i) {
    float t, u, v;
    if (intersectTriangle(o, d, s.verts[i * 3], s.verts[i * 3 + 1], s.verts[i * 3 + 2], best.t, &t, &u, &v)) {
      best.t = t;
      best.prim = static_cast<std::int32_t>(i);
    }
  }
  return best;
}

void checkAgainstBruteForce(const Soup& soup, int rays, std::uint32_t seed) {
  std::size_t n = soup.verts.size() / 3;
  std::vector<Bounds3> boxes(n);
  Bounds3 all;
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      boxes[i].grow(soup.verts[i * 3 + static_cast<std::size_t>(k)]);
      all.grow(soup.verts[i * 3 + static_cast<std::size_t>(k)]);
    }
  Bvh bvh = buildBvh(boxes);
  ASSERT_EQ(bvh.primOrder.size(), n);
  std::vector<Vec3> packed(n * 3);
  for (std::size_t p = 0; p < n; ++p)
    for (int k = 0; k < 3; ++k) packed[p * 3 + static_cast<std::size_t>(k)] = soup.verts[bvh.primOrder[p] * 3 + static_cast<std::size_t>(k)];

  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  Vec3 c = all.center();
  float r = length(all.extent());
  int hits = 0;
  for (int i = 0; i < rays; ++i) {
    // Origins on a sphere around the mesh, aimed at random points inside its box.
    Vec3 o = c + normalize(Vec3{u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f}) * r;
    Vec3 target = all.lo + all.extent() * Vec3{u(rng), u(rng), u(rng)};
    Vec3 d = normalize(target - o);
    RayHit ref = bruteForce(soup, o, d);
    RayHit got = traverseClosest(bvh, packed, o, d, 1e30f);
    if (ref.prim < 0) {
      EXPECT_LT(got.prim, 0) << "ray " << i << " found a hit brute force missed";
      continue;
    }
    ++hits;
    ASSERT_GE(got.prim, 0) << "ray " << i << " missed; brute force hit at t=" << ref.t;
    EXPECT_NEAR(got.t, ref.t, 1e-5f * std::max(1.0f, ref.t)) << "ray " << i;
    // Ties between coplanar triangles may pick either; the distance must agree.
  }
  EXPECT_GT(hits, rays / 10) << "the test rays should mostly hit";
}

TEST(Bvh, RandomTrianglesAgreeWithBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1, 1);
  Soup s;
  for (int i = 0; i < 2000; ++i) {
    Vec3 c{u(rng) * 4, u(rng) * 4, u(rng) * 4};
    for (int k = 0; k < 3; ++k) s.verts.push_back(c + Vec3{u(rng), u(rng), u(rng)} * 0.3f);
  }
  checkAgainstBruteForce(s, 3000, 11);
}

TEST(Bvh, DegenerateInputs) {
  // All triangles at one point, and a single triangle: the builder must terminate and agree.
  Soup same;
  for (int i = 0; i < 100; ++i) same.verts.insert(same.verts.end(), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  checkAgainstBruteForce(same, 200, 1);
  Soup one;
  one.verts = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  checkAgainstBruteForce(one, 200, 2);
  Bvh empty = buildBvh({});
  ASSERT_EQ(empty.nodes.size(), 1u);
  EXPECT_LT(empty.nodes[0].leftCount, 0);
  EXPECT_LT(empty.nodes[0].rightCount, 0);
}

TEST(Bvh, AdversarialDepthIsBounded) {
  // Exponentially spaced triangles push SAH towards one-primitive peels.
  std::vector<Bounds3> boxes;
  for (int i = 0; i < 5000; ++i) {
    float x = std::pow(1.01f, static_cast<float>(i));
    Bounds3 b;
    b.grow({x, 0, 0});
    b.grow({x * 1.001f, 1, 1});
    boxes.push_back(b);
  }
  Bvh bvh = buildBvh(boxes);
  EXPECT_LE(bvh.depth, 40 + 14) << "the GPU traversal stack holds 48 entries over two levels";
}

// Scene data must never crash the process (a hostile file reached the builder with coordinates
// near the float limit and NaN): any float input builds, every primitive lands in exactly one
// leaf, and the depth stays bounded.
TEST(Bvh, AnyFloatInputBuilds) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const float big = std::numeric_limits<float>::max(), tiny = std::numeric_limits<float>::denorm_min();
  const float values[] = {0.0f, 1.0f, -1.0f, 1e38f, -1e38f, big, -big, inf, -inf, nan, tiny, -tiny, 6.7e23f};
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(std::size(values)) - 1);
  for (int round = 0; round < 20; ++round) {
    std::vector<Bounds3> boxes;
    const int n = round == 0 ? 1 : 50 * round;
    for (int i = 0; i < n; ++i) {
      Bounds3 b;
      b.lo = Vec3{values[pick(rng)], values[pick(rng)], values[pick(rng)]};
      b.hi = Vec3{values[pick(rng)], values[pick(rng)], values[pick(rng)]};
      boxes.push_back(b);
    }
    Bvh bvh = buildBvh(boxes);
    std::vector<int> seen(boxes.size(), 0);
    for (std::uint32_t p : bvh.primOrder) {
      ASSERT_LT(p, boxes.size());
      ++seen[p];
    }
    for (int count : seen) EXPECT_EQ(count, 1);
    std::vector<int> leafHits(boxes.size(), 0);
    for (const GpuBvhNode& node : bvh.nodes)
      for (auto [index, count] : {std::pair{node.left, node.leftCount}, std::pair{node.right, node.rightCount}})
        for (std::int32_t k = 0; k < count; ++k) ++leafHits[static_cast<std::size_t>(index + k)];
    for (int count : leafHits) EXPECT_EQ(count, 1) << "each packed primitive in one leaf";
    EXPECT_LE(bvh.depth, 40 + 14);
  }
}

TEST(Bvh, BunnyAgreesWithBruteForce) {
  RETILE_SHARED_OR_SKIP(bunny, "scenes/bunny/bunny.obj");
  std::vector<std::string> warnings;
  auto g = readObjGeometry(bunny, &warnings);
  ASSERT_TRUE(g.ok()) << g.error();
  Soup s;
  for (std::uint32_t i : g->indices) s.verts.push_back(g->positions[i]);
  checkAgainstBruteForce(s, 400, 5);
}

}  // namespace
}  // namespace retile
