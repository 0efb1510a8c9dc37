/*
 * Shevtsov, Soupikov, Kapustin's test on a precomputed 48-byte record (after
 * Wald's projection test): the normal is stored divided by its dominant
 * component k, so t needs one division and the hit's two other coordinates
 * give the barycentrics through two stored edge equations. Triangles whose
 * normal is axis-aligned (n_u = n_v = 0, common in architecture) take a fast
 * path that skips two multiply-adds for t.
 *
 * Unlike the paper's record, ours keeps vertex a instead of the plane and edge
 * offsets (n_d, b_d, c_d; the same 12 words): every quantity is then taken
 * relative to the triangle, a - o, as in Möller's test. With absolute offsets
 * a scene 1e4 from the origin lost ~1e-3 in t, enough for rays leaving a
 * surface to hit it again, and small triangles lost ~1e-4 in barycentrics.
 *
 * It is fast for packets, since the record is compact and the test branch-free
 * per lane, but not watertight: the hit point is recomputed per triangle, so a
 * ray through a shared edge or vertex can miss both (2 of 25,600 test rays on
 * spd_tetra, whose tetrahedra meet at edges and vertices). Widening each
 * triangle by 2^-20 of its barycentric range closed those but made a ray
 * graze a hair in hairball; 2^-22 closed nothing. Single rays use the
 * watertight test (tri_watertight.h).
 */
#ifndef FR_GEOM_TRI_SHEVTSOV_H
#define FR_GEOM_TRI_SHEVTSOV_H
#include <math.h>
#include <stdint.h>
#include "base/vec3.h"

typedef struct fr_tri_shevtsov {
  float n_u, n_v, a_k;  /* normal / n_k; vertex a's k coordinate */
  int32_t k;            /* dominant axis; u = (k+1)%3, v = (k+2)%3 */
  float b_u, b_v, a_u;  /* beta  = b_u (h_u - a_u) + b_v (h_v - a_v) (weight of vertex 1) */
  uint32_t prim;
  float c_u, c_v, a_v;  /* gamma = c_u (h_u - a_u) + c_v (h_v - a_v) (weight of vertex 2) */
  uint32_t axis_aligned;
} fr_tri_shevtsov;

_Static_assert(sizeof(fr_tri_shevtsov) == 48, "Shevtsov record is 48 bytes");

/* 0 if the triangle is degenerate (no record made). */
int fr_tri_shevtsov_make(fr_tri_shevtsov *r, vec3 p0, vec3 p1, vec3 p2, uint32_t prim);

/* The division is deferred, as in the paper: hit point and barycentrics are
 * kept multiplied by det, compared after flipping signs by det's sign, and
 * only a hit divides. */
static inline int fr_tri_shevtsov_test(const fr_tri_shevtsov *r, vec3 o, vec3 d, float tnear, float tfar,
                                       float *t, float *u, float *v) {
  static const int next[3] = {1, 2, 0};
  int k = r->k, ku = next[k], kv = next[ku];
  /* the origin relative to vertex a */
  float wk = r->a_k - v3_get(o, k), wu = r->a_u - v3_get(o, ku), wv = r->a_v - v3_get(o, kv);
  float dk = v3_get(d, k), du = v3_get(d, ku), dv = v3_get(d, kv);
  float det, num; /* t = num / det */
  if (r->axis_aligned) {
    det = dk;
    num = wk;
  } else {
    det = (dk + r->n_u * du) + r->n_v * dv;
    num = (wk + r->n_u * wu) + r->n_v * wv;
  }
  float hu = num * du - wu * det, hv = num * dv - wv * det; /* (hit point - a) * det */
  float bd = r->b_u * hu + r->b_v * hv, gd = r->c_u * hu + r->c_v * hv;
  float sg = det < 0.0f ? -1.0f : 1.0f, ad = fabsf(det);
  float bs = bd * sg, gs = gd * sg, ns = num * sg;
  /* branchless mask: one combined condition, NaN fails it */
  int hit = (ad > 0.0f) & (bs >= 0.0f) & (gs >= 0.0f) & (bs + gs <= ad) & (ns > tnear * ad) & (ns < tfar * ad);
  if (!hit) return 0;
  float tt = num / det, inv = 1.0f / det;
  if (!(tt > tnear && tt < tfar)) return 0; /* rounding of the division */
  *t = tt; *u = bd * inv; *v = gd * inv;
  return 1;
}
#endif
