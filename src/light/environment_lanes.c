/*
 * An image environment's samples and texel lookups for many paths at once
 * (light/environment.h), compiled once per ISA: the scalar calls' own
 * arithmetic (the inline steps of environment.h and distribution2d.h) lane
 * by lane, which the compiler turns into vector code with gathers, so the
 * answers are the same bits as one at a time. A guide table's walk takes
 * two steps in the vector loop; the lanes that need more (seldom) finish
 * one at a time. Each stage runs over the whole chunk before the next reads
 * what it fetched, so the chunk's cache misses overlap. Indices are ints:
 * fr_env_from_image keeps 4 w h below 2^31.
 */
#include "base/simd.h"
#include "light/environment.h"

enum { CHUNK = 64 };

static void sample_chunk(const fr_env *env, int m, const float *restrict u1, const float *restrict u2,
                         vec3 *restrict dir, vec3 *restrict le, float *restrict pdf) {
  const fr_env e = *env; /* a copy the loops see is not written */
  const fr_dist2d d = e.dist;
  const int w = d.w, h = d.h, row = w + 1;
  int x[CHUNK], y[CHUNK];
  float u[CHUNK], v[CHUNK], dx[CHUNK], dy[CHUNK], dz[CHUNK], r[CHUNK], g[CHUNK], b[CHUNK];
  for (int j = 0; j < m; j++) { /* the row, from the marginal */
    const int i = (int)d.guide_marg[fr_dist2d_slot(h, u2[j])];
    y[j] = fr_dist2d_step(d.cdf_marg, 0, h, fr_dist2d_step(d.cdf_marg, 0, h, i, u2[j]), u2[j]);
  }
  for (int j = 0; j < m; j++) {
    y[j] = fr_dist2d_walk(d.cdf_marg, h, y[j], u2[j]);
    __builtin_prefetch(d.guide_row + y[j] * w + fr_dist2d_slot(w, u1[j]));
  }
  for (int j = 0; j < m; j++) { /* the column, from the row's conditional */
    x[j] = (int)d.guide_row[y[j] * w + fr_dist2d_slot(w, u1[j])];
  }
  for (int j = 0; j < m; j++) { /* the guide's entry's cumulative sum and texel fetched */
    __builtin_prefetch(d.cdf_row + y[j] * row + x[j] + 1);
    __builtin_prefetch(e.texels + 4 * (y[j] * w + x[j]));
  }
  for (int j = 0; j < m; j++) {
    const int at = y[j] * row;
    x[j] = fr_dist2d_step(d.cdf_row, at, w, fr_dist2d_step(d.cdf_row, at, w, x[j], u1[j]), u1[j]);
  }
  for (int j = 0; j < m; j++) x[j] = fr_dist2d_walk(d.cdf_row + y[j] * row, w, x[j], u1[j]);
  for (int j = 0; j < m; j++) { /* the point in the cell */
    const int at = y[j] * row + x[j];
    fr_dist2d_cell_point_of(w, h, x[j], y[j], d.cdf_row[at], d.cdf_row[at + 1], d.cdf_marg[y[j]], d.cdf_marg[y[j] + 1],
                            u1[j], u2[j], &u[j], &v[j]);
  }
  for (int j = 0; j < m; j++) { /* its direction and density */
    const int t = 4 * (y[j] * w + x[j]);
    float dd[3];
    const int some = fr_env_sample_dir(&e, u[j], v[j], e.texels[t + 3], dd, &pdf[j]);
    dx[j] = some ? dd[0] : 0.0f, dy[j] = some ? dd[1] : 0.0f, dz[j] = some ? dd[2] : 0.0f;
    const float k = some ? e.intensity : 0.0f;
    r[j] = e.texels[t] * k, g[j] = e.texels[t + 1] * k, b[j] = e.texels[t + 2] * k;
  }
  for (int j = 0; j < m; j++) dir[j] = v3(dx[j], dy[j], dz[j]), le[j] = v3(r[j], g[j], b[j]);
}

void FR_ISA_FN(fr_env_sample_batch)(const fr_env *e, size_t n, const float *u1, const float *u2, vec3 *dir, vec3 *le,
                                    float *pdf) {
  for (size_t a = 0; a < n; a += CHUNK)
    sample_chunk(e, (int)(n - a < CHUNK ? n - a : CHUNK), u1 + a, u2 + a, dir + a, le + a, pdf + a);
}

void FR_ISA_FN(fr_env_texel_batch)(const fr_env *env, size_t n, const float *restrict x, const float *restrict y,
                                   const float *restrict z, int *restrict texel, float *restrict sin_t) {
  const fr_env e = *env;
  for (size_t j = 0; j < n; j++) {
    float u, v;
    fr_env_to_uv(&e, x[j], y[j], z[j], &u, &v, &sin_t[j]);
    texel[j] = fr_env_texel_index(&e, u, v);
  }
}

void FR_ISA_FN(fr_env_smooth_at_batch)(const fr_env *env, size_t n, const float *restrict x, const float *restrict y,
                                       const float *restrict z, float *restrict fx, float *restrict fy) {
  const fr_env e = *env;
  for (size_t j = 0; j < n; j++) fr_env_smooth_at(&e, x[j], y[j], z[j], &fx[j], &fy[j]);
}
