/* Helpers shared by the tests: random numbers, scenes, a brute-force
 * double-precision oracle. */
#ifndef FR_TEST_UTIL_H
#define FR_TEST_UTIL_H
#include <dirent.h>
#include <math.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include "base/rng.h"
#include "base/vec3.h"
#include "frusta.h"
#include "api/scene.h"
#include "render/views.h"
#include "render/workload.h"

/* Under the sanitizers (several times slower) the slowest tests check
 * fewer random cases and smaller images: FR_TEST_ROUNDS(n) of them. */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define FR_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define FR_TEST_SANITIZED 1
#endif
#endif
#ifndef FR_TEST_SANITIZED
#define FR_TEST_SANITIZED 0
#endif
#define FR_TEST_ROUNDS(n) (FR_TEST_SANITIZED ? ((n) + 3) / 4 : (n))

static inline float urand(fr_rng *r, float lo, float hi) { return lo + (hi - lo) * fr_rng_float(r); }

/* Closest hit by testing every triangle in double precision (Möller–Trumbore).
 * Returns t (INFINITY for a miss) and the triangle's distance to the nearest
 * edge in barycentric units, so callers can skip rays too close to an edge for
 * float and double to be expected to agree. */
static inline double brute_force(const float *pos, const uint32_t *idx, size_t ntris, const fr_ray *r,
                                 uint32_t *prim, double *edge_margin, int skip_degenerate) {
  double best = INFINITY;
  *prim = FR_INVALID_ID;
  *edge_margin = 1.0;
  double o[3] = {r->org[0], r->org[1], r->org[2]}, d[3] = {r->dir[0], r->dir[1], r->dir[2]};
  for (size_t t = 0; t < ntris; t++) {
    const float *a = pos + 3 * (size_t)idx[3 * t], *b = pos + 3 * (size_t)idx[3 * t + 1], *c = pos + 3 * (size_t)idx[3 * t + 2];
    double e1[3], e2[3], s[3];
    for (int k = 0; k < 3; k++) { e1[k] = (double)b[k] - a[k]; e2[k] = (double)c[k] - a[k]; s[k] = o[k] - a[k]; }
    double p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
    double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    double nx = e1[1] * e2[2] - e1[2] * e2[1], ny = e1[2] * e2[0] - e1[0] * e2[2], nz = e1[0] * e2[1] - e1[1] * e2[0];
    if (skip_degenerate && nx == 0 && ny == 0 && nz == 0) continue;
    double nl = sqrt(nx * nx + ny * ny + nz * nz), dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (fabs(det) <= 1e-6 * nl * dl) {
      /* ray (nearly) parallel to the plane: if it lies in the plane, any answer is right */
      double sl = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
      if (fabs(s[0] * nx + s[1] * ny + s[2] * nz) <= 1e-5 * nl * (sl + 1e-30)) *edge_margin = 0.0;
      continue;
    }
    double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
    double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
    double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
    double tt = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    double m = fmin(fmin(u, v), 1.0 - u - v);
    if (m < -1e-3 || !(tt > r->tnear && tt < r->tfar)) continue;
    /* near misses count as "close to an edge" too */
    if (tt < best) {
      if (m >= 0.0) { best = tt; *prim = (uint32_t)t; }
    }
    if (fabs(m) < *edge_margin && (m >= 0.0 || m > -1e-3)) *edge_margin = fabs(m);
  }
  return best;
}
typedef struct mesh_ref { const float *pos; const uint32_t *idx; size_t nt; } mesh_ref;

static inline mesh_ref scene_mesh(const fr_scene *s) {
  mesh_ref m = {fr_scene_vertices(s), fr_scene_indices(s), fr_scene_triangle_count(s)};
  return m;
}

/* The committed scene at path and a workload on it from the scene's own
 * view at size x size (eps as workloads.md sets it); the caller releases
 * the scene. */
static inline fr_scene *shared_workload(const char *path, int size, fr_workload *w) {
  fr_scene *s;
  if (fr_scene_load(path, &s) != FR_OK) fail_msg("%s: %s", path, fr_last_error());
  assert_int_equal(fr_scene_commit(s), FR_OK);
  memset(w, 0, sizeof *w);
  w->scene = s;
  assert_true(fr_view_lookup(s->name, &w->view));
  assert_int_equal(fr_camera_setup(&w->cam, w->view.eye, w->view.at, w->view.up, w->view.fov, size, size), FR_OK);
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  w->eps = 1e-4f * v3_len(v3_sub(v3_load(hi), v3_load(lo)));
  return s;
}

/* A random point of a random triangle of m. */
static inline vec3 random_surface_point(fr_rng *r, const mesh_ref *m) {
  uint32_t t = fr_rng_u32(r) % (uint32_t)m->nt;
  vec3 a = v3_load(m->pos + 3 * m->idx[3 * t]), b = v3_load(m->pos + 3 * m->idx[3 * t + 1]),
       c = v3_load(m->pos + 3 * m->idx[3 * t + 2]);
  float u = fr_rng_float(r) * 0.5f, v = fr_rng_float(r) * 0.5f;
  return v3_add(a, v3_add(v3_scale(v3_sub(b, a), u), v3_scale(v3_sub(c, a), v)));
}

/* 1 if a disagreement on this ray is excusable: its nearest hit (in double
 * precision, over a range widened by the tolerance) is within rounding of an
 * edge, or within 1e-4 max(1, |t|) of tnear or tfar. */
