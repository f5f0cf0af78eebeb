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

MediumAt worldMediumOf(const Environment& e) {
  if (!e.filled()) return {};
  return {max(e.mediumAbsorption, Vec3{0.0f}), max(e.mediumScattering, Vec3{0.0f}), std::clamp(e.mediumAnisotropy, -0.99f, 0.99f)};
}

MediaAround mediaAround(const RenderSceneData& d, Vec3 point) {
  // Outside every holder is the world's medium. Glass holds a vacuum at least, so where the world
  // has a medium, empty glass counts too.
  const MediaAround outside{d.worldMedium, d.worldMedium};
  constexpr std::uint32_t kHolders = 1u << gpu::kMatDielectric | 1u << gpu::kMatRoughDielectric | 1u << gpu::kMatBoundary;
  if (!(d.materialTypes & (1u << gpu::kMaskMedium)) || !(d.materialTypes & kHolders) || d.tlasRoot < 0) return outside;
  const bool transforms = d.instanceTransforms;
  const bool direct = d.directReferences && !transforms;
  auto intOf = [](float f) { return std::bit_cast<std::int32_t>(f); };
  auto mediumOf = [&](std::int32_t material) {
    if (material < 0) return d.worldMedium;
    const std::size_t mbase = static_cast<std::size_t>(material) * gpu::kMaterialTexels;
    const vec4 &interior = d.materials[mbase + 8], &scattering = d.materials[mbase + 9];
    const int type = intOf(d.materials[mbase].w) & gpu::kMatTypeBits;
    return MediumAt{{interior.x, interior.y, interior.z},
                    {scattering.x, scattering.y, scattering.z},
                    scattering.w,
                    type == gpu::kMatDielectric || type == gpu::kMatRoughDielectric};
  };
  // The first two holders a ray from the point leaves by faces it did not come in by (-1: it
  // leaves the scene first). kUndecided where it meets an opaque surface before (a wall does not
  // tell which of its sides a medium is on: the volumetric caustic's gas fills a box of plain
  // walls closed by one boundary), unless `throughWalls`. Glass counts even empty (the path is in
  // a vacuum inside it), a boundary only with its medium (one without leaves the path's as it is).
  constexpr std::int32_t kUndecided = -2;
  struct Left {
    std::int32_t first = kUndecided, second = kUndecided;
  };
  auto leftBy = [&](Vec3 dir, bool throughWalls) {
    Left left;
    std::vector<std::int32_t> entered;
    Vec3 origin = point;
    for (int hits = 0; hits < 64; ++hits) {
      const PackedTrace hit = tracePacked(d.meshTraversal, d.topTraversal, d.tlasRoot, direct, origin, dir, 1e30f);
      if (hit.prim < 0) {
        (left.first == kUndecided ? left.first : left.second) = -1;
        return left;
      }
      const std::size_t base = static_cast<std::size_t>(hit.instance) * gpu::kInstanceTexels;
      const std::int32_t material = hit.instance >= 0 && base + 3 < d.instances.size() ? intOf(d.instances[base + 3].z) : -1;
      const std::size_t mbase = static_cast<std::size_t>(material) * gpu::kMaterialTexels;
      if (material < 0 || mbase + 9 >= d.materials.size()) return left;
      const int type = intOf(d.materials[mbase].w) & gpu::kMatTypeBits;
      const MediumAt medium = mediumOf(material);
      const bool filled = maxComponent(medium.absorption + medium.scattering) > 0;
      const bool glass = medium.glass;
      if (!glass && type != gpu::kMatBoundary && !throughWalls) return left;
      if (glass || (type == gpu::kMatBoundary && filled)) {
        const vec4* t = d.meshTraversal.data() + static_cast<std::size_t>(hit.prim) * gpu::kTriTexels;
        Vec3 n = cross(Vec3{t[1].x, t[1].y, t[1].z}, Vec3{t[2].x, t[2].y, t[2].z});
        if (transforms) {  // the rows of the inverse transform, transposed: the normal's matrix
          const vec4* r = d.instances.data() + base;
          n = Vec3{r[0].x * n.x + r[1].x * n.y + r[2].x * n.z, r[0].y * n.x + r[1].y * n.y + r[2].y * n.z,
                   r[0].z * n.x + r[1].z * n.y + r[2].z * n.z};
        }
        if (dot(n, dir) < 0) {
          entered.push_back(material);
        } else if (!entered.empty() && entered.back() == material) {
          entered.pop_back();
        } else if (left.first == kUndecided) {
          left.first = material;
        } else {
          left.second = material;
          return left;
        }
      }
      const Vec3 at = origin + dir * hit.t;
      origin = at + dir * (1e-4f * (1.0f + std::max({std::abs(at.x), std::abs(at.y), std::abs(at.z)})));
    }
    return left;
  };
  // Fourteen directions (the faces' and the corners' of a cube, turned off the axes, so that no
  // ray runs along a wall or through an edge by design). A holder left is evidence; a ray that
  // leaves the scene is not against it (one side of an open boundary, a water surface, is its
  // medium's), so the holder most rays leave wins, and none only when no ray leaves one. Where
  // every ray meets a wall first, they are cast again through the walls.
  static const Vec3 kDirections[14] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},   {0, -1, 0}, {0, 0, 1},   {0, 0, -1},  {1, 1, 1},
                                       {1, 1, -1}, {1, -1, 1}, {1, -1, -1}, {-1, 1, 1}, {-1, 1, -1}, {-1, -1, 1}, {-1, -1, -1}};
  const Mat4 turn = Mat4::rotateY(0.37f) * Mat4::rotateX(0.23f);
  Left rays[14];
  bool decided = false;
  for (bool throughWalls : {false, true}) {
    for (int i = 0; i < 14; ++i) {
      rays[i] = leftBy(normalize(turn.transformVector(kDirections[i])), throughWalls);
      decided = decided || rays[i].first != kUndecided;
    }
    if (decided) break;
  }
  auto mostLeft = [&](std::int32_t Left::*which, std::int32_t given) {  // of the rays whose first is `given`, if any
    std::map<std::int32_t, int> votes;
    for (const Left& l : rays)
      if (l.*which >= 0 && (given < 0 || l.first == given)) ++votes[l.*which];
    std::int32_t best = -1;
    int most = 0;
    for (const auto& [m, n] : votes)
      if (n > most) {
        most = n;
        best = m;
      }
    return best;
  };
  const std::int32_t inner = mostLeft(&Left::first, -1);
  return inner < 0 ? outside : MediaAround{mediumOf(inner), mediumOf(mostLeft(&Left::second, inner))};
}

