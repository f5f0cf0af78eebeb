// The packed BVH agrees with brute-force intersection: the GPU traverses the same layout.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "render/bvh.h"
#include "render/packed_trace.h"
#include "render/render_scene.h"
#include "scene/primitives.h"
#include "retile/image.h"
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

// Builds the soup's BVH and its triangles in packed order, as traverseClosest takes them.
Bvh buildSoup(const Soup& soup, std::vector<Vec3>* packed) {
  std::vector<Bounds3> boxes(soup.verts.size() / 3);
  for (std::size_t i = 0; i < boxes.size(); ++i)
    for (std::size_t k = 0; k < 3; ++k) boxes[i].grow(soup.verts[i * 3 + k]);
  Bvh bvh = buildBvh(boxes);
  packed->clear();
  for (std::uint32_t p : bvh.primOrder)
    for (std::size_t k = 0; k < 3; ++k) packed->push_back(soup.verts[p * 3 + k]);
  return bvh;
}

void checkAgainstBruteForce(const Soup& soup, int rays, std::uint32_t seed) {
  std::size_t n = soup.verts.size() / 3;
  Bounds3 all;
  for (const Vec3& v : soup.verts) all.grow(v);
  std::vector<Vec3> packed;
  Bvh bvh = buildSoup(soup, &packed);
  ASSERT_EQ(bvh.primOrder.size(), n);

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
  for (std::int32_t count : empty.nodes[0].count) EXPECT_LT(count, 0);
}

// The GPU's 48-byte node names its children by where the first inner child and the first leaf's
// record are (layouts.h), so the builder must lay them out one after another in slot order.
TEST(Bvh, ChildrenLieWhereTwoBasesFindThem) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int leafSize : {1, 4}) {
    std::vector<Bounds3> boxes;
    for (int i = 0; i < 3000; ++i) {
      Bounds3 b;
      Vec3 c{u(rng) * 8, u(rng) * 8, u(rng) * 8};
      b.grow(c);
      b.grow(c + Vec3{u(rng), u(rng), u(rng)} * 0.2f);
      boxes.push_back(b);
    }
    BvhBuildOptions options;
    options.maxLeafSize = leafSize;
    const Bvh bvh = buildBvh(boxes, options);
    std::vector<int> seen(boxes.size(), 0);
    for (std::size_t k = 0; k < bvh.nodes.size(); ++k) {
      const BvhNode& n = bvh.nodes[k];
      int inner = 0, used = 0;
      std::int32_t nextLeaf = -1;
      for (std::size_t c = 0; c < kBvhWidth; ++c) {
        if (n.count[c] < 0) continue;
        ASSERT_EQ(used++, static_cast<int>(c)) << "node " << k << ": an empty slot before a used one";
        if (n.count[c] == 0) {
          ASSERT_EQ(inner, static_cast<int>(c)) << "node " << k << ": an inner child after a leaf";
          EXPECT_EQ(n.index[c], n.index[0] + inner) << "node " << k << ": inner children apart";
          EXPECT_GT(n.index[c], static_cast<std::int32_t>(k)) << "a child before its parent";
          ++inner;
          continue;
        }
        if (nextLeaf >= 0) {
          EXPECT_EQ(n.index[c], nextLeaf) << "node " << k << ": leaves apart";
        }
        nextLeaf = n.index[c] + n.count[c];
        EXPECT_LE(n.count[c], leafSize);
        for (std::int32_t i = n.index[c]; i < nextLeaf; ++i) ++seen[bvh.primOrder[static_cast<std::size_t>(i)]];
      }
    }
    for (std::size_t p = 0; p < seen.size(); ++p) ASSERT_EQ(seen[p], 1) << "primitive " << p << " in " << seen[p] << " leaves";
  }
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
    for (const BvhNode& node : bvh.nodes)
      for (std::size_t c = 0; c < kBvhWidth; ++c)
        for (std::int32_t k = 0; k < node.count[c]; ++k) ++leafHits[static_cast<std::size_t>(node.index[c] + k)];
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

// A node's quantised child boxes hold the boxes they stand for, with the grid anywhere in float
// range: tiny and huge, far from the origin, flat, and on both sides of zero. And a box takes
// less than a grid step of room beyond its own, at 8 bits per plane.
TEST(Bvh, QuantisedChildBoxesHoldTheirBoxes) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  const float scales[] = {1e-30f, 1e-6f, 1.0f, 1e3f, 1e20f, 1e37f};
  const float offsets[] = {0.0f, -1.0f, 1e4f, -3e7f, 1e30f};
  for (float scale : scales)
    for (float offset : offsets)
      for (int round = 0; round < 50; ++round) {
        BvhNode n;
        const int children = 1 + round % kBvhWidth;
        for (int c = 0; c < children; ++c) {
          const auto k = static_cast<std::size_t>(c);
          Vec3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
          if (round % 7 == 0) b.y = a.y;  // flat
          n.box[k] = Bounds3{};
          n.box[k].grow(Vec3{offset} + a * scale);
          n.box[k].grow(Vec3{offset} + b * scale);
          n.count[k] = 1;
        }
        const QuantizedNode q = quantize(n);
        Bounds3 all;
        for (int c = 0; c < children; ++c) all.grow(n.box[static_cast<std::size_t>(c)]);
        for (int c = 0; c < children; ++c) {
          const Bounds3& want = n.box[static_cast<std::size_t>(c)];
          const Bounds3 got = dequantize(q, c);
          for (int axis = 0; axis < 3; ++axis) {
            ASSERT_LE(got.lo[axis], want.lo[axis]) << "scale " << scale << " offset " << offset << " axis " << axis;
            ASSERT_GE(got.hi[axis], want.hi[axis]) << "scale " << scale << " offset " << offset << " axis " << axis;
            // Room: a grid step of the node's extent on each side, or float rounding far out.
            const float extent = all.hi[axis] - all.lo[axis];
            const float ulps = 4 * std::abs(std::nextafter(want.hi[axis], 3e38f) - want.hi[axis]);
            const float room = extent / 127.0f + ulps + 1e-37f;
            EXPECT_LE(want.lo[axis] - got.lo[axis], room) << "scale " << scale << " offset " << offset;
            EXPECT_LE(got.hi[axis] - want.hi[axis], room) << "scale " << scale << " offset " << offset;
          }
        }
      }
}

// Rays aimed at the edges of axis-aligned squares on an integer grid (a tiled floor), from near
// and far: they hit triangles on the planes where child boxes meet, where a box test that
// rounds inwards loses hits (the binary BVH's exact boxes did from afar; quantised boxes without
// room around their planes did from near too). Each ray finds the hit brute force finds.
TEST(Bvh, RaysAtBoxFacesStillHit) {
  Soup s;
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 16; ++j) {
      const float x = static_cast<float>(i), z = static_cast<float>(j);
      s.verts.insert(s.verts.end(), {{x, 0, z}, {x + 1, 0, z}, {x + 1, 0, z + 1}, {x, 0, z}, {x + 1, 0, z + 1}, {x, 0, z + 1}});
    }
  std::vector<Vec3> packed;
  const Bvh bvh = buildSoup(s, &packed);
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(0, 1);
  std::uniform_int_distribution<int> line(0, 16);
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    // A point on a grid line (x or z an integer), seen from near or far above.
    Vec3 target{static_cast<float>(line(rng)), 0, u(rng) * 16};
    if (i % 2) std::swap(target.x, target.z);
    const float distance = i % 3 == 0 ? 1e-3f : (i % 3 == 1 ? 1.0f : 1e3f);
    const Vec3 o = target + normalize(Vec3{u(rng) - 0.5f, 0.2f + u(rng), u(rng) - 0.5f}) * distance;
    const Vec3 d = normalize(target - o);
    const RayHit ref = bruteForce(s, o, d);
    const RayHit got = traverseClosest(bvh, packed, o, d, 1e30f);
    if (ref.prim < 0) continue;  // between two triangles' edges, brute force finds neither
    ++hits;
    ASSERT_GE(got.prim, 0) << "ray " << i << " from " << distance << " missed; brute force hit at t=" << ref.t;
    EXPECT_NEAR(got.t, ref.t, 1e-5f * std::max(1.0f, ref.t)) << "ray " << i;
  }
  EXPECT_GT(hits, 15000);
}

// Two unit cubes far apart: the root is visited, then each leaf's one primitive costs one step
// for the share of rays through the root's box that also pass through the leaf's.
TEST(Bvh, ExpectedStepsFollowTheSurfaceAreaHeuristic) {
  Bounds3 a, b;
  a.grow({0, 0, 0});
  a.grow({1, 1, 1});
  b.grow({9, 0, 0});
  b.grow({10, 1, 1});
  const std::vector<Bounds3> boxes{a, b};
  BvhBuildOptions one;
  one.maxLeafSize = 1;
  const Bvh bvh = buildBvh(boxes, one);
  ASSERT_EQ(bvh.nodes.size(), 1u);
  const float root = bvh.bounds.area();  // 10 x 1 x 1: 42
  EXPECT_FLOAT_EQ(expectedSteps(bvh, [](std::uint32_t) { return 1.0f; })[0], 1.0f + 2 * 6.0f / root);
  // A primitive's own cost scales its term.
  const std::vector<float> steps = expectedSteps(bvh, [&](std::uint32_t p) { return bvh.primOrder[p] == 0 ? 5.0f : 1.0f; });
  EXPECT_FLOAT_EQ(steps[0], 1.0f + (6.0f * 5.0f + 6.0f) / root);
}

// The collapse chooses each node's children and leaves for the least expected steps: allowed
// larger leaves, it can only do as well or better, as the binary tree it collapses is the same.
TEST(Bvh, LargerLeavesNeverCostMoreExpectedSteps) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<Bounds3> boxes(3000);
  for (Bounds3& b : boxes) {
    // Clusters of small boxes and some long ones, so that leaves and cuts have choices to make.
    const Vec3 c{std::floor(unit(rng) * 6) + unit(rng) * 0.3f, unit(rng), unit(rng) * 4};
    const float size = unit(rng) < 0.1f ? 1.0f : 0.02f;
    b.grow(c);
    b.grow(c + Vec3{unit(rng), unit(rng), unit(rng)} * size);
  }
  float previous = std::numeric_limits<float>::infinity();
  for (int leafSize = 1; leafSize <= kMaxLeafSize; ++leafSize) {
    BvhBuildOptions options;
    options.maxLeafSize = leafSize;
    const Bvh bvh = buildBvh(boxes, options);
    const float steps = expectedSteps(bvh, [](std::uint32_t) { return 1.0f; })[0];
    EXPECT_LE(steps, previous * 1.00001f) << "leaves of up to " << leafSize;
    previous = steps;
  }
}

