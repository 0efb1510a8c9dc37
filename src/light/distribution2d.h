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
/* n points as fr_dist2d_sample makes each (the same bits), their table
 * lookups overlapped: each stage's memory accesses for all n are begun
 * before the next stage reads them. */
void fr_dist2d_sample_batch(const fr_dist2d *d, size_t n, const float *u1, const float *u2, float *u, float *v, int *x,
                            int *y);
/* The density over the unit square in cell (x, y), w h weight / total. */
float fr_dist2d_pdf(const fr_dist2d *d, int x, int y);
#endif
