// The Tungsten/Bitterli importer: any bytes either fail with a message naming the file or give a
// scene that passes checkImportedScene. Meshes and textures the file names are looked up beside
// it and are mostly missing, which is itself a path the importer must survive.
#include "fuzz_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace retile;
  auto file = fuzz::writeInput(data, size, "scene.json");
  auto imported = importTungsten(file);
  if (!imported) {
    if (imported.error().find("scene.json") == std::string::npos) fuzz::invariant("an error that does not name the file", imported.error());
    return 0;
  }
  fuzz::checkImportedScene(imported->scene);
  return 0;
}
