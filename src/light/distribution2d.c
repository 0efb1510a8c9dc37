#include "light/distribution2d.h"
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"

/* guide[k] = the first i in [0, n) with cdf[i + 1] > k / n (n - 1 if none) */
static void build_guide(const float *cdf, int n, uint32_t *guide) {
  int i = 0;
  for (int k = 0; k < n; k++) {
    const float u = (float)k / (float)n;
    while (i < n - 1 && cdf[i + 1] <= u) i++;
    guide[k] = (uint32_t)i;
  }
}

fr_error fr_dist2d_build(fr_dist2d *d, const float *weight, int w, int h) {
  memset(d, 0, sizeof *d);
  const size_t n = (size_t)w * (size_t)h;
  d->w = w, d->h = h;
  d->weight = malloc(fr_mul_size(n, sizeof(float)));
  d->cdf_row = malloc(fr_mul_size((size_t)h, ((size_t)w + 1) * sizeof(float)));
  d->cdf_marg = malloc(((size_t)h + 1) * sizeof(float));
  d->guide_row = malloc(fr_mul_size(n, sizeof(uint32_t)));
  d->guide_marg = malloc((size_t)h * sizeof(uint32_t));
  if (!d->weight || !d->cdf_row || !d->cdf_marg || !d->guide_row || !d->guide_marg) { fr_dist2d_free(d); return fr_fail(FR_ERR_NOMEM, "out of memory for a %dx%d distribution", w, h); }
  memcpy(d->weight, weight, n * sizeof(float));
  double *rows = calloc((size_t)h, sizeof(double));
  if (!rows) { fr_dist2d_free(d); return fr_fail(FR_ERR_NOMEM, "out of memory"); }
  double total = 0.0;
  for (int y = 0; y < h; y++) {
    float *c = d->cdf_row + (size_t)y * ((size_t)w + 1);
    double s = 0.0;
    c[0] = 0.0f;
    for (int x = 0; x < w; x++) { s += weight[(size_t)y * w + x]; c[x + 1] = (float)s; }
    for (int x = 1; x <= w; x++) c[x] = s > 0.0 ? (float)(c[x] / s) : (float)x / (float)w;
    c[w] = 1.0f;
    rows[y] = s;
    total += s;
  }
  if (!(total > 0.0)) { free(rows); fr_dist2d_free(d); return fr_fail(FR_ERR_ARG, "nothing to sample: every weight is 0"); }
  double s = 0.0;
  d->cdf_marg[0] = 0.0f;
  for (int y = 0; y < h; y++) { s += rows[y]; d->cdf_marg[y + 1] = (float)(s / total); }
  d->cdf_marg[h] = 1.0f;
  free(rows);
  d->total = total;
  d->pdf_scale = (float)((double)w * h / total);
  for (int y = 0; y < h; y++) build_guide(d->cdf_row + (size_t)y * ((size_t)w + 1), w, d->guide_row + (size_t)y * w);
  build_guide(d->cdf_marg, h, d->guide_marg);
  return FR_OK;
}

void fr_dist2d_free(fr_dist2d *d) {
  free(d->weight); free(d->cdf_row); free(d->cdf_marg); free(d->guide_row); free(d->guide_marg);
  memset(d, 0, sizeof *d);
}

/* The i with cdf[i] <= u < cdf[i + 1] among n intervals (never an empty
 * one), from its guide. */
static int find(const float *cdf, const uint32_t *guide, int n, float u) {
  return fr_dist2d_walk(cdf, n, (int)guide[fr_dist2d_slot(n, u)], u);
}

void fr_dist2d_sample(const fr_dist2d *d, float u1, float u2, float *u, float *v, int *x, int *y) {
  const int yy = find(d->cdf_marg, d->guide_marg, d->h, u2);
  const float *c = d->cdf_row + (size_t)yy * ((size_t)d->w + 1);
  const int xx = find(c, d->guide_row + (size_t)yy * d->w, d->w, u1);
  fr_dist2d_cell_point(d, xx, yy, u1, u2, u, v);
  *x = xx, *y = yy;
}

float fr_dist2d_pdf(const fr_dist2d *d, int x, int y) {
  return d->weight[(size_t)y * d->w + x] * d->pdf_scale;
}
