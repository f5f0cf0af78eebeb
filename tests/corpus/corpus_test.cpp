// Every file of ../shared/corpus goes through the importer: valid files load or fail with a
// message naming them; malformed files fail with such a message (or load with a warning saying
// what was dropped); nothing crashes or hangs this process.
#include <gtest/gtest.h>

#include "core/files.h"
#include "core/json.h"
#include "retile/io.h"
#include "test_support.h"

namespace retile {
namespace {

// Malformed files that Assimp 5.2.5 loads without logging anything, and that render as a sensible
// model (checked by eye at 96x96): there is no message to pass on. Any other malformed file that
// loads must carry a warning.
const char* const kSilentlyRepaired[] = {
    "assimp-IndexOutOfRange",                   // Assimp drops the bad triangle: 11 of 12 load
    "tinygltf-zero-sized-bin-chunk-issue-440",  // its one triangle loads intact
    "ufbx-fuzz_0003",                           // a mutated FBX whose cube still loads whole
    "assimp-malformed_property_index_oob",      // 3MF: the bad property index is ignored
};

bool silentlyRepaired(const std::string& path) {
  for (const char* name : kSilentlyRepaired)
    if (path.find(name) != std::string::npos) return true;
  return false;
}

// Files the glTF specification says a 2.0 loader must refuse.
bool mustBeRefused(const std::string& path) {
  return path.find("Compatibility_04-minVersion") != std::string::npos || path.find("Compatibility_05-extRequired") != std::string::npos;
}

TEST(Corpus, EveryFileImportsOrFailsCleanly) {
  RETILE_SHARED_OR_SKIP(manifest, "corpus/manifest.json");
  auto text = readFile(manifest);
  ASSERT_TRUE(text.ok());
  auto entries = json::parse(text.value());
  ASSERT_TRUE(entries.ok() && entries->isArray());
  ImportOptions options;
  options.assimpTimeout = std::chrono::milliseconds(30000);
  int loaded = 0, failed = 0;
  for (const auto& e : entries->asArray()) {
    std::string path = e.find("path")->asString();
    std::string category = e.find("category")->asString();
    auto file = manifest.parent_path() / path;
    SCOPED_TRACE(path);
    auto r = importScene(file, options);
    std::string name = file.filename().string();
    if (r.ok()) {
      ++loaded;
      EXPECT_FALSE(r->scene.objects.empty() && r->scene.lights.empty());
      if (category == "malformed" && !silentlyRepaired(path)) {
        EXPECT_FALSE(r->warnings.empty()) << "a malformed file loaded without any warning";
      }
      EXPECT_FALSE(mustBeRefused(path)) << "the glTF specification requires refusing this file";
    } else {
      ++failed;
      EXPECT_NE(r.error().find(name), std::string::npos) << "message does not name the file: " << r.error();
      EXPECT_GT(r.error().size(), name.size() + 10) << r.error();
    }
    std::printf("%-9s %-8s %s%s\n", category.c_str(), r.ok() ? "loaded" : "failed", path.c_str(),
                r.ok() ? (r->warnings.empty() ? "" : ("  (" + r->warnings[0] + ")").c_str()) : ("  " + r.error()).c_str());
  }
  std::printf("%d loaded, %d failed cleanly\n", loaded, failed);
  EXPECT_GT(loaded, 60);
}

}  // namespace
}  // namespace retile
