#include "render/packed_trace.h"

#include <array>
#include <bit>
#include <vector>

#include "render/bvh.h"

namespace retile {

namespace {
std::uint32_t wordOf(float f) { return std::bit_cast<std::uint32_t>(f); }
std::int32_t intOf(float f) { return std::bit_cast<std::int32_t>(f); }

// scene.glsl's kStackSize: a push onto a full stack is dropped there, and here.
constexpr int kStackSize = 128;

Vec3 safeInverse(Vec3 d) {
  auto inv = [](float v) { return std::abs(v) > 1e-12f ? 1.0f / v : (v >= 0.0f ? 1e30f : -1e30f); };
  return {inv(d.x), inv(d.y), inv(d.z)};
}

std::int32_t childItem(std::uint32_t slot, std::uint32_t innerCount, std::uint32_t starts, std::uint32_t innerBase, std::uint32_t leafBase,
                       int leafKind) {
  const bool inner = slot < innerCount;
  const std::uint32_t unit = inner ? innerBase + slot : leafBase + ((starts >> (gpu::kStartBits * slot)) & ((1u << gpu::kStartBits) - 1u));
  return static_cast<std::int32_t>(unit * gpu::kUnitTexels) << gpu::kItemOffsetShift | (inner ? gpu::kItemNode : leafKind);
}
}  // namespace

PackedTrace tracePacked(std::span<const gpu::vec4> mesh, std::span<const gpu::vec4> top, std::int32_t root, bool direct, Vec3 origin,
                        Vec3 direction, float tMax) {
  auto texel = [&](std::int64_t k) -> const gpu::vec4& {
    return k < static_cast<std::int64_t>(mesh.size()) ? mesh[static_cast<std::size_t>(k)]
                                                      : top[static_cast<std::size_t>(k - static_cast<std::int64_t>(mesh.size()))];
  };
  PackedTrace out;
  out.t = tMax;
  const Vec3 worldInv = safeInverse(direction);
  Vec3 o = origin, d = direction, inv = worldInv;
  std::vector<std::int32_t> stack;
  stack.reserve(64);
  std::int32_t item = root, instance = -1, flags = 0;
  int instanceSp = -1;
  for (;;) {
    ++out.steps;
    const std::int64_t at = item >> gpu::kItemOffsetShift;
    const int kind = item & 3;
    const gpu::vec4 r0 = texel(at), r1 = texel(at + 1), r2 = texel(at + 2);
    std::int32_t next = -1;
    if (kind == gpu::kItemNode) {
      const std::uint32_t w0 = wordOf(r0.w);
      const std::array<std::uint32_t, 4> qa{wordOf(r1.x), wordOf(r1.y), wordOf(r1.z), wordOf(r1.w)};
      const std::array<std::uint32_t, 4> qb{wordOf(r2.x), wordOf(r2.y), wordOf(r2.z), wordOf(r2.w)};
      // Per axis: the planes a ray enters and leaves by (lo and hi swap where it goes negative).
      const std::uint32_t lo[3] = {qa[0], qa[1], qa[2]}, hi[3] = {qa[3], qb[0], qb[1]};
      const float originOf[3] = {r0.x, r0.y, r0.z};
      float tNear[4], tFar[4];
      for (int a = 0; a < 3; ++a) {
        const float base = (originOf[a] - o[a]) * inv[a];
        const float scaled = std::bit_cast<float>(((w0 >> (8 * a)) & 255u) << 23) * inv[a];
        const bool negative = inv[a] < 0.0f;
        const std::uint32_t in = negative ? hi[a] : lo[a], outPlanes = negative ? lo[a] : hi[a];
        for (int c = 0; c < 4; ++c) {
          const float tIn = base + static_cast<float>((in >> (8 * c)) & 255u) * scaled;
          const float tOut = base + static_cast<float>((outPlanes >> (8 * c)) & 255u) * scaled;
          if (a == 0) {
            tNear[c] = tIn > 0.0f ? tIn : 0.0f;
            tFar[c] = tOut;
          } else {
            tNear[c] = tIn > tNear[c] ? tIn : tNear[c];
            tFar[c] = tOut < tFar[c] ? tOut : tFar[c];
          }
        }
      }
      const std::uint32_t shape = (w0 >> 24) | ((qb[2] >> (gpu::kBaseBits - 8)) & 0x3f00u) | ((qb[3] >> (gpu::kBaseBits - 14)) & 0xfc000u);
      const std::uint32_t innerCount = (shape >> gpu::kLayoutInner) & 7u, used = (shape >> gpu::kLayoutUsed) & 7u;
      const int leafKind = !direct && (shape & (1u << gpu::kLayoutInstances)) != 0u ? gpu::kItemInstance : gpu::kItemTriangles;
      const std::uint32_t starts = (shape >> (gpu::kLayoutStarts - gpu::kStartBits)) & ~((1u << gpu::kStartBits) - 1u);
      const std::uint32_t baseMask = (1u << gpu::kBaseBits) - 1u;
      const std::uint32_t innerBase = qb[2] & baseMask, leafBase = qb[3] & baseMask;
      bool entered[4];
      for (std::uint32_t c = 0; c < 4; ++c) {
        float far = tFar[c] * kSlabSlack;
        far = far < out.t ? far : out.t;
        entered[c] = tNear[c] <= far && c < used;
      }
      // Ranks, nearest entry first, ties to the later slot (scene.glsl).
      const bool c01 = tNear[1] <= tNear[0], c02 = tNear[2] <= tNear[0], c03 = tNear[3] <= tNear[0];
      const bool c12 = tNear[2] <= tNear[1], c13 = tNear[3] <= tNear[1], c23 = tNear[3] <= tNear[2];
      const std::uint32_t rank[4] = {std::uint32_t{c01} + c02 + c03, std::uint32_t{!c01} + c12 + c13, std::uint32_t{!c02} + !c12 + c23,
                                     std::uint32_t{!c03} + !c13 + !c23};
      std::uint32_t inOrder = 0;
      for (int c = 0; c < 4; ++c) inOrder |= std::uint32_t{entered[c]} << rank[c];
      const std::uint32_t left = inOrder & (15u << static_cast<std::uint32_t>((item >> 2) & 3));
      const std::uint32_t rest = left & (left - 1u);
      auto slotOfRank = [&](std::uint32_t pos) { return rank[0] == pos ? 0u : (rank[1] == pos ? 1u : (rank[2] == pos ? 2u : 3u)); };
      if (left != 0u) {
        const auto pos = static_cast<std::uint32_t>(std::countr_zero(left));
        next = childItem(slotOfRank(pos), innerCount, starts, innerBase, leafBase, leafKind);
        if (rest != 0u && static_cast<int>(stack.size()) < kStackSize) {
          const auto pos2 = static_cast<std::uint32_t>(std::countr_zero(rest));
          stack.push_back((rest & (rest - 1u)) == 0u ? childItem(slotOfRank(pos2), innerCount, starts, innerBase, leafBase, leafKind)
                                                     : (item & ~12) | static_cast<std::int32_t>((pos + 1) << 2));
        }
      }
    } else if (kind == gpu::kItemTriangles) {
      const Vec3 v0{r0.x, r0.y, r0.z}, e1{r1.x, r1.y, r1.z}, e2{r2.x, r2.y, r2.z};
      const Vec3 pv = cross(d, e2);
      const float det = dot(e1, pv);
      const float invDet = 1.0f / det;
      const Vec3 s = o - v0;
      const float u = dot(s, pv) * invDet;
      const Vec3 q = cross(s, e1);
      const float v = dot(d, q) * invDet;
      const float t = dot(e2, q) * invDet;
      // An object hit from the front only is passed from behind (det < 0), as in the kernel.
      const bool culls = direct ? (intOf(r2.w) & gpu::kTriCullBack) != 0 : (flags & gpu::kInstanceCullBack) != 0;
      if (det != 0.0f && u >= 0.0f && v >= 0.0f && u + v <= 1.0f && t > 0.0f && t < out.t && !(culls && det < 0.0f)) {
        out.t = t;
        out.prim = intOf(r0.w);
        out.instance = direct ? (intOf(r2.w) & gpu::kTriInstanceMask) : instance;
      }
      if (r1.w == 0.0f) next = item + (gpu::kTriTexels << gpu::kItemOffsetShift);
    } else if (!direct) {
      // Enter an instance: rows r1..r3 map world space to it (identity rows map exactly).
      const gpu::vec4 r3 = texel(at + 3);
      instance = intOf(r0.y);
      flags = intOf(r0.z);
      auto row = [](const gpu::vec4& r, Vec3 p, float w) { return r.x * p.x + r.y * p.y + r.z * p.z + r.w * w; };
      o = {row(r1, origin, 1), row(r2, origin, 1), row(r3, origin, 1)};
      d = {row(r1, direction, 0), row(r2, direction, 0), row(r3, direction, 0)};
      inv = safeInverse(d);
      instanceSp = static_cast<int>(stack.size());
      next = intOf(r0.x);
    }
    bool finished = false;
    if (next < 0) {
      finished = stack.empty();
      if (!finished) {
        next = stack.back();
        stack.pop_back();
      }
    }
    if (static_cast<int>(stack.size()) < instanceSp || finished) {
      o = origin;
      d = direction;
      inv = worldInv;
      instance = -1;
      flags = 0;
      instanceSp = -1;
    }
    if (finished) return out;
    item = next;
  }
}

}  // namespace retile
