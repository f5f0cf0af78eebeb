#include "cli.h"
#include "cli11.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <cstdio>
#include <memory>

#include "retile/log.h"

namespace retile::cli {

Result<ImportedScene> loadScene(const std::string& name) {
  if (name == "default") {
    ImportedScene s;
    s.scene = makeDefaultScene();
    s.format = "built-in";
    return s;
  }
  return importScene(name);
}

void printRenderWarnings(const std::vector<std::string>& renderWarnings, const std::vector<std::string>& importWarnings) {
  for (const auto& w : renderWarnings)
    if (!importReported(w, importWarnings)) std::fprintf(stderr, "warning: %s\n", w.c_str());
}

void progressBar(const std::string& label, int done, int total, double seconds) {
  // Redrawing in place needs a terminal; in a log (CI, a pipe) print one line per tenth instead.
  static const bool terminal = isatty(fileno(stderr)) != 0;
  if (!terminal) {
    // Progress may jump (a run converging without a report): print whenever a new tenth is
    // reached, and always the end.
    static std::string lastLabel;
    static int lastTenth = -1;
    const int tenths = total > 0 ? done * 10 / total : 10;
    if (label != lastLabel) lastLabel = label, lastTenth = -1;
    if (done < total && tenths <= lastTenth) return;
    lastTenth = tenths;
    const double eta = done > 0 ? seconds * (total - done) / done : 0;
    std::fprintf(stderr, "%s %d/%d  %.1f s, %.1f s left\n", label.c_str(), done, total, seconds, eta);
    return;
  }
  const int width = 30;
  int filled = total > 0 ? done * width / total : width;
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(width, '.');
  double eta = done > 0 ? seconds * (total - done) / done : 0;
  std::fprintf(stderr, "\r%s [%s] %d/%d  %.1f s elapsed, %.1f s left   ", label.c_str(), bar.c_str(), done, total, seconds, eta);
  if (done >= total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

namespace {

int runImport(const std::string& file, const std::string& saveAs) {
  auto scene = loadScene(file);
  if (!scene) {
    std::fprintf(stderr, "error: %s\n", scene.error().c_str());
    return 1;
  }
  const Scene& s = scene->scene;
  for (const auto& w : scene->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  std::printf("%s: %s scene: %zu objects, %zu meshes, %zu triangles, %zu materials, %zu textures, %zu lights\n", file.c_str(),
              scene->format.c_str(), s.objects.size(), s.meshes.size(), s.triangleCount(), s.materials.size(), s.textures.size(),
              s.lights.size());
  const Environment& e = s.environment;
  std::string environment = cat("environment: ", environmentTypeName(e.type));
  if (e.filled()) {
    const Vec3 a = e.mediumAbsorption, sc = e.mediumScattering;
    environment += cat("; a medium fills the world: absorption (", a.x, ", ", a.y, ", ", a.z, "), scattering (", sc.x, ", ", sc.y, ", ",
                       sc.z, "), anisotropy ", e.mediumAnisotropy);
  }
  std::printf("%s\n", environment.c_str());
  if (!saveAs.empty()) {
    auto saved = saveNativeScene(s, saveAs);
    if (!saved) {
      std::fprintf(stderr, "error: %s\n", saved.error().c_str());
      return 1;
    }
    std::printf("saved as %s\n", saveAs.c_str());
  }
  return 0;
}

}  // namespace

void addImport(CLI::App& app, int* status) {
  CLI::App* cmd = app.add_subcommand("import", "Import a scene and say what it holds (objects, meshes, triangles, ...)");
  auto file = std::make_shared<std::string>();
  cmd->add_option("FILE", *file, "a scene file (glTF, OBJ, FBX, PLY, Tungsten scene.json, .retile) or 'default'")
      ->required()
      ->type_name("");
  auto saveAs = std::make_shared<std::string>();
  cmd->add_option("--save", *saveAs, "also save the imported scene in Retile's own format (.retile), atomically")->type_name("OUT.retile");
  cmd->callback([file, saveAs, status] { *status = runImport(*file, *saveAs); });
}

}  // namespace retile::cli
