/*
 * The soft-shadow tile driver: a tile's 16 shadow rays per pixel as batches
 * of 16 frusta (one per pixel) through the tracer's multi-frusta kernel where
 * it has one, falling back to ray streams where frusta would be outrun by
 * rays; as rays for a tracer without frusta. Every decision is the tile's,
 * not the thread's, so an image does not depend on scheduling.
 */
#include <string.h>
#include "render/mft_rays.h"
#include "render/tile.h"
#include "trace/counters.h"

/* A tile falls back to ray streams once its first batch's frusta fetched
 * more than SOFT_FRUSTA_MAX_TRIS triangles and visited more than
 * SOFT_FRUSTA_MAX_NODES nodes each: wide frusta over fine triangles
 * (dragon fetches ~20 per frustum at 1024x1024, kitchen ~5, conference and
 * sibenik ~1). Many triangles in few node visits are a few large leaves the
 * corner rays mostly cull, which frusta still win. Rays that part ways at
 * the scale of the triangles go fastest as ray streams (docs/design.md,
 * "Multi-frusta"). */
#define SOFT_FRUSTA_MAX_TRIS 8
#define SOFT_FRUSTA_MAX_NODES 12
/* Every tile first builds its shaft (fr_mft_shaft): the leaves segments
 * from the box of its hit points to the light can reach. Where it lists at
 * most FR_MFT_SHAFT_MAX leaves, the batches test those leaves instead of
 * walking the tree. A tile whose shaft gave up falls back already when its
 * first batch passes these lower bounds: its batches would walk as many
 * nodes as the first. */
#define SOFT_SHAFT_DECIDES_TRIS 4u
#define SOFT_SHAFT_DECIDES_NODES 8u

/* The box of a tile's n pixels' shadow rays' origins (their primary hit
 * points) and the box of their ends (the quad light); 0 where no pixel has
 * a hit. */
typedef struct tile_box { float plo[3], phi[3], qlo[3], qhi[3]; } tile_box;

static int tile_box_of(const fr_workload *w, const fr_tile_buffers *B, int n, tile_box *tb) {
  int any = 0;
  for (int a = 0; a < 3; a++) tb->plo[a] = tb->qlo[a] = INFINITY, tb->phi[a] = tb->qhi[a] = -INFINITY;
  for (int i = 0; i < n; i++) {
    const fr_hit *h = &B->prim_hit[i];
    if (h->prim == FR_INVALID_ID) continue;
    const vec3 p = hit_point(&B->prim_ray[i], h); /* the batches' origins, bit for bit */
    const float pc[3] = {p.x, p.y, p.z};
    for (int a = 0; a < 3; a++) { /* comparisons, not fminf: a libm call without -ffast-math */
      tb->plo[a] = pc[a] < tb->plo[a] ? pc[a] : tb->plo[a];
      tb->phi[a] = pc[a] > tb->phi[a] ? pc[a] : tb->phi[a];
    }
    any = 1;
  }
  const vec3 c0 = w->view.area_c, c1 = v3_add(c0, w->view.area_e1), c2 = v3_add(c0, w->view.area_e2),
             c3 = v3_add(c1, w->view.area_e2);
  const vec3 cs[4] = {c0, c1, c2, c3};
  for (int k = 0; k < 4; k++) {
    const float q[3] = {cs[k].x, cs[k].y, cs[k].z};
    for (int a = 0; a < 3; a++) {
      tb->qlo[a] = q[a] < tb->qlo[a] ? q[a] : tb->qlo[a];
      tb->qhi[a] = q[a] > tb->qhi[a] ? q[a] : tb->qhi[a];
    }
  }
  return any;
}

/* The shaft of a tile's shadow rays on tree b (fr_mft_shaft_build);
 * 0: none (too wide). */