// Small triangles along the diagonal from -corner to corner: a thin rod whose box is mostly empty.
std::shared_ptr<const MeshGeometry> diagonalRod(Vec3 corner, std::uint32_t triangles, std::uint32_t seed) {
  auto soup = std::make_shared<MeshGeometry>();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (std::uint32_t i = 0; i < triangles; ++i) {
    const Vec3 c = corner * unit(rng);
    for (int v = 0; v < 3; ++v) soup->positions.push_back(c + Vec3{unit(rng), unit(rng), unit(rng)} * 0.05f);
    for (std::uint32_t v = 0; v < 3; ++v) soup->indices.push_back(i * 3 + v);
  }
  return soup;
}

// Instances that overlap are entered at subtrees of their BVHs, so that the instance BVH can
// separate what their boxes share; instances apart keep one reference each. The choice is made
// anew when the instance BVH stops being direct, and then kept while objects move.
TEST(RenderScene, OverlappingInstancesAreEnteredAtSubtrees) {
  Scene s = test::emptyScene(8, 8);
  const NodeId mat = test::addMaterial(s, Material{});
  // Two rods crossing the same cube along different diagonals: each box holds the other rod.
  test::addMeshObject(s, "a", diagonalRod({1, 1, 1}, 2000, 1), mat, Mat4::identity());
  const NodeId b = test::addMeshObject(s, "b", diagonalRod({1, -1, 1}, 2000, 2), mat, Mat4::identity());
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  EXPECT_TRUE(builder.data().directReferences);
  EXPECT_EQ(builder.data().instanceObject.size(), 2u);
  EXPECT_GT(builder.data().instanceReferences, 2u);
  // The first move gives b a transform: no longer direct, and the count is chosen anew, as for
  // records from the start.
  Object* moved = s.object(b);
  ASSERT_NE(moved, nullptr);
  moved->transform = Mat4::translate({0.1f, 0, 0}) * moved->transform;
  EXPECT_NE(builder.update(s, kUpdateInstances, nullptr) & kDirtyInstances, 0u);
  EXPECT_FALSE(builder.data().directReferences);
  const std::size_t references = builder.data().instanceReferences;
  RenderSceneBuilder records;
  records.setDirectReferences(false);
  records.update(s, kUpdateAll, nullptr);
  EXPECT_EQ(references, records.data().instanceReferences);
  EXPECT_GT(references, 2u);
  // Later moves repack the instance BVH with the same choice.
  moved->transform = Mat4::translate({0.1f, 0, 0}) * moved->transform;
  EXPECT_NE(builder.update(s, kUpdateInstances, nullptr) & kDirtyInstances, 0u);
  EXPECT_EQ(builder.data().instanceReferences, references);
}

// Where each mesh's triangles are packed follows the scene, not where the meshes happen to live
// in memory: a triangle's index seeds its cut-out's coin, so an order by address changed the
// image from one build to the next.
TEST(RenderScene, ThePackedBuffersDoNotDependOnWhereTheMeshesLiveInMemory) {
  // The scene's meshes in one array, in the scene's order or the reverse: their addresses are in
  // one order or the other.
  auto packed = [](bool backwards) {
    constexpr std::size_t kRods = 6;
    auto store = std::make_shared<std::vector<MeshGeometry>>(kRods);
    auto at = [&](std::size_t i) { return backwards ? kRods - 1 - i : i; };
    for (std::size_t i = 0; i < kRods; ++i)
      (*store)[at(i)] = *diagonalRod({1, 1, 1}, 50 + static_cast<std::uint32_t>(i) * 7, static_cast<std::uint32_t>(i));
    Scene s = test::emptyScene(8, 8);
    const NodeId mat = test::addMaterial(s, Material{});
    for (std::size_t i = 0; i < kRods; ++i)
      test::addMeshObject(s, "rod", std::shared_ptr<const MeshGeometry>(store, &(*store)[at(i)]), mat,
                          Mat4::translate({static_cast<float>(i), 0, 0}));
    RenderSceneBuilder builder;
    builder.update(s, kUpdateAll, nullptr);
    return builder.data().meshTraversal;
  };
  const auto forwards = packed(false), backwards = packed(true);
  ASSERT_EQ(forwards.size(), backwards.size());
  EXPECT_EQ(std::memcmp(forwards.data(), backwards.data(), forwards.size() * sizeof(forwards[0])), 0);
}

// The kernel's traversal mirrored on the CPU (tracePacked) finds what brute force finds, over an
// instance BVH packed direct and one entered through records, with instances opened at subtrees
// (crossing rods), a shared mesh and, after a move, instance transforms (one mirroring); two
// objects (a rod and a ball) are hit from the front only. Direct costs fewer steps on the same rays: no step
// enters an instance.
TEST(RenderScene, PackedTraversalFindsWhatBruteForceFinds) {
  Scene s = test::emptyScene(8, 8);
  const NodeId mat = test::addMaterial(s, Material{});
  test::addMeshObject(s, "a", diagonalRod({1, 1, 1}, 1500, 1), mat, Mat4::identity());
  const NodeId b = test::addMeshObject(s, "b", diagonalRod({1, -1, 1}, 1500, 2), mat, Mat4::identity());
  // Small soups all over the middle: opened, their references are runs of triangles.
  for (std::uint32_t i = 0; i < 40; ++i)
    test::addMeshObject(s, "crumbs", diagonalRod({0.6f, 0.6f, -0.6f}, 12, 10 + i), mat, Mat4::identity());
  const auto sphere = makeSphere(12, 24);
  test::addMeshObject(s, "ball", sphere, mat, Mat4::translate({0.3f, 0.2f, -0.4f}) * Mat4::scale(Vec3{0.5f}));
  test::addMeshObject(s, "ball 2", sphere, mat, Mat4::translate({-0.6f, -0.3f, 0.5f}) * Mat4::scale(Vec3{0.4f}));
  s.object(b)->cullBackFaces = true;
  s.objects.back().cullBackFaces = true;
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  struct Ray {
    Vec3 o, d;
  };
  std::vector<Ray> rays;
  for (int i = 0; i < 1500; ++i) {
    // From anywhere around, mostly towards the middle, where the objects are.
    const Vec3 o = Vec3{unit(rng), unit(rng), unit(rng)} * 1.5f, towards = Vec3{unit(rng), unit(rng), unit(rng)} * 0.7f;
    if (length(towards - o) < 0.1f) continue;
    rays.push_back({o, normalize(towards - o)});
  }
  auto check = [&](const RenderSceneBuilder& builder, const char* what) {
    const RenderSceneData& d = builder.data();
    std::uint64_t steps = 0;
    int hits = 0, wrong = 0;
    for (const Ray& r : rays) {
      // Brute force over every object's triangles, in world space.
      float best = 1e30f;
      NodeId bestObject = kNoNode;
      for (const Object& o : s.objects) {
        if (!o.visible) continue;
        const MeshGeometry& g = *s.mesh(o.mesh)->geometry;
        for (std::size_t t = 0; t < g.triangleCount(); ++t) {
          const Vec3 v0 = o.transform.transformPoint(g.positions[g.indices[3 * t]]);
          const Vec3 v1 = o.transform.transformPoint(g.positions[g.indices[3 * t + 1]]);
          const Vec3 v2 = o.transform.transformPoint(g.positions[g.indices[3 * t + 2]]);
          float tt, u, v;
          const Vec3 front =
              o.transform.inverse().transposed().transformVector(cross(g.positions[g.indices[3 * t + 1]] - g.positions[g.indices[3 * t]],
                                                                       g.positions[g.indices[3 * t + 2]] - g.positions[g.indices[3 * t]]));
          if (o.cullBackFaces && dot(front, r.d) > 0) continue;
          if (intersectTriangle(r.o, r.d, v0, v1, v2, best, &tt, &u, &v) && tt > 0) {
            best = tt;
            bestObject = o.id;
          }
        }
      }
      const PackedTrace p = tracePacked(d.meshTraversal, d.topTraversal, d.tlasRoot, d.directReferences, r.o, r.d, 1e30f);
      steps += p.steps;
      const NodeId found = p.prim < 0 ? kNoNode : d.instanceObject.at(static_cast<std::size_t>(p.instance));
      if (bestObject != kNoNode) ++hits;
      if (found != bestObject || (found != kNoNode && std::abs(p.t - best) > 1e-4f * (1 + best))) ++wrong;
    }
    EXPECT_GT(hits, static_cast<int>(rays.size()) / 4) << what;
    EXPECT_LE(wrong, static_cast<int>(rays.size()) / 500) << what << ": " << wrong << " rays find another hit than brute force";
    return steps;
  };
  RenderSceneBuilder direct, records;
  records.setDirectReferences(false);
  direct.update(s, kUpdateAll, nullptr);
  records.update(s, kUpdateAll, nullptr);
  ASSERT_TRUE(direct.data().directReferences);
  ASSERT_FALSE(records.data().directReferences);
  EXPECT_GT(direct.data().instanceReferences, direct.data().instanceObject.size()) << "the rods are entered at subtrees";
  const std::uint64_t directSteps = check(direct, "direct");
  const std::uint64_t recordSteps = check(records, "records");
  EXPECT_LT(directSteps, recordSteps);
  // Hiding and showing an object keeps every instance's number: the triangles that carry it
  // are not uploaded again.
  s.objects[0].visible = false;
  EXPECT_EQ(direct.update(s, kUpdateInstances, nullptr) & (kDirtyGeometry | kDirtyTriangleNames), 0u);
  check(direct, "one hidden");
  s.objects[0].visible = true;
  EXPECT_EQ(direct.update(s, kUpdateInstances, nullptr) & (kDirtyGeometry | kDirtyTriangleNames), 0u);
  Object* moved = s.object(b);
  ASSERT_NE(moved, nullptr);
  moved->transform = Mat4::translate({0.2f, 0.1f, 0}) * Mat4::rotateY(0.3f);
  // The culled ball mirrored: its front is where its winding's normal, carried by the normal
  // matrix, points (outwards, as the brute force has it), not where its world-space winding does.
  s.objects.back().transform = s.objects.back().transform * Mat4::scale({-1, 1, 1});
  direct.update(s, kUpdateInstances, nullptr);
  EXPECT_FALSE(direct.data().directReferences) << "a transform turns direct off";
  EXPECT_TRUE(direct.data().instanceTransforms);
  check(direct, "after a move");
}

