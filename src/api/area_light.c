/* fr_visibility_area_light: the soft-shadow tile driver (render/tile.h)
 * on the caller's points. Each run of up to 256 points goes through it as
 * one tile of "primary hits" at exactly those points (a ray of zero
 * direction hit at t = 0), point i taking sample set i % 16; the sets are
 * spread (each covers the whole light, stratified 4x4), so every point's
 * samples estimate its own visibility without the renderer's filter. */
#include <math.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"
#include "render/mft_rays.h"
#include "render/tile.h"
#include "render/tracer.h"
#include "scene.h"

static int finite3(const float *p) { return isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]); }

fr_error fr_visibility_area_light(const fr_scene *s, const float corner[3], const float e1[3], const float e2[3],
                                  const float *points, size_t n, int samples, uint64_t seed, float eps,
                                  float *visibility) {
  if (!s || !corner || !e1 || !e2 || (n && (!points || !visibility)))
    return fr_fail(FR_ERR_ARG, "fr_visibility_area_light: NULL scene, light or arrays");
  if (!s->committed) return fr_fail(FR_ERR_STATE, "fr_visibility_area_light: the scene is not committed");
  if (samples < 16 || samples > 4096 || samples % 16)
    return fr_fail(FR_ERR_ARG, "fr_visibility_area_light: samples %d is not a multiple of 16 in 16..4096", samples);
  if (!finite3(corner) || !finite3(e1) || !finite3(e2) || !(eps >= 0.0f) || !isfinite(eps))
    return fr_fail(FR_ERR_ARG, "fr_visibility_area_light: the light or eps is not finite");
  if (!n) return FR_OK;
  fr_tile_buffers *B = fr_alloc_aligned(sizeof *B, 64);
  fr_mft_sets *sets = fr_alloc_aligned(sizeof *sets, 64);
  if (!B || !sets) {
    fr_free_aligned(B);
    fr_free_aligned(sets);
    return fr_fail(FR_ERR_NOMEM, "out of memory");
  }
  fr_workload w;
  memset(&w, 0, sizeof w);
  w.scene = s;
  w.eps = eps;
  w.view.area_c = v3_load(corner), w.view.area_e1 = v3_load(e1), w.view.area_e2 = v3_load(e2);
  w.light_sets = sets;
  const fr_mft_tracer m = fr_mft_tracer_of(s, fr_mft_opts_default());
  const fr_tracer t = s->sphere_bvh.nprims ? fr_tracer_frusta(s) : fr_tracer_mft(&m);
  const int passes = samples / 16;
  float lit[TILE_PIX];
  for (size_t a = 0; a < n; a += TILE_PIX) {
    const int k = n - a < TILE_PIX ? (int)(n - a) : TILE_PIX;
    for (int i = 0; i < k; i++) {
      const float *p = points + 3 * (a + (size_t)i);
      fr_ray *r = &B->prim_ray[i];
      memcpy(r->org, p, sizeof r->org);
      r->dir[0] = r->dir[1] = r->dir[2] = 0.0f;
      r->tnear = 0.0f, r->tfar = 0.0f;
      B->prim_hit[i] = (fr_hit){0.0f, 0.0f, 0.0f, finite3(p) ? 0u : FR_INVALID_ID, {0.0f, 0.0f, 0.0f}};
      B->px[i] = i & 3, B->py[i] = (i >> 2) & 3;
      visibility[a + (size_t)i] = 0.0f;
    }
    for (int pass = 0; pass < passes; pass++) {
      fr_mft_sets_light(sets, e1, e2, seed + (uint64_t)pass, FR_LIGHT_SETS_SPREAD);
      for (int i = 0; i < k; i++) lit[i] = 0.0f;
      fr_tile_soft_shadows(&w, &t, B, k, lit);
      for (int i = 0; i < k; i++) visibility[a + (size_t)i] += lit[i];
    }
    for (int i = 0; i < k; i++) visibility[a + (size_t)i] /= (float)passes;
  }
  fr_free_aligned(B);
  fr_free_aligned(sets);
  return FR_OK;
}
