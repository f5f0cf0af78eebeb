// Synthetic scenes for benchmarks: sizes no shared scene has, built the same way every time.
#pragma once

#include <cstdint>

#include "retile/scene.h"

namespace retile {

// A furnished room of about `triangles` triangles (at least a few thousand): walls, floor and
// ceiling with a ceiling light and a window of sky, a statue, a sofa of cushions, a table with
// chairs, shelves of small props and two plants of loose leaves, each object its own mesh. A BVH
// sees what an interior gives it (large flat walls, many medium objects, foliage of small
// scattered triangles), not a single tessellated blob. Deterministic for a given count; pure data,
// any thread.
Scene makeFurnishedRoom(std::uint64_t triangles);

}  // namespace retile
