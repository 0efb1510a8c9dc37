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

/* The guide slot of u among n intervals. */
static int guide_slot(int n, float u) {
  const int k = (int)(u * (float)n);
  return k >= n ? n - 1 : k < 0 ? 0 : k;
}

/* From interval i (a guide's entry, never past the answer) up to the i with
 * cdf[i] <= u < cdf[i + 1] among n intervals: a walk of a step or two. */
static int walk(const float *cdf, int n, int i, float u) {
  while (i < n - 1 && cdf[i + 1] <= u) i++;
  return i;
}

/* The i with cdf[i] <= u < cdf[i + 1] among n intervals (never an empty
 * one), from its guide. */
static int find(const float *cdf, const uint32_t *guide, int n, float u) {
  return walk(cdf, n, (int)guide[guide_slot(n, u)], u);
}

/* The point in cell (xx, yy) that (u1, u2) maps to. */
static void cell_point(const fr_dist2d *d, int xx, int yy, float u1, float u2, float *u, float *v) {
  const float *c = d->cdf_row + (size_t)yy * ((size_t)d->w + 1);
  const float dv = d->cdf_marg[yy + 1] - d->cdf_marg[yy], du = c[xx + 1] - c[xx];
  const float fv = dv > 0.0f ? (u2 - d->cdf_marg[yy]) / dv : 0.5f, fu = du > 0.0f ? (u1 - c[xx]) / du : 0.5f;
  *u = ((float)xx + (fu < 0.0f ? 0.0f : fu)) / (float)d->w;
  *v = ((float)yy + (fv < 0.0f ? 0.0f : fv)) / (float)d->h;
  if (*u >= 1.0f) *u = 0.99999994f;
  if (*v >= 1.0f) *v = 0.99999994f;
}

void fr_dist2d_sample(const fr_dist2d *d, float u1, float u2, float *u, float *v, int *x, int *y) {
  const int yy = find(d->cdf_marg, d->guide_marg, d->h, u2);
  const float *c = d->cdf_row + (size_t)yy * ((size_t)d->w + 1);
  const int xx = find(c, d->guide_row + (size_t)yy * d->w, d->w, u1);
  cell_point(d, xx, yy, u1, u2, u, v);
  *x = xx, *y = yy;
}

void fr_dist2d_sample_batch(const fr_dist2d *d, size_t n, const float *u1, const float *u2, float *u, float *v, int *x,
                            int *y) {
  const size_t w = (size_t)d->w;
  /* the rows from the marginal (small: it stays in cache); their columns'
   * guide entries fetched, one each: a row's tables are far apart */
  for (size_t j = 0; j < n; j++) {
    y[j] = find(d->cdf_marg, d->guide_marg, d->h, u2[j]);
    __builtin_prefetch(d->guide_row + (size_t)y[j] * w + (size_t)guide_slot(d->w, u1[j]));
  }
  /* the guides read, the cumulative sums they point at fetched */
  for (size_t j = 0; j < n; j++) {
    x[j] = (int)d->guide_row[(size_t)y[j] * w + (size_t)guide_slot(d->w, u1[j])];
    __builtin_prefetch(d->cdf_row + (size_t)y[j] * (w + 1) + (size_t)x[j] + 1);
  }
  /* the walks from the guides, and the points */
  for (size_t j = 0; j < n; j++) {
    x[j] = walk(d->cdf_row + (size_t)y[j] * (w + 1), d->w, x[j], u1[j]);
    cell_point(d, x[j], y[j], u1[j], u2[j], u + j, v + j);
  }
}

float fr_dist2d_pdf(const fr_dist2d *d, int x, int y) {
  return d->weight[(size_t)y * d->w + x] * d->pdf_scale;
}
