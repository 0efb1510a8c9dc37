/* Random test scenes of mixed triangle kinds and random rays of mixed kinds,
 * shared by the traversal and packet tests. */
#ifndef FR_TEST_RANDOM_SCENE_H
#define FR_TEST_RANDOM_SCENE_H
#include <stdlib.h>
#include "test_util.h"

typedef struct scene_data { float *pos; uint32_t *idx; size_t nv, nt; } scene_data;

static inline void add_tri(scene_data *s, vec3 a, vec3 b, vec3 c) {
  vec3 p[3] = {a, b, c};
  for (int k = 0; k < 3; k++) {
    s->pos[3 * s->nv] = p[k].x; s->pos[3 * s->nv + 1] = p[k].y; s->pos[3 * s->nv + 2] = p[k].z;
    s->idx[3 * s->nt + k] = (uint32_t)s->nv++;
  }
  s->nt++;
}

/* Random triangles of mixed kinds around `center` with extent `size`. */
static inline scene_data make_scene(fr_rng *r, size_t n, vec3 center, float size) {
  scene_data s = {malloc(n * 9 * sizeof(float)), malloc(n * 3 * sizeof(uint32_t)), 0, 0};
  for (size_t i = 0; i < n; i++) {
    vec3 a = v3_add(center, v3(urand(r, -size, size), urand(r, -size, size), urand(r, -size, size)));
    float e = size * 0.1f;
    vec3 b = v3_add(a, v3(urand(r, -e, e), urand(r, -e, e), urand(r, -e, e)));
    vec3 c = v3_add(a, v3(urand(r, -e, e), urand(r, -e, e), urand(r, -e, e)));
    switch (i % 6) {
    case 0: b.z = a.z; c.z = a.z; break;                                  /* axis-aligned */
    case 1: a.y = center.y; b.y = center.y; c.y = center.y; break;         /* coplanar set */
    case 2: c = v3_add(a, v3_scale(v3_sub(b, a), 0.5f)); c.x += e * 1e-4f; break; /* sliver */
    case 3: if (i % 12 == 3) c = b; break;                                /* some degenerate */
    default: break;
    }
    add_tri(&s, a, b, c);
  }
  return s;
}

/* *src gets the triangle a ray starts on (kind 1), else FR_INVALID_ID. */
static inline fr_ray random_ray(fr_rng *r, vec3 center, float size, const scene_data *s, int kind, uint32_t *src) {
  *src = FR_INVALID_ID;
  vec3 o = v3_add(center, v3(urand(r, -2 * size, 2 * size), urand(r, -2 * size, 2 * size), urand(r, -2 * size, 2 * size)));
  vec3 target = v3_add(center, v3(urand(r, -size, size), urand(r, -size, size), urand(r, -size, size)));
  float tnear = 0.0f;
  if (kind == 1) { /* start on a surface */
    size_t t = fr_rng_u32(r) % s->nt;
    *src = (uint32_t)t;
    float u = fr_rng_float(r) * 0.5f, v = fr_rng_float(r) * 0.5f;
    vec3 a = v3_load(s->pos + 3 * s->idx[3 * t]), b = v3_load(s->pos + 3 * s->idx[3 * t + 1]), c = v3_load(s->pos + 3 * s->idx[3 * t + 2]);
    o = v3_add(a, v3_add(v3_scale(v3_sub(b, a), u), v3_scale(v3_sub(c, a), v)));
    tnear = 1e-4f * size;
  } else if (kind == 2) { /* along an edge */
    size_t t = fr_rng_u32(r) % s->nt;
    vec3 a = v3_load(s->pos + 3 * s->idx[3 * t]), b = v3_load(s->pos + 3 * s->idx[3 * t + 1]);
    o = v3_sub(a, v3_sub(b, a));
    target = b;
  } else if (kind == 3) { /* axis-parallel direction */
    target = o;
    int ax = (int)(fr_rng_u32(r) % 3);
    if (ax == 0) target.x = center.x; else if (ax == 1) target.y = center.y; else target.z = center.z;
    if (target.x == o.x && target.y == o.y && target.z == o.z) target.x += 1.0f;
  }
  vec3 d = v3_sub(target, o);
  if (fr_rng_u32(r) & 1) d = v3_norm(d);
  fr_ray ray = {{o.x, o.y, o.z}, tnear, {d.x, d.y, d.z}, (fr_rng_u32(r) % 4 == 0) ? urand(r, 0.2f, 1.0f) : INFINITY};
  return ray;
}


static inline void free_scene(scene_data *s) { free(s->pos); free(s->idx); }

/* The scene of sd, committed. */
/* The scene of sd, committed or (commit 0) left open for more (spheres). */
static inline fr_scene *commit_scene_with(const scene_data *sd, int commit) {
  fr_scene *s;
  assert_int_equal(fr_scene_from_arrays(sd->pos, sd->nv, sd->idx, sd->nt, &s), FR_OK);
  if (commit && fr_scene_commit(s) != FR_OK) fail_msg("commit: %s", fr_last_error());
  return s;
}
static inline fr_scene *commit_scene(const scene_data *sd) { return commit_scene_with(sd, 1); }
#endif
