#include "core/numbers.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <system_error>

namespace retile::numbers {
namespace {

// from_chars reports out of range without saying which way. The decimal order of magnitude of
// the digits it consumed tells: any value outside a float's or double's range is either above
// 1e38 or below 1e-45, so a negative order is an underflow.
bool isUnderflow(const char* first, const char* last) {
  const char* p = first;
  if (p < last && *p == '-') ++p;
  bool seen = false, afterPoint = false;
  long intDigits = 0, leadingFractionZeros = 0;
  for (; p < last; ++p) {
    char c = *p;
    if (c == '.') {
      afterPoint = true;
    } else if (c >= '0' && c <= '9') {
      if (!seen && c != '0') seen = true;
      if (!afterPoint && seen) ++intDigits;
      if (afterPoint && !seen) ++leadingFractionZeros;
    } else {
      break;
    }
  }
  if (!seen) return true;  // all zeros: cannot overflow
  // the power of ten of the first non-zero digit
  long order = intDigits > 0 ? intDigits - 1 : -(leadingFractionZeros + 1);
  if (p < last && (*p == 'e' || *p == 'E')) {
    long exponent = 0;
    auto r = std::from_chars(p + 1 + (p + 1 < last && p[1] == '+'), last, exponent);
    if (r.ec == std::errc::result_out_of_range) return p + 1 < last && p[1] == '-';
    // Saturate: hundreds of digits before an exponent near the limit must not overflow the sum.
    if (exponent > 0 && order > std::numeric_limits<long>::max() - exponent) return false;
    if (exponent < 0 && order < std::numeric_limits<long>::min() - exponent) return true;
    order += exponent;
  }
  return order < 0;
}

template <class T>
const char* readImpl(const char* first, const char* last, T* out) {
  T v{};
  auto r = std::from_chars(first, last, v);
  if (r.ec == std::errc::result_out_of_range) {
    bool negative = first < last && *first == '-';
    T magnitude = isUnderflow(first, r.ptr) ? T(0) : std::numeric_limits<T>::infinity();
    *out = negative ? -magnitude : magnitude;
    return r.ptr;
  }
  if (r.ec != std::errc()) return nullptr;
  *out = v;
  return r.ptr;
}

template <class T>
std::optional<T> whole(std::string_view text) {
  T v{};
  const char* end = readImpl(text.data(), text.data() + text.size(), &v);
  if (!end || end != text.data() + text.size()) return std::nullopt;
  return v;
}

}  // namespace

const char* read(const char* first, const char* last, double* out) { return readImpl(first, last, out); }
const char* read(const char* first, const char* last, float* out) { return readImpl(first, last, out); }

std::optional<double> toDouble(std::string_view text) { return whole<double>(text); }
std::optional<float> toFloat(std::string_view text) { return whole<float>(text); }

void append(std::string& out, double value) {
  char buf[40];
  std::to_chars_result r;
  if (value == std::floor(value) && std::abs(value) < 1e15) {
    r = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::fixed);
  } else if (auto f = static_cast<float>(value); std::isfinite(f) && static_cast<double>(f) == value) {
    r = std::to_chars(buf, buf + sizeof buf, f);
  } else {
    r = std::to_chars(buf, buf + sizeof buf, value);
  }
  out.append(buf, r.ptr);
}

std::string format(double value) {
  std::string s;
  append(s, value);
  return s;
}

}  // namespace retile::numbers
