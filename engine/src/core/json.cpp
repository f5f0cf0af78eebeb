#include "core/json.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/numbers.h"
#include "retile/log.h"

namespace retile::json {

const Value* Value::find(std::string_view key) const {
  if (!isObject()) return nullptr;
  for (const auto& [k, v] : asObject())
    if (k == key) return &v;
  return nullptr;
}

void Value::set(std::string key, Value value) {
  if (!isObject()) *this = Value(Object{});
  asObject().emplace_back(std::move(key), std::move(value));
}

const char* typeName(Value::Type t) {
  switch (t) {
    case Value::Type::kNull: return "null";
    case Value::Type::kBool: return "a boolean";
    case Value::Type::kNumber: return "a number";
    case Value::Type::kString: return "a string";
    case Value::Type::kArray: return "an array";
    case Value::Type::kObject: return "an object";
  }
  return "?";
}

namespace {

class Parser {
 public:
  Parser(std::string_view text, const ParseLimits& limits) : s_(text), limits_(limits) {}

  Result<Value> run() {
    if (s_.size() > limits_.maxBytes) return fail("document is larger than the limit");
    // A UTF-8 byte order mark is legal noise in files written by some tools.
    if (s_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;
    Value v;
    if (!parseValue(v, 0)) return Result<Value>::failure(error_);
    skipSpace();
    if (pos_ != s_.size()) return fail("unexpected content after the end of the document");
    return v;
  }

 private:
  Result<Value> fail(const std::string& what) {
    setError(what);
    return Result<Value>::failure(error_);
  }

  bool setError(const std::string& what) {
    if (!error_.empty()) return false;
    int line = 1, col = 1;
    for (std::size_t i = 0; i < pos_ && i < s_.size(); ++i) {
      if (s_[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    error_ = cat("line ", line, ", column ", col, ": ", what);
    return false;
  }

  void skipSpace() {
    while (pos_ < s_.size()) {
      char c = s_[pos_];
      if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
        ++pos_;
      } else if (c == '/' && pos_ + 1 < s_.size() && s_[pos_ + 1] == '/') {
        // Tungsten's files are strict JSON, but hand-edited scene files often carry comments.
        while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
      } else {
        break;
      }
    }
  }

  bool parseValue(Value& out, int depth) {
    if (depth > limits_.maxDepth) return setError(cat("nesting deeper than ", limits_.maxDepth));
    skipSpace();
    if (pos_ >= s_.size()) return setError("unexpected end of file");
    char c = s_[pos_];
    if (c == '{') return parseObject(out, depth);
    if (c == '[') return parseArray(out, depth);
    if (c == '"') {
      std::string str;
      if (!parseString(str)) return false;
      out = Value(std::move(str));
      return true;
    }
    if (c == '-' || (c >= '0' && c <= '9')) return parseNumber(out);
    if (s_.compare(pos_, 4, "true") == 0) {
      pos_ += 4;
      out = Value(true);
      return true;
    }
    if (s_.compare(pos_, 5, "false") == 0) {
      pos_ += 5;
      out = Value(false);
      return true;
    }
    if (s_.compare(pos_, 4, "null") == 0) {
      pos_ += 4;
      out = Value();
      return true;
    }
    return setError(cat("unexpected character '", printable(c), "'"));
  }

  static std::string printable(char c) {
    if (c >= 32 && c < 127) return std::string(1, c);
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned char>(c));
    return buf;
  }

  bool parseObject(Value& out, int depth) {
    ++pos_;
    Object obj;
    skipSpace();
    if (pos_ < s_.size() && s_[pos_] == '}') {
      ++pos_;
      out = Value(std::move(obj));
      return true;
    }
    for (;;) {
      skipSpace();
      if (pos_ >= s_.size() || s_[pos_] != '"') return setError("expected a member name in quotes");
      std::string key;
      if (!parseString(key)) return false;
      skipSpace();
      if (pos_ >= s_.size() || s_[pos_] != ':') return setError("expected ':' after a member name");
      ++pos_;
      Value v;
      if (!parseValue(v, depth + 1)) return false;
      obj.emplace_back(std::move(key), std::move(v));
      skipSpace();
      if (pos_ >= s_.size()) return setError("unexpected end of file inside an object");
      if (s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (s_[pos_] == '}') {
        ++pos_;
        out = Value(std::move(obj));
        return true;
      }
      return setError("expected ',' or '}' in an object");
    }
  }

  bool parseArray(Value& out, int depth) {
    ++pos_;
    Array arr;
    skipSpace();
    if (pos_ < s_.size() && s_[pos_] == ']') {
      ++pos_;
      out = Value(std::move(arr));
      return true;
    }
    for (;;) {
      Value v;
      if (!parseValue(v, depth + 1)) return false;
      arr.push_back(std::move(v));
      skipSpace();
      if (pos_ >= s_.size()) return setError("unexpected end of file inside an array");
      if (s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (s_[pos_] == ']') {
        ++pos_;
        out = Value(std::move(arr));
        return true;
      }
      return setError("expected ',' or ']' in an array");
    }
  }

  bool parseNumber(Value& out) {
    std::size_t start = pos_;
    if (s_[pos_] == '-') ++pos_;
    auto digits = [&] {
      std::size_t d = pos_;
      while (pos_ < s_.size() && s_[pos_] >= '0' && s_[pos_] <= '9') ++pos_;
      return pos_ - d;
    };
    if (digits() == 0) return setError("malformed number");
    if (pos_ < s_.size() && s_[pos_] == '.') {
      ++pos_;
      if (digits() == 0) return setError("malformed number: no digits after '.'");
    }
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      ++pos_;
      if (pos_ < s_.size() && (s_[pos_] == '+' || s_[pos_] == '-')) ++pos_;
      if (digits() == 0) return setError("malformed number: no exponent digits");
    }
    std::string_view text = s_.substr(start, pos_ - start);
    auto d = numbers::toDouble(text);
    if (!d) return setError("malformed number");
    // Overflow to infinity is an error: no scene value needs it and it poisons the renderer.
    // Underflow reads as zero, as every other JSON reader does.
    if (!std::isfinite(*d)) return setError(cat("number out of range: ", text));
    out = Value(*d);
    return true;
  }

  static void appendUtf8(std::string& s, std::uint32_t cp) {
    if (cp < 0x80) {
      s += static_cast<char>(cp);
    } else if (cp < 0x800) {
      s += static_cast<char>(0xC0 | (cp >> 6));
      s += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
      s += static_cast<char>(0xE0 | (cp >> 12));
      s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      s += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
      s += static_cast<char>(0xF0 | (cp >> 18));
      s += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
      s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
      s += static_cast<char>(0x80 | (cp & 0x3F));
    }
  }

  bool parseHex4(std::uint32_t& cp) {
    if (pos_ + 4 > s_.size()) return setError("truncated \\u escape");
    cp = 0;
    for (int i = 0; i < 4; ++i) {
      char c = s_[pos_++];
      cp <<= 4;
      if (c >= '0' && c <= '9') cp |= static_cast<std::uint32_t>(c - '0');
      else if (c >= 'a' && c <= 'f') cp |= static_cast<std::uint32_t>(c - 'a' + 10);
      else if (c >= 'A' && c <= 'F') cp |= static_cast<std::uint32_t>(c - 'A' + 10);
      else return setError("bad hex digit in \\u escape");
    }
    return true;
  }

  bool parseString(std::string& out) {
    ++pos_;  // opening quote
    while (pos_ < s_.size()) {
      char c = s_[pos_++];
      if (c == '"') return true;
      if (static_cast<unsigned char>(c) < 0x20) return setError("control character inside a string");
      if (c != '\\') {
        out += c;
        continue;
      }
      if (pos_ >= s_.size()) break;
      char e = s_[pos_++];
      switch (e) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          std::uint32_t cp = 0;  // set by parseHex4 (a TSan build of GCC 12 cannot tell)
          if (!parseHex4(cp)) return false;
          if (cp >= 0xD800 && cp < 0xDC00) {
            std::uint32_t lo = 0;
            if (s_.compare(pos_, 2, "\\u") != 0) return setError("unpaired surrogate in \\u escape");
            pos_ += 2;
            if (!parseHex4(lo)) return false;
            if (lo < 0xDC00 || lo > 0xDFFF) return setError("unpaired surrogate in \\u escape");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
          } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
            return setError("unpaired surrogate in \\u escape");
          }
          appendUtf8(out, cp);
          break;
        }
        default: return setError(cat("unknown escape '\\", printable(e), "'"));
      }
    }
    return setError("unterminated string");
  }