// A hidden object keeps its instance (and its number) but is neither reached nor a light.
TEST(RenderScene, AHiddenEmitterLightsNothing) {
  Scene s = test::emptyScene(8, 8);
  Material lamp;
  lamp.emission = Vec3{4.0f};
  const NodeId light = test::addMeshObject(s, "lamp", makeQuad(), test::addMaterial(s, lamp), Mat4::identity());
  test::addMeshObject(s, "floor", makeQuad(), test::addMaterial(s, Material{}), Mat4::translate({0, -1, 0}));
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  EXPECT_EQ(builder.data().emitters.size(), 2u * gpu::kEmitterTexels);
  EXPECT_NE(builder.data().features() & gpu::kFeatureEmitters, 0u);
  s.object(light)->visible = false;
  builder.update(s, kUpdateInstances, nullptr);
  EXPECT_TRUE(builder.data().emitters.empty());
  EXPECT_EQ(builder.data().features() & gpu::kFeatureEmitters, 0u);
  EXPECT_EQ(builder.data().instanceObject.size(), 2u);
  EXPECT_EQ(builder.data().instanceReferences, 1u) << "only the floor is in the instance BVH";
}

// The sample rays that choose how far instances are opened do not depend on the camera seeing
// the scene: looking away from the crossing rods, they are still opened.
TEST(RenderScene, ACameraLookingAwayStillOpensOverlappingInstances) {
  Scene s = test::emptyScene(8, 8);
  const NodeId mat = test::addMaterial(s, Material{});
  test::addMeshObject(s, "a", diagonalRod({1, 1, 1}, 2000, 1), mat, Mat4::identity());
  test::addMeshObject(s, "b", diagonalRod({1, -1, 1}, 2000, 2), mat, Mat4::identity());
  s.camera.position = {0, 0, 5};
  s.camera.target = {0, 0, 10};
  RenderSceneBuilder away;
  away.update(s, kUpdateAll, nullptr);
  EXPECT_GT(away.data().instanceReferences, 2u);
}

// Choosing how far to open the instances traces sample rays, tens of milliseconds on a big
// scene, which an edit would add to the editor's next frame. So showing, hiding, adding or
// moving an object keeps the factor (the first move, which turns direct references off, finds the
// factor for records chosen with the direct one); it is chosen again when meshes change or the
// visible objects differ from those of the last choice by more than an eighth.
TEST(RenderScene, SmallEditsKeepTheBraidFactor) {
  Scene s = test::emptyScene(8, 8);
  const NodeId mat = test::addMaterial(s, Material{});
  std::vector<NodeId> rods;
  for (std::uint32_t i = 0; i < 16; ++i)
    rods.push_back(test::addMeshObject(s, "rod", diagonalRod({1, i % 2 ? 1.0f : -1.0f, 1}, 200, i + 1), mat, Mat4::identity()));
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  ASSERT_TRUE(builder.data().directReferences);
  const std::uint64_t chosen = builder.braidChoices();
  EXPECT_EQ(chosen, 1u);
  const std::size_t opened = builder.data().instanceReferences;
  // The overlapping rods are opened, and with records too (as a builder that packs only records
  // chooses for this scene), which the first move below must find.
  EXPECT_GT(opened, rods.size());
  RenderSceneBuilder records;
  records.setDirectReferences(false);
  records.update(s, kUpdateAll, nullptr);
  const std::size_t openedForRecords = records.data().instanceReferences;
  EXPECT_GT(openedForRecords, rods.size());
  auto object = [&](NodeId id) -> Object& {
    return *std::find_if(s.objects.begin(), s.objects.end(), [&](const Object& o) { return o.id == id; });
  };

  // Hidden and shown again, then two of sixteen hidden (an eighth).
  object(rods[3]).visible = false;
  builder.update(s, kUpdateInstances, nullptr);
  object(rods[3]).visible = true;
  builder.update(s, kUpdateInstances, nullptr);
  EXPECT_EQ(builder.data().instanceReferences, opened);
  object(rods[0]).visible = false;
  object(rods[1]).visible = false;
  builder.update(s, kUpdateInstances, nullptr);
  EXPECT_EQ(builder.braidChoices(), chosen);
  object(rods[0]).visible = true;
  object(rods[1]).visible = true;
  builder.update(s, kUpdateInstances, nullptr);

  object(rods[5]).transform = Mat4::translate({0.1f, 0, 0});
  builder.update(s, kUpdateInstances, nullptr);
  EXPECT_FALSE(builder.data().directReferences);
  EXPECT_EQ(builder.braidChoices(), chosen) << "the first move chose the factor again";
  EXPECT_EQ(builder.data().instanceReferences, openedForRecords);

  // Three of sixteen hidden: more than an eighth.
  for (std::size_t i = 0; i < 3; ++i) object(rods[i]).visible = false;
  builder.update(s, kUpdateInstances, nullptr);
  EXPECT_EQ(builder.braidChoices(), chosen + 1);

  builder.update(s, kUpdateGeometry | kUpdateInstances, nullptr);
  EXPECT_EQ(builder.braidChoices(), chosen + 2);
}

TEST(RenderScene, InstancesApartKeepOneReferenceEach) {
  Scene s = test::emptyScene(8, 8);
  const NodeId mat = test::addMaterial(s, Material{});
  const auto sphere = makeSphere(16, 32);
  for (int i = 0; i < 6; ++i) test::addMeshObject(s, "ball", sphere, mat, Mat4::translate({4.0f * static_cast<float>(i), 0, 0}));
  RenderSceneBuilder builder;
  // Entered through records, where each reference costs a step. (Direct, opening the balls costs
  // nothing more, and the surface area heuristic may open them.)
  builder.setDirectReferences(false);
  builder.update(s, kUpdateAll, nullptr);
  EXPECT_EQ(builder.data().instanceObject.size(), 6u);
  EXPECT_EQ(builder.data().instanceReferences, 6u);
}

// Light samples pick emitter triangles by power: a textured emitter's is scaled by its texture's
// mean, and its records name its triangle and texture for the uv lookup at a sample. (Two lamps
// side by side facing the same way gain little from a choice per point: no light groups.)
TEST(RenderScene, ATexturedEmitterIsPickedByItsTexturesMean) {
  Scene s = test::emptyScene(8, 8);
  Texture dim;
  dim.id = s.newId();
  dim.kind = TextureKind::Checker;
  dim.checkerOn = Vec3{0.2f};
  dim.checkerOff = Vec3{0.0f};  // mean 0.1
  s.textures.push_back(dim);
  Material plain;
  plain.emission = Vec3{3.0f};
  Material textured = plain;
  textured.emissionTexture = dim.id;
  test::addMeshObject(s, "plain", makeQuad(), test::addMaterial(s, plain), Mat4::identity());
  test::addMeshObject(s, "textured", makeQuad(), test::addMaterial(s, textured), Mat4::translate({3, 0, 0}));
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  const RenderSceneData& d = builder.data();
  ASSERT_EQ(d.emitters.size(), 4u * gpu::kEmitterTexels);
  EXPECT_NE(d.features() & static_cast<std::uint32_t>(gpu::kFeatureEmissionTextures), 0u);
  EXPECT_EQ(d.lightGroups, 0) << "gain " << d.lightGroupGain;
  EXPECT_LT(d.lightGroupGain, kLightGroupMinGain);
  double pick[2] = {0, 0};
  for (std::size_t e = 0; e < 4; ++e) {
    const vec4* r = d.emitters.data() + e * gpu::kEmitterTexels;
    const int texture = std::bit_cast<std::int32_t>(r[4].w);
    pick[texture >= 0 ? 1 : 0] += r[3].w;
    const int triangle = std::bit_cast<std::int32_t>(r[2].w);
    ASSERT_GE(triangle, 0);
    ASSERT_LT(static_cast<std::size_t>(triangle), d.triangleCount);
  }
  EXPECT_NEAR(pick[0] + pick[1], 1.0, 1e-5);
  EXPECT_NEAR(pick[1], 0.1 / 1.1, 1e-4) << "the textured emitter has a tenth of the power";
}

// The gain of choosing a light group per point: with one group's weight everywhere it has, as
// much as by power (1); with two equal lamps, each seen from the far side of the other's plane
// where only it can light, the share of power each gets by power is a half (2).
TEST(RenderScene, ALightGroupsGainIsWhatChoosingPerPointSaves) {
  const Bounds3 box{{-1, -1, -1}, {1, 1, 1}};
  auto lamp = [](Vec3 centre, Vec3 normal, float scale) {
    return std::array<vec4, 2>{vec4{centre.x, centre.y, centre.z, scale}, vec4{normal.x, normal.y, normal.z, 1e30f}};
  };
  std::vector<vec4> shapes;
  auto add = [&](const std::array<vec4, 2>& l) { shapes.insert(shapes.end(), l.begin(), l.end()); };
  // The same weights at every point in proportion to the power: as good as by power.
  add(lamp({0, 0, 0}, {0, 0, 0}, 1));
  add(lamp({0, 0, 0}, {0, 0, 0}, 3));
  EXPECT_NEAR(lightGroupGain(shapes, {1, 3}, box), 1.0, 1e-6);
  // Two lamps at the centre facing opposite ways: every point sees one.
  shapes.clear();
  add(lamp({0, 0, 0}, {0, 1, 0}, 1));
  add(lamp({0, 0, 0}, {0, -1, 0}, 1));
  EXPECT_NEAR(lightGroupGain(shapes, {1, 1}, box), 2.0, 1e-6);
  // The same with a tenth of the power in the first: where only it lights, by power it gets a
  // tenth of the samples (second moment 11 w^2 against w^2), where the other does 11/10.
  EXPECT_GT(lightGroupGain(shapes, {1, 10}, box), 2.0);
  EXPECT_EQ(lightGroupGain(shapes, {1, 1}, Bounds3{}), 1.0) << "no points";
}

