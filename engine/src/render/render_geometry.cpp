#include "render/render_scene.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numeric>
#include <functional>
#include <iterator>
#include <map>
#include <optional>
#include <unordered_set>

#include "core/files.h"
#include "render/packed_trace.h"
#include "io/image_io.h"
#include "retile/color.h"
#include "retile/error.h"
#include "retile/log.h"
#include "render/pack_util.h"

namespace retile {

using namespace pack;

namespace {

// The item naming the record of `kind` at texel `offset` of the traversal buffer (layouts.h).
std::int32_t traversalItem(std::int64_t offset, int kind) {
  if (offset + 4 > gpu::kMaxTraversalTexels)
    throw Error(cat("the scene's triangles and BVHs need more than ", gpu::kMaxTraversalTexels / 1048576,
                    " M texels (about 35 M triangles), more than the renderer's one traversal buffer holds"));
  return static_cast<std::int32_t>((offset << gpu::kItemOffsetShift) | kind);
}

// The unit (layouts.h kUnitTexels) at texel `offset` of the traversal buffer, as a node's base.
std::uint32_t traversalUnit(std::int64_t offset) {
  RETILE_ASSERT(offset % gpu::kUnitTexels == 0, cat("texel ", offset, " is not at a unit"));
  traversalItem(offset, gpu::kItemNode);  // the same limit
  static_assert(gpu::kMaxTraversalTexels / gpu::kUnitTexels < (1 << gpu::kBaseBits));
  return static_cast<std::uint32_t>(offset / gpu::kUnitTexels);
}

// Appends a node's three texels (layouts.h): n's boxes, quantised, its slots' layout (innerCount
// inner children, `used` slots, leaves of instance records or of triangles, where slots 1..3's
// leaves start) and its two bases, the leaves' `leafUnits` units from leafUnit on.
void pushNode(std::vector<vec4>& out, const BvhNode& n, std::uint32_t innerCount, std::uint32_t used, bool instances, std::uint32_t starts,
              std::uint32_t innerUnit, std::uint32_t leafUnit, std::int32_t leafUnits) {
  if (leafUnits > 0) traversalUnit(gpu::kUnitTexels * (std::int64_t{leafUnit} + leafUnits - 1));  // the last within the limit too
  auto word = [](std::uint32_t u) { return std::bit_cast<float>(u); };
  const QuantizedNode q = quantize(n);
  const std::uint32_t layout = innerCount << gpu::kLayoutInner | used << gpu::kLayoutUsed | (instances ? 1u : 0u) << gpu::kLayoutInstances |
                               starts << gpu::kLayoutStarts;
  out.push_back({q.origin[0], q.origin[1], q.origin[2], word(q.exponents | (layout & 255u) << 24)});
  out.push_back({word(q.lo[0]), word(q.lo[1]), word(q.lo[2]), word(q.hi[0])});
  out.push_back({word(q.hi[1]), word(q.hi[2]), word(innerUnit | (layout >> 8 & 63u) << gpu::kBaseBits),
                 word(leafUnit | (layout >> 14) << gpu::kBaseBits)});
}

// Appends `nodes` (render/bvh.h, child indices local to them) to `out`, a part of the traversal
// buffer that starts at its texel `outBase`. Their leaves' records are at texel `leafBase`, one
// unit per triangle of a mesh BVH, or two per reference of the instance BVH (`instances`).
void appendNodes(std::vector<vec4>& out, const std::vector<BvhNode>& nodes, std::int64_t outBase, std::int64_t leafBase, bool instances) {
  const std::int64_t base = outBase + static_cast<std::int64_t>(out.size());
  const std::int64_t leafTexels = instances ? gpu::kInstanceRecordTexels : gpu::kTriTexels;
  static_assert(gpu::kNodeTexels == gpu::kUnitTexels && gpu::kTriTexels == gpu::kUnitTexels &&
                gpu::kInstanceRecordTexels % gpu::kUnitTexels == 0);
  for (const BvhNode& n : nodes) {
    // The children's layout (layouts.h): inner ones, then leaves, each consecutive, then none.
    std::uint32_t innerCount = 0, used = 0, starts = 0;
    std::int32_t leaf = -1, units = 0;  // the first leaf's record; units of the leaves so far
    for (std::size_t c = 0; c < kBvhWidth; ++c) {
      const std::int32_t index = n.index[c], count = n.count[c];
      if (count < 0) continue;
      RETILE_ASSERT(used == c, "a node's empty slot before a used one");
      ++used;
      if (count == 0) {
        RETILE_ASSERT(innerCount == c && index == n.index[0] + static_cast<std::int32_t>(c), "a node's inner children out of order");
        ++innerCount;
        continue;
      }
      RETILE_ASSERT(instances ? count == 1 : count <= gpu::kMaxLeafTriangles, cat("a leaf of ", count));
      if (leaf < 0) leaf = index;
      RETILE_ASSERT(index == leaf + (instances ? units / 2 : units), "a node's leaves are not consecutive");
      if (c > 0) starts |= static_cast<std::uint32_t>(units) << (gpu::kStartBits * (c - 1));
      units += instances ? 2 : count;
    }
    const std::uint32_t innerUnit = innerCount == 0 ? 0 : traversalUnit(base + std::int64_t{n.index[0]} * gpu::kNodeTexels);
    const std::uint32_t leafUnit = leaf < 0 ? 0 : traversalUnit(leafBase + std::int64_t{leaf} * leafTexels);
    pushNode(out, n, innerCount, used, instances, starts, innerUnit, leafUnit, units);
  }
}

// What the instance BVH's leaf p references when it is packed direct: the record at texel
// `texel` of the traversal buffer, an inner node of a mesh BVH or a run of `triangles`.
struct DirectRef {
  std::int64_t texel;
  bool node;
  std::int32_t triangles;
};

// Appends the instance BVH `nodes` to `out`, the top part of the traversal buffer from its texel
// outBase, with each leaf (one reference) replaced by what it references (layouts.h
// kFeatureDirectReferences), copied from `mesh`, the first part: a mesh BVH's inner node becomes
// an inner child, a copy of that node, whose children stay where they are; a run of triangles
// stays a leaf, a copy of the run placed after the nodes. The copies let a node's children stay
// consecutive, as its two bases require, and cost 48 bytes a node and up to 192 a run (at most
// kMaxBraidReferences of them: 3 MiB).
void appendDirectTop(std::vector<vec4>& out, std::int64_t outBase, const std::vector<BvhNode>& nodes,
                     const std::function<DirectRef(std::int32_t)>& refOf, const std::vector<vec4>& mesh) {
  // The nodes in output order: a node of the instance BVH (tlas >= 0) or a copy. Each node's
  // inner children, its own then its copies, are consecutive from inner[node].
  struct Unit {
    std::int32_t tlas;
    std::int64_t copyFrom;
  };
  std::vector<Unit> units{{0, -1}};
  std::vector<std::size_t> inner(nodes.size(), 0);
  for (std::size_t i = 0; i < units.size(); ++i) {
    if (units[i].tlas < 0) continue;
    const BvhNode& n = nodes[static_cast<std::size_t>(units[i].tlas)];
    inner[static_cast<std::size_t>(units[i].tlas)] = units.size();
    for (std::size_t c = 0; c < kBvhWidth; ++c)
      if (n.count[c] == 0) units.push_back({n.index[c], -1});
    for (std::size_t c = 0; c < kBvhWidth; ++c) {
      RETILE_ASSERT(n.count[c] <= 1, "an instance BVH leaf of more than one reference");
      if (n.count[c] > 0)
        if (const DirectRef r = refOf(n.index[c]); r.node) units.push_back({-1, r.texel});
    }
  }
  const std::int64_t first = outBase + static_cast<std::int64_t>(out.size());
  const std::int64_t leafBase = first + static_cast<std::int64_t>(units.size()) * gpu::kNodeTexels;
  std::vector<vec4> leaves;
  for (const Unit& u : units) {
    if (u.tlas < 0) {
      out.insert(out.end(), mesh.begin() + u.copyFrom, mesh.begin() + u.copyFrom + gpu::kNodeTexels);
      continue;
    }
    const BvhNode& n = nodes[static_cast<std::size_t>(u.tlas)];
    BvhNode slots;  // n's children in the order layouts.h asks for: inner ones, then leaves
    std::uint32_t innerCount = 0, used = 0, starts = 0;
    std::int32_t leafUnits = 0;
    const auto leafUnit = static_cast<std::uint32_t>((leafBase + static_cast<std::int64_t>(leaves.size())) / gpu::kUnitTexels);
    auto take = [&](std::size_t c, std::int32_t count) {
      slots.box[used] = n.box[c];
      slots.count[used] = count;
      ++used;
    };
    for (std::size_t c = 0; c < kBvhWidth; ++c)
      if (n.count[c] == 0) take(c, 0), ++innerCount;
    for (std::size_t c = 0; c < kBvhWidth; ++c)
      if (n.count[c] > 0 && refOf(n.index[c]).node) take(c, 0), ++innerCount;
    for (std::size_t c = 0; c < kBvhWidth; ++c) {
      if (n.count[c] <= 0) continue;
      const DirectRef r = refOf(n.index[c]);
      if (r.node) continue;
      if (used > 0) starts |= static_cast<std::uint32_t>(leafUnits) << (gpu::kStartBits * (used - 1));
      take(c, r.triangles);
      leaves.insert(leaves.end(), mesh.begin() + r.texel, mesh.begin() + r.texel + std::int64_t{r.triangles} * gpu::kTriTexels);
      leafUnits += r.triangles;
    }
    const std::uint32_t innerUnit =
        innerCount == 0 ? 0 : traversalUnit(first + static_cast<std::int64_t>(inner[static_cast<std::size_t>(u.tlas)]) * gpu::kNodeTexels);
    pushNode(out, slots, innerCount, used, false, starts, innerUnit,
             leafUnits > 0 ? traversalUnit(std::int64_t{leafUnit} * gpu::kUnitTexels) : 0, leafUnits);
  }
  out.insert(out.end(), leaves.begin(), leaves.end());
}

bool finite(const Mat4& t) {
  return std::all_of(&t.m[0][0], &t.m[0][0] + 16, [](float v) { return std::isfinite(v); });
}

// The inverse of a transform a mesh can be packed with: affine, finite, invertible and not
// mirrored (a mirror would turn its triangles' winding, which says which side of an emitter
// shines), with a finite affine inverse. Nothing for any other.
std::optional<Mat4> packedInverse(const Mat4& t) {
  if (!finite(t) || t.m[3][0] != 0 || t.m[3][1] != 0 || t.m[3][2] != 0 || t.m[3][3] != 1) return std::nullopt;
  if (!(t.linearDeterminant() > 0)) return std::nullopt;
  const Mat4 inv = t.inverse();
  if (!finite(inv) || inv.m[3][3] != 1) return std::nullopt;
  return inv;
}

struct SampleRay {
  Vec3 origin, direction;
};
constexpr float kRayFar = 1e30f;
constexpr int kSamplePaths = 1024;

// A visible instance's triangles, where sample paths may start when the camera sees little.
struct SampleSurface {
  std::uint32_t triOffset, triangles;
  const Mat4* toWorld;    // from the mesh's packed space
  const Mat4* fromWorld;  // its inverse
};

// Rays as a path tracer sends them, to count what a packing costs: from the camera through
// random points of the image, then two diffuse bounces (cosine-weighted, on the side the ray
// came from) from where they hit, traced through the packing given (mesh, top, root). Where
// fewer than a quarter of the camera's rays hit anything (a camera inside a wall or looking
// away), as many paths again start on the visible triangles (chosen by count) with one bounce,
// so that the choice still sees the geometry the camera will turn to. A fixed sequence, so that
// a scene gets the same choice each time it is packed. The shadow rays a path also sends are
// not among them. fromWorldOf(instance): the inverse of the instance's transform to world space.
std::vector<SampleRay> sampleRays(const Scene& scene, const std::vector<vec4>& mesh, const std::vector<vec4>& top, std::int32_t root,
                                  bool direct, std::span<const SampleSurface> surfaces,
                                  const std::function<const Mat4&(std::int32_t)>& fromWorldOf) {
  std::vector<SampleRay> rays;
  std::uint32_t state = 0x9e3779b9u;
  auto random = [&] {  // xorshift32: the same numbers on every platform, unlike <random>'s distributions
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return static_cast<float>(state >> 8) * (1.0f / 16777216.0f);
  };
  // A cosine-weighted direction about n, and the point `at` off the surface towards n by a
  // little more than its coordinates' rounding.
  auto leave = [&](Vec3 at, Vec3 n) {
    const float offset = 1e-4f * (1.0f + std::max({std::abs(at.x), std::abs(at.y), std::abs(at.z)}));
    const float r = std::sqrt(random()), phi = 2 * kPi * random();
    const Vec3 a = std::abs(n.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 u = normalize(cross(a, n)), v = cross(n, u);
    return SampleRay{at + n * offset,
                     normalize(u * (r * std::cos(phi)) + v * (r * std::sin(phi)) + n * std::sqrt(std::max(0.0f, 1 - r * r)))};
  };
  // Traces a path from `ray` for up to `bounces` bounces; whether its first ray hit.
  auto follow = [&](SampleRay ray, int bounces) {
    bool hitFirst = false;
    for (int bounce = 0; bounce <= bounces; ++bounce) {
      if (!std::isfinite(ray.origin.x + ray.origin.y + ray.origin.z + ray.direction.x + ray.direction.y + ray.direction.z)) break;
      rays.push_back(ray);
      const PackedTrace hit = tracePacked(mesh, top, root, direct, ray.origin, ray.direction, kRayFar);
      hitFirst = hitFirst || (bounce == 0 && hit.prim >= 0);
      if (hit.prim < 0 || bounce == bounces) break;
      const vec4* t = mesh.data() + static_cast<std::size_t>(hit.prim) * gpu::kTriTexels;
      Vec3 n = cross(Vec3{t[1].x, t[1].y, t[1].z}, Vec3{t[2].x, t[2].y, t[2].z});
      if (hit.instance >= 0) n = fromWorldOf(hit.instance).transposed().transformVector(n);
      if (!(length(n) > 0)) break;
      n = normalize(n);
      ray = leave(ray.origin + ray.direction * hit.t, dot(n, ray.direction) > 0 ? -n : n);
    }
    return hitFirst;
  };
  const Camera& cam = scene.camera;
  const Mat4 toWorld = Mat4::lookAt(cam.position, cam.target, cam.up);
  const float tanHalf = std::tan(0.5f * std::clamp(cam.verticalFov, 1e-3f, 3.1f));
  const float aspect =
      scene.settings.height > 0 ? static_cast<float>(scene.settings.width) / static_cast<float>(scene.settings.height) : 1.0f;
  int seen = 0;
  for (int path = 0; path < kSamplePaths; ++path) {
    const float x = (2 * random() - 1) * tanHalf * aspect, y = (2 * random() - 1) * tanHalf;
    seen += follow({cam.position, normalize(toWorld.transformVector(Vec3{x, y, -1}))}, 2) ? 1 : 0;
  }
  std::vector<std::uint64_t> before;  // triangles of the surfaces before each
  std::uint64_t total = 0;
  for (const SampleSurface& f : surfaces) {
    before.push_back(total);
    total += f.triangles;
  }
  for (int path = 0; seen < kSamplePaths / 4 && total > 0 && path < kSamplePaths; ++path) {
    const auto k = std::min(static_cast<std::uint64_t>(random() * static_cast<float>(total)), total - 1);
    const std::size_t f = static_cast<std::size_t>(std::upper_bound(before.begin(), before.end(), k) - before.begin()) - 1;
    const vec4* t = mesh.data() + (std::size_t{surfaces[f].triOffset} + (k - before[f])) * gpu::kTriTexels;
    const Vec3 v0{t[0].x, t[0].y, t[0].z}, e1{t[1].x, t[1].y, t[1].z}, e2{t[2].x, t[2].y, t[2].z};
    const float r = std::sqrt(random()), b = random();
    const Mat4& m = *surfaces[f].toWorld;
    const Vec3 n = surfaces[f].fromWorld->transposed().transformVector(cross(e1, e2));
    if (!(length(n) > 0)) continue;
    const Vec3 side = normalize(n) * (random() < 0.5f ? 1.0f : -1.0f);
    follow(leave(m.transformPoint(v0 + e1 * (r * (1 - b)) + e2 * (r * b)), side), 1);
  }
  return rays;
}

}  // namespace

Mat4 RenderSceneBuilder::placement(const Mat4& objectTransform, const MeshEntry& mesh) {
  if (mesh.placed == Mat4::identity()) return objectTransform;
  if (objectTransform == mesh.placed) return Mat4::identity();  // exactly, not by rounding
  return objectTransform * mesh.placedInverse;
}

const RenderSceneBuilder::MeshEntry* RenderSceneBuilder::entryOf(const Object& o) const {
  auto it = meshOf_.find(o.mesh);
  if (it == meshOf_.end()) return nullptr;
  // A copy made before the object took another mesh is not its.
  if (auto c = copyOf_.find(o.id); c != copyOf_.end() && c->second->geometry == it->second->geometry) return c->second;
  return it->second;
}

// Packs e.geometry's triangles and BVH into e, placed by `place` when it can be (packedInverse).
void RenderSceneBuilder::packMesh(MeshEntry& e, const Mat4* place) {
  const MeshGeometry& g = *e.geometry;
  std::vector<Vec3> placedPositions, placedNormals;
  const std::optional<Mat4> inverse = place && !(*place == Mat4::identity()) ? packedInverse(*place) : std::nullopt;
  if (inverse) {
    placedPositions.reserve(g.positions.size());
    for (Vec3 v : g.positions) placedPositions.push_back(place->transformPoint(v));
    // Placed, a hostile file's huge coordinates could overflow: such a mesh keeps its own space.
    if (std::all_of(placedPositions.begin(), placedPositions.end(), [](Vec3 v) { return std::isfinite(v.x + v.y + v.z); })) {
      e.placed = *place;
      e.placedInverse = *inverse;
      // Normals by the inverse transpose, not renormalised: interpolating them then equals
      // interpolating the mesh's own and transforming (the shader normalises).
      const Mat4 normalMatrix = e.placedInverse.transposed();
      placedNormals.reserve(g.normals.size());
      for (Vec3 v : g.normals) placedNormals.push_back(normalMatrix.transformVector(v));
    } else {
      placedPositions = {};
    }
  }
  const bool moved = !(e.placed == Mat4::identity());
  const std::vector<Vec3>& positions = moved ? placedPositions : g.positions;
  const std::vector<Vec3>& normals = moved ? placedNormals : g.normals;
  std::size_t n = g.triangleCount();
  std::vector<Bounds3> boxes(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) boxes[i].grow(positions[g.indices[i * 3 + static_cast<std::size_t>(k)]]);
  // A node's layout has four bits for where each leaf's run starts, and the shader tests runs of at most
  // kMaxLeafTriangles (layouts.h).
  static_assert(kMaxLeafSize <= gpu::kMaxLeafTriangles);
  e.bvh = buildBvh(boxes);
  e.steps = expectedSteps(e.bvh, [](std::uint32_t) { return 1.0f; });
  e.triangles.resize(n * gpu::kTriTexels);
  e.shading.resize(n * gpu::kTriShadeTexels);
  bool hasN = !normals.empty(), hasUv = !g.uvs.empty();
  for (std::size_t p = 0; p < n; ++p) {
    std::size_t src = e.bvh.primOrder[p];
    std::uint32_t i0 = g.indices[src * 3], i1 = g.indices[src * 3 + 1], i2 = g.indices[src * 3 + 2];
    Vec3 v0 = positions[i0], v1 = positions[i1], v2 = positions[i2];
    e.triangles[p * gpu::kTriTexels + 0] = v4(v0, 0);
    e.triangles[p * gpu::kTriTexels + 1] = v4(v1 - v0, 0);
    e.triangles[p * gpu::kTriTexels + 2] = v4(v2 - v0, 0);
    Vec3 n0 = hasN ? normals[i0] : Vec3{}, n1 = hasN ? normals[i1] : Vec3{}, n2 = hasN ? normals[i2] : Vec3{};
    Vec2 t0 = hasUv ? g.uvs[i0] : Vec2{}, t1 = hasUv ? g.uvs[i1] : Vec2{}, t2 = hasUv ? g.uvs[i2] : Vec2{};
    // Zero normals (from NaN in the file) fall back to the geometric normal in the shader.
    bool useN = hasN && dot(n0, n0) > 0 && dot(n1, n1) > 0 && dot(n2, n2) > 0;
    e.shading[p * gpu::kTriShadeTexels + 0] = v4(n0, t0.x);
    e.shading[p * gpu::kTriShadeTexels + 1] = v4(n1, t0.y);
    e.shading[p * gpu::kTriShadeTexels + 2] = v4(n2, t1.x);
    e.shading[p * gpu::kTriShadeTexels + 3] = {t1.y, t2.x, t2.y, useN ? 1.0f : 0.0f};
  }
  // Where each leaf's run ends (layouts.h): traversal goes on to the next triangle until then.
  for (const BvhNode& node : e.bvh.nodes)
    for (std::size_t c = 0; c < kBvhWidth; ++c)
      if (node.count[c] > 0) e.triangles[static_cast<std::size_t>(node.index[c] + node.count[c] - 1) * gpu::kTriTexels + 1].w = 1.0f;
}

void RenderSceneBuilder::packGeometry(const Scene& scene) {
  for (auto& [key, e] : meshes_) e.used = false;
  meshOf_.clear();
  copyOf_.clear();
  // A mesh is packed where its first object puts it. An object that puts a shared mesh elsewhere
  // gets a copy packed where it puts it, so that no instance needs a transform, while the
  // copies stay few: at most an eighth more triangles, or 65536 (8 MiB), whichever is more (a
  // scene of truly instanced meshes keeps one of each, and its transforms).
  std::unordered_map<const MeshGeometry*, const Mat4*> firstPlace;
  std::vector<const Object*> elsewhere;
  std::size_t unique = 0, copied = 0;
  for (const Object& o : scene.objects) {
    const Mesh* m = scene.mesh(o.mesh);
    if (!m || !m->geometry || m->geometry->indices.empty()) continue;
    auto [it, first] = firstPlace.try_emplace(m->geometry.get(), &o.transform);
    if (first) {
      unique += m->geometry->triangleCount();
    } else if (!(o.transform == *it->second) && packedInverse(o.transform)) {
      elsewhere.push_back(&o);
      copied += m->geometry->triangleCount();
    }
  }
  // The entries in the scene's order, which decides where each mesh's triangles are packed: a
  // triangle's index seeds its cut-out's coin (scene.glsl hitRandom), so an order of the map's
  // keys (addresses) would change the image from one build to the next.
  std::vector<MeshEntry*> order;
  auto use = [&](MeshEntry& e) {
    if (!e.used) order.push_back(&e);
    e.used = true;
  };
  for (const Mesh& m : scene.meshes) {
    if (!m.geometry || m.geometry->indices.empty()) continue;
    auto [it, inserted] = meshes_.try_emplace({m.geometry.get(), kNoNode});
    MeshEntry& e = it->second;
    use(e);
    meshOf_[m.id] = &e;
    if (!inserted) continue;
    e.geometry = m.geometry;
    auto place = firstPlace.find(m.geometry.get());
    packMesh(e, place == firstPlace.end() ? nullptr : place->second);
  }
  if (copied <= std::max<std::size_t>(unique / 8, 65536)) {
    for (const Object* o : elsewhere) {
      const Mesh* m = scene.mesh(o->mesh);
      auto [it, inserted] = meshes_.try_emplace({m->geometry.get(), o->id});
      MeshEntry& e = it->second;
      use(e);
      copyOf_[o->id] = &e;
      if (!inserted) continue;
      e.geometry = m->geometry;
      packMesh(e, &o->transform);
    }
  }
  std::erase_if(meshes_, [](const auto& kv) { return !kv.second.used; });

  // Triangles first, at texel 3p for packed triangle p, so that shading finds a hit's edges
  // from its index alone; then the BVHs, whose leaves name triangle runs. A mesh's packed
  // triangles live in one place only: a new mesh's in its entry until they are placed here, a
  // kept mesh's in the arrays of the last update, from which they are copied.
  std::size_t triangles = 0, nodes = 0;
  for (const MeshEntry* e : order) {
    triangles += e->bvh.primOrder.size();
    nodes += e->bvh.nodes.size();
  }
  std::vector<vec4> traversal, shading;
  traversal.reserve(triangles * gpu::kTriTexels + nodes * gpu::kNodeTexels);
  shading.reserve(triangles * gpu::kTriShadeTexels);
  for (MeshEntry* entry : order) {
    MeshEntry& e = *entry;
    const std::size_t n = e.bvh.primOrder.size();
    const auto offset = static_cast<std::uint32_t>(traversal.size() / gpu::kTriTexels);
    const bool fresh = !e.triangles.empty();
    const vec4* tri = fresh ? e.triangles.data() : data_.meshTraversal.data() + std::size_t{e.triOffset} * gpu::kTriTexels;
    const vec4* shade = fresh ? e.shading.data() : data_.triangleShading.data() + std::size_t{e.triOffset} * gpu::kTriShadeTexels;
    traversal.insert(traversal.end(), tri, tri + n * gpu::kTriTexels);
    shading.insert(shading.end(), shade, shade + n * gpu::kTriShadeTexels);
    for (std::size_t p = 0; p < n; ++p) traversal[(offset + p) * gpu::kTriTexels].w = bitsOf(static_cast<std::int32_t>(offset + p));
    e.triOffset = offset;
    e.triangles = std::vector<vec4>();  // `= {}` would clear and keep the memory
    e.shading = std::vector<vec4>();
  }
  data_.meshTraversal = std::move(traversal);
  data_.triangleShading = std::move(shading);
  data_.triangleCount = triangles;
  for (MeshEntry* e : order) {
    auto base = static_cast<std::int64_t>(data_.meshTraversal.size());
    e->rootItem = traversalItem(base, gpu::kItemNode);
    appendNodes(data_.meshTraversal, e->bvh.nodes, 0, std::int64_t{e->triOffset} * gpu::kTriTexels, false);
  }
}

static_assert(gpu::kMaxBlendChain == kMaxBlendChain, "the kernel follows as many blends as the scene allows");

// An object with a mesh whose box is not empty: an instance, visible or not.
struct RenderSceneBuilder::InstanceCandidate {
  const Object* object;
  const MeshEntry* mesh;
  Mat4 transform;  // from the mesh's packed space to world space
  Bounds3 bounds;
  bool visible;
};

// The instances' flags (layouts.h kInstance...) and inverse transforms, as their records hold
// them; the instance BVH's records repeat them.
struct RenderSceneBuilder::InstanceRecords {
  std::vector<int> flags;
  std::vector<Mat4> inverse;
};

// A reference of the instance BVH: a subtree of an instance's BVH, entered like an instance.
struct RenderSceneBuilder::BraidRef {
  std::uint32_t cand;
  std::int32_t item;           // where traversal enters the instance's BVH
  std::int32_t node;           // that BVH's node index when item is an inner node, else -1
  Bounds3 bounds;              // world space
  std::int32_t triangles = 0;  // a leaf's, when item is one
};

// An instance BVH and the top part of the traversal buffer packed from it.
struct RenderSceneBuilder::TopPacking {
  std::vector<BraidRef> refs;
  Bvh tlas;
  std::vector<vec4> top;
};

// The instance BVHs that the candidates allow, opened to a braid factor, and their packings above
// `mesh`, the traversal buffer's part that the meshes fill.
class RenderSceneBuilder::TopLevel {
 public:
  TopLevel(const std::vector<InstanceCandidate>& cands, std::size_t visible, const InstanceRecords& records, const std::vector<vec4>& mesh)
      : cands_(cands), visible_(visible), records_(records), mesh_(mesh), base_(static_cast<std::int64_t>(mesh.size())) {}

