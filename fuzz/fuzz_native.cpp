// The native scene reader (.retile files, and the text the import worker sends back): any bytes
// either fail with a message naming the file or give a scene that passes checkImportedScene.
#include "fuzz_scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace retile;
  std::string text(reinterpret_cast<const char*>(data), size);
  auto imported = nativeSceneFromString(text, "input.retile", fuzz::inputPath(""));
  if (!imported) {
    if (imported.error().find("input.retile") == std::string::npos)
      fuzz::invariant("an error that does not name the file", imported.error());
    return 0;
  }
  fuzz::checkImportedScene(imported->scene);
  return 0;
}
