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
  TextureImage image;
  bool isFloat = false;
  std::string colorSpaceTag;
};

// Tungsten's LDR decoding (ImageIO::loadLdr with gamma correction): a 256-entry table of
// floor(255 (v/255)^2.2), kept in 8 bits; colour only, alpha stays as stored.
const std::array<std::uint8_t, 256>& gamma22Table() {
  static const std::array<std::uint8_t, 256> table = [] {
    std::array<std::uint8_t, 256> t{};
    for (int v = 0; v < 256; ++v)
      t[static_cast<std::size_t>(v)] = static_cast<std::uint8_t>(std::floor(255.0 * std::pow(v / 255.0, 2.2) + 1e-9));
    return t;
  }();
  return table;
}

void decodeGamma22(TextureImage& image) {
  const auto& table = gamma22Table();
  if (image.eightBit()) {
    for (std::size_t i = 0; i < image.rgba8.size(); ++i)
      if (i % 4 != 3) image.rgba8[i] = table[image.rgba8[i]];
    return;
  }
  for (std::size_t i = 0; i < image.rgba.size(); ++i) {
    if (i % 4 == 3) continue;
    const long v = std::lround(std::clamp(image.rgba[i], 0.0f, 1.0f) * 255.0f);
    image.rgba[i] = static_cast<float>(table[static_cast<std::size_t>(v)]) / 255.0f;
  }
}

// Whether the colour configuration decodes sRGB textures by the curve the shader applies to 8-bit
// texels (it does with the shipped config; a $OCIO config may also change the primaries, and
// then 8-bit textures are decoded here, to floats). Judged once, on every byte value of each
// channel alone, to well within a half float's precision.
bool configDecodesSrgbByTheCurve() {
  static const bool same = [] {
    std::vector<float> px(256 * 3 * 4, 0.0f);
    for (std::size_t v = 0; v < 256; ++v)
      for (std::size_t c = 0; c < 3; ++c) {
        px[(v * 3 + c) * 4 + c] = static_cast<float>(v) / 255.0f;
        px[(v * 3 + c) * 4 + 3] = 1.0f;
      }
    ColorConfig::get()->srgbToLinear(px.data(), 256 * 3);
    for (std::size_t v = 0; v < 256; ++v)
      for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t k = 0; k < 3; ++k) {
          const float want = k == c ? srgbCurve(static_cast<float>(v) / 255.0f) : 0.0f;
          if (!(std::abs(px[(v * 3 + c) * 4 + k] - want) <= 2e-4f * want + 1e-6f)) return false;
        }
    return true;
  }();
  return same;
}

// eightBit: keep an 8-bit source's bytes (TextureImage::rgba8) instead of converting to floats.
Result<Decoded> decode(const std::string& name, OIIO::Filesystem::IOProxy* proxy, const ImageLimits& limits, bool eightBit) {
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
  const int nc = spec.nchannels;
  const auto stride = static_cast<std::uint64_t>(nc);
  eightBit = eightBit && spec.format == OIIO::TypeDesc::UINT8 && spec.channelformats.empty();
  Decoded d;
  d.isFloat = spec.format.basetype == OIIO::TypeDesc::FLOAT || spec.format.basetype == OIIO::TypeDesc::HALF ||
              spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  d.colorSpaceTag = lowercase(std::string(spec.get_string_attribute("oiio:ColorSpace")));
  TextureImage& img = d.image;
  img.width = spec.width;
  img.height = spec.height;
  img.hasAlpha = spec.alpha_channel >= 0 && spec.alpha_channel < nc;
  const auto alpha = static_cast<std::uint64_t>(std::max(spec.alpha_channel, 0));
  // Grey sources fill all three colour channels.
  auto expand = [&](const auto* src, auto* out, auto one) {
    for (std::uint64_t p = 0; p < pixels; ++p) {
      const auto* s = &src[p * stride];
      auto* o = &out[p * 4];
      o[0] = s[0];
      o[1] = nc < 3 ? s[0] : s[1];
      o[2] = nc < 3 ? s[0] : s[2];
      o[3] = img.hasAlpha ? s[alpha] : one;
    }
  };
  // Halves below 6.1e-5 convert correctly only with denormals kept (core/process.h), so the
  // conversion runs here, in this thread, not in OpenImageIO's pool, whose threads may flush them.
  KeepDenormals keep;
  in->threads(1);
  if (eightBit) {
    std::vector<std::uint8_t> tmp(pixels * stride);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT8, tmp.data()))
      return R::failure(cat(name, ": cannot decode the image: ", in->geterror()));
    img.rgba8.resize(pixels * 4);
    expand(tmp.data(), img.rgba8.data(), std::uint8_t{255});
  } else {
    std::vector<float> tmp(pixels * stride);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, tmp.data()))
      return R::failure(cat(name, ": cannot decode the image: ", in->geterror()));
    img.rgba.resize(pixels * 4);
    expand(tmp.data(), img.rgba.data(), 1.0f);
  }
  return d;
}

}  // namespace