static inline int ambiguous(const mesh_ref *m, const fr_ray *r) {
  uint32_t prim;
  double margin;
  fr_ray wide = *r;
  wide.tnear = r->tnear - 1e-4f * fmaxf(1.0f, fabsf(r->tnear));
  wide.tfar = r->tfar + 1e-4f * fmaxf(1.0f, fabsf(r->tfar));
  double t = brute_force(m->pos, m->idx, m->nt, &wide, &prim, &margin, 1);
  if (margin < 1e-4) return 1;
  if (t < INFINITY && (fabs(t - r->tnear) <= 1e-4 * fmax(1.0, fabs(t)) || fabs(t - r->tfar) <= 1e-4 * fmax(1.0, fabs(t))))
    return 1;
  return 0;
}

/* out = $FRUSTA_SHARED/scenes/rel (../shared without it). */
static inline void shared_scene_path(char *out, size_t cap, const char *rel) {
  const char *root = getenv("FRUSTA_SHARED");
  snprintf(out, cap, "%s/scenes%s%s", root ? root : "../shared", *rel ? "/" : "", rel);
}

/* Calls fn with the path of every .ply.zst of ../shared/scenes (or
 * $FRUSTA_SHARED/scenes); returns how many. A missing folder fails the test. */
static inline int for_each_shared_scene(void (*fn)(const char *path, void *ctx), void *ctx) {
  char dir[1024];
  shared_scene_path(dir, sizeof dir, "");
  DIR *d = opendir(dir);
  if (!d) fail_msg("cannot open %s: the shared scenes must sit beside the repository", dir);
  int count = 0;
  struct dirent *ent;
  while ((ent = readdir(d))) {
    if (ent->d_name[0] == '.') continue;
    char sub[1400];
    snprintf(sub, sizeof sub, "%s/%s", dir, ent->d_name);
    DIR *sd = opendir(sub);
    if (!sd) continue;
    struct dirent *f;
    while ((f = readdir(sd)))
      if (strstr(f->d_name, ".ply.zst")) {
        char path[2000];
        snprintf(path, sizeof path, "%s/%s", sub, f->d_name);
        fn(path, ctx);
        count++;
      }
    closedir(sd);
  }
  closedir(d);
  return count;
}

/* A closed, consistently wound, star-shaped solid around c, committed: a
 * lat-long grid of st rings of sl vertices, radii jittered by 0.8..1.2,
 * one vertex per pole. *pos_out (the caller frees it) gets the vertices. */
static inline fr_scene *closed_latlong_sphere(fr_rng *r, vec3 c, float radius, int st, int sl, float **pos_out,
                                              size_t *nv_out) {
  const size_t ST = (size_t)st, SL = (size_t)sl;
  size_t nv = 2 + (ST - 1) * SL, nt = 2 * SL + 2 * SL * (ST - 2), v = 0, t = 0;
  float *pos = malloc(nv * 3 * sizeof(float));
  uint32_t *idx = malloc(nt * 3 * sizeof(uint32_t));
#define PUT(x, y, z) (pos[3 * v] = (x), pos[3 * v + 1] = (y), pos[3 * v + 2] = (z), v++)
  PUT(c.x, c.y + radius, c.z);
  for (size_t i = 1; i < ST; i++)
    for (size_t j = 0; j < SL; j++) {
      float th = (float)M_PI * (float)i / (float)ST, ph = 2.0f * (float)M_PI * (float)j / (float)SL;
      float rr = radius * urand(r, 0.8f, 1.2f);
      PUT(c.x + rr * sinf(th) * cosf(ph), c.y + rr * cosf(th), c.z + rr * sinf(th) * sinf(ph));
    }
  PUT(c.x, c.y - radius, c.z);
#define RING(i, j) (uint32_t)(1 + ((i) - 1) * SL + ((j) % SL))
#define TRI(a, b, cc) (idx[3 * t] = (a), idx[3 * t + 1] = (b), idx[3 * t + 2] = (cc), t++)
  for (size_t j = 0; j < SL; j++) TRI(0, RING(1, j + 1), RING(1, j));
  for (size_t i = 1; i < ST - 1; i++)
    for (size_t j = 0; j < SL; j++) {
      TRI(RING(i, j), RING(i, j + 1), RING(i + 1, j + 1));
      TRI(RING(i, j), RING(i + 1, j + 1), RING(i + 1, j));
    }
  for (size_t j = 0; j < SL; j++) TRI((uint32_t)(nv - 1), RING(ST - 1, j), RING(ST - 1, j + 1));
#undef PUT
#undef RING
#undef TRI
  fr_scene *s;
  assert_int_equal(fr_scene_from_arrays(pos, nv, idx, nt, &s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  free(idx);
  *pos_out = pos;
  *nv_out = nv;
  return s;
}

/* Zero-area test on raw arrays, as the library's (double precision). */
static inline int fr_mesh_degenerate_prim(const float *pos, const uint32_t *idx, uint32_t t) {
  const float *a = pos + 3 * (size_t)idx[3 * t], *b = pos + 3 * (size_t)idx[3 * t + 1], *c = pos + 3 * (size_t)idx[3 * t + 2];
  double e1[3], e2[3];
  for (int k = 0; k < 3; k++) { e1[k] = (double)b[k] - a[k]; e2[k] = (double)c[k] - a[k]; }
  return e1[1] * e2[2] - e1[2] * e2[1] == 0 && e1[2] * e2[0] - e1[0] * e2[2] == 0 && e1[0] * e2[1] - e1[1] * e2[0] == 0;
}
#endif
