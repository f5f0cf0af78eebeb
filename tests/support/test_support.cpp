#include "test_support.h"

#include "core/process.h"

#include <atomic>
#include <cstdio>
#include <mutex>
#include <vector>
#include <clocale>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <unistd.h>

namespace fs = std::filesystem;

namespace retile::test {

namespace {
// The suites drive lavapipe as retile's command line does (core/process.h), but for the editor's
// (RETILE_TEST_EDITOR_LANES: gui_tests; gui_vulkan_tests does not link this), which stay at the
// width the editor runs at, so that its kernels' subgroup size is tested too. Before main, while
// the process has one thread, as setenv needs.
#ifndef RETILE_TEST_EDITOR_LANES
[[maybe_unused]] const bool kWideCpuVectors = (preferWideCpuVectors(), true);
#endif
}  // namespace

fs::path sharedDir() {
  if (const char* env = std::getenv("RETILE_SHARED"); env && *env) return env;
  return RETILE_SHARED_DIR;
}

fs::path sharedPath(const std::string& relative) {
  fs::path p = sharedDir() / relative;
  std::error_code ec;
  return fs::exists(p, ec) ? p : fs::path();
}

namespace {
std::mutex tempRootsMutex;
std::vector<fs::path> tempRoots;

// At exit: a run that passed leaves nothing behind in /tmp (thousands of directories gathered
// there over a day's runs); a failed one keeps its files to look at, and says where.
void removeTempRoots() {
  std::lock_guard lock(tempRootsMutex);
  if (::testing::UnitTest::GetInstance()->Failed()) {
    const fs::path kept = fs::temp_directory_path() / ("retile-test-" + std::to_string(::getpid()) + "-*");
    if (!tempRoots.empty())
      std::fprintf(stderr, "retile tests: a test failed, so the files tests wrote stay in %s\n", kept.string().c_str());
    return;
  }
  std::error_code ec;
  for (const fs::path& root : tempRoots) fs::remove_all(root, ec);
}
}  // namespace

fs::path tempDir() {
  static std::atomic<int> counter{0};
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "test";
  const fs::path root = fs::temp_directory_path() / ("retile-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  {
    std::lock_guard lock(tempRootsMutex);
    if (tempRoots.empty()) std::atexit(removeTempRoots);
    tempRoots.push_back(root);
  }
  fs::path p = root / name;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

NodeId addFileTexture(Scene& s, const fs::path& file, TextureColorSpace space) {
  Texture t;
  t.id = s.newId();
  t.name = file.stem().string();
  t.path = file;
  t.colorSpace = space;
  s.textures.push_back(t);
  return t.id;
}

void writePpm(const fs::path& file, int width, int height, const std::vector<std::uint8_t>& rgb) {
  ASSERT_EQ(rgb.size(), static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3) << file;
  std::ofstream out(file, std::ios::binary);
  out << "P6\n" << width << " " << height << "\n255\n";
  out.write(reinterpret_cast<const char*>(rgb.data()), static_cast<std::streamsize>(rgb.size()));
  ASSERT_TRUE(out.good()) << file;
}

fs::path commaLocaleDir(std::string* error) {
  fs::path dir = fs::temp_directory_path() / "retile-test-locales";
  if (fs::exists(dir / "de_DE.UTF-8" / "LC_NUMERIC")) return dir;
  // Compiled beside the final place and renamed, so a concurrent suite never sees half a locale.
  fs::path staging = fs::temp_directory_path() / ("retile-test-locales-" + std::to_string(::getpid()));
  fs::remove_all(staging);
  fs::create_directories(staging);
  std::string cmd = "localedef -i de_DE -f UTF-8 '" + (staging / "de_DE.UTF-8").string() + "' >/dev/null 2>&1";
  int rc = std::system(cmd.c_str());
  if (!fs::exists(staging / "de_DE.UTF-8" / "LC_NUMERIC")) {
    *error = "localedef could not make de_DE.UTF-8 (exit " + std::to_string(rc) +
             "); install the 'locales' package (scripts/setup-debian.sh does)";
    fs::remove_all(staging);
    return {};
  }
  std::error_code ec;
  fs::rename(staging, dir, ec);
  fs::remove_all(staging);  // when another suite won the race
  return dir;
}

ScopedCommaLocale::ScopedCommaLocale() {
  previous_ = std::setlocale(LC_ALL, nullptr);
  fs::path dir = commaLocaleDir(&error_);
  if (dir.empty()) return;
  ::setenv("LOCPATH", dir.c_str(), 1);
  if (!std::setlocale(LC_ALL, "de_DE.UTF-8")) {
    error_ = "setlocale(LC_ALL, \"de_DE.UTF-8\") failed with LOCPATH=" + dir.string();
    return;
  }
  if (std::strtod("0,5", nullptr) != 0.5) error_ = "de_DE.UTF-8 is active but strtod does not read \"0,5\" as 0.5";
}

ScopedCommaLocale::~ScopedCommaLocale() { std::setlocale(LC_ALL, previous_.c_str()); }

NodeId addMaterial(Scene& s, Material m) {
  m.id = s.newId();
  s.materials.push_back(m);
  return m.id;
}

NodeId addMeshObject(Scene& s, const std::string& name, std::shared_ptr<const MeshGeometry> g, NodeId material, const Mat4& transform) {
  Mesh mesh;
  mesh.id = s.newId();
  mesh.name = name;
  mesh.geometry = std::move(g);
  s.meshes.push_back(mesh);
  Object o;
  o.id = s.newId();
  o.name = name;
  o.mesh = mesh.id;
  o.material = material;
  o.transform = transform;
  s.objects.push_back(o);
  return o.id;
}

Scene emptyScene(int width, int height) {
  Scene s;
  s.settings.width = width;
  s.settings.height = height;
  s.environment.type = EnvironmentType::Constant;
  s.environment.color = Vec3{0.0f};
  return s;
}

double meanLuminance(const RenderImage& img, int x0, int y0, int x1, int y1) {
  double sum = 0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      std::size_t i = static_cast<std::size_t>(y * img.width + x) * 3;
      sum += luminance({img.color[i], img.color[i + 1], img.color[i + 2]});
      ++n;
    }
  return n ? sum / n : 0.0;
}

bool allFinite(const RenderImage& img) {
  for (float v : img.color)
    if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace retile::test

#include "gpu_support.h"

namespace retile::test {

bool requireDevice() {
  const char* ci = std::getenv("CI");
  return ci && *ci && std::string(ci) != "0" && std::string(ci) != "false";
}

std::unique_ptr<Renderer> makeRenderer(std::string* whyNot, const RendererOptions& options) {
  // Only a missing driver or device skips; a shader or pipeline that fails to build throws on and
  // fails the test.
  try {
    return std::make_unique<Renderer>(options);
  } catch (const NoDeviceError& e) {
    *whyNot = e.what();
    return nullptr;
  }
}

std::unique_ptr<Renderer> makeRecordsRenderer(std::string* whyNot) {
  RendererOptions options;
  options.directReferences = false;
  return makeRenderer(whyNot, options);
}

Camera frontCamera(float fov) {
  Camera c;
  c.position = {0, 0, 0};
  c.target = {0, 0, -1};
  c.up = {0, 1, 0};
  c.verticalFov = radians(fov);
  return c;
}

}  // namespace retile::test
