// Text <-> number for files and command lines. Never the C library's strtod/printf family: those
// follow the process locale, which Qt sets from the environment, so under a comma-decimal locale
// (de_DE, fr_FR, ru_RU...) they stop reading at '.' and write "0,5". Any thread may call.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace retile::numbers {

// Reads the longest number at the start of [first, last) as std::from_chars does (no leading '+',
// no hex, "inf" and "nan" spelled out). Unlike from_chars, a value too small for T reads as a
// signed zero and one too large as a signed infinity: the caller, who knows what the value is for,
// decides whether that is an error. Returns where the number ended, or nullptr when none starts at
// first.
const char* read(const char* first, const char* last, double* out);
const char* read(const char* first, const char* last, float* out);

// The whole of text must be one number (after the same rules); no surrounding spaces.
std::optional<double> toDouble(std::string_view text);
std::optional<float> toFloat(std::string_view text);

// The shortest text that reads back as the same value. A double that holds a float exactly is
// written as that float's shortest form, so 0.1f becomes "0.1", not "0.10000000149011612"; whole
// numbers below 1e15 are written without an exponent.
void append(std::string& out, double value);
std::string format(double value);

}  // namespace retile::numbers