  std::int32_t root() const { return traversalItem(base_, gpu::kItemNode); }

  // Where instances overlap, a ray inside their union is inside every one of their boxes and
  // must enter each. So the instance BVH is built over references to subtrees of the instances'
  // BVHs (partial re-braiding, after Benthin et al. 2017): starting from each instance's root,
  // the reference with the largest box is replaced by its children (up to four) until there are
  // `budget` references. A reference is entered like an instance, at its subtree. Where
  // instances do not overlap, opening them gains nothing, so the factor is chosen by the steps
  // it costs sample rays (chooseBraidFactors), and kept across small edits (resetBraidIfStale),
  // so that a move builds one instance BVH, whose size stays proportional to the number of
  // objects.
  std::vector<BraidRef> braid(std::size_t budget) const {
    std::vector<BraidRef> refs;
    refs.reserve(budget);
    for (std::uint32_t c = 0; c < cands_.size(); ++c)
      if (cands_[c].visible) refs.push_back({c, cands_[c].mesh->rootItem, 0, cands_[c].bounds});
    auto smaller = [&](std::size_t a, std::size_t b) { return refs[a].bounds.area() < refs[b].bounds.area(); };
    std::vector<std::size_t> open(refs.size());  // a max-heap by area of the references that can still be opened
    std::iota(open.begin(), open.end(), std::size_t{0});
    std::make_heap(open.begin(), open.end(), smaller);
    while (!open.empty() && refs.size() < budget) {
      std::pop_heap(open.begin(), open.end(), smaller);
      const std::size_t r = open.back();
      open.pop_back();
      const std::vector<BraidRef> children = childrenOf(refs[r]);
      if (children.size() < 2) continue;  // a leaf root: nothing to open
      const std::size_t first = refs.size();
      refs[r] = children[0];
      refs.insert(refs.end(), children.begin() + 1, children.end());
      auto reopen = [&](std::size_t i) {
        if (refs[i].node < 0) return;
        open.push_back(i);
        std::push_heap(open.begin(), open.end(), smaller);
      };
      reopen(r);
      for (std::size_t i = first; i < refs.size(); ++i) reopen(i);
    }
    return refs;
  }

