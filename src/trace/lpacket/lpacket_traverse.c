/*
 * Large-packet traversal of the binary BVH (trace/lpacket.h), compiled once
 * per ISA. A stack entry is a child reference, its box (the parent node and
 * slot) and the parent's set of chunks; the box is tested when the entry is
 * popped, first for the whole packet by its bounds (the cull), then chunk by
 * chunk, which narrows the set the way the traversal mode says. Testing on
 * pop is what lets the partition mode split its list in place: a subtree
 * only reorders the prefix its sibling will read, never its contents.
 *
 * Triangles are tested 16 rays at a time with the watertight edge test of
 * trace/tri_edges16.h, each ray from its own origin.
 */
#include <math.h>
#include <string.h>
#include "base/simd.h"
#include "base/simd_packet.h"
#include "trace/counters.h"
#include "trace/lpacket/lpacket.h"
#include "trace/sphere16.h"
#include "trace/tri_edges16.h"

#if P != 16
#error "the large-packet kernels are 16 wide"
#endif

#define ROUND_UP (1.0f + 0x1p-20f)
#define TINY 1e-18f
/* Chunks a leaf's set must span before its triangles are culled: on
 * Whitted 16x16 packets 4 and 8 measured alike and 1-3% above 2 (kitchen,
 * museum). At least 2: setup makes no bounds for one chunk. */
#ifndef TRI_CULL_MIN_CHUNKS
#define TRI_CULL_MIN_CHUNKS 4
#endif
#define STACK 256

typedef struct entry {
  uint32_t ref;
  const fr_bvh2_node *parent; /* NULL for the root: no box to test */
  int slot;
  int depth;                  /* masked: the frame of the parent's masks */
  int a, b;                   /* ranged: first and last chunk; partition: list length */
} entry;

/* the rays of chunk c whose slab test reaches box k of node n before their tfar */
FR_INLINE unsigned box16(const fr_lpacket *p, int c, const fr_bvh2_node *n, int k) {
  const float *lo[3] = {n->lo_x, n->lo_y, n->lo_z}, *hi[3] = {n->hi_x, n->hi_y, n->hi_z};
  const int i = 16 * c;
  vpf tn = vp_load(p->tnear + i), tf = vp_load(p->tfar + i);
  for (int a = 0; a < 3; a++) {
    vpf o = vp_load(p->o[a] + i), rd = vp_load(p->rd[a] + i);
    vpf t0 = vp_mul(vp_sub(vp(lo[a][k]), o), rd), t1 = vp_mul(vp_sub(vp(hi[a][k]), o), rd);
    tn = vp_max(tn, vp_min(t0, t1));
    tf = vp_min(tf, vp_max(t0, t1));
  }
  FR_COUNT(lp_box_chunks, 1);
  return vpm_bits(vp_le(tn, vp_mul(tf, vp(ROUND_UP))));
}

/* The edge vectors of triangle r seen from chunk c's origins. */
typedef struct edges16 { vpf E[3][3], det; float n[3]; } edges16;

FR_INLINE void chunk_edges(const fr_lpacket *p, int c, const fr_bvh2_tri *r, edges16 *e) {
  const int i = 16 * c;
  vpf o[3] = {vp_load(p->o[0] + i), vp_load(p->o[1] + i), vp_load(p->o[2] + i)};
  fr_tri_edges16(r, e->n, o, e->E, &e->det);
}

/* Chunk c's rays of m against triangle index ti (edges e); closest: keeps
 * the nearer hits, else returns the rays that hit anything in range. */
