/*
 * The packet kernels' any-hit walk (see bvhn_packet_closest.c for the
 * traversal): a packet ends when every ray is occluded; shadow segments
 * test the scene's planar occluders first. Compiled once per ISA, packet
 * size (FR_PACKET) and BVH width (FR_WIDTH).
 */
#include "trace/wide/packet_common.h"

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

static unsigned occluded_rays(const fr_bvhn *b, const fr_packet_opts *o, unsigned valid, const rays_in *in) {
  packet pk;
  valid = packet_setup(&pk, valid, in);
  const int threshold = packet_threshold(o, &pk);
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
  uint32_t leaves = 0, sparse_leaves = 0;
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
      leaves++;
      sparse_leaves += nactive <= P / 2;
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
  if (o->use) {
    o->use->leaves += leaves;
    o->use->sparse_leaves += sparse_leaves;
  }
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


const fr_packet_fns PK_TABLE = {PK_FN(intersect_packet), occluded_packet, PK_FN(intersect_rays_idx), occluded_rays_idx};
