// Integer arithmetic that lavapipe would run one lane at a time, done in all lanes at once.
#ifndef RETILE_INTEGER_GLSL
#define RETILE_INTEGER_GLSL

// a / b, exact for every a and every b from 1 to 2^30, without an integer division: lavapipe
// divides integers one lane at a time, a scalar division for each (the bump maps' % cost the
// kitchen 7 % of its samples/s), and floats in all lanes at once. The first float quotient is
// within about a thousand of a / b (a rounded to 24 bits); the remainder it leaves, divided
// again, brings it within one, and a step either way settles it. Holds with a division a few
// ulps off, as GPUs may have it. (integer_probe.comp, tests/gpu/shader_math_test.cpp)
uint quotient(uint a, uint b) {
  float fb = float(b);
  uint q = uint(min(float(a) / fb, 4294967040.0));  // the largest float below 2^32
  q += uint(int(floor(float(int(a - q * b)) / fb)));
  int r = int(a - q * b);
  return r < 0 ? q - 1u : (uint(r) >= b ? q + 1u : q);
}

#endif
