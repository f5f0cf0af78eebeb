// Colour management through OpenColorIO: the display transform for the viewport and PNG
// output, and decoding of texture encodings into the renderer's linear Rec.709.
//
// ColorConfig::get() loads the config named by $OCIO when set, else the one shipped in
// resources/ocio; it is created once per process and is then read-only, so any thread may use it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "retile/image.h"

namespace retile {

class ColorConfig {
 public:
  // The process-wide configuration. Throws retile::Error if neither $OCIO nor the shipped
  // config can be loaded (the message names both files and why).
  static std::shared_ptr<const ColorConfig> get();
  // Loads a specific config file (tests; the editor's preferences).
  static std::shared_ptr<const ColorConfig> load(const std::string& path);

  virtual ~ColorConfig() = default;
  virtual std::string source() const = 0;              // the file it came from
  virtual std::vector<std::string> views() const = 0;  // views of the default display
  virtual std::string display() const = 0;

  // Linear RGB (3 floats per pixel) to 8-bit RGBA through exposure, the view and gamma.
  virtual void toDisplay8(const float* rgb, std::size_t pixels, const DisplaySettings& settings, std::uint8_t* rgba) const = 0;
  // The same, to display-referred floats (3 per pixel), unclamped.
  virtual void toDisplayFloat(const float* rgb, std::size_t pixels, const DisplaySettings& settings, float* out) const = 0;
  // sRGB-encoded values to linear, in place (RGBA floats; alpha untouched).
  virtual void srgbToLinear(float* rgba, std::size_t pixels) const = 0;
};

// The sRGB curve (IEC 61966-2-1) from encoded to linear, for v in [0, 1]: what the shader decodes
// 8-bit sRGB texels by, and the decoding when no configuration provides one.
float srgbCurve(float v);

// Where shipped resources live: $RETILE_RESOURCES, else <executable>/../share/retile when it
// holds them (installed), else the source tree's resources/ (builds run in place).
std::string resourceDirectory();

}  // namespace retile
