// Our own OBJ reader for the meshes that Tungsten scenes reference. Assimp reads OBJ files that
// the user opens directly (with their .mtl); Tungsten meshes carry no materials and can number in
// the hundreds, where one child process per file would cost seconds.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <unordered_map>

#include "core/files.h"
#include "core/numbers.h"
#include "retile/io.h"
#include "retile/log.h"

namespace retile {
namespace {

struct Cursor {
  const char* p;
  const char* end;
  void skipSpace() {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
  }
  bool atLineEnd() {
    skipSpace();
    return p >= end || *p == '\n' || *p == '#';
  }
  void nextLine() {
    while (p < end && *p != '\n') ++p;
    if (p < end) ++p;
  }
  bool readFloat(float& v) {
    skipSpace();
    // from_chars rejects a leading '+', which some exporters write.
    if (p < end && *p == '+') ++p;
    // An underflow (1e-50) reads as 0 and an overflow as infinity; "nan" and "inf" read as
    // themselves, and the sanitizer drops non-finite vertices and counts them.
    const char* next = numbers::read(p, end, &v);
    if (!next) return false;
    p = next;
    return true;
  }
  bool readInt(long& v) {
    auto r = std::from_chars(p, end, v);
    if (r.ec != std::errc()) return false;
    p = r.ptr;
    return true;
  }
};

struct Key {
  long v, t, n;
  bool operator==(const Key&) const = default;
};
struct KeyHash {
  std::size_t operator()(const Key& k) const {
    return std::hash<long>()(k.v) ^ (std::hash<long>()(k.t) * 31) ^ (std::hash<long>()(k.n) * 1009);
  }
};

}  // namespace

Result<MeshGeometry> readObjGeometry(const std::filesystem::path& file, std::vector<std::string>* warnings, const ImportOptions& options) {
  auto text = readFile(file, options.maxFileBytes);
  if (!text) return Result<MeshGeometry>::failure(text.error());
  const std::string& s = text.value();
  Cursor c{s.data(), s.data() + s.size()};

  std::vector<Vec3> pos, nrm;
  std::vector<Vec2> tex;
  MeshGeometry g;
  std::unordered_map<Key, std::uint32_t, KeyHash> vertexOf;
  std::vector<std::uint32_t> poly;
  std::size_t badFaces = 0;
  int line = 1;

  auto fail = [&](const std::string& what) { return Result<MeshGeometry>::failure(cat(file.string(), ": line ", line, ": ", what)); };

  for (; c.p < c.end; ++line) {
    c.skipSpace();
    if (c.p >= c.end) break;
    const char* lineStart = c.p;
    if (*c.p == 'v' && c.p + 1 < c.end && (c.p[1] == ' ' || c.p[1] == '\t')) {
      c.p += 1;
      Vec3 v;
      if (!c.readFloat(v.x) || !c.readFloat(v.y) || !c.readFloat(v.z)) return fail("malformed vertex position");
      pos.push_back(v);
    } else if (c.p + 2 < c.end && c.p[0] == 'v' && c.p[1] == 'n') {
      c.p += 2;
      Vec3 v;
      if (!c.readFloat(v.x) || !c.readFloat(v.y) || !c.readFloat(v.z)) return fail("malformed vertex normal");
      nrm.push_back(v);
    } else if (c.p + 2 < c.end && c.p[0] == 'v' && c.p[1] == 't') {
      c.p += 2;
      Vec2 v;
      if (!c.readFloat(v.x)) return fail("malformed texture coordinate");
      if (!c.atLineEnd() && !c.readFloat(v.y)) return fail("malformed texture coordinate");
      tex.push_back(v);
    } else if (*c.p == 'f' && c.p + 1 < c.end && (c.p[1] == ' ' || c.p[1] == '\t')) {
      c.p += 1;
      poly.clear();
      bool bad = false;
      while (!c.atLineEnd()) {
        long idx[3] = {0, 0, 0};
        if (!c.readInt(idx[0])) return fail("malformed face index");
        for (int k = 1; k < 3 && c.p < c.end && *c.p == '/'; ++k) {
          ++c.p;
          if (c.p < c.end && *c.p != '/' && *c.p != ' ' && *c.p != '\t' && *c.p != '\n' && *c.p != '\r') {
            if (!c.readInt(idx[k])) return fail("malformed face index");
          }
        }
        // Negative indices count back from the latest element; 0 is invalid in OBJ.
        auto resolve = [&](long i, std::size_t count) -> long {
          if (i > 0) return i - 1 < static_cast<long>(count) ? i - 1 : -2;
          if (i < 0) return static_cast<long>(count) + i >= 0 ? static_cast<long>(count) + i : -2;
          return -1;
        };
        Key key{resolve(idx[0], pos.size()), resolve(idx[1], tex.size()), resolve(idx[2], nrm.size())};
        if (key.v < 0 || key.t == -2 || key.n == -2) {
          bad = true;
          continue;
        }
        auto [it, inserted] = vertexOf.try_emplace(key, static_cast<std::uint32_t>(g.positions.size()));
        if (inserted) {
          g.positions.push_back(pos[static_cast<std::size_t>(key.v)]);
          g.normals.push_back(key.n >= 0 ? nrm[static_cast<std::size_t>(key.n)] : Vec3{0, 0, 0});
          g.uvs.push_back(key.t >= 0 ? tex[static_cast<std::size_t>(key.t)] : Vec2{0, 0});
        }
        poly.push_back(it->second);
      }
      if (bad || poly.size() < 3) {
        ++badFaces;
      } else {
        for (std::size_t i = 1; i + 1 < poly.size(); ++i) g.indices.insert(g.indices.end(), {poly[0], poly[i], poly[i + 1]});
        if (g.indices.size() / 3 > options.maxTriangles) return fail(cat("more than ", options.maxTriangles, " triangles"));
      }
    }
    (void)lineStart;
    c.nextLine();
  }

  if (badFaces && warnings) warnings->push_back(cat(file.string(), ": skipped ", badFaces, " faces with missing or out-of-range indices"));
  if (nrm.empty()) g.normals.clear();
  if (tex.empty()) g.uvs.clear();
  std::size_t dropped = sanitizeGeometry(g);
  if (dropped && warnings) warnings->push_back(cat(file.string(), ": dropped ", dropped, " triangles with NaN or infinite vertices"));
  if (g.indices.empty()) return Result<MeshGeometry>::failure(cat(file.string(), ": contains no triangles"));
  return g;
}

std::size_t sanitizeGeometry(MeshGeometry& g, std::vector<std::int32_t>* perTriangle) {
  std::size_t n = g.positions.size();
  if (g.normals.size() != n) g.normals.clear();
  if (g.uvs.size() != n) g.uvs.clear();
  for (Vec3& v : g.normals)
    if (!isFinite(v)) v = {0, 0, 0};  // zero means "use the geometric normal"
  for (Vec2& t : g.uvs)
    if (!std::isfinite(t.x) || !std::isfinite(t.y)) t = {0, 0};
  std::vector<std::uint32_t> kept;
  kept.reserve(g.indices.size());
  std::size_t dropped = 0;
  for (std::size_t i = 0; i + 2 < g.indices.size(); i += 3) {
    bool ok = true;
    for (int k = 0; k < 3; ++k) {
      std::uint32_t idx = g.indices[i + static_cast<std::size_t>(k)];
      if (idx >= n || !isFinite(g.positions[idx])) ok = false;
    }
    if (ok) {
      if (perTriangle && i / 3 < perTriangle->size()) (*perTriangle)[kept.size() / 3] = (*perTriangle)[i / 3];
      kept.insert(kept.end(), g.indices.begin() + static_cast<std::ptrdiff_t>(i), g.indices.begin() + static_cast<std::ptrdiff_t>(i) + 3);
    } else {
      ++dropped;
    }
  }
  dropped += (g.indices.size() % 3) ? 1 : 0;
  if (perTriangle) perTriangle->resize(std::min(perTriangle->size(), kept.size() / 3));
  g.indices = std::move(kept);
  // Every position a kept triangle uses is finite now; one that is not belongs to no triangle (a
  // dropped one, or a face a reader skipped) but would still reach the bounds.
  if (dropped || std::any_of(g.positions.begin(), g.positions.end(), [](const Vec3& p) { return !isFinite(p); })) {
    // Compact: vertices no triangle uses go.
    std::vector<std::uint32_t> remap(n, UINT32_MAX);
    MeshGeometry out;
    for (std::uint32_t& idx : g.indices) {
      if (remap[idx] == UINT32_MAX) {
        remap[idx] = static_cast<std::uint32_t>(out.positions.size());
        out.positions.push_back(g.positions[idx]);
        if (!g.normals.empty()) out.normals.push_back(g.normals[idx]);
        if (!g.uvs.empty()) out.uvs.push_back(g.uvs[idx]);
      }
      idx = remap[idx];
    }
    out.indices = std::move(g.indices);
    g = std::move(out);
  }
  return dropped;
}

}  // namespace retile
