#include "io/image_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "core/files.h"
#include "core/process.h"
#include "retile/color.h"
#include "retile/image.h"
#include "retile/log.h"

namespace fs = std::filesystem;

namespace retile {
namespace {

struct Decoded {
  LinearImage image;
  bool isFloat = false;
  std::string colorSpaceTag;
};

// Tungsten's LDR decoding (ImageIO::loadLdr with gamma correction): a 256-entry table of
// floor(255 (v/255)^2.2), kept in 8 bits; colour only, alpha stays as stored.
void tungstenGamma(LinearImage& image) {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int v = 0; v < 256; ++v) t[static_cast<std::size_t>(v)] = static_cast<float>(std::floor(255.0 * std::pow(v / 255.0, 2.2) + 1e-9) / 255.0);
    return t;
  }();
  for (std::size_t i = 0; i < image.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    const long v = std::lround(std::clamp(image.rgba[i], 0.0f, 1.0f) * 255.0f);
    image.rgba[i] = table[static_cast<std::size_t>(v)];
  }
}

Result<Decoded> decode(const std::string& name, OIIO::Filesystem::IOProxy* proxy, const ImageLimits& limits) {
  using R = Result<Decoded>;
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // keep colour straight, not premultiplied
  auto in = OIIO::ImageInput::open(name, &config, proxy);
  if (!in) {
    std::string why = OIIO::geterror();
    return R::failure(cat(name, ": cannot read the image: ", why.empty() ? "unknown format" : why));
  }
  const OIIO::ImageSpec& spec = in->spec();
  // OIIO's own limits are not enforced by every reader: check the header before allocating.
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth != 1 || spec.deep)
    return R::failure(cat(name, ": unsupported image layout (", spec.width, "x", spec.height, ", ", spec.nchannels, " channels)"));
  auto pixels = static_cast<std::uint64_t>(spec.width) * static_cast<std::uint64_t>(spec.height);
  if (pixels > limits.maxPixels || spec.nchannels > 64)
    return R::failure(cat(name, ": image of ", spec.width, "x", spec.height, " with ", spec.nchannels,
                          " channels is larger than the limit of ", limits.maxPixels, " pixels"));
  int nc = spec.nchannels;
  std::vector<float> tmp(pixels * static_cast<std::uint64_t>(nc));
  // Halves below 6.1e-5 convert correctly only with denormals kept (core/process.h), so the
  // conversion runs here, in this thread, not in OpenImageIO's pool, whose threads may flush them.
  KeepDenormals keep;
  in->threads(1);
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, tmp.data()))
    return R::failure(cat(name, ": cannot decode the image: ", in->geterror()));
  Decoded d;
  d.isFloat = spec.format.basetype == OIIO::TypeDesc::FLOAT || spec.format.basetype == OIIO::TypeDesc::HALF ||
              spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  d.colorSpaceTag = lowercase(std::string(spec.get_string_attribute("oiio:ColorSpace")));
  LinearImage& img = d.image;
  img.width = spec.width;
  img.height = spec.height;
  img.hasAlpha = spec.alpha_channel >= 0 && spec.alpha_channel < nc;
  img.rgba.assign(pixels * 4, 1.0f);
  for (std::uint64_t p = 0; p < pixels; ++p) {
    const float* s = &tmp[p * static_cast<std::uint64_t>(nc)];
    float* o = &img.rgba[p * 4];
    if (nc < 3) {
      o[0] = o[1] = o[2] = s[0];
    } else {
      o[0] = s[0];
      o[1] = s[1];
      o[2] = s[2];
    }
    if (img.hasAlpha) o[3] = s[spec.alpha_channel];
  }
  return d;
}

}  // namespace

Result<LinearImage> readImageRaw(const fs::path& file, const ImageLimits& limits) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return Result<LinearImage>::failure(cat(file.string(), ": file not found"));
  auto d = decode(file.string(), nullptr, limits);
  if (!d) return Result<LinearImage>::failure(d.error());
  return std::move(d->image);
}

