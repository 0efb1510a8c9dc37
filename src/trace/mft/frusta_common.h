/*
 * What the multi-frusta kernels' any-hit walk (mft_occluded.c) and
 * closest-hit walk (mft_intersect.c) share: the 16 frusta and their set-up,
 * the node test, the leaf culls and ray tests, and the stack. Included by
 * those two files only, which are compiled once per ISA.
 *
 * Multi-frusta traversal of the binary BVH (Benthin & Wald 2009, §4), one
 * frustum per lane of a 16-wide register, compiled once per ISA.
 *
 * Node: both child boxes against all 16 frusta by interval arithmetic over
 * each frustum's box of ray directions (§4.1). An axis whose direction
 * interval contains 0 gets the straddling bound (the paper's "zero-interval
 * fix"). Nearer child first, by how many frusta enter it first. (A test of
 * the box a bounded frustum sweeps, tried on shadow frusta, never culled a
 * box the interval test kept: with t bounded by tfar, the interval test
 * implies it on every axis.)
 *
 * Leaf, per triangle: for all 16 frusta at once, the three edge cross
 * products seen from each frustum's origin, then the corner rays against the
 * edges and the plane (all four outside one edge, or all four meeting the
 * plane out of range: the frustum skips the triangle, §4.2). Then, frustum by
 * frustum (bitscan), its 16 rays are made from start + delta and tested with
 * the same cross products (§4.4):
 *
 *   w_i = d . E_i,  E_0 = (v1-o) x (v2-o), E_1 = (v2-o) x (v0-o), E_2 = (v0-o) x (v1-o)
 *   hit when every w_i has the sign of det = (v0-o) . n, t = det / (d . n) in (tnear, tfar)
 *
 * The cross products come from trace/tri_edges16.h: from each edge's
 * smaller vertex, accurate for tiny far triangles and watertight.
 */
#ifndef FR_TRACE_MFT_FRUSTA_COMMON_H
#define FR_TRACE_MFT_FRUSTA_COMMON_H
#include <math.h>
#include <stddef.h>
#include <string.h>
#include "base/simd.h"
#include "base/simd_packet.h"
#include "trace/counters.h"
#include "trace/mft/mft.h"
#include "trace/plane_test.h"
#include "trace/tri_edges16.h"

#if P != 16
#error "the frusta kernels are 16 wide"
#endif

#define ROUND_UP (1.0f + 0x1p-20f)
#define GUARD 0x1p-19f   /* rounding allowance of a corner-ray dot product, relative to |d| |E| */
#define STACK 256
#define TINY 1e-18f
/* When a frustum's bounds shrink to its active rays. Bounds made from more
 * rays still hold the rest, so the choice is free. After every triangle
 * that occludes some of its rays (the paper's CR), a frustum could shrink up
 * to 15 times, and the reductions and rebuilt bounds cost more than they
 * save where a batch's rays end in a few large occluders, but save where
 * they end a few at a time in fine geometry and the traversal goes on
 * long. So frusta shrink after each leaf with an occlusion only once their
 * batch has fetched more than EAGER_FETCHED triangles (dragon's batches
 * fetch ~110, conference's and sibenik's ~15, kitchen's ~60). */
#define EAGER_FETCHED 8u

/* The 16 frusta in structure-of-arrays form; lane f is frustum f. */
typedef struct frusta {
  float o[3][16] __attribute__((aligned(64)));
  float s[3][16] __attribute__((aligned(64)));
  float tnear[16] __attribute__((aligned(64)));
  float tfar[16] __attribute__((aligned(64)));   /* shadows: given; closest: farthest hit so far */
  /* interval arithmetic: reciprocals of the direction bounds. On an axis
   * where a frustum's directions have one sign, rs = 1/(the largest |d|),
   * rl = 1/(the smallest); where they straddle 0, rs = 1/dhi > 0, rl = 1/dlo < 0 */
  float rs[3][16] __attribute__((aligned(64)));
  float rl[3][16] __attribute__((aligned(64)));
  float corner[4][3][16] __attribute__((aligned(64)));
  float guard[16] __attribute__((aligned(64)));   /* GUARD * the largest |component| of a direction */
  unsigned pos[3], straddle[3]; /* lanes with directions > 0 / straddling 0, per axis */
  /* each frustum's 16 rays' reciprocal directions, made when it first
   * reaches a leaf (rd_ready): leaf boxes are tested ray by ray */
  float rd[16][3][16] __attribute__((aligned(64)));
  unsigned rd_ready;
  unsigned cull_seen, cull_gone; /* frustum-triangle pairs the corner-ray cull saw and removed */
  /* whether every valid frustum starts at origin[] (a pinhole camera's): a
   * leaf's cross products are then the same for all frusta
   * (leaf_edges_shared) */
  int shared_origin;
  float origin[3];
  const fr_mft_set *set[16];
} frusta;

