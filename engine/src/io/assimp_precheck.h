// Checks Assimp 5.2 skips, made before handing a file to it (in the import worker process).
// glTF: the specification requires a loader to refuse files that need a newer version or an
// extension it does not implement; Assimp loads them and renders them wrongly. OBJ: Assimp
// silently replaces a missing material library or an unknown `usemtl` by its default material.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "retile/error.h"

namespace retile {

// Fails with the reason when the file must be refused; otherwise returns the warnings to show
// (possibly none). Reads at most the file's header and text, never its binary payload.
Result<std::vector<std::string>> precheckAssimpInput(const std::filesystem::path& file);

}  // namespace retile
