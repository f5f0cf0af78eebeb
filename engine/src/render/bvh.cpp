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

  Builder(std::span<const Bounds3> b, std::vector<std::uint32_t>& o, const BvhBuildOptions& op) : order(o), opt(op) {
    boxes.reserve(b.size());
    centroids.resize(b.size());
    for (std::size_t i = 0; i < b.size(); ++i) {
      boxes.push_back(finiteBox(b[i]));
      centroids[i] = boxes[i].lo * 0.5f + boxes[i].hi * 0.5f;  // (lo + hi) / 2 could overflow
    }
  }

  // Returns the split position in (start, start+count).
  std::uint32_t split(std::uint32_t start, std::uint32_t count) {
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
    // All centroids coincide (or SAH found nothing): split the range in the middle.
    if (bestAxis < 0) return start + count / 2;
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
    nodes.reserve(boxes.size() * 2);
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
      BuildNode n = nodes[it.node];
      // Down to single primitives: which subtrees become leaves is the collapse's choice.
      if (n.count <= 1) continue;
      if (it.depth >= kSahDepthLimit && n.count <= static_cast<std::uint32_t>(opt.maxLeafSize)) continue;
      // Past a depth, SAH may keep peeling off single primitives of adversarial inputs; a median
      // split bounds the rest to log2(count) levels, so the GPU's fixed traversal stack holds.
      std::uint32_t m = it.depth < kSahDepthLimit ? split(n.start, n.count) : medianSplit(n.start, n.count);
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

// Room every quantised plane keeps from the plane it bounds, as a fraction of the node's extent:
// the shader computes a plane's distance as (origin - o) / d + q * scale / d, whose rounding
// differs from that of the exact box's slab test by a few ulps of the node's size.
constexpr float kQuantisedPad = 1.0f / (1 << 20);

// A plane of the grid, in the float arithmetic of dequantize (q * scale is exact: q < 2^8 and
// scale a power of two).
float gridPlane(float origin, std::uint32_t q, float scale) { return origin + static_cast<float>(q) * scale; }

// The pieces of cut `id` of binary node n's subtree (see collapseCosts), in `out`; their count, 0
// where the cut does not exist (a node it opens is a leaf). Cut 0 is n's two children; 1 to 7
// open one or two of those further.
std::size_t cutPieces(const std::vector<BuildNode>& bn, std::int32_t n, std::uint8_t id, std::array<std::int32_t, kBvhWidth>& out) {
  std::size_t count = 0;
  bool exists = true;
  auto put = [&](std::int32_t i) { out[count++] = i; };
  // Opens node i: its two children, or a failed cut when it is a leaf.
  auto open = [&](std::int32_t i, auto&& then) {
    const BuildNode& b = bn[static_cast<std::size_t>(i)];
    if (b.left < 0) exists = false;
    else then(b.left, b.right);
  };
  open(n, [&](std::int32_t l, std::int32_t r) {
    auto both = [&](std::int32_t a, std::int32_t b) { put(a), put(b); };
    switch (id) {
      case 0: put(l), put(r); break;
      case 1: open(l, both), put(r); break;
      case 2: put(l), open(r, both); break;
      case 3: open(l, both), open(r, both); break;
      case 4: open(l, [&](std::int32_t a, std::int32_t b) { open(a, both), put(b); }), put(r); break;
      case 5: open(l, [&](std::int32_t a, std::int32_t b) { put(a), open(b, both); }), put(r); break;
      case 6: put(l), open(r, [&](std::int32_t a, std::int32_t b) { open(a, both), put(b); }); break;
      default: put(l), open(r, [&](std::int32_t a, std::int32_t b) { put(a), open(b, both); }); break;
    }
  });
  return exists ? count : 0;
}

// Per binary node: the cut its four-wide node takes, and whether it is a leaf where it is a piece.
struct Collapse {
  std::vector<std::uint8_t> cut;
  std::vector<std::uint8_t> leaf;
};

// Visits of a four-wide node by a ray that enters it, as the shader takes them: one, and one more
// for each child entered past the second (max(1, e - 1) for e entered). Children are taken as
// entered independently, each with the chance of its area over the node's.
float expectedVisits(const std::array<float, kBvhWidth>& p, std::size_t count) {
  // The distribution of the number entered (Poisson binomial), up to four.
  std::array<float, kBvhWidth + 1> dist{1.0f, 0, 0, 0, 0};
  for (std::size_t c = 0; c < count; ++c)
    for (std::size_t k = c + 1; k-- > 0;) dist[k + 1] += dist[k] * p[c], dist[k] *= 1.0f - p[c];
  return 1.0f + dist[3] + 2.0f * dist[4];
}

// The least expected steps of each binary subtree, bottom up (children come after their parents
// in the build array), as area times steps: a piece is a leaf of its primitives (when it has no
// more than a leaf may hold), one step each, or a four-wide node of its best cut. Cuts are the
// eight ways to split a node into two to four pieces; the best over them is exact for this model
// (a node's cost depends on its pieces' costs alone), where opening the largest child was greedy.
Collapse collapseCosts(const std::vector<BuildNode>& bn, std::span<const std::uint32_t> order, const BvhBuildOptions& opt) {
  // The steps of the primitives before each position of the build's order.
  std::vector<float> before(order.size() + 1, 0.0f);
  for (std::size_t i = 0; i < order.size(); ++i) before[i + 1] = before[i] + (opt.primCost ? opt.primCost(order[i]) : 1.0f);
  Collapse plan;
  plan.cut.assign(bn.size(), 0);
  plan.leaf.assign(bn.size(), 0);
  std::vector<float> piece(bn.size(), 0.0f);
  for (std::size_t k = bn.size(); k-- > 0;) {
    const BuildNode& n = bn[k];
    const float area = n.bounds.area();
    const float asLeaf = (before[n.start + n.count] - before[n.start]) * area;
    const bool mayLeaf = n.left < 0 || n.count <= static_cast<std::uint32_t>(opt.maxLeafSize);
    if (n.left < 0) {
      piece[k] = asLeaf;
      plan.leaf[k] = 1;
      continue;
    }
    float best = std::numeric_limits<float>::infinity();
    for (std::uint8_t id = 0; id < 8; ++id) {
      std::array<std::int32_t, kBvhWidth> kids{};
      const std::size_t count = cutPieces(bn, static_cast<std::int32_t>(k), id, kids);
      if (count == 0) continue;
      std::array<float, kBvhWidth> p{};
      float inside = 0;
      for (std::size_t c = 0; c < count; ++c) {
        const auto kid = static_cast<std::size_t>(kids[c]);
        p[c] = area > 0 ? std::min(bn[kid].bounds.area() / area, 1.0f) : 1.0f;
        inside += piece[kid];
      }
      const float cost = area * expectedVisits(p, count) + inside;
      if (cost < best) {
        best = cost;
        plan.cut[k] = id;
      }
    }
    piece[k] = best;
    if (mayLeaf && asLeaf <= best) {
      piece[k] = asLeaf;
      plan.leaf[k] = 1;
    }
  }
  return plan;
}

}  // namespace

