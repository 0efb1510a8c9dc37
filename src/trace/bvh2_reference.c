#include "bvh2_reference.h"
#include <math.h>
#include "geom/tri_watertight.h"
#include "trace/kernels.h"

static vec3 vertex(const fr_mesh *m, uint32_t prim, int k) { return v3_load(m->pos + 3 * (size_t)m->idx[3 * (size_t)prim + k]); }

/* Visits every leaf whose box the ray reaches; stops early when any_hit finds one. */
static int traverse(const fr_bvh2 *b, const fr_mesh *m, const fr_ray *ray, fr_hit *hit, int any_hit) {
  if (fr_ray_invalid(ray)) return 0;
  vec3 o = v3_load(ray->org), d = v3_load(ray->dir);
  const float rd[3] = {fr_bvh2_rcp(d.x), fr_bvh2_rcp(d.y), fr_bvh2_rcp(d.z)};
  fr_wt_ray w = fr_wt_setup(d);
  float tfar = ray->tfar;
  uint32_t stack[256];
  int sp = 0, found = 0;
  stack[sp++] = b->root;
  while (sp) {
    uint32_t ref = stack[--sp];
    if (ref & FR_BVH2_LEAF) {
      uint32_t first = FR_BVH2_LEAF_FIRST(ref), count = FR_BVH2_LEAF_COUNT(ref);
      for (uint32_t i = first; i < first + count; i++) {
        uint32_t prim = b->prims[i];
        vec3 p0 = vertex(m, prim, 0), p1 = vertex(m, prim, 1), p2 = vertex(m, prim, 2);
        float t, u, v;
        if (!fr_tri_watertight(&w, o, d, ray->tnear, tfar, p0, p1, p2, &t, &u, &v)) continue;
        if (any_hit) return 1;
        found = 1;
        tfar = t;
        hit->t = t; hit->u = u; hit->v = v; hit->prim = prim; /* t refined below, once */
        vec3 ng = v3_cross(v3_sub(p1, p0), v3_sub(p2, p0));
        hit->ng[0] = ng.x; hit->ng[1] = ng.y; hit->ng[2] = ng.z;
      }
      continue;
    }
    const fr_bvh2_node *n = &b->nodes[ref];
    for (int k = 0; k < 2; k++)
      if (fr_bvh2_box_hit(n, k, ray->org, rd, ray->tnear, tfar) && sp < 256) stack[sp++] = n->child[k];
  }
  return found;
}

void fr_bvh2_intersect_reference(const fr_bvh2 *b, const fr_mesh *m, const fr_ray *ray, fr_hit *hit) {
  fr_hit_miss(hit);
  if (!traverse(b, m, ray, hit, 0)) return;
  hit->t = fr_tri_refine_t(v3_load(ray->org), v3_load(ray->dir), ray->tnear, ray->tfar, vertex(m, hit->prim, 0),
                           vertex(m, hit->prim, 1), vertex(m, hit->prim, 2), hit->t);
}

int fr_bvh2_occluded_reference(const fr_bvh2 *b, const fr_mesh *m, const fr_ray *ray) {
  fr_hit h;
  return traverse(b, m, ray, &h, 1);
}
