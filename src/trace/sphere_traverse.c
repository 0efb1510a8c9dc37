#include "sphere_traverse.h"
#include <math.h>
#include "trace/counters.h"
#include "trace/kernels.h"

#define STACK 128

typedef struct sray { float o[3], rd[3]; } sray;

static float rcp(float d) {
  if (fabsf(d) < 1e-18f) d = copysignf(1e-18f, d);
  return 1.0f / d;
}

/* entry distance of box k of n, or INFINITY if the ray misses it in [tnear, tfar] */
static float box_enter(const fr_bvh2_node *n, int k, const sray *r, float tnear, float tfar) {
  float lo[3] = {n->lo_x[k], n->lo_y[k], n->lo_z[k]}, hi[3] = {n->hi_x[k], n->hi_y[k], n->hi_z[k]};
  float tn = tnear, tf = tfar;
  for (int a = 0; a < 3; a++) {
    float t0 = (lo[a] - r->o[a]) * r->rd[a], t1 = (hi[a] - r->o[a]) * r->rd[a];
    if (r->rd[a] < 0.0f) { float t = t0; t0 = t1; t1 = t; }
    tn = t0 > tn ? t0 : tn;
    tf = t1 < tf ? t1 : tf;
  }
  return tn <= fr_widen_exit(tf) ? tn : INFINITY;
}

void fr_spheres_hit(const fr_bvh2 *b, uint32_t prim_base, const fr_ray *ray, uint32_t li, float t, fr_hit *hit) {
  const fr_sphere *s = &b->spheres[li];
  hit->t = t;
  hit->u = hit->v = 0.0f;
  hit->prim = prim_base + b->prims[li];
  for (int a = 0; a < 3; a++) hit->ng[a] = ray->org[a] + t * ray->dir[a] - s->c[a];
}

/* Nearest sphere hit before tfar (any: the first found); its leaf index in *li. */
static int traverse(const fr_bvh2 *b, const fr_ray *ray, float tfar, int any, uint32_t *li, float *t) {
  if (b->nprims == 0 || fr_ray_invalid(ray)) return 0;
  sray r = {{ray->org[0], ray->org[1], ray->org[2]}, {rcp(ray->dir[0]), rcp(ray->dir[1]), rcp(ray->dir[2])}};
  struct { uint32_t ref; float t; } stack[STACK];
  int sp = 0, found = 0;
  stack[sp].ref = b->root;
  stack[sp++].t = -INFINITY;
  while (sp) {
    sp--;
    if (stack[sp].t > tfar) continue;
    uint32_t ref = stack[sp].ref;
    if (ref & FR_BVH2_LEAF) {
      uint32_t first = FR_BVH2_LEAF_FIRST(ref), count = FR_BVH2_LEAF_COUNT(ref);
      for (uint32_t i = first; i < first + count; i++) {
        float th;
        FR_COUNT(sp_tests, 1);
        if (!fr_sphere_hit(&b->spheres[i], ray->org, ray->dir, ray->tnear, tfar, &th)) continue;
        *li = i;
        *t = tfar = th;
        found = 1;
        if (any) return 1;
      }
      continue;
    }
    const fr_bvh2_node *n = &b->nodes[ref];
    FR_COUNT(sp_box_tests, 2);
    float t0 = box_enter(n, 0, &r, ray->tnear, tfar), t1 = box_enter(n, 1, &r, ray->tnear, tfar);
    int near = t1 < t0;
    float tn = near ? t1 : t0, tf = near ? t0 : t1;
    /* the farther child first onto the stack; the stack depth is bounded by the build's */
    if (tf < INFINITY && sp < STACK) { stack[sp].ref = n->child[!near]; stack[sp++].t = tf; }
    if (tn < INFINITY && sp < STACK) { stack[sp].ref = n->child[near]; stack[sp++].t = tn; }
  }
  return found;
}

void fr_spheres_intersect1(const fr_bvh2 *b, uint32_t prim_base, const fr_ray *ray, fr_hit *hit) {
  uint32_t li;
  float t;
  float tfar = hit->prim == FR_INVALID_ID ? ray->tfar : hit->t;
  if (traverse(b, ray, tfar, 0, &li, &t)) fr_spheres_hit(b, prim_base, ray, li, t, hit);
}

int fr_spheres_occluded1(const fr_bvh2 *b, const fr_ray *ray) {
  uint32_t li;
  float t;
  return traverse(b, ray, ray->tfar, 1, &li, &t);
}

void fr_spheres_intersect1_brute(const fr_bvh2 *b, uint32_t prim_base, const fr_ray *ray, fr_hit *hit) {
  if (fr_ray_invalid(ray)) return;
  float tfar = hit->prim == FR_INVALID_ID ? ray->tfar : hit->t;
  for (uint32_t i = 0; i < b->nprims; i++) {
    float t;
    if (fr_sphere_hit(&b->spheres[i], ray->org, ray->dir, ray->tnear, tfar, &t)) {
      fr_spheres_hit(b, prim_base, ray, i, t, hit);
      tfar = t;
    }
  }
}
