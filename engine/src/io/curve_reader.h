// Readers of strand files for Tungsten's "curves" primitive: Cem Yuksel's .hair format and
// Tungsten's .fiber format. Any thread.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "retile/error.h"
#include "retile/io.h"
#include "scene/curves.h"

namespace retile {

// Reads a .hair or .fiber file (by its extension). A file that is truncated, whose counts do not
// fit its size or each other, or that has no positions fails with a message naming the file; a
// strand with a node that is not finite is dropped, and a radius that is negative or not finite
// becomes 0, each with a warning.
Result<CurveSet> readCurves(const std::filesystem::path& path, std::vector<std::string>* warnings, const ImportOptions& options = {});

}  // namespace retile
