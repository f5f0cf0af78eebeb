// Image files through OpenImageIO, with colour conversion through OpenColorIO (color/).
// Any thread; no shared state besides OIIO's own thread-safe caches.
#pragma once

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

// Decodes a texture node's image (file or embedded) to linear RGBA floats. Colour conversion
// follows tex.colorSpace (Auto: 8/16-bit integer formats are sRGB, float formats linear).
Result<LinearImage> loadTextureImage(const Texture& tex, const std::filesystem::path& baseDirectory,
                                     const ImageLimits& limits = {});

// Reads any image OIIO knows as linear floats without conversion (for tests and references).
Result<LinearImage> readImageRaw(const std::filesystem::path& file, const ImageLimits& limits = {});

}  // namespace retile
