/*
 * Packet traversal (Benthin, Wald, Woop, Ernst, Mark: "Combining Single and
 * Packet Ray Tracing ... on the Intel MIC Architecture", §V): P = 8 or 16 rays,
 * one per SIMD lane, traverse an N-wide BVH together. Per node:
 *
 *   1. when all rays share a direction octant, interval arithmetic over the
 *      whole packet (Boulos, Wald, Shirley §3.1) culls the children no ray
 *      can hit, all N at once; the survivors are pushed nearest last by that
 *      bound, and each is tested against the P rays (one SIMD test) only
 *      when popped;
 *   2. otherwise each child is tested against the P rays at once and those
 *      hit are pushed with their ray mask and per-ray entry distances.
 *
 * Leaves test their triangles one at a time against all P rays with
 * Shevtsov's test on the precomputed 48-byte record (geom/tri_shevtsov.h),
 * with its axis-aligned fast path, after an inverse mailbox check; a leaf
 * reached by only a few active rays tests them four at a time against its
 * four-triangle blocks instead (quad leaves, trace/tri4_quad.h).
 *
 * The hybrid: on each pop, if at most hybrid_threshold rays are still active
 * in the popped subtree, they finish it one by one with the single-ray kernel
 * of the same ISA and width, and the packet goes on with the next pop. A
 * packet whose rays share a direction octant uses uniform_threshold instead:
 * its few remaining rays still visit nearly the same nodes, and the MIC
 * paper's 7 left such packets 3-10% behind plain packets
 * (docs/performance-log.md, "The hybrid's threshold for one-octant
 * packets").
 *
 * Compiled once per ISA, packet size (FR_PACKET) and BVH width (FR_WIDTH).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>
#include "base/simd.h"
#include "base/simd_packet.h"
#include "base/timer.h"
#include "trace/bvhn_node.h"
#include "trace/counters.h"
#include "trace/hybrid_tune.h"
#include "trace/kernels.h"
#include "trace/plane_test.h"
#include "trace/tri4_quad.h"

typedef struct packet {
  float o[3][P] __attribute__((aligned(64)));
  float d[3][P] __attribute__((aligned(64)));
  float rd[3][P] __attribute__((aligned(64)));
  float tnear[P] __attribute__((aligned(64)));
  float tfar[P] __attribute__((aligned(64)));  /* as given */
  /* uniform: every active ray has the same direction sign on each axis, so
   * near and far planes are the same for all (near_off: float offsets of the
   * near planes in a node); then the interval bounds below are finite. */
  int uniform;
  int near_off[3];
  float omin[3], omax[3], rmin[3], rmax[3], tnear_min;
  float ia_near_o[3], ia_far_o[3]; /* see ia_test */
} packet;

/* A packet's rays as loaded, in fr_ray's field order. */
typedef struct rays_in { vpf o[3], tnear, d[3], tfar; } rays_in;

static void load_soa(const fr_ray16 *in, rays_in *r) {
  r->o[0] = vp_loadu(in->org_x); r->o[1] = vp_loadu(in->org_y); r->o[2] = vp_loadu(in->org_z);
  r->d[0] = vp_loadu(in->dir_x); r->d[1] = vp_loadu(in->dir_y); r->d[2] = vp_loadu(in->dir_z);
  r->tnear = vp_loadu(in->tnear); r->tfar = vp_loadu(in->tfar);
}

/* out[i] = stride * idx[i], lanes past n repeating idx[0]: the float offsets
 * of records for vp_gather and vp_scatter. A full packet (the usual case)
 * takes a loop the compiler vectorizes; the one with the lane test did not
 * vectorize and cost 1.7% of a primary tile's instructions (callgrind). */
FR_INLINE void lane_offsets(const uint32_t *idx, int n, int32_t stride, int32_t *out) {
  if (n >= P) {
    for (int i = 0; i < P; i++) out[i] = stride * (int32_t)idx[i];
    return;
  }
  for (int i = 0; i < P; i++) out[i] = stride * (int32_t)idx[i < n ? i : 0];
}

/* Whether idx[0..n) is a full packet of consecutive rays, as a renderer's
 * calls in one octant give: their rays and hits are then whole records in
 * a row, moved by transposes instead of gathers and scatters. */
FR_INLINE int lanes_in_a_row(const uint32_t *idx, int n) {
  if (n < P) return 0;
  int ok = 1;
  for (int i = 0; i < P; i++) ok &= idx[i] == idx[0] + (uint32_t)i;
  return ok;
}

/* rays[idx[0..n)], 1 <= n <= P, gathered straight into registers: copying
 * them lane by lane into an fr_ray16 first cost a store-forwarding stall on
 * every vector load after it. Lanes past n repeat ray idx[0]; returns the
 * mask of the first n. row: lanes_in_a_row(idx, n). */
_Static_assert(sizeof(fr_ray) == 8 * sizeof(float), "fr_ray is gathered as 8 floats");
static unsigned load_aos(const fr_ray *rays, const uint32_t *idx, int n, int row, rays_in *r) {
  const float *f = (const float *)rays;
  if (row) {
    vpf rec[8];
    vp_load_records8(f + 8 * (size_t)idx[0], rec);
    for (int a = 0; a < 3; a++) { r->o[a] = rec[a]; r->d[a] = rec[4 + a]; }
    r->tnear = rec[3];
    r->tfar = rec[7];
    return FR_PACKET_ALL;
  }
  int32_t gi[P] __attribute__((aligned(64)));
  lane_offsets(idx, n, 8, gi);
  for (int a = 0; a < 3; a++) {
    r->o[a] = vp_gather(f + a, gi);
    r->d[a] = vp_gather(f + 4 + a, gi);
  }
  r->tnear = vp_gather(f + 3, gi);
  r->tfar = vp_gather(f + 7, gi);
  return n >= P ? FR_PACKET_ALL : (1u << n) - 1u;
}

