#include "lpacket.h"
#include <math.h>
#include <string.h>
#include "trace/kernels.h"

static const char *traversal_names[FR_LP_TRAVERSAL_COUNT] = {"masked", "ranged", "partition"};

const char *fr_lp_traversal_name(fr_lp_traversal t) { return t < FR_LP_TRAVERSAL_COUNT ? traversal_names[t] : "?"; }

int fr_lp_traversal_parse(const char *name, fr_lp_traversal *out) {
  for (int i = 0; i < FR_LP_TRAVERSAL_COUNT; i++)
    if (!strcmp(name, traversal_names[i])) { *out = (fr_lp_traversal)i; return 1; }
  return 0;
}

static int ray_ok(const fr_ray *r) {
  for (int a = 0; a < 3; a++)
    if (!isfinite(r->org[a]) || !isfinite(r->dir[a])) return 0;
  if (r->dir[0] == 0.0f && r->dir[1] == 0.0f && r->dir[2] == 0.0f) return 0;
  return !isnan(r->tnear) && !isnan(r->tfar) && r->tnear <= r->tfar;
}

void fr_lpacket_load(fr_lpacket *p, const fr_ray *rays, int n) {
  p->n = n;
  p->nchunks = (n + 15) / 16;
  memset(p->valid, 0, sizeof p->valid);
  for (int i = 0; i < 16 * p->nchunks; i++) {
    int ok = i < n && ray_ok(&rays[i]);
    for (int a = 0; a < 3; a++) {
      p->o[a][i] = ok ? rays[i].org[a] : 0.0f;
      p->d[a][i] = ok ? rays[i].dir[a] : 1.0f;
    }
    /* an invalid lane's range is empty, so it fails every test by itself too */
    p->tnear[i] = ok ? rays[i].tnear : 1.0f;
    p->tfar[i] = ok ? rays[i].tfar : 0.0f;
    p->valid[i / 16] |= (uint16_t)(ok << (i % 16));
  }
}

void fr_lpacket_hits(const fr_lpacket *p, const fr_lp_scene *g, fr_hit *hits) {
  const fr_bvh2 *b = g->tris;
  for (int i = 0; i < p->n; i++) {
    fr_hit *h = &hits[i];
    uint32_t t = p->tri[i];
    if (t == FR_INVALID_ID) {
      h->t = INFINITY;
      h->u = h->v = 0.0f;
      h->prim = FR_INVALID_ID;
      h->ng[0] = h->ng[1] = h->ng[2] = 0.0f;
      continue;
    }
    if (t & FR_LP_SPHERE) { /* the same operations as fr_spheres_hit */
      uint32_t li = t & ~FR_LP_SPHERE;
      const fr_sphere *s = &g->spheres->spheres[li];
      h->t = p->tfar[i];
      h->u = h->v = 0.0f;
      h->prim = g->sphere_base + g->spheres->prims[li];
      for (int a = 0; a < 3; a++) h->ng[a] = p->o[a][i] + h->t * p->d[a][i] - s->c[a];
      continue;
    }
    const fr_bvh2_tri *r = &b->tris[t];
    h->t = p->tfar[i];
    h->u = p->u[i];
    h->v = p->v[i];
    h->prim = r->prim;
    fr_bvh2_tri_normal(r, h->ng);
  }
}

const fr_lp_fns *fr_lp_active(void) {
  switch (fr_kernels_active()->isa) {
  case FR_ISA_AVX512: return &fr_lp_avx512;
  case FR_ISA_AVX2: return &fr_lp_avx2;
  default: return &fr_lp_scalar;
  }
}