Result<LinearImage> loadTextureImage(const Texture& tex, const fs::path& base, const ImageLimits& limits) {
  using R = Result<LinearImage>;
  Result<Decoded> d = Result<Decoded>::failure("");
  if (tex.kind == TextureKind::Embedded) {
    if (tex.encoded.empty()) return R::failure(cat("texture '", tex.name, "': embedded image is empty"));
    OIIO::Filesystem::IOMemReader mem(const_cast<std::uint8_t*>(tex.encoded.data()), tex.encoded.size());
    std::string hint = tex.encodedFormat.empty() ? "png" : tex.encodedFormat;
    if (hint == "jpeg") hint = "jpg";
    d = decode(cat("embedded.", hint), &mem, limits);
    if (!d) return R::failure(cat("texture '", tex.name, "': ", d.error()));
  } else if (tex.kind == TextureKind::File) {
    auto resolved = resolveScenePath(base, tex.path.string());
    if (!resolved) {
      fs::path shown = tex.path.is_absolute() ? tex.path : base / tex.path;
      return R::failure(cat(shown.string(), ": texture file not found"));
    }
    d = decode(resolved->string(), nullptr, limits);
    if (!d) return R::failure(d.error());
  } else {
    return R::failure(cat("texture '", tex.name, "' is procedural and has no image"));
  }
  Decoded& dec = d.value();
  bool srgb = false;
  switch (tex.colorSpace) {
    case TextureColorSpace::TungstenGamma:
      if (!dec.isFloat) tungstenGamma(dec.image);
      break;
    case TextureColorSpace::SRGB: srgb = true; break;
    case TextureColorSpace::Linear:
    case TextureColorSpace::Raw: srgb = false; break;
    case TextureColorSpace::Auto:
      srgb = dec.colorSpaceTag == "srgb" || (dec.colorSpaceTag.empty() && !dec.isFloat) ||
             dec.colorSpaceTag.rfind("gamma", 0) == 0;
      break;
  }
  if (srgb) ColorConfig::get()->srgbToLinear(dec.image.rgba.data(), dec.image.rgba.size() / 4);
  return std::move(dec.image);
}

Result<bool> writeRenderImage(const RenderImage& image, const fs::path& file, const DisplaySettings& display) {
  using R = Result<bool>;
  std::string ext = extensionLower(file);
  if (image.width <= 0 || image.height <= 0) return R::failure(cat(file.string(), ": nothing to write (empty image)"));
  auto pixels = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  if (image.color.size() != pixels * 3 || !(image.display.empty() || image.display.size() == pixels * 3))
    return R::failure(cat(file.string(), ": image data is incomplete"));
  fs::path tmp = temporarySibling(file);
  auto fail = [&](const std::string& why) {
    std::error_code ec;
    fs::remove(tmp, ec);
    return R::failure(cat(file.string(), ": ", why, "; any existing file is unchanged"));
  };

  if (ext == "exr") {
    std::vector<std::string> names = {"R", "G", "B"};
    bool aux = image.albedo.size() == pixels * 3 && image.normal.size() == pixels * 3 && image.depth.size() == pixels &&
               image.objectId.size() == pixels;
    if (aux) names.insert(names.end(), {"albedo.R", "albedo.G", "albedo.B", "N.X", "N.Y", "N.Z", "Z", "id"});
    // Denoised: R, G, B are what is shown; the accumulation (unbiased, noisy) follows as raw.*.
    const bool denoised = image.display.size() == pixels * 3;
    const std::size_t rawAt = names.size();
    if (denoised) names.insert(names.end(), {"raw.R", "raw.G", "raw.B"});
    const std::vector<float>& shown = image.shown();
    OIIO::ImageSpec spec(image.width, image.height, static_cast<int>(names.size()), OIIO::TypeDesc::HALF);
    spec.channelnames = names;
    spec.channelformats.assign(names.size(), OIIO::TypeDesc::HALF);
    if (aux) {
      spec.z_channel = 9;
      spec.channelformats[9] = OIIO::TypeDesc::FLOAT;
      spec.channelformats[10] = OIIO::TypeDesc::FLOAT;  // object ids up to 2^24 stay exact
    }
    spec.attribute("compression", "zip");
    spec.attribute("oiio:ColorSpace", "Linear");
    std::vector<float> data(pixels * names.size());
    for (std::size_t p = 0; p < pixels; ++p) {
      float* o = &data[p * names.size()];
      for (int c = 0; c < 3; ++c) o[c] = shown[p * 3 + static_cast<std::size_t>(c)];
      if (denoised)
        for (int c = 0; c < 3; ++c) o[rawAt + static_cast<std::size_t>(c)] = image.color[p * 3 + static_cast<std::size_t>(c)];
      if (!aux) continue;
      for (int c = 0; c < 3; ++c) {
        o[3 + c] = image.albedo[p * 3 + static_cast<std::size_t>(c)];
        o[6 + c] = image.normal[p * 3 + static_cast<std::size_t>(c)];
      }
      o[9] = std::isfinite(image.depth[p]) ? image.depth[p] : 3.0e38f;
      o[10] = static_cast<float>(image.objectId[p]);
    }
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) return fail(cat("cannot create an EXR writer: ", OIIO::geterror()));
    if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, data.data()) || !out->close())
      return fail(out->geterror());
  } else if (ext == "png") {
    std::vector<std::uint8_t> rgba(pixels * 4);
    try {
      ColorConfig::get()->toDisplay8(image.shown().data(), pixels, display, rgba.data());
    } catch (const std::exception& e) {
      return fail(e.what());
    }
    OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    spec.attribute("oiio:UnassociatedAlpha", 1);
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) return fail(cat("cannot create a PNG writer: ", OIIO::geterror()));
    if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, rgba.data()) || !out->close())
      return fail(out->geterror());
  } else {
    return R::failure(cat(file.string(), ": unknown output format '.", ext, "' (use .exr or .png)"));
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) return fail(cat("cannot move the finished file into place: ", ec.message()));
  return true;
}

}  // namespace retile
