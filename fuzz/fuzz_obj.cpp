// The OBJ reader (Tungsten's meshes): any bytes either fail with a message naming the file or
// give a mesh the renderer can take: finite positions, every index inside the vertex list,
// normals and uvs either absent or one per vertex.
#include <cmath>

#include "fuzz_support.h"
#include "retile/io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace retile;
  auto file = fuzz::writeInput(data, size, "input.obj");
  std::vector<std::string> warnings;
  auto mesh = readObjGeometry(file, &warnings);
  if (!mesh) {
    if (mesh.error().find("input.obj") == std::string::npos) fuzz::invariant("an error that does not name the file", mesh.error());
    return 0;
  }
  const MeshGeometry& g = mesh.value();
  for (const Vec3& p : g.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) fuzz::invariant("a non-finite position");
  for (auto i : g.indices)
    if (static_cast<std::size_t>(i) >= g.positions.size()) fuzz::invariant("an index past the vertex list");
  if (g.indices.size() % 3 != 0) fuzz::invariant("indices that are not whole triangles");
  if (!g.normals.empty() && g.normals.size() != g.positions.size()) fuzz::invariant("normals of the wrong count");
  if (!g.uvs.empty() && g.uvs.size() != g.positions.size()) fuzz::invariant("uvs of the wrong count");
  return 0;
}
