/* fr_intersect_camera and fr_intersect_camera_arrays: a pinhole camera's
 * rays traced as multi-frusta (trace/mft): 16 frusta of 4x4 pixels per
 * 16x16 tile, made on demand from the camera, never stored as rays; the
 * pixels of 4x4 blocks the image cuts off go as single rays. The two calls
 * differ only in where the answers go: records, or arrays, through a tile
 * of them copied out a whole row at a time. */
#include <string.h>
#include "base/error.h"
#include "render/camera.h"
#include "render/mft_rays.h"
#include "scene.h"
#include "trace/kernels.h"

/* Where a call's answers go: records, or (hits NULL) arrays. */
typedef struct camera_out {
  fr_ray *rays;              /* records, may be NULL */
  fr_hit *hits;
  const fr_hit_arrays *arr;  /* arrays, when hits is NULL */
  int normals;
} camera_out;

/* The normal of triangle prim into ng (zero for none). Neighbouring pixels
 * mostly hit one triangle: *last keeps the previous one. */
static void normal_of(const fr_scene *s, uint32_t prim, float ng[3], fr_hit *last) {
  if (prim == FR_INVALID_ID) { ng[0] = ng[1] = ng[2] = 0.0f; return; }
  if (prim != last->prim) {
    fr_scene_triangle_normal(s, prim, last->ng);
    last->prim = prim;
  }
  memcpy(ng, last->ng, 3 * sizeof(float));
}

/* Pixel i's answer from a single ray: r, and h with its normal. */
static void put_single(const camera_out *o, size_t i, const fr_ray *r, const fr_hit *h) {
  if (o->hits) {
    if (o->rays) o->rays[i] = *r;
    o->hits[i] = *h;
    if (!o->normals) memset(o->hits[i].ng, 0, sizeof o->hits[i].ng);
    return;
  }
  const fr_hit_arrays *a = o->arr;
  if (a->t) a->t[i] = h->t;
  if (a->u) a->u[i] = h->u;
  if (a->v) a->v[i] = h->v;
  if (a->prim) a->prim[i] = h->prim;
  if (a->ng) memcpy(a->ng + 3 * i, h->ng, sizeof h->ng);
  if (a->dir) memcpy(a->dir + 3 * i, r->dir, sizeof r->dir);
}

/* The first min(n, 16) of a tile row's 4-byte elements (floats or ids): a
 * whole row as one fixed-size copy, because a copy of a variable size
 * compiles to `rep movs`, slow at this size. */
static void copy_row(void *to, const void *from, int n) {
  if (n >= 16)
    memcpy(to, from, 16 * 4);
  else if (n > 0)
    memcpy(to, from, (size_t)n * 4);
}

