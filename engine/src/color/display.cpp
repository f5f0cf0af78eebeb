#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>

#include "core/process.h"
#include "retile/color.h"
#include "retile/error.h"
#include "retile/log.h"

namespace OCIO = OCIO_NAMESPACE;
namespace fs = std::filesystem;

namespace retile {

std::string resourceDirectory() {
  if (const char* env = std::getenv("RETILE_RESOURCES"); env && *env) return env;
  // Installed first (the package's share/retile beside its bin/), so that an installed retile on
  // the machine that built it does not read the source tree.
  std::error_code ec;
  fs::path installed = (executableDirectory() / ".." / "share" / "retile").lexically_normal();
  if (fs::exists(installed / "ocio" / "config.ocio", ec)) return installed.string();
  fs::path built = RETILE_RESOURCE_DIR;
  if (fs::exists(built / "ocio" / "config.ocio", ec)) return built.string();
  return installed.string();
}

namespace {

class OcioConfig final : public ColorConfig {
 public:
  OcioConfig(OCIO::ConstConfigRcPtr config, std::string source) : config_(std::move(config)), source_(std::move(source)) {
    display_ = config_->getDefaultDisplay();
    // Our renders are linear Rec.709; find that space in whatever config we were given, and
    // fall back to its scene_linear role.
    for (const char* name : {"Linear Rec.709 (sRGB)", "lin_rec709", "Utility - Linear - sRGB", "Linear"}) {
      if (config_->getColorSpace(name)) {
        sceneLinear_ = name;
        break;
      }
    }
    if (sceneLinear_.empty()) sceneLinear_ = OCIO::ROLE_SCENE_LINEAR;
    // Decoding 8-bit sRGB through a 256-entry table built by OCIO is exact and fast.
    OCIO::ConstConfigRcPtr builtin = config_;
    std::string srgbSpace;
    for (const char* name : {"sRGB - Texture", "srgb_texture", "Utility - sRGB - Texture"})
      if (config_->getColorSpace(name)) {
        srgbSpace = name;
        break;
      }
    if (!srgbSpace.empty()) {
      toLinear_ = config_->getProcessor(srgbSpace.c_str(), sceneLinear_.c_str())->getDefaultCPUProcessor();
    } else {
      logWarning("OCIO config ", source_, " has no sRGB texture colour space; decoding sRGB analytically");
    }
  }

  std::string source() const override { return source_; }
  std::string display() const override { return display_; }
  std::vector<std::string> views() const override {
    std::vector<std::string> v;
    for (int i = 0; i < config_->getNumViews(display_.c_str()); ++i) v.emplace_back(config_->getView(display_.c_str(), i));
    return v;
  }

  OCIO::ConstCPUProcessorRcPtr displayProcessor(const std::string& view) const {
    std::lock_guard lock(mutex_);
    auto it = cache_.find(view);
    if (it != cache_.end()) return it->second;
    std::string chosen = view;
    bool known = false;
    for (const auto& v : views()) known = known || v == view;
    if (!known) {
      chosen = config_->getDefaultView(display_.c_str());
      logWarning("OCIO view '", view, "' is not in ", source_, "; using '", chosen, "'");
    }
    auto p = config_->getProcessor(sceneLinear_.c_str(), display_.c_str(), chosen.c_str(), OCIO::TRANSFORM_DIR_FORWARD)
                 ->getDefaultCPUProcessor();
    cache_[view] = p;
    return p;
  }

  void toDisplayFloat(const float* rgb, std::size_t pixels, const DisplaySettings& s, float* out) const override {
    float scale = std::exp2(s.exposure);
    for (std::size_t i = 0; i < pixels * 3; ++i) out[i] = std::isfinite(rgb[i]) ? rgb[i] * scale : 0.0f;
    if (pixels == 0) return;
    auto p = displayProcessor(s.view);
    OCIO::PackedImageDesc img(out, static_cast<long>(pixels), 1, 3);
    p->apply(img);
    if (s.gamma != 1.0f && s.gamma > 0.0f) {
      float inv = 1.0f / s.gamma;
      for (std::size_t i = 0; i < pixels * 3; ++i) out[i] = out[i] > 0 ? std::pow(out[i], inv) : out[i];
    }
  }

