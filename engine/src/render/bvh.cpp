#include "render/bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <thread>

#include "retile/error.h"
#include "retile/log.h"

namespace retile {
namespace {

struct BuildNode {
  Bounds3 bounds;
  std::uint32_t start = 0, count = 0;  // leaf range in primOrder
  std::int32_t left = -1, right = -1;  // children in the build array; -1 for leaves
};

// Any float must build (a hostile file's coordinates reach here: NaN, infinities, 1e38): boxes
// are made finite (NaN to 0, infinities to the largest float) and ordered (lo <= hi), centroids
// are computed without overflow, and bins are chosen in double precision with NaN-safe clamping,
// so no float ever indexes out of range or breaks the sort's ordering.
float finite(float v) {
  if (std::isnan(v)) return 0.0f;
  return std::clamp(v, -std::numeric_limits<float>::max(), std::numeric_limits<float>::max());
}

Bounds3 finiteBox(const Bounds3& b) {
  Bounds3 r;
  for (int k = 0; k < 3; ++k) {
    const float a = finite(b.lo[k]), c = finite(b.hi[k]);
    r.lo[k] = std::min(a, c);
    r.hi[k] = std::max(a, c);
  }
  return r;
}

int binOf(float c, double lo, double scale, int bins) {
  const double t = (static_cast<double>(c) - lo) * scale;
  if (!(t > 0.0)) return 0;  // NaN too
  return t >= bins - 1 ? bins - 1 : static_cast<int>(t);
}

struct Builder {
  std::vector<Bounds3> boxes;
  std::vector<Vec3> centroids;
  std::vector<std::uint32_t>& order;
  const BvhBuildOptions& opt;
  std::vector<BuildNode> nodes;
  int maxDepth = 0;

  Builder(std::span<const Bounds3> b, std::vector<std::uint32_t>& o, const BvhBuildOptions& op)
      : order(o), opt(op) {
    boxes.reserve(b.size());
    centroids.resize(b.size());
    for (std::size_t i = 0; i < b.size(); ++i) {
      boxes.push_back(finiteBox(b[i]));
      centroids[i] = boxes[i].lo * 0.5f + boxes[i].hi * 0.5f;  // (lo + hi) / 2 could overflow
    }
  }

  // Returns the split position in [start, start+count) or start when a leaf is best.
  std::uint32_t split(std::uint32_t start, std::uint32_t count, const Bounds3& bounds) {
    Bounds3 cb;
    for (std::uint32_t i = start; i < start + count; ++i) cb.grow(centroids[order[i]]);
    const int nb = opt.bins;
    float bestCost = std::numeric_limits<float>::infinity();
    int bestAxis = -1, bestBin = -1;
    std::array<Bounds3, 64> binBounds;
    std::array<std::uint32_t, 64> binCount;
    std::array<float, 64> rightArea;
    std::array<std::uint32_t, 64> rightCount;
    for (int axis = 0; axis < 3; ++axis) {
      const double lo = cb.lo[axis], hi = cb.hi[axis];
      if (!(hi > lo)) continue;
      const double scale = nb / (hi - lo);
      for (int b = 0; b < nb; ++b) {
        binBounds[static_cast<std::size_t>(b)] = Bounds3{};
        binCount[static_cast<std::size_t>(b)] = 0;
      }
      for (std::uint32_t i = start; i < start + count; ++i) {
        std::uint32_t p = order[i];
        const int b = binOf(centroids[p][axis], lo, scale, nb);
        binBounds[static_cast<std::size_t>(b)].grow(boxes[p]);
        ++binCount[static_cast<std::size_t>(b)];
      }
      Bounds3 acc;
      std::uint32_t n = 0;
      for (int b = nb - 1; b > 0; --b) {
        acc.grow(binBounds[static_cast<std::size_t>(b)]);
        n += binCount[static_cast<std::size_t>(b)];
        rightArea[static_cast<std::size_t>(b)] = acc.area();
        rightCount[static_cast<std::size_t>(b)] = n;
      }
      acc = Bounds3{};
      n = 0;
      for (int b = 0; b < nb - 1; ++b) {
        acc.grow(binBounds[static_cast<std::size_t>(b)]);
        n += binCount[static_cast<std::size_t>(b)];
        std::uint32_t rc = rightCount[static_cast<std::size_t>(b + 1)];
        if (n == 0 || rc == 0) continue;
        float cost = acc.area() * static_cast<float>(n) + rightArea[static_cast<std::size_t>(b + 1)] * static_cast<float>(rc);
        if (cost < bestCost) {
          bestCost = cost;
          bestAxis = axis;
          bestBin = b;
        }
      }
    }
    float parentArea = std::max(bounds.area(), 1e-30f);
    float leafCost = opt.intersectionCost * static_cast<float>(count);
    float splitCost = opt.traversalCost + opt.intersectionCost * bestCost / parentArea;
    bool mustSplit = count > static_cast<std::uint32_t>(opt.maxLeafSize);
    if (bestAxis < 0 || (!mustSplit && splitCost >= leafCost)) {
      if (!mustSplit) return start;
      // All centroids coincide (or SAH found nothing): split the range in the middle.
      return start + count / 2;
    }
    const double lo = cb.lo[bestAxis];
    const double scale = nb / (static_cast<double>(cb.hi[bestAxis]) - lo);
    auto mid = std::partition(order.begin() + start, order.begin() + start + count,
                              [&](std::uint32_t p) { return binOf(centroids[p][bestAxis], lo, scale, nb) <= bestBin; });
    auto m = static_cast<std::uint32_t>(mid - order.begin());
    if (m == start || m == start + count) m = start + count / 2;
    return m;
  }