static fr_error trace_camera(const char *fn, const fr_scene *s, const fr_pinhole *p, int y0, int rows,
                             const camera_out *o) {
  if (!s->committed) return fr_fail(FR_ERR_STATE, "%s: the scene is not committed", fn);
  if (s->sphere_bvh.nprims) return fr_fail(FR_ERR_UNSUPPORTED, "%s: scenes with spheres are not supported", fn);
  fr_camera cam;
  fr_error e = fr_camera_setup(&cam, v3_load(p->eye), v3_load(p->at), v3_load(p->up), p->fov_deg, p->width, p->height);
  if (e != FR_OK) return e;
  if (y0 < 0 || rows < 0 || rows > p->height - y0)
    return fr_fail(FR_ERR_ARG, "%s: rows %d..%d are not in the image's %d", fn, y0, y0 + rows, p->height);
  const size_t width = (size_t)p->width;
  if (!s->bvh2.nprims) { /* nothing to hit */
    fr_hit miss;
    fr_hit_miss(&miss);
    for (int y = y0; y < y0 + rows; y++)
      for (int x = 0; x < p->width; x++) {
        fr_ray r = fr_camera_ray(&cam, x, y);
        put_single(o, (size_t)(y - y0) * width + (size_t)x, &r, &miss);
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
  /* Arrays go through a tile of them, 16 elements a row, and out a row at
   * a time: the user's rows lie a page apart, and written 4 pixels at a
   * time straight into them, a tile's 64 or more lines thrashed the cache. */
  struct {
    float t[256], u[256], v[256], ng[768], dir[768];
    uint32_t prim[256];
  } tile;
  const fr_hit_arrays *a = o->arr;
  const fr_hit_arrays ta = {a && a->t ? tile.t : NULL, a && a->u ? tile.u : NULL, a && a->v ? tile.v : NULL,
                            a && a->prim ? tile.prim : NULL, a && a->ng ? tile.ng : NULL,
                            a && a->dir ? tile.dir : NULL};
  const camera_out to = o->hits ? *o : (camera_out){NULL, NULL, &ta, o->normals};
  for (int ty = y0; ty < y0 + rows; ty += 16)
    for (int tx = 0; tx < p->width; tx += 16) {
      /* pixel (x, y) is element base + (y - ty) * stride + x - tx of to */
      const size_t base = o->hits ? (size_t)(ty - y0) * width + (size_t)tx : 0, stride = o->hits ? width : 16;
      const int tile_rows = y0 + rows - ty < 16 ? y0 + rows - ty : 16, cols = p->width - tx < 16 ? p->width - tx : 16;
      fr_mft_batch_camera(&b, &cam, tx, ty);
      if (b.valid) {
        k->intersect(tree, &opts, &b, &sets, &h);
        if (o->hits)
          k->expand(&b, &sets, &h, r256, h256);
        else
          k->expand_arrays(&b, &sets, &h, &ta, 0, 16, tile_rows);
      }
      /* records and normals pixel by pixel; the frusta's arrays are written */
      const unsigned by_pixel = o->normals || o->hits ? 0xffffu : 0xffffu & ~b.valid;
      int nleft = 0;
      for (unsigned todo = by_pixel; todo; todo &= todo - 1) {
        const int f = __builtin_ctz(todo);
        for (int j = 0; j < 16; j++) {
          int x = 4 * (f & 3) + (j & 3), y = 4 * (f >> 2) + (j >> 2);
          if (x >= cols || y >= tile_rows) continue;
          size_t i = base + (size_t)y * stride + (size_t)x;
          if (!(b.valid >> f & 1)) {
            left[nleft] = fr_camera_ray(&cam, tx + x, ty + y);
            left_at[nleft++] = i;
          } else if (o->hits) {
            if (o->rays) o->rays[i] = r256[16 * f + j];
            o->hits[i] = h256[16 * f + j];
            if (o->normals) normal_of(s, o->hits[i].prim, o->hits[i].ng, &last);
          } else {
            normal_of(s, h.prim[f][j], tile.ng + 3 * i, &last);
          }
        }
      }
      if (nleft) {
        fr_intersect_stream(s, left, left_hit, (size_t)nleft);
        for (int j = 0; j < nleft; j++) put_single(&to, left_at[j], &left[j], &left_hit[j]);
      }
      if (o->hits) continue;
      for (int y = 0; y < tile_rows; y++) {
        const size_t at = (size_t)(ty - y0 + y) * width + (size_t)tx, from = 16 * (size_t)y;
        if (a->t) copy_row(a->t + at, tile.t + from, cols);
        if (a->u) copy_row(a->u + at, tile.u + from, cols);
        if (a->v) copy_row(a->v + at, tile.v + from, cols);
        if (a->prim) copy_row(a->prim + at, tile.prim + from, cols);
        for (int c = 0; c < 3; c++) {
          if (a->ng) copy_row(a->ng + 3 * at + 16 * c, tile.ng + 3 * from + 16 * c, 3 * cols - 16 * c);
          if (a->dir) copy_row(a->dir + 3 * at + 16 * c, tile.dir + 3 * from + 16 * c, 3 * cols - 16 * c);
        }
      }
    }
  return FR_OK;
}

fr_error fr_intersect_camera(const fr_scene *s, const fr_pinhole *p, int y0, int rows, unsigned flags, fr_ray *rays,
                             fr_hit *hits) {
  if (!s || !p || !hits) return fr_fail(FR_ERR_ARG, "fr_intersect_camera: NULL scene, camera or hits");
  if (flags & ~(unsigned)FR_CAMERA_NO_NORMALS) return fr_fail(FR_ERR_ARG, "fr_intersect_camera: unknown flags 0x%x", flags);
  const camera_out o = {rays, hits, NULL, !(flags & FR_CAMERA_NO_NORMALS)};
  return trace_camera("fr_intersect_camera", s, p, y0, rows, &o);
}

fr_error fr_intersect_camera_arrays(const fr_scene *s, const fr_pinhole *p, int y0, int rows, const fr_hit_arrays *out) {
  if (!s || !p || !out) return fr_fail(FR_ERR_ARG, "fr_intersect_camera_arrays: NULL scene, camera or out");
  const camera_out o = {NULL, NULL, out, out->ng != NULL};
  return trace_camera("fr_intersect_camera_arrays", s, p, y0, rows, &o);
}