/* Returns the valid mask without rays that cannot hit (the conditions of
 * fr_ray_invalid, lane by lane). */
static unsigned packet_setup(packet *pk, unsigned valid, const rays_in *in) {
  const vpf inf = vp(INFINITY), zero = vp(0.0f), tiny = vp(1e-18f);
  vpf tnear = in->tnear, tfar = in->tfar;
  valid &= FR_PACKET_ALL & vpm_bits(vp_le(tnear, tfar));
  unsigned nonzero = 0;
  vpf o[3], d[3];
  for (int a = 0; a < 3; a++) {
    o[a] = in->o[a];
    d[a] = in->d[a];
    valid &= vpm_bits(vpm_and(vp_lt(vp_abs(o[a]), inf), vp_lt(vp_abs(d[a]), inf)));
    nonzero |= ~vpm_bits(vp_eq(d[a], zero));
  }
  valid &= nonzero;
  /* invalid lanes get harmless values: they are masked off everywhere */
  vpm ok = vpm_bits_to(valid);
  for (int a = 0; a < 3; a++) {
    o[a] = vp_select(ok, o[a], zero);
    d[a] = vp_select(ok, d[a], vp(1.0f));
    /* as the single-ray kernel: a zero component would give inf * 0 = NaN */
    vpf dd = vp_select(vp_lt(vp_abs(d[a]), tiny), vp_copysign(tiny, d[a]), d[a]);
    vpf rd = vp_div(vp(1.0f), dd);
    vp_store(pk->o[a], o[a]);
    vp_store(pk->d[a], d[a]);
    vp_store(pk->rd[a], rd);
    pk->omin[a] = vp_reduce_min(vp_select(ok, o[a], inf));
    pk->omax[a] = vp_reduce_max(vp_select(ok, o[a], vp(-INFINITY)));
    pk->rmin[a] = vp_reduce_min(vp_select(ok, rd, inf));
    pk->rmax[a] = vp_reduce_max(vp_select(ok, rd, vp(-INFINITY)));
  }
  tnear = vp_select(ok, tnear, zero);
  vp_store(pk->tnear, tnear);
  vp_store(pk->tfar, vp_select(ok, tfar, zero));
  pk->tnear_min = vp_reduce_min(vp_select(ok, tnear, inf));
  pk->uniform = valid != 0;
  for (int a = 0; a < 3; a++) {
    int pos = pk->rmin[a] > 0.0f, neg = pk->rmax[a] < 0.0f;
    pk->uniform &= pos | neg;
    pk->near_off[a] = pos ? 2 * a * W : (2 * a + 1) * W;
    pk->ia_near_o[a] = pos ? pk->omax[a] : pk->omin[a];
    pk->ia_far_o[a] = pos ? pk->omin[a] : pk->omax[a];
  }
  return valid;
}

/* Step 1: children that no ray of the packet can hit, by interval arithmetic
 * on the origins [omin, omax] and reciprocal directions [rmin, rmax] (uniform
 * packets only). On an axis where every r > 0, (plane - o) * r is smallest
 * for the largest o and largest for the smallest o; where every r < 0 the
 * other way round: so ia_near_o / ia_far_o hold the origin bound that gives
 * the nearest entry and the farthest exit, and two products per plane bound
 * the rest. Each bound is the same rounded operations a ray's own test makes,
 * and rounding is monotonic, so the bounds contain every ray's float
 * distances: the cull is exactly as conservative as the per-ray test.
 * Returns the mask of children that may be hit; lo gets the packet's nearest
 * entry distance into each. */
FR_INLINE int ia_test(const node_t *n, const packet *pk, float tfar_max, float *lo) {
  const float *f = (const float *)n;
  vnode tn = VN(pk->tnear_min), tf = VN(tfar_max);
  for (int a = 0; a < 3; a++) {
    vnode rlo = VN(pk->rmin[a]), rhi = VN(pk->rmax[a]);
    vnode x = VN_SUB(VN_LOAD(f + pk->near_off[a]), VN(pk->ia_near_o[a]));
    vnode y = VN_SUB(VN_LOAD(f + (pk->near_off[a] ^ W)), VN(pk->ia_far_o[a]));
    tn = VN_MAX(tn, VN_MIN(VN_MUL(x, rlo), VN_MUL(x, rhi)));
    tf = VN_MIN(tf, VN_MAX(VN_MUL(y, rlo), VN_MUL(y, rhi)));
  }
  VN_STORE(lo, tn);
  return VN_LE_BITS(tn, VN_MUL(tf, VN(ROUND_UP)));
}

/* The packet's rays in registers. */
typedef struct pregs { vpf o[3], rd[3], tnear; } pregs;

/* Step 2: child c against every ray; the mask of active rays that hit it
 * within [tnear, tfar], entry distances in *tn. Same arithmetic as the
 * single-ray box test, so a ray sees the same boxes in both modes. */
FR_INLINE unsigned child_test(const float *f, int c, const packet *pk, const pregs *R, vpf tfar, unsigned active,
                              vpf *tn_out) {
  FR_COUNT(pk_box_tests, 1);
  FR_COUNT(pk_box_lanes, __builtin_popcount(active));
  vpf tn = R->tnear, tf = tfar;
  if (pk->uniform) {
    for (int a = 0; a < 3; a++) {
      vpf tna = vp_mul(vp_sub(vp(f[pk->near_off[a] + c]), R->o[a]), R->rd[a]);
      vpf tfa = vp_mul(vp_sub(vp(f[(pk->near_off[a] ^ W) + c]), R->o[a]), R->rd[a]);
      tn = vp_max(tn, tna);
      tf = vp_min(tf, tfa);
    }
  } else {
    /* mixed signs: order the two planes per ray (empty slots never get here,
     * their inverted boxes would turn inside out) */
    for (int a = 0; a < 3; a++) {
      vpf t0 = vp_mul(vp_sub(vp(f[2 * a * W + c]), R->o[a]), R->rd[a]);
      vpf t1 = vp_mul(vp_sub(vp(f[(2 * a + 1) * W + c]), R->o[a]), R->rd[a]);
      tn = vp_max(tn, vp_min(t0, t1));
      tf = vp_min(tf, vp_max(t0, t1));
    }
  }
  *tn_out = tn;
  return active & vpm_bits(vp_le(tn, vp_mul(tf, vp(ROUND_UP))));
}