// Light groups switch on at kLightGroupMinGain but, once on, stay on down to kLightGroupKeepGain,
// so a lamp turned to and fro across one threshold does not swap kernel variants at each
// crossing. Two lamps inside a ball of white, the second turned from facing away from the first
// (each lights its own half: a high gain) to facing the same way (a low gain), and back.
TEST(RenderScene, LightGroupsTurnedOnStayOnUntilTheirGainFallsFarther) {
  Scene s = test::emptyScene(8, 8);
  Material lamp;
  lamp.emission = Vec3{2.0f};
  const NodeId lampId = test::addMaterial(s, lamp);
  test::addMeshObject(s, "room", makeSphere(8, 16), test::addMaterial(s, Material{}), Mat4::scale(Vec3{20.0f}));
  test::addMeshObject(s, "up", makeQuad(), lampId, Mat4::identity());
  const NodeId turned = test::addMeshObject(s, "turned", makeQuad(), lampId, Mat4::translate({1.5f, 0, 0}));
  constexpr int kSteps = 24;
  auto turn = [&](int step) {
    s.object(turned)->transform = Mat4::translate({1.5f, 0, 0}) * Mat4::rotateZ(kPi * static_cast<float>(step) / kSteps);
  };
  // The gain at each angle, as a scene opened there has it.
  std::vector<double> gain(kSteps + 1);
  bool between = false;
  for (int k = 0; k <= kSteps; ++k) {
    turn(k);
    RenderSceneBuilder fresh;
    fresh.update(s, kUpdateAll, nullptr);
    gain[static_cast<std::size_t>(k)] = fresh.data().lightGroupGain;
    EXPECT_EQ(fresh.data().lightGroups > 0, fresh.data().lightGroupGain >= kLightGroupMinGain) << k;
    between =
        between || (gain[static_cast<std::size_t>(k)] >= kLightGroupKeepGain && gain[static_cast<std::size_t>(k)] < kLightGroupMinGain);
  }
  ASSERT_LT(gain[0], kLightGroupKeepGain) << "facing the same way";
  ASSERT_GE(gain[kSteps], kLightGroupMinGain) << "facing apart";
  ASSERT_TRUE(between) << "some angle between the thresholds";
  RenderSceneBuilder builder;
  turn(kSteps);
  builder.update(s, kUpdateAll, nullptr);
  int keptOn = 0, keptOff = 0;
  auto sweep = [&](int from, int to) {
    const int step = from < to ? 1 : -1;
    for (int k = from;; k += step) {
      const bool wasOn = builder.data().lightGroups > 0;
      turn(k);
      builder.update(s, kUpdateInstances | kUpdateLights, nullptr);
      const double g = gain[static_cast<std::size_t>(k)];
      EXPECT_NEAR(builder.data().lightGroupGain, g, 1e-6 * g) << k;
      const bool on = builder.data().lightGroups > 0;
      EXPECT_EQ(on, g >= (wasOn ? kLightGroupKeepGain : kLightGroupMinGain)) << k << ", gain " << g;
      if (on && g < kLightGroupMinGain) ++keptOn;
      if (!on && g >= kLightGroupKeepGain) ++keptOff;
      if (k == to) break;
    }
  };
  sweep(kSteps, 0);
  sweep(0, kSteps);
  EXPECT_GT(keptOn, 0) << "on below the gain that turns them on";
  EXPECT_GT(keptOff, 0) << "off above the gain that keeps them on";
}

// Each emissive instance is a light group: its run of emitters, an alias table within the run,
// its bounding sphere, its plane where all its triangles lie in one facing one way (a quad, not a
// ball nor two quads back to back), and a scale from its power. One group, or more than
// kMaxLightGroups, compiles no groups in, and picks among all emitters by power.
TEST(RenderScene, EmissiveInstancesAreLightGroupsWithTheirPlanes) {
  Scene s = test::emptyScene(8, 8);
  Material lamp;
  lamp.emission = Vec3{2.0f};
  const NodeId lampId = test::addMaterial(s, lamp);
  // Facing down, 2 x 2, its centre at (5, 3, 0).
  test::addMeshObject(s, "quad", makeQuad(), lampId, Mat4::translate({5, 3, 0}) * Mat4::rotateX(kPi) * Mat4::scale({2, 1, 2}));
  test::addMeshObject(s, "ball", makeSphere(8, 16), lampId, Mat4::translate({-4, 0, 0}));
  auto twoFaced = std::make_shared<MeshGeometry>(*makeQuad());
  for (std::uint32_t i : {0u, 2u, 1u, 0u, 3u, 2u}) twoFaced->indices.push_back(i);
  std::swap(twoFaced->indices[7], twoFaced->indices[8]);
  std::swap(twoFaced->indices[10], twoFaced->indices[11]);
  test::addMeshObject(s, "two faced", twoFaced, lampId, Mat4::translate({0, 0, 6}));
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  const RenderSceneData& d = builder.data();
  const std::size_t n = d.emitters.size() / gpu::kEmitterTexels;
  ASSERT_EQ(d.lightGroups, 3) << "gain " << d.lightGroupGain;
  EXPECT_GE(d.lightGroupGain, kLightGroupMinGain);
  EXPECT_NE(d.features() & static_cast<std::uint32_t>(gpu::kFeatureLightGroups), 0u);
  ASSERT_EQ(d.emitterAlias.size(), n + 3u * gpu::kLightGroupTexels);
  ASSERT_EQ(d.lightGroupShapes.size(), 6u);
  std::size_t covered = 0;
  int planes = 0;
  for (int g = 0; g < 3; ++g) {
    const vec4 run = d.emitterAlias[n + static_cast<std::size_t>(g) * gpu::kLightGroupTexels];
    const vec4* rec = d.lightGroupShapes.data() + 2 * static_cast<std::size_t>(g);
    const auto first = static_cast<std::size_t>(std::bit_cast<std::int32_t>(run.x));
    const auto count = static_cast<std::size_t>(std::bit_cast<std::int32_t>(run.y));
    EXPECT_EQ(first, covered) << "the groups are consecutive runs";
    covered += count;
    double picks = 0, area = 0;
    for (std::size_t e = first; e < first + count; ++e) {
      EXPECT_EQ(std::bit_cast<std::int32_t>(d.emitterAlias[e].z), g);
      const auto alias = static_cast<std::size_t>(std::bit_cast<std::int32_t>(d.emitterAlias[e].y));
      EXPECT_TRUE(alias >= first && alias < first + count) << "an alias within the group";
      picks += d.emitters[e * gpu::kEmitterTexels + 3].w;
      area += d.emitters[e * gpu::kEmitterTexels].w;
    }
    EXPECT_NEAR(picks, 1.0, 1e-5) << g;
    const Vec3 normal{rec[1].x, rec[1].y, rec[1].z};
    if (count == 2) {
      // The quad facing down: its centre on its plane y = 3, its scale area x 2, its most weight
      // that over its bounding radius (sqrt 2) squared.
      ++planes;
      EXPECT_NEAR(normal.y, -1.0f, 1e-5f);
      EXPECT_NEAR(rec[0].x, 5.0f, 1e-5f);
      EXPECT_NEAR(rec[0].y, 3.0f, 1e-5f);
      EXPECT_NEAR(rec[0].w, 8.0f, 1e-3f);
      EXPECT_NEAR(rec[1].w, 4.0f, 1e-3f);
    } else {
      EXPECT_EQ(length(normal), 0.0f) << "no one plane facing one way: group " << g;
      EXPECT_NEAR(rec[0].w, area * 2.0 / 4.0, 1e-3 * area) << "a quarter of its area times its radiance";
    }
  }
  EXPECT_EQ(planes, 1);
  EXPECT_EQ(covered, n);

  // A tilted triangle, whose bounding box's centre is off its plane: the centre is put on it.
  Scene tilted = test::emptyScene(8, 8);
  auto triangle = std::make_shared<MeshGeometry>();
  triangle->positions = {{0, 0, 0}, {1, 0, 0}, {0, 0, 2}};
  triangle->normals.assign(3, {0, 1, 0});
  triangle->uvs.assign(3, {0, 0});
  triangle->indices = {0, 2, 1};
  const NodeId tiltedLamp = test::addMaterial(tilted, lamp);
  test::addMeshObject(tilted, "triangle", triangle, tiltedLamp, Mat4::translate({1, 2, 3}) * Mat4::rotateZ(0.5f) * Mat4::rotateX(0.7f));
  test::addMeshObject(tilted, "quad", makeQuad(), tiltedLamp, Mat4::translate({0, -5, 0}));
  builder.update(tilted, kUpdateAll, nullptr);
  {
    const RenderSceneData& t = builder.data();
    ASSERT_EQ(t.lightGroups, 2);
    const vec4* rec = t.lightGroupShapes.data();  // the triangle's group, the first
    const Vec3 normal{rec[1].x, rec[1].y, rec[1].z}, centre{rec[0].x, rec[0].y, rec[0].z};
    const Vec3 corner{t.emitters[0].x, t.emitters[0].y, t.emitters[0].z};
    EXPECT_NEAR(length(normal), 1.0f, 1e-5f) << "a plane";
    EXPECT_NEAR(dot(normal, centre - corner), 0.0f, 1e-5f) << "the centre on the plane";
    const Mat4 place = Mat4::translate({1, 2, 3}) * Mat4::rotateZ(0.5f) * Mat4::rotateX(0.7f);
    Bounds3 placed;
    for (Vec3 v : triangle->positions) placed.grow(place.transformPoint(v));
    EXPECT_GT(std::abs(dot(normal, placed.center() - corner)), 0.01f) << "the box's centre is off the plane";
  }

  // One emitter: no groups, and the picks are among all emitters.
  Scene one = test::emptyScene(8, 8);
  test::addMeshObject(one, "ball", makeSphere(8, 16), test::addMaterial(one, lamp), Mat4::identity());
  builder.update(one, kUpdateAll, nullptr);
  EXPECT_EQ(builder.data().lightGroups, 0);
  EXPECT_EQ(builder.data().features() & static_cast<std::uint32_t>(gpu::kFeatureLightGroups), 0u);
  EXPECT_EQ(builder.data().emitterAlias.size(), builder.data().emitters.size() / gpu::kEmitterTexels);
  EXPECT_TRUE(builder.data().lightGroupShapes.empty());
  // More than kMaxLightGroups: the same.
  Scene many = test::emptyScene(8, 8);
  const NodeId manyLamp = test::addMaterial(many, lamp);
  for (int i = 0; i <= gpu::kMaxLightGroups; ++i)
    test::addMeshObject(many, "quad", makeQuad(), manyLamp, Mat4::translate({2.0f * static_cast<float>(i), 0, 0}));
  builder.update(many, kUpdateAll, nullptr);
  const RenderSceneData& m = builder.data();
  EXPECT_EQ(m.lightGroups, 0);
  double picks = 0;
  for (std::size_t e = 0; e < m.emitters.size() / gpu::kEmitterTexels; ++e) picks += m.emitters[e * gpu::kEmitterTexels + 3].w;
  EXPECT_NEAR(picks, 1.0, 1e-5);
}