FR_INLINE unsigned tri16(fr_lpacket *p, int c, const fr_bvh2_tri *r, edges16 *e, uint32_t ti, unsigned m, int closest) {
  const int i = 16 * c;
  vpf dx = vp_load(p->d[0] + i), dy = vp_load(p->d[1] + i), dz = vp_load(p->d[2] + i);
  vpf w[3], det = e->det;
  FR_COUNT(lp_tri_chunks, 1);
  m = fr_tri_edges16_inside(dx, dy, dz, e->E, det, m, w);
  if (!m) return 0;
  vpf tf = vp_load(p->tfar + i);
  vpf t = vp_div(det, fr_dot3v(dx, dy, dz, vp(e->n[0]), vp(e->n[1]), vp(e->n[2])));
  m &= vpm_bits(vpm_and(vp_gt(t, vp_load(p->tnear + i)), vp_lt(t, tf)));
  if (!m || !closest) return m;
  vpf inv = vp_div(vp(1.0f), vp_add(vp_add(w[0], w[1]), w[2]));
  vpm hm = vpm_bits_to(m);
  vp_store(p->tfar + i, vp_select(hm, t, tf));
  vp_store(p->u + i, vp_select(hm, vp_mul(w[1], inv), vp_load(p->u + i)));
  vp_store(p->v + i, vp_select(hm, vp_mul(w[2], inv), vp_load(p->v + i)));
  for (unsigned mm = m; mm; mm &= mm - 1) p->tri[i + __builtin_ctz(mm)] = ti;
  return m;
}

/* Chunk c's rays of m against the sphere at leaf index li: fr_sphere_roots'
 * operations lane by lane, so the answers are fr_intersect1's bit for bit. */
FR_INLINE unsigned sphere16(fr_lpacket *p, int c, const fr_sphere *s, uint32_t li, unsigned m, int closest) {
  const int i = 16 * c;
  const vpf o[3] = {vp_load(p->o[0] + i), vp_load(p->o[1] + i), vp_load(p->o[2] + i)};
  const vpf d[3] = {vp_load(p->d[0] + i), vp_load(p->d[1] + i), vp_load(p->d[2] + i)};
  const vpf tf = vp_load(p->tfar + i);
  vpf t;
  FR_COUNT(lp_sph_chunks, 1);
  m = fr_sphere16_hit(s, o, d, vp_load(p->tnear + i), tf, m, &t);
  if (!m || !closest) return m;
  vpm hm = vpm_bits_to(m);
  vp_store(p->tfar + i, vp_select(hm, t, tf));
  vp_store(p->u + i, vp_select(hm, vp(0.0f), vp_load(p->u + i)));
  vp_store(p->v + i, vp_select(hm, vp(0.0f), vp_load(p->v + i)));
  for (unsigned mm = m; mm; mm &= mm - 1) p->tri[i + __builtin_ctz(mm)] = FR_LP_SPHERE | li;
  return m;
}

typedef struct state {
  fr_lpacket *p;
  const fr_bvh2 *b;
  const fr_lp_opts *opt;
  float dmean[3];
  int live;      /* chunks with rays still alive (any hit) */
  int shared;    /* every valid ray starts at o0 (camera rays) */
  float o0[3];
} state;

/* Interval-arithmetic bounds (all the IA cull reads) straight from the
 * rays' floats, 16 lanes at a time: min and max are exact, and the
 * reciprocal intervals are those of the very reciprocals box16 multiplies
 * by, so the cull stays conservative. The general build (fr_pbounds_build:
 * three passes in double, for the planes too) cost more than the IA cull
 * saved. */
