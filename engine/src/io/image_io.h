// Image files through OpenImageIO, with colour conversion through OpenColorIO (color/).
// Any thread; no shared state besides OIIO's own thread-safe caches.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "retile/error.h"
#include "retile/scene.h"

namespace retile {

struct LinearImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgba;  // linear scene values (or raw data), row 0 at the top
  bool hasAlpha = false;    // the file had an alpha channel (else alpha is 1)
};

struct ImageLimits {
  std::uint64_t maxPixels = std::uint64_t(1) << 28;  // 16k x 16k
};

// A texture as the renderer stores it. An 8-bit source stays 8 bits a channel: a quarter of the
// memory of linear halves and an eighth of floats, where textures are most of a scene's memory.
// Its colour is then decoded per texel by `curve` where it is read (the shader); alpha is linear.
// Other sources, and 8-bit ones whose decoding is not such a curve, are linear floats.
struct TextureImage {
  enum class Curve { Linear, SRGB };
  int width = 0;
  int height = 0;
  bool hasAlpha = false;            // the file had an alpha channel (else alpha is 1 / 255)
  std::vector<std::uint8_t> rgba8;  // when not empty: RGBA, row 0 at the top
  Curve curve = Curve::Linear;      // of rgba8's colour
  std::vector<float> rgba;          // otherwise: linear RGBA
  bool eightBit() const { return !rgba8.empty(); }
  // What each byte value of rgba8's colour decodes to by `curve` (alpha is value / 255).
  std::array<float, 256> byteValues() const;
  // The linear values either way (rgba8 decoded by its curve, as the shader decodes it).
  LinearImage toLinear() &&;
};

// Decodes a texture node's image (file or embedded). Colour conversion follows tex.colorSpace
// (Auto: 8/16-bit integer formats are sRGB, float formats linear).
Result<TextureImage> loadTexture(const Texture& tex, const std::filesystem::path& baseDirectory, const ImageLimits& limits = {});

// Reads any image OIIO knows as linear floats without conversion (for tests and references).
Result<LinearImage> readImageRaw(const std::filesystem::path& file, const ImageLimits& limits = {});

}  // namespace retile
