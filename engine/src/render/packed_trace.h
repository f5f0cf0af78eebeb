// The shader's traversal (shaders/common/scene.glsl traceStep) on the CPU, over the packed
// traversal buffer: the same items, node layout, child order and stack, step for step, so that it
// counts the loop iterations a ray costs the kernel. The render scene uses it to choose how far
// the instance BVH opens its instances (render_scene.cpp packInstances), by the steps of sample
// rays rather than by the surface area heuristic alone; the tests use it to check a packing
// without a device. Pure computation: any thread.
#pragma once

#include <cstdint>
#include <span>

#include "retile/math.h"
#include "shared/layouts.h"

namespace retile {

// A ray's closest hit and the traversal steps it took. No cut-out test: a cut-out counts as
// solid, which changes a count only where a ray would have gone through one. Back faces of an
// object hit from the front only are passed, as in the kernel.
struct PackedTrace {
  float t = 0;
  std::int32_t prim = -1;      // packed triangle index (its texel is 3 * prim), -1: a miss
  std::int32_t instance = -1;  // the instance entered, or with `direct` the one the triangle names
  std::uint32_t steps = 0;     // loop iterations, as the kernel counts them
};

// The buffer is `mesh` followed by `top` (RenderSceneData::meshTraversal and topTraversal);
// `root` is the instance BVH's root item. direct: packed with kFeatureDirectReferences.
PackedTrace tracePacked(std::span<const gpu::vec4> mesh, std::span<const gpu::vec4> top, std::int32_t root, bool direct, Vec3 origin,
                        Vec3 direction, float tMax);

}  // namespace retile