static void ia_bounds(fr_lpacket *p) {
  fr_pbounds *b = &p->bounds;
  memset(b, 0, sizeof *b);
  const vpf inf = vp(INFINITY), ninf = vp(-INFINITY);
  vpf olo[3], ohi[3], dlo[3], dhi[3], rlo[3], rhi[3], tlo = inf, thi = ninf;
  for (int a = 0; a < 3; a++) olo[a] = dlo[a] = rlo[a] = inf, ohi[a] = dhi[a] = rhi[a] = ninf;
  int any = 0;
  for (int c = 0; c < p->nchunks; c++) {
    if (!p->valid[c]) continue;
    any = 1;
    const int i = 16 * c;
    const vpm m = vpm_bits_to(p->valid[c]);
    for (int a = 0; a < 3; a++) {
      vpf o = vp_load(p->o[a] + i), d = vp_load(p->d[a] + i), r = vp_load(p->rd[a] + i);
      olo[a] = vp_min(olo[a], vp_select(m, o, inf)); ohi[a] = vp_max(ohi[a], vp_select(m, o, ninf));
      dlo[a] = vp_min(dlo[a], vp_select(m, d, inf)); dhi[a] = vp_max(dhi[a], vp_select(m, d, ninf));
      rlo[a] = vp_min(rlo[a], vp_select(m, r, inf)); rhi[a] = vp_max(rhi[a], vp_select(m, r, ninf));
    }
    tlo = vp_min(tlo, vp_select(m, vp_load(p->tnear + i), inf));
    thi = vp_max(thi, vp_select(m, vp_load(p->tfar + i), ninf));
  }
  if (!any) { b->empty = 1; return; }
  b->tmin = vp_reduce_min(tlo);
  b->tmax = vp_reduce_max(thi);
  float scale = 0.0f;
  int shared = 1;
  for (int a = 0; a < 3; a++) {
    b->olo[a] = vp_reduce_min(olo[a]); b->ohi[a] = vp_reduce_max(ohi[a]);
    b->dlo[a] = vp_reduce_min(dlo[a]); b->dhi[a] = vp_reduce_max(dhi[a]);
    if (b->dlo[a] > 0.0f || b->dhi[a] < 0.0f) {
      b->uniform |= 1u << a;
      b->rlo[a] = vp_reduce_min(rlo[a]);
      b->rhi[a] = vp_reduce_max(rhi[a]);
    }
    scale = fr_pb_max(scale, fr_pb_max(fabsf(b->olo[a]), fabsf(b->ohi[a])));
    shared &= b->olo[a] == b->ohi[a];
  }
  b->scale = scale;
  b->shared_origin = shared;
}

/* Float error allowance of the plane bounds: each bound below is off by at
 * most about 2^-21 of the magnitudes it is made of, and is pushed outward
 * by twice that. */
#define PLANE_ERR 0x1p-20f

/* Bounding planes along the major axis k (packet_bounds.h), in float, 16
 * lanes at a time, each bound pushed outward by a bound on its own rounding
 * error. The double build (fr_pbounds_build: three scalar passes) cost more
 * than the planes and corner rays saved. Non-finite bounds (a direction
 * nearly perpendicular to every axis of one sign) leave the IA bounds. */
