// The dependency rules of docs/ARCHITECTURE.md, checked on the sources. Each test lists every
// offending line, not just the first, so one run shows the whole of a breach.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>

namespace fs = std::filesystem;

namespace {

fs::path sourceRoot() { return fs::path(RETILE_SOURCE_DIR); }

struct Include {
  std::string where;  // file:line
  std::string header;
};

// Every #include of the C++ sources under `dir`, with the header as written.
std::vector<Include> includes(const fs::path& dir) {
  static const std::regex pattern(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
  std::vector<Include> found;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::string ext = e.path().extension().string();
    if (ext != ".h" && ext != ".cpp" && ext != ".hpp") continue;
    std::ifstream in(e.path());
    std::string line;
    int n = 0;
    std::smatch m;
    while (std::getline(in, line)) {
      ++n;
      if (std::regex_search(line, m, pattern))
        found.push_back({fs::relative(e.path(), sourceRoot()).string() + ":" + std::to_string(n), m[1].str()});
    }
  }
  return found;
}

// The includes under `dir` whose header matches `forbidden`, one per line of the message.
std::string breaches(const fs::path& dir, const std::regex& forbidden, const std::regex& exempt = std::regex("^$")) {
  std::string out;
  for (const auto& inc : includes(dir)) {
    if (std::regex_search(inc.where, exempt)) continue;
    if (std::regex_search(inc.header, forbidden)) out += "  " + inc.where + ": " + inc.header + "\n";
  }
  return out;
}

TEST(Dependencies, EngineIncludesNoQt) {
  std::string found = breaches(sourceRoot() / "engine", std::regex(R"(^Q[A-Za-z]|^qt|/Q[A-Z])"));
  EXPECT_EQ(found, "") << "the engine is Qt-free:\n" << found;
}

TEST(Dependencies, PublicHeadersExposeNoThirdPartyOrPrivateHeaders) {
  std::string found =
      breaches(sourceRoot() / "engine" / "include",
               std::regex(R"(^(vulkan|assimp|OpenImageIO|OpenColorIO|glslang|core/|render/|vk/|io/|color/|schedule/|eval/|scene/))"));
  EXPECT_EQ(found, "") << "engine/include/retile names only standard C++ and engine types:\n" << found;
}

TEST(Dependencies, ScheduleIncludesOnlyCoreAndThePublicTypes) {
  // Every project header it includes is core/, schedule/ or a plain public header: every policy,
  // the planner and the budget arithmetic are testable without a GPU.
  std::string found = breaches(sourceRoot() / "engine" / "src" / "schedule",
                               std::regex(R"(^(vk|render|io|color|eval|scene|vulkan|assimp|OpenImageIO|OpenColorIO|glslang)[/.])"));
  EXPECT_EQ(found, "") << "schedule/ depends only on core/:\n" << found;
}

TEST(Dependencies, CoreLibraryNeverReachesTheRendererOrThirdPartyLibraries) {
  // retile_core (core, scene, io readers, schedule, eval's metrics and scenarios) links nothing but
  // the standard library; image I/O, the Assimp worker and the evaluation's runs (eval/eval.cpp,
  // eval/stability.cpp: sessions and references) belong to other targets.
  std::string found;
  for (const char* dir : {"core", "scene", "io", "schedule", "eval"})
    found += breaches(sourceRoot() / "engine" / "src" / dir,
                      std::regex(R"(^(vk/|render/|color/|vulkan|OpenImageIO|OpenColorIO|glslang|io/image_io))"),
                      std::regex(R"(io/(image_io|assimp_)|eval/(eval|stability)\.cpp)"));
  EXPECT_EQ(found, "") << "retile_core reaches no renderer, Vulkan, OIIO or OCIO:\n" << found;
}

TEST(Dependencies, ImportersNeverIncludeTheRenderer) {
  std::string found = breaches(sourceRoot() / "engine" / "src" / "io", std::regex(R"(^(render|vk|schedule)/)"));
  EXPECT_EQ(found, "") << "io/ never reaches render/, vk/ or schedule/:\n" << found;
}

TEST(Dependencies, TheEditorUsesOnlyThePublicEngineApi) {
  std::string found = breaches(sourceRoot() / "ui", std::regex(R"(^(core|render|vk|io|color|schedule|eval|scene)/)"));
  EXPECT_EQ(found, "") << "ui/ includes engine headers from engine/include/retile only:\n" << found;
}

TEST(Dependencies, TheRuleCheckerSeesIncludes) {
  // Guards the checker itself: a rule that finds nothing because the scan is broken would pass.
  EXPECT_NE(breaches(sourceRoot() / "engine" / "src" / "render", std::regex(R"(^vk/)")), "");
  EXPECT_NE(breaches(sourceRoot() / "ui", std::regex(R"(^Q)")), "");
}

}  // namespace
