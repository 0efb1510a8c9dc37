/*
 * Analytic spheres: the scene's second primitive (the SPD scenes are made of
 * them). A hit's prim numbers spheres after the triangles: prim = number of
 * triangles + sphere index.
 *
 * The ray test is written once, as fr_sphere_roots below, on float
 * operations that the 16-wide version (trace/sphere16.h) repeats in the same
 * order, so single rays and packets agree bit for bit. It avoids the two
 * cancellations of the textbook quadratic (Haines et al., Ray Tracing Gems
 * ch. 7): the discriminant is taken from the ray's closest approach to the
 * centre, and the smaller root as c / q.
 */
#ifndef FR_GEOM_SPHERE_H
#define FR_GEOM_SPHERE_H
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include "frusta.h"

typedef struct fr_sphere { float c[3], r; } fr_sphere;

/* The spheres of a scene, in the order they were added. */
typedef struct fr_spheres {
  fr_sphere *s;
  uint32_t *mat;   /* material per sphere, FR_INVALID_ID for none */
  size_t n, cap;
} fr_spheres;

void fr_spheres_free(fr_spheres *set);
/* Rejects non-finite centres and radii that are not finite and > 0. */
fr_error fr_spheres_add(fr_spheres *set, const float c[3], float r, uint32_t mat);

/* Both roots of |o + t d - c| = r, near <= far; 0 (and no roots) if the
 * line misses. o and d need not be normalized. */
static inline int fr_sphere_roots(const fr_sphere *s, const float o[3], const float d[3], float *near, float *far) {
  float fx = o[0] - s->c[0], fy = o[1] - s->c[1], fz = o[2] - s->c[2];
  float a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  float b = -(fx * d[0] + fy * d[1] + fz * d[2]);
  float tc = b / a;                              /* closest approach */
  float lx = fx + tc * d[0], ly = fy + tc * d[1], lz = fz + tc * d[2];
  float h = s->r * s->r - (lx * lx + ly * ly + lz * lz);
  if (!(h >= 0.0f)) return 0;                    /* also NaN */
  float c = (fx * fx + fy * fy + fz * fz) - s->r * s->r;
  float q = b + copysignf(sqrtf(a * h), b);
  float t1 = q / a, t2 = q != 0.0f ? c / q : t1;
  *near = t1 < t2 ? t1 : t2;
  *far = t1 < t2 ? t2 : t1;
  return 1;
}

/* The nearest root in (tnear, tfar), from inside the sphere the far one. */
static inline int fr_sphere_hit(const fr_sphere *s, const float o[3], const float d[3], float tnear, float tfar,
                                float *t) {
  float t0, t1;
  if (!fr_sphere_roots(s, o, d, &t0, &t1)) return 0;
  float th = t0 > tnear ? t0 : t1;
  if (!(th > tnear && th < tfar)) return 0;
  *t = th;
  return 1;
}
#endif