static void plane_bounds(fr_lpacket *p) {
  ia_bounds(p);
  fr_pbounds *b = &p->bounds;
  if (b->empty || !b->uniform) return;
  const vpf inf = vp(INFINITY), ninf = vp(-INFINITY), zero = vp(0.0f), E = vp(PLANE_ERR);
  /* the major axis: the one of uniform sign whose directions stay farthest
   * from 0 relative to their length, so the slopes stay small */
  vpf frac[3] = {inf, inf, inf};
  for (int c = 0; c < p->nchunks; c++) {
    if (!p->valid[c]) continue;
    const int i = 16 * c;
    const vpm m = vpm_bits_to(p->valid[c]);
    vpf ad[3] = {vp_abs(vp_load(p->d[0] + i)), vp_abs(vp_load(p->d[1] + i)), vp_abs(vp_load(p->d[2] + i))};
    vpf inv = vp_div(vp(1.0f), vp_add(vp_add(ad[0], ad[1]), ad[2]));
    for (int a = 0; a < 3; a++) frac[a] = vp_min(frac[a], vp_select(m, vp_mul(ad[a], inv), inf));
  }
  int k = -1;
  float best = -1.0f;
  for (int a = 0; a < 3; a++) {
    float f = vp_reduce_min(frac[a]);
    if (((b->uniform >> a) & 1) && f > best) best = f, k = a;
  }
  const int u = (k + 1) % 3, v = (k + 2) % 3;
  const float sk = b->dlo[k] > 0.0f ? 1.0f : -1.0f;
  /* K = sk x_k grows along every ray: knear and kfar bound the rays' K */
  vpf kn = inf, kf = ninf;
  for (int c = 0; c < p->nchunks; c++) {
    if (!p->valid[c]) continue;
    const int i = 16 * c;
    const vpm m = vpm_bits_to(p->valid[c]);
    vpf K = vp_mul(vp(sk), vp_load(p->o[k] + i)), dk = vp_abs(vp_load(p->d[k] + i));
    vpf an = vp_mul(vp_load(p->tnear + i), dk), af = vp_mul(vp_load(p->tfar + i), dk);
    /* K + 0 is exact: no allowance, so camera rays keep a point at knear */
    vpf en = vp_select(vp_eq(an, zero), zero, vp_mul(vp_add(vp_abs(K), vp_abs(an)), E));
    vpf ef = vp_mul(vp_add(vp_abs(K), vp_abs(af)), E);
    kn = vp_min(kn, vp_select(m, vp_sub(vp_add(K, an), en), inf));
    kf = vp_max(kf, vp_select(m, vp_add(vp_add(K, af), ef), ninf)); /* tfar = inf: +inf */
  }
  /* A shared origin's K bounds every start when no tnear is negative; then
   * every ray crosses knear at the origin itself, the single point the
   * corner-ray edge test (fr_pbounds_cull_tri) takes it for. */
  const float knear = b->shared_origin && b->tmin >= 0.0f ? sk * b->olo[k] : vp_reduce_min(kn);
  const float kfar = vp_reduce_max(kf);
  /* each ray's u, v where it crosses K = knear, and its slopes du/dK, dv/dK */
  vpf ulo = inf, vlo = inf, sulo = inf, svlo = inf, uhi = ninf, vhi = ninf, suhi = ninf, svhi = ninf;
  for (int c = 0; c < p->nchunks; c++) {
    if (!p->valid[c]) continue;
    const int i = 16 * c;
    const vpm m = vpm_bits_to(p->valid[c]);
    vpf rk = vp_div(vp(1.0f), vp_abs(vp_load(p->d[k] + i)));
    vpf back = vp_sub(vp(knear), vp_mul(vp(sk), vp_load(p->o[k] + i)));
    vpf su = vp_mul(vp_load(p->d[u] + i), rk), sv = vp_mul(vp_load(p->d[v] + i), rk);
    vpf ou = vp_load(p->o[u] + i), ov = vp_load(p->o[v] + i), bu = vp_mul(back, su), bv = vp_mul(back, sv);
    vpf pu = vp_add(ou, bu), pv = vp_add(ov, bv);
    vpf eu = vp_select(vp_eq(bu, zero), zero, vp_mul(vp_add(vp_abs(ou), vp_abs(bu)), E));
    vpf ev = vp_select(vp_eq(bv, zero), zero, vp_mul(vp_add(vp_abs(ov), vp_abs(bv)), E));
    vpf esu = vp_mul(vp_abs(su), E), esv = vp_mul(vp_abs(sv), E);
    ulo = vp_min(ulo, vp_select(m, vp_sub(pu, eu), inf)); uhi = vp_max(uhi, vp_select(m, vp_add(pu, eu), ninf));
    vlo = vp_min(vlo, vp_select(m, vp_sub(pv, ev), inf)); vhi = vp_max(vhi, vp_select(m, vp_add(pv, ev), ninf));
    sulo = vp_min(sulo, vp_select(m, vp_sub(su, esu), inf)); suhi = vp_max(suhi, vp_select(m, vp_add(su, esu), ninf));
    svlo = vp_min(svlo, vp_select(m, vp_sub(sv, esv), inf)); svhi = vp_max(svhi, vp_select(m, vp_add(sv, esv), ninf));
  }
  const float f[8] = {vp_reduce_min(ulo), vp_reduce_max(uhi), vp_reduce_min(vlo), vp_reduce_max(vhi),
                      vp_reduce_min(sulo), vp_reduce_max(suhi), vp_reduce_min(svlo), vp_reduce_max(svhi)};
  if (!isfinite(knear) || isnan(kfar)) return;
  for (int j = 0; j < 8; j++)
    if (!isfinite(f[j])) return;
  b->has_planes = 1;
  b->k = k; b->u = u; b->v = v;
  b->sk = sk;
  b->knear = knear; b->kfar = kfar;
  b->ulo = f[0]; b->uhi = f[1]; b->vlo = f[2]; b->vhi = f[3];
  b->sulo = f[4]; b->suhi = f[5]; b->svlo = f[6]; b->svhi = f[7];
  b->scale = fr_pb_max(b->scale, fabsf(knear));
}