  // The instance BVH over the references of `factor` per visible instance (kMaxBraidReferences
  // at most), into *refs.
  Bvh build(std::size_t factor, bool packDirect, std::vector<BraidRef>* refs) const {
    *refs = braid(std::max(visible_, std::min(visible_ * factor, kMaxBraidReferences)));
    std::vector<Bounds3> boxes;
    boxes.reserve(refs->size());
    for (const BraidRef& r : *refs) boxes.push_back(r.bounds);
    BvhBuildOptions opt;
    opt.maxLeafSize = 1;  // a TLAS leaf is one reference: traversal enters its subtree directly
    // Entering a reference is one step, unless packed direct, then its subtree's.
    const float enter = packDirect ? 0.0f : 1.0f;
    opt.primCost = [this, refs, enter](std::uint32_t i) {
      const BraidRef& r = (*refs)[i];
      if (r.node >= 0) return enter + cands_[r.cand].mesh->steps[static_cast<std::size_t>(r.node)];
      return enter + static_cast<float>(r.triangles);  // a leaf: its triangles
    };
    return buildBvh(boxes, opt);
  }

  // The top part of the traversal buffer: the instance BVH, then one record per reference (in
  // the BVH's packed order), or, direct, what the references name (copied after the numbering,
  // so that copies of triangles carry it too).
  std::vector<vec4> pack(const Bvh& tlas, const std::vector<BraidRef>& refs, bool packDirect) const {
    std::vector<vec4> top;
    if (packDirect) {
      appendDirectTop(
          top, base_, tlas.nodes,
          [&](std::int32_t p) {
            const BraidRef& r = refs[tlas.primOrder[static_cast<std::size_t>(p)]];
            return DirectRef{r.item >> gpu::kItemOffsetShift, r.node >= 0, r.triangles};
          },
          mesh_);
      return top;
    }
    const auto records = base_ + static_cast<std::int64_t>(tlas.nodes.size()) * gpu::kNodeTexels;
    appendNodes(top, tlas.nodes, base_, records, true);
    for (std::uint32_t p : tlas.primOrder) {
      const BraidRef& r = refs[p];
      const Mat4& inv = records_.inverse[r.cand];
      top.push_back(ints(r.item, static_cast<std::int32_t>(r.cand), records_.flags[r.cand], 0));
      for (int row = 0; row < 3; ++row) top.push_back({inv.m[row][0], inv.m[row][1], inv.m[row][2], inv.m[row][3]});
      top.insert(top.end(), gpu::kInstanceRecordTexels - 4, vec4{});
    }
    RETILE_ASSERT(
        records + static_cast<std::int64_t>(refs.size()) * gpu::kInstanceRecordTexels == base_ + static_cast<std::int64_t>(top.size()),
        "instance records out of place");
    return top;
  }

