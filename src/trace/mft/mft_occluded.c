/*
 * Multi-frusta any-hit walk (shadow frusta): frusta end when all their rays
 * are occluded, test the scene's planar occluders and a batch's cached
 * occluder leaves first, and stop early within a budget. Compiled once per
 * ISA.
 */
#include "trace/mft/frusta_common.h"

/* The scene's planar occluders (accel/plane_occluders.h) against the
 * frusta in *alive, before any traversal: a ray crossing one inside, by
 * margins far above the rounding of this test and of the triangle tests, is
 * occluded by one of its triangles, so it joins occ[f] as its traversal
 * would have made it. A frustum whose corner rays do not all cross the
 * plane is passed by (its rays are left to the traversal). Only the
 * occluders of bit mask `which` are tested (those past the 32nd always):
 * a shaft around the batch tells which it may cross (fr_mft_shaft_planes_off).
 * Returns the rays occluded. */
static unsigned occlude_planes(frusta *F, const fr_plane_occluders *planes, uint32_t which, const fr_mft_opts *opt,
                               const fr_mft_sets *T, unsigned active[16], uint16_t occ[16], unsigned *alive) {
  unsigned shrink = 0, occluded = 0;
  const vpf zero = vp(0.0f), tf16 = vp_load(F->tfar);
  for (size_t i = 0; i < planes->n && *alive; i++) {
    if (i < 32 && !((which >> i) & 1u)) continue;
    const fr_plane_occluder *p = &planes->list[i];
    const int a = p->axis, u = (a + 1) % 3, v = (a + 2) % 3;
    /* All frusta at once (one by one this cost Whitted's thin point-light
     * frusta 3% on kitchen): those whose four corner rays cross the plane
     * within their range, and whose corner rays' crossings span a box that
     * meets the polygon's. Only a filter: a frustum passed by is traced. */
    const vpf c = vp(p->c), oa = vp_load(F->o[a]), ou16 = vp_load(F->o[u]), ov16 = vp_load(F->o[v]);
    const vpf side = vp_sub(oa, c), toward = vp_sub(c, oa);
    vpm cross = vpm_bits_to(0xFFFFu);
    vpf ulo = vp(INFINITY), uhi = vp(-INFINITY), vlo = ulo, vhi = uhi;
    for (int j = 0; j < 4; j++) {
      const vpf ca = vp_load(F->corner[j][a]);
      cross = vpm_and(cross, vp_lt(vp_mul(vp_sub(vp_add(oa, vp_mul(tf16, ca)), c), side), zero));
      const vpf t = vp_div(toward, ca);
      const vpf hu = vp_add(ou16, vp_mul(t, vp_load(F->corner[j][u]))), hv = vp_add(ov16, vp_mul(t, vp_load(F->corner[j][v])));
      ulo = vp_min(ulo, hu); uhi = vp_max(uhi, hu);
      vlo = vp_min(vlo, hv); vhi = vp_max(vhi, hv);
    }
    const vpm meets = vpm_and(vpm_and(vp_le(ulo, vp(p->hi[0])), vp_ge(uhi, vp(p->lo[0]))),
                              vpm_and(vp_le(vlo, vp(p->hi[1])), vp_ge(vhi, vp(p->lo[1]))));
    const unsigned passed = *alive & vpm_bits(vpm_and(cross, meets));
    if (!passed) continue;
    /* The polygon's edges that each frustum's corner rays cross inside of,
     * by twice the point margin: the polygon is convex and the margin a
     * convex function of the crossing, so every ray of the frustum
     * crosses inside those edges by the margin too, and only the others
     * are tested ray by ray (a frustum under the table tests none, one at
     * its rim one or two, of up to 16). */
    const vpf du = vp_max(vp_abs(vp_sub(ulo, ou16)), vp_abs(vp_sub(uhi, ou16)));
    const vpf dv = vp_max(vp_abs(vp_sub(vlo, ov16)), vp_abs(vp_sub(vhi, ov16)));
    const vpf err = vp_mul(vp(2.0f * FR_PLANE_POINT_MARGIN), vp_add(vp_add(vp_abs(ou16), vp_abs(ov16)), vp_add(du, dv)));
    unsigned inside[FR_PLANE_OCCLUDER_EDGES];
    for (int k = 0; k < p->nedges; k++) {
      const vpf wu = p->nu[k] >= 0.0f ? uhi : ulo, wv = p->nv[k] >= 0.0f ? vhi : vlo; /* the box's corner farthest out */
      inside[k] = vpm_bits(vp_le(vp_add(vp_add(vp_mul(vp(p->nu[k]), wu), vp_mul(vp(p->nv[k]), wv)), err), vp(p->e[k])));
    }
    for (unsigned g = passed; g; g &= g - 1) {
      const int f = __builtin_ctz(g);
      unsigned edges = 0;
      for (int k = 0; k < p->nedges; k++) edges |= (~inside[k] >> f & 1u) << k;
      FR_COUNT(mft_plane_frusta, 1);
      FR_COUNT(mft_plane_whole, edges == 0);
      const frustum_dirs D = dirs_of(F, f);
      const vpf o[3] = {vp(F->o[0][f]), vp(F->o[1][f]), vp(F->o[2][f])}, d[3] = {D.x, D.y, D.z};
      const unsigned hits = active[f] & fr_plane_hits_edges(p, o, d, vp(F->tnear[f]), vp(F->tfar[f]), edges);
      if (!hits) continue;
      const unsigned bit = 1u << f;
      occ[f] |= (uint16_t)hits;
      active[f] &= ~hits;
      occluded += (unsigned)__builtin_popcount(hits);
      if (!active[f]) *alive &= ~bit;
      else if (opt->shrink) shrink |= bit;
    }
  }
  shrink &= *alive;
  if (shrink) shrink_to_active(F, opt, T, shrink, active);
  FR_COUNT(mft_plane_rays, occluded);
  return occluded;
}

