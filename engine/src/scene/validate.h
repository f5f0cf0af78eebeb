// The import boundary's check: every scene an importer returns (native, Tungsten, OBJ, or the
// import worker's conversion of whatever Assimp read) passes through validateScene before anything
// else sees it, so that no value from a file can crash or hang the renderer. Pure; any thread.
#pragma once

#include <string>
#include <vector>

#include "retile/error.h"
#include "retile/scene.h"

namespace retile {

// Coordinates beyond this are taken as garbage (an out-of-bounds read in a hostile file gives
// values near the float limit): float keeps about 7 digits, so geometry that far out cannot sit
// beside anything of a visible size. Real scenes stay many orders of magnitude inside it.
constexpr float kMaxCoordinate = 1e12f;

// Repairs what can be repaired and says what it did, one warning per kind of fault and item
// (triangles with non-finite or absurd vertices or indices past the vertex list are dropped,
// normals and uvs of the wrong count are dropped, an unusable camera frames the scene, material,
// light and environment values outside their ranges are clamped or reset, render settings are
// clamped). Fails, naming nothing (the caller adds the file), only when no triangle and no light
// is left of a scene that had some.
Result<bool> validateScene(Scene& scene, std::vector<std::string>& warnings);

}  // namespace retile
