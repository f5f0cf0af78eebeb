// The child-process side of Assimp imports: converts one file to a Scene and writes it to
// stdout in the native format; warnings go to stderr as "warning: " lines and a failure as an
// "error: " line with exit code 2. Only the retile-import-worker executable links this.
#pragma once

#include <filesystem>
#include <string>

#include "retile/error.h"

namespace retile {

int assimpWorkerMain(int argc, char** argv);

// What the worker does to one file, without the process around it: Assimp reads it, the result is
// converted and validated and comes back as native text (warnings are printed to stderr as they
// arise, so that those leading up to a crash still reach the user). Every refusal is a failure
// with a message; only std::bad_alloc (memory ran out) is thrown. For the worker and the conversion's fuzz target only: Assimp itself may
// crash or hang on hostile input, which is why the editor runs this in a child process.
Result<std::string> convertWithAssimp(const std::filesystem::path& file);

}  // namespace retile