/* The leaves that occluded the most rays in a batch so far, most first. */
typedef struct best_leaves { uint32_t ref[FR_MFT_OCCLUDERS]; unsigned rays[FR_MFT_OCCLUDERS]; unsigned n; } best_leaves;

static void best_leaves_add(best_leaves *L, uint32_t ref, unsigned rays) {
  unsigned i;
  if (L->n < FR_MFT_OCCLUDERS) i = L->n++;
  else if (L->rays[FR_MFT_OCCLUDERS - 1] >= rays) return;
  else i = FR_MFT_OCCLUDERS - 1;
  for (; i > 0 && L->rays[i - 1] < rays; i--) {
    L->ref[i] = L->ref[i - 1];
    L->rays[i] = L->rays[i - 1];
  }
  L->ref[i] = ref;
  L->rays[i] = rays;
}

/* fr_mft_budget.planes_only: the planar occluders alone. */
static void occluded_planes_only(const fr_bvh2 *b, const fr_mft_opts *opt, const fr_mft_batch *B,
                                 const fr_mft_sets *T, uint32_t which, uint16_t occ[16]) {
  const unsigned valid = B->valid & 0xFFFFu;
  if (!valid || !b->planes) return;
  frusta F;
  frusta_setup(&F, B, T, valid);
  unsigned active[16], alive = valid;
  for (int f = 0; f < 16; f++) active[f] = (valid >> f) & 1 ? 0xFFFFu : 0;
  occlude_planes(&F, b->planes, which, opt, T, active, occ, &alive);
}

/* A shadow batch entering leaf e with the frusta m, whose box test passed:
 * unless it is a cached occluder (tested already, skip), its rays' own box
 * tests, then its triangles; *fetched counts them, best (when not NULL)
 * ranks the leaf by the rays it occluded. */
FR_INLINE void shadow_leaf(frusta *F, const fr_bvh2 *b, const fr_mft_opts *opt, const fr_mft_sets *T, const entry *e,
                           unsigned m, const uint32_t skip[FR_MFT_OCCLUDERS], unsigned active[16], uint16_t occ[16],
                           unsigned *alive, unsigned *fetched, best_leaves *best) {
  int cached = 0;
  for (unsigned c = 0; c < FR_MFT_OCCLUDERS; c++) cached |= e->ref == skip[c];
  if (cached) return;
  unsigned rays[16];
  m = leaf_rays(F, e, m, active, NULL, rays);
  if (!m) return;
  *fetched += FR_BVH2_LEAF_COUNT(e->ref);
  const int eager = opt->shrink && *fetched > EAGER_FETCHED;
  const unsigned got = occlude_leaf(F, b, opt, T, e->ref, m, rays, active, occ, alive, eager);
  if (got && best) best_leaves_add(best, e->ref, got);
}