/* Inverse mailboxing (Shevtsov et al.): the packet remembers the last 8
 * triangles it tested, in a ring on its own stack. */
typedef struct mailbox { uint32_t id[8] __attribute__((aligned(32))); unsigned pos; } mailbox;

FR_INLINE int mailbox_seen(mailbox *mb, uint32_t id) {
#if defined(FR_BUILD_ISA_SCALAR)
  for (int i = 0; i < 8; i++)
    if (mb->id[i] == id) return 1;
#else
  __m256i eq = _mm256_cmpeq_epi32(_mm256_load_si256((const __m256i *)mb->id), _mm256_set1_epi32((int)id));
  if (_mm256_movemask_epi8(eq)) return 1;
#endif
  mb->id[mb->pos++ & 7] = id;
  return 0;
}

/* One triangle against the active rays: Shevtsov's test with the division
 * deferred to the hits, lane by lane the same operations as
 * fr_tri_shevtsov_test (a sign flip by xor is the multiply by +-1 there).
 * Returns the rays hit in (tnear, tfar); *t, *u, *v hold their hits. */
FR_INLINE unsigned tri_test(const fr_tri_shevtsov *r, const packet *pk, const pregs *R, vpf tfar, unsigned active,
                            int aa_path, vpf *t_out, vpf *u_out, vpf *v_out) {
  static const int next[3] = {1, 2, 0};
  int k = r->k, ku = next[k], kv = next[ku];
  /* the origins relative to vertex a */
  vpf wk = vp_sub(vp(r->a_k), vp_load(pk->o[k]));
  vpf wu = vp_sub(vp(r->a_u), vp_load(pk->o[ku])), wv = vp_sub(vp(r->a_v), vp_load(pk->o[kv]));
  vpf dk = vp_load(pk->d[k]), du = vp_load(pk->d[ku]), dv = vp_load(pk->d[kv]);
  vpf det, num;
  if (aa_path && r->axis_aligned) {
    det = dk;
    num = wk;
  } else {
    vpf nu = vp(r->n_u), nv = vp(r->n_v);
    det = vp_add(vp_add(dk, vp_mul(nu, du)), vp_mul(nv, dv));
    num = vp_add(vp_add(wk, vp_mul(nu, wu)), vp_mul(nv, wv));
  }
  vpf hu = vp_sub(vp_mul(num, du), vp_mul(wu, det)), hv = vp_sub(vp_mul(num, dv), vp_mul(wv, det));
  vpf bd = vp_add(vp_mul(vp(r->b_u), hu), vp_mul(vp(r->b_v), hv));
  vpf gd = vp_add(vp_mul(vp(r->c_u), hu), vp_mul(vp(r->c_v), hv));
  vpf sg = vp_and(det, vp(-0.0f)), ad = vp_abs(det);
  vpf bs = vp_xor(bd, sg), gs = vp_xor(gd, sg), ns = vp_xor(num, sg);
  vpf zero = vp(0.0f);
  unsigned m = active & vpm_bits(vpm_and(vpm_and(vp_gt(ad, zero), vp_ge(bs, zero)), vp_ge(gs, zero)));
  if (!m) return 0;
  m &= vpm_bits(vpm_and(vpm_and(vp_le(vp_add(bs, gs), ad), vp_gt(ns, vp_mul(R->tnear, ad))), vp_lt(ns, vp_mul(tfar, ad))));
  if (!m) return 0;
  vpf t = vp_div(num, det), inv = vp_div(vp(1.0f), det);
  m &= vpm_bits(vpm_and(vp_gt(t, R->tnear), vp_lt(t, tfar))); /* rounding of the division */
  *t_out = t;
  *u_out = vp_mul(bd, inv);
  *v_out = vp_mul(gd, inv);
  return m;
}

/* A pending subtree. Two kinds: box == NULL, its rays already tested
 * against its box (their entry distances in a parallel array); or box = the
 * parent's node, slot its place there, dist the packet's interval bound: the
 * per-ray test waits until the entry is popped, and is skipped when dist
 * shows that every ray has found something nearer (Embree's coherent
 * traversal works this way too). */
typedef struct stack_entry {
  uint32_t ref;
  unsigned mask;
  int slot;
  float dist;
  const float *box;
} stack_entry;

/* prefetch_ref for the packet kernels: their leaves read the Shevtsov
 * records (48 bytes, four per block), not the blocks. */
FR_INLINE void prefetch_packet_ref(const fr_bvhn *b, uint32_t ref) {
  if (!(ref & FR_BVHN_LEAF)) {
    prefetch_ref(b, ref);
    return;
  }
  const char *p = (const char *)&b->shev[4 * (size_t)FR_BVHN_LEAF_FIRST(ref)];
  __builtin_prefetch(p);
  __builtin_prefetch(p + 64);
  __builtin_prefetch(p + 128);
}

/* Pushes the children in keep for a lazy test: sorted farthest first (closest
 * hit), or in slot order so that the last slot pops first (any hit). */
