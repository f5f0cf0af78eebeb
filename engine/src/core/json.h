// A small JSON reader and writer of our own, for scene files we must not trust: nesting depth
// and sizes are bounded, and every parse error names the line and column. Values are trees of
// plain containers; any thread may use its own values.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "retile/error.h"
#include "retile/math.h"

namespace retile::json {

class Value;
using Array = std::vector<Value>;
// Objects keep their members in file order (for readable round trips); lookups are linear,
// which is fine for the small objects scene files hold.
using Object = std::vector<std::pair<std::string, Value>>;

class Value {
 public:
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject };

  Value() = default;
  Value(std::nullptr_t) {}
  Value(bool b) : v_(b) {}
  Value(double d) : v_(d) {}
  Value(float d) : v_(static_cast<double>(d)) {}
  Value(int i) : v_(static_cast<double>(i)) {}
  Value(std::int64_t i) : v_(static_cast<double>(i)) {}
  Value(std::uint64_t i) : v_(static_cast<double>(i)) {}
  Value(std::uint32_t i) : v_(static_cast<double>(i)) {}
  Value(const char* s) : v_(std::string(s)) {}
  Value(std::string s) : v_(std::move(s)) {}
  Value(Array a) : v_(std::make_shared<Array>(std::move(a))) {}
  Value(Object o) : v_(std::make_shared<Object>(std::move(o))) {}

  Type type() const { return static_cast<Type>(v_.index()); }
  bool isNull() const { return type() == Type::kNull; }
  bool isBool() const { return type() == Type::kBool; }
  bool isNumber() const { return type() == Type::kNumber; }
  bool isString() const { return type() == Type::kString; }
  bool isArray() const { return type() == Type::kArray; }
  bool isObject() const { return type() == Type::kObject; }

  bool asBool() const { return std::get<bool>(v_); }
  double asNumber() const { return std::get<double>(v_); }
  const std::string& asString() const { return std::get<std::string>(v_); }
  const Array& asArray() const { return *std::get<std::shared_ptr<Array>>(v_); }
  const Object& asObject() const { return *std::get<std::shared_ptr<Object>>(v_); }
  Array& asArray() { return *std::get<std::shared_ptr<Array>>(v_); }
  Object& asObject() { return *std::get<std::shared_ptr<Object>>(v_); }

  // Member lookup; nullptr when this is not an object or has no such key.
  const Value* find(std::string_view key) const;
  // Appends a member to an object value.
  void set(std::string key, Value value);

 private:
  std::variant<std::monostate, bool, double, std::string, std::shared_ptr<Array>, std::shared_ptr<Object>> v_;
};

const char* typeName(Value::Type t);

struct ParseLimits {
  int maxDepth = 128;
  std::size_t maxBytes = std::size_t(1) << 31;
};

// Parses a whole document; trailing content other than whitespace is an error.
Result<Value> parse(std::string_view text, const ParseLimits& limits = {});

// Writes with two-space indentation; numbers round-trip floats exactly. JSON has no NaN or
// infinity: they are written as null (an infinite PSNR in a report), and a caller that must read
// its output back checks firstNonFinite before writing.
std::string write(const Value& value, bool pretty = true);

// Where the first NaN or infinite number in `value` sits ("materials[2].albedo[0]"), or an empty
// string when every number is finite.
std::string firstNonFinite(const Value& value);

}  // namespace retile::json

namespace retile::json {

// Lenient readers for scene files: a colour may be written as one number or three.
bool toFloat(const Value& v, float* out);
bool toVec3(const Value& v, Vec3* out);  // a number (splat) or an array of three numbers
bool toVec2(const Value& v, Vec2* out);
Value fromVec3(Vec3 v);

}  // namespace retile::json
