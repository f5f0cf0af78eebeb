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

#endif