FR_INLINE int push_lazy(const fr_bvhn *b, stack_entry *stack, int sp, const node_t *n, int keep, unsigned active,
                        const float *lo, int sorted) {
  const float *f = (const float *)n;
  if (b->packet_prefetch)
    for (int m = keep; m; m &= m - 1) prefetch_packet_ref(b, n->child[__builtin_ctz((unsigned)m)]);
  if (!sorted) {
    for (; keep; keep &= keep - 1) {
      int c = __builtin_ctz((unsigned)keep);
      stack[sp++] = (stack_entry){n->child[c], active, c, lo[c], f};
    }
    return sp;
  }
  int base = sp;
  for (; keep; keep &= keep - 1) { /* insertion sort by entry bound, farthest first */
    int c = __builtin_ctz((unsigned)keep);
    stack_entry x = {n->child[c], active, c, lo[c], f};
    int j = sp - 1;
    while (j >= base && stack[j].dist < x.dist) { stack[j + 1] = stack[j]; j--; }
    stack[j + 1] = x;
    sp++;
  }
  return sp;
}

static inline fr_ray lane_ray(const packet *pk, int i, float tfar) {
  fr_ray r = {{pk->o[0][i], pk->o[1][i], pk->o[2][i]}, pk->tnear[i], {pk->d[0][i], pk->d[1][i], pk->d[2][i]}, tfar};
  return r;
}

/* A closest-hit packet's answers in registers (prim as float bit patterns). */
typedef struct hit_regs { vpf t, u, v, prim, ng[3]; } hit_regs;

/* The answers of fr_hit_finish, for all lanes at once: the hit triangles'
 * vertices gathered lane by lane, the double-precision t of
 * fr_tri_refine_lane in one loop the compiler vectorizes, the normal as
 * v3_cross(p1 - p0, p2 - p0) with the same operations. Misses get
 * fr_hit_miss's values. */
static void finish(const fr_bvhn *b, const packet *pk, const uint32_t *best, vpf tfar, vpf U, vpf V, hit_regs *h) {
  enum { REC = sizeof(fr_tri4) / sizeof(float) };
  _Static_assert(offsetof(fr_tri4, prim) == 36 * sizeof(float), "prim follows the vertices");
  int32_t ix[P] __attribute__((aligned(64)));
  unsigned hit = 0;
  for (int i = 0; i < P; i++) {
    int ok = best[i] != FR_INVALID_ID;
    hit |= (unsigned)ok << i;
    ix[i] = ok ? (int32_t)((best[i] >> 2) * REC + (best[i] & 3)) : 0;
  }
  const vpf zero = vp(0.0f);
  h->t = vp(INFINITY); h->u = h->v = zero; h->prim = vp_id(FR_INVALID_ID);
  h->ng[0] = h->ng[1] = h->ng[2] = zero;
  if (!hit) return;
  /* A[3 * vertex + axis]; ix counts floats from b->tris, so it must fit an int32 */
  float A[9][P] __attribute__((aligned(64)));
  vpf prim;
  const float *base = (const float *)b->tris;
  /* A coherent packet's hits lie on a few triangles: each is read once and
   * broadcast to its lanes, the first straight over zeros. Sixteen-lane
   * gathers took a sixth of conference primary packet16's kernel samples
   * here; they stay for packets whose hits spread over more triangles. */
  enum { FINISH_BROADCASTS = 4 };
  unsigned left = hit;
  int gather = 0;
  prim = vp_id(FR_INVALID_ID);
  for (int it = 0; left; it++) {
    const uint32_t id = best[__builtin_ctz(left)];
    unsigned same = 0;
    for (int i = 0; i < P; i++) same |= (unsigned)(best[i] == id) << i;
    same &= left;
    /* a first triangle with under a quarter of the hits, or more than
     * FINISH_BROADCASTS triangles: fine geometry or incoherent rays */
    if (it == FINISH_BROADCASTS || (!it && 4 * __builtin_popcount(same) < __builtin_popcount(hit))) {
      gather = 1;
      break;
    }
    left &= ~same;
    const float *rec = base + (size_t)(id >> 2) * REC + (id & 3);
    const vpm sm = vpm_bits_to(same);
    for (int k = 0; k < 9; k++) vp_store(A[k], vp_select(sm, vp(rec[4 * k]), it ? vp_load(A[k]) : zero));
    prim = vp_select(sm, vp_id(((const uint32_t *)rec)[36]), prim);
  }
  if (gather && b->nblocks <= (size_t)INT32_MAX / REC) {
    for (int k = 0; k < 9; k++) vp_store(A[k], vp_gather(base + 4 * k, ix));
    prim = vp_gather(base + 36, ix);
  } else if (gather) { /* too many blocks for 32-bit indices */
    float pr[P] __attribute__((aligned(64)));
    for (int i = 0; i < P; i++) {
      const float *rec = base + (hit >> i & 1 ? (size_t)(best[i] >> 2) * REC + (best[i] & 3) : 0);
      for (int k = 0; k < 9; k++) A[k][i] = rec[4 * k];
      memcpy(&pr[i], rec + 36, sizeof(float));
    }
    prim = vp_load(pr);
  }
  float TF[P] __attribute__((aligned(64))), T[P] __attribute__((aligned(64)));
  vp_store(TF, tfar);
  for (int i = 0; i < P; i++)
    T[i] = fr_tri_refine_lane(pk->o[0][i], pk->o[1][i], pk->o[2][i], pk->d[0][i], pk->d[1][i], pk->d[2][i], pk->tnear[i],
                              pk->tfar[i], A[0][i], A[1][i], A[2][i], A[3][i], A[4][i], A[5][i], A[6][i], A[7][i],
                              A[8][i], TF[i]);
  vpf e1[3], e2[3];
  for (int k = 0; k < 3; k++) {
    vpf p0 = vp_load(A[k]);
    e1[k] = vp_sub(vp_load(A[3 + k]), p0);
    e2[k] = vp_sub(vp_load(A[6 + k]), p0);
  }
  vpm m = vpm_bits_to(hit);
  h->t = vp_select(m, vp_load(T), h->t);
  h->u = vp_select(m, U, zero);
  h->v = vp_select(m, V, zero);
  h->prim = vp_select(m, prim, h->prim);
  h->ng[0] = vp_select(m, vp_sub(vp_mul(e1[1], e2[2]), vp_mul(e1[2], e2[1])), zero);
  h->ng[1] = vp_select(m, vp_sub(vp_mul(e1[2], e2[0]), vp_mul(e1[0], e2[2])), zero);
  h->ng[2] = vp_select(m, vp_sub(vp_mul(e1[0], e2[1]), vp_mul(e1[1], e2[0])), zero);
}

