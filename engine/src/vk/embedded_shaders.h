// Shader sources compiled into the binary by cmake/EmbedShaders.cmake; names are paths
// relative to shaders/ (e.g. "common/rng.glsl").
#pragma once

#include <span>

namespace retile::vk {

struct EmbeddedShader {
  const char* name;
  const char* source;
};

std::span<const EmbeddedShader> embeddedShaders();

}  // namespace retile::vk