/* Per lane, what a frustum's bounds are made from: the (a, b) box of its
 * active rays and the box [lo, hi] of their delta vectors. */
typedef struct ray_box {
  float amin[16] __attribute__((aligned(64))), amax[16] __attribute__((aligned(64)));
  float bmin[16] __attribute__((aligned(64))), bmax[16] __attribute__((aligned(64)));
  float lo[3][16] __attribute__((aligned(64))), hi[3][16] __attribute__((aligned(64)));
} ray_box;

/* Lane f of R: the box of the rays of frustum f in `rays` (all 16: the set's
 * own box; fewer after shrinking: masked reductions), their delta vectors'
 * box only with `deltas`. */
static inline void ray_box_of(const frusta *F, int f, unsigned rays, ray_box *R, int deltas) {
  const fr_mft_set *S = F->set[f];
  if (rays == 0xFFFFu) {
    R->amin[f] = S->amin; R->amax[f] = S->amax; R->bmin[f] = S->bmin; R->bmax[f] = S->bmax;
    for (int a = 0; a < 3; a++) { R->lo[a][f] = S->lo[a]; R->hi[a][f] = S->hi[a]; }
    return;
  }
  vpm m = vpm_bits_to(rays);
  vpf inf = vp(INFINITY), ninf = vp(-INFINITY);
  const float *dl[3] = {S->dx, S->dy, S->dz};
  R->amin[f] = vp_reduce_min(vp_select(m, vp_load(S->a), inf));
  R->amax[f] = vp_reduce_max(vp_select(m, vp_load(S->a), ninf));
  R->bmin[f] = vp_reduce_min(vp_select(m, vp_load(S->b), inf));
  R->bmax[f] = vp_reduce_max(vp_select(m, vp_load(S->b), ninf));
  for (int a = 0; a < 3 && deltas; a++) {
    vpf d = vp_load(dl[a]);
    R->lo[a][f] = vp_reduce_min(vp_select(m, d, inf));
    R->hi[a][f] = vp_reduce_max(vp_select(m, d, ninf));
  }
}

/* Stores v into the lanes of m of p, keeping the others. */
static inline void store_lanes(float *p, vpm m, vpf v) { vp_store(p, vp_select(m, v, vp_load(p))); }

/* The bounds of the frusta in `lanes` from their ray boxes, all lanes at
 * once (frustum by frustum this was a quarter of soft16's time): the corner
 * rays always, the direction intervals only with `intervals` (without, the
 * intervals of more rays stay, which still hold these). */
static inline void frusta_bounds(frusta *F, const fr_mft_sets *T, unsigned lanes, const ray_box *R, int intervals) {
  const vpm m = vpm_bits_to(lanes);
  const vpf zero = vp(0.0f), one = vp(1.0f), tiny = vp(TINY), ntiny = vp(-TINY);
  vpf big = zero;
  for (int a = 0; a < 3 && intervals; a++) {
    vpf s = vp_load(F->s[a]);
    /* rounding is monotonic: s + lo <= s + delta_k <= s + hi for the rays' own sums */
    vpf dlo = vp_add(s, vp_load(R->lo[a])), dhi = vp_add(s, vp_load(R->hi[a]));
    big = vp_max(big, vp_max(vp_abs(dlo), vp_abs(dhi)));
    vpm pos = vp_gt(dlo, zero), neg = vp_lt(dhi, zero);
    unsigned pb = vpm_bits(pos), nb = vpm_bits(neg) & ~pb;
    F->pos[a] = (F->pos[a] & ~lanes) | (pb & lanes);
    F->straddle[a] = (F->straddle[a] & ~lanes) | (~(pb | nb) & lanes);
    /* one sign: rs = 1/(the largest |d|), rl = 1/(the smallest); straddling
     * 0: rs = 1/dhi > 0, rl = 1/dlo < 0 */
    vpf rs = vp_select(vpm_bits_to(nb), vp_min(dlo, ntiny), vp_max(dhi, tiny));
    vpf rl = vp_select(pos, vp_max(dlo, tiny), vp_select(vpm_bits_to(nb), vp_min(dhi, ntiny), vp_min(dlo, ntiny)));
    store_lanes(F->rs[a], m, vp_div(one, rs));
    store_lanes(F->rl[a], m, vp_div(one, rl));
  }
  for (int j = 0; j < 4; j++) {
    vpf ca = vp_load(j & 1 ? R->amax : R->amin), cb = vp_load(j & 2 ? R->bmax : R->bmin);
    for (int a = 0; a < 3; a++) {
      vpf c = vp_add(vp_mul(ca, vp(T->e1[a])), vp_mul(cb, vp(T->e2[a])));
      store_lanes(F->corner[j][a], m, vp_add(vp_load(F->s[a]), c));
    }
  }
  /* without intervals the guard of more rays stays: larger, so still safe */
  if (intervals) store_lanes(F->guard, m, vp_mul(vp(GUARD), big));
}

