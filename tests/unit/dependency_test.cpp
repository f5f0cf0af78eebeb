// The dependency rules of docs/ARCHITECTURE.md, checked on the sources: the engine never
// includes Qt, and its public headers name no Vulkan, Assimp, OpenImageIO or OpenColorIO type.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>

namespace fs = std::filesystem;

namespace {

fs::path sourceRoot() { return fs::path(RETILE_TEST_DATA_DIR).parent_path().parent_path(); }

std::vector<std::string> offenders(const fs::path& dir, const std::regex& pattern) {
  std::vector<std::string> found;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path());
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      if (std::regex_search(line, pattern)) found.push_back(e.path().string() + ":" + std::to_string(n) + ": " + line);
    }
  }
  return found;
}

TEST(Dependencies, EngineIncludesNoQt) {
  auto found = offenders(sourceRoot() / "engine", std::regex(R"(#\s*include\s*[<"]Q[A-Za-z])"));
  EXPECT_TRUE(found.empty()) << found.front();
}

TEST(Dependencies, PublicHeadersExposeNoThirdPartyTypes) {
  auto found = offenders(sourceRoot() / "engine" / "include",
                         std::regex(R"(#\s*include\s*[<"](vulkan|assimp|OpenImageIO|OpenColorIO|glslang))"));
  EXPECT_TRUE(found.empty()) << found.front();
}

TEST(Dependencies, ScheduleDependsOnlyOnCore) {
  fs::path schedule = sourceRoot() / "engine" / "src" / "schedule";
  if (!fs::exists(schedule)) GTEST_SKIP() << "no schedule module yet";
  auto found = offenders(schedule, std::regex(R"(#\s*include\s*[<"](vk/|render/|io/|color/|vulkan))"));
  EXPECT_TRUE(found.empty()) << found.front();
}

}  // namespace
