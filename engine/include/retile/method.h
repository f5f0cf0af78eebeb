// The re-rendering methods of ../shared/METHOD.md, by name, and their settings. Plain values: the
// GUI or command line builds them, the render thread applies them between frames.
#pragma once

#include <string>
#include <vector>

#include "retile/math.h"

namespace retile {

enum class MethodKind {
  Global,            // discard everything on an edit, 1 spp full frames
  Spiral,            // tiles by Chebyshev distance from the point of change
  Focus,             // spirals from the point of change and from 1-3 focus points, alternating
  Indirection,       // classes from what the tracer saw of the selected object; automatic Q
  IndirectionFocus,  // indirection classes, then focus spirals for the rest
  Change,            // a cheap 1-spp probe, then tiles whose estimate changed most
};
constexpr int kMethodKindCount = 6;

const char* methodName(MethodKind kind);
bool methodFromName(const std::string& name, MethodKind* out);
std::vector<std::string> methodNames();

struct FocusPoint {
  Vec2 pixel{0.0f};      // image position; for a following point, its offset is kept from the PoC
  bool follows = false;  // follows the edited object's screen motion (reflections) or stays (shadows)
};

struct MethodSettings {
  MethodKind kind = MethodKind::Spiral;
  int tileSize = 16;              // T: 8, 16 or 32
  int quality = 64;               // Q >= 1 samples per pixel of a served tile; 0 = automatic (indirection)
  bool smooth = false;            // smooth transition: tiles after the prioritized ones keep capped stale sums
  int staleCap = 8;               // smooth: stale samples kept per pixel; the old image's weight after n
                                  // frames of fresh samples at q each is staleCap / (staleCap + n q)
  std::vector<FocusPoint> focus;  // up to 3
  int indirectionFrames = 4;      // frames over which the indirection counters are gathered
  // Denoising (schedule/denoise_regions.h): the global method and continuous refinement denoise
  // the whole frame each frame; a pass denoises a growing region, re-sized when its width grew
  // by more than this share of the image's width, or its height by more than this share of its
  // height, since the last re-size: the same steps at every render size (the paper's 200 px at
  // 1920 wide is about a tenth).
  bool denoise = false;
  double denoiseThreshold = 0.1;
  bool softBorders = true;                  // with denoise: seams between tiles showing different things blend
  static constexpr int kFeatherPixels = 4;  // over this many pixels each side
  // Verified reuse (schedule/reuse.h): a restarted tile keeps its samples beside the fresh ones
  // while a test finds them in agreement. The false-reject rate is the chance that one test of
  // an unchanged tile drops its history.
  bool reuse = false;
  double reuseFalseReject = 1e-4;
};

// "spiral", "spiral+smooth", "global+denoise", "indirection+focus+smooth+denoise": the method and
// its options, as reports and frame records name it.
std::string methodLabel(const MethodSettings& s);

// Checks ranges; returns an empty string when the settings are usable, else what is wrong.
std::string validateMethodSettings(const MethodSettings& s);

}  // namespace retile
