#include "all_hits.h"
#include <math.h>
#include <stdlib.h>
#include "base/error.h"
#include "geom/tri_watertight.h"
#include "trace/bvh2_reference.h"

/* A vertex in the ray's sheared frame (as fr_tri_watertight places it). */
typedef struct projected { float x, y, z; } projected;

static projected project(const fr_wt_ray *w, const float o[3], const float p[3]) {
  const float a[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
  projected q = {a[w->kx] - w->sx * a[w->kz], a[w->ky] - w->sy * a[w->kz], a[w->kz]};
  return q;
}

/* The edge value qx*py - qy*px of the edge p -> q at the ray (the origin of
 * the frame), exact in sign: float products are exact in double and one
 * rounded difference keeps the sign. Where it is zero, the sign at the
 * point moved by (eps, eps^2): that of its gradient's first non-zero
 * component, (qy - py, px - qx). */
static double edge_value(projected p, projected q, int *sign) {
  double e = (double)q.x * p.y - (double)q.y * p.x;
  if (e != 0.0) *sign = e > 0.0 ? 1 : -1;
  else if (q.y != p.y) *sign = q.y > p.y ? 1 : -1;
  else *sign = p.x > q.x ? 1 : (p.x < q.x ? -1 : 0);
  return e;
}

static int crossing(const fr_ray *ray, const fr_wt_ray *w, const float p0[3], const float p1[3], const float p2[3],
                    float *t, float *u, float *v) {
  projected a = project(w, ray->org, p0), b = project(w, ray->org, p1), c = project(w, ray->org, p2);
  int s0, s1, s2;
  double e0 = edge_value(b, c, &s0), e1 = edge_value(c, a, &s1), e2 = edge_value(a, b, &s2);
  if (s0 == 0 || s0 != s1 || s0 != s2) return 0;
  double det = e0 + e1 + e2;
  if (det == 0.0) return 0;
  float tt = fr_tri_plane_t(ray->org[0], ray->org[1], ray->org[2], ray->dir[0], ray->dir[1], ray->dir[2], p0[0], p0[1],
                            p0[2], p1[0], p1[1], p1[2], p2[0], p2[1], p2[2]);
  if (!(tt > ray->tnear && tt < ray->tfar)) return 0;
  *t = tt;
  *u = (float)(e1 / det);
  *v = (float)(e2 / det);
  return 1;
}

int fr_tri_crossing(const fr_ray *ray, const float p0[3], const float p1[3], const float p2[3], float *t, float *u,
                    float *v) {
  if (fr_ray_invalid(ray)) return 0;
  fr_wt_ray w = fr_wt_setup(v3_load(ray->dir));
  return crossing(ray, &w, p0, p1, p2, t, u, v);
}

static int push(fr_crossings *c, fr_crossing x) {
  if (c->n == c->cap) {
    size_t cap = c->cap ? 2 * c->cap : 64;
    fr_crossing *p = realloc(c->items, cap * sizeof *p);
    if (!p) return 0;
    c->items = p;
    c->cap = cap;
  }
  c->items[c->n++] = x;
  return 1;
}

static int by_t_then_prim(const void *pa, const void *pb) {
  const fr_crossing *a = pa, *b = pb;
  if (a->t != b->t) return a->t < b->t ? -1 : 1;
  return (a->prim > b->prim) - (a->prim < b->prim);
}

fr_error fr_bvh2_all_hits(const fr_bvh2 *b, const fr_mesh *m, const fr_ray *ray, fr_crossings *c) {
  c->n = 0;
  if (fr_ray_invalid(ray) || !b->nprims) return FR_OK;
  fr_wt_ray w = fr_wt_setup(v3_load(ray->dir));
  const float rd[3] = {fr_bvh2_rcp(ray->dir[0]), fr_bvh2_rcp(ray->dir[1]), fr_bvh2_rcp(ray->dir[2])};
  uint32_t stack[256]; /* the build's depth limit keeps a binary tree's stack far below this */
  int sp = 0;
  stack[sp++] = b->root;
  while (sp) {
    uint32_t ref = stack[--sp];
    if (ref & FR_BVH2_LEAF) {
      uint32_t first = FR_BVH2_LEAF_FIRST(ref), count = FR_BVH2_LEAF_COUNT(ref);
      for (uint32_t i = first; i < first + count; i++) {
        uint32_t prim = b->prims[i];
        const uint32_t *ix = m->idx + 3 * (size_t)prim;
        fr_crossing x = {0, 0, 0, prim};
        if (crossing(ray, &w, m->pos + 3 * (size_t)ix[0], m->pos + 3 * (size_t)ix[1], m->pos + 3 * (size_t)ix[2], &x.t,
                     &x.u, &x.v) &&
            !push(c, x))
          return fr_fail(FR_ERR_NOMEM, "fr_intersect_all: out of memory for %zu crossings", c->n);
      }
      continue;
    }
    const fr_bvh2_node *n = &b->nodes[ref];
    for (int k = 0; k < 2; k++)
      if (fr_bvh2_box_hit(n, k, ray->org, rd, ray->tnear, ray->tfar) && sp < 256) stack[sp++] = n->child[k];
  }
  /* A triangle split into several leaf references crosses at the same t
   * in each: after sorting, its copies are neighbours. */
  if (c->n > 1) qsort(c->items, c->n, sizeof *c->items, by_t_then_prim);
  size_t k = 0;
  for (size_t i = 0; i < c->n; i++)
    if (k == 0 || c->items[i].prim != c->items[k - 1].prim || c->items[i].t != c->items[k - 1].t)
      c->items[k++] = c->items[i];
  c->n = k;
  return FR_OK;
}

void fr_crossings_free(fr_crossings *c) {
  free(c->items);
  c->items = NULL;
  c->n = c->cap = 0;
}
