#include "scene/curves.h"

#include <algorithm>
#include <cmath>

namespace retile {

namespace {

std::uint32_t strandStart(const CurveSet& c, std::size_t i) { return i ? c.ends[i - 1] : 0; }

// The uniform quadratic B-spline of control points a, b, c at t in [0, 1] (Tungsten's
// BSpline::quadratic), and its derivative.
template <typename T>
T spline(T a, T b, T c, float t) {
  return (0.5f * a - b + 0.5f * c) * (t * t) + (b - a) * t + 0.5f * (a + b);
}
Vec3 splineDerivative(Vec3 a, Vec3 b, Vec3 c, float t) { return (a - 2.0f * b + c) * t + (b - a); }

// Some unit vector perpendicular to t.
Vec3 perpendicular(Vec3 t) {
  Vec3 axis = std::abs(t.x) < 0.6f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  return normalize(cross(t, axis));
}

struct Ring {
  Vec3 centre;
  float radius;
  Vec3 tangent;
};

}  // namespace

std::size_t CurveSet::pieceCount() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < ends.size(); ++i) {
    const std::uint32_t nodes = ends[i] - strandStart(*this, i);
    n += nodes >= 3 ? nodes - 2 : 0;
  }
  return n;
}

void applyCurveThickness(CurveSet& curves, const float* thickness, bool taper) {
  if (!thickness && !taper) return;
  for (std::size_t i = 0; i < curves.ends.size(); ++i) {
    const std::uint32_t start = strandStart(curves, i), end = curves.ends[i];
    for (std::uint32_t t = start; t < end; ++t) {
      float r = thickness ? *thickness : curves.radii[t];
      // Tungsten's formula, which for a strand of one node divides by zero; such a strand
      // draws nothing anyway.
      if (taper && end - start > 1) r *= 1.0f - (static_cast<float>(t - start) - 0.5f) / static_cast<float>(end - start - 1);
      curves.radii[t] = r;
    }
  }
}