/* The leaves a packet reaches with only a few active rays: four rays by
 * four triangles a test (trace/tri4_quad.h), rather than one triangle by P
 * rays. Up to QUAD_ANY_MOST rays (of 16) for any hit: against 4, 2 threads,
 * 1024x1024, interleaved, dragon shadow hybrid16 1.011x (3/4 pairs); 16
 * read 0.962x. Closest hits, where each hit costs a store of the packet's
 * answers and a reduction per ray, up to QUAD_CLOSEST_MOST: at 8,
 * conference primary 0.965x and diffuse8 0.977x against none, at 4 within
 * 1.5% of none on conference and kitchen and +1-6% on dragon and hairball
 * (docs/performance-log.md). quad_wanted says whether to, setting q up at the
 * packet's first such leaf; q->ok is -1 until then. */
enum { QUAD_ANY_MOST = 8, QUAD_CLOSEST_MOST = 4 };
FR_INLINE int quad_wanted(const fr_packet_opts *o, int most, quad_rays *q, const packet *pk, unsigned valid,
                          int nactive) {
  if (!o->quad_leaves || nactive > most * P / 16) return 0;
  if (q->ok < 0) quad_setup(q, pk->o, pk->d, valid);
  return q->ok;
}

/* The rays of `active` against leaf ref; returns those occluded. */
static unsigned quad_occluded(const fr_bvhn *b, uint32_t ref, const quad_rays *q, const packet *pk, unsigned active) {
  const fr_tri4 *tr = &b->tris[FR_BVHN_LEAF_FIRST(ref)];
  const uint32_t nb = FR_BVHN_LEAF_BLOCKS(ref);
  unsigned occ = 0;
  while (active) {
    quad_group g;
    active = quad_gather(q, pk->tnear, pk->tfar, active, &g);
    unsigned live = quad_live(&g);
    for (uint32_t k = 0; k < nb && live; k++) {
      FR_COUNT(pk_quad_tests, 1);
      unsigned hit = quad_test(&tr[k], q, &g, live, NULL);
      for (int j = 0; hit; j++, hit >>= 4)
        if (hit & 0xF) {
          occ |= 1u << g.lane[j];
          live &= ~(0xFu << (4 * j));
        }
    }
  }
  return occ;
}

/* The rays of `active` against leaf ref for their closest hits: TF, UU, VV
 * and B (by lane; ids as float bit patterns, written by memcpy so that no
 * access breaks type aliasing) get the new hits, block by block as the
 * single-ray kernel takes them (tri4_nearest: the nearest lane, the first
 * on ties). */
static void quad_closest(const fr_bvhn *b, uint32_t ref, const quad_rays *q, const packet *pk, unsigned active,
                         float *TF, float *UU, float *VV, float *B) {
  const uint32_t first = FR_BVHN_LEAF_FIRST(ref), nb = FR_BVHN_LEAF_BLOCKS(ref);
  while (active) {
    quad_group g;
    active = quad_gather(q, pk->tnear, TF, active, &g);
    const unsigned live = quad_live(&g);
    for (uint32_t k = 0; k < nb; k++) {
      FR_COUNT(pk_quad_tests, 1);
      quad_hit h;
      const unsigned hit = quad_test(&b->tris[first + k], q, &g, live, &h);
      if (!hit) continue;
      float T[P] __attribute__((aligned(64))), E1[P] __attribute__((aligned(64)));
      float E2[P] __attribute__((aligned(64))), INV[P] __attribute__((aligned(64)));
      vp_store(T, h.t); vp_store(E1, h.e1); vp_store(E2, h.e2); vp_store(INV, h.inv);
      for (int j = 0; j < g.n; j++) {
        unsigned m = (hit >> (4 * j)) & 0xFu;
        if (!m) continue;
        int bl = 4 * j + __builtin_ctz(m);
        for (m &= m - 1; m; m &= m - 1) {
          const int i = 4 * j + __builtin_ctz(m);
          if (T[i] < T[bl]) bl = i;
        }
        const int lane = g.lane[j];
        TF[lane] = T[bl];
        UU[lane] = E1[bl] * INV[bl];
        VV[lane] = E2[bl] * INV[bl];
        const uint32_t id = 4 * (first + k) + (uint32_t)(bl & 3);
        memcpy(&B[lane], &id, sizeof id);
        g.tfar = vp_select(vpm_bits_to(0xFu << (4 * j)), vp(T[bl]), g.tfar);
      }
    }
  }
}

/* Per thread and kernel: the hybrid's threshold for packets of several
 * direction octants (trace/hybrid_tune.h). */
static _Thread_local fr_hybrid_tune tune_closest, tune_any;

/* What a packet's timing goes to: the tuner's arm (-1: not tuned) and the
 * packet's rays. */
typedef struct tune_arm { int arm; unsigned rays; } tune_arm;

/* The packet's switch threshold, from the tuner where o->tune asks for it. */
static int packet_threshold(const fr_bvhn *b, const fr_packet_opts *o, const packet *pk, unsigned valid,
                            fr_hybrid_tune *t, tune_arm *ta) {
  if (pk->uniform) return o->uniform_threshold;
  if (!o->tune || !o->hybrid_threshold || !valid) return o->hybrid_threshold;
  int timed;
  const int arm = fr_hybrid_tune_pick(t, b, &timed);
  if (timed) ta->arm = arm, ta->rays = (unsigned)__builtin_popcount(valid);
  return arm ? P : o->hybrid_threshold;
}