unsigned FR_ISA_FN(fr_mft_occluded)(const fr_bvh2 *b, const fr_mft_opts *opt, const fr_mft_batch *B, const fr_mft_sets *T,
                             uint16_t occ[16], fr_mft_budget *budget, fr_mft_occluders *cache) {
  frusta F;
  unsigned valid = B->valid & 0xFFFFu;
  unsigned visited = 0;
  const int bounded = budget && (budget->nodes || budget->tris);
  for (int f = 0; f < 16; f++) occ[f] = 0;
  if (budget) budget->visited = 0, budget->stopped = 0;
  if (budget && budget->planes_only) {
    occluded_planes_only(b, opt, B, T, cache ? ~cache->planes_off : ~0u, occ);
    budget->stopped = 1;
    return 0;
  }
  FR_COUNT(mft_batches, 1);
  FR_COUNT(rays, 16 * __builtin_popcount(valid));
  if (!valid || !b->nodes) return 0;
  frusta_setup(&F, B, T, valid);
  unsigned fetched = 0;
  unsigned active[16];
  for (int f = 0; f < 16; f++) active[f] = (valid >> f) & 1 ? 0xFFFFu : 0;
  unsigned alive = valid;
  /* the scene's planar occluders first: no fetch, no box test */
  if (b->planes) occlude_planes(&F, b->planes, cache ? ~cache->planes_off : ~0u, opt, T, active, occ, &alive);
  /* The previous batch's best occluders first (see fr_mft_occluders): all
   * active rays, no box test; the traversal then skips those leaves, which
   * every ray still active has missed. What it saves is the traversal of
   * the frusta it finishes: a fifth of conference's soft16 instructions,
   * little where penumbrae are wide and occluders fine (kitchen, dragon),
   * where a frustum is seldom finished by two leaves. */
  best_leaves best = {{0}, {0}, 0};
  uint32_t skip[FR_MFT_OCCLUDERS] = {0};
  const unsigned ncache = cache ? cache->n : 0;
  for (unsigned c = 0; c < ncache && c < FR_MFT_OCCLUDERS && alive; c++) {
    const uint32_t ref = cache->leaf[c], first = FR_BVH2_LEAF_FIRST(ref), count = FR_BVH2_LEAF_COUNT(ref);
    /* any leaf of this tree gives true answers; another tree's is skipped */
    if (!(ref & FR_BVH2_LEAF) || count > FR_BVH2_MAX_LEAF || first + (size_t)count > b->nprims) continue;
    skip[c] = ref;
    fetched += count;
    FR_COUNT(mft_cached_leaves, 1);
    /* shrinking after them by the traversal's rule too (shrinking always
     * cost more than it saved) */
    const int eager = opt->shrink && fetched > EAGER_FETCHED;
    const unsigned got = occlude_leaf(&F, b, opt, T, ref, alive, active, active, occ, &alive, eager);
    if (got) best_leaves_add(&best, ref, got);
  }
  if (cache && cache->shaft) {
    /* The shaft's leaves alone, in the order its build met them: no leaf
     * outside it can be reached, and each one's box test is the one its
     * parent's visit would make, so the rays meet the same triangles (the
     * answers do not depend on the order). A leaf test counts as a node
     * visit for the budget. */
    const fr_mft_shaft *sh = cache->shaft;
    FR_COUNT(mft_shaft_batches, 1);
    for (unsigned i = 0; i < sh->n && alive; i++) {
      if (bounded && visited >= budget->nodes && fetched >= budget->tris) {
        budget->stopped = 1;
        goto out;
      }
      visited++;
      const fr_bvh2_node *pn = &b->nodes[sh->leaf[i] >> 1];
      const int slot = (int)(sh->leaf[i] & 1u);
      FR_COUNT(mft_box_tests, 1);
      FR_COUNT(mft_box_lanes, __builtin_popcount(alive));
      vpf tn;
      const unsigned hit = box_test(&F, pn, slot, alive, &tn);
      if (!hit) continue;
      const entry e = {pn->child[slot], hit, pn, slot};
      shadow_leaf(&F, b, opt, T, &e, hit, skip, active, occ, &alive, &fetched, &best);
    }
    goto out;
  }
  entry stack[STACK];
  int sp = 0;
  stack[sp++] = (entry){b->root, valid, NULL, 0};
  while (sp && alive) {
    entry e = stack[--sp];
    e.mask &= alive;
    while (e.mask) {
      if (!(e.ref & FR_BVH2_LEAF)) {
        if (bounded && visited >= budget->nodes && fetched >= budget->tris) {
          budget->stopped = 1;
          goto out;
        }
        visited++;
        if (!visit_node(&F, b, e.ref, e.mask, stack, &sp, &e)) break;
        continue;
      }
      shadow_leaf(&F, b, opt, T, &e, e.mask & alive, skip, active, occ, &alive, &fetched, cache ? &best : NULL);
      break;
    }
  }
out:
  if (cache) {
    cache->n = best.n;
    for (unsigned c = 0; c < best.n; c++) cache->leaf[c] = best.ref[c];
  }
  if (budget) budget->visited = visited;
  return fetched;
}

