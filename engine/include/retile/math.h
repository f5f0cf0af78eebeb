// Small value types shared by the scene document, the importers and the renderer. Plain
// structs with no invariants; any thread may use them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace retile {

struct Vec2 {
  float x = 0, y = 0;
  friend bool operator==(const Vec2&, const Vec2&) = default;
};

struct Vec3 {
  float x = 0, y = 0, z = 0;
  constexpr Vec3() = default;
  constexpr Vec3(float a, float b, float c) : x(a), y(b), z(c) {}
  constexpr explicit Vec3(float s) : x(s), y(s), z(s) {}
  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  friend bool operator==(const Vec3&, const Vec3&) = default;
};

struct Vec4 {
  float x = 0, y = 0, z = 0, w = 0;
  friend bool operator==(const Vec4&, const Vec4&) = default;
};

constexpr Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
constexpr Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
constexpr Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
constexpr Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
constexpr Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
constexpr Vec3 operator*(float s, Vec3 a) { return a * s; }
constexpr Vec3 operator/(Vec3 a, float s) { return {a.x / s, a.y / s, a.z / s}; }
constexpr Vec3& operator+=(Vec3& a, Vec3 b) { return a = a + b; }
constexpr Vec3& operator*=(Vec3& a, float s) { return a = a * s; }
constexpr float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline float length(Vec3 a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalize(Vec3 a) {
  float l = length(a);
  return l > 0 ? a / l : Vec3{0, 0, 0};
}
constexpr Vec3 min(Vec3 a, Vec3 b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
constexpr Vec3 max(Vec3 a, Vec3 b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline bool isFinite(Vec3 a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }
constexpr float maxComponent(Vec3 a) { return std::max(a.x, std::max(a.y, a.z)); }
constexpr float minComponent(Vec3 a) { return std::min(a.x, std::min(a.y, a.z)); }
constexpr float luminance(Vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

constexpr float kPi = 3.14159265358979323846f;
constexpr float radians(float deg) { return deg * (kPi / 180.0f); }
constexpr float degrees(float rad) { return rad * (180.0f / kPi); }

// Axis-aligned box; an empty box has min > max so that growing it by any point works.
struct Bounds3 {
  Vec3 lo{std::numeric_limits<float>::infinity()};
  Vec3 hi{-std::numeric_limits<float>::infinity()};
  void grow(Vec3 p) {
    lo = min(lo, p);
    hi = max(hi, p);
  }
  void grow(const Bounds3& b) {
    lo = min(lo, b.lo);
    hi = max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  Vec3 center() const { return (lo + hi) * 0.5f; }
  Vec3 extent() const { return hi - lo; }
  float area() const {
    if (empty()) return 0;
    Vec3 e = extent();
    return 2 * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

// Row-major 4x4 affine or projective matrix; points are column vectors (p' = M p).
struct Mat4 {
  float m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};

  static Mat4 identity() { return {}; }
  static Mat4 translate(Vec3 t);
  static Mat4 scale(Vec3 s);
  static Mat4 rotateX(float radians);
  static Mat4 rotateY(float radians);
  static Mat4 rotateZ(float radians);
  // Camera-to-world for a camera at `eye` looking at `target`: columns are right, up, -forward.
  static Mat4 lookAt(Vec3 eye, Vec3 target, Vec3 up);

  Vec3 transformPoint(Vec3 p) const;
  Vec3 transformVector(Vec3 v) const;
  Vec3 translation() const { return {m[0][3], m[1][3], m[2][3]}; }
  Mat4 inverse() const;  // general inverse; a singular matrix yields all zeros
  Mat4 transposed() const;
  // The determinant of the linear (upper 3x3) part, in double: negative where the transform
  // mirrors (turns a winding and a handedness), zero where it flattens.
  double linearDeterminant() const;
  // The rotation nearest in spirit to the linear part: its x, y and z columns made orthonormal
  // in that order (Gram-Schmidt), right-handed; identity when they are degenerate or not finite.
  Mat4 rotationPart() const;
  bool isFinite() const;
  friend Mat4 operator*(const Mat4& a, const Mat4& b);
  friend bool operator==(const Mat4&, const Mat4&) = default;
};

Bounds3 transformBounds(const Mat4& m, const Bounds3& b);

// A transform as an artist edits it: translate * rotateZ * rotateY * rotateX * scale, angles in
// degrees. decompose() reads any affine transform so (shear, which compose() cannot make, is
// dropped; a mirrored transform gets a negative x scale); compose(decompose(m)) is m for every
// transform without shear.
struct Trs {
  Vec3 translation{0.0f};
  Vec3 rotationDegrees{0.0f};  // about x, then y, then z
  Vec3 scale{1.0f};
};
Trs decompose(const Mat4& m);
Mat4 compose(const Trs& t);

}  // namespace retile