Bvh buildBvh(std::span<const Bounds3> primBounds, const BvhBuildOptions& options) {
  RETILE_ASSERT(options.bins >= 2 && options.bins <= 64, cat("bins = ", options.bins));
  Bvh out;
  out.primOrder.resize(primBounds.size());
  for (std::size_t i = 0; i < primBounds.size(); ++i) out.primOrder[i] = static_cast<std::uint32_t>(i);
  if (primBounds.empty()) {
    out.nodes.emplace_back();
    return out;
  }
  Builder b(primBounds, out.primOrder, options);
  b.build();
  out.bounds = b.nodes[0].bounds;

  // Collapse to four-wide nodes, choosing each node's children (a cut of its binary subtree, at
  // most four pieces) and which pieces become leaves, so that the expected steps of a ray
  // entering the root are least (collapseCosts). Breadth first, so children follow their parents.
  const auto& bn = b.nodes;
  const Collapse plan = collapseCosts(bn, out.primOrder, options);
  std::vector<std::uint32_t> behind{0};  // the binary node each four-wide node stands for
  std::vector<int> level{1};
  for (std::size_t k = 0; k < behind.size(); ++k) {
    std::array<std::int32_t, kBvhWidth> kids{};
    std::size_t count = 0;
    if (k == 0 && plan.leaf[0]) kids[count++] = 0;  // the root is a leaf
    else count = cutPieces(bn, static_cast<std::int32_t>(behind[k]), plan.cut[behind[k]], kids);
    auto isLeaf = [&](std::int32_t kid) { return plan.leaf[static_cast<std::size_t>(kid)] != 0; };
    // Inner children first, then leaves (render/bvh.h BvhNode).
    std::stable_partition(kids.begin(), kids.begin() + static_cast<std::ptrdiff_t>(count), [&](std::int32_t kid) { return !isLeaf(kid); });
    BvhNode w;
    for (std::size_t c = 0; c < count; ++c) {
      const BuildNode& ch = bn[static_cast<std::size_t>(kids[c])];
      w.box[c] = ch.bounds;
      if (isLeaf(kids[c])) {
        w.index[c] = static_cast<std::int32_t>(ch.start);
        w.count[c] = static_cast<std::int32_t>(ch.count);
      } else {
        w.index[c] = static_cast<std::int32_t>(behind.size());
        w.count[c] = 0;
        behind.push_back(static_cast<std::uint32_t>(kids[c]));
        level.push_back(level[k] + 1);
        out.depth = std::max(out.depth, level[k] + 1);
      }
    }
    out.nodes.push_back(w);
  }
  out.depth = std::max(out.depth, 1);

  // Breadth first, a node's inner children are consecutive already; its leaves' runs are made so
  // by renumbering the primitives node by node, each node's leaves in slot order.
  std::vector<std::uint32_t> order;
  order.reserve(out.primOrder.size());
  for (BvhNode& n : out.nodes) {
    for (std::size_t c = 0; c < kBvhWidth; ++c) {
      if (n.count[c] <= 0) continue;
      const auto first = static_cast<std::size_t>(n.index[c]);
      n.index[c] = static_cast<std::int32_t>(order.size());
      order.insert(order.end(), out.primOrder.begin() + static_cast<std::ptrdiff_t>(first),
                   out.primOrder.begin() + static_cast<std::ptrdiff_t>(first + static_cast<std::size_t>(n.count[c])));
    }
  }
  RETILE_ASSERT(order.size() == out.primOrder.size(), "a primitive in no leaf, or in two");
  out.primOrder = std::move(order);
  return out;
}

