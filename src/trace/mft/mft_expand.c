/*
 * A batch of frusta back into rays: ray k of frustum f becomes rays[16 f + k]
 * with a unit direction, and its hit hits[16 f + k] with t in units of that
 * direction (the form every other tracer answers in), for renderers that go
 * on from camera frusta ray by ray. A frustum at a time: its 16 directions
 * are normalized in one register each per axis, and rays and hits are
 * written as whole records (base/simd_packet.h): ray by ray, with a store
 * per float, this step took a sixth of sibenik's primary-ray time, and
 * records made the whole workload 24% faster.
 *
 * fr_mft_expand_arrays writes the same answers as arrays instead, rows of
 * 4 pixels at a time into a tile of them (fr_intersect_camera_arrays),
 * without records in between.
 *
 * Compiled once per ISA; every level gives the same bits (sqrt and division
 * are correctly rounded, and the operations are those of the scalar loop in
 * the tests).
 */
#include <math.h>
#include <string.h>
#include "base/simd.h"
#include "base/simd_packet.h"
#include "trace/mft/mft.h"

_Static_assert(FR_PACKET == FR_MFT_RAYS, "one lane per ray of a frustum");
_Static_assert(sizeof(fr_ray) == 8 * sizeof(float) && sizeof(fr_hit) == 7 * sizeof(float), "records of 8 and 7 floats");

/* Frustum f's 16 directions d (start + delta, as the kernels traced them)
 * and their lengths; returns its hits' t in units of the unit directions
 * (+inf on a miss). */
FR_INLINE vpf frustum_t(const fr_mft_batch *b, const fr_mft_sets *sets, const fr_mft_hits *h, int f, vpf d[3],
                        vpf *len) {
  const fr_mft_set *s = &sets->set[b->set[f]];
  const float *dl[3] = {s->dx, s->dy, s->dz};
  for (int a = 0; a < 3; a++) d[a] = vp_add(vp(b->start[a][f]), vp_load(dl[a]));
  *len = vp_sqrt(vp_add(vp_add(vp_mul(d[0], d[0]), vp_mul(d[1], d[1])), vp_mul(d[2], d[2])));
  unsigned miss = 0;
  for (int k = 0; k < FR_MFT_RAYS; k++) miss |= (unsigned)(h->prim[f][k] == FR_INVALID_ID) << k;
  return vp_select(vpm_bits_to(miss), vp(INFINITY), vp_mul(vp_load(h->t[f]), *len));
}

void FR_ISA_FN(fr_mft_expand)(const fr_mft_batch *b, const fr_mft_sets *sets, const fr_mft_hits *h, fr_ray *rays,
                              fr_hit *hits) {
  const vpf zero = vp(0.0f), inf = vp(INFINITY);
  for (int f = 0; f < FR_MFT_FRUSTA; f++) {
    vpf d[3], len;
    const vpf t = frustum_t(b, sets, h, f, d, &len);
    vpf ray[8] = {vp(b->org[0][f]), vp(b->org[1][f]), vp(b->org[2][f]), zero,
                  vp_div(d[0], len), vp_div(d[1], len), vp_div(d[2], len), inf};
    float prim[FR_MFT_RAYS] __attribute__((aligned(64))); /* ids as float bit patterns: copied, never cast */
    memcpy(prim, h->prim[f], sizeof prim);
    vpf hit[7] = {t, vp_load(h->u[f]), vp_load(h->v[f]), vp_load(prim), zero, zero, zero};
    vp_store_records((float *)(rays + FR_MFT_RAYS * f), ray, 8);
    vp_store_records((float *)(hits + FR_MFT_RAYS * f), hit, 7);
  }
}

void FR_ISA_FN(fr_mft_expand_arrays)(const fr_mft_batch *b, const fr_mft_sets *sets, const fr_mft_hits *h,
                                     const fr_hit_arrays *out, size_t at, size_t width, int rows) {
  for (unsigned todo = b->valid; todo; todo &= todo - 1) {
    const int f = __builtin_ctz(todo);
    vpf d[3], len;
    float t[FR_MFT_RAYS] __attribute__((aligned(64))), dir[3][FR_MFT_RAYS] __attribute__((aligned(64)));
    vp_store(t, frustum_t(b, sets, h, f, d, &len));
    if (out->dir)
      for (int a = 0; a < 3; a++) vp_store(dir[a], vp_div(d[a], len));
    /* ray k is pixel (k & 3, k >> 2) of the frustum's 4x4 block */
    const int top = 4 * (f >> 2), last = rows - top < 4 ? rows - top : 4;
    for (int r = 0; r < last; r++) {
      const size_t e = at + (size_t)(top + r) * width + (size_t)(4 * (f & 3));
      const int k = 4 * r;
      if (out->t) memcpy(out->t + e, t + k, 4 * sizeof(float));
      if (out->u) memcpy(out->u + e, h->u[f] + k, 4 * sizeof(float));
      if (out->v) memcpy(out->v + e, h->v[f] + k, 4 * sizeof(float));
      if (out->prim) memcpy(out->prim + e, h->prim[f] + k, 4 * sizeof(uint32_t));
      if (out->dir)
        for (int c = 0; c < 4; c++)
          for (int a = 0; a < 3; a++) out->dir[3 * (e + (size_t)c) + (size_t)a] = dir[a][k + c];
    }
  }
}