static int tile_shaft(const fr_bvh2 *b, const tile_box *tb, fr_mft_shaft *s) {
  const int ok = fr_mft_shaft_build(b, tb->plo, tb->phi, tb->qlo, tb->qhi, s);
  FR_COUNT(mft_shafts, 1);
  FR_COUNT(mft_shaft_fails, !ok);
  return ok;
}

/* Set bits of a 16-bit mask. This file is built for every CPU, without
 * -mpopcnt, where __builtin_popcount is a call into libgcc. */
static inline int bits16(unsigned x) {
  x = x - ((x >> 1) & 0x5555u);
  x = (x & 0x3333u) + ((x >> 2) & 0x3333u);
  x = (x + (x >> 4)) & 0x0F0Fu;
  return (int)((x + (x >> 8)) & 0x1Fu);
}

/* Per tile: how its batches go, and the rays queued for the tracer. */
typedef struct soft_tile {
  const fr_bvh2 *shaft_tree; /* the tree shafts are built on; NULL: no shaft */
  fr_mft_shaft shaft;
  /* one per tile, so that what a batch costs does not depend on which
   * thread traced the tile before */
  fr_mft_occluders cache;
  int as_rays;    /* the rest of the tile's batches go as rays ... */
  int as_streams; /* ... and as ray streams (the tile fell back) */
  int m, nheld;   /* rays queued in B->rays; batches held in B->held */
  uint8_t by_rays[TILE_PIX]; /* pixels whose visibility the rays decide */
} soft_tile;

/* Batch j: pixels 16 j .. 16 j + 15 with a primary hit, each a frustum from
 * its hit point p towards the light, t in (eps / |light centre - p|, 1 - 1e-4). */
static void batch_of(const fr_workload *w, const fr_tile_buffers *B, int n, int j, vec3 centre, fr_mft_batch *b) {
  memset(b, 0, sizeof *b);
  for (int f = 0; f < 16 && 16 * j + f < n; f++) {
    int i = 16 * j + f;
    const fr_hit *h = &B->prim_hit[i];
    if (h->prim == FR_INVALID_ID) continue;
    vec3 p = hit_point(&B->prim_ray[i], h), st = v3_sub(w->view.area_c, p);
    b->org[0][f] = p.x; b->org[1][f] = p.y; b->org[2][f] = p.z;
    b->start[0][f] = st.x; b->start[1][f] = st.y; b->start[2][f] = st.z;
    b->tfar[f] = 1.0f - 1e-4f;
    b->set[f] = (uint8_t)fr_mft_light_set(B->px[i], B->py[i]);
    b->valid |= 1u << f;
  }
  /* tnear for all 16 lanes in a loop the compiler vectorizes (the same
   * operations as eps / v3_len(centre - p)); lanes without a hit are never
   * read */
  for (int f = 0; f < 16; f++) {
    const float dx = centre.x - b->org[0][f], dy = centre.y - b->org[1][f], dz = centre.z - b->org[2][f];
    b->tnear[f] = w->eps / sqrtf(dx * dx + dy * dy + dz * dz);
  }
}

/* Batch j (the jj-th traced) as frusta. Returns 1 where the frusta answered
 * it (lit written); 0 where it stopped because the tile falls back, its
 * occluded rays in occ. The batch stops as soon as the fall-back is certain
 * (counts only grow, so the verdict is the whole batch's), at a fraction of
 * the whole batch's cost. */
