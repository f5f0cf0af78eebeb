// GLSL to SPIR-V at run time with the glslang library, cached on disk by a hash of the sources
// and defines, so the second start of the editor skips compilation. Thread-safe: glslang is
// initialised once per process and compiles are serialised.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace retile::vk {

struct ShaderDefine {
  std::string name;
  std::string value;
};

// Compiles the embedded compute shader `entry` (e.g. "trace.comp"). Throws retile::Error with
// glslang's log when compilation fails.
std::vector<std::uint32_t> compileComputeShader(const std::string& entry, const std::vector<ShaderDefine>& defines = {});

}  // namespace retile::vk
