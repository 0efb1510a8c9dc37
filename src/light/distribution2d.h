/*
 * A piecewise-constant 2D distribution over a w x h grid of non-negative
 * weights: a marginal over rows, a conditional over each row's columns,
 * sampled by inverting their cumulative sums (pbrt's Distribution2D).
 */
#ifndef FR_LIGHT_DISTRIBUTION2D_H
#define FR_LIGHT_DISTRIBUTION2D_H
#include <stdint.h>
#include "frusta.h"

typedef struct fr_dist2d {
  int w, h;
  float *cdf_row;   /* h x (w + 1): each row's normalized cumulative sum */
  float *cdf_marg;  /* h + 1 */
  /* guide tables (Chen's): guide[k] is the first interval i whose cdf[i + 1]
   * exceeds k / n, so that the search for u starts at guide[u n] and
   * walks a step or two, not log n */
  uint32_t *guide_row; /* h x w */
  uint32_t *guide_marg; /* h */
  float *weight;    /* w x h, the weights themselves */
  double total;     /* their sum */
  float pdf_scale;  /* w h / total */
} fr_dist2d;

/* FR_ERR_ARG when every weight is 0 (nothing to sample). */
fr_error fr_dist2d_build(fr_dist2d *d, const float *weight, int w, int h);
void fr_dist2d_free(fr_dist2d *d);
/* A point (u, v) in [0, 1)^2 from u1 (column) and u2 (row), and its cell
 * in *x, *y. */
void fr_dist2d_sample(const fr_dist2d *d, float u1, float u2, float *u, float *v, int *x, int *y);
/* The density over the unit square in cell (x, y), w h weight / total. */
float fr_dist2d_pdf(const fr_dist2d *d, int x, int y);

/* The searches' steps, inline so that the batch code (light/
 * environment_lanes.c, compiled per ISA) makes the same bits. */

/* The guide slot of u among n intervals. */
static inline int fr_dist2d_slot(int n, float u) {
  const int k = (int)(u * (float)n);
  return k >= n ? n - 1 : k < 0 ? 0 : k;
}

/* From interval i (a guide's entry, never past the answer) one step toward
 * the i with c[i] <= u < c[i + 1] among n intervals, c = cdf + at (one
 * base and an index, which vector code gathers from); c has n + 1
 * entries, so c[i + 1] is always there. */
static inline int fr_dist2d_step(const float *cdf, int at, int n, int i, float u) {
  return i + ((i < n - 1) & (cdf[at + i + 1] <= u));
}

/* ... all the way: a step or two. */
static inline int fr_dist2d_walk(const float *cdf, int n, int i, float u) {
  while (i < n - 1 && cdf[i + 1] <= u) i++;
  return i;
}

/* The point in cell (xx, yy) of a w x h grid that (u1, u2) maps to, from
 * the cumulative sums at the cell's ends: c0, c1 of its row's (at xx and
 * xx + 1), m0, m1 of the marginal's (at yy and yy + 1). */
static inline void fr_dist2d_cell_point_of(int w, int h, int xx, int yy, float c0, float c1, float m0, float m1,
                                           float u1, float u2, float *u, float *v) {
  const float dv = m1 - m0, du = c1 - c0;
  /* divided first and then chosen, so that vector code has no branch */
  const float qv = (u2 - m0) / dv, qu = (u1 - c0) / du;
  const float fv = dv > 0.0f ? qv : 0.5f, fu = du > 0.0f ? qu : 0.5f;
  const float pu = ((float)xx + (fu < 0.0f ? 0.0f : fu)) / (float)w;
  const float pv = ((float)yy + (fv < 0.0f ? 0.0f : fv)) / (float)h;
  *u = pu >= 1.0f ? 0.99999994f : pu;
  *v = pv >= 1.0f ? 0.99999994f : pv;
}

static inline void fr_dist2d_cell_point(const fr_dist2d *d, int xx, int yy, float u1, float u2, float *u, float *v) {
  const float *c = d->cdf_row + (size_t)yy * ((size_t)d->w + 1);
  fr_dist2d_cell_point_of(d->w, d->h, xx, yy, c[xx], c[xx + 1], d->cdf_marg[yy], d->cdf_marg[yy + 1], u1, u2, u, v);
}
#endif
