#include "retile/method.h"

#include "retile/log.h"

namespace retile {

namespace {
const char* const kNames[kMethodKindCount] = {"global", "spiral", "focus", "indirection", "indirection+focus", "change"};
}

const char* methodName(MethodKind kind) {
  int i = static_cast<int>(kind);
  return i >= 0 && i < kMethodKindCount ? kNames[i] : "?";
}

bool methodFromName(const std::string& name, MethodKind* out) {
  for (int i = 0; i < kMethodKindCount; ++i)
    if (name == kNames[i]) {
      *out = static_cast<MethodKind>(i);
      return true;
    }
  return false;
}

std::vector<std::string> methodNames() { return {std::begin(kNames), std::end(kNames)}; }

std::string methodLabel(const MethodSettings& s) {
  std::string label = methodName(s.kind);
  if (s.smooth && s.kind != MethodKind::Global) label += "+smooth";
  if (s.reuse) label += "+reuse";
  if (s.denoise) label += "+denoise";
  return label;
}

std::string validateMethodSettings(const MethodSettings& s) {
  if (s.tileSize != 8 && s.tileSize != 16 && s.tileSize != 32) return cat("tile size must be 8, 16 or 32, not ", s.tileSize);
  if (s.quality < 0 || s.quality > 4096) return cat("quality must be 1..4096 (or 0 for automatic), not ", s.quality);
  if (s.quality == 0 && s.kind != MethodKind::Indirection && s.kind != MethodKind::IndirectionFocus)
    return "automatic quality (0) needs an indirection method";
  if (s.staleCap < 1 || s.staleCap > 1 << 20) return cat("stale cap must be at least 1, not ", s.staleCap);
  if (s.focus.size() > 3) return cat("at most 3 focus points, not ", s.focus.size());
  for (const auto& f : s.focus)
    if (!(f.pixel.x == f.pixel.x) || !(f.pixel.y == f.pixel.y)) return "a focus point is NaN";
  if (s.indirectionFrames < 1 || s.indirectionFrames > 64) return "indirection frames must be 1..64";
  if (s.reuse && s.kind == MethodKind::Global) return "reuse keeps what an edit did not change: it needs an incremental method, not global";
  if (!(s.reuseFalseReject > 0.0 && s.reuseFalseReject < 0.5))
    return cat("the reuse false-reject rate must be in (0, 0.5), not ", s.reuseFalseReject);
  if (!(s.denoiseThreshold >= 0 && s.denoiseThreshold <= 1))
    return cat("the denoise threshold is a share of the image, 0..1, not ", s.denoiseThreshold);
  return {};
}

}  // namespace retile