static inline void frusta_setup(frusta *F, const fr_mft_batch *B, const fr_mft_sets *T, unsigned valid) {
  F->rd_ready = 0;
  F->cull_seen = 2; /* a prior: half culled */
  F->cull_gone = 1;
  memset(F->pos, 0, sizeof F->pos);
  memset(F->straddle, 0, sizeof F->straddle);
  for (int f = 0; f < 16; f++) {
    int lane_valid = (valid >> f) & 1;
    for (int a = 0; a < 3; a++) {
      F->o[a][f] = lane_valid ? B->org[a][f] : 0.0f;
      F->s[a][f] = lane_valid ? B->start[a][f] : 1.0f;
    }
    F->tnear[f] = lane_valid ? B->tnear[f] : 0.0f;
    F->tfar[f] = lane_valid ? B->tfar[f] : 0.0f;
    F->set[f] = &T->set[lane_valid ? B->set[f] % FR_MFT_SETS : 0];
  }
  /* invalid lanes start at 0 but are never tested: only the valid agree,
   * bit for bit (-0 and 0 would round some zero products differently) */
  const int f0 = valid ? __builtin_ctz(valid) : 0;
  F->shared_origin = 1;
  for (int a = 0; a < 3; a++) {
    F->origin[a] = F->o[a][f0];
    for (int f = 0; f < 16; f++)
      F->shared_origin &= !((valid >> f) & 1) || !memcmp(&F->o[a][f], &F->origin[a], sizeof(float));
  }
  ray_box R;
  for (int f = 0; f < 16; f++) ray_box_of(F, f, 0xFFFFu, &R, 1);
  frusta_bounds(F, T, 0xFFFFu, &R, 1);
}

#define dot3 fr_dot3v

/* a . b for a cull with a guard: fused where the level has FMA */
FR_INLINE vpf dot3_bound(vpf ax, vpf ay, vpf az, vpf bx, vpf by, vpf bz) {
  return vp_madd_bound(ax, bx, vp_madd_bound(ay, by, vp_mul(az, bz)));
}

/* Child k of a node against the frusta in `m`; *tn: a lower bound of each
 * frustum's entry distance. */
FR_INLINE unsigned box_test(const frusta *F, const fr_bvh2_node *n, int k, unsigned m, vpf *tn_out) {
  const float *lo[3] = {n->lo_x, n->lo_y, n->lo_z}, *hi[3] = {n->hi_x, n->hi_y, n->hi_z};
  vpf tn = vp_load(F->tnear), tf = vp_load(F->tfar);
  for (int a = 0; a < 3; a++) {
    vpf blo = vp(lo[a][k]), bhi = vp(hi[a][k]), o = vp_load(F->o[a]);
    vpf nlo = vp_sub(blo, o), nhi = vp_sub(bhi, o);
    vpf rs = vp_load(F->rs[a]), rl = vp_load(F->rl[a]);
    vpm pos = vpm_bits_to(F->pos[a]);
    vpf nearp = vp_select(pos, nlo, nhi), farp = vp_select(pos, nhi, nlo);
    vpf enter = vp_min(vp_mul(nearp, rs), vp_mul(nearp, rl));
    vpf leave = vp_max(vp_mul(farp, rs), vp_mul(farp, rl));
    if (F->straddle[a] & m) {
      /* d in [dlo < 0, dhi > 0]: a box ahead (o < lo) is entered no sooner
       * than along dhi, one behind (o > hi) no sooner than along dlo, and
       * nothing bounds the exit */
      vpm st = vpm_bits_to(F->straddle[a]);
      enter = vp_select(st, vp_max(vp_mul(nlo, rs), vp_mul(nhi, rl)), enter);
      leave = vp_select(st, vp(INFINITY), leave);
    }
    tn = vp_max(tn, enter);
    tf = vp_min(tf, leave);
  }
  *tn_out = tn;
  return m & vpm_bits(vp_le(tn, vp_mul(tf, vp(ROUND_UP))));
}

