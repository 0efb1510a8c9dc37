/* Sine and cosine of a fraction of a turn, for the samplers' angles. */
#ifndef FR_BASE_SINCOS_H
#define FR_BASE_SINCOS_H

/* sin and cos of 2 pi u for u >= 0 (a sample in [0, 1)), within 1e-7 of
 * the exact values: the nearest quarter turn taken out, the rest (at most
 * an eighth of a turn) by its Taylor series to x^9 and x^8, whose remainders
 * there are under 3e-8. Inline and branch-free: a path tracer takes one or
 * two a bounce, and libm's sincosf is a call with a general reduction. */
static inline void fr_sincos_turns(float u, float *s, float *c) {
  const float t = 4.0f * u;
  const int q = (int)(t + 0.5f); /* the nearest quarter turn (t >= 0: truncation is the floor) */
  const float x = (t - (float)q) * 1.57079632679489662f, x2 = x * x;
  const float sn = x * (1.0f + x2 * (-1.0f / 6 + x2 * (1.0f / 120 + x2 * (-1.0f / 5040 + x2 * (1.0f / 362880)))));
  const float cs = 1.0f + x2 * (-0.5f + x2 * (1.0f / 24 + x2 * (-1.0f / 720 + x2 * (1.0f / 40320))));
  /* turned by q quarters: (sn, cs), (cs, -sn), (-sn, -cs), (-cs, sn) */
  const int k = q & 3;
  const float a = k & 1 ? cs : sn, b = k & 1 ? sn : cs;
  *s = k & 2 ? -a : a;
  *c = (k == 1 || k == 2) ? -b : b;
}
#endif
