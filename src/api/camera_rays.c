/* fr_intersect_camera: a pinhole camera's rays traced as multi-frusta
 * (trace/mft): 16 frusta of 4x4 pixels per 16x16 tile, made on demand from
 * the camera, never stored as rays; the pixels of 4x4 blocks the image cuts
 * off go as single rays. */
#include <string.h>
#include "base/error.h"
#include "render/camera.h"
#include "render/mft_rays.h"
#include "scene.h"
#include "trace/kernels.h"

/* Neighbouring pixels mostly hit one triangle: *last keeps the previous
 * hit's normal. */
static void set_normal(const fr_scene *s, fr_hit *h, fr_hit *last) {
  if (h->prim == FR_INVALID_ID) { h->ng[0] = h->ng[1] = h->ng[2] = 0.0f; return; }
  if (h->prim == last->prim) { memcpy(h->ng, last->ng, sizeof h->ng); return; }
  fr_scene_triangle_normal(s, h->prim, h->ng);
  *last = *h;
}

fr_error fr_intersect_camera(const fr_scene *s, const fr_pinhole *p, int y0, int rows, unsigned flags, fr_ray *rays,
                             fr_hit *hits) {
  if (!s || !p || !hits) return fr_fail(FR_ERR_ARG, "fr_intersect_camera: NULL scene, camera or hits");
  if (!s->committed) return fr_fail(FR_ERR_STATE, "fr_intersect_camera: the scene is not committed");
  if (s->sphere_bvh.nprims) return fr_fail(FR_ERR_UNSUPPORTED, "fr_intersect_camera: scenes with spheres are not supported");
  fr_camera cam;
  fr_error e = fr_camera_setup(&cam, v3_load(p->eye), v3_load(p->at), v3_load(p->up), p->fov_deg, p->width, p->height);
  if (e != FR_OK) return e;
  if (flags & ~(unsigned)FR_CAMERA_NO_NORMALS) return fr_fail(FR_ERR_ARG, "fr_intersect_camera: unknown flags 0x%x", flags);
  const int normals = !(flags & FR_CAMERA_NO_NORMALS);
  if (y0 < 0 || rows < 0 || rows > p->height - y0)
    return fr_fail(FR_ERR_ARG, "fr_intersect_camera: rows %d..%d are not in the image's %d", y0, y0 + rows, p->height);
  if (!s->bvh2.nprims) { /* nothing to hit */
    for (int y = y0; y < y0 + rows; y++)
      for (int x = 0; x < p->width; x++) {
        size_t i = (size_t)(y - y0) * (size_t)p->width + (size_t)x;
        fr_ray r = fr_camera_ray(&cam, x, y);
        if (rays) rays[i] = r;
        fr_hit_miss(&hits[i]);
      }
    return FR_OK;
  }
  fr_mft_sets sets;
  fr_mft_sets_camera(&sets, &cam);
  const fr_mft_fns *k = fr_mft_active();
  const fr_mft_opts opts = fr_mft_opts_default();
  const fr_bvh2 *tree = s->bvh2_mft.nprims ? &s->bvh2_mft : &s->bvh2;
  fr_mft_batch b;
  fr_mft_hits h;
  fr_ray r256[256], left[256];
  fr_hit h256[256], left_hit[256];
  size_t left_at[256];
  fr_hit last = {0.0f, 0.0f, 0.0f, FR_INVALID_ID, {0.0f, 0.0f, 0.0f}};
  for (int ty = y0; ty < y0 + rows; ty += 16)
    for (int tx = 0; tx < p->width; tx += 16) {
      fr_mft_batch_camera(&b, &cam, tx, ty);
      if (b.valid) {
        k->intersect(tree, &opts, &b, &sets, &h);
        k->expand(&b, &sets, &h, r256, h256);
      }
      int nleft = 0;
      for (int f = 0; f < 16; f++)
        for (int j = 0; j < 16; j++) {
          int x = tx + 4 * (f & 3) + (j & 3), y = ty + 4 * (f >> 2) + (j >> 2);
          if (x >= p->width || y >= y0 + rows) continue;
          size_t i = (size_t)(y - y0) * (size_t)p->width + (size_t)x;
          if (b.valid >> f & 1) {
            if (rays) rays[i] = r256[16 * f + j];
            hits[i] = h256[16 * f + j];
            if (normals) set_normal(s, &hits[i], &last);
          } else {
            left[nleft] = fr_camera_ray(&cam, x, y);
            left_at[nleft++] = i;
          }
        }
      if (!nleft) continue;
      fr_intersect_stream(s, left, left_hit, (size_t)nleft);
      for (int j = 0; j < nleft; j++) {
        if (rays) rays[left_at[j]] = left[j];
        hits[left_at[j]] = left_hit[j];
        if (!normals) memset(hits[left_at[j]].ng, 0, sizeof hits[left_at[j]].ng);
      }
    }
  return FR_OK;
}