static void intersect_walk(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const rays_in *in, hit_regs *out,
                           tune_arm *ta) {
  packet pk;
  valid = packet_setup(&pk, valid, in);
  const int threshold = packet_threshold(b, o, &pk, valid, &tune_closest, ta);
  FR_COUNT(packets, 1);
  FR_COUNT(rays, __builtin_popcount(valid));
  /* Each lane's best triangle (4 * block + lane) as the bits of a float, in
   * a register: a hit updates it with one select instead of a store per lane. */
  vpf best = vp_id(FR_INVALID_ID);
  pregs R;
  for (int a = 0; a < 3; a++) { R.o[a] = vp_load(pk.o[a]); R.rd[a] = vp_load(pk.rd[a]); }
  R.tnear = vp_load(pk.tnear);
  vpf tfar = vp_select(vpm_bits_to(valid), vp_load(pk.tfar), vp(-INFINITY));
  vpf U = vp(0.0f), V = vp(0.0f);
  float tmax = INFINITY;
  int tmax_stale = 1;
  mailbox mb;
  for (int i = 0; i < 8; i++) mb.id[i] = FR_INVALID_ID;
  mb.pos = 0;
  quad_rays quad = {.ok = -1};

  stack_entry stack[STACK_SIZE];
  float stack_tn[STACK_SIZE][P] __attribute__((aligned(64)));
  int sp = 0;
  if (valid) {
    stack[0] = (stack_entry){b->root, valid, 0, 0.0f, NULL};
    vp_store(stack_tn[0], vp(-INFINITY));
    sp = 1;
  }
  while (sp) {
    sp--;
    const stack_entry e = stack[sp];
    const uint32_t ref = e.ref;
    unsigned active;
    if (e.box) {
      if (tmax_stale) { tmax = vp_reduce_max(tfar); tmax_stale = 0; }
      if (e.dist > tmax * ROUND_UP) continue;
      vpf tn;
      active = child_test(e.box, e.slot, &pk, &R, tfar, e.mask, &tn);
    } else {
      active = e.mask & vpm_bits(vp_le(vp_load(stack_tn[sp]), vp_mul(tfar, vp(ROUND_UP))));
    }
    if (!active) continue;
    int nactive = __builtin_popcount(active);
    if (nactive <= threshold && !(ref & FR_BVHN_LEAF)) {
      FR_COUNT(switches, 1);
      FR_COUNT(switch_rays, nactive);
      float TF[P] __attribute__((aligned(64))), UU[P] __attribute__((aligned(64))), VV[P] __attribute__((aligned(64)));
      lane_ids B;
      vp_store(TF, tfar); vp_store(UU, U); vp_store(VV, V); vp_store(B.f, best);
      for (unsigned m = active; m; m &= m - 1) {
        int i = __builtin_ctz(m);
        fr_ray r = lane_ray(&pk, i, TF[i]);
        fr_subtree_hit h;
        if (o->single->intersect_subtree(b, ref, &r, &h)) { TF[i] = h.t; UU[i] = h.u; VV[i] = h.v; B.u[i] = h.id; }
      }
      tfar = vp_load(TF); U = vp_load(UU); V = vp_load(VV); best = vp_load(B.f);
      tmax_stale = 1;
      continue;
    }
    if ((ref & FR_BVHN_LEAF) && quad_wanted(o, QUAD_CLOSEST_MOST, &quad, &pk, valid, nactive)) {
      float TF[P] __attribute__((aligned(64))), UU[P] __attribute__((aligned(64))), VV[P] __attribute__((aligned(64)));
      lane_ids B;
      vp_store(TF, tfar); vp_store(UU, U); vp_store(VV, V); vp_store(B.f, best);
      quad_closest(b, ref, &quad, &pk, active, TF, UU, VV, B.f);
      tfar = vp_load(TF); U = vp_load(UU); V = vp_load(VV); best = vp_load(B.f);
      tmax_stale = 1;
      continue;
    }
    if (ref & FR_BVHN_LEAF) {
      const uint32_t li = FR_BVHN_LEAF_FIRST(ref);
      const fr_tri_shevtsov *rec = &b->shev[4 * (size_t)li];
      const int nrec = 4 * (int)FR_BVHN_LEAF_BLOCKS(ref);
      for (int j = 0; j < nrec && rec[j].prim != FR_INVALID_ID; j++) { /* only the last block has empty lanes */
        if (o->mailbox && mailbox_seen(&mb, rec[j].prim)) { FR_COUNT(mailbox_hits, 1); continue; }
        FR_COUNT(pk_tri_tests, 1);
        FR_COUNT(pk_tri_lanes, nactive);
        vpf t, u, v;
        unsigned hit = tri_test(&rec[j], &pk, &R, tfar, active, o->axis_aligned, &t, &u, &v);
        if (!hit) continue;
        vpm hm = vpm_bits_to(hit);
        tmax_stale = 1;
        tfar = vp_select(hm, t, tfar);
        U = vp_select(hm, u, U);
        V = vp_select(hm, v, V);
        best = vp_select(hm, vp_id(4 * li + (uint32_t)j), best);
        /* finish() reads the hit triangles' vertices: start loading them now */
        const char *blk = (const char *)&b->tris[li + (uint32_t)j / 4];
        __builtin_prefetch(blk);
        __builtin_prefetch(blk + 64);
        __builtin_prefetch(blk + 128);
      }
      continue;
    }
    const node_t *n = (const node_t *)FR_BVHN_NODE_AT(b, ref);
    const float *f = (const float *)n;
    FR_COUNT(pk_nodes, 1);
    int nc = (int)n->nchildren;
    int cand = (1 << nc) - 1;
    if (o->ia_cull && pk.uniform) {
      /* the packet's farthest tfar: over all its rays, recomputed only after
       * hits (looser than a bound over the active rays, but no reduction per
       * node) */
      if (tmax_stale) { tmax = vp_reduce_max(tfar); tmax_stale = 0; }
      float lo[W] __attribute__((aligned(32)));
      int keep = ia_test(n, &pk, tmax, lo) & cand;
      FR_COUNT(ia_culled, __builtin_popcount((unsigned)(cand & ~keep)));
      sp = push_lazy(b, stack, sp, n, keep, active, lo, 1);
      continue;
    }
    /* Mixed direction signs: each child against every ray now; hit
     * children pushed farthest first with their rays' entry distances. */
    int hc[W], nh = 0;
    unsigned hmask[W];
    float key[W];
    float tn_c[W][P] __attribute__((aligned(64)));
    for (; cand; cand &= cand - 1) {
      int c = __builtin_ctz((unsigned)cand);
      vpf tn;
      unsigned hm = child_test(f, c, &pk, &R, tfar, active, &tn);
      if (!hm) continue;
      vp_store(tn_c[nh], tn);
      /* order by the first hitting ray's entry distance: as good as the
       * packet's minimum for coherent packets, without a reduction */
      key[nh] = tn_c[nh][__builtin_ctz(hm)];
      hmask[nh] = hm;
      hc[nh++] = c;
    }
    int order[W];
    for (int a = 0; a < nh; a++) { /* insertion sort by entry distance, farthest first */
      int x = a, bpos = a - 1;
      while (bpos >= 0 && key[order[bpos]] < key[x]) { order[bpos + 1] = order[bpos]; bpos--; }
      order[bpos + 1] = x;
    }
    for (int a = 0; a < nh; a++) {
      int x = order[a];
      if (b->packet_prefetch) prefetch_packet_ref(b, n->child[hc[x]]);
      stack[sp] = (stack_entry){n->child[hc[x]], hmask[x], 0, 0.0f, NULL};
      vp_store(stack_tn[sp], vp_load(tn_c[x]));
      sp++;
    }
  }

  lane_ids B;
  vp_store(B.f, best);
  finish(b, &pk, B.u, tfar, U, V, out);
}

