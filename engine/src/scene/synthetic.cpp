#include "scene/synthetic.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>

#include "retile/log.h"
#include "scene/primitives.h"

namespace retile {
namespace {

// Smooth normals from the triangles around each vertex (area weighted).
void computeNormals(MeshGeometry& g) {
  g.normals.assign(g.positions.size(), Vec3{0.0f});
  for (std::size_t i = 0; i + 2 < g.indices.size(); i += 3) {
    const Vec3 a = g.positions[g.indices[i]], b = g.positions[g.indices[i + 1]], c = g.positions[g.indices[i + 2]];
    const Vec3 n = cross(b - a, c - a);
    for (int k = 0; k < 3; ++k) g.normals[g.indices[i + static_cast<std::size_t>(k)]] += n;
  }
  for (Vec3& n : g.normals) {
    const float l = length(n);
    n = l > 0 ? n / l : Vec3{0, 1, 0};
  }
}

// A lumpy sphere of about `triangles` triangles: a sphere whose radius varies smoothly with
// direction (`lumps` bumps around), so it is no perfect blob.
std::shared_ptr<const MeshGeometry> makeLumpy(std::uint64_t triangles, float lumps, float depth) {
  const int rings = std::max(4, static_cast<int>(std::sqrt(static_cast<double>(triangles) / 4.0)));
  auto sphere = makeSphere(rings, 2 * rings);
  auto g = std::make_shared<MeshGeometry>(*sphere);
  for (Vec3& p : g->positions) {
    const float theta = std::acos(std::clamp(p.y, -1.0f, 1.0f)), phi = std::atan2(p.z, p.x);
    p = p * (1.0f + depth * std::sin(lumps * theta) * std::cos(lumps * phi));
  }
  computeNormals(*g);
  return g;
}

// `count` leaves (two triangles each, about 6 cm) scattered in an ellipsoid of the given radii
// around the origin, facing every way.
std::shared_ptr<const MeshGeometry> makeFoliage(std::uint64_t count, Vec3 radii, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  auto g = std::make_shared<MeshGeometry>();
  g->positions.reserve(count * 4);
  g->indices.reserve(count * 6);
  for (std::uint64_t i = 0; i < count; ++i) {
    Vec3 c;
    do c = {u(rng), u(rng), u(rng)};
    while (dot(c, c) > 1.0f);
    c = {c.x * radii.x, c.y * radii.y, c.z * radii.z};
    Vec3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
    if (length(a) < 1e-3f) a = {1, 0, 0};
    a = normalize(a) * 0.03f;
    b = normalize(cross(a, length(cross(a, b)) < 1e-6f ? Vec3{0, 1, 0} : b)) * 0.02f;
    const auto base = static_cast<std::uint32_t>(g->positions.size());
    for (Vec3 p : {c - a - b, c + a - b, c + a + b, c - a + b}) {
      g->positions.push_back(p);
      g->uvs.push_back({0, 0});
    }
    g->indices.insert(g->indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  computeNormals(*g);
  return g;
}

Material material(const char* name, MaterialType type, Vec3 albedo, float roughness = 0.3f) {
  Material m;
  m.name = name;
  m.type = type;
  m.albedo = albedo;
  m.roughness = roughness;
  if (type == MaterialType::RoughConductor) m.metal = "Al";
  return m;
}

}  // namespace

Scene makeFurnishedRoom(std::uint64_t triangles) {
  triangles = std::max<std::uint64_t>(triangles, 4000);
  Scene s;
  s.settings.width = 320;
  s.settings.height = 180;
  s.settings.maxBounces = 16;
  s.settings.pixelFilter = PixelFilter::Box;
  s.settings.filterWidth = 1.0f;
  s.camera.position = {-2.6f, 1.6f, 2.2f};
  s.camera.target = {0.4f, 0.9f, -0.9f};
  s.camera.up = {0, 1, 0};
  s.camera.verticalFov = radians(55.0f);
  s.environment.type = EnvironmentType::Constant;  // seen through the window
  s.environment.color = Vec3{1.2f, 1.3f, 1.5f};
  std::mt19937 rng(7);

  // The room: 6 x 3 x 5 m, its walls facing in; a window hole in the left wall lets the sky in.
  const NodeId wall = addMaterial(s, material("Wall", MaterialType::Lambert, {0.72f, 0.7f, 0.66f}));
  const NodeId floorMat = addMaterial(s, material("Floor", MaterialType::RoughPlastic, {0.45f, 0.3f, 0.2f}, 0.25f));
  const NodeId quad = addMesh(s, "Quad", makeQuad());
  const NodeId cube = addMesh(s, "Cube", makeCube());
  addObject(s, "Floor", quad, floorMat, Mat4::scale({6, 1, 5}));
  addObject(s, "Ceiling", quad, wall, Mat4::translate({0, 3, 0}) * Mat4::rotateX(kPi) * Mat4::scale({6, 1, 5}));
  addObject(s, "Back wall", quad, wall, Mat4::translate({0, 1.5f, -2.5f}) * Mat4::rotateX(kPi / 2) * Mat4::scale({6, 1, 3}));
  addObject(s, "Front wall", quad, wall, Mat4::translate({0, 1.5f, 2.5f}) * Mat4::rotateX(-kPi / 2) * Mat4::scale({6, 1, 3}));
  addObject(s, "Right wall", quad, wall, Mat4::translate({3, 1.5f, 0}) * Mat4::rotateZ(kPi / 2) * Mat4::scale({3, 1, 5}));
  // The left wall in four pieces around a 1.6 x 1.2 m window.
  const Mat4 left = Mat4::translate({-3, 1.5f, 0}) * Mat4::rotateZ(-kPi / 2);
  addObject(s, "Left wall below", quad, wall, left * Mat4::translate({0.9f, 0, 0}) * Mat4::scale({1.2f, 1, 5}));
  addObject(s, "Left wall above", quad, wall, left * Mat4::translate({-1.05f, 0, 0}) * Mat4::scale({0.9f, 1, 5}));
  addObject(s, "Left wall back", quad, wall, left * Mat4::translate({-0.15f, 0, -1.65f}) * Mat4::scale({0.9f, 1, 1.7f}));
  addObject(s, "Left wall front", quad, wall, left * Mat4::translate({-0.15f, 0, 1.65f}) * Mat4::scale({0.9f, 1, 1.7f}));
  Material lamp = material("Ceiling light", MaterialType::Lambert, {0, 0, 0});
  lamp.emission = Vec3{12.0f, 11.0f, 9.5f};
  addObject(s, "Ceiling light", quad, addMaterial(s, lamp),
            Mat4::translate({0.5f, 2.98f, -0.5f}) * Mat4::rotateX(kPi) * Mat4::scale({1.0f, 1, 0.6f}));

  // The triangle budget: a statue 25 %, a sofa 18 %, a table and chairs 11 %, props 33 %, the
  // plants' leaves 10 % and pots 2 %.
  const auto share = [&](double f) { return static_cast<std::uint64_t>(static_cast<double>(triangles) * f); };
  addMeshObject(s, "Statue", makeLumpy(share(0.25), 9.0f, 0.12f),
                material("Bronze", MaterialType::RoughConductor, {0.9f, 0.75f, 0.5f}, 0.25f),
                Mat4::translate({2.2f, 0.55f, -1.8f}) * Mat4::scale({0.35f, 0.55f, 0.35f}));
  const NodeId fabric = addMaterial(s, material("Sofa fabric", MaterialType::Lambert, {0.55f, 0.12f, 0.1f}));
  for (int i = 0; i < 6; ++i) {
    const bool back = i >= 3;
    const float x = -0.9f + 0.7f * static_cast<float>(i % 3);
    const NodeId mesh = addMesh(s, "Cushion", makeLumpy(share(0.03), 5.0f, 0.04f));
    addObject(s, "Cushion", mesh, fabric,
              Mat4::translate({x, back ? 0.75f : 0.45f, back ? -2.15f : -1.8f}) *
                  Mat4::scale(back ? Vec3{0.34f, 0.3f, 0.1f} : Vec3{0.34f, 0.1f, 0.3f}));
  }
  const NodeId wood = addMaterial(s, material("Table wood", MaterialType::RoughPlastic, {0.35f, 0.2f, 0.1f}, 0.1f));
  addObject(s, "Table top", addMesh(s, "Table top", makeLumpy(share(0.07), 3.0f, 0.01f)), wood,
            Mat4::translate({0.4f, 0.75f, 0.3f}) * Mat4::scale({0.8f, 0.03f, 0.5f}));
  for (int i = 0; i < 4; ++i) {
    const float x = i % 2 ? 0.95f : -0.15f, z = i / 2 ? 0.65f : -0.05f;
    addObject(s, "Table leg", cube, wood, Mat4::translate({x, 0.37f, z}) * Mat4::scale({0.05f, 0.74f, 0.05f}));
    const NodeId seat = addMesh(s, "Chair seat", makeLumpy(share(0.01), 4.0f, 0.02f));
    const float cx = i % 2 ? 1.45f : -0.65f, cz = i / 2 ? 0.6f : 0.0f;
    addObject(s, "Chair seat", seat, fabric, Mat4::translate({cx, 0.45f, cz}) * Mat4::scale({0.22f, 0.05f, 0.22f}));
    addObject(s, "Chair leg", cube, wood, Mat4::translate({cx, 0.21f, cz}) * Mat4::scale({0.05f, 0.42f, 0.05f}));
  }
  // Shelves on the right wall, with props: 120 small objects of mixed materials.
  const NodeId shelfMat = addMaterial(s, material("Shelf", MaterialType::Lambert, {0.8f, 0.8f, 0.78f}));
  const NodeId propMats[] = {addMaterial(s, material("Ceramic", MaterialType::RoughPlastic, {0.85f, 0.85f, 0.8f}, 0.1f)),
                             addMaterial(s, material("Steel", MaterialType::RoughConductor, {1, 1, 1}, 0.15f)),
                             addMaterial(s, material("Paint", MaterialType::Lambert, {0.2f, 0.35f, 0.6f})),
                             addMaterial(s, material("Glaze", MaterialType::Plastic, {0.7f, 0.5f, 0.1f}))};
  constexpr int kProps = 120;
  const std::uint64_t perProp = std::max<std::uint64_t>(share(0.33) / kProps, 8);
  std::uniform_real_distribution<float> jitter(0.0f, 1.0f);
  for (int shelf = 0; shelf < 4; ++shelf) {
    const float y = 0.4f + 0.55f * static_cast<float>(shelf);
    addObject(s, "Shelf", cube, shelfMat, Mat4::translate({2.8f, y, 0.5f}) * Mat4::scale({0.35f, 0.03f, 2.6f}));
    for (int i = 0; i < kProps / 4; ++i) {
      const float size = 0.05f + 0.05f * jitter(rng);
      const float z = -0.75f + 2.5f * (static_cast<float>(i) + 0.5f) / (kProps / 4);
      const NodeId mesh = addMesh(s, "Prop", makeLumpy(perProp, 2.0f + static_cast<float>(i % 5), 0.1f));
      addObject(s, "Prop", mesh, propMats[(shelf + i) % 4],
                Mat4::translate({2.8f, y + 0.015f + size, z}) * Mat4::scale({size, size * (1.0f + jitter(rng)), size}));
    }
  }
  // Two plants of loose leaves in pots by the window.
  const NodeId leaf = addMaterial(s, material("Leaf", MaterialType::Lambert, {0.12f, 0.35f, 0.08f}));
  const NodeId pot = addMaterial(s, material("Pot", MaterialType::OrenNayar, {0.5f, 0.25f, 0.15f}, 0.5f));
  for (int i = 0; i < 2; ++i) {
    const float z = i ? 1.3f : -1.2f;
    addObject(s, "Pot", addMesh(s, "Pot", makeLumpy(std::max<std::uint64_t>(share(0.01), 200), 6.0f, 0.05f)), pot,
              Mat4::translate({-2.6f, 0.2f, z}) * Mat4::scale({0.18f, 0.2f, 0.18f}));
    addObject(s, "Leaves", addMesh(s, "Leaves", makeFoliage(share(0.05), {0.35f, 0.45f, 0.35f}, rng)), leaf,
              Mat4::translate({-2.6f, 0.85f, z}));
  }
  return s;
}

}  // namespace retile