// An emitter's cone is packed as its cosine where the kernel reads it (the material's eighth
// texel, z), and compiles the cone in only while some emitter's cone is narrower than the
// hemisphere: not for a cone on something that does not emit, nor once it is back at 90.
TEST(RenderScene, AnEmissionConeIsPackedAsItsCosineAndCompiledInWhileNarrower) {
  Scene s = test::emptyScene(8, 8);
  Material lamp;
  lamp.emission = Vec3{2.0f};
  lamp.emissionCone = 60;
  Material dark;
  dark.emissionCone = 10;  // not an emitter: no cone to render
  const NodeId lampId = test::addMaterial(s, lamp), darkId = test::addMaterial(s, dark);
  test::addMeshObject(s, "lamp", makeQuad(), lampId, Mat4::identity());
  test::addMeshObject(s, "dark", makeQuad(), darkId, Mat4::translate({3, 0, 0}));
  const auto cone = static_cast<std::uint32_t>(gpu::kFeatureEmissionCone);
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  const auto cosineOf = [&](std::size_t material) { return builder.data().materials[material * gpu::kMaterialTexels + 7].z; };
  EXPECT_NEAR(cosineOf(0), 0.5f, 1e-6f);
  EXPECT_NE(builder.data().features() & cone, 0u);
  s.material(lampId)->emissionCone = 90;
  builder.update(s, kUpdateMaterials, nullptr);
  EXPECT_EQ(cosineOf(0), 0.0f) << "the hemisphere";
  EXPECT_EQ(builder.data().features() & cone, 0u) << "a narrow cone on a material that does not emit compiles nothing";
  s.material(lampId)->emissionCone = std::numeric_limits<float>::quiet_NaN();
  builder.update(s, kUpdateMaterials, nullptr);
  EXPECT_EQ(cosineOf(0), 0.0f) << "not a number: the hemisphere";
}

// A roughness texture on a type without roughness (left there by a change of type, or written in
// a native file) is not packed: the kernel would read it for nothing. On a rough type it is, and
// on a thin sheet, which has no roughness, as its thickness (the kernel scales its film, in the
// roughness slot, and its absorption by it).
TEST(RenderScene, OnlyARoughTypeOrASheetReadsItsRoughnessTexture) {
  Scene s = test::emptyScene(8, 8);
  Texture grain;
  grain.id = s.newId();
  grain.kind = TextureKind::Checker;
  s.textures.push_back(grain);
  Material sheet;
  sheet.type = MaterialType::ThinSheet;
  sheet.filmThickness = 300;
  sheet.roughnessTexture = grain.id;
  Material rough = sheet;
  rough.type = MaterialType::RoughPlastic;
  Material matte = sheet;
  matte.type = MaterialType::Lambert;
  test::addMeshObject(s, "sheet", makeQuad(), test::addMaterial(s, sheet), Mat4::identity());
  test::addMeshObject(s, "plastic", makeQuad(), test::addMaterial(s, rough), Mat4::translate({3, 0, 0}));
  test::addMeshObject(s, "matte", makeQuad(), test::addMaterial(s, matte), Mat4::translate({6, 0, 0}));
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  const RenderSceneData& d = builder.data();
  auto roughnessTexture = [&](std::size_t material) {
    return std::bit_cast<std::int32_t>(d.materials[material * gpu::kMaterialTexels + 3].w);
  };
  EXPECT_GE(roughnessTexture(0), 0) << "the sheet: its thickness";
  EXPECT_EQ(d.materials[0 * gpu::kMaterialTexels + 1].x, 300.0f) << "its film in the roughness slot";
  EXPECT_GE(roughnessTexture(1), 0) << "the rough plastic";
  EXPECT_EQ(roughnessTexture(2), -1) << "lambert has no roughness";
}

// Textures are packed in one array, 8-bit ones a word a texel and padded to whole pairs, half
// floats two words a texel; an update copies unchanged ones from the last packing instead of
// decoding their files again. With the first texture removed, the others hold the same texels at
// their new offsets, although one's file is gone by then (it would be shown as a checker if it
// were read again).
TEST(RenderScene, TexturesKeepTheirTexelsWhenOthersComeAndGo) {
  Scene s = test::emptyScene(8, 8);
  const auto dir = test::tempDir();
  auto bytes = [&](const std::string& name, const std::vector<int>& row) {
    const auto file = dir / (name + ".ppm");
    std::vector<std::uint8_t> rgb;
    for (int v : row)
      rgb.insert(rgb.end(), {static_cast<std::uint8_t>(v), static_cast<std::uint8_t>(v / 2), static_cast<std::uint8_t>(255 - v)});
    test::writePpm(file, static_cast<int>(row.size()), 1, rgb);
    return file;
  };
  RenderImage halves;
  halves.width = 2;
  halves.height = 1;
  halves.color = {0.25f, 0.5f, 2.0f, 4.0f, 0.125f, 0.0f};
  const auto exr = dir / "halves.exr";
  ASSERT_TRUE(writeRenderImage(halves, exr).ok());
  for (const auto& file : {bytes("odd", {10, 20, 30}), exr, bytes("one", {200})}) test::addFileTexture(s, file, TextureColorSpace::Linear);
  RenderSceneBuilder builder;
  std::vector<std::string> warnings;
  builder.update(s, kUpdateAll, &warnings);
  EXPECT_TRUE(warnings.empty());
  // Texture i's (flags, width, height) and its words.
  auto texture = [&](int index) {
    const RenderSceneData& d = builder.data();
    const vec4* info = d.textureInfo.data() + static_cast<std::size_t>(index) * gpu::kTextureTexels;
    const auto [offset, w, h, flags] = std::array{std::bit_cast<std::int32_t>(info->x), std::bit_cast<std::int32_t>(info->y),
                                                  std::bit_cast<std::int32_t>(info->z), std::bit_cast<std::int32_t>(info->w)};
    const std::size_t words = static_cast<std::size_t>(w * h) * ((flags & gpu::kTexEightBit) ? 1 : 2);
    EXPECT_LE(static_cast<std::size_t>(offset) * 2 + words, d.texels.size());
    return std::pair{
        std::array{flags, w, h},
        std::vector<std::uint32_t>(d.texels.begin() + offset * 2, d.texels.begin() + offset * 2 + static_cast<std::ptrdiff_t>(words))};
  };
  const auto odd = texture(0), half = texture(1), one = texture(2);
  EXPECT_EQ(odd.first, (std::array{gpu::kTexBitmap | gpu::kTexEightBit, 3, 1}));
  EXPECT_EQ(odd.second, (std::vector<std::uint32_t>{0xfff5050au, 0xffeb0a14u, 0xffe10f1eu}));
  EXPECT_EQ(one.first, (std::array{gpu::kTexBitmap | gpu::kTexEightBit, 1, 1}));
  EXPECT_EQ(half.first, (std::array{gpu::kTexBitmap, 2, 1}));
  EXPECT_EQ(half.second[0], floatToHalf(0.25f) | std::uint32_t{floatToHalf(0.5f)} << 16);
  EXPECT_EQ(half.second[1], floatToHalf(2.0f) | std::uint32_t{floatToHalf(1.0f)} << 16);
  EXPECT_EQ(builder.data().texels.size(), 4u + 4u + 2u) << "3 bytes' words and a pad, 2 halves, 1 byte's word and a pad";
  // The kernel reads both storages, and no sRGB.
  const auto features = builder.data().features();
  EXPECT_NE(features & static_cast<std::uint32_t>(gpu::kFeatureByteTexels), 0u);
  EXPECT_NE(features & static_cast<std::uint32_t>(gpu::kFeatureHalfTexels), 0u);
  EXPECT_EQ(features & static_cast<std::uint32_t>(gpu::kFeatureSrgbTexels), 0u);

  std::filesystem::remove(exr);
  s.textures.erase(s.textures.begin());
  builder.update(s, kUpdateTextures, &warnings);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  EXPECT_EQ(texture(0), half) << "kept, not read again";
  EXPECT_EQ(texture(1), one);
  EXPECT_EQ(builder.data().texels.size(), 4u + 2u);
  // Without the half-float texture and with an sRGB one, the kernel reads bytes alone, and sRGB.
  s.textures.erase(s.textures.begin());
  s.textures.back().colorSpace = TextureColorSpace::SRGB;
  builder.update(s, kUpdateTextures, &warnings);
  EXPECT_EQ(
      builder.data().features() & static_cast<std::uint32_t>(gpu::kFeatureByteTexels | gpu::kFeatureHalfTexels | gpu::kFeatureSrgbTexels),
      static_cast<std::uint32_t>(gpu::kFeatureByteTexels | gpu::kFeatureSrgbTexels));
}