/* Per-leaf scratch: the cross products and plane distances of one triangle
 * for all frusta, stored so a frustum's values can be broadcast. */
typedef struct tri_frusta {
  float e[3][3][16] __attribute__((aligned(64)));
  float det[16] __attribute__((aligned(64)));
  float n[3]; /* the triangle's normal (fr_bvh2_tri_normal) */
} tri_frusta;
/* ray_hits reads a lane's edges and det from one pointer: e + 16 (3 i + a), det at e + 16 * 9 */
_Static_assert(offsetof(tri_frusta, det) == 9 * 16 * sizeof(float), "det follows the edges");

/* The corner-ray cull: the frusta of m that may hit the triangle of edges E,
 * det and normal n (lane f seen from frustum f's origin). */
FR_INLINE unsigned corner_cull(const frusta *F, const vpf E[3][3], vpf det, const float n[3], unsigned m) {
  vpf nx = vp(n[0]), ny = vp(n[1]), nz = vp(n[2]);
  vpf sg = vp_and(det, vp(-0.0f)), zero = vp(0.0f), guard = vp_load(F->guard);
  unsigned cull = 0;
  for (int i = 0; i < 3; i++) {
    vpf wmax = vp(-INFINITY);
    for (int j = 0; j < 4; j++) {
      vpf w = dot3_bound(vp_load(F->corner[j][0]), vp_load(F->corner[j][1]), vp_load(F->corner[j][2]), E[i][0], E[i][1], E[i][2]);
      wmax = vp_max(wmax, vp_xor(w, sg));
    }
    vpf g = vp_mul(guard, vp_add(vp_add(vp_abs(E[i][0]), vp_abs(E[i][1])), vp_abs(E[i][2])));
    cull |= vpm_bits(vp_lt(vp_add(wmax, g), zero));
  }
  /* the plane: t = det / (d . n) beyond tfar (or behind) for all four corners */
  vpf gmax = vp(-INFINITY);
  for (int j = 0; j < 4; j++) {
    vpf g = dot3_bound(vp_load(F->corner[j][0]), vp_load(F->corner[j][1]), vp_load(F->corner[j][2]), nx, ny, nz);
    gmax = vp_max(gmax, vp_xor(g, sg));
  }
  gmax = vp_add(gmax, vp_mul(guard, vp(fabsf(n[0]) + fabsf(n[1]) + fabsf(n[2]))));
  cull |= vpm_bits(vp_le(gmax, zero));
  cull |= vpm_bits(vp_lt(vp_mul(gmax, vp_load(F->tfar)), vp_mul(vp_abs(det), vp(1.0f - 0x1p-18f))));
  return m & ~cull;
}

/* The frusta of m that may hit triangle r (all of m without corner_rays);
 * fills X. */
FR_INLINE unsigned tri_cull(const frusta *F, const fr_bvh2_tri *r, unsigned m, int corner_rays, tri_frusta *X) {
  vpf o[3] = {vp_load(F->o[0]), vp_load(F->o[1]), vp_load(F->o[2])};
  vpf E[3][3], det;
  fr_bvh2_tri_normal(r, X->n);
  fr_tri_edges16(r, X->n, o, E, &det);
  for (int i = 0; i < 3; i++)
    for (int a = 0; a < 3; a++) vp_store(X->e[i][a], E[i][a]);
  vp_store(X->det, det);
  return corner_rays ? corner_cull(F, E, det, X->n, m) : m;
}

/* Whether the corner-ray cull runs for a triangle met by n frusta: where
 * the share of frusta it removed so far in this batch, times n, exceeds
 * its cost in 16-ray tests. */
FR_INLINE int cull_pays(const frusta *F, const fr_mft_opts *opt, int n) {
  return opt->corner_rays && (float)F->cull_gone * (float)n >= opt->corner_cost * (float)F->cull_seen;
}

/* The cull's bookkeeping: what it saw and removed, and the paper's Table 1. */
FR_INLINE unsigned cull_counted(frusta *F, int culled, unsigned m, unsigned left) {
  const int n = __builtin_popcount(m);
  FR_COUNT(mft_tris, 1);
  FR_COUNT(mft_tri_frusta, n);
  if (culled) {
    F->cull_seen += (unsigned)n;
    F->cull_gone += (unsigned)(n - __builtin_popcount(left));
  }
  FR_COUNT(mft_tri_left, __builtin_popcount(left));
  return left;
}

