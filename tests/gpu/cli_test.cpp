// The command line as a user runs it, in a child process: here under a comma-decimal locale, where
// every fractional number in the scene file, on the command line and in the output must still be
// read and written with '.'.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/files.h"
#include "core/process.h"
#include "io/image_io.h"
#include "retile/image.h"
#include "retile/io.h"
#include "retile/log.h"
#include "test_support.h"

namespace retile {
namespace {

// Sets LC_ALL and LOCPATH for the children started while it lives.
class CommaLocaleEnvironment {
 public:
  explicit CommaLocaleEnvironment(const std::filesystem::path& dir) {
    ::setenv("LOCPATH", dir.c_str(), 1);
    ::setenv("LC_ALL", "de_DE.UTF-8", 1);
  }
  ~CommaLocaleEnvironment() { ::unsetenv("LC_ALL"); }
};

TEST(Cli, ImportAndRenderUnderACommaDecimalLocale) {
  RETILE_SHARED_OR_SKIP(scene, "scenes/cornell-box/scene.json");
  std::string error;
  std::filesystem::path locales = test::commaLocaleDir(&error);
  ASSERT_FALSE(locales.empty()) << error;
  CommaLocaleEnvironment env(locales);
  ChildLimits limits;
  limits.timeout = std::chrono::minutes(5);

  std::filesystem::path saved = test::tempDir() / "box.retile";
  ChildResult imported = runChild(RETILE_CLI_PATH, {"import", scene.string(), "--save", saved.string()}, limits);
  ASSERT_EQ(imported.exitCode, 0) << imported.err;
  EXPECT_NE(imported.out.find("8 objects"), std::string::npos) << imported.out;
  // Saved under the comma locale, read here under the C locale: the same scene, to the bit.
  auto original = importScene(scene);
  auto reread = loadNativeScene(saved);
  ASSERT_TRUE(original.ok()) << original.error();
  ASSERT_TRUE(reread.ok()) << reread.error();
  EXPECT_EQ(nativeSceneToString(reread->scene), nativeSceneToString(original->scene));

  std::filesystem::path out = test::tempDir() / "box.exr";
  ChildResult rendered = runChild(
      RETILE_CLI_PATH, {"render", scene.string(), "--size", "24x24", "--spp", "2", "--exposure", "0.5", "--out", out.string()}, limits);
  ASSERT_EQ(rendered.exitCode, 0) << rendered.err;
  auto image = readImageRaw(out);
  ASSERT_TRUE(image.ok()) << image.error();
  ASSERT_EQ(image->width, 24);
  double mean = 0;
  for (std::size_t i = 0; i < image->rgba.size(); i += 4) mean += image->rgba[i + 1];
  EXPECT_GT(mean / (24 * 24), 0.05) << "the box is lit: its light's fractional coordinates were read";

  ChildResult comma = runChild(RETILE_CLI_PATH, {"render", scene.string(), "--exposure", "0,5"}, limits);
  EXPECT_EQ(comma.exitCode, 2);
  EXPECT_NE(comma.err.find("'0,5' is not a number"), std::string::npos) << comma.err;
}

// A PNG shows the scene through the view its file asks for (a Tungsten camera's tonemap), unless
// --view says otherwise: the default render is byte for byte the one with that view named, and
// not the Standard view's.
TEST(Cli, APngIsShownThroughTheScenesViewUnlessToldOtherwise) {
  Scene s = makeDefaultScene();
  s.settings.view = "Raw";
  const auto dir = test::tempDir();
  ASSERT_TRUE(saveNativeScene(s, dir / "raw.retile").ok());
  ChildLimits limits;
  limits.timeout = std::chrono::minutes(5);
  auto render = [&](const std::string& name, const std::vector<std::string>& view) {
    std::vector<std::string> args = {"render", (dir / "raw.retile").string(), "--size", "16x16", "--spp", "2",
                                     "--out",  (dir / name).string()};
    args.insert(args.end(), view.begin(), view.end());
    ChildResult r = runChild(RETILE_CLI_PATH, args, limits);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    auto bytes = readFile(dir / name);
    return bytes.ok() ? bytes.value() : std::string();
  };
  const std::string byScene = render("scene.png", {}), raw = render("raw.png", {"--view", "Raw"}),
                    standard = render("standard.png", {"--view", "Standard"});
  ASSERT_FALSE(byScene.empty());
  EXPECT_EQ(byScene, raw);
  EXPECT_NE(byScene, standard);
}

// A render whose paths ran into the loop limit says so (they lack light: the image is biased), and
// one that did not says nothing. All of a frame's paths in one invocation run past the limit.
TEST(Cli, ARenderSaysWhenPathsWereCutAtTheLoopLimit) {
  const auto dir = test::tempDir();
  ChildLimits limits;
  limits.timeout = std::chrono::minutes(5);
  auto render = [&](const std::vector<std::string>& extra) {
    std::vector<std::string> args = {"render", "default", "--size", "192x108", "--spp", "1", "--out", (dir / "cut.png").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return runChild(RETILE_CLI_PATH, args, limits);
  };
  ChildResult cut = render({"--paths", std::to_string(192 * 108)});
  ASSERT_EQ(cut.exitCode, 0) << cut.err;
  EXPECT_NE(cut.err.find("were cut short, or never started, at the trace kernel's loop limit"), std::string::npos) << cut.err;
  ChildResult whole = render({});
  ASSERT_EQ(whole.exitCode, 0) << whole.err;
  EXPECT_EQ(whole.err.find("cut short"), std::string::npos) << whole.err;
}

// `retile compare` with a noise image lists the ratio by block size: noise averages away as blocks
// grow, a bias does not. Three synthetic images: the reference flat; ours at two seeds, each with
// its own noise and both 3 % brighter on the left half (the bias our renderer would have).
TEST(Cli, CompareTellsABiasFromNoiseByBlockSize) {
  const int w = 128, h = 64;
  auto image = [&](unsigned seed, float noise, float bias) {
    RenderImage im;
    im.width = w;
    im.height = h;
    im.color.resize(static_cast<std::size_t>(w * h * 3));
    std::uint32_t state = seed;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        state = state * 1664525u + 1013904223u;
        const float u = static_cast<float>(state >> 8) / static_cast<float>(1u << 24) - 0.5f;
        const float v = 0.5f * (1.0f + (x < w / 2 ? bias : 0.0f)) + noise * u;
        for (int c = 0; c < 3; ++c) im.color[static_cast<std::size_t>((y * w + x) * 3 + c)] = v;
      }
    return im;
  };
  const auto dir = test::tempDir();
  ASSERT_TRUE(writeRenderImage(image(1, 0.0f, 0.0f), dir / "ref.exr").ok());
  ASSERT_TRUE(writeRenderImage(image(2, 0.2f, 0.03f), dir / "a.exr").ok());
  ASSERT_TRUE(writeRenderImage(image(3, 0.2f, 0.03f), dir / "b.exr").ok());
  ChildLimits limits;
  limits.timeout = std::chrono::minutes(2);
  ChildResult r = runChild(RETILE_CLI_PATH,
                           {"compare", (dir / "a.exr").string(), (dir / "ref.exr").string(), "--noise", (dir / "b.exr").string()}, limits);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  auto ratioAt = [&](int size) {
    const std::string key = cat("block ", size < 10 ? " " : "", size, ": ");
    const std::size_t at = r.out.find(key);
    if (at == std::string::npos) return -1.0;
    const std::size_t ratio = r.out.find("ratio ", at);
    return std::atof(r.out.c_str() + ratio + 6);
  };
  const double one = ratioAt(1), big = ratioAt(32);
  ASSERT_GT(one, 0) << r.out;
  ASSERT_GT(big, 0) << r.out;
  EXPECT_LT(one, 1.2) << "per pixel the noise hides the bias\n" << r.out;
  EXPECT_GT(big, 3.0) << "over 32x32 blocks the bias stands out\n" << r.out;
  // Each 16x16 block's difference in units of its noise: the bias is 0.015, its standard error
  // 0.2 / sqrt(12) / 16 = 0.0036, so the 16 biased blocks of 32 stand out at z 4.2 (a few may
  // not: z scatters by 1) and the others stay within 3. The reference has no noise: with no bias the ratio would be sqrt(1 / 2).
  const std::size_t beyond = r.out.find(" blocks beyond 3");
  ASSERT_NE(beyond, std::string::npos) << r.out;
  const std::size_t countAt = r.out.rfind("; ", beyond) + 2;
  const int count = std::atoi(r.out.c_str() + countAt);
  EXPECT_GE(count, 10) << r.out;
  EXPECT_LE(count, 18) << r.out;
  const std::string key = "with no bias the ratio would be about ";
  const std::size_t expected = r.out.find(key);
  ASSERT_NE(expected, std::string::npos) << r.out;
  EXPECT_NEAR(std::atof(r.out.c_str() + expected + key.size()), std::sqrt(0.5), 0.05) << r.out;
}

// Each command explains itself: `--help` at every level exits 0 and lists the command's options
// (one CLI11 tree, so nothing the command reads is missing from its help).
TEST(Cli, HelpAtEveryLevelListsTheOptions) {
  struct Case {
    std::vector<std::string> args;
    std::vector<std::string> mentions;
  };
  const std::vector<Case> cases = {
      {{"--help"}, {"render", "edit", "eval", "compare", "bench", "import", "--version", "retile [SCENE]"}},
      {{"render", "--help"},
       {"Usage: retile render", "--spp", "--size", "--seed", "--max-bounces", "--out", "--view", "--exposure", "--denoise", "1..1048576"}},
      {{"edit", "-h"},
       {"--script", "--method", "--out-dir", "--stale-cap", "--no-images", "--quality", "--reference", "--threshold", "--denoise-threshold",
        "--no-soft-borders", "--reuse-rate", "spiral"}},
      {{"eval", "--help"},
       {"--quick", "--stability", "--methods", "--scenarios", "--script", "--reference-spp", "--every", "--target", "--cases", "ghosting"}},
      {{"compare", "--help"}, {"IMAGE", "REFERENCE", "--noise", "--block", "--exclude", "--worst"}},
      {{"import", "--help"}, {"FILE", "--save"}},
      {{"bench", "--help"}, {"throughput", "bvh", "edit", "frames", "denoise", "scale"}},
      {{"bench", "throughput", "--help"},
       {"Usage: retile bench throughput", "--paths", "--frames", "--max-bounces", "--size", "--spp-per-frame"}},
      {{"bench", "frames", "--help"}, {"--seconds", "--method", "--drag", "--object"}},
      {{"bench", "edit", "--help"}, {"--edits"}},
      {{"bench", "bvh", "--help"}, {"--triangles"}},
  };
  for (const Case& c : cases) {
    std::string line;
    for (const auto& a : c.args) line += " " + a;
    SCOPED_TRACE("retile" + line);
    ChildResult r = runChild(RETILE_CLI_PATH, c.args, ChildLimits{});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    for (const auto& m : c.mentions) EXPECT_NE(r.out.find(m), std::string::npos) << m << " in\n" << r.out;
  }
  ChildResult version = runChild(RETILE_CLI_PATH, {"-V"}, ChildLimits{});
  EXPECT_EQ(version.exitCode, 0);
  EXPECT_EQ(version.out.rfind("retile 0.", 0), 0u) << version.out;
}

// A mistyped value is refused before anything is loaded or rendered: exit 2 and a message naming
// the option, never a silent 0.
TEST(Cli, RefusesBadValuesNamingTheOption) {
  const std::filesystem::path out = test::tempDir() / "never.png";
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"render", "default", "--spp", "abc"}, "--spp: 'abc' is not a whole number"},
      {{"render", "default", "--spp", "0"}, "--spp: 0 is outside 1..1048576"},
      {{"render", "default", "--max-bounces", "2000"}, "--max-bounces: 2000 is outside 0..1024"},
      {{"render", "default", "--exposure", "x"}, "--exposure: 'x' is not a number"},
      {{"render", "default", "--size", "64x0"}, "--size: height 0 is outside 1..16384"},
      {{"render", "default", "--out", "a.jpg"}, "--out: 'a.jpg' must end in .png or .exr"},
      {{"render", "default", "--frobnicate", "2"}, "--frobnicate"},
      {{"render"}, "SCENE is required"},
      {{"edit", "default", "--script", "s.json", "--method", "spiral", "--out-dir", "d", "--threshold", "abc"},
       "--threshold: 'abc' is not a number"},
      {{"edit", "default", "--script", "s.json", "--method", "spirl", "--out-dir", "d"}, "unknown method 'spirl'"},
      {{"edit", "default", "--method", "spiral", "--out-dir", "d"}, "--script is required"},
      {{"edit", "default", "--script", "s.json", "--method", "spiral", "--out-dir", "d", "--reuse-rate", "0.1"},
       "--reuse-rate requires --reuse"},
      {{"eval", "--out-dir", "d", "--scenarios", "fig6,fig7"}, "unknown scenario 'fig7'"},
      {{"eval", "--out-dir", "d", "--cases", "burst"}, "--cases requires --stability"},
      {{"compare", "a.exr", "b.exr", "--exclude", "1,2,3"}, "--exclude: '1,2,3' is not X,Y,W,H"},
      {{"bench", "throughput", "default", "--paths", "-1"}, "--paths: -1 is outside 1..1048576"},
      {{"bench", "throughput", "default", "--spp-per-frame", "0"}, "--spp-per-frame: 0 is outside 1..1024"},
      {{"bench", "throughput", "default", "--size", "1920x1080", "--spp-per-frame", "1024"},
       "--spp-per-frame: 1024 samples per pixel at 1920x1080 make 2123366400 samples a frame, more than 16777216"},
      {{"bench", "throughput", "default", "--frames", "1e3"}, "--frames: '1e3' is not a whole number"},
      {{"bench", "fast"}, "unknown command 'fast'"},
  };
  for (Case c : cases) {
    std::string line;
    for (const auto& a : c.args) line += " " + a;
    SCOPED_TRACE("retile" + line);
    if (c.args[0] == "render" && std::find(c.args.begin(), c.args.end(), "--out") == c.args.end())
      c.args.insert(c.args.end(), {"--out", out.string()});
    ChildResult r = runChild(RETILE_CLI_PATH, c.args, ChildLimits{});
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("device:"), std::string::npos) << "refused before a renderer was made:\n" << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
}