// A texture a material bumps by is packed with its slopes after its colour (scene.glsl
// textureSlope reads them): for each texel, the channels' mean across the two texels beside it,
// along a row and down the rows, wrapped. Whichever edit makes it a bump map or no longer one,
// a material's alone, the packing is a fresh packing's, and the colour stays where it was.
TEST(RenderScene, BumpTexturesArePackedWithTheirSlopes) {
  Scene s = test::emptyScene(8, 8);
  const auto file = test::tempDir() / "bumps.ppm";
  // Grey rows: 0, 0.2, 0.6 | 1, 1, 1 | 0.4, 0.4, 0.4.
  const std::vector<std::uint8_t> greys = {0, 51, 153, 255, 255, 255, 102, 102, 102};
  std::vector<std::uint8_t> rgb;
  for (std::uint8_t g : greys) rgb.insert(rgb.end(), {g, g, g});
  test::writePpm(file, 3, 3, rgb);
  const NodeId texture = test::addFileTexture(s, file, TextureColorSpace::Linear);
  Material m;
  m.albedoTexture = texture;
  const NodeId material = test::addMaterial(s, m);
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  const RenderSceneData& d = builder.data();
  auto slopes = [&] { return std::bit_cast<std::int32_t>(d.textureInfo[1].x); };
  EXPECT_EQ(slopes(), -1) << "an albedo has none";
  const std::vector<std::uint32_t> colour = d.texels;
  ASSERT_EQ(colour.size(), 10u) << "nine words and a pad";

  s.material(material)->bumpTexture = texture;
  s.material(material)->bumpStrength = 2;
  EXPECT_NE(builder.update(s, kUpdateMaterials, nullptr) & kDirtyTextures, 0u) << "a material's edit packs the slopes";
  ASSERT_EQ(slopes(), 5) << "after the colour's five pairs";
  ASSERT_EQ(d.texels.size(), 20u);
  EXPECT_TRUE(std::equal(colour.begin(), colour.end(), d.texels.begin()));
  const float g[3][3] = {{0.0f, 0.2f, 0.6f}, {1, 1, 1}, {0.4f, 0.4f, 0.4f}};
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) {
      const std::uint32_t word = d.texels[static_cast<std::size_t>(10 + y * 3 + x)];
      EXPECT_NEAR(halfToFloat(static_cast<std::uint16_t>(word & 0xffffu)), g[y][(x + 1) % 3] - g[y][(x + 2) % 3], 1e-3) << x << ", " << y;
      EXPECT_NEAR(halfToFloat(static_cast<std::uint16_t>(word >> 16)), g[(y + 1) % 3][x] - g[(y + 2) % 3][x], 1e-3) << x << ", " << y;
    }
  const std::vector<std::uint32_t> withSlopes = d.texels;
  RenderSceneBuilder fresh;
  fresh.update(s, kUpdateAll, nullptr);
  EXPECT_EQ(fresh.data().texels, withSlopes);
  ASSERT_EQ(fresh.data().textureInfo.size(), d.textureInfo.size());
  EXPECT_EQ(std::memcmp(fresh.data().textureInfo.data(), d.textureInfo.data(), d.textureInfo.size() * sizeof(vec4)), 0);
  builder.update(s, kUpdateTextures, nullptr);
  EXPECT_EQ(d.texels, withSlopes) << "copied from the last packing";

  s.material(material)->bumpStrength = 0;
  EXPECT_NE(builder.update(s, kUpdateMaterials, nullptr) & kDirtyTextures, 0u) << "a bump of strength 0 reads none";
  EXPECT_EQ(slopes(), -1);
  EXPECT_EQ(d.texels, colour);
  s.material(material)->bumpStrength = 2;
  builder.update(s, kUpdateMaterials, nullptr);
  EXPECT_EQ(d.texels, withSlopes) << "made again from the colour";
}

// Sets the scene's environment to a map of two texels, 1 then 3, written as EXR to `file`.
void setTwoTexelSky(Scene& s, const std::filesystem::path& file) {
  RenderImage sky;
  sky.width = 2;
  sky.height = 1;
  sky.color = {1.0f, 1.0f, 1.0f, 3.0f, 3.0f, 3.0f};
  ASSERT_TRUE(writeRenderImage(sky, file).ok());
  s.environment.type = EnvironmentType::Map;
  s.environment.map = test::addFileTexture(s, file, TextureColorSpace::Linear);
}

// The sky map is one of the scene's textures and is packed once, with them; the distribution
// that light samples draw its texels by is built from the packed texels, so it follows the
// brighter one.
TEST(RenderScene, AnEnvironmentMapIsStoredOnceAmongTheTextures) {
  Scene s = test::emptyScene(8, 8);
  setTwoTexelSky(s, test::tempDir() / "two-texel-sky.exr");
  RenderSceneBuilder builder;
  std::vector<std::string> warnings;
  builder.update(s, kUpdateAll, &warnings);
  EXPECT_TRUE(warnings.empty());
  const RenderSceneData& d = builder.data();
  EXPECT_EQ(d.environmentType, gpu::kEnvMap);
  EXPECT_EQ(d.environmentMap, 0) << "the texture's own entry";
  EXPECT_EQ(d.texels.size(), 4u) << "two texels of two words, once";
  ASSERT_EQ(d.environmentCdf.size(), 1u + 2u + 3u);
  EXPECT_NEAR(d.environmentCdf[1 + 2 + 1], 0.25, 1e-6) << "the first texel's share of its row";
}

// Dragging the sky's intensity or colour changes the frame's tint, not the packed arrays: the
// texels and the light-sampling distribution stay (nothing to copy or upload), the light pick
// follows the new power. A baked sky is packed after the textures and replaced alone; whatever
// the environment went through, the arrays end as a fresh packing of the same scene makes them.
TEST(RenderScene, AnEnvironmentEditRepacksOnlyWhatItChanged) {
  Scene s = test::emptyScene(8, 8);
  const auto otherFile = test::tempDir() / "edited-sky-other.ppm";
  test::writePpm(otherFile, 3, 1, {10, 20, 30, 40, 50, 60, 70, 80, 90});
  const NodeId other = test::addFileTexture(s, otherFile, TextureColorSpace::Linear);
  ASSERT_NE(other, kNoNode);
  setTwoTexelSky(s, test::tempDir() / "edited-sky.exr");
  s.environment.color = Vec3{1.0f};
  s.environment.intensity = 0.5f;
  Material lit;
  lit.emission = {1, 1, 1};
  test::addMeshObject(s, "light", makeQuad(), test::addMaterial(s, lit), Mat4::identity());
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  const RenderSceneData& d = builder.data();
  const std::vector<std::uint32_t> texels = d.texels;
  const std::vector<float> cdf = d.environmentCdf;
  const float pick = d.lightPick[1];
  auto edit = [&](const Environment& e) {
    auto flags = applyEdit(s, SetEnvironment{e});
    EXPECT_TRUE(flags.ok());
    return builder.update(s, flags.ok() ? flags.value() : 0u, nullptr);
  };
  Environment e = s.environment;
  e.intensity = 4;
  EXPECT_EQ(edit(e) & (kDirtyTextures | kDirtyEnvironment | kDirtyGeometry | kDirtyInstances | kDirtyMaterials), 0u)
      << "an intensity drag repacks nothing";
  EXPECT_EQ(d.texels, texels);
  EXPECT_EQ(d.environmentCdf, cdf);
  EXPECT_EQ(d.environmentType, gpu::kEnvMap);
  EXPECT_FLOAT_EQ(d.environmentTint.x, 4 * s.environment.color.x);
  EXPECT_GT(d.lightPick[1], pick) << "a brighter sky takes more of the light samples";

  // To a baked sky: the sky's texels follow the textures', and the map's distribution goes.
  e.type = EnvironmentType::Sky;
  EXPECT_EQ(edit(e) & (kDirtyTextures | kDirtyEnvironment), kDirtyTextures | kDirtyEnvironment);
  ASSERT_GT(d.texels.size(), texels.size());
  EXPECT_TRUE(std::equal(texels.begin(), texels.end(), d.texels.begin())) << "the textures' texels kept in place";
  EXPECT_EQ(d.environmentMap, 2) << "the sky's entry after the two textures";
  const std::vector<std::uint32_t> withSky = d.texels;
  const std::vector<float> skyCdf = d.environmentCdf;
  e.intensity = 2;
  EXPECT_EQ(edit(e) & (kDirtyTextures | kDirtyEnvironment), 0u) << "the same sky, brighter";
  EXPECT_EQ(d.texels, withSky);
  e.zenith = {0.1f, 0.2f, 0.9f};
  EXPECT_EQ(edit(e) & kDirtyTextures, kDirtyTextures) << "another sky";
  EXPECT_EQ(d.texels.size(), withSky.size());
  EXPECT_NE(d.texels, withSky);
  EXPECT_NE(d.environmentCdf, skyCdf);

  // Back to the map: as a fresh packing makes the arrays.
  e.type = EnvironmentType::Map;
  EXPECT_EQ(edit(e) & (kDirtyTextures | kDirtyEnvironment), kDirtyTextures | kDirtyEnvironment);
  RenderSceneBuilder fresh;
  fresh.update(s, kUpdateAll, nullptr);
  EXPECT_EQ(d.texels, fresh.data().texels);
  EXPECT_EQ(d.textureInfo.size(), fresh.data().textureInfo.size());
  EXPECT_EQ(d.environmentCdf, fresh.data().environmentCdf);
  EXPECT_EQ(d.halfTexels, fresh.data().halfTexels);
  EXPECT_EQ(d.lightPick[1], fresh.data().lightPick[1]);

  // A texture edit under a baked sky: the sky comes back after the textures.
  e.type = EnvironmentType::Sky;
  edit(e);
  ASSERT_TRUE(applyEdit(s, RemoveNode{other}).ok());
  builder.update(s, kUpdateTextures | kUpdateMaterials | kUpdateEnvironment, nullptr);
  RenderSceneBuilder again;
  again.update(s, kUpdateAll, nullptr);
  EXPECT_EQ(d.texels, again.data().texels);
  EXPECT_EQ(d.environmentMap, again.data().environmentMap);
  EXPECT_EQ(d.environmentCdf, again.data().environmentCdf);
}