  static constexpr int kSahDepthLimit = 40;

  std::uint32_t medianSplit(std::uint32_t start, std::uint32_t count) {
    Bounds3 cb;
    for (std::uint32_t i = start; i < start + count; ++i) cb.grow(centroids[order[i]]);
    Vec3 e = cb.extent();
    int axis = e.x > e.y ? (e.x > e.z ? 0 : 2) : (e.y > e.z ? 1 : 2);
    std::uint32_t m = start + count / 2;
    std::nth_element(order.begin() + start, order.begin() + m, order.begin() + start + count,
                     [&](std::uint32_t a, std::uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
    return m;
  }

  void build() {
    nodes.reserve(boxes.size() * 2 / static_cast<std::size_t>(std::max(1, opt.maxLeafSize - 1)) + 1);
    BuildNode root;
    root.start = 0;
    root.count = static_cast<std::uint32_t>(boxes.size());
    for (const Bounds3& b : boxes) root.bounds.grow(b);
    nodes.push_back(root);
    struct Item {
      std::uint32_t node;
      int depth;
    };
    std::vector<Item> stack{{0, 1}};
    while (!stack.empty()) {
      Item it = stack.back();
      stack.pop_back();
      maxDepth = std::max(maxDepth, it.depth);
      BuildNode n = nodes[it.node];
      if (n.count <= 1) continue;
      if (it.depth >= kSahDepthLimit && n.count <= static_cast<std::uint32_t>(opt.maxLeafSize)) continue;
      // Past a depth, SAH may keep peeling off single primitives of adversarial inputs; a median
      // split bounds the rest to log2(count) levels, so the GPU's fixed traversal stack holds.
      std::uint32_t m = it.depth < kSahDepthLimit ? split(n.start, n.count, n.bounds) : medianSplit(n.start, n.count);
      if (m == n.start) continue;  // leaf
      BuildNode l, r;
      l.start = n.start;
      l.count = m - n.start;
      r.start = m;
      r.count = n.start + n.count - m;
      for (std::uint32_t i = l.start; i < l.start + l.count; ++i) l.bounds.grow(boxes[order[i]]);
      for (std::uint32_t i = r.start; i < r.start + r.count; ++i) r.bounds.grow(boxes[order[i]]);
      auto li = static_cast<std::int32_t>(nodes.size());
      nodes.push_back(l);
      nodes.push_back(r);
      nodes[it.node].left = li;
      nodes[it.node].right = li + 1;
      stack.push_back({static_cast<std::uint32_t>(li), it.depth + 1});
      stack.push_back({static_cast<std::uint32_t>(li + 1), it.depth + 1});
    }
  }
};

void setSlot(float mn[3], float mx[3], std::int32_t& index, std::int32_t& count, const Bounds3& b, std::int32_t i,
             std::int32_t c) {
  for (int k = 0; k < 3; ++k) {
    mn[k] = b.lo[k];
    mx[k] = b.hi[k];
  }
  index = i;
  count = c;
}

void setEmpty(float mn[3], float mx[3], std::int32_t& index, std::int32_t& count) {
  // min > max: the slab test never reports a hit.
  for (int k = 0; k < 3; ++k) {
    mn[k] = 1e30f;
    mx[k] = -1e30f;
  }
  index = 0;
  count = -1;
}

}  // namespace

Bvh buildBvh(std::span<const Bounds3> primBounds, const BvhBuildOptions& options) {
  RETILE_ASSERT(options.bins >= 2 && options.bins <= 64, cat("bins = ", options.bins));
  Bvh out;
  out.primOrder.resize(primBounds.size());
  for (std::size_t i = 0; i < primBounds.size(); ++i) out.primOrder[i] = static_cast<std::uint32_t>(i);
  if (primBounds.empty()) {
    GpuBvhNode root{};
    setEmpty(root.lmin, root.lmax, root.left, root.leftCount);
    setEmpty(root.rmin, root.rmax, root.right, root.rightCount);
    out.nodes.push_back(root);
    return out;
  }
  Builder b(primBounds, out.primOrder, options);
  b.build();
  out.bounds = b.nodes[0].bounds;
  out.depth = b.maxDepth;

  // Pack: every inner build node becomes a GPU node; leaves live in their parent's slots. A
  // root that is a leaf gets a GPU node with one empty slot.
  const auto& bn = b.nodes;
  std::vector<std::int32_t> gpuIndex(bn.size(), -1);
  std::vector<std::uint32_t> inner;
  inner.push_back(0);
  gpuIndex[0] = 0;
  for (std::size_t k = 0; k < inner.size(); ++k) {
    const BuildNode& n = bn[inner[k]];
    for (std::int32_t c : {n.left, n.right}) {
      if (c >= 0 && bn[static_cast<std::size_t>(c)].left >= 0) {
        gpuIndex[static_cast<std::size_t>(c)] = static_cast<std::int32_t>(inner.size());
        inner.push_back(static_cast<std::uint32_t>(c));
      }
    }
  }
  out.nodes.resize(inner.size());
  for (std::size_t k = 0; k < inner.size(); ++k) {
    const BuildNode& n = bn[inner[k]];
    GpuBvhNode& g = out.nodes[k];
    if (n.left < 0) {  // the root is a leaf
      setSlot(g.lmin, g.lmax, g.left, g.leftCount, n.bounds, static_cast<std::int32_t>(n.start),
              static_cast<std::int32_t>(n.count));
      setEmpty(g.rmin, g.rmax, g.right, g.rightCount);
      continue;
    }
    auto fill = [&](std::int32_t c, float* mn, float* mx, std::int32_t& idx, std::int32_t& cnt) {
      const BuildNode& ch = bn[static_cast<std::size_t>(c)];
      if (ch.left < 0)
        setSlot(mn, mx, idx, cnt, ch.bounds, static_cast<std::int32_t>(ch.start), static_cast<std::int32_t>(ch.count));
      else
        setSlot(mn, mx, idx, cnt, ch.bounds, gpuIndex[static_cast<std::size_t>(c)], 0);
    };
    fill(n.left, g.lmin, g.lmax, g.left, g.leftCount);
    fill(n.right, g.rmin, g.rmax, g.right, g.rightCount);
  }
  return out;
}

Bounds3 slotBounds(const float* mn, const float* mx) {
  Bounds3 b;
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = mn[k];
    b.hi[k] = mx[k];
  }
  return b;
}

std::vector<float> expectedSteps(const Bvh& bvh, const std::function<float(std::uint32_t)>& primCost) {
  std::vector<float> steps(bvh.nodes.size(), 0.0f);
  for (std::size_t k = bvh.nodes.size(); k-- > 0;) {
    const GpuBvhNode& n = bvh.nodes[k];
    Bounds3 box;
    float weighted = 0;  // sum over slots of area * expected steps inside
    float unweighted = 0;
    auto slot = [&](const float* mn, const float* mx, std::int32_t index, std::int32_t count) {
      if (count < 0) return;
      const Bounds3 b = slotBounds(mn, mx);
      box.grow(b);
      float inside = 0;
      if (count == 0) {
        inside = steps[static_cast<std::size_t>(index)];
      } else {
        for (std::int32_t i = 0; i < count; ++i) inside += primCost(static_cast<std::uint32_t>(index + i));
      }
      weighted += b.area() * inside;
      unweighted += inside;
    };
    slot(n.lmin, n.lmax, n.left, n.leftCount);
    slot(n.rmin, n.rmax, n.right, n.rightCount);
    const float area = box.area();
    // A box without area (a line or a point): every ray that reaches it enters both slots.
    steps[k] = 1.0f + (area > 0 ? weighted / area : unweighted);
  }
  return steps;
}

bool intersectTriangle(Vec3 o, Vec3 d, Vec3 v0, Vec3 v1, Vec3 v2, float tMax, float* t, float* u, float* v) {
  Vec3 e1 = v1 - v0, e2 = v2 - v0;
  Vec3 p = cross(d, e2);
  float det = dot(e1, p);
  if (det == 0.0f) return false;
  float inv = 1.0f / det;
  Vec3 s = o - v0;
  float uu = dot(s, p) * inv;
  if (uu < 0.0f || uu > 1.0f) return false;
  Vec3 q = cross(s, e1);
  float vv = dot(d, q) * inv;
  if (vv < 0.0f || uu + vv > 1.0f) return false;
  float tt = dot(e2, q) * inv;
  if (!(tt > 0.0f && tt < tMax)) return false;
  *t = tt;
  *u = uu;
  *v = vv;
  return true;
}

namespace {
// The box's exit distance is taken this much further (the shader's kSlabSlack): each distance
// is rounded, and for a flat box (a floor) seen from afar, the rounded entry through one pair of
// planes can pass the rounded exit through another by an ulp and lose the hit (Ize, "Robust
// BVH ray traversal", 2013: 1 + 2 gamma(3)).
constexpr float kSlabSlack = 1.0000004f;

bool slab(const float* mn, const float* mx, Vec3 o, Vec3 inv, float tMax, float* tNear) {
  float t0 = 0.0f, t1 = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 3; ++k) {
    float a = (mn[k] - o[k]) * inv[k];
    float b = (mx[k] - o[k]) * inv[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  *tNear = t0;
  return t0 <= std::min(t1 * kSlabSlack, tMax);
}
}  // namespace

RayHit traverseClosest(const Bvh& bvh, std::span<const Vec3> tris, Vec3 o, Vec3 d, float tMax) {
  RayHit hit;
  hit.t = tMax;
  Vec3 inv{1.0f / d.x, 1.0f / d.y, 1.0f / d.z};
  std::int32_t stack[128];
  int sp = 0;
  std::int32_t node = 0;
  for (;;) {
    const GpuBvhNode& n = bvh.nodes[static_cast<std::size_t>(node)];
    float tl, tr;
    bool hl = n.leftCount >= 0 && slab(n.lmin, n.lmax, o, inv, hit.t, &tl);
    bool hr = n.rightCount >= 0 && slab(n.rmin, n.rmax, o, inv, hit.t, &tr);
    auto leaf = [&](std::int32_t start, std::int32_t count) {
      for (std::int32_t i = start; i < start + count; ++i) {
        float t, u, v;
        auto k = static_cast<std::size_t>(i) * 3;
        if (intersectTriangle(o, d, tris[k], tris[k + 1], tris[k + 2], hit.t, &t, &u, &v)) {
          hit.t = t;
          hit.u = u;
          hit.v = v;
          hit.prim = i;
        }
      }
    };
    if (hl && n.leftCount > 0) {
      leaf(n.left, n.leftCount);
      hl = false;
    }
    if (hr && n.rightCount > 0) {
      leaf(n.right, n.rightCount);
      hr = false;
    }
    if (hl && hr) {
      std::int32_t nearN = tl <= tr ? n.left : n.right;
      std::int32_t farN = tl <= tr ? n.right : n.left;
      stack[sp++] = farN;
      node = nearN;
    } else if (hl) {
      node = n.left;
    } else if (hr) {
      node = n.right;
    } else {
      if (sp == 0) break;
      node = stack[--sp];
    }
  }
  return hit;
}

}  // namespace retile