static int frusta_batch(const fr_workload *w, const fr_tracer *t, soft_tile *st, int jj, int j, const fr_mft_batch *b,
                        uint16_t occ[FR_MFT_FRUSTA], float *lit) {
  const unsigned nf = (unsigned)bits16(b->valid);
  fr_mft_budget budget = {0, 0, 0, 0, 0};
  /* a tile's first batch without a shaft: the lower bounds decide */
  const int lower = jj == 0 && st->shaft_tree && !st->cache.shaft;
  if (!w->mft_no_fallback) {
    budget.nodes = (lower ? SOFT_SHAFT_DECIDES_NODES : SOFT_FRUSTA_MAX_NODES) * nf + 1;
    budget.tris = (lower ? SOFT_SHAFT_DECIDES_TRIS : SOFT_FRUSTA_MAX_TRIS) * nf + 1;
  }
  const unsigned fetched = t->occluded_frusta(t->ctx, b, w->light_sets, occ, &budget, &st->cache);
  st->as_rays = st->as_streams = !w->mft_no_fallback && fetched > SOFT_FRUSTA_MAX_TRIS * nf &&
                                 budget.visited > SOFT_FRUSTA_MAX_NODES * nf;
  if (lower && !st->as_rays && !w->mft_no_fallback && fetched > SOFT_SHAFT_DECIDES_TRIS * nf &&
      budget.visited > SOFT_SHAFT_DECIDES_NODES * nf)
    st->as_rays = st->as_streams = 1;
  if (budget.stopped) {
    FR_COUNT(mft_stopped_batches, 1);
    return 0;
  }
  float open[FR_MFT_FRUSTA]; /* all lanes at once, vectorized */
  for (int f = 0; f < FR_MFT_FRUSTA; f++) open[f] = (float)(16 - bits16(occ[f])) / 16.0f;
  for (unsigned v = b->valid; v; v &= v - 1) lit[16 * j + __builtin_ctz(v)] = open[__builtin_ctz(v)];
  return 1;
}

/* A batch of a fallen-back tile, held for the ray streams with the rays its
 * frusta found occluded. Batches after the tile's verdict still test the
 * planar occluders, which end the rays they cover. */
static void hold_batch(const fr_tracer *t, const fr_workload *w, fr_tile_buffers *B, soft_tile *st, int j,
                       const fr_mft_batch *b, uint16_t occ[FR_MFT_FRUSTA], int framed) {
  if (!framed && b->valid) {
    fr_mft_budget planes = {0, 0, 0, 0, 1};
    t->occluded_frusta(t->ctx, b, w->light_sets, occ, &planes, &st->cache);
  }
  for (unsigned v = b->valid; v; v &= v - 1) st->by_rays[16 * j + __builtin_ctz(v)] = 1;
  B->held[st->nheld] = *b;
  memcpy(B->held_occ[st->nheld], occ, sizeof B->held_occ[0]);
  B->held_j[st->nheld++] = j;
}

/* A tracer without frusta: each pixel's 16 rays in a row. */
static void queue_batch_rays(const fr_mft_sets *T, fr_tile_buffers *B, soft_tile *st, int j, const fr_mft_batch *b) {
  for (unsigned v = b->valid; v; v &= v - 1) {
    int f = __builtin_ctz(v);
    st->by_rays[16 * j + f] = 1;
    for (int k = 0; k < FR_MFT_RAYS; k++) {
      fr_ray *r = &B->rays[st->m];
      fr_mft_ray(b, T, f, k, r->org, r->dir);
      r->tnear = b->tnear[f];
      r->tfar = b->tfar[f];
      B->owner[st->m++] = 16 * j + f;
    }
  }
}

/* The held batches' rays their frusta left open, four light samples at a
 * time: the sets are consecutive runs of one Sobol (0,8,2)-net, so sample k
 * of every set lies in the same 1/16-wide strip of the light along e1, and
 * a four of korder in one quarter of it. A stream of 64 rays then runs from
 * 16 pixels to a quarter of the light rather than from 4 pixels to all of
 * it. */
static void queue_held_rays(const fr_mft_sets *T, fr_tile_buffers *B, soft_tile *st) {
  static const int korder[16] = {0, 12, 4, 8, 5, 9, 1, 13, 6, 10, 2, 14, 3, 15, 7, 11};
  for (int q = 0; q < 4; q++)
    for (int h = 0; h < st->nheld; h++) {
      const fr_mft_batch *hb = &B->held[h];
      for (unsigned v = hb->valid; v; v &= v - 1)
        for (int kk = 0; kk < 4; kk++) {
          int f = __builtin_ctz(v), k = korder[4 * q + kk];
          if ((B->held_occ[h][f] >> k) & 1) continue;
          fr_ray *r = &B->rays[st->m];
          fr_mft_ray(hb, T, f, k, r->org, r->dir);
          r->tnear = hb->tnear[f];
          r->tfar = hb->tfar[f];
          B->owner[st->m++] = 16 * B->held_j[h] + f;
        }
    }
}