/* tri_cull for a leaf's triangle, where it pays */
FR_INLINE unsigned leaf_tri_cull(frusta *F, const fr_bvh2_tri *r, unsigned m, const fr_mft_opts *opt,
                                  tri_frusta *X) {
  const int cull = cull_pays(F, opt, __builtin_popcount(m));
  return cull_counted(F, cull, m, tri_cull(F, r, m, cull, X));
}

/* A leaf's triangles seen from the frusta's shared origin: lane k of L
 * holds triangle k's cross products and det (fr_tri_edges16's operations
 * on the same values, so the same bits it gives every frustum) and nrm its
 * normal (fr_bvh2_tri_normal's). One pass for the whole leaf instead of one
 * per triangle, each computing the same value in all 16 lanes. */
typedef struct leaf_edges {
  tri_frusta t; /* e[i][a][k], det[k] */
  float nrm[3][16] __attribute__((aligned(64)));
} leaf_edges;

FR_INLINE void leaf_edges_shared(const frusta *F, const fr_bvh2_tri *r, uint32_t count, leaf_edges *L) {
  /* fields 0-7 and 4-11 of the 12-float records (lanes past count repeat
   * the last triangle): v0, v1, v2 */
  _Static_assert(sizeof(fr_bvh2_tri) == 12 * sizeof(float) && offsetof(fr_bvh2_tri, v2) == 6 * sizeof(float),
                 "records of 12 floats, vertices first");
  vpf lo[8], hi[8];
  vp_load_records8_rows((const float *)r, 12, (int)count, lo);
  vp_load_records8_rows((const float *)r + 4, 12, (int)count, hi);
  unsigned flip[3] = {0, 0, 0};
  for (uint32_t k = 0; k < count; k++)
    for (int i = 0; i < 3; i++) flip[i] |= ((r[k].edge_flip >> i) & 1u) << k;
  vpf V0[3] = {lo[0], lo[1], lo[2]}, V1[3] = {lo[3], lo[4], lo[5]}, V2[3] = {lo[6], lo[7], hi[4]};
  vpf A[3], B[3], C[3], n[3];
  for (int a = 0; a < 3; a++) {
    const vpf o = vp(F->origin[a]);
    A[a] = vp_sub(V0[a], o); B[a] = vp_sub(V1[a], o); C[a] = vp_sub(V2[a], o);
  }
  { /* fr_bvh2_tri_normal, lane by lane in a loop the compiler vectorizes */
    float V[9][FR_PACKET] __attribute__((aligned(64)));
    for (int a = 0; a < 3; a++) { vp_store(V[a], V0[a]); vp_store(V[3 + a], V1[a]); vp_store(V[6 + a], V2[a]); }
    for (int k = 0; k < FR_PACKET; k++)
      fr_tri_normal_lane(V[0][k], V[1][k], V[2][k], V[3][k], V[4][k], V[5][k], V[6][k], V[7][k], V[8][k], &L->nrm[0][k],
                         &L->nrm[1][k], &L->nrm[2][k]);
    for (int a = 0; a < 3; a++) n[a] = vp_load(L->nrm[a]);
  }
  vp_store(L->t.det, fr_dot3v(A[0], A[1], A[2], n[0], n[1], n[2]));
  const vpf *ends[3][2] = {{V1, V2}, {V2, V0}, {V0, V1}};
  const vpf *from[3][2] = {{B, C}, {C, A}, {A, B}};
  for (int i = 0; i < 3; i++) {
    const vpm fl = vpm_bits_to(flip[i]);
    vpf d[3], po[3], c[3];
    for (int a = 0; a < 3; a++) { /* fr_tri_edges16's edge from its smaller vertex p to q, lane by lane */
      const vpf p = vp_select(fl, ends[i][1][a], ends[i][0][a]);
      d[a] = vp_sub(vp_select(fl, ends[i][0][a], ends[i][1][a]), p);
      po[a] = vp_select(fl, from[i][1][a], from[i][0][a]);
    }
    fr_cross3v(po, d, c);
    const vpf sg = vp_select(fl, vp(-0.0f), vp(0.0f));
    for (int a = 0; a < 3; a++) vp_store(L->t.e[i][a], vp_xor(c[a], sg));
  }
}