  std::string_view s_;
  ParseLimits limits_;
  std::size_t pos_ = 0;
  std::string error_;
};

void writeString(std::string& out, const std::string& s) {
  out += '"';
  for (unsigned char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  out += '"';
}

bool isFlat(const Value& v) {
  if (!v.isArray()) return false;
  if (v.asArray().size() > 16) return false;
  for (const auto& e : v.asArray())
    if (e.isArray() || e.isObject()) return false;
  return true;
}

void writeValue(std::string& out, const Value& v, bool pretty, int indent) {
  auto newline = [&](int n) {
    if (!pretty) return;
    out += '\n';
    out.append(static_cast<std::size_t>(n) * 2, ' ');
  };
  switch (v.type()) {
    case Value::Type::kNull: out += "null"; break;
    case Value::Type::kBool: out += v.asBool() ? "true" : "false"; break;
    case Value::Type::kNumber:
      if (std::isfinite(v.asNumber())) numbers::append(out, v.asNumber());
      else out += "null";
      break;
    case Value::Type::kString: writeString(out, v.asString()); break;
    case Value::Type::kArray: {
      const Array& a = v.asArray();
      bool flat = isFlat(v);  // short vectors of numbers stay on one line
      out += '[';
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (i) out += flat && pretty ? ", " : ",";
        if (!flat) newline(indent + 1);
        writeValue(out, a[i], pretty, indent + 1);
      }
      if (!flat && !a.empty()) newline(indent);
      out += ']';
      break;
    }
    case Value::Type::kObject: {
      const Object& o = v.asObject();
      out += '{';
      for (std::size_t i = 0; i < o.size(); ++i) {
        if (i) out += ',';
        newline(indent + 1);
        writeString(out, o[i].first);
        out += pretty ? ": " : ":";
        writeValue(out, o[i].second, pretty, indent + 1);
      }
      if (!o.empty()) newline(indent);
      out += '}';
      break;
    }
  }
}

}  // namespace

Result<Value> parse(std::string_view text, const ParseLimits& limits) { return Parser(text, limits).run(); }

namespace {

bool findNonFinite(const Value& v, std::string& path) {
  const std::size_t at = path.size();
  if (v.isNumber()) return !std::isfinite(v.asNumber());
  if (v.isArray())
    for (std::size_t i = 0; i < v.asArray().size(); ++i) {
      path += cat("[", i, "]");
      if (findNonFinite(v.asArray()[i], path)) return true;
      path.resize(at);
    }
  if (v.isObject())
    for (const auto& [key, e] : v.asObject()) {
      path += path.empty() ? key : "." + key;
      if (findNonFinite(e, path)) return true;
      path.resize(at);
    }
  return false;
}

}  // namespace

std::string firstNonFinite(const Value& value) {
  std::string path;
  if (!findNonFinite(value, path)) return {};
  return path.empty() ? "the value" : path;
}

std::string write(const Value& value, bool pretty) {
  std::string out;
  writeValue(out, value, pretty, 0);
  if (pretty) out += '\n';
  return out;
}

}  // namespace retile::json

namespace retile::json {

bool toFloat(const Value& v, float* out) {
  if (!v.isNumber()) return false;
  double d = v.asNumber();
  if (!std::isfinite(static_cast<float>(d))) return false;
  *out = static_cast<float>(d);
  return true;
}

bool toVec3(const Value& v, Vec3* out) {
  float f;
  if (toFloat(v, &f)) {
    *out = Vec3{f};
    return true;
  }
  if (!v.isArray() || v.asArray().size() != 3) return false;
  Vec3 r;
  for (int i = 0; i < 3; ++i)
    if (!toFloat(v.asArray()[static_cast<std::size_t>(i)], &r[i])) return false;
  *out = r;
  return true;
}

bool toVec2(const Value& v, Vec2* out) {
  float f;
  if (toFloat(v, &f)) {
    *out = Vec2{f, f};
    return true;
  }
  if (!v.isArray() || v.asArray().size() != 2) return false;
  return toFloat(v.asArray()[0], &out->x) && toFloat(v.asArray()[1], &out->y);
}

Value fromVec3(Vec3 v) { return Value(Array{Value(v.x), Value(v.y), Value(v.z)}); }

}  // namespace retile::json
