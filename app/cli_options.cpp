// The option helpers of cli.h: numbers read without the C library, ranges and defaults in the help.
#include <algorithm>
#include <charconv>
#include <cmath>

#include "cli.h"
#include "cli11.h"
#include "core/numbers.h"
#include "retile/log.h"
#include "retile/scene.h"

namespace retile::cli {

namespace {

Result<double> readNumber(const std::string& text, double lo, double hi) {
  auto v = numbers::toDouble(text);
  if (!v || !std::isfinite(*v)) return Result<double>::failure(cat("'", text, "' is not a number"));
  if (*v < lo || *v > hi) return Result<double>::failure(cat(text, " is outside ", numbers::format(lo), "..", numbers::format(hi)));
  return *v;
}

Result<ImageSize> readSize(const std::string& text) {
  auto x = text.find('x');
  if (x == std::string::npos) return Result<ImageSize>::failure(cat("'", text, "' is not WIDTHxHEIGHT"));
  auto w = readInt(text.substr(0, x), 1, kMaxImageSide);
  if (!w) return Result<ImageSize>::failure("width " + w.error());
  auto h = readInt(text.substr(x + 1), 1, kMaxImageSide);
  if (!h) return Result<ImageSize>::failure("height " + h.error());
  return ImageSize{w.value(), h.value()};
}

// An option read by `read`: CLI11 only collects the text. The check runs first (CLI11 puts the
// option's name before its message), so the callback's second reading cannot fail.
template <class Read, class Store>
CLI::Option* addRead(CLI::App& app, const std::string& name, Read read, Store store, const std::string& type, const std::string& help) {
  CLI::Validator check(
      [read](std::string& text) {
        auto r = read(text);
        return r ? std::string() : r.error();
      },
      "");
  return app
      .add_option_function<std::string>(
          name, [read, store](const std::string& text) { store(read(text).value()); }, help)
      ->check(check)
      ->type_name(type);
}

std::string withRange(const std::string& help, const std::string& range, const std::string& fallback) {
  return cat(help, " (", range, fallback.empty() ? "" : "; default: ", fallback, ")");
}

std::string intRange(int lo, int hi) { return cat(lo, "..", hi); }
std::string numberRange(double lo, double hi) { return numbers::format(lo) + ".." + numbers::format(hi); }
std::string sizeRange() { return cat("each side 1..", kMaxImageSide); }

}  // namespace

Result<int> readInt(const std::string& text, int lo, int hi) {
  int v = 0;
  auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size()) return Result<int>::failure(cat("'", text, "' is not a whole number"));
  if (v < lo || v > hi) return Result<int>::failure(cat(v, " is outside ", lo, "..", hi));
  return v;
}

CLI::Option* addInt(CLI::App& app, const std::string& name, int* out, int lo, int hi, const std::string& help) {
  return addRead(
      app, name, [lo, hi](const std::string& t) { return readInt(t, lo, hi); }, [out](int v) { *out = v; }, "N",
      withRange(help, intRange(lo, hi), std::to_string(*out)));
}

CLI::Option* addInt(CLI::App& app, const std::string& name, std::optional<int>* out, int lo, int hi, const std::string& help,
                    const std::string& otherwise) {
  return addRead(
      app, name, [lo, hi](const std::string& t) { return readInt(t, lo, hi); }, [out](int v) { *out = v; }, "N",
      withRange(help, intRange(lo, hi), otherwise));
}

CLI::Option* addNumber(CLI::App& app, const std::string& name, double* out, double lo, double hi, const std::string& help) {
  return addRead(
      app, name, [lo, hi](const std::string& t) { return readNumber(t, lo, hi); }, [out](double v) { *out = v; }, "X",
      withRange(help, numberRange(lo, hi), numbers::format(*out)));
}

CLI::Option* addNumber(CLI::App& app, const std::string& name, std::optional<double>* out, double lo, double hi, const std::string& help,
                       const std::string& otherwise) {
  return addRead(
      app, name, [lo, hi](const std::string& t) { return readNumber(t, lo, hi); }, [out](double v) { *out = v; }, "X",
      withRange(help, numberRange(lo, hi), otherwise));
}

CLI::Option* addSize(CLI::App& app, ImageSize* out, const std::string& help) {
  return addRead(
      app, "--size", readSize, [out](ImageSize v) { *out = v; }, "WxH", withRange(help, sizeRange(), cat(out->width, "x", out->height)));
}

CLI::Option* addSize(CLI::App& app, std::optional<ImageSize>* out, const std::string& help, const std::string& otherwise) {
  return addRead(
      app, "--size", readSize, [out](ImageSize v) { *out = v; }, "WxH", withRange(help, sizeRange(), otherwise));
}

CLI::Option* addScene(CLI::App& app, std::string* out) {
  return app.add_option("SCENE", *out, "a scene file (glTF, OBJ, FBX, PLY, Tungsten scene.json, .retile) or 'default'")
      ->required()
      ->type_name("");
}

CLI::Validator oneOf(const std::string& what, const std::vector<std::string>& names) {
  return CLI::Validator(
      [what, names](std::string& text) {
        if (std::find(names.begin(), names.end(), text) != names.end()) return std::string();
        std::string known;
        for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
        return cat("unknown ", what, " '", text, "' (", known, ")");
      },
      "");
}

}  // namespace retile::cli