/* Soft shadows: pixels 16 j .. 16 j + 15 with a primary hit are the frusta
 * of batch j, rays p + t (c + s e1 + q e2 - p) for the samples of the
 * pixel's interleaved set. Returns the shadow rays traced; lit[i] gets
 * pixel i's unoccluded fraction. */
uint64_t fr_tile_soft_shadows(const fr_workload *w, const fr_tracer *t, fr_tile_buffers *B, int n, float *lit) {
  const fr_mft_sets *T = w->light_sets;
  vec3 centre = v3_add(w->view.area_c, v3_scale(v3_add(w->view.area_e1, w->view.area_e2), 0.5f));
  uint64_t rays = 0;
  soft_tile st;
  memset(&st.by_rays, 0, sizeof st.by_rays);
  st.m = st.nheld = st.as_streams = 0;
  st.as_rays = !t->occluded_frusta;
  st.cache = (fr_mft_occluders){{0}, 0, NULL, 0};
  /* the tile's shaft: which planar occluders its rays may cross, and the
   * leaves they may reach */
  tile_box tb;
  st.shaft_tree = t->occluded_frusta && t->shaft_tree && !w->mft_no_shaft ? t->shaft_tree(t->ctx) : NULL;
  if (st.shaft_tree && !tile_box_of(w, B, n, &tb)) st.shaft_tree = NULL;
  if (st.shaft_tree) {
    st.cache.planes_off = fr_mft_shaft_planes_off(st.shaft_tree, tb.plo, tb.phi, tb.qlo, tb.qhi);
    if (tile_shaft(st.shaft_tree, &tb, &st.shaft)) st.cache.shaft = &st.shaft;
  }
  for (int jj = 0; jj < (n + 15) / 16; jj++) {
    /* a full tile's 4x4 blocks in serpentine order: each batch borrows the
     * occluders of a neighbour */
    const int row = jj / (TILE / 4), col = jj % (TILE / 4);
    const int j = n == TILE_PIX ? row * (TILE / 4) + (row & 1 ? TILE / 4 - 1 - col : col) : jj;
    fr_mft_batch b;
    batch_of(w, B, n, j, centre, &b);
    rays += 16u * (uint64_t)bits16(b.valid);
    uint16_t occ[FR_MFT_FRUSTA] = {0};
    const int framed = !st.as_rays; /* traced as frusta (planar occluders included) */
    if (framed && frusta_batch(w, t, &st, jj, j, &b, occ, lit)) continue;
    if (t->occluded_frusta && b.valid) FR_COUNT(mft_ray_batches, 1);
    if (st.as_streams && b.valid) FR_COUNT(mft_stream_batches, 1);
    if (st.as_streams) hold_batch(t, w, B, &st, j, &b, occ, framed);
    else queue_batch_rays(T, B, &st, j, &b);
  }
  /* an occluded ray adds nothing to its pixel's count, so the held batches'
   * rays the frusta found occluded are not traced again */
  queue_held_rays(T, B, &st);
  if (st.m) {
    t->occluded(t->ctx, B->rays, B->occ, (size_t)st.m, st.as_streams ? FR_RAYS_DIVERGENT : 0);
    int cnt[TILE_PIX] = {0};
    for (int k = 0; k < st.m; k++) cnt[B->owner[k]] += !B->occ[k];
    for (int i = 0; i < n; i++)
      if (st.by_rays[i]) lit[i] = (float)cnt[i] / 16.0f;
  }
  return rays;
}