static void intersect_rays(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const rays_in *in, hit_regs *out) {
  tune_arm ta = {-1, 0};
  /* the clock read only before a packet the tuner will time */
  const int due = o->tune && fr_hybrid_tune_due(&tune_closest);
  const uint64_t t0 = due ? fr_cycles() : 0;
  intersect_walk(b, o, valid, in, out, &ta);
  if (due && ta.arm >= 0) fr_hybrid_tune_record(&tune_closest, ta.arm, fr_cycles() - t0, ta.rays);
}

static void intersect_packet(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const fr_ray16 *in,
                             fr_hit16 *out) {
  rays_in r;
  load_soa(in, &r);
  hit_regs h;
  intersect_rays(b, o, valid, &r, &h);
  const unsigned asked = valid & FR_PACKET_ALL;
  vp_store_mask(out->t, asked, h.t); vp_store_mask(out->u, asked, h.u); vp_store_mask(out->v, asked, h.v);
  vp_store_mask((float *)out->prim, asked, h.prim);
  vp_store_mask(out->ng_x, asked, h.ng[0]); vp_store_mask(out->ng_y, asked, h.ng[1]); vp_store_mask(out->ng_z, asked, h.ng[2]);
}

/* rays[idx[0..n)] to hits[idx[0..n)], answers scattered straight from
 * registers (fr_hit as 7 floats). */
_Static_assert(sizeof(fr_hit) == 7 * sizeof(float) && offsetof(fr_hit, prim) == 3 * sizeof(float) &&
                   offsetof(fr_hit, ng) == 4 * sizeof(float), "fr_hit is scattered as 7 floats");
static void intersect_rays_idx(const fr_bvhn *b, const fr_packet_opts *o, const fr_ray *rays, const uint32_t *idx, int n,
                               fr_hit *hits) {
  rays_in r;
  const int row = lanes_in_a_row(idx, n);
  const unsigned asked = load_aos(rays, idx, n, row, &r);
  hit_regs h;
  intersect_rays(b, o, asked, &r, &h);
  float *f = (float *)hits;
  if (row) {
    const vpf rec[7] = {h.t, h.u, h.v, h.prim, h.ng[0], h.ng[1], h.ng[2]};
    vp_store_records(f + 7 * (size_t)idx[0], rec, 7);
    return;
  }
  int32_t si[P] __attribute__((aligned(64)));
  lane_offsets(idx, n, 7, si);
  vp_scatter(f, si, asked, h.t); vp_scatter(f + 1, si, asked, h.u); vp_scatter(f + 2, si, asked, h.v);
  vp_scatter(f + 3, si, asked, h.prim);
  for (int a = 0; a < 3; a++) vp_scatter(f + 4 + a, si, asked, h.ng[a]);
}

/* The rays of valid that a planar occluder of the scene occludes
 * (accel/plane_occluders.h): shadow segments only (finite tfar), each
 * tested only by occluders whose plane it crosses within its range. Rays
 * without an end, hemisphere rays above all, cross most planes and seldom
 * a polygon: testing them cost kitchen ao16 hybrid16 2.3% even with the
 * polygons' boxes first. */
static unsigned planes_occluded(const fr_plane_occluders *planes, const packet *pk, const pregs *R, vpf tfar,
                                unsigned valid) {
  valid &= vpm_bits(vp_lt(tfar, vp(INFINITY)));
  if (!valid) return 0;
  const vpf d[3] = {vp_load(pk->d[0]), vp_load(pk->d[1]), vp_load(pk->d[2])};
  unsigned occ = 0;
  for (size_t i = 0; i < planes->n; i++) {
    const fr_plane_occluder *p = &planes->list[i];
    const vpf c = vp(p->c), side = vp_sub(R->o[p->axis], c);
    const vpf end = vp_sub(vp_add(R->o[p->axis], vp_mul(tfar, d[p->axis])), c);
    if (!(valid & ~occ & vpm_bits(vp_lt(vp_mul(side, end), vp(0.0f))))) continue;
    occ |= valid & fr_plane_hits(p, R->o, d, R->tnear, tfar);
  }
  FR_COUNT(pk_plane_rays, __builtin_popcount(occ));
  return occ;
}

