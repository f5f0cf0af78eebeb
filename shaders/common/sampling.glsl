#ifndef RETILE_SAMPLING_GLSL
#define RETILE_SAMPLING_GLSL

const float PI = 3.14159265358979323846;
const float INV_PI = 0.31830988618379067154;

// Orthonormal basis around n (Duff et al. 2017), stable for every n.
void makeFrame(vec3 n, out vec3 t, out vec3 b) {
  float s = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + n.z);
  float c = n.x * n.y * a;
  t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
  b = vec3(c, s + n.y * n.y * a, -n.y);
}

vec3 toLocal(vec3 v, vec3 t, vec3 b, vec3 n) { return vec3(dot(v, t), dot(v, b), dot(v, n)); }
vec3 toWorld(vec3 v, vec3 t, vec3 b, vec3 n) { return v.x * t + v.y * b + v.z * n; }

vec3 sampleCosineHemisphere(vec2 u) {
  // Concentric disk mapping, lifted to the hemisphere.
  vec2 o = 2.0 * u - 1.0;
  vec2 d;
  if (o.x == 0.0 && o.y == 0.0) {
    d = vec2(0.0);
  } else if (abs(o.x) > abs(o.y)) {
    float r = o.x;
    float th = (PI / 4.0) * (o.y / o.x);
    d = r * vec2(cos(th), sin(th));
  } else {
    float r = o.y;
    float th = (PI / 2.0) - (PI / 4.0) * (o.x / o.y);
    d = r * vec2(cos(th), sin(th));
  }
  float z = sqrt(max(0.0, 1.0 - dot(d, d)));
  return vec3(d, z);
}

vec3 sampleUniformSphere(vec2 u) {
  float z = 1.0 - 2.0 * u.x;
  float r = sqrt(max(0.0, 1.0 - z * z));
  float phi = 2.0 * PI * u.y;
  return vec3(r * cos(phi), r * sin(phi), z);
}

// Henyey and Greenstein's phase function of asymmetry g at the cosine between the propagation
// direction and the scattered one; it is also the pdf of sampleHenyeyGreenstein's directions.
float henyeyGreenstein(float cosTheta, float g) {
  float term = 1.0 + g * g - 2.0 * g * cosTheta;
  return (0.25 * INV_PI) * (1.0 - g * g) / (term * sqrt(term));
}

// A direction scattered from the propagation direction d by Henyey and Greenstein's phase
// function of asymmetry g (cos theta by its inverted CDF; near g = 0, the uniform sphere). The
// phase function is its own pdf: the sample's weight is 1.
vec3 sampleHenyeyGreenstein(vec3 d, float g, vec2 u) {
  float cosTheta = 1.0 - 2.0 * u.x;
  if (abs(g) > 1e-3) {
    float s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
    cosTheta = clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
  }
  float sinTheta = sqrt(max(0.0, 1.0 - cosTheta * cosTheta));
  float phi = 2.0 * PI * u.y;
  vec3 t, b;
  makeFrame(d, t, b);
  return toWorld(vec3(sinTheta * cos(phi), sinTheta * sin(phi), cosTheta), t, b, d);
}

// Uniform point on a triangle (barycentrics), area-preserving square-root mapping.
vec2 sampleTriangle(vec2 u) {
  float s = sqrt(u.x);
  return vec2(1.0 - s, u.y * s);
}

float powerHeuristic(float a, float b) {
  float a2 = a * a, b2 = b * b;
  return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
float maxComponent(vec3 c) { return max(c.x, max(c.y, c.z)); }

#endif
