/* Trigonometry in turns for the samplers and the environment's lookups:
 * inline polynomials, as accurate as float allows, where libm's are calls
 * with general range reductions (a path tracer takes several a bounce). */
#ifndef FR_BASE_TRIG_H
#define FR_BASE_TRIG_H
#include <math.h>

/* sin and cos of 2 pi u for u >= 0 (a sample in [0, 1)), within 1e-7 of
 * the exact values: the nearest quarter turn taken out, the rest (at most
 * an eighth of a turn) by its Taylor series to x^9 and x^8, whose remainders
 * there are under 3e-8. */
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
  *c = ((k == 1) | (k == 2)) ? -b : b;
}

/* atan2(y, x) / (2 pi), in [-1/2, 1/2] (atan2's signs and zeros): the
 * angle's tangent reduced to [0, 1], whose arctangent an odd polynomial of
 * degree 15 fits within 1.2e-7 radians (a least-squares fit, reweighted
 * toward the largest errors), then placed in its octant. */
static inline float fr_atan2_turns(float y, float x) {
  const float ax = fabsf(x), ay = fabsf(y), mx = ax > ay ? ax : ay, mn = ax > ay ? ay : ax;
  const float q = mn / mx, t = mx > 0.0f ? q : 0.0f, t2 = t * t; /* divided first: a select, no branch */
  float a = t * (9.999993443e-01f +
                 t2 * (-3.332986236e-01f +
                       t2 * (1.994656920e-01f +
                             t2 * (-1.390864849e-01f +
                                   t2 * (9.642246366e-02f +
                                         t2 * (-5.591300130e-02f + t2 * (2.186342701e-02f + t2 * -4.054697696e-03f)))))));
  if (ay > ax) a = 1.57079632679489662f - a;
  if (x < 0.0f) a = 3.14159265358979324f - a;
  return (signbit(y) ? -a : a) * 0.159154943091895336f;
}
#endif
