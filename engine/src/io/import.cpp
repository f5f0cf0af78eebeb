#include <algorithm>
#include <cstdlib>
#include <fstream>

#include "core/files.h"
#include "core/process.h"
#include "retile/io.h"
#include "retile/log.h"
#include "scene/validate.h"

namespace fs = std::filesystem;

namespace retile {
namespace {

fs::path importWorkerPath() {
  if (const char* env = std::getenv("RETILE_IMPORT_WORKER"); env && *env) return env;
  fs::path beside = executableDirectory() / "retile-import-worker";
  std::error_code ec;
  if (fs::exists(beside, ec)) return beside;
  // Installed (packaging/CMakeLists.txt): a helper, not a command, so not in bin/.
  fs::path installed = (executableDirectory() / ".." / "libexec" / "retile" / "retile-import-worker").lexically_normal();
  if (fs::exists(installed, ec)) return installed;
#ifdef RETILE_IMPORT_WORKER_BUILD_PATH
  return RETILE_IMPORT_WORKER_BUILD_PATH;
#else
  return beside;
#endif
}

std::string firstLineWithPrefix(const std::string& text, const std::string& prefix) {
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    if (line.rfind(prefix, 0) == 0) return line.substr(prefix.size());
    pos = end + 1;
  }
  return {};
}

}  // namespace

Result<ImportedScene> importAssimp(const fs::path& file, const ImportOptions& options) {
  using R = Result<ImportedScene>;
  std::error_code ec;
  if (!fs::exists(file, ec)) return R::failure(cat(file.string(), ": file not found"));
  if (fs::is_directory(file, ec)) return R::failure(cat(file.string(), ": is a directory, not a file"));
  auto size = fs::file_size(file, ec);
  if (!ec && size > options.maxFileBytes)
    return R::failure(cat(file.string(), ": file is ", size, " bytes, more than the limit of ", options.maxFileBytes));

  fs::path worker = importWorkerPath();
  ChildLimits limits;
  limits.timeout = options.assimpTimeout;
  limits.addressSpaceBytes = options.assimpMemoryLimit;
  ChildResult child = runChild(worker, {fs::absolute(file).string()}, limits);
  if (!child.started) return R::failure(cat(file.string(), ": cannot start the import worker ", worker.string(), ": ", child.startError));
  if (child.timedOut)
    return R::failure(cat(file.string(), ": the importer did not finish within ", options.assimpTimeout.count() / 1000.0,
                          " s and was stopped; nothing was loaded"));
  if (child.outputTooLarge) return R::failure(cat(file.string(), ": the imported scene is too large"));
  if (child.signal)
    return R::failure(cat(file.string(), ": the Assimp importer crashed on this file (", signalDescription(child.signal),
                          "); it ran in a separate process, so nothing else was affected, and nothing was loaded"));
  if (child.exitCode == 127) return R::failure(cat(file.string(), ": cannot run the import worker ", worker.string()));
  if (child.exitCode == 3)
    return R::failure(
        cat(file.string(), ": the importer ran out of memory (limit ", options.assimpMemoryLimit >> 20, " MiB); nothing was loaded"));
  if (child.exitCode != 0) {
    std::string why = firstLineWithPrefix(child.err, "error: ");
    if (why.empty()) why = firstLineWithPrefix(child.err, "assimp: ");
    if (why.empty()) why = cat("the importer failed (exit code ", child.exitCode, ")");
    return R::failure(cat(file.string(), ": ", why));
  }
  auto result = nativeSceneFromString(child.out, file, file.parent_path());
  if (!result) return R::failure(cat(file.string(), ": the import worker returned an unreadable scene: ", result.error()));
  result->format = cat("assimp:", extensionLower(file));
  std::size_t pos = 0;
  while (pos < child.err.size()) {
    std::size_t end = child.err.find('\n', pos);
    if (end == std::string::npos) end = child.err.size();
    std::string line = child.err.substr(pos, end - pos);
    if (line.rfind("warning: ", 0) == 0) result->warnings.push_back(line.substr(9));
    pos = end + 1;
  }
  return result;
}

namespace {

Result<ImportedScene> importByFormat(const fs::path& file, const ImportOptions& options) {
  using R = Result<ImportedScene>;
  std::error_code ec;
  if (!fs::exists(file, ec)) return R::failure(cat(file.string(), ": file not found"));
  if (fs::is_directory(file, ec)) return R::failure(cat(file.string(), ": is a directory, not a file"));
  std::string ext = extensionLower(file);
  if (ext == "retile") return loadNativeScene(file, options);
  if (ext == "json") {
    // Our native files are JSON too; tell them apart by their first bytes.
    std::ifstream in(file, std::ios::binary);
    std::string head(4096, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    head.resize(static_cast<std::size_t>(in.gcount()));
    if (head.find("\"retile-scene\"") != std::string::npos) return loadNativeScene(file, options);
    if (head.find("\"asset\"") != std::string::npos && head.find("\"version\"") != std::string::npos &&
        head.find("\"primitives\"") == std::string::npos)
      return importAssimp(file, options);  // a glTF file with a .json name
    return importTungsten(file, options);
  }
  return importAssimp(file, options);
}

}  // namespace

bool importReported(const std::string& renderWarning, const std::vector<std::string>& importWarnings) {
  const std::string file = fs::path(renderWarning.substr(0, renderWarning.find(": "))).filename().string();
  return !file.empty() &&
         std::any_of(importWarnings.begin(), importWarnings.end(), [&](const std::string& i) { return i.find(file) != std::string::npos; });
}

Result<ImportedScene> importScene(const fs::path& file, const ImportOptions& options) {
  auto imported = importByFormat(file, options);
  if (!imported) return imported;
  // Whatever read it, nothing past this point sees a value the renderer cannot take.
  std::vector<std::string> repairs;
  auto valid = validateScene(imported->scene, repairs);
  if (!valid) return Result<ImportedScene>::failure(cat(file.string(), ": ", valid.error()));
  for (const std::string& r : repairs) imported->warnings.push_back(cat(file.filename().string(), ": ", r));
  return imported;
}

}  // namespace retile
