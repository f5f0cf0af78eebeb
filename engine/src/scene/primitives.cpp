#include "scene/primitives.h"

#include <cmath>

namespace retile {

std::shared_ptr<const MeshGeometry> makeQuad() {
  auto g = std::make_shared<MeshGeometry>();
  g->positions = {{-0.5f, 0, -0.5f}, {0.5f, 0, -0.5f}, {0.5f, 0, 0.5f}, {-0.5f, 0, 0.5f}};
  g->normals.assign(4, {0, 1, 0});
  g->uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  g->indices = {0, 2, 1, 0, 3, 2};  // counter-clockwise seen from +y
  return g;
}

std::shared_ptr<const MeshGeometry> makeCube() {
  auto g = std::make_shared<MeshGeometry>();
  const Vec3 normals[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const Vec3& n : normals) {
    // Two axes spanning the face, chosen so that u x v = n (counter-clockwise from outside).
    Vec3 u = std::abs(n.y) > 0.5f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    Vec3 v = cross(n, u);
    auto base = static_cast<std::uint32_t>(g->positions.size());
    const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (const auto& c : corners) {
      g->positions.push_back(n * 0.5f + u * (0.5f * c[0]) + v * (0.5f * c[1]));
      g->normals.push_back(n);
      g->uvs.push_back({0.5f * (c[0] + 1), 0.5f * (c[1] + 1)});
    }
    g->indices.insert(g->indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  return g;
}

std::shared_ptr<const MeshGeometry> makeSphere(int rings, int segments) {
  auto g = std::make_shared<MeshGeometry>();
  for (int r = 0; r <= rings; ++r) {
    float theta = kPi * static_cast<float>(r) / static_cast<float>(rings);
    for (int s = 0; s <= segments; ++s) {
      float phi = 2 * kPi * static_cast<float>(s) / static_cast<float>(segments);
      Vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
      g->positions.push_back(n);
      g->normals.push_back(n);
      g->uvs.push_back({static_cast<float>(s) / static_cast<float>(segments), static_cast<float>(r) / static_cast<float>(rings)});
    }
  }
  auto idx = [&](int r, int s) { return static_cast<std::uint32_t>(r * (segments + 1) + s); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      // Skip the degenerate triangle at each pole.
      if (r != 0) g->indices.insert(g->indices.end(), {idx(r, s), idx(r + 1, s), idx(r, s + 1)});
      if (r != rings - 1) g->indices.insert(g->indices.end(), {idx(r, s + 1), idx(r + 1, s), idx(r + 1, s + 1)});
    }
  return g;
}

std::shared_ptr<const MeshGeometry> makeLathe(const std::vector<Vec2>& profile, int segments) {
  auto g = std::make_shared<MeshGeometry>();
  auto n = static_cast<int>(profile.size());
  // Profile normals from neighbouring segments, so that the walls shade smoothly.
  std::vector<Vec2> pn(profile.size());
  for (int i = 0; i < n; ++i) {
    Vec2 a = profile[static_cast<std::size_t>(std::max(i - 1, 0))];
    Vec2 b = profile[static_cast<std::size_t>(std::min(i + 1, n - 1))];
    float dx = b.x - a.x, dy = b.y - a.y;
    float l = std::sqrt(dx * dx + dy * dy);
    pn[static_cast<std::size_t>(i)] = l > 0 ? Vec2{dy / l, -dx / l} : Vec2{1, 0};
  }
  for (int i = 0; i < n; ++i)
    for (int s = 0; s <= segments; ++s) {
      float phi = 2 * kPi * static_cast<float>(s) / static_cast<float>(segments);
      float c = std::cos(phi), sn = std::sin(phi);
      const Vec2& p = profile[static_cast<std::size_t>(i)];
      const Vec2& q = pn[static_cast<std::size_t>(i)];
      g->positions.push_back({p.x * c, p.y, -p.x * sn});
      g->normals.push_back(normalize(Vec3{q.x * c, q.y, -q.x * sn}));
      g->uvs.push_back({static_cast<float>(s) / static_cast<float>(segments), static_cast<float>(i) / static_cast<float>(n - 1)});
    }
  auto idx = [&](int i, int s) { return static_cast<std::uint32_t>(i * (segments + 1) + s); };
  for (int i = 0; i + 1 < n; ++i)
    for (int s = 0; s < segments; ++s) {
      g->indices.insert(g->indices.end(), {idx(i, s), idx(i, s + 1), idx(i + 1, s)});
      g->indices.insert(g->indices.end(), {idx(i, s + 1), idx(i + 1, s + 1), idx(i + 1, s)});
    }
  return g;
}

std::shared_ptr<const MeshGeometry> makeCylinder(bool capped, int segments) {
  auto g = std::make_shared<MeshGeometry>(*makeLathe({{0.5f, -0.5f}, {0.5f, 0.5f}}, segments));
  if (!capped) return g;
  for (const auto& cap : {makeLathe({{0.0f, -0.5f}, {0.5f, -0.5f}}, segments), makeLathe({{0.5f, 0.5f}, {0.0f, 0.5f}}, segments)}) {
    auto base = static_cast<std::uint32_t>(g->positions.size());
    g->positions.insert(g->positions.end(), cap->positions.begin(), cap->positions.end());
    g->normals.insert(g->normals.end(), cap->normals.begin(), cap->normals.end());
    g->uvs.insert(g->uvs.end(), cap->uvs.begin(), cap->uvs.end());
    for (std::uint32_t i : cap->indices) g->indices.push_back(base + i);
  }
  return g;
}

NodeId addMesh(Scene& s, std::string name, std::shared_ptr<const MeshGeometry> g) {
  Mesh m;
  m.id = s.newId();
  m.name = std::move(name);
  m.geometry = std::move(g);
  s.meshes.push_back(std::move(m));
  return s.meshes.back().id;
}

NodeId addMaterial(Scene& s, Material m) {
  m.id = s.newId();
  s.materials.push_back(std::move(m));
  return s.materials.back().id;
}

NodeId addObject(Scene& s, std::string name, NodeId mesh, NodeId material, const Mat4& xf) {
  Object o;
  o.id = s.newId();
  o.name = std::move(name);
  o.mesh = mesh;
  o.material = material;
  o.transform = xf;
  s.objects.push_back(std::move(o));
  return s.objects.back().id;
}

NodeId addMeshObject(Scene& s, const std::string& name, std::shared_ptr<const MeshGeometry> g, Material m, const Mat4& xf) {
  const NodeId mesh = addMesh(s, name, std::move(g));
  m.name = name;
  const NodeId material = addMaterial(s, std::move(m));
  return addObject(s, name, mesh, material, xf);
}

}  // namespace retile
