// Hair and fibre strands (Tungsten's "curves" primitive) and the tubes of triangles they are
// rendered as. Plain functions on values; any thread may call them.
//
// Tungsten intersects each strand's quadratic B-spline directly, as the front half of a round
// tube seen along the ray. Retile's kernel traces triangles only, so a strand becomes a closed
// tube of a few sides that follows the same spline with the same radius. A tube costs far more
// memory than the spline (about 2 KB of device memory per spline piece at the defaults, against
// Tungsten's 16 bytes a node), which is why makeCurveTubes works to a triangle budget.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "retile/scene.h"

namespace retile {

// Strands as Tungsten's CurveIO loads them: strand i is nodes [i ? ends[i - 1] : 0, ends[i]),
// the nodes the control points of a uniform quadratic B-spline (the strand runs from the
// midpoint of its first two nodes to the midpoint of its last two), each with a radius.
struct CurveSet {
  std::vector<std::uint32_t> ends;
  std::vector<Vec3> positions;
  std::vector<float> radii;

  std::size_t strandCount() const { return ends.size(); }
  // Quadratic pieces of all strands with at least three nodes (a strand of n has n - 2).
  std::size_t pieceCount() const;
};

// Tungsten's curve_thickness and curve_taper (Curves::loadCurves): `thickness`, when set, is
// every node's radius; a taper scales node k of a strand of n by 1 - (k - 0.5) / (n - 1).
void applyCurveThickness(CurveSet& curves, const float* thickness, bool taper);

struct CurveTubeOptions {
  int sides = 4;         // of each tube's cross-section, 3 or more
  int subdivisions = 2;  // straight sections per spline piece, before the budget
  std::uint64_t maxTriangles = 12'000'000;
};

struct CurveTubes {
  MeshGeometry geometry;
  std::size_t strandsKept = 0;  // strands with a tube (of those with three nodes or more)
  std::size_t strandsUsable = 0;
  int subdivisions = 0;  // what the budget allowed
  int sides = 0;
};

// One closed tube per strand of three nodes or more: `sides` faces around, outward facing, with
// smooth normals about the spline, and a flat cap at each end (a tube open at its ends would let
// a path that refracts into it leave through an end without crossing a surface). The polygon is
// scaled so that its width, averaged over the directions it is seen from, is the strand's
// diameter (its perimeter over pi). u runs along the strand from 0 to 1, v around it.
// Over the budget, the subdivisions drop to one, then the sides to three, then every k-th strand
// is kept.
CurveTubes makeCurveTubes(const CurveSet& curves, const CurveTubeOptions& options = {});

}  // namespace retile