/* leaf_tri_cull for triangle k of a leaf_edges_shared leaf; n gets its normal */
FR_INLINE unsigned leaf_tri_cull_shared(frusta *F, const leaf_edges *L, uint32_t k, unsigned m,
                                         const fr_mft_opts *opt, float n[3]) {
  for (int a = 0; a < 3; a++) n[a] = L->nrm[a][k];
  const int cull = cull_pays(F, opt, __builtin_popcount(m));
  unsigned left = m;
  if (cull) {
    vpf E[3][3];
    for (int i = 0; i < 3; i++)
      for (int a = 0; a < 3; a++) E[i][a] = vp(L->t.e[i][a][k]);
    left = corner_cull(F, E, vp(L->t.det[k]), n, m);
  }
  return cull_counted(F, cull, m, left);
}

/* A leaf's per-triangle scratch: the cross products for every frustum, or
 * once for a shared origin. */
typedef struct leaf_scratch {
  tri_frusta X[FR_BVH2_MAX_LEAF];
  leaf_edges L;
  float nk[FR_BVH2_MAX_LEAF][3];
} leaf_scratch;

/* What a leaf's culls leave for the ray tests: triangle k's frusta, where
 * frustum f finds its cross products and det (edges[k] + step * f) and its
 * normal. */
typedef struct leaf_tris {
  unsigned left[FR_BVH2_MAX_LEAF];
  const float *edges[FR_BVH2_MAX_LEAF], *nrm[FR_BVH2_MAX_LEAF];
  int step;
} leaf_tris;

/* Every triangle's cull (first, count) against the frusta m; returns the
 * frusta any triangle is left to. */
FR_INLINE unsigned leaf_culls(frusta *F, const fr_bvh2 *b, uint32_t first, uint32_t count, unsigned m,
                              const fr_mft_opts *opt, leaf_scratch *S, leaf_tris *T) {
  unsigned any = 0;
  if (F->shared_origin && count) { /* leaf_edges_shared repeats row count - 1 */
    leaf_edges_shared(F, &b->tris[first], count, &S->L);
    for (uint32_t k = 0; k < count; k++) {
      any |= T->left[k] = leaf_tri_cull_shared(F, &S->L, k, m, opt, S->nk[k]);
      T->edges[k] = &S->L.t.e[0][0][k];
      T->nrm[k] = S->nk[k];
    }
    T->step = 0;
    return any;
  }
  for (uint32_t k = 0; k < count; k++) {
    any |= T->left[k] = leaf_tri_cull(F, &b->tris[first + k], m, opt, &S->X[k]);
    T->edges[k] = &S->X[k].e[0][0][0];
    T->nrm[k] = S->X[k].n;
  }
  T->step = 1;
  return any;
}

/* Frustum f's 16 ray directions, made from its start vector and deltas. */
typedef struct frustum_dirs { vpf x, y, z; } frustum_dirs;
FR_INLINE frustum_dirs dirs_of(const frusta *F, int f) {
  const fr_mft_set *S = F->set[f];
  frustum_dirs d = {vp_add(vp(F->s[0][f]), vp_load(S->dx)), vp_add(vp(F->s[1][f]), vp_load(S->dy)),
                    vp_add(vp(F->s[2][f]), vp_load(S->dz))};
  return d;
}

/* Frustum f's 16 rays (directions D) against a triangle, its edges and det
 * as seen from f's origin at e (a lane of a tri_frusta) and its normal n:
 * the rays of `rays` that hit it in (tnear, tcur), *t their distances and w
 * the edge values. No branches: where a triangle covers a few of a frustum's rays,
 * whether any of them hits is a coin toss, and early exits after the edge
 * test mispredicted on about half the tests. */
FR_INLINE unsigned ray_hits(const frusta *F, const frustum_dirs *D, const float *e, const float n[3], int f, vpf tcur,
                            unsigned rays, vpf w[3], vpf *t) {
  const vpf dx = D->x, dy = D->y, dz = D->z;
  vpf E[3][3];
  for (int i = 0; i < 3; i++)
    for (int a = 0; a < 3; a++) E[i][a] = vp(e[16 * (3 * i + a)]);
  const vpf det = vp(e[16 * 9]);
  unsigned m = fr_tri_edges16_inside(dx, dy, dz, E, det, rays, w);
  *t = vp_div(det, dot3(dx, dy, dz, vp(n[0]), vp(n[1]), vp(n[2])));
  return m & vpm_bits(vpm_and(vp_gt(*t, vp(F->tnear[f])), vp_lt(*t, tcur)));
}

/* A closest-hit frustum's answers in registers (prim as float bit
 * patterns). u and v hold the edge values w1 and w2, and ws their sum with
 * w0: the barycentrics w1 / ws and w2 / ws are made once at the end of the
 * batch (one division per ray instead of one per ray test; the same
 * operations, so the same bits). */