  void toDisplay8(const float* rgb, std::size_t pixels, const DisplaySettings& s, std::uint8_t* rgba) const override {
    std::vector<float> tmp(pixels * 3);
    toDisplayFloat(rgb, pixels, s, tmp.data());
    for (std::size_t i = 0; i < pixels; ++i) {
      for (int c = 0; c < 3; ++c) {
        float v = std::clamp(tmp[i * 3 + static_cast<std::size_t>(c)], 0.0f, 1.0f);
        rgba[i * 4 + static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(std::lround(v * 255.0f));
      }
      rgba[i * 4 + 3] = 255;
    }
  }

  void srgbToLinear(float* rgba, std::size_t pixels) const override {
    if (toLinear_) {
      OCIO::PackedImageDesc img(rgba, static_cast<long>(pixels), 1, 4);
      toLinear_->apply(img);
      return;
    }
    for (std::size_t i = 0; i < pixels; ++i)
      for (int c = 0; c < 3; ++c) {
        float& v = rgba[i * 4 + static_cast<std::size_t>(c)];
        v = srgbCurve(v);
      }
  }

 private:
  OCIO::ConstConfigRcPtr config_;
  std::string source_;
  std::string display_;
  std::string sceneLinear_;
  OCIO::ConstCPUProcessorRcPtr toLinear_;
  mutable std::mutex mutex_;
  mutable std::map<std::string, OCIO::ConstCPUProcessorRcPtr> cache_;
};

std::shared_ptr<const ColorConfig> tryLoad(const std::string& path, std::string* error) {
  try {
    auto cfg = OCIO::Config::CreateFromFile(path.c_str());
    cfg->validate();
    auto result = std::make_shared<OcioConfig>(cfg, path);
    // Build the default view now so a missing LUT shows up here, not at the first frame.
    DisplaySettings probe;
    probe.view = cfg->getDefaultView(cfg->getDefaultDisplay());
    float px[3] = {0.18f, 0.18f, 0.18f}, out[3];
    result->toDisplayFloat(px, 1, probe, out);
    return result;
  } catch (const std::exception& e) {
    *error = e.what();
    return nullptr;
  }
}

}  // namespace

std::shared_ptr<const ColorConfig> ColorConfig::load(const std::string& path) {
  std::string error;
  auto cfg = tryLoad(path, &error);
  if (!cfg) throw Error(cat("OCIO config ", path, ": ", error));
  return cfg;
}

std::shared_ptr<const ColorConfig> ColorConfig::get() {
  static std::once_flag once;
  static std::shared_ptr<const ColorConfig> instance;
  static std::string failure;
  std::call_once(once, [] {
    OCIO::SetLoggingLevel(OCIO::LOGGING_LEVEL_WARNING);
    OCIO::SetLoggingFunction([](const char* m) {
      std::string s(m ? m : "");
      while (!s.empty() && s.back() == '\n') s.pop_back();
      logWarning("OCIO: ", s);
    });
    std::string shipped = (fs::path(resourceDirectory()) / "ocio" / "config.ocio").string();
    std::string envError;
    if (const char* env = std::getenv("OCIO"); env && *env) {
      instance = tryLoad(env, &envError);
      if (instance) return;
      logWarning("OCIO config from $OCIO (", env, ") failed: ", envError, "; using ", shipped);
    }
    std::string error;
    instance = tryLoad(shipped, &error);
    if (!instance) failure = cat("cannot load the colour configuration ", shipped, ": ", error);
  });
  if (!instance) throw Error(failure);
  return instance;
}

float srgbCurve(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

}  // namespace retile
