#include "vk/shader_compiler.h"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <glslang/build_info.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "core/files.h"
#include "retile/error.h"
#include "retile/log.h"
#include "vk/embedded_shaders.h"

namespace fs = std::filesystem;

namespace retile::vk {
namespace {

std::mutex gMutex;

const char* findSource(const std::string& name) {
  for (const EmbeddedShader& s : embeddedShaders())
    if (name == s.name) return s.source;
  return nullptr;
}

class EmbeddedIncluder : public glslang::TShader::Includer {
 public:
  IncludeResult* includeLocal(const char* header, const char*, size_t) override { return lookup(header); }
  IncludeResult* includeSystem(const char* header, const char*, size_t) override { return lookup(header); }
  void releaseInclude(IncludeResult* r) override { delete r; }

 private:
  static IncludeResult* lookup(const char* header) {
    const char* src = findSource(header);
    if (!src) return nullptr;
    return new IncludeResult(header, src, std::strlen(src), nullptr);
  }
};

std::uint64_t sourcesHash() {
  static const std::uint64_t h = [] {
    std::uint64_t x = fnv1a64(cat(GLSLANG_VERSION_MAJOR, ".", GLSLANG_VERSION_MINOR, ".", GLSLANG_VERSION_PATCH));
    for (const EmbeddedShader& s : embeddedShaders()) {
      x = fnv1a64(s.name, x);
      x = fnv1a64(s.source, x);
    }
    return x;
  }();
  return h;
}

fs::path cacheDirectory() {
  if (const char* env = std::getenv("RETILE_SHADER_CACHE"); env) return *env ? fs::path(env) : fs::path();
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return fs::path(xdg) / "retile" / "spirv";
  if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / "retile" / "spirv";
  return {};
}

// What besides the sources and defines decides the SPIR-V: the glslang release, the GLSL version
// and targets, and the code generator's options. All of it goes into the cache key, so that a
// change to any of it is not answered with SPIR-V made the old way.
constexpr int kGlslVersion = 460;
constexpr glslang::EShTargetClientVersion kVulkanTarget = glslang::EShTargetVulkan_1_2;
constexpr glslang::EShTargetLanguageVersion kSpirvTarget = glslang::EShTargetSpv_1_5;
constexpr bool kOptimize = true;

std::string compileConfiguration() {
  return cat("glslang ", GLSLANG_VERSION_MAJOR, ".", GLSLANG_VERSION_MINOR, ".", GLSLANG_VERSION_PATCH, " glsl ", kGlslVersion, " vulkan ",
             static_cast<int>(kVulkanTarget), " spirv ", static_cast<int>(kSpirvTarget), kOptimize ? " optimized" : " unoptimized");
}

}  // namespace

std::vector<std::uint32_t> compileComputeShader(const std::string& entry, const std::vector<ShaderDefine>& defines) {
  std::string preamble;
  for (const auto& d : defines) preamble += cat("#define ", d.name, " ", d.value, "\n");
  static const std::string configuration = compileConfiguration();
  std::uint64_t key = fnv1a64(configuration, fnv1a64(preamble, fnv1a64(entry, sourcesHash())));
  fs::path dir = cacheDirectory();
  fs::path cached = dir.empty() ? fs::path() : dir / cat(fs::path(entry).stem().string(), "-", std::hex, key, ".spv");

  if (!cached.empty()) {
    std::error_code ec;
    if (fs::exists(cached, ec)) {
      auto bytes = readFile(cached, std::uint64_t(64) << 20);
      std::uint32_t magic = 0;
      if (bytes && bytes->size() >= 4 && bytes->size() % 4 == 0) std::memcpy(&magic, bytes->data(), 4);
      if (magic == 0x07230203u) {  // SPIR-V
        std::vector<std::uint32_t> words(bytes->size() / 4);
        std::memcpy(words.data(), bytes->data(), bytes->size());
        return words;
      }
    }
  }

  const char* source = findSource(entry);
  if (!source) throw Error(cat("shader '", entry, "' is not embedded in this build"));

  std::vector<std::uint32_t> spirv;
  {
    std::lock_guard lock(gMutex);
    static bool initialised = glslang::InitializeProcess();
    if (!initialised) throw Error("glslang failed to initialise");
    glslang::TShader shader(EShLangCompute);
    const char* names[] = {entry.c_str()};
    const char* texts[] = {source};
    shader.setStringsWithLengthsAndNames(texts, nullptr, names, 1);
    shader.setPreamble(preamble.c_str());
    shader.setEnvInput(glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan, 100);
    shader.setEnvClient(glslang::EShClientVulkan, kVulkanTarget);
    shader.setEnvTarget(glslang::EShTargetSpv, kSpirvTarget);
    EmbeddedIncluder includer;
    auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
    if (!shader.parse(GetDefaultResources(), kGlslVersion, false, messages, includer))
      throw Error(cat("compiling shader '", entry, "':\n", shader.getInfoLog()));
    glslang::TProgram program;
    program.addShader(&shader);
    if (!program.link(messages)) throw Error(cat("linking shader '", entry, "':\n", program.getInfoLog()));
    glslang::SpvOptions options;
    options.disableOptimizer = !kOptimize;
    glslang::GlslangToSpv(*program.getIntermediate(EShLangCompute), spirv, &options);
  }

  if (!cached.empty()) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!ec) {
      auto r = writeFileAtomic(cached, std::string_view(reinterpret_cast<const char*>(spirv.data()), spirv.size() * 4));
      if (!r) logDebug("shader cache not written: ", r.error());
    }
  }
  return spirv;
}

}  // namespace retile::vk