static void make_bounds(fr_lpacket *p, fr_cull cull) {
  if (cull == FR_CULL_IA) ia_bounds(p);
  else if (cull != FR_CULL_OFF) plane_bounds(p);
}

static void setup(state *S, fr_lpacket *p, const fr_lp_opts *opt) {
  S->p = p;
  S->opt = opt;
  S->live = 0;
  S->shared = 1;
  float *o0 = S->o0;
  o0[0] = o0[1] = o0[2] = 0.0f;
  for (int c = 0; c < p->nchunks; c++)
    if (p->valid[c]) {
      int k = __builtin_ctz(p->valid[c]);
      for (int a = 0; a < 3; a++) o0[a] = p->o[a][16 * c + k];
      break;
    }
  double sum[3] = {0, 0, 0};
  vpf tiny = vp(TINY);
  for (int c = 0; c < p->nchunks; c++) {
    const int i = 16 * c;
    for (int a = 0; a < 3; a++) {
      vpf d = vp_load(p->d[a] + i);
      d = vp_select(vp_lt(vp_abs(d), tiny), vp_copysign(tiny, d), d);
      vp_store(p->rd[a] + i, vp_div(vp(1.0f), d));
    }
    p->alive[c] = p->valid[c];
    /* bit for bit (-0 is not 0 to the edge products' signs) */
    for (int k = 0; k < 16 && S->shared; k++)
      if ((p->valid[c] >> k) & 1) S->shared = !memcmp(&p->o[0][i + k], &o0[0], 4) && !memcmp(&p->o[1][i + k], &o0[1], 4) &&
                                            !memcmp(&p->o[2][i + k], &o0[2], 4);
    p->occ[c] = 0;
    S->live += p->valid[c] != 0;
    for (int k = 0; k < 16; k++) {
      p->tri[i + k] = FR_INVALID_ID;
      if ((p->valid[c] >> k) & 1)
        for (int a = 0; a < 3; a++) sum[a] += p->d[a][i + k];
    }
  }
  for (int a = 0; a < 3; a++) S->dmean[a] = (float)sum[a];
  /* one chunk: no cull is ever tried (narrow, leaf), so no bounds */
  if (p->nchunks > 1) make_bounds(p, opt->cull);
}

/* Whether the whole packet misses box k of node n by its bounds. */
static int cull_box(const state *S, const fr_bvh2_node *n, int k) {
  float lo[3] = {n->lo_x[k], n->lo_y[k], n->lo_z[k]}, hi[3] = {n->hi_x[k], n->hi_y[k], n->hi_z[k]};
  if (!fr_pbounds_cull_box(&S->p->bounds, S->opt->cull, lo, hi)) return 0;
  FR_COUNT(lp_culled, 1);
  return 1;
}

/* Narrows the parent's set (entry e) to the chunks with a ray that hits e's
 * box; fills the child set in *out. 0 when no chunk is left. The packet's
 * bounds are tried only once the first chunk tested has missed (Overbeck's
 * order): where a ray of it hits, which is most boxes a coherent packet
 * visits, the cull could not have helped and costs nothing. Nor is it
 * tried when no chunk is left to test after the one that missed. */
