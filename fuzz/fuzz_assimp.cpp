// The import worker's conversion: Assimp reads the input (its format chosen by the first byte,
// among those the editor offers), our converter turns it into a Scene, validates it and writes
// native text, and the parent's reader must accept that text. Assimp is not instrumented and
// runs in a child process in the editor: a crash inside Assimp is not ours to fix here, so run
// this target with -fork and -ignore_crashes and read the crash's stack before acting on it.
#include "fuzz_scene.h"
#include "io/assimp_worker.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace retile;
  if (size < 1) return 0;
  static const char* const kExtensions[] = {".obj", ".gltf", ".glb", ".ply", ".stl", ".dae", ".fbx", ".off"};
  const char* ext = kExtensions[data[0] % (sizeof kExtensions / sizeof *kExtensions)];
  auto file = fuzz::writeInput(data + 1, size - 1, std::string("input") + ext);
  auto text = convertWithAssimp(file);
  if (!text) return 0;
  auto imported = nativeSceneFromString(text.value(), file, file.parent_path());
  if (!imported) fuzz::invariant("the parent refuses what the worker wrote", imported.error());
  fuzz::checkImportedScene(imported->scene);
  return 0;
}