// A mesh's packed triangles are kept in one place (the arrays of the last update) and copied
// from there when meshes come and go: after adding a mesh and removing the first, every packed
// triangle still holds its mesh's vertices and names its own global index.
TEST(RenderScene, PackedTrianglesSurviveMeshesComingAndGoing) {
  Scene s = test::emptyScene(8, 8);
  const NodeId mat = test::addMaterial(s, Material{});
  const auto rodA = diagonalRod({1, 1, 1}, 300, 1), rodB = diagonalRod({1, -1, 1}, 500, 2);
  const NodeId a = test::addMeshObject(s, "a", rodA, mat, Mat4::identity());
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  auto check = [&](const char* when, std::size_t expected) {
    const RenderSceneData& d = builder.data();
    ASSERT_EQ(d.triangleCount, expected) << when;
    ASSERT_GE(d.meshTraversal.size(), expected * gpu::kTriTexels) << when;
    ASSERT_EQ(d.triangleShading.size(), expected * gpu::kTriShadeTexels) << when;
    // Every packed triangle is one of the scene's, whole, and knows its index.
    std::vector<const MeshGeometry*> meshes;
    for (const Mesh& m : s.meshes) meshes.push_back(m.geometry.get());
    for (std::size_t p = 0; p < expected; ++p) {
      const vec4* t = d.meshTraversal.data() + p * gpu::kTriTexels;
      EXPECT_EQ(std::bit_cast<std::int32_t>(t[0].w), static_cast<std::int32_t>(p)) << when;
      const Vec3 v0{t[0].x, t[0].y, t[0].z}, v1 = v0 + Vec3{t[1].x, t[1].y, t[1].z}, v2 = v0 + Vec3{t[2].x, t[2].y, t[2].z};
      bool found = false;
      for (const MeshGeometry* g : meshes)
        for (std::size_t k = 0; k < g->triangleCount() && !found; ++k)
          found = g->positions[g->indices[k * 3]] == v0 && length(g->positions[g->indices[k * 3 + 1]] - v1) < 1e-5f &&
                  length(g->positions[g->indices[k * 3 + 2]] - v2) < 1e-5f;
      if (!found) {
        ADD_FAILURE() << when << ": packed triangle " << p << " is none of the scene's";
        return;
      }
    }
  };
  check("one mesh", 300);
  test::addMeshObject(s, "b", rodB, mat, Mat4::identity());
  builder.update(s, kUpdateGeometry, nullptr);
  check("a mesh added", 800);
  std::erase_if(s.objects, [&](const Object& o) { return o.id == a; });
  std::erase_if(s.meshes, [&](const Mesh& m) { return m.geometry == rodA; });
  builder.update(s, kUpdateGeometry, nullptr);
  check("the first removed", 500);
}

// A mesh is packed where its first object puts it, and a small mesh shared by objects elsewhere
// is copied for each, so that no instance needs a transform and the kernel carries none; an
// object moved later is reached through its instance's transform from where it was packed.
TEST(RenderScene, MeshesArePackedWhereTheirObjectsPutThem) {
  Scene s = test::emptyScene(8, 8);
  const NodeId mat = test::addMaterial(s, Material{});
  const Mat4 t1 = Mat4::translate({2, 0, -1}) * Mat4::rotateY(0.7f) * Mat4::scale({2, 1, 0.5f});
  const NodeId rod = test::addMeshObject(s, "rod", diagonalRod({1, 1, 1}, 300, 1), mat, t1);
  const auto quad = makeQuad();
  test::addMeshObject(s, "quad", quad, mat, Mat4::translate({0, -1, 0}) * Mat4::scale(Vec3{5}));
  test::addMeshObject(s, "quad again", quad, mat, Mat4::translate({0, 4, 0}) * Mat4::rotateX(kPi));
  Object* moved = s.object(rod);
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  const auto transforms = static_cast<std::uint32_t>(gpu::kFeatureInstanceTransforms);
  auto worldToPacked = [&](NodeId object) {
    const RenderSceneData& d = builder.data();
    for (std::size_t i = 0; i < d.instanceObject.size(); ++i)
      if (d.instanceObject[i] == object) {
        Mat4 m;
        for (int r = 0; r < 3; ++r) {
          const vec4 row = d.instances[i * gpu::kInstanceTexels + static_cast<std::size_t>(r)];
          m.m[r][0] = row.x, m.m[r][1] = row.y, m.m[r][2] = row.z, m.m[r][3] = row.w;
        }
        return m;
      }
    ADD_FAILURE() << "no instance of object " << object;
    return Mat4{};
  };
  EXPECT_EQ(builder.data().features() & transforms, 0u);
  EXPECT_EQ(builder.data().triangleCount, 300u + 2u + 2u) << "the quad copied for its second object";
  for (std::size_t i = 0; i < builder.data().instanceObject.size(); ++i)
    EXPECT_EQ(worldToPacked(builder.data().instanceObject[i]), Mat4::identity());
  // The rod's triangles are packed in world space: its first vertex, placed, is a packed one.
  const MeshGeometry& g = *s.mesh(moved->mesh)->geometry;
  const Vec3 first = t1.transformPoint(g.positions[g.indices[0]]);
  bool found = false;
  for (std::size_t p = 0; p < builder.data().triangleCount && !found; ++p) {
    const vec4* t = builder.data().meshTraversal.data() + p * gpu::kTriTexels;
    found = length(Vec3{t[0].x, t[0].y, t[0].z} - first) < 1e-5f;
  }
  EXPECT_TRUE(found) << "the rod's first vertex, placed, is packed";

  // Moved: its instance maps the world to where the rod was packed.
  const Mat4 t2 = Mat4::translate({-3, 1, 0}) * Mat4::rotateZ(0.3f);
  moved->transform = t2;
  builder.update(s, kUpdateInstances, nullptr);
  EXPECT_NE(builder.data().features() & transforms, 0u);
  const Vec3 v = g.positions[g.indices[4]];
  EXPECT_LT(length(worldToPacked(rod).transformPoint(t2.transformPoint(v)) - t1.transformPoint(v)), 1e-4f);
  // Back where it was packed: no transform again.
  moved->transform = t1;
  builder.update(s, kUpdateInstances, nullptr);
  EXPECT_EQ(builder.data().features() & transforms, 0u);

  // Truly instanced (a copy would add more than 65536 triangles and an eighth): one of each
  // mesh, and transforms.
  const auto big = diagonalRod({-1, 1, 1}, 70000, 3);
  test::addMeshObject(s, "big", big, mat, Mat4::identity());
  test::addMeshObject(s, "big again", big, mat, Mat4::translate({0, 0, 5}));
  builder.update(s, kUpdateGeometry, nullptr);
  EXPECT_EQ(builder.data().triangleCount, 300u + 2u + 70000u);
  EXPECT_NE(builder.data().features() & transforms, 0u);
}

