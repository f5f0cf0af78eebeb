// The child-process side of Assimp imports: converts one file to a Scene and writes it to
// stdout in the native format; warnings go to stderr as "warning: " lines and a failure as an
// "error: " line with exit code 2. Only the retile-import-worker executable links this.
#pragma once

namespace retile {

int assimpWorkerMain(int argc, char** argv);

}  // namespace retile
