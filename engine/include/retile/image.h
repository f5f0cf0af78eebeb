// Rendered images and writing them out. Any thread.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "retile/error.h"
#include "retile/scene.h"

namespace retile {

// A resolved render: linear radiance and the auxiliary outputs the denoiser and the priority
// policies use. Row 0 is the top of the image.
struct RenderImage {
  int width = 0;
  int height = 0;
  std::vector<float> color;        // RGB, linear scene-referred
  std::vector<float> albedo;       // RGB of the first hit
  std::vector<float> normal;       // XYZ world-space shading normal of the first hit
  std::vector<float> depth;        // distance to the first hit; +inf for the background
  std::vector<NodeId> objectId;    // object of the first hit; kNoNode for the background
  std::vector<float> sampleCount;  // samples accumulated per pixel
  std::vector<float> moment2;      // mean of the samples' squared luminance (with the mean: variance)
  // RGB as displayed: the denoised layer and the raw accumulation composed with soft borders
  // (DenoiseWork). Empty when nothing was composed: then `color` is what is shown.
  std::vector<float> display;
  const std::vector<float>& shown() const { return display.empty() ? color : display; }
  // Verified reuse: per pixel the history kept inside the accumulation (schedule/reuse.h) as
  // sample count, mean R, G, B and mean squared luminance (kHistoryFloats floats); empty when none
  // is kept.
  static constexpr std::size_t kHistoryFloats = 5;
  std::vector<float> history;
};

struct DisplaySettings {
  std::string view = "Standard";  // an OCIO view of the sRGB display: "Standard" or "Filmic"
  float exposure = 0.0f;          // stops, applied in linear before the view transform
  float gamma = 1.0f;             // extra display gamma after the view transform
};

// EXR: linear half-float R,G,B (the shown image: denoised when it was) plus raw.* (the
// accumulation, when denoised), albedo.*, N.*, Z and id channels. PNG: 8-bit through the
// display transform. Chosen by extension; written atomically (temporary file, then rename).
Result<bool> writeRenderImage(const RenderImage& image, const std::filesystem::path& file, const DisplaySettings& display = {});

}  // namespace retile
