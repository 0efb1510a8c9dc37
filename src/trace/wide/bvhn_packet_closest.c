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
 * its few remaining rays still visit nearly the same nodes, where the MIC
 * paper's 7 left such packets behind plain packets.
 *
 * Compiled once per ISA, packet size (FR_PACKET) and BVH width (FR_WIDTH).
 */
#include "trace/wide/packet_common.h"

/* The answers of fr_hit_finish, for all lanes at once: the hit triangles'
 * vertices gathered lane by lane, the double-precision t of
 * fr_tri_refine_lane in one loop the compiler vectorizes, the normal as
 * v3_cross(p1 - p0, p2 - p0) with the same operations. Misses get
 * fr_hit_miss's values. */
static inline void fr_cross3(const vpf a[3], const vpf b[3], vpf c[3]) {
  c[0] = vp_sub(vp_mul(a[1], b[2]), vp_mul(a[2], b[1]));
  c[1] = vp_sub(vp_mul(a[2], b[0]), vp_mul(a[0], b[2]));
  c[2] = vp_sub(vp_mul(a[0], b[1]), vp_mul(a[1], b[0]));
}
static inline vpf fr_dot3(const vpf a[3], const vpf b[3]) {
  return vp_add(vp_add(vp_mul(a[0], b[0]), vp_mul(a[1], b[1])), vp_mul(a[2], b[2]));
}

static void finish(const fr_bvhn *b, const packet *pk, const uint32_t *best, vpf tfar, hit_regs *h) {
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
  vpf e1[3], e2[3], w[3];
  const vpf t = vp_load(T);
  for (int k = 0; k < 3; k++) {
    vpf p0 = vp_load(A[k]);
    e1[k] = vp_sub(vp_load(A[3 + k]), p0);
    e2[k] = vp_sub(vp_load(A[6 + k]), p0);
    w[k] = vp_add(vp_sub(vp_load(pk->o[k]), p0), vp_mul(t, vp_load(pk->d[k]))); /* the hit point, less p0 */
  }
  vpf n[3], c[3];
  fr_cross3(e1, e2, n);
  /* u and v of the hit point itself, w = u e1 + v e2 (w x e2 = u n, e1 x w
   * = v n), clamped into the triangle: they depend on the ray and the
   * triangle only, not on whether the packet or the single-ray phase found
   * it, so the hybrid's tuning never shows in an answer */
  const vpf inn = vp_div(vp(1.0f), fr_dot3(n, n));
  fr_cross3(w, e2, c);
  vpf u = vp_max(vp_mul(fr_dot3(n, c), inn), zero);
  fr_cross3(e1, w, c);
  vpf v = vp_max(vp_mul(fr_dot3(n, c), inn), zero);
  const vpf sum = vp_max(vp_add(u, v), vp(1.0f));
  vpm m = vpm_bits_to(hit);
  h->t = vp_select(m, t, h->t);
  h->u = vp_select(m, vp_div(u, sum), zero);
  h->v = vp_select(m, vp_div(v, sum), zero);
  h->prim = vp_select(m, vp_and(prim, vp_id(~FR_TRI4_THIN)), h->prim); /* the ids without the thin flag */
  for (int k = 0; k < 3; k++) h->ng[k] = vp_select(m, n[k], zero);
}

/* The rays of `active` against leaf ref for their closest hits: TF and B
 * (by lane; ids as float bit patterns, written by memcpy so that no
 * access breaks type aliasing) get the new hits, block by block as the
 * single-ray kernel takes them (tri4_nearest: the nearest lane, the first
 * on ties). */
static void quad_closest(const fr_bvhn *b, uint32_t ref, const quad_rays *q, const packet *pk, unsigned active,
                         float *TF, float *B) {
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
      float T[P] __attribute__((aligned(64)));
      vp_store(T, h.t);
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
        const uint32_t id = 4 * (first + k) + (uint32_t)(bl & 3);
        memcpy(&B[lane], &id, sizeof id);
        g.tfar = vp_select(vpm_bits_to(0xFu << (4 * j)), vp(T[bl]), g.tfar);
      }
    }
  }
}

static void intersect_rays(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const rays_in *in, hit_regs *out) {
  packet pk;
  valid = packet_setup(&pk, valid, in);
  const int threshold = packet_threshold(o, &pk);
  FR_COUNT(packets, 1);
  FR_COUNT(rays, __builtin_popcount(valid));
  /* Each lane's best triangle (4 * block + lane) as the bits of a float, in
   * a register: a hit updates it with one select instead of a store per lane. */
  vpf best = vp_id(FR_INVALID_ID);
  pregs R;
  for (int a = 0; a < 3; a++) { R.o[a] = vp_load(pk.o[a]); R.rd[a] = vp_load(pk.rd[a]); }
  R.tnear = vp_load(pk.tnear);
  vpf tfar = vp_select(vpm_bits_to(valid), vp_load(pk.tfar), vp(-INFINITY));
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
      float TF[P] __attribute__((aligned(64)));
      lane_ids B;
      vp_store(TF, tfar); vp_store(B.f, best);
      for (unsigned m = active; m; m &= m - 1) {
        int i = __builtin_ctz(m);
        fr_ray r = lane_ray(&pk, i, TF[i]);
        fr_subtree_hit h;
        if (o->single->intersect_subtree(b, ref, &r, &h)) { TF[i] = h.t; B.u[i] = h.id; }
      }
      tfar = vp_load(TF); best = vp_load(B.f);
      tmax_stale = 1;
      continue;
    }
    if ((ref & FR_BVHN_LEAF) && quad_wanted(o, QUAD_CLOSEST_MOST, &quad, &pk, valid, nactive)) {
      float TF[P] __attribute__((aligned(64)));
      lane_ids B;
      vp_store(TF, tfar); vp_store(B.f, best);
      quad_closest(b, ref, &quad, &pk, active, TF, B.f);
      tfar = vp_load(TF); best = vp_load(B.f);
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
  finish(b, &pk, B.u, tfar, out);
}

void PK_FN(intersect_packet)(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const fr_ray16 *in,
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
void PK_FN(intersect_rays_idx)(const fr_bvhn *b, const fr_packet_opts *o, const fr_ray *rays, const uint32_t *idx, int n,
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

