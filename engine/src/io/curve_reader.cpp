#include "io/curve_reader.h"

#include <array>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "core/files.h"
#include "retile/log.h"

namespace retile {

namespace {

// Little-endian fields read from a byte string, each checked against its end.
class Bytes {
 public:
  explicit Bytes(const std::string& d) : d_(d) {}
  template <typename T>
  bool read(T* v) {
    if (pos_ > d_.size() || d_.size() - pos_ < sizeof(T)) return false;
    std::memcpy(v, d_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  std::size_t left() const { return pos_ <= d_.size() ? d_.size() - pos_ : 0; }
  std::size_t pos() const { return pos_; }
  void seek(std::size_t p) { pos_ = p; }
  const char* at() const { return d_.data() + pos_; }

 private:
  const std::string& d_;
  std::size_t pos_ = 0;
};

using CurveResult = Result<CurveSet>;

// Yuksel's format (cemyuksel.com/research/hairmodels): a 128-byte header ("HAIR", strand and
// point counts, a bit field of which arrays follow, defaults, 88 bytes of text), then the arrays:
// segments per strand (uint16), points (3 floats), thickness, transparency, colour.
CurveResult readHair(const std::filesystem::path& path, const std::string& d) {
  const std::string name = path.string();
  Bytes in(d);
  char magic[4];
  std::uint32_t strands = 0, points = 0, fields = 0, defaultSegments = 0;
  float defaultThickness = 0, defaultTransparency = 0, defaultColor[3];
  if (!in.read(&magic) || std::memcmp(magic, "HAIR", 4) != 0)
    return CurveResult::failure(cat(name, ": not a .hair file (no HAIR signature)"));
  if (!in.read(&strands) || !in.read(&points) || !in.read(&fields) || !in.read(&defaultSegments) || !in.read(&defaultThickness) ||
      !in.read(&defaultTransparency) || !in.read(&defaultColor) || in.left() < 88)
    return CurveResult::failure(cat(name, ": truncated header"));
  in.seek(in.pos() + 88);
  const bool hasSegments = fields & 1u, hasPoints = fields & 2u, hasThickness = fields & 4u;
  if (!hasPoints) return CurveResult::failure(cat(name, ": the file has no points"));
  // What the arrays need, checked before anything is allocated.
  const std::uint64_t need = (hasSegments ? 2ull * strands : 0) + 12ull * points + (hasThickness ? 4ull * points : 0);
  if (need > in.left())
    return CurveResult::failure(
        cat(name, ": truncated (", strands, " strands and ", points, " points need ", need, " bytes, ", in.left(), " follow the header)"));
  CurveSet c;
  c.ends.resize(strands);
  std::uint64_t total = 0;
  for (std::uint32_t i = 0; i < strands; ++i) {
    std::uint16_t segments = 0;
    if (hasSegments) in.read(&segments);
    total += (hasSegments ? segments : defaultSegments) + 1ull;
    if (total > points) return CurveResult::failure(cat(name, ": its strands need more than the ", points, " points it has"));
    c.ends[i] = static_cast<std::uint32_t>(total);
  }
  c.positions.resize(points);
  std::memcpy(c.positions.data(), in.at(), 12ull * points);
  in.seek(in.pos() + 12ull * points);
  c.radii.assign(points, defaultThickness);
  if (hasThickness) std::memcpy(c.radii.data(), in.at(), 4ull * points);
  c.positions.resize(total);
  c.radii.resize(total);
  return c;
}

// Tungsten's format (CurveIO's Fiber): a 40-byte header (8 bytes of signature, version 1,
// content type 0, header length, vertex and curve counts), then attributes, each a descriptor
// (its own length, the data's, flags, value type and count, a name) and its data; a descriptor
// length of 0 ends them. Read: num_vertices (per curve, uint16), position (3 floats), width.
CurveResult readFiber(const std::filesystem::path& path, const std::string& d) {
  const std::string name = path.string();
  static constexpr std::array<unsigned char, 8> kMagic{0x80, 0xBF, 0x80, 0x46, 0x49, 0x42, 0x45, 0x52};
  Bytes in(d);
  std::array<unsigned char, 8> magic{};
  std::uint16_t major = 0, minor = 0;
  std::uint32_t content = 0;
  std::uint64_t headerLength = 0, vertices = 0, curves = 0;
  if (!in.read(&magic) || magic != kMagic) return CurveResult::failure(cat(name, ": not a .fiber file (no FIBER signature)"));
  if (!in.read(&major) || !in.read(&minor) || !in.read(&content) || !in.read(&headerLength) || !in.read(&vertices) || !in.read(&curves))
    return CurveResult::failure(cat(name, ": truncated header"));
  if (major != 1 || content != 0)
    return CurveResult::failure(cat(name, ": fiber version ", major, " content type ", content, " is not supported (1, 0)"));
  // Every vertex has its position in the file, and every curve its count.
  if (vertices > d.size() / 12 || curves > d.size() / 2)
    return CurveResult::failure(cat(name, ": ", vertices, " vertices and ", curves, " curves cannot fit in ", d.size(), " bytes"));
  CurveSet c;
  std::vector<std::uint16_t> counts;
  std::uint64_t offset = headerLength;
  bool positions = false;
  for (int attributes = 0; attributes < 4096; ++attributes) {
    if (offset > d.size()) return CurveResult::failure(cat(name, ": an attribute starts past the end of the file"));
    in.seek(static_cast<std::size_t>(offset));
    std::uint64_t descriptorLength = 0, dataLength = 0;
    std::uint16_t flags = 0;
    std::uint8_t type = 0, perElement = 0;
    if (!in.read(&descriptorLength)) return CurveResult::failure(cat(name, ": truncated attribute list"));
    if (descriptorLength == 0) break;
    if (!in.read(&dataLength) || !in.read(&flags) || !in.read(&type) || !in.read(&perElement))
      return CurveResult::failure(cat(name, ": truncated attribute descriptor"));
    std::string attribute;
    while (in.left() > 0 && *in.at() != '\0' && attribute.size() < 256) {
      attribute.push_back(*in.at());
      in.seek(in.pos() + 1);
    }
    if (descriptorLength > d.size() - offset || dataLength > d.size() - offset - descriptorLength)
      return CurveResult::failure(cat(name, ": attribute '", attribute, "' runs past the end of the file"));
    const char* data = d.data() + offset + descriptorLength;
    const bool perCurve = flags & 1u;
    // Types 3 (uint16) and 8 (float), as Tungsten reads them; fewer values than elements
    // repeat the last, as in Tungsten.
    auto take = [&](auto* out, std::uint64_t elements) {
      using T = std::remove_pointer_t<decltype(out)>;
      const std::uint64_t present = dataLength / sizeof(T);
      if (present == 0) return false;
      for (std::uint64_t i = 0; i < elements; ++i) std::memcpy(&out[i], data + std::min(i, present - 1) * sizeof(T), sizeof(T));
      return true;
    };
    if (attribute == "num_vertices" && perCurve && type == 3 && perElement == 1) {
      counts.resize(static_cast<std::size_t>(curves));
      if (!take(counts.data(), curves)) counts.clear();
    } else if (attribute == "position" && !perCurve && type == 8 && perElement == 3) {
      c.positions.resize(static_cast<std::size_t>(vertices));
      positions = take(c.positions.data(), vertices);
    } else if (attribute == "width" && !perCurve && type == 8 && perElement == 1) {
      c.radii.resize(static_cast<std::size_t>(vertices));
      if (!take(c.radii.data(), vertices)) c.radii.clear();
    }
    offset += descriptorLength + dataLength;
  }
  if (!positions) return CurveResult::failure(cat(name, ": the file has no positions"));
  if (counts.empty()) return CurveResult::failure(cat(name, ": the file has no num_vertices"));
  if (c.radii.empty()) c.radii.assign(c.positions.size(), 0.0f);
  std::uint64_t total = 0;
  c.ends.resize(counts.size());
  for (std::size_t i = 0; i < counts.size(); ++i) {
    total += counts[i];
    if (total > vertices) return CurveResult::failure(cat(name, ": its curves need more than the ", vertices, " vertices it has"));
    c.ends[i] = static_cast<std::uint32_t>(total);
  }
  c.positions.resize(total);
  c.radii.resize(total);
  return c;
}

}  // namespace

Result<CurveSet> readCurves(const std::filesystem::path& path, std::vector<std::string>* warnings, const ImportOptions& options) {
  auto data = readFile(path, options.maxFileBytes);
  if (!data) return CurveResult::failure(data.error());
  const std::string ext = extensionLower(path);
  CurveResult read = ext == "hair"    ? readHair(path, data.value())
                     : ext == "fiber" ? readFiber(path, data.value())
                                      : CurveResult::failure(cat(path.string(), ": unsupported curve format '.", ext, "' (hair or fiber)"));
  if (!read) return read;
  CurveSet& c = read.value();
  // A strand with a node that is not finite is dropped whole (its spline would run off to
  // infinity); a radius that is negative or not finite is 0.
  CurveSet kept;
  std::size_t dropped = 0, radii = 0;
  for (std::size_t i = 0; i < c.ends.size(); ++i) {
    const std::uint32_t start = i ? c.ends[i - 1] : 0, end = c.ends[i];
    bool finite = true;
    for (std::uint32_t n = start; n < end && finite; ++n) finite = isFinite(c.positions[n]);
    if (!finite) {
      ++dropped;
      continue;
    }
    for (std::uint32_t n = start; n < end; ++n) {
      float r = c.radii[n];
      if (!(r >= 0) || !std::isfinite(r)) {
        r = 0;
        ++radii;
      }
      kept.positions.push_back(c.positions[n]);
      kept.radii.push_back(r);
    }
    kept.ends.push_back(static_cast<std::uint32_t>(kept.positions.size()));
  }
  if (dropped && warnings)
    warnings->push_back(cat(path.filename().string(), ": dropped ", dropped, " strands with a position that is not finite"));
  if (radii && warnings) warnings->push_back(cat(path.filename().string(), ": ", radii, " negative or non-finite radii taken as 0"));
  return kept;
}

}  // namespace retile