// A mirrored transform is not packed: it would turn the triangles' winding, which says which
// side of an emitter shines.
TEST(RenderScene, AMirroredObjectKeepsItsTransform) {
  Scene s = test::emptyScene(8, 8);
  test::addMeshObject(s, "mirrored", makeQuad(), test::addMaterial(s, Material{}), Mat4::scale({-1, 1, 1}));
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  EXPECT_NE(builder.data().features() & static_cast<std::uint32_t>(gpu::kFeatureInstanceTransforms), 0u);
}

}  // namespace
// The camera's medium comes from the glass or boundary around it: the way out that no way in
// matches, along the packed scene's own rays, whether the instance BVH is packed direct, as
// records, or with transforms; and the medium around that one.
TEST(RenderScene, TheCameraIsInTheMediumAroundIt) {
  Scene s = test::emptyScene(8, 8);
  Material fog;
  fog.type = MaterialType::Boundary;
  fog.interiorAbsorption = Vec3{0.1f, 0.2f, 0.3f};
  Material milk;
  milk.type = MaterialType::Dielectric;
  milk.interiorScattering = Vec3{5.0f};
  milk.interiorAnisotropy = 0.3f;
  Material lens;
  lens.type = MaterialType::Dielectric;
  Material veil;
  veil.type = MaterialType::Boundary;
  test::addMeshObject(s, "fog", makeCube(), test::addMaterial(s, fog), Mat4::scale({10, 10, 10}));
  const NodeId milkObject =
      test::addMeshObject(s, "milk", makeCube(), test::addMaterial(s, milk), Mat4::translate({2, 0, 0}) * Mat4::scale({2, 2, 2}));
  test::addMeshObject(s, "lens", makeCube(), test::addMaterial(s, lens), Mat4::translate({-2, 0, 0}) * Mat4::scale({2, 2, 2}));
  test::addMeshObject(s, "veil", makeCube(), test::addMaterial(s, veil), Mat4::translate({0, 0, 2}) * Mat4::scale({2, 2, 2}));
  const Vec3 fogged{0.1f, 0.2f, 0.3f};
  auto check = [&](const RenderSceneData& d, Vec3 milkAt) {
    EXPECT_EQ(mediaAround(d, {0, 0, 0}).in.absorption, fogged) << "in the fog, past the milk and the lens";
    EXPECT_EQ(mediaAround(d, {0, 0, 0}).around.absorption, Vec3(0.0f));
    EXPECT_EQ(mediaAround(d, {0, 0, 2}).in.absorption, fogged) << "a boundary without a medium changes nothing";
    const MediaAround inMilk = mediaAround(d, milkAt);
    EXPECT_EQ(inMilk.in.scattering, Vec3(5.0f));
    EXPECT_EQ(inMilk.in.absorption, Vec3(0.0f));
    EXPECT_FLOAT_EQ(inMilk.in.anisotropy, 0.3f);
    EXPECT_EQ(inMilk.around.absorption, fogged) << "the milk is in the fog";
    EXPECT_TRUE(inMilk.in.glass);
    EXPECT_FALSE(inMilk.around.glass) << "the fog's is a boundary's";
    EXPECT_EQ(mediaAround(d, {-2, 0, 0}).in.absorption, Vec3(0.0f)) << "empty glass holds a vacuum";
    EXPECT_EQ(mediaAround(d, {-2, 0, 0}).around.absorption, fogged);
    EXPECT_EQ(mediaAround(d, {0, 0, 20}).in.absorption, Vec3(0.0f)) << "outside everything";
  };
  RenderSceneBuilder builder;
  builder.update(s, kUpdateAll, nullptr);
  EXPECT_TRUE(builder.data().directReferences);
  check(builder.data(), {2, 0, 0});
  RenderSceneBuilder records;
  records.setDirectReferences(false);
  records.update(s, kUpdateAll, nullptr);
  check(records.data(), {2, 0, 0});
  s.object(milkObject)->transform = Mat4::translate({2, -1, 0}) * Mat4::rotateY(0.7f) * Mat4::rotateX(0.4f) * Mat4::scale({2, 1, 2});
  builder.update(s, kUpdateInstances, nullptr);
  EXPECT_TRUE(builder.data().instanceTransforms);
  check(builder.data(), {2, -1, 0});

  // With the world filled too, outside every holder is the world's medium, and so is what is
  // around the outermost one.
  const Vec3 haze{0.01f, 0.02f, 0.04f};
  s.environment.mediumAbsorption = haze;
  builder.update(s, kUpdateEnvironment, nullptr);
  EXPECT_EQ(mediaAround(builder.data(), {0, 0, 20}).in.absorption, haze) << "outside everything";
  EXPECT_EQ(mediaAround(builder.data(), {0, 0, 20}).around.absorption, haze);
  EXPECT_EQ(mediaAround(builder.data(), {0, 0, 0}).in.absorption, fogged);
  EXPECT_EQ(mediaAround(builder.data(), {0, 0, 0}).around.absorption, haze) << "the fog is in the haze";
  EXPECT_EQ(mediaAround(builder.data(), {2, -1, 0}).around.absorption, fogged);
  // A world's medium and nothing that holds one: no rays need be cast.
  Scene open = test::emptyScene(8, 8);
  test::addMeshObject(open, "wall", makeCube(), test::addMaterial(open, Material{}), Mat4::identity());
  open.environment.mediumScattering = Vec3{0.5f};
  open.environment.mediumAnisotropy = 0.4f;
  RenderSceneBuilder openBuilder;
  openBuilder.update(open, kUpdateAll, nullptr);
  const MediaAround inOpen = mediaAround(openBuilder.data(), {0, 0, 5});
  EXPECT_EQ(inOpen.in.scattering, Vec3(0.5f));
  EXPECT_FLOAT_EQ(inOpen.in.anisotropy, 0.4f);
  EXPECT_EQ(inOpen.around.scattering, Vec3(0.5f));
  // Nor need the sky be sampled for light through a medium that dims every channel of it.
  open.environment.color = Vec3{1.0f};
  openBuilder.update(open, kUpdateEnvironment, nullptr);
  EXPECT_EQ(openBuilder.data().lightPick[1], 0.0f);
  open.environment.mediumScattering = Vec3{0.5f, 0.5f, 0.0f};
  openBuilder.update(open, kUpdateEnvironment, nullptr);
  EXPECT_GT(openBuilder.data().lightPick[1], 0.0f) << "the third channel sees the sky";
}

// Glass whose medium scatters blocks every shadow ray from inside it to a light outside, so such
// a scene's kernel samples no light there (trace.comp scatterInMedium) unless some light may be
// inside: an emitter or a point light whose bounds meet the glass's, or the glass itself glowing.
TEST(RenderScene, ALightInsideScatteringGlassKeepsItsLightSampling) {
  Scene s = test::emptyScene(8, 8);
  Material milk;
  milk.type = MaterialType::Dielectric;
  milk.interiorScattering = Vec3{6.0f};
  const NodeId milkMaterial = test::addMaterial(s, milk);
  const NodeId glass = test::addMeshObject(s, "milk", makeCube(), milkMaterial, Mat4::scale({2, 2, 2}));
  Material lamp;
  lamp.emission = Vec3{5.0f};
  const NodeId quad = test::addMeshObject(s, "lamp", makeQuad(), test::addMaterial(s, lamp), Mat4::translate({0, 4, 0}));
  RenderSceneBuilder builder;
  auto inside = [&] {
    builder.update(s, kUpdateAll, nullptr);
    return builder.data().lightInScatteringGlass;
  };
  EXPECT_FALSE(inside()) << "the lamp is above the glass";
  s.object(quad)->transform = Mat4::translate({0, 0.5f, 0});
  EXPECT_TRUE(inside()) << "the lamp is in it";
  s.object(quad)->transform = Mat4::translate({0, 4, 0});
  Light bulb;
  bulb.id = s.newId();
  bulb.type = LightType::Point;
  bulb.position = {0.2f, 0.1f, 0};
  s.lights.push_back(bulb);
  EXPECT_TRUE(inside()) << "a point light in it";
  s.lights.back().position = {0, 0, 5};
  EXPECT_FALSE(inside());
  s.material(milkMaterial)->emission = Vec3{1.0f};
  EXPECT_TRUE(inside()) << "glowing glass lights its own inside";
  s.material(milkMaterial)->emission = Vec3{0.0f};
  s.material(milkMaterial)->interiorScattering = Vec3{0.0f};
  s.material(milkMaterial)->interiorAbsorption = Vec3{1.0f};
  s.object(quad)->transform = Mat4::translate({0, 0.5f, 0});
  EXPECT_FALSE(inside()) << "nothing scatters in it: no light is sampled from inside anyway";
  s.material(milkMaterial)->interiorScattering = Vec3{6.0f};
  s.object(quad)->transform = Mat4::translate({0, 4, 0});
  EXPECT_FALSE(inside());
  // Where a path inside can get out other than through the glass, any light may be reached.
  s.material(milkMaterial)->alpha = 0.5f;
  EXPECT_TRUE(inside()) << "cut-out glass";
  s.material(milkMaterial)->alpha = 1;
  s.object(glass)->cullBackFaces = true;
  EXPECT_TRUE(inside()) << "culled glass: shadow rays leave it through its back faces";
  s.object(glass)->cullBackFaces = false;
  const NodeId sea = test::addMeshObject(s, "sea", makeQuad(), milkMaterial, Mat4::translate({0, -10, 0}) * Mat4::scale({100, 1, 100}));
  EXPECT_TRUE(inside()) << "a water surface is open: a lamp above it is reached from below";
  s.object(sea)->visible = false;
  EXPECT_FALSE(inside());
  Material paint, plaster;
  paint.blendWith = test::addMaterial(s, plaster);
  paint.blendRatio = 0.5f;
  const NodeId painted = test::addMaterial(s, paint);
  s.material(paint.blendWith)->blendWith = milkMaterial;
  s.material(paint.blendWith)->blendRatio = 0.5f;
  test::addMeshObject(s, "painted", makeCube(), painted, Mat4::translate({10, 0, 0}));
  EXPECT_TRUE(inside()) << "milk two blends deep in a painted box, which a path leaves through the paint";
  s.material(painted)->blendWith = kNoNode;
  EXPECT_FALSE(inside());
  s.object(glass)->visible = false;
  EXPECT_FALSE(inside());
}

// The volumetric caustic's set-up: gas in a box of plain walls, closed by one boundary quad.
// Rays that meet a wall first cannot tell; those through the quad can. Turned to face into the
// box, the quad holds the gas outside it: then only a transform of its normal done right says so.
TEST(RenderScene, AWallDoesNotTellTheCamerasMediumABoundaryDoes) {
  Scene s = test::emptyScene(8, 8);
  Material gas;
  gas.type = MaterialType::Boundary;
  gas.interiorScattering = Vec3{1.0f};
  const NodeId wall = test::addMaterial(s, Material{});
  // A unit box: five walls of a cube, and the quad across its open +z side facing out.
  const Mat4 walls[5] = {Mat4::translate({0, -0.5f, 0}), Mat4::translate({0, 0.5f, 0}) * Mat4::rotateX(kPi),
                         Mat4::translate({0.5f, 0, 0}) * Mat4::rotateZ(kPi / 2), Mat4::translate({-0.5f, 0, 0}) * Mat4::rotateZ(-kPi / 2),
                         Mat4::translate({0, 0, -0.5f}) * Mat4::rotateX(kPi / 2)};
  for (const Mat4& m : walls) test::addMeshObject(s, "wall", makeQuad(), wall, m);
  const NodeId front =
      test::addMeshObject(s, "front", makeQuad(), test::addMaterial(s, gas), Mat4::translate({0, 0, 0.5f}) * Mat4::rotateX(kPi / 2));
  const Vec3 inside{0.1f, -0.2f, 0.1f}, before{0.2f, 0.1f, 3.0f};
  for (bool direct : {true, false}) {
    RenderSceneBuilder builder;
    builder.setDirectReferences(direct);
    builder.update(s, kUpdateAll, nullptr);
    EXPECT_EQ(mediaAround(builder.data(), inside).in.scattering, Vec3(1.0f)) << "inside the box";
    EXPECT_EQ(mediaAround(builder.data(), before).in.scattering, Vec3(0.0f)) << "before its open side";
    s.object(front)->transform =
        Mat4::translate({0, 0, 0.5f}) * Mat4::rotateY(0.3f) * Mat4::rotateX(-kPi / 2) * Mat4::scale({1.5f, 1, 1.5f});
    builder.update(s, kUpdateInstances, nullptr);
    EXPECT_TRUE(builder.data().instanceTransforms);
    EXPECT_EQ(mediaAround(builder.data(), inside).in.scattering, Vec3(0.0f)) << "facing in, the quad holds the gas outside";
    EXPECT_EQ(mediaAround(builder.data(), before).in.scattering, Vec3(1.0f));
    s.object(front)->transform = Mat4::translate({0, 0, 0.5f}) * Mat4::rotateX(kPi / 2);
  }
}

}  // namespace retile