  TopPacking packing(std::size_t factor, bool packDirect) const {
    TopPacking p;
    p.tlas = build(factor, packDirect, &p.refs);
    p.top = pack(p.tlas, p.refs, packDirect);
    return p;
  }

  // Traversal steps of `rays` through a packing, as the kernel counts them (tracePacked).
  std::uint64_t steps(const std::vector<SampleRay>& rays, const std::vector<vec4>& top, bool packDirect) const {
    std::uint64_t steps = 0;
    for (const SampleRay& r : rays) steps += tracePacked(mesh_, top, root(), packDirect, r.origin, r.direction, kRayFar).steps;
    return steps;
  }

  // The factor for packing `packDirect` whose packing costs `rays` the fewest steps, from
  // *best, the packing of factor 1, which becomes the chosen one. A factor must save 1 % of the
  // steps to be taken: more references cost memory and build time.
  std::size_t bestFactor(const std::vector<SampleRay>& rays, bool packDirect, TopPacking* best) const {
    std::uint64_t fewest = steps(rays, best->top, packDirect);
    std::size_t factor = 1, previous = best->refs.size();
    for (std::size_t f = 2; f <= kMaxBraidFactor && !rays.empty(); f *= 2) {
      std::vector<BraidRef> tried;
      Bvh bvh = build(f, packDirect, &tried);
      const bool opened = tried.size() > previous;
      previous = tried.size();
      if (!opened) break;  // nothing left to open, or the cap reached
      std::vector<vec4> packed = pack(bvh, tried, packDirect);
      const std::uint64_t n = steps(rays, packed, packDirect);
      if (static_cast<double>(n) < 0.99 * static_cast<double>(fewest)) {
        fewest = n;
        factor = f;
        best->refs = std::move(tried);
        best->tlas = std::move(bvh);
        best->top = std::move(packed);
      }
    }
    return factor;
  }