typedef struct frustum_hits { vpf t, u, v, ws, prim; } frustum_hits;

/* ray_hits for closest hits: the rays hit take the triangle's t, edge
 * values and id in h. */
FR_INLINE unsigned ray_test_closest(const frusta *F, const frustum_dirs *D, const float *e, const float n[3],
                                    const fr_bvh2_tri *r, int f, unsigned rays, frustum_hits *h) {
  vpf w[3], t;
  const unsigned m = ray_hits(F, D, e, n, f, h->t, rays, w, &t);
  const vpm hm = vpm_bits_to(m);
  h->t = vp_select(hm, t, h->t);
  h->u = vp_select(hm, w[1], h->u);
  h->v = vp_select(hm, w[2], h->v);
  h->ws = vp_select(hm, vp_add(vp_add(w[0], w[1]), w[2]), h->ws);
  h->prim = vp_select(hm, vp_id(r->prim), h->prim);
  return m;
}

/* The rays of frustum f (among `rays`) whose slab test reaches box k of node
 * n before tcur (the single-ray kernels' test, on rays made on demand): a
 * frustum often spans a leaf box its rays all pass by. */
FR_INLINE unsigned leaf_box_rays(frusta *F, const fr_bvh2_node *n, int k, int f, vpf tcur, unsigned rays) {
  if (!((F->rd_ready >> f) & 1)) {
    const fr_mft_set *S = F->set[f];
    const float *dl[3] = {S->dx, S->dy, S->dz};
    vpf tiny = vp(TINY);
    for (int a = 0; a < 3; a++) {
      vpf d = vp_add(vp(F->s[a][f]), vp_load(dl[a]));
      d = vp_select(vp_lt(vp_abs(d), tiny), vp_copysign(tiny, d), d);
      vp_store(F->rd[f][a], vp_div(vp(1.0f), d));
    }
    F->rd_ready |= 1u << f;
  }
  const float *lo[3] = {n->lo_x, n->lo_y, n->lo_z}, *hi[3] = {n->hi_x, n->hi_y, n->hi_z};
  vpf tn = vp(F->tnear[f]), tf = tcur;
  for (int a = 0; a < 3; a++) {
    vpf rd = vp_load(F->rd[f][a]);
    vpf t0 = vp_mul(vp(lo[a][k] - F->o[a][f]), rd), t1 = vp_mul(vp(hi[a][k] - F->o[a][f]), rd);
    tn = vp_max(tn, vp_min(t0, t1));
    tf = vp_min(tf, vp_max(t0, t1));
  }
  return rays & vpm_bits(vp_le(tn, vp_mul(tf, vp(ROUND_UP))));
}

/* a subtree and the frusta that enter it; leaves keep their box's node and slot */
typedef struct entry { uint32_t ref; unsigned mask; const fr_bvh2_node *parent; int slot; } entry;

/* Entering leaf e: rays[f] gets the rays of frustum f (among base[f]) whose
 * own box test reaches the leaf before tcur[f] (per ray; NULL: the frustum's
 * tfar); returns the frusta of m left with any. */
FR_INLINE unsigned leaf_rays(frusta *F, const entry *e, unsigned m, const unsigned *base, const float (*tcur)[16],
                             unsigned rays[16]) {
  for (unsigned g = m; g; g &= g - 1) {
    int f = __builtin_ctz(g);
    /* no parent: the root is a leaf, with no box to test */
    rays[f] = e->parent ? leaf_box_rays(F, e->parent, e->slot, f, tcur ? vp_load(tcur[f]) : vp(F->tfar[f]), base[f])
                        : base[f];
    /* whether any ray of the frustum reaches the leaf is a coin toss too:
     * no branch */
    m &= ~((unsigned)(rays[f] == 0) << f);
  }
  return m;
}

/* A node visit starts loading what its hit children will read: their
 * nodes, or the first MFT_PREFETCH_TRIS lines of their triangles (camera
 * leaves hold at most 8). Unlike the BVHN kernels' prefetch it is on for
 * every tree: it pays where leaves miss the cache (dragon) and costs
 * nothing elsewhere. 0 turns it off, for measurement. */
#ifndef MFT_PREFETCH_TRIS
#define MFT_PREFETCH_TRIS 8
#endif

