/*
 * Multi-frusta closest-hit walk (camera frusta), and the kernel table of
 * this ISA. Compiled once per ISA.
 */
#include "trace/mft/frusta_common.h"

static unsigned intersect_mft(const fr_bvh2 *b, const fr_mft_opts *opt, const fr_mft_batch *B, const fr_mft_sets *T,
                              fr_mft_hits *H) {
  frusta F;
  leaf_scratch S;
  leaf_tris L;
  float ws[16][16] __attribute__((aligned(64))); /* the hits' edge value sums (frustum_hits) */
  unsigned valid = B->valid & 0xFFFFu;
  /* t starts at tfar: a hit must come nearer (reset to +inf for misses at the end) */
  for (int f = 0; f < 16; f++)
    for (int k = 0; k < 16; k++) {
      H->t[f][k] = (valid >> f) & 1 ? B->tfar[f] : INFINITY;
      H->u[f][k] = H->v[f][k] = 0.0f;
      ws[f][k] = 1.0f;
      H->prim[f][k] = FR_INVALID_ID;
    }
  FR_COUNT(mft_batches, 1);
  FR_COUNT(rays, 16 * __builtin_popcount(valid));
  if (!valid || !b->nodes) return 0;
  frusta_setup(&F, B, T, valid);
  unsigned fetched = 0, found = 0;
  entry stack[STACK];
  int sp = 0;
  stack[sp++] = (entry){b->root, valid, NULL, 0};
  while (sp) {
    entry e = stack[--sp];
    while (e.mask) {
      if (!(e.ref & FR_BVH2_LEAF)) {
        if (!visit_node(&F, b, e.ref, e.mask, stack, &sp, &e)) break;
        continue;
      }
      uint32_t first = FR_BVH2_LEAF_FIRST(e.ref), count = FR_BVH2_LEAF_COUNT(e.ref);
      static const unsigned all[16] = {0xFFFFu, 0xFFFFu, 0xFFFFu, 0xFFFFu, 0xFFFFu, 0xFFFFu, 0xFFFFu, 0xFFFFu,
                                       0xFFFFu, 0xFFFFu, 0xFFFFu, 0xFFFFu, 0xFFFFu, 0xFFFFu, 0xFFFFu, 0xFFFFu};
      unsigned changed = 0, rays[16], m = leaf_rays(&F, &e, e.mask, all, (const float(*)[16])H->t, rays);
      if (!m) break;
      fetched += count;
      /* First every triangle's cull, then frustum by frustum the triangles
       * left to it, in leaf order (so each ray meets its triangles in the
       * same order as triangle by triangle, and keeps the same nearest
       * hit): a frustum's directions and nearest hits stay in registers
       * across the leaf instead of being made and reloaded per test. */
      unsigned any = leaf_culls(&F, b, first, count, m, opt, &S, &L);
      for (; any; any &= any - 1) {
        const int f = __builtin_ctz(any);
        const frustum_dirs D = dirs_of(&F, f);
        lane_ids ids;
        memcpy(ids.u, H->prim[f], sizeof ids.u);
        frustum_hits h = {vp_load(H->t[f]), vp_load(H->u[f]), vp_load(H->v[f]), vp_load(ws[f]), vp_load(ids.f)};
        unsigned hits = 0;
        for (uint32_t k = 0; k < count; k++)
          if ((L.left[k] >> f) & 1)
            hits |= ray_test_closest(&F, &D, L.edges[k] + L.step * f, L.nrm[k], &b->tris[first + k], f, rays[f], &h);
        if (hits) {
          vp_store(H->t[f], h.t);
          vp_store(H->u[f], h.u);
          vp_store(H->v[f], h.v);
          vp_store(ws[f], h.ws);
          vp_store(ids.f, h.prim);
          memcpy(H->prim[f], ids.u, sizeof ids.u);
          changed |= 1u << f;
        }
      }
      found |= changed;
      /* the frusta with hits now end at their farthest ray's hit (open until all rays hit) */
      for (; changed; changed &= changed - 1) {
        int f = __builtin_ctz(changed);
        F.tfar[f] = vp_reduce_max(vp_load(H->t[f]));
      }
      break;
    }
  }
  for (; found; found &= found - 1) { /* misses keep 0 = 0 * (1 / 1) */
    const int f = __builtin_ctz(found);
    const vpf inv = vp_div(vp(1.0f), vp_load(ws[f]));
    vp_store(H->u[f], vp_mul(vp_load(H->u[f]), inv));
    vp_store(H->v[f], vp_mul(vp_load(H->v[f]), inv));
  }
  for (int f = 0; f < 16; f++)
    for (int k = 0; k < 16; k++)
      if (H->prim[f][k] == FR_INVALID_ID) H->t[f][k] = INFINITY;
  return fetched;
}


const fr_mft_fns FR_ISA_FN(fr_mft) = {FR_ISA_FN(fr_mft_occluded), intersect_mft, FR_ISA_FN(fr_mft_expand),
                                   FR_ISA_FN(fr_mft_from_rays), FR_ISA_FN(fr_mft_expand_arrays),
                                   FR_ISA_FN(fr_mft_rays_to_points), FR_ISA_FN(fr_mft_from_points)};