QuantizedNode quantize(const BvhNode& node) {
  QuantizedNode q{};
  Bounds3 all;
  for (int c = 0; c < kBvhWidth; ++c)
    if (node.count[static_cast<std::size_t>(c)] >= 0) all.grow(node.box[static_cast<std::size_t>(c)]);
  if (all.empty()) all = Bounds3{Vec3{0.0f}, Vec3{0.0f}};
  for (int a = 0; a < 3; ++a) {
    const double extent = static_cast<double>(all.hi[a]) - all.lo[a];
    const auto pad = static_cast<float>(extent * kQuantisedPad);
    // The grid starts a pad below the lowest plane; the smallest power of two whose 255 steps
    // reach a pad above the highest is the scale.
    const float origin = all.lo[a] - pad;
    const float top = all.hi[a] + pad;
    int e = -126;
    const double need = (static_cast<double>(top) - origin) / 255.0;
    if (need > 0) e = std::clamp(static_cast<int>(std::ceil(std::log2(need))), -126, 127);
    while (e < 127 && gridPlane(origin, 255, std::ldexp(1.0f, e)) < top) ++e;
    const float scale = std::ldexp(1.0f, e);
    q.origin[a] = origin;
    q.exponents |= static_cast<std::uint32_t>(e + 127) << (8 * a);
    for (int c = 0; c < kBvhWidth; ++c) {
      const auto k = static_cast<std::size_t>(c);
      std::uint32_t lo = 255, hi = 0;  // an empty slot: inside out, so no ray enters it
      if (node.count[k] >= 0) {
        const float want = node.box[k].lo[a] - pad, wantHi = node.box[k].hi[a] + pad;
        lo = static_cast<std::uint32_t>(std::clamp(std::floor((static_cast<double>(want) - origin) / scale), 0.0, 255.0));
        while (lo > 0 && gridPlane(origin, lo, scale) > want) --lo;
        hi = static_cast<std::uint32_t>(std::clamp(std::ceil((static_cast<double>(wantHi) - origin) / scale), 0.0, 255.0));
        while (hi < 255 && gridPlane(origin, hi, scale) < wantHi) ++hi;
      }
      q.lo[a] |= lo << (8 * c);
      q.hi[a] |= hi << (8 * c);
    }
  }
  return q;
}