/* Both children of a node; pushes the farther, returns the nearer in *next. */
FR_INLINE int visit_node(const frusta *F, const fr_bvh2 *b, uint32_t ref, unsigned m, entry *stack, int *sp,
                         entry *next) {
  const fr_bvh2_node *n = &b->nodes[ref];
  FR_COUNT(mft_nodes, 1);
  FR_COUNT(mft_box_tests, 2);
  FR_COUNT(mft_box_lanes, 2 * __builtin_popcount(m));
  vpf tn0, tn1;
  unsigned h0 = box_test(F, n, 0, m, &tn0), h1 = box_test(F, n, 1, m, &tn1);
  if (h0 && MFT_PREFETCH_TRIS > 0) fr_bvh2_prefetch(b, n->child[0], MFT_PREFETCH_TRIS);
  if (h1 && MFT_PREFETCH_TRIS > 0) fr_bvh2_prefetch(b, n->child[1], MFT_PREFETCH_TRIS);
  /* nearer first: the child more of the frusta in both enter first. No
   * branch on which children were hit: the far one is always written and
   * pushed only when both were */
  const int two = (h0 != 0) & (h1 != 0);
  const unsigned both = h0 & h1;
  const int first0 = __builtin_popcount(both & vpm_bits(vp_le(tn0, tn1))) * 2 >= __builtin_popcount(both);
  const int near1 = two ? !first0 : h0 == 0;
  stack[*sp] = (entry){n->child[!near1], near1 ? h0 : h1, n, !near1};
  *sp += two;
  *next = (entry){n->child[near1], near1 ? h1 : h0, n, near1};
  return (h0 | h1) != 0;
}

/* The frusta in `shrink` shrink their bounds to their rays still active
 * (the paper's "CR"), all at once. */
FR_INLINE void shrink_to_active(frusta *F, const fr_mft_opts *opt, const fr_mft_sets *T, unsigned shrink,
                              const unsigned active[16]) {
  ray_box R;
  memset(&R, 0, sizeof R);
  const int intervals = opt->shrink == FR_MFT_SHRINK_ALL;
  for (unsigned l = shrink; l; l &= l - 1) ray_box_of(F, __builtin_ctz(l), active[__builtin_ctz(l)], &R, intervals);
  frusta_bounds(F, T, shrink, &R, intervals);
}

/* A shadow leaf's triangles (leaf reference ref) against the frusta m,
 * rays[f] the rays of frustum f among active[f] that may reach it: the
 * rays they hit join occ[f] and leave active[f], frusta left with none
 * leave *alive. Returns how many rays the leaf occluded.
 *
 * As the closest-hit kernel: every triangle's cull first, then frustum by
 * frustum its triangles, its directions in registers across the leaf.
 * Occlusion does not depend on the order.
 * Shrinking waits for the end of the leaf, so the leaf's later culls use
 * the bounds it started with: still conservative, and shadow leaves hold at
 * most four triangles. */
FR_INLINE unsigned occlude_leaf(frusta *F, const fr_bvh2 *b, const fr_mft_opts *opt, const fr_mft_sets *T,
                                uint32_t ref, unsigned m, const unsigned rays[16], unsigned active[16],
                                uint16_t occ[16], unsigned *alive, int eager) {
  const uint32_t first = FR_BVH2_LEAF_FIRST(ref), count = FR_BVH2_LEAF_COUNT(ref);
  leaf_scratch S;
  leaf_tris L;
  unsigned any = leaf_culls(F, b, first, count, m, opt, &S, &L), shrink = 0, occluded = 0;
  for (; any; any &= any - 1) {
    const int f = __builtin_ctz(any);
    const frustum_dirs D = dirs_of(F, f);
    const vpf tf = vp(F->tfar[f]);
    unsigned live = rays[f] & active[f], hits = 0;
    /* no branch on the hits, for the same reason as ray_hits */
    for (uint32_t k = 0; k < count; k++) {
      vpf w[3], t;
      const unsigned hit = (L.left[k] >> f) & 1 ? ray_hits(F, &D, L.edges[k] + L.step * f, L.nrm[k], f, tf, live, w, &t) : 0u;
      hits |= hit;
      live &= ~hit;
    }
    const unsigned bit = 1u << f;
    occ[f] |= (uint16_t)hits;
    active[f] &= ~hits;
    occluded += (unsigned)__builtin_popcount(hits);
    const unsigned done = active[f] ? 0u : bit;
    *alive &= ~done;
    shrink |= hits && !done && eager ? bit : 0u;
  }
  /* the frusta whose rays this leaf occluded some of shrink, all at once */
  if (shrink) shrink_to_active(F, opt, T, shrink, active);
  return occluded;
}

#endif