static unsigned occluded_walk(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const rays_in *in,
                              tune_arm *ta) {
  packet pk;
  valid = packet_setup(&pk, valid, in);
  const int threshold = packet_threshold(b, o, &pk, valid, &tune_any, ta);
  FR_COUNT(packets, 1);
  FR_COUNT(rays, __builtin_popcount(valid));
  pregs R;
  for (int a = 0; a < 3; a++) { R.o[a] = vp_load(pk.o[a]); R.rd[a] = vp_load(pk.rd[a]); }
  R.tnear = vp_load(pk.tnear);
  const vpf tfar = vp_load(pk.tfar);
  const float tfar_max = vp_reduce_max(vp_select(vpm_bits_to(valid), tfar, vp(-INFINITY)));
  mailbox mb;
  for (int i = 0; i < 8; i++) mb.id[i] = FR_INVALID_ID;
  mb.pos = 0;

  quad_rays quad = {.ok = -1};

  /* A ray's tfar never shrinks here, so a pushed child needs no distances:
   * its rays hit its box and stay active until occluded. */
  stack_entry stack[STACK_SIZE];
  int sp = 0;
  unsigned occ = valid && b->planes ? planes_occluded(b->planes, &pk, &R, tfar, valid) : 0;
  if (occ == valid) return occ;
  if (valid) stack[sp++] = (stack_entry){b->root, valid, 0, 0.0f, NULL};
  while (sp) {
    sp--;
    const stack_entry e = stack[sp];
    const uint32_t ref = e.ref;
    unsigned active = e.mask & ~occ;
    if (active && e.box) {
      vpf tn;
      active = child_test(e.box, e.slot, &pk, &R, tfar, active, &tn);
    }
    if (!active) continue;
    int nactive = __builtin_popcount(active);
    if (nactive <= threshold && !(ref & FR_BVHN_LEAF)) {
      FR_COUNT(switches, 1);
      FR_COUNT(switch_rays, nactive);
      for (unsigned m = active; m; m &= m - 1) {
        int i = __builtin_ctz(m);
        fr_ray r = lane_ray(&pk, i, pk.tfar[i]);
        if (o->single->occluded_subtree(b, ref, &r)) occ |= 1u << i;
      }
    } else if (ref & FR_BVHN_LEAF) {
      if (quad_wanted(o, QUAD_ANY_MOST, &quad, &pk, valid, nactive)) {
        occ |= quad_occluded(b, ref, &quad, &pk, active);
        goto next;
      }
      const fr_tri_shevtsov *rec = &b->shev[4 * (size_t)FR_BVHN_LEAF_FIRST(ref)];
      const int nrec = 4 * (int)FR_BVHN_LEAF_BLOCKS(ref);
      for (int j = 0; j < nrec && rec[j].prim != FR_INVALID_ID && active; j++) {
        if (o->mailbox && mailbox_seen(&mb, rec[j].prim)) { FR_COUNT(mailbox_hits, 1); continue; }
        FR_COUNT(pk_tri_tests, 1);
        FR_COUNT(pk_tri_lanes, __builtin_popcount(active));
        vpf t, u, v;
        unsigned hit = tri_test(&rec[j], &pk, &R, tfar, active, o->axis_aligned, &t, &u, &v);
        occ |= hit;
        active &= ~hit;
      }
    } else {
      const node_t *n = (const node_t *)FR_BVHN_NODE_AT(b, ref);
      const float *f = (const float *)n;
      FR_COUNT(pk_nodes, 1);
      int cand = (1 << n->nchildren) - 1;
      if (o->ia_cull && pk.uniform) {
        float lo[W] __attribute__((aligned(32)));
        int keep = ia_test(n, &pk, tfar_max, lo) & cand;
        FR_COUNT(ia_culled, __builtin_popcount((unsigned)(cand & ~keep)));
        sp = push_lazy(b, stack, sp, n, keep, active, lo, 0);
        goto next;
      }
      /* slot order, so the last slot pops first (see the single-ray any-hit) */
      for (; cand; cand &= cand - 1) {
        int c = __builtin_ctz((unsigned)cand);
        vpf tn;
        unsigned hm = child_test(f, c, &pk, &R, tfar, active, &tn);
        if (!hm) continue;
        if (b->packet_prefetch) prefetch_packet_ref(b, n->child[c]);
        stack[sp++] = (stack_entry){n->child[c], hm, 0, 0.0f, NULL};
      }
    }
  next:
    if (occ == valid) break;
  }
  return occ;
}

static unsigned occluded_rays(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const rays_in *in) {
  tune_arm ta = {-1, 0};
  const int due = o->tune && fr_hybrid_tune_due(&tune_any);
  const uint64_t t0 = due ? fr_cycles() : 0;
  const unsigned occ = occluded_walk(b, o, valid, in, &ta);
  if (due && ta.arm >= 0) fr_hybrid_tune_record(&tune_any, ta.arm, fr_cycles() - t0, ta.rays);
  return occ;
}

static unsigned occluded_packet(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const fr_ray16 *in) {
  rays_in r;
  load_soa(in, &r);
  return occluded_rays(b, o, valid, &r);
}

static unsigned occluded_rays_idx(const fr_bvhn *b, const fr_packet_opts *o, const fr_ray *rays, const uint32_t *idx,
                                  int n) {
  rays_in r;
  unsigned valid = load_aos(rays, idx, n, lanes_in_a_row(idx, n), &r);
  return occluded_rays(b, o, valid, &r);
}

#define PK_NAME3(p, w, isa) fr_packet_p##p##_w##w##_##isa
#define PK_NAME(p, w, isa) PK_NAME3(p, w, isa)
const fr_packet_fns PK_NAME(FR_PACKET, FR_WIDTH, FR_ISA_SUFFIX) = {intersect_packet, occluded_packet, intersect_rays_idx,
                                                       occluded_rays_idx};
