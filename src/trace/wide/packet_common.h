/*
 * What the packet kernels' closest-hit walk (bvhn_packet_closest.c) and
 * any-hit walk (bvhn_packet_any.c) share: the packet and its set-up, the
 * node and triangle tests, the stack, quad leaves and the hybrid's
 * threshold. Included by those two files only, which are compiled once per
 * ISA, packet size (FR_PACKET) and BVH width (FR_WIDTH).
 */
#ifndef FR_TRACE_WIDE_PACKET_COMMON_H
#define FR_TRACE_WIDE_PACKET_COMMON_H
#include <math.h>
#include <stddef.h>
#include <string.h>
#include "base/simd.h"
#include "base/simd_packet.h"
#include "trace/wide/bvhn_node.h"
#include "trace/counters.h"
#include "trace/kernels.h"
#include "trace/plane_test.h"
#include "trace/wide/tri4_quad.h"

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

static inline void load_soa(const fr_ray16 *in, rays_in *r) {
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
static inline unsigned load_aos(const fr_ray *rays, const uint32_t *idx, int n, int row, rays_in *r) {
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
static inline unsigned packet_setup(packet *pk, unsigned valid, const rays_in *in) {
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

/* The leaves a packet reaches with only a few active rays: four rays by
 * four triangles a test (trace/tri4_quad.h), rather than one triangle by P
 * rays. Up to QUAD_ANY_MOST rays (of 16) for any hit; for closest hits, where
 * each hit costs a store of the packet's answers and a reduction per ray,
 * up to QUAD_CLOSEST_MOST (8 would lose on coherent rays). quad_wanted says
 * whether to, setting q up at the packet's first such leaf; q->ok is -1
 * until then. */
enum { QUAD_ANY_MOST = 8, QUAD_CLOSEST_MOST = 4 };
FR_INLINE int quad_wanted(const fr_packet_opts *o, int most, quad_rays *q, const packet *pk, unsigned valid,
                          int nactive) {
  if (!o->quad_leaves || nactive > most * P / 16) return 0;
  if (q->ok < 0) quad_setup(q, pk->o, pk->d, valid);
  return q->ok;
}


/* The packet's switch threshold: fixed per kind of packet, so that which
 * phase finds a ray's hit, and so which of two triangles at one t it
 * reports, depends on the packet's rays alone, never on what the thread
 * traced before. */
FR_INLINE int packet_threshold(const fr_packet_opts *o, const packet *pk) {
  return pk->uniform ? o->uniform_threshold : o->hybrid_threshold;
}


/* The kernels' exported symbols: fr_packet_p<P>_w<N>_<isa>[_name]. */
#define PK_CAT(p, w, isa, n) fr_packet_p##p##_w##w##_##isa##n
#define PK_SYM(p, w, isa, n) PK_CAT(p, w, isa, n)
#define PK_FN(n) PK_SYM(FR_PACKET, FR_WIDTH, FR_ISA_SUFFIX, _##n)
#define PK_TABLE PK_SYM(FR_PACKET, FR_WIDTH, FR_ISA_SUFFIX, )

void PK_FN(intersect_packet)(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const fr_ray16 *in,
                             fr_hit16 *out);
void PK_FN(intersect_rays_idx)(const fr_bvhn *b, const fr_packet_opts *o, const fr_ray *rays, const uint32_t *idx,
                               int n, fr_hit *hits);
#endif