 private:
  // A reference's children, each a reference of the same instance.
  std::vector<BraidRef> childrenOf(const BraidRef& ref) const {
    const InstanceCandidate& c = cands_[ref.cand];
    const BvhNode& n = c.mesh->bvh.nodes[static_cast<std::size_t>(ref.node)];
    const std::int64_t nodes = c.mesh->rootItem >> gpu::kItemOffsetShift;
    std::vector<BraidRef> children;
    for (std::size_t k = 0; k < kBvhWidth; ++k) {
      const std::int32_t index = n.index[k], count = n.count[k];
      if (count < 0) continue;
      const Bounds3 world = transformBounds(c.transform, n.box[k]);
      if (count == 0)
        children.push_back({ref.cand, traversalItem(nodes + std::int64_t{index} * gpu::kNodeTexels, gpu::kItemNode), index, world});
      else
        children.push_back(
            {ref.cand, traversalItem((std::int64_t{c.mesh->triOffset} + index) * gpu::kTriTexels, gpu::kItemTriangles), -1, world, count});
    }
    return children;
  }

  const std::vector<InstanceCandidate>& cands_;
  std::size_t visible_;
  const InstanceRecords& records_;
  const std::vector<vec4>& mesh_;
  std::int64_t base_;  // the top part's first texel
};

// Hidden objects are instances too, with no reference in the instance BVH: so an instance's
// number does not change when another is hidden or shown, and with direct references the
// triangles that carry it need not be uploaded again.
std::vector<RenderSceneBuilder::InstanceCandidate> RenderSceneBuilder::instanceCandidates(const Scene& scene) const {
  std::vector<InstanceCandidate> cands;
  for (const Object& o : scene.objects) {
    const MeshEntry* mesh = entryOf(o);
    if (!mesh) continue;
    const Mat4 t = placement(o.transform, *mesh);
    Bounds3 b = transformBounds(t, mesh->bvh.bounds);
    if (b.empty()) continue;
    cands.push_back({&o, mesh, t, b, o.visible});
  }
  return cands;
}

int RenderSceneBuilder::instanceFlags(const Scene& scene, const InstanceCandidate& c) const {
  const Material* mat = scene.material(c.object->material);
  int flags = 0;
  // A boundary is crossed whole (its medium must not be left at random).
  if (mat && mat->type != MaterialType::Boundary && (mat->alpha < 1.0f || textureIndex(mat->alphaTexture) >= 0))
    flags |= gpu::kInstanceAlphaTested;
  if (mat && sheetInBlend(scene, *mat)) flags |= gpu::kInstanceSheet;
  if (mat && mat->emissive()) flags |= gpu::kInstanceEmissive;
  if (mat && mat->type == MaterialType::Boundary) flags |= gpu::kInstanceBoundary;
  if (c.object->cullBackFaces) flags |= gpu::kInstanceCullBack;
  return flags;
}

// The instances' records, flags and numbers come first: the instance BVH's packing needs them.
RenderSceneBuilder::InstanceRecords RenderSceneBuilder::packInstanceRecords(const Scene& scene, const std::vector<InstanceCandidate>& cands,
                                                                            bool direct, bool transforms) {
  data_.directReferences = direct;
  data_.instances.clear();
  data_.instanceObject.clear();
  data_.instancedTriangles = 0;
  data_.cutOuts = data_.sheetShadows = false;
  data_.cullBack = false;
  data_.instanceTransforms = transforms;
  InstanceRecords records{std::vector<int>(cands.size(), 0), std::vector<Mat4>(cands.size())};
  for (std::size_t i = 0; i < cands.size(); ++i) {
    const InstanceCandidate& c = cands[i];
    const int flags = instanceFlags(scene, c);
    if (c.visible && (flags & gpu::kInstanceAlphaTested)) data_.cutOuts = true;
    // A sheet's pause is the cut-outs' (RETILE_ALPHA_TEST).
    if (c.visible && (flags & gpu::kInstanceSheet)) data_.sheetShadows = true;
    if (c.visible && (flags & gpu::kInstanceCullBack)) data_.cullBack = true;
    records.flags[i] = flags;
    records.inverse[i] = c.transform.inverse();
    const Mat4& inv = records.inverse[i];
    for (int r = 0; r < 3; ++r) data_.instances.push_back({inv.m[r][0], inv.m[r][1], inv.m[r][2], inv.m[r][3]});
    data_.instances.push_back(ints(0, static_cast<std::int32_t>(c.mesh->triOffset), materialIndex(c.object->material), -1));
    data_.instances.push_back(ints(static_cast<std::int32_t>(i) + 1, flags, 0, 0));
    data_.instanceObject.push_back(c.object->id);
    if (c.visible) data_.instancedTriangles += c.mesh->bvh.primOrder.size();
  }
  return records;
}

// Direct, each triangle names its instance: a visible object's, or where none uses its mesh
// a hidden one's, so that showing it later changes nothing. The names change when objects are
// added or removed (or a cut-out's or culling flag changes), and then the meshes' part is
// uploaded again; a mesh whose triangles already name the right instance is not touched.
// Returns whether any triangle was renamed.
bool RenderSceneBuilder::nameTriangles(const std::vector<InstanceCandidate>& cands, const std::vector<int>& flagsOf) {
  bool renamed = false;
  std::unordered_map<const MeshEntry*, std::size_t> namer;
  for (std::size_t i = 0; i < cands.size(); ++i)
    if (cands[i].visible) namer[cands[i].mesh] = i;
  for (std::size_t i = 0; i < cands.size(); ++i)
    if (!cands[i].visible) namer.try_emplace(cands[i].mesh, i);
  for (const auto& [mesh, i] : namer) {
    const std::uint32_t name = static_cast<std::uint32_t>(i) | ((flagsOf[i] & gpu::kInstanceAlphaTested) ? gpu::kTriAlphaTested : 0u) |
                               ((flagsOf[i] & gpu::kInstanceBoundary) ? gpu::kTriBoundary : 0u) |
                               ((flagsOf[i] & gpu::kInstanceCullBack) ? gpu::kTriCullBack : 0u) |
                               ((flagsOf[i] & gpu::kInstanceSheet) ? gpu::kTriSheet : 0u);
    if (mesh->named == name) continue;
    mesh->named = name;
    renamed = true;
    const std::size_t from = mesh->triOffset, to = from + mesh->bvh.primOrder.size();
    for (std::size_t p = from; p < to; ++p) data_.meshTraversal[p * gpu::kTriTexels + 2].w = std::bit_cast<float>(name);
  }
  return renamed;
}

// Choosing the braid factors costs tens of milliseconds (the spaceship 30, a room of a million
// triangles 60), so it is done when meshes change (chooseBraid), or when the visible objects
// differ from those of the last choice by more than an eighth of those (and by more than two),
// not for each object shown, hidden, added or removed, which would delay the editor's next frame
// by as much. Forgets the factors chosen when it is time to choose again.
void RenderSceneBuilder::resetBraidIfStale(const std::vector<InstanceCandidate>& cands, std::size_t visible, bool chooseBraid) {
  std::vector<NodeId> visibleIds;
  visibleIds.reserve(visible);
  for (const InstanceCandidate& c : cands)
    if (c.visible) visibleIds.push_back(c.object->id);
  std::sort(visibleIds.begin(), visibleIds.end());
  std::vector<NodeId> differ;  // objects visible now or then but not both
  std::set_symmetric_difference(visibleIds.begin(), visibleIds.end(), braidVisible_.begin(), braidVisible_.end(),
                                std::back_inserter(differ));
  if (chooseBraid || differ.size() > std::max<std::size_t>(braidVisible_.size() / 8, 2)) {
    braidVisible_ = std::move(visibleIds);
    braidFactor_ = {0, 0};
  }
}

// How far instances are opened: the factor whose packing costs sample rays the fewest
// traversal steps, counted as the kernel counts them (tracePacked). The surface area
// heuristic assumes rays come from outside every box; a path's rays start on surfaces, inside
// the boxes of the instances around them, and the heuristic keeps the living room's objects
// whole where 16 references each take 10 % fewer loop iterations a path. The rays leave the
// camera as it is when the factor is chosen.
//
// Direct, a reference costs no step of its own, so the factor for records differs: a scene
// packed direct chooses it too, from the same rays, so that the first move (which turns direct
// off) need not choose. A scene packed with records that turns direct (its transforms undone, a
// duplicate removed) chooses the direct factor then. Returns the packing chosen for `direct`.
RenderSceneBuilder::TopPacking RenderSceneBuilder::chooseBraidFactors(const Scene& scene, const TopLevel& top,
                                                                      const std::vector<InstanceCandidate>& cands,
                                                                      const InstanceRecords& records, bool direct) {
  ++braidChoices_;
  TopPacking chosen = top.packing(1, direct);  // the rays are traced through the packing of factor 1
  std::vector<SampleSurface> surfaces;
  for (std::size_t i = 0; i < cands.size(); ++i)
    if (cands[i].visible)
      surfaces.push_back({cands[i].mesh->triOffset, static_cast<std::uint32_t>(cands[i].mesh->bvh.primOrder.size()), &cands[i].transform,
                          &records.inverse[i]});
  const std::vector<SampleRay> rays =
      sampleRays(scene, data_.meshTraversal, chosen.top, top.root(), direct, surfaces,
                 [&](std::int32_t instance) -> const Mat4& { return records.inverse[static_cast<std::size_t>(instance)]; });
  braidFactor_[direct] = top.bestFactor(rays, direct, &chosen);
  if (direct && braidFactor_[false] == 0) {
    TopPacking withRecords = top.packing(1, false);
    braidFactor_[false] = top.bestFactor(rays, false, &withRecords);
  }
  return chosen;
}

bool RenderSceneBuilder::packInstances(const Scene& scene, bool chooseBraid) {
  const std::vector<InstanceCandidate> cands = instanceCandidates(scene);
  const auto visible = static_cast<std::size_t>(std::count_if(cands.begin(), cands.end(), [](const auto& c) { return c.visible; }));
  // Direct references (layouts.h kFeatureDirectReferences) need every instance in world space as
  // packed, and each triangle in one instance only, as it names it.
  bool transforms = false, shared = false;
  {
    std::unordered_set<const MeshEntry*> seen;
    for (const InstanceCandidate& c : cands) {
      if (!c.visible) continue;
      transforms = transforms || !(c.transform == Mat4::identity());
      shared = shared || !seen.insert(c.mesh).second;
    }
  }
  // A triangle names its instance in kTriInstanceMask's bits.
  const bool direct = directReferences_ && !transforms && !shared && cands.size() <= static_cast<std::size_t>(gpu::kTriInstanceMask);
  const InstanceRecords records = packInstanceRecords(scene, cands, direct, transforms);
  const bool renamed = direct && nameTriangles(cands, records.flags);

  const TopLevel top(cands, visible, records, data_.meshTraversal);
  data_.tlasRoot = top.root();
  resetBraidIfStale(cands, visible, chooseBraid);
  TopPacking chosen =
      braidFactor_[direct] == 0 ? chooseBraidFactors(scene, top, cands, records, direct) : top.packing(braidFactor_[direct], direct);
  data_.bounds = chosen.tlas.bounds;
  data_.topTraversal = std::move(chosen.top);
  data_.instanceReferences = chosen.refs.size();
  return renamed;
}

}  // namespace retile
