// Bounding volume hierarchies on the CPU, packed for the GPU. Pure computation: no Vulkan, any
// thread, testable without a device.
//
// The hierarchy is four-wide: a binary SAH build, down to single primitives, collapsed so that
// each node holds up to four children, where which children and which leaves are chosen for the
// fewest expected traversal steps. On lavapipe every loop iteration of the traversal pays for the whole loop body
// (shaders/common/scene.glsl), so what counts is the number of steps a ray takes; a four-wide node
// decides among four children in one step, and its child boxes, quantised to 8 bits per plane
// relative to the node's box, keep a node in 48 bytes, less than a binary node took. A node names its children by two bases only
// (layouts.h), which buildBvh's order makes possible.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "retile/math.h"

namespace retile {

constexpr int kBvhWidth = 4;
constexpr int kMaxLeafSize = 4;  // the default: a mesh leaf's triangles

// A node as built. Slot c: count[c] > 0 is a leaf of count[c] primitives starting at index[c] (in
// the packed primitive order); count[c] == 0 an inner node at index[c]; count[c] < 0 an empty
// slot. Inner children come first, then leaves, then empty slots. A node's inner children are
// consecutive nodes and its leaves' primitives consecutive runs, each in slot order, so that the
// GPU's node needs only where the first of each starts.
struct BvhNode {
  std::array<Bounds3, kBvhWidth> box;
  std::array<std::int32_t, kBvhWidth> index{};
  std::array<std::int32_t, kBvhWidth> count{-1, -1, -1, -1};
};

// A node's child boxes as the GPU reads them: per axis, a float origin and a power-of-two
// scale, and for each child an 8-bit lower and upper plane (child c in bits 8c..8c+7 of lo[axis]
// and hi[axis]). Every child's box contains the box it was made from (origin + q * scale, in
// float arithmetic, rounds outwards).
struct QuantizedNode {
  float origin[3];
  std::uint32_t exponents;  // biased exponent of axis k's scale in bits 8k..8k+7
  std::uint32_t lo[3];
  std::uint32_t hi[3];
};
QuantizedNode quantize(const BvhNode& node);
// A quantised box's exit distance is taken this much further, for rays from afar, where the
// rounding of the distances themselves exceeds the pad its planes keep (the shader's kSlabSlack).
constexpr float kSlabSlack = 1.0000004f;
float quantizedScale(const QuantizedNode& q, int axis);
Bounds3 dequantize(const QuantizedNode& q, int child);

struct BvhBuildOptions {
  int maxLeafSize = kMaxLeafSize;  // leaves never hold more
  int bins = 16;                   // SAH bins per axis
  // The traversal steps of input primitive i (a leaf's cost is its primitives'); one when unset.
  std::function<float(std::uint32_t)> primCost;
};

struct Bvh {
  std::vector<BvhNode> nodes;            // nodes[0] is the root; children after their parent
  std::vector<std::uint32_t> primOrder;  // packed primitive i is input primitive primOrder[i]
  Bounds3 bounds;
  int depth = 0;
};

// Builds with binned SAH over the given primitive boxes, then collapses to four-wide nodes (for
// the fewest expected steps, as expectedSteps counts them, with options.primCost for leaves). An
// empty input yields a single root with empty slots, so traversal code needs no special case.
// depth counts the levels of four-wide nodes.
Bvh buildBvh(std::span<const Bounds3> primBounds, const BvhBuildOptions& options = {});

// Expected traversal steps of a ray that enters each node's box (index as in bvh.nodes), by the
// surface area heuristic, as the shader traverses: a node takes a step for each child the ray
// enters after the second (and at least one), a leaf's primitives primCost(packed index) each;
// every loop iteration does one step of any kind.
std::vector<float> expectedSteps(const Bvh& bvh, const std::function<float(std::uint32_t)>& primCost);

// Reference traversal of a packed triangle BVH, mirroring the shader (quantised boxes, children
// nearest entry first, one stack entry pushed per visit), for tests.
struct RayHit {
  float t = 0;
  float u = 0, v = 0;
  std::int32_t prim = -1;  // packed primitive index
};
// triangles: three vertices per packed primitive, in packed order.
RayHit traverseClosest(const Bvh& bvh, std::span<const Vec3> triangles, Vec3 origin, Vec3 direction, float tMax);
bool intersectTriangle(Vec3 o, Vec3 d, Vec3 v0, Vec3 v1, Vec3 v2, float tMax, float* t, float* u, float* v);

}  // namespace retile
