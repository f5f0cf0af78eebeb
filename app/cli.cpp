#include "cli.h"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <iostream>

#include "core/numbers.h"
#include "retile/log.h"

namespace retile::cli {

bool Args::has(const std::string& name) const {
  for (const auto& [k, v] : options)
    if (k == name) return true;
  return false;
}

std::string Args::get(const std::string& name, const std::string& fallback) const {
  for (const auto& [k, v] : options)
    if (k == name) return v;
  return fallback;
}

Result<Args> parseArgs(const std::vector<std::string>& argv, const std::vector<std::string>& known,
                       const std::vector<std::string>& flags) {
  Args a;
  for (std::size_t i = 0; i < argv.size(); ++i) {
    const std::string& s = argv[i];
    if (s.rfind("--", 0) != 0 || s == "--") {
      a.positional.push_back(s);
      continue;
    }
    std::string name = s, value;
    if (auto eq = s.find('='); eq != std::string::npos) {
      name = s.substr(0, eq);
      value = s.substr(eq + 1);
    }
    bool isFlag = std::find(flags.begin(), flags.end(), name) != flags.end();
    bool isKnown = std::find(known.begin(), known.end(), name) != known.end();
    if (!isFlag && !isKnown) return Result<Args>::failure(cat("unknown option ", name));
    if (isKnown && value.empty() && s.find('=') == std::string::npos) {
      if (i + 1 >= argv.size()) return Result<Args>::failure(cat("option ", name, " needs a value"));
      value = argv[++i];
    }
    a.options.emplace_back(name, value);
  }
  return a;
}

Result<int> parseInt(const std::string& option, const std::string& text, int lo, int hi) {
  int v = 0;
  auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size())
    return Result<int>::failure(cat(option, ": '", text, "' is not a whole number"));
  if (v < lo || v > hi) return Result<int>::failure(cat(option, ": ", v, " is outside ", lo, "..", hi));
  return v;
}

Result<double> parseNumber(const std::string& option, const std::string& text, double lo, double hi) {
  auto v = numbers::toDouble(text);
  if (!v || !std::isfinite(*v)) return Result<double>::failure(cat(option, ": '", text, "' is not a number"));
  if (*v < lo || *v > hi) return Result<double>::failure(cat(option, ": ", text, " is outside ", lo, "..", hi));
  return *v;
}

Result<bool> parseSize(const std::string& text, int* width, int* height) {
  auto x = text.find('x');
  if (x == std::string::npos) return Result<bool>::failure(cat("--size: '", text, "' is not WIDTHxHEIGHT"));
  auto w = parseInt("--size width", text.substr(0, x), 1, kMaxImageSide);
  if (!w) return Result<bool>::failure(w.error());
  auto h = parseInt("--size height", text.substr(x + 1), 1, kMaxImageSide);
  if (!h) return Result<bool>::failure(h.error());
  *width = w.value();
  *height = h.value();
  return true;
}

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
  for (const auto& w : renderWarnings) {
    // "FILE: problem": the importer has already reported a missing file; say the rest.
    std::string file = std::filesystem::path(w.substr(0, w.find(": "))).filename().string();
    bool known = !file.empty() && std::any_of(importWarnings.begin(), importWarnings.end(),
                                              [&](const std::string& i) { return i.find(file) != std::string::npos; });
    if (!known) std::fprintf(stderr, "warning: %s\n", w.c_str());
  }
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
  std::fprintf(stderr, "\r%s [%s] %d/%d  %.1f s elapsed, %.1f s left   ", label.c_str(), bar.c_str(), done, total,
               seconds, eta);
  if (done >= total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

int runImport(const std::vector<std::string>& argv) {
  auto args = parseArgs(argv, {});
  if (!args || args->positional.size() != 1) {
    std::fprintf(stderr, "usage: retile import FILE\n");
    return 2;
  }
  auto scene = loadScene(args->positional[0]);
  if (!scene) {
    std::fprintf(stderr, "error: %s\n", scene.error().c_str());
    return 1;
  }
  const Scene& s = scene->scene;
  for (const auto& w : scene->warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  std::printf("%s: %s scene: %zu objects, %zu meshes, %zu triangles, %zu materials, %zu textures, %zu lights\n",
              args->positional[0].c_str(), scene->format.c_str(), s.objects.size(), s.meshes.size(),
              s.triangleCount(), s.materials.size(), s.textures.size(), s.lights.size());
  return 0;
}

}  // namespace retile::cli