CurveTubes makeCurveTubes(const CurveSet& curves, const CurveTubeOptions& options) {
  CurveTubes out;
  int sides = std::max(options.sides, 3);
  std::size_t pieces = 0;
  for (std::size_t i = 0; i < curves.ends.size(); ++i) {
    const std::uint32_t nodes = curves.ends[i] - strandStart(curves, i);
    if (nodes >= 3) {
      ++out.strandsUsable;
      pieces += nodes - 2;
    }
  }
  // Triangles: two per side per section, and sides - 2 per cap.
  auto triangles = [&](int subdivisions, std::size_t strands, std::size_t pieceCount) {
    return std::uint64_t(pieceCount) * std::uint64_t(subdivisions) * std::uint64_t(2 * sides) +
           std::uint64_t(strands) * std::uint64_t(2 * (sides - 2));
  };
  // Over the budget: one section a piece, then three sides (hair's shading looks only at the
  // tube's direction, not its shape: the sides change only its outline), then fewer strands.
  int subdivisions = std::max(options.subdivisions, 1);
  if (triangles(subdivisions, out.strandsUsable, pieces) > options.maxTriangles) subdivisions = 1;
  if (triangles(subdivisions, out.strandsUsable, pieces) > options.maxTriangles) sides = 3;
  std::size_t stride = 1;
  const std::uint64_t whole = triangles(subdivisions, out.strandsUsable, pieces);
  if (whole > options.maxTriangles)
    stride = static_cast<std::size_t>((whole + options.maxTriangles - 1) / std::max<std::uint64_t>(options.maxTriangles, 1));
  out.subdivisions = subdivisions;
  out.sides = sides;

  // A regular polygon of circumradius R is, averaged over the directions it is seen from, as
  // wide as its perimeter over pi: 2 sides R sin(pi / sides) / pi, which this makes 2 r.
  const float widen = kPi / (static_cast<float>(sides) * std::sin(kPi / static_cast<float>(sides)));
  MeshGeometry& g = out.geometry;
  std::vector<Ring> rings;
  std::size_t usable = 0;
  for (std::size_t i = 0; i < curves.ends.size(); ++i) {
    const std::uint32_t start = strandStart(curves, i), end = curves.ends[i];
    if (end - start < 3) continue;
    if (usable++ % stride != 0) continue;
    rings.clear();
    for (std::uint32_t p = start; p + 2 < end; ++p) {
      const Vec3 a = curves.positions[p], b = curves.positions[p + 1], c = curves.positions[p + 2];
      const float ra = curves.radii[p], rb = curves.radii[p + 1], rc = curves.radii[p + 2];
      for (int k = p == start ? 0 : 1; k <= subdivisions; ++k) {
        const float t = static_cast<float>(k) / static_cast<float>(subdivisions);
        rings.push_back({spline(a, b, c, t), std::max(spline(ra, rb, rc, t), 0.0f) * widen, splineDerivative(a, b, c, t)});
      }
    }
    // Along the strand, the ring's axes are carried from one ring to the next (each projected
    // off the new tangent), so that the tube does not twist. A tangent of zero length (nodes
    // repeated) keeps the previous one.
    Vec3 tangent = normalize(rings.front().tangent);
    for (const Ring& r : rings)
      if (length(r.tangent) > 0) {
        tangent = normalize(r.tangent);
        break;
      }
    if (length(tangent) == 0) tangent = {0, 1, 0};  // every node in one place: a tube of no length
    Vec3 n = perpendicular(tangent);
    const auto base = static_cast<std::uint32_t>(g.positions.size());
    const float strandLength = static_cast<float>(rings.size() - 1);
    for (std::size_t r = 0; r < rings.size(); ++r) {
      if (Vec3 t = normalize(rings[r].tangent); length(t) > 0) {
        tangent = t;
        Vec3 projected = n - tangent * dot(n, tangent);
        n = length(projected) > 1e-6f ? normalize(projected) : perpendicular(tangent);
      }
      const Vec3 b = cross(tangent, n);
      for (int s = 0; s < sides; ++s) {
        const float phi = 2 * kPi * static_cast<float>(s) / static_cast<float>(sides);
        const Vec3 dir = n * std::cos(phi) + b * std::sin(phi);
        g.positions.push_back(rings[r].centre + dir * rings[r].radius);
        g.normals.push_back(dir);
        g.uvs.push_back({static_cast<float>(r) / strandLength, static_cast<float>(s) / static_cast<float>(sides)});
      }
    }
    // Counter-clockwise seen from outside: (ring r, side s), (r, s + 1), (r + 1, s) turns about
    // cross(tangent x dir, tangent) = dir.
    auto at = [&](std::size_t r, int s) { return base + static_cast<std::uint32_t>(r * sides + (s % sides)); };
    for (std::size_t r = 0; r + 1 < rings.size(); ++r)
      for (int s = 0; s < sides; ++s)
        g.indices.insert(g.indices.end(), {at(r, s), at(r, s + 1), at(r + 1, s), at(r, s + 1), at(r + 1, s + 1), at(r + 1, s)});
    // The caps: their own vertices, with the axis as their normal, fanned out to face away.
    for (int cap = 0; cap < 2; ++cap) {
      const std::size_t r = cap == 0 ? 0 : rings.size() - 1;
      const auto capBase = static_cast<std::uint32_t>(g.positions.size());
      Vec3 outward = normalize(rings[r].tangent);
      if (length(outward) == 0) outward = tangent;
      if (cap == 0) outward = -outward;
      for (int s = 0; s < sides; ++s) {
        g.positions.push_back(g.positions[at(r, s)]);
        g.normals.push_back(outward);
        g.uvs.push_back(g.uvs[at(r, s)]);
      }
      for (int s = 1; s + 1 < sides; ++s) {
        std::uint32_t a = capBase, b = capBase + static_cast<std::uint32_t>(s), c = capBase + static_cast<std::uint32_t>(s + 1);
        // The ring's order turns about the tangent: the start cap is wound the other way.
        if (cap == 0) std::swap(b, c);
        g.indices.insert(g.indices.end(), {a, b, c});
      }
    }
    ++out.strandsKept;
  }
  return out;
}

}  // namespace retile