FR_INLINE int narrow(state *S, const entry *e, entry *out) {
  fr_lpacket *p = S->p;
  const fr_bvh2_node *n = e->parent;
  const int k = e->slot, cull = S->opt->cull != FR_CULL_OFF;
  switch (S->opt->traversal) {
  case FR_LP_MASKED: {
    const uint16_t *in = p->frames[e->depth];
    if (e->depth + 1 >= FR_LP_FRAMES) {
      /* deeper than the frames: keep the parent's masks (a superset) */
      out->depth = e->depth;
      return !(cull && cull_box(S, n, k));
    }
    uint16_t *mo = p->frames[e->depth + 1];
    unsigned any = 0;
    int tested = 0;
    for (int c = 0; c < p->nchunks; c++) {
      unsigned m = in[c] & p->alive[c];
      if (m) {
        m &= box16(p, c, n, k);
        if (!tested++ && !m && cull && c + 1 < p->nchunks && cull_box(S, n, k)) return 0;
      }
      mo[c] = (uint16_t)m;
      any |= m;
    }
    out->depth = e->depth + 1;
    return any != 0;
  }
  case FR_LP_RANGED: {
    int first = -1, last = -1, tested = 0;
    for (int c = e->a; c <= e->b; c++) {
      if (!p->alive[c]) continue;
      if (box16(p, c, n, k) & p->alive[c]) { first = c; break; }
      if (!tested++ && cull && c < e->b && cull_box(S, n, k)) return 0;
    }
    if (first < 0) return 0;
    for (int c = e->b; c > first; c--)
      if (p->alive[c] && (box16(p, c, n, k) & p->alive[c])) { last = c; break; }
    out->a = first;
    out->b = last < 0 ? first : last;
    return 1;
  }
  default: {
    uint8_t *l = p->list;
    int hit = 0, tested = 0;
    for (int j = 0; j < e->a; j++) {
      int c = l[j];
      if (!p->alive[c]) continue;
      if (box16(p, c, n, k) & p->alive[c]) {
        l[j] = l[hit];
        l[hit++] = (uint8_t)c;
      } else if (!tested++ && !hit && cull && j + 1 < e->a && cull_box(S, n, k)) return 0;
    }
    out->a = hit;
    return hit > 0;
  }
  }
}

/* The leaf of entry e (its set already narrowed into e) against its
 * triangles, or its spheres in the sphere tree. */
static void leaf(state *S, const entry *e, int closest) {
  fr_lpacket *p = S->p;
  const fr_bvh2 *b = S->b;
  uint32_t ref = e->ref, first = FR_BVH2_LEAF_FIRST(ref), count = FR_BVH2_LEAF_COUNT(ref);
  FR_COUNT(lp_leaves, 1);
  const int nc = S->opt->traversal == FR_LP_RANGED ? e->b - e->a + 1 : S->opt->traversal == FR_LP_PARTITION ? e->a : p->nchunks;
  /* the cull pays only where it may save more than one chunk's test */
  const int cull = S->opt->cull != FR_CULL_OFF && nc >= TRI_CULL_MIN_CHUNKS;
  for (uint32_t j = 0; j < count; j++) {
    const fr_bvh2_tri *r = b->spheres ? NULL : &b->tris[first + j];
    const fr_sphere *sp = b->spheres ? &b->spheres[first + j] : NULL;
    FR_COUNT(lp_tris, 1);
    if (cull &&
        (sp ? fr_pbounds_cull_sphere(&p->bounds, S->opt->cull, sp->c, sp->r)
            : fr_pbounds_cull_tri(&p->bounds, S->opt->cull, r->v0, r->v1, r->v2))) {
      if (sp) FR_COUNT(lp_sph_culled, 1);
      else FR_COUNT(lp_tri_culled, 1);
      continue;
    }
    edges16 ed;
    int have_edges = 0;
    if (r) fr_bvh2_tri_normal(r, ed.n);
    else ed.n[0] = ed.n[1] = ed.n[2] = 0.0f; /* spheres: no edges */
    for (int jc = 0; jc < nc; jc++) {
      int c = S->opt->traversal == FR_LP_RANGED ? e->a + jc : S->opt->traversal == FR_LP_PARTITION ? p->list[jc] : jc;
      unsigned m = p->alive[c];
      if (S->opt->traversal == FR_LP_MASKED) m &= p->frames[e->depth][c];
      if (!m) continue;
      unsigned hit;
      if (sp) hit = sphere16(p, c, sp, first + j, m, closest);
      else {
        /* one origin: the edges are the same in every chunk (and lane),
         * made once per triangle, bit for bit what each chunk would make */
        if (!S->shared) chunk_edges(p, c, r, &ed);
        else if (!have_edges) {
          const vpf o[3] = {vp(S->o0[0]), vp(S->o0[1]), vp(S->o0[2])};
          fr_tri_edges16(r, ed.n, o, ed.E, &ed.det);
          have_edges = 1;
        }
        hit = tri16(p, c, r, &ed, first + j, m, closest);
      }
      if (!closest && hit) {
        p->occ[c] |= (uint16_t)hit;
        p->alive[c] &= (uint16_t)~hit;
        if (!p->alive[c] && --S->live == 0) return;
      }
    }
  }
}