float quantizedScale(const QuantizedNode& q, int axis) {
  return std::ldexp(1.0f, static_cast<int>((q.exponents >> (8 * axis)) & 255u) - 127);
}

Bounds3 dequantize(const QuantizedNode& q, int child) {
  Bounds3 b;
  for (int a = 0; a < 3; ++a) {
    const float s = quantizedScale(q, a);
    b.lo[a] = gridPlane(q.origin[a], (q.lo[a] >> (8 * child)) & 255u, s);
    b.hi[a] = gridPlane(q.origin[a], (q.hi[a] >> (8 * child)) & 255u, s);
  }
  return b;
}

std::vector<float> expectedSteps(const Bvh& bvh, const std::function<float(std::uint32_t)>& primCost) {
  std::vector<float> steps(bvh.nodes.size(), 0.0f);
  for (std::size_t k = bvh.nodes.size(); k-- > 0;) {
    const BvhNode& n = bvh.nodes[k];
    Bounds3 box;
    for (std::size_t c = 0; c < kBvhWidth; ++c)
      if (n.count[c] >= 0) box.grow(n.box[c]);
    const float area = box.area();
    float inside = 0;  // expected steps inside the children entered
    std::array<float, kBvhWidth> p{};
    std::size_t used = 0;
    for (std::size_t c = 0; c < kBvhWidth; ++c) {
      if (n.count[c] < 0) continue;
      // A box without area (a line or a point): every ray that reaches it enters every child.
      const float chance = area > 0 ? std::min(n.box[c].area() / area, 1.0f) : 1.0f;
      p[used++] = chance;
      float cost = 0;
      if (n.count[c] == 0) {
        cost = steps[static_cast<std::size_t>(n.index[c])];
      } else {
        for (std::int32_t i = 0; i < n.count[c]; ++i) cost += primCost(static_cast<std::uint32_t>(n.index[c] + i));
      }
      inside += chance * cost;
    }
    steps[k] = expectedVisits(p, used) + inside;
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
// The shader's test of a node's four child boxes (shaders/common/scene.glsl), operation for
// operation: which children the ray enters before tMax (bit c for slot c), and where it enters
// each (never NaN: a distance only replaces a smaller one).
int enteredChildren(const BvhNode& n, const QuantizedNode& q, Vec3 o, Vec3 inv, float tMax, float (&near)[kBvhWidth]) {
  float hi[kBvhWidth];
  for (int c = 0; c < kBvhWidth; ++c) {
    near[c] = 0.0f;
    hi[c] = std::numeric_limits<float>::infinity();
  }
  for (int a = 0; a < 3; ++a) {
    const float base = (q.origin[a] - o[a]) * inv[a];
    const float step = quantizedScale(q, a) * inv[a];
    for (int c = 0; c < kBvhWidth; ++c) {
      float t0 = base + static_cast<float>((q.lo[a] >> (8 * c)) & 255u) * step;
      float t1 = base + static_cast<float>((q.hi[a] >> (8 * c)) & 255u) * step;
      if (inv[a] < 0.0f) std::swap(t0, t1);
      near[c] = t0 > near[c] ? t0 : near[c];
      hi[c] = t1 < hi[c] ? t1 : hi[c];
    }
  }
  int mask = 0;
  for (int c = 0; c < kBvhWidth; ++c) {
    const float far = hi[c] * kSlabSlack;
    if (near[c] <= (far < tMax ? far : tMax) && n.count[static_cast<std::size_t>(c)] >= 0) mask |= 1 << c;
  }
  return mask;
}

std::array<int, kBvhWidth> childRanks(const float (&near)[kBvhWidth]) {
  // Nearer first, ties in reverse slot order: a strict total order, as the keys are never NaN.
  std::array<int, kBvhWidth> rank{};
  for (int i = 0; i < kBvhWidth; ++i)
    for (int j = i + 1; j < kBvhWidth; ++j) {
      if (near[j] <= near[i]) ++rank[static_cast<std::size_t>(i)];
      else ++rank[static_cast<std::size_t>(j)];
    }
  return rank;
}
}  // namespace

RayHit traverseClosest(const Bvh& bvh, std::span<const Vec3> tris, Vec3 o, Vec3 d, float tMax) {
  RayHit hit;
  hit.t = tMax;
  Vec3 inv{1.0f / d.x, 1.0f / d.y, 1.0f / d.z};
  // What the shader's items name: a node to visit from a position of its order on (count 0), or
  // a leaf of `count` primitives.
  struct Entry {
    std::int32_t index;
    std::int32_t count;
    int from;
  };
  Entry stack[128];
  int sp = 0;
  Entry at{0, 0, 0};
  for (;;) {
    if (at.count > 0) {
      for (std::int32_t i = at.index; i < at.index + at.count; ++i) {
        float t, u, v;
        auto p = static_cast<std::size_t>(i) * 3;
        if (intersectTriangle(o, d, tris[p], tris[p + 1], tris[p + 2], hit.t, &t, &u, &v)) {
          hit.t = t;
          hit.u = u;
          hit.v = v;
          hit.prim = i;
        }
      }
    } else {
      const BvhNode& n = bvh.nodes[static_cast<std::size_t>(at.index)];
      const QuantizedNode q = quantize(n);
      float near[kBvhWidth];
      const int mask = enteredChildren(n, q, o, inv, hit.t, near);
      // The children entered, nearest first, from position at.from of that order on.
      const std::array<int, kBvhWidth> rank = childRanks(near);
      int slotAt[kBvhWidth];
      for (int c = 0; c < kBvhWidth; ++c) slotAt[rank[static_cast<std::size_t>(c)]] = c;
      int open[kBvhWidth], opened = 0, first = -1;
      for (int i = at.from; i < kBvhWidth; ++i) {
        const int slot = slotAt[i];
        if (!(mask >> slot & 1)) continue;
        if (first < 0) first = i;
        open[opened++] = slot;
      }
      auto child = [&](int slot) {
        const auto k = static_cast<std::size_t>(slot);
        return Entry{n.index[k], n.count[k], 0};
      };
      if (opened > 0) {
        // Pushed: the one child left as it is, or this node, to go on after the first.
        if (opened == 2) stack[sp++] = child(open[1]);
        if (opened > 2) stack[sp++] = {at.index, 0, first + 1};
        at = child(open[0]);
        continue;
      }
    }
    if (sp == 0) break;
    at = stack[--sp];
  }
  return hit;
}

}  // namespace retile