std::array<float, 256> TextureImage::byteValues() const {
  std::array<float, 256> values{};
  for (std::size_t v = 0; v < 256; ++v) {
    const float f = static_cast<float>(v) / 255.0f;
    values[v] = curve == Curve::SRGB ? srgbCurve(f) : f;
  }
  return values;
}

LinearImage TextureImage::toLinear() && {
  LinearImage out;
  out.width = width;
  out.height = height;
  out.hasAlpha = hasAlpha;
  if (!eightBit()) {
    out.rgba = std::move(rgba);
    return out;
  }
  const std::array<float, 256> colour = byteValues();
  out.rgba.resize(rgba8.size());
  for (std::size_t i = 0; i < rgba8.size(); ++i) out.rgba[i] = i % 4 == 3 ? static_cast<float>(rgba8[i]) / 255.0f : colour[rgba8[i]];
  rgba8 = {};
  return out;
}

Result<LinearImage> readImageRaw(const fs::path& file, const ImageLimits& limits) {
  std::error_code ec;
  if (!fs::exists(file, ec)) return Result<LinearImage>::failure(cat(file.string(), ": file not found"));
  auto d = decode(file.string(), nullptr, limits, false);
  if (!d) return Result<LinearImage>::failure(d.error());
  return std::move(d->image).toLinear();
}

Result<TextureImage> loadTexture(const Texture& tex, const fs::path& base, const ImageLimits& limits) {
  using R = Result<TextureImage>;
  Result<Decoded> d = Result<Decoded>::failure("");
  if (tex.kind == TextureKind::Embedded) {
    if (tex.encoded.empty()) return R::failure(cat("texture '", tex.name, "': embedded image is empty"));
    OIIO::Filesystem::IOMemReader mem(const_cast<std::uint8_t*>(tex.encoded.data()), tex.encoded.size());
    std::string hint = tex.encodedFormat.empty() ? "png" : tex.encodedFormat;
    if (hint == "jpeg") hint = "jpg";
    d = decode(cat("embedded.", hint), &mem, limits, true);
    if (!d) return R::failure(cat("texture '", tex.name, "': ", d.error()));
  } else if (tex.kind == TextureKind::File) {
    auto resolved = resolveScenePath(base, tex.path.string());
    if (!resolved) {
      fs::path shown = tex.path.is_absolute() ? tex.path : base / tex.path;
      return R::failure(cat(shown.string(), ": texture file not found"));
    }
    d = decode(resolved->string(), nullptr, limits, true);
    if (!d) return R::failure(d.error());
  } else {
    return R::failure(cat("texture '", tex.name, "' is procedural and has no image"));
  }
  Decoded& dec = d.value();
  TextureImage& img = dec.image;
  bool srgb = false;
  switch (tex.colorSpace) {
    case TextureColorSpace::Gamma22:
      if (!dec.isFloat) decodeGamma22(img);
      break;
    case TextureColorSpace::SRGB: srgb = true; break;
    case TextureColorSpace::Linear:
    case TextureColorSpace::Raw: srgb = false; break;
    case TextureColorSpace::Auto:
      // Integer data is encoded unless its file says linear: OpenImageIO tags a PPM "Rec709" (the
      // transfer curve of its standard, not linear light), which the sRGB curve decodes closely.
      srgb = dec.isFloat ? dec.colorSpaceTag == "srgb" || dec.colorSpaceTag.rfind("gamma", 0) == 0 : dec.colorSpaceTag != "linear";
      break;
  }
  if (srgb && img.eightBit() && configDecodesSrgbByTheCurve()) {
    img.curve = TextureImage::Curve::SRGB;
  } else if (srgb) {
    LinearImage linear = std::move(img).toLinear();  // the bytes as they are: the curve is linear so far
    ColorConfig::get()->srgbToLinear(linear.rgba.data(), linear.rgba.size() / 4);
    img = TextureImage{};
    img.width = linear.width;
    img.height = linear.height;
    img.hasAlpha = linear.hasAlpha;
    img.rgba = std::move(linear.rgba);
  }
  return std::move(img);
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
