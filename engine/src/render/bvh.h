// Bounding volume hierarchies on the CPU, packed for the GPU. Pure computation: no Vulkan, any
// thread, testable without a device.
//
// Node layout of the builder's output (64 bytes): each node stores the boxes of both children,
// so one visit decides which children a ray enters and in which order.
//   lmin left | lmax leftCount | rmin right | rmax rightCount
// count > 0: a leaf of `count` primitives starting at `index` (in the packed primitive order);
// count == 0: an inner node at `index`; count < 0: an empty slot (its box never hits).
// render/render_scene.cpp packs these nodes into the traversal buffer the shader reads, with the
// children as items (shaders/shared/layouts.h).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "retile/math.h"

namespace retile {

struct GpuBvhNode {
  float lmin[3];
  std::int32_t left;
  float lmax[3];
  std::int32_t leftCount;
  float rmin[3];
  std::int32_t right;
  float rmax[3];
  std::int32_t rightCount;
};
static_assert(sizeof(GpuBvhNode) == 64);

struct BvhBuildOptions {
  int maxLeafSize = 4;     // leaves never hold more (forced splits beyond it)
  int bins = 16;           // SAH bins per axis
  float traversalCost = 1.0f;
  float intersectionCost = 1.0f;
};

struct Bvh {
  std::vector<GpuBvhNode> nodes;        // nodes[0] is the root
  std::vector<std::uint32_t> primOrder; // packed primitive i is input primitive primOrder[i]
  Bounds3 bounds;
  int depth = 0;
};

// Builds with binned SAH over the given primitive boxes. An empty input yields a single root
// with two empty slots, so traversal code needs no special case.
Bvh buildBvh(std::span<const Bounds3> primBounds, const BvhBuildOptions& options = {});

// The box of a node's slot (lmin/lmax or rmin/rmax), the inverse of how the builder fills it.
Bounds3 slotBounds(const float* mn, const float* mx);

// Expected traversal steps of a ray that enters each node's box (index as in bvh.nodes), by the
// surface area heuristic: a node visit costs one step and a leaf's primitives primCost(packed
// index) each, as in the shader, where every loop iteration does one step of any kind.
// Children's indices exceed their parent's (the builder packs breadth-first).
std::vector<float> expectedSteps(const Bvh& bvh, const std::function<float(std::uint32_t)>& primCost);

// Reference traversal of a packed triangle BVH, mirroring the shader, for tests.
struct RayHit {
  float t = 0;
  float u = 0, v = 0;
  std::int32_t prim = -1;  // packed primitive index
};
// triangles: three vertices per packed primitive, in packed order.
RayHit traverseClosest(const Bvh& bvh, std::span<const Vec3> triangles, Vec3 origin, Vec3 direction, float tMax);
bool intersectTriangle(Vec3 o, Vec3 d, Vec3 v0, Vec3 v1, Vec3 v2, float tMax, float* t, float* u, float* v);

}  // namespace retile
