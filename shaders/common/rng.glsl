// Random numbers that depend only on (pixel, sample index, seed): any sample can be replayed.
#ifndef RETILE_RNG_GLSL
#define RETILE_RNG_GLSL

uint pcgHash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

struct Rng {
  uint state;
};

Rng rngInit(uint pixel, uint sampleIndex, uint seed) {
  Rng r;
  r.state = pcgHash(pixel ^ pcgHash(sampleIndex ^ pcgHash(seed + 0x9e3779b9u)));
  return r;
}

// PCG-RXS-M-XS step; 24 high-quality bits per float in [0, 1).
float rand(inout Rng r) {
  r.state = r.state * 747796405u + 2891336453u;
  uint word = ((r.state >> ((r.state >> 28u) + 4u)) ^ r.state) * 277803737u;
  word = (word >> 22u) ^ word;
  return float(word >> 8) * (1.0 / 16777216.0);
}

vec2 rand2(inout Rng r) {
  float a = rand(r);
  return vec2(a, rand(r));
}

// A sample's position in its pixel: the R2 sequence (Roberts, "The unreasonable effectiveness of
// quasirandom sequences", 2018) over the pixel's sample index, shifted by a random offset per pixel
// (a Cranley-Patterson rotation, so neighbouring pixels do not share a pattern). Any run of
// consecutive samples of a pixel covers it far more evenly than independent ones: a light's or a
// window's edge converges much faster. In 32-bit fixed point, exact for any index.
vec2 pixelJitter(uint pixel, uint sampleIndex, uint seed) {
  uint h = pcgHash(pixel ^ pcgHash(seed + 0x85ebca6bu));
  uvec2 offset = uvec2(h, pcgHash(h));
  uvec2 x = offset + uvec2(3242174889u, 2447445413u) * sampleIndex;  // 2^32 times (1/phi2, 1/phi2^2)
  return vec2(x >> 8u) * (1.0 / 16777216.0);
}

#endif
