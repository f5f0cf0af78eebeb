#include "retile/math.h"

#include <algorithm>
#include <cmath>

namespace retile {

Mat4 Mat4::translate(Vec3 t) {
  Mat4 r;
  r.m[0][3] = t.x;
  r.m[1][3] = t.y;
  r.m[2][3] = t.z;
  return r;
}

Mat4 Mat4::scale(Vec3 s) {
  Mat4 r;
  r.m[0][0] = s.x;
  r.m[1][1] = s.y;
  r.m[2][2] = s.z;
  return r;
}

Mat4 Mat4::rotateX(float a) {
  Mat4 r;
  float c = std::cos(a), s = std::sin(a);
  r.m[1][1] = c;
  r.m[1][2] = -s;
  r.m[2][1] = s;
  r.m[2][2] = c;
  return r;
}

Mat4 Mat4::rotateY(float a) {
  Mat4 r;
  float c = std::cos(a), s = std::sin(a);
  r.m[0][0] = c;
  r.m[0][2] = s;
  r.m[2][0] = -s;
  r.m[2][2] = c;
  return r;
}

Mat4 Mat4::rotateZ(float a) {
  Mat4 r;
  float c = std::cos(a), s = std::sin(a);
  r.m[0][0] = c;
  r.m[0][1] = -s;
  r.m[1][0] = s;
  r.m[1][1] = c;
  return r;
}

Mat4 Mat4::lookAt(Vec3 eye, Vec3 target, Vec3 up) {
  Vec3 forward = normalize(target - eye);
  Vec3 right = normalize(cross(forward, up));
  if (length(right) == 0) {
    // Looking straight along `up`: any perpendicular will do, pick a stable one.
    right = normalize(cross(forward, std::abs(forward.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 0, 1}));
  }
  Vec3 trueUp = cross(right, forward);
  Mat4 r;
  for (int i = 0; i < 3; ++i) {
    r.m[i][0] = right[i];
    r.m[i][1] = trueUp[i];
    r.m[i][2] = -forward[i];
    r.m[i][3] = eye[i];
  }
  return r;
}

Vec3 Mat4::transformPoint(Vec3 p) const {
  Vec3 r;
  for (int i = 0; i < 3; ++i) r[i] = m[i][0] * p.x + m[i][1] * p.y + m[i][2] * p.z + m[i][3];
  float w = m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3];
  return (w != 1.0f && w != 0.0f) ? r / w : r;
}

Vec3 Mat4::transformVector(Vec3 v) const {
  Vec3 r;
  for (int i = 0; i < 3; ++i) r[i] = m[i][0] * v.x + m[i][1] * v.y + m[i][2] * v.z;
  return r;
}

Mat4 operator*(const Mat4& a, const Mat4& b) {
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += a.m[i][k] * b.m[k][j];
      r.m[i][j] = s;
    }
  return r;
}

Mat4 Mat4::transposed() const {
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = m[j][i];
  return r;
}

Mat4 Mat4::rotationPart() const {
  Vec3 x{m[0][0], m[1][0], m[2][0]}, y{m[0][1], m[1][1], m[2][1]};
  const float lx = length(x);
  if (!(lx > 1e-12f) || !std::isfinite(lx)) return {};
  x = x / lx;
  y = y - x * dot(x, y);
  const float ly = length(y);
  if (!(ly > 1e-6f * lx) || !std::isfinite(ly)) return {};
  y = y / ly;
  const Vec3 z = cross(x, y);
  Mat4 r;
  for (int row = 0; row < 3; ++row) {
    r.m[row][0] = x[row];
    r.m[row][1] = y[row];
    r.m[row][2] = z[row];
  }
  return r;
}

bool Mat4::isFinite() const {
  for (const auto& row : m)
    for (float v : row)
      if (!std::isfinite(v)) return false;
  return true;
}

Mat4 Mat4::inverse() const {
  // Gauss-Jordan with partial pivoting in double: transforms from files can be badly scaled.
  double a[4][8];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      a[i][j] = m[i][j];
      a[i][j + 4] = (i == j) ? 1.0 : 0.0;
    }
  for (int c = 0; c < 4; ++c) {
    int pivot = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::abs(a[r][c]) > std::abs(a[pivot][c])) pivot = r;
    if (std::abs(a[pivot][c]) < 1e-30) {
      Mat4 zero;
      for (auto& row : zero.m)
        for (float& v : row) v = 0;
      return zero;
    }
    if (pivot != c)
      for (int j = 0; j < 8; ++j) std::swap(a[c][j], a[pivot][j]);
    double inv = 1.0 / a[c][c];
    for (int j = 0; j < 8; ++j) a[c][j] *= inv;
    for (int r = 0; r < 4; ++r) {
      if (r == c) continue;
      double f = a[r][c];
      if (f == 0.0) continue;
      for (int j = 0; j < 8; ++j) a[r][j] -= f * a[c][j];
    }
  }
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = static_cast<float>(a[i][j + 4]);
  return r;
}

double Mat4::linearDeterminant() const {
  auto a = [&](int r, int c) { return static_cast<double>(m[r][c]); };
  return a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) +
         a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
}

Trs decompose(const Mat4& m) {
  Trs t;
  t.translation = m.translation();
  Vec3 col[3];
  for (int j = 0; j < 3; ++j) col[j] = Vec3{m.m[0][j], m.m[1][j], m.m[2][j]};
  t.scale = Vec3{length(col[0]), length(col[1]), length(col[2])};
  if (m.linearDeterminant() < 0) t.scale.x = -t.scale.x;  // mirrored
  float r[3][3];
  for (int j = 0; j < 3; ++j) {
    const float s = j == 0 ? t.scale.x : j == 1 ? t.scale.y : t.scale.z;
    const Vec3 c = s != 0.0f ? col[j] / s : Vec3{j == 0 ? 1.0f : 0.0f, j == 1 ? 1.0f : 0.0f, j == 2 ? 1.0f : 0.0f};
    r[0][j] = c.x;
    r[1][j] = c.y;
    r[2][j] = c.z;
  }
  // R = Rz(c) Ry(b) Rx(a): r[2][0] = -sin b.
  const float sb = std::clamp(-r[2][0], -1.0f, 1.0f);
  const float b = std::asin(sb);
  float a, c;
  if (std::abs(sb) < 0.99999f) {
    a = std::atan2(r[2][1], r[2][2]);
    c = std::atan2(r[1][0], r[0][0]);
  } else {  // gimbal lock: only a - c (or a + c) is defined; put it all in c
    a = 0.0f;
    c = std::atan2(-r[0][1], r[1][1]);
  }
  t.rotationDegrees = Vec3{degrees(a), degrees(b), degrees(c)};
  return t;
}

Mat4 compose(const Trs& t) {
  return Mat4::translate(t.translation) * Mat4::rotateZ(radians(t.rotationDegrees.z)) * Mat4::rotateY(radians(t.rotationDegrees.y)) *
         Mat4::rotateX(radians(t.rotationDegrees.x)) * Mat4::scale(t.scale);
}

Bounds3 transformBounds(const Mat4& m, const Bounds3& b) {
  Bounds3 r;
  if (b.empty()) return r;
  for (int i = 0; i < 8; ++i) {
    Vec3 p{(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z};
    r.grow(m.transformPoint(p));
  }
  return r;
}

}  // namespace retile