// `retile eval --quick` as a reviewer runs it, with one method of each policy and the denoiser
// (every method runs in the stability suite): three scenarios, a report that opens offline, and
// references that a second run takes from disk.
TEST(Cli, EvalQuickWritesTheReportAndCachesReferences) {
  const std::filesystem::path out = test::tempDir() / "eval";
  ChildLimits limits;
  limits.timeout = std::chrono::minutes(10);
  ChildResult run = runChild(RETILE_CLI_PATH,
                             {"eval", "default", "--quick", "--methods", "global,spiral,focus,indirection,global+denoise", "--scenarios",
                              "fig6,material,light", "--out-dir", out.string()},
                             limits);
  ASSERT_EQ(run.exitCode, 0) << run.err;
  for (const char* f : {"index.html", "metrics.csv", "summary.csv"}) EXPECT_TRUE(std::filesystem::exists(out / f)) << f;

  auto metrics = readFile(out / "metrics.csv");
  ASSERT_TRUE(metrics) << metrics.error();
  EXPECT_EQ(metrics->rfind("scenario,scene,method,frame,ms,samples,rmse,psnr,ssim,psnr_hvs_m,rmse_affected,rmse_rest", 0), 0u);
  for (const char* m : {",global,", ",spiral,", ",focus,", ",indirection,", ",global+denoise,"})
    for (const char* sc : {"fig6,", "material,", "light,"})
      EXPECT_NE(metrics->find(std::string("\n") + sc + "default" + m), std::string::npos) << sc << m;

  // Nine charts, each a PNG with something drawn on it and an SVG beside it.
  int charts = 0;
  for (const auto& e : std::filesystem::directory_iterator(out / "charts")) {
    if (e.path().extension() != ".png") continue;
    ++charts;
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(e.path()).replace_extension(".svg"))) << e.path();
    auto img = readImageRaw(e.path());
    ASSERT_TRUE(img.ok()) << img.error();
    // Text and grid are grey; the methods' lines and points are the only colour. A line chart
    // has thousands of such pixels, the speed-against-accuracy chart 300 to 600 and under a
    // hundred when no method reached the target (their empty squares one over the other in the
    // "not reached" band, one square's outline about 80); a chart drawn without its layout (a
    // view never shown) shrinks into a corner of the page.
    std::size_t coloured = 0;
    for (std::size_t i = 0; i < img->rgba.size(); i += 4)
      coloured += std::max({std::abs(img->rgba[i] - img->rgba[i + 1]), std::abs(img->rgba[i + 1] - img->rgba[i + 2]),
                            std::abs(img->rgba[i] - img->rgba[i + 2])}) > 0.25f;
    const bool tradeoff = e.path().stem().string().ends_with("-tradeoff");
    EXPECT_GT(coloured, tradeoff ? 60u : 250u) << e.path() << ": methods drawn, not a blank chart";
  }
  EXPECT_EQ(charts, 9);
  EXPECT_TRUE(std::filesystem::exists(out / "strips" / "default-fig6.png"));
  auto page = readFile(out / "index.html");
  ASSERT_TRUE(page);
  EXPECT_NE(page->find("charts/default-fig6-tradeoff.png"), std::string::npos);

  // Again, one scenario: every reference comes from disk.
  ChildResult again =
      runChild(RETILE_CLI_PATH, {"eval", "--quick", "--methods", "spiral", "--scenarios", "material", "--out-dir", out.string()}, limits);
  ASSERT_EQ(again.exitCode, 0) << again.err;
  EXPECT_NE(again.err.find("references: 0 rendered, 2 reused"), std::string::npos) << again.err;
}

}  // namespace
}  // namespace retile
