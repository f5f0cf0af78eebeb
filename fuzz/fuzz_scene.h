// What every scene reader promises, checked on whatever it accepted: the import boundary's
// validation passes, the renderer's packing (BVH build, textures decoded, emitters) takes the
// scene, and the scene saves to native text that reads back and saves to the same text.
#pragma once

#include <string>
#include <vector>

#include "fuzz_support.h"
#include "render/render_scene.h"
#include "retile/edit.h"
#include "retile/io.h"
#include "scene/validate.h"

namespace retile::fuzz {

inline void checkImportedScene(Scene& scene) {
  std::vector<std::string> warnings;
  if (!validateScene(scene, warnings)) return;  // refused with a message: fine
  RenderSceneBuilder builder;
  builder.update(scene, kUpdateAll, &warnings);
  // A texture path that does not resolve beside the file is replaced by its recorded absolute
  // location on reading (native_scene.cpp), so the first round may change paths; from then on,
  // saving what was read must give the same text.
  auto roundTrip = [&](const std::string& text) {
    auto reread = nativeSceneFromString(text, "resaved.retile", scene.baseDirectory);
    if (!reread) invariant("a validated scene's native text does not read back", reread.error());
    return nativeSceneToString(reread->scene);
  };
  std::string saved = roundTrip(nativeSceneToString(scene));
  std::string again = roundTrip(saved);
  if (again != saved) {
    std::size_t at = 0;
    while (at < again.size() && at < saved.size() && again[at] == saved[at]) ++at;
    std::size_t from = at > 200 ? at - 200 : 0;
    invariant("save(read(save(scene))) differs from save(scene)",
              saved.substr(from, 400) + "\n--- read back and saved again:\n" + again.substr(from, 400));
  }
}

}  // namespace retile::fuzz