/* Both children are pushed untested (narrow tests them when popped), and
 * their nodes or first leaf lines are prefetched as they are pushed. 0
 * turns that off, for measurement. */
#ifndef LP_PREFETCH_LINES
#define LP_PREFETCH_LINES 4
#endif

/* The packet through one tree (triangles or spheres). */
static void walk(state *S0, const fr_bvh2 *b, int closest) {
  state S = *S0;
  fr_lpacket *p = S.p;
  const fr_lp_opts *opt = S.opt;
  S.b = b;
  entry stack[STACK];
  int sp = 0;
  entry root = {b->root, NULL, 0, 0, 0, p->nchunks - 1};
  if (opt->traversal == FR_LP_MASKED) memcpy(p->frames[0], p->valid, sizeof p->valid);
  if (opt->traversal == FR_LP_PARTITION) {
    root.a = 0;
    for (int c = 0; c < p->nchunks; c++)
      if (p->valid[c]) p->list[root.a++] = (uint8_t)c;
  }
  stack[sp++] = root;
  while (sp > 0) {
    entry e = stack[--sp], in = e;
    FR_COUNT(lp_nodes, 1);
    if (e.parent && !narrow(&S, &in, &e)) continue;
    if (e.ref & FR_BVH2_LEAF) {
      leaf(&S, &e, closest);
      if (!closest && S.live == 0) break;
      continue;
    }
    if (sp + 2 > STACK) continue; /* cannot happen: the build caps the depth */
    const fr_bvh2_node *n = &b->nodes[e.ref];
    /* nearer child first along the packet's mean direction */
    float s = 0.0f;
    const float *lo[3] = {n->lo_x, n->lo_y, n->lo_z}, *hi[3] = {n->hi_x, n->hi_y, n->hi_z};
    for (int a = 0; a < 3; a++) s += (lo[a][0] + hi[a][0] - lo[a][1] - hi[a][1]) * S.dmean[a];
    int near = s > 0.0f;
    entry c0 = e, c1 = e;
    c0.ref = n->child[!near]; c0.parent = n; c0.slot = !near;
    c1.ref = n->child[near]; c1.parent = n; c1.slot = near;
    stack[sp++] = c0;
    stack[sp++] = c1;
#if LP_PREFETCH_LINES
    fr_bvh2_prefetch(b, c1.ref, LP_PREFETCH_LINES);
    fr_bvh2_prefetch(b, c0.ref, LP_PREFETCH_LINES);
#endif
  }
  S0->live = S.live;
}

static void traverse(const fr_lp_scene *g, const fr_lp_opts *opt, fr_lpacket *p, int closest) {
  state S;
  FR_COUNT(lp_packets, 1);
  setup(&S, p, opt);
  FR_COUNT(rays, S.live ? p->n : 0);
  if (!S.live) return;
  if (g->tris && g->tris->nodes && g->tris->nprims) walk(&S, g->tris, closest);
  if (g->spheres && g->spheres->nprims && S.live) walk(&S, g->spheres, closest);
}

static void lp_intersect(const fr_lp_scene *g, const fr_lp_opts *opt, fr_lpacket *p) { traverse(g, opt, p, 1); }
static void lp_occluded(const fr_lp_scene *g, const fr_lp_opts *opt, fr_lpacket *p) { traverse(g, opt, p, 0); }

/* The packet's bounds as the traversal makes them for opt->cull (tests). */
static void lp_bounds(const fr_lp_opts *opt, fr_lpacket *p) {
  state S;
  setup(&S, p, opt);
  make_bounds(p, opt->cull);
}

const fr_lp_fns FR_ISA_FN(fr_lp) = {lp_intersect, lp_occluded, lp_bounds};
