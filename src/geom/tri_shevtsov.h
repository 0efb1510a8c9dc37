/*
 * Shevtsov, Soupikov, Kapustin's test on a precomputed 48-byte record (after
 * Wald's projection test): the plane is stored divided by its dominant normal
 * component k, so t needs one division and the hit's two other coordinates give
 * the barycentrics through two stored edge equations. Triangles whose normal is
 * axis-aligned (n_u = n_v = 0, common in architecture) take a fast path that
 * skips two multiply-adds for t.
 *
 * It is fast for packets, since the record is compact and the test branch-free
 * per lane, but not watertight: the hit point is recomputed per triangle, so a
 * ray through a shared edge can miss both. The BVH4 leaves use the watertight test (tri_watertight.h).
 */
#ifndef FR_GEOM_TRI_SHEVTSOV_H
#define FR_GEOM_TRI_SHEVTSOV_H
#include <stdint.h>
#include "base/vec3.h"

typedef struct fr_tri_shevtsov {
  float n_u, n_v, n_d;  /* plane: p[k] + n_u p[u] + n_v p[v] = n_d */
  int32_t k;            /* dominant axis; u = (k+1)%3, v = (k+2)%3 */
  float b_u, b_v, b_d;  /* beta  = b_u h_u + b_v h_v + b_d (weight of vertex 1) */
  uint32_t prim;
  float c_u, c_v, c_d;  /* gamma = c_u h_u + c_v h_v + c_d (weight of vertex 2) */
  uint32_t axis_aligned;
} fr_tri_shevtsov;

_Static_assert(sizeof(fr_tri_shevtsov) == 48, "Shevtsov record is 48 bytes");

/* 0 if the triangle is degenerate (no record made). */
int fr_tri_shevtsov_make(fr_tri_shevtsov *r, vec3 p0, vec3 p1, vec3 p2, uint32_t prim);

static inline int fr_tri_shevtsov_test(const fr_tri_shevtsov *r, vec3 o, vec3 d, float tnear, float tfar,
                                       float *t, float *u, float *v) {
  static const int next[3] = {1, 2, 0};
  int k = r->k, ku = next[k], kv = next[ku];
  float ok = v3_get(o, k), ou = v3_get(o, ku), ov = v3_get(o, kv);
  float dk = v3_get(d, k), du = v3_get(d, ku), dv = v3_get(d, kv);
  float tt;
  if (r->axis_aligned) {
    tt = (r->n_d - ok) / dk;
  } else {
    float det = dk + r->n_u * du + r->n_v * dv;
    tt = (r->n_d - ok - r->n_u * ou - r->n_v * ov) / det;
  }
  if (!(tt > tnear && tt < tfar)) return 0;
  float hu = ou + tt * du, hv = ov + tt * dv;
  float beta = r->b_u * hu + r->b_v * hv + r->b_d;
  float gamma = r->c_u * hu + r->c_v * hv + r->c_d;
  /* branchless mask: one combined condition, NaN fails it */
  int hit = (beta >= 0.0f) & (gamma >= 0.0f) & (beta + gamma <= 1.0f);
  if (!hit) return 0;
  *t = tt; *u = beta; *v = gamma;
  return 1;
}
#endif
