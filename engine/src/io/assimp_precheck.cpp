#include "io/assimp_precheck.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "core/files.h"
#include "core/json.h"
#include "retile/log.h"

namespace retile {
namespace {

namespace fs = std::filesystem;

// Extensions Debian's Assimp 5.2.5 implements (its glTF2 importer; Draco through libdraco).
// A file that requires any other one cannot be shown as its author intended.
const std::set<std::string, std::less<>> kSupportedGltfExtensions = {
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_unlit",
    "KHR_lights_punctual",
    "KHR_texture_transform",
    "KHR_materials_sheen",
    "KHR_materials_clearcoat",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_ior",
    "KHR_draco_mesh_compression",
};

// "2.1" -> {2, 1}; anything unparsable -> nullopt.
std::optional<std::pair<int, int>> parseVersion(const std::string& v) {
  int major = 0, minor = 0;
  char dot = 0;
  std::istringstream in(v);
  if (!(in >> major >> dot >> minor) || dot != '.') return std::nullopt;
  return std::make_pair(major, minor);
}

Result<std::string> gltfJsonText(const fs::path& file, bool binary) {
  if (!binary) return readFile(file, std::uint64_t(1) << 30);
  std::ifstream in(file, std::ios::binary);
  std::array<std::uint32_t, 5> header{};
  if (!in.read(reinterpret_cast<char*>(header.data()), sizeof header))
    return Result<std::string>::failure("the file is shorter than a GLB header");
  if (header[0] != 0x46546C67u) return Result<std::string>::failure("the file does not start with the GLB magic 'glTF'");
  if (header[3] != 0x4E4F534Au) return Result<std::string>::failure("the first GLB chunk is not the JSON chunk");
  std::error_code ec;
  std::uint64_t size = fs::file_size(file, ec);
  if (ec || header[2] > size - std::min<std::uint64_t>(size, 20))
    return Result<std::string>::failure(cat("the JSON chunk claims ", header[2], " bytes, more than the file holds"));
  std::string text(header[2], '\0');
  if (!in.read(text.data(), static_cast<std::streamsize>(text.size()))) return Result<std::string>::failure("the JSON chunk is cut short");
  return text;
}

Result<std::vector<std::string>> checkGltf(const fs::path& file, bool binary) {
  auto text = gltfJsonText(file, binary);
  // Let Assimp report files we cannot even frame: its messages for those are specific enough.
  if (!text) return std::vector<std::string>{};
  auto root = json::parse(text.value());
  if (!root || !root->isObject()) return std::vector<std::string>{};
  if (const json::Value* asset = root->find("asset"); asset && asset->isObject()) {
    if (const json::Value* mv = asset->find("minVersion"); mv && mv->isString()) {
      auto v = parseVersion(mv->asString());
      if (!v) return Result<std::vector<std::string>>::failure(cat("asset.minVersion '", mv->asString(), "' is not a version number"));
      if (*v > std::make_pair(2, 0))
        return Result<std::vector<std::string>>::failure(
            cat("the file needs glTF ", mv->asString(), " or later (asset.minVersion); this importer reads glTF 2.0"));
    }
  }
  if (const json::Value* req = root->find("extensionsRequired"); req && req->isArray()) {
    std::vector<std::string> missing;
    for (const auto& e : req->asArray())
      if (e.isString() && !kSupportedGltfExtensions.count(e.asString())) missing.push_back(e.asString());
    if (!missing.empty()) {
      std::string list;
      for (const auto& m : missing) list += (list.empty() ? "" : ", ") + m;
      return Result<std::vector<std::string>>::failure(
          cat("the file requires the glTF extension", missing.size() > 1 ? "s " : " ", list, ", which this importer does not implement"));
    }
  }
  return std::vector<std::string>{};
}

std::string restOfLine(const std::string& line, std::size_t keywordLength) {
  std::string r = line.substr(std::min(line.size(), keywordLength));
  auto first = r.find_first_not_of(" \t");
  auto last = r.find_last_not_of(" \t\r");
  return first == std::string::npos ? std::string() : r.substr(first, last - first + 1);
}

bool startsWithKeyword(const std::string& line, std::string_view keyword) {
  return line.size() > keyword.size() && line.compare(0, keyword.size(), keyword) == 0 &&
         (line[keyword.size()] == ' ' || line[keyword.size()] == '\t');
}

std::vector<std::string> checkObj(const fs::path& file) {
  std::vector<std::string> warnings;
  std::ifstream in(file, std::ios::binary);
  std::set<std::string, std::less<>> used;
  std::vector<std::string> libraries;
  std::string line;
  while (std::getline(in, line)) {
    if (startsWithKeyword(line, "mtllib")) libraries.push_back(restOfLine(line, 6));
    else if (startsWithKeyword(line, "usemtl")) used.insert(restOfLine(line, 6));
  }
  std::set<std::string, std::less<>> defined;
  for (const auto& lib : libraries) {
    auto path = resolveScenePath(file.parent_path(), lib);
    if (!path) {
      warnings.push_back(cat("material library '", lib, "' not found; its materials are shown as default grey"));
      continue;
    }
    std::ifstream mtl(*path, std::ios::binary);
    while (std::getline(mtl, line))
      if (startsWithKeyword(line, "newmtl")) defined.insert(restOfLine(line, 6));
  }
  if (!warnings.empty()) return warnings;  // every usemtl would be reported again
  std::vector<std::string> unknown;
  for (const auto& u : used)
    if (!defined.count(u)) unknown.push_back(u);
  if (!unknown.empty()) {
    std::string list;
    for (std::size_t i = 0; i < unknown.size() && i < 5; ++i) list += (i ? ", '" : "'") + unknown[i] + "'";
    if (unknown.size() > 5) list += cat(" and ", unknown.size() - 5, " more");
    warnings.push_back(
        cat("usemtl names material", unknown.size() > 1 ? "s " : " ", list, " that no material library defines; shown as default grey"));
  }
  return warnings;
}

}  // namespace

Result<std::vector<std::string>> precheckAssimpInput(const fs::path& file) {
  std::string ext = extensionLower(file);
  if (ext == "gltf" || ext == "glb") return checkGltf(file, ext == "glb");
  if (ext == "obj") return checkObj(file);
  return std::vector<std::string>{};
}

}  // namespace retile