namespace {
// Whether the triangles close a surface: after welding positions that agree to a millionth of the
// mesh's size, every edge is met exactly once in each direction (closed and consistently wound).
// A water surface, a window pane or a mesh with holes is not: a path inside can leave it.
bool closedSurface(const MeshGeometry& g) {
  if (g.indices.empty()) return false;
  const Bounds3 b = g.bounds();
  const float cell = std::max(maxComponent(b.extent()), 1e-30f) * 1e-6f;
  using Cell = std::array<std::int64_t, 3>;
  struct CellHash {
    std::size_t operator()(const Cell& c) const { return static_cast<std::size_t>(c[0] * 73856093 ^ c[1] * 19349663 ^ c[2] * 83492791); }
  };
  std::unordered_map<Cell, std::uint32_t, CellHash> welded;
  std::vector<std::uint32_t> id(g.positions.size());
  for (std::size_t i = 0; i < g.positions.size(); ++i) {
    const Vec3 q = (g.positions[i] - b.lo) / cell;
    const Cell key{std::llround(q.x), std::llround(q.y), std::llround(q.z)};
    id[i] = welded.emplace(key, static_cast<std::uint32_t>(welded.size())).first->second;
  }
  std::unordered_map<std::uint64_t, int> edges;  // directed edge -> times met
  for (std::size_t t = 0; t + 2 < g.indices.size(); t += 3)
    for (int e = 0; e < 3; ++e) {
      const std::uint64_t from = id[g.indices[t + e]], to = id[g.indices[t + (e + 1) % 3]];
      if (from == to) continue;  // a degenerate triangle's collapsed edge
      if (++edges[from << 32 | to] > 1) return false;
    }
  for (const auto& [edge, n] : edges)
    if (!edges.count((edge & 0xffffffffu) << 32 | edge >> 32)) return false;
  return true;
}
}  // namespace

bool RenderSceneBuilder::lightInScatteringGlass(const Scene& scene) const {
  // Glass blocks shadow rays, so from a scattering point inside it only a light inside it can be
  // sampled: bounds that meet keep the sampling, and an emissive glass meets itself. That holds
  // only where a path inside cannot get out but through the glass: so any scattering glass that
  // is open (closedSurface), cut out, culled, or blended with something other than uncut glass
  // keeps it too.
  auto isGlass = [](const Material& m) { return m.type == MaterialType::Dielectric || m.type == MaterialType::RoughDielectric; };
  auto scatteringGlass = [&](const Material* m) { return m && isGlass(*m) && m->filled() && maxComponent(m->interiorScattering) > 0; };
  // Most scenes have none: then no instance needs looking at (this runs at every object move).
  if (std::none_of(scene.materials.begin(), scene.materials.end(), [&](const Material& m) { return scatteringGlass(&m); })) return false;
  std::vector<Bounds3> glass, lights;
  for (std::size_t i = 0; i < data_.instanceObject.size(); ++i) {
    const Object* o = scene.object(data_.instanceObject[i]);
    const Material* mat = o && o->visible ? scene.material(o->material) : nullptr;
    const MeshEntry* mesh = mat ? entryOf(*o) : nullptr;
    if (!mesh) continue;
    // Its blend chain, as the kernel follows it (fetchMaterial): glass throughout, or not.
    bool scatters = false, allGlass = true;
    forEachInBlend(scene, *mat, [&](const Material& part) {
      scatters = scatters || scatteringGlass(&part);
      allGlass = allGlass && isGlass(part) && part.alpha >= 1 && part.alphaTexture == kNoNode;
    });
    if (scatters) {
      // Culled, its back faces let shadow rays out, and paths.
      if (!allGlass || o->cullBackFaces) return true;
      if (mesh->closed < 0) mesh->closed = mesh->geometry && closedSurface(*mesh->geometry) ? 1 : 0;
      if (!mesh->closed) return true;
    }
    if (!scatters && !mat->emissive()) continue;
    const Bounds3 b = transformBounds(placement(o->transform, *mesh), mesh->bvh.bounds);
    if (scatters) glass.push_back(b);
    if (mat->emissive()) lights.push_back(b);
  }
  if (glass.empty()) return false;
  for (const Light& l : scene.lights)
    if (l.visible && l.type != LightType::Directional) lights.push_back(Bounds3{l.position, l.position});
  auto meet = [](const Bounds3& a, const Bounds3& b) {
    return a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y && a.lo.z <= b.hi.z && b.lo.z <= a.hi.z;
  };
  for (const Bounds3& g : glass)
    for (const Bounds3& l : lights)
      if (meet(g, l)) return true;
  return false;
}

}  // namespace retile
