#include "workload.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "base/alloc.h"
#include "base/rng.h"
#include "base/timer.h"
#include "render/mft_rays.h"
#include "trace/counters.h"

#define TILE 16 /* 16 blocks of 4x4 pixels: one batch of 16 frusta */
#define TILE_PIX (TILE * TILE)
#define MAX_SEC 16 /* secondary rays per pixel */

static const char *names[FR_WL_COUNT] = {"primary", "shadow", "soft16", "ao16", "diffuse8", "specular8", "whitted"};

const char *fr_workload_name(fr_workload_kind k) { return k < FR_WL_COUNT ? names[k] : "?"; }

int fr_workload_parse(const char *name, fr_workload_kind *k) {
  for (int i = 0; i < FR_WL_COUNT; i++)
    if (strcmp(name, names[i]) == 0) { *k = (fr_workload_kind)i; return 1; }
  return 0;
}

typedef struct buffers {
  fr_ray rays[TILE_PIX * MAX_SEC];
  fr_hit hits[TILE_PIX * MAX_SEC];
  uint8_t occ[TILE_PIX * MAX_SEC];
  int px[TILE_PIX], py[TILE_PIX];
  fr_hit prim_hit[TILE_PIX];
  fr_ray prim_ray[TILE_PIX];
  int owner[TILE_PIX * MAX_SEC];
  /* soft shadows: a tile's batches held back for ray streams, the rays
   * their frusta found occluded, and their batch numbers */
  fr_mft_batch held[TILE_PIX / 16];
  uint16_t held_occ[TILE_PIX / 16][FR_MFT_FRUSTA];
  int held_j[TILE_PIX / 16];
} buffers;

/* Unit geometric normal of a hit, facing the ray; taken from the scene so that
 * every tracer shades with the same normals. */
static vec3 hit_point(const fr_ray *r, const fr_hit *h) {
  return v3_add(v3_load(r->org), v3_scale(v3_load(r->dir), h->t));
}

static vec3 facing_normal(const fr_scene *s, const fr_hit *h, const fr_ray *r) {
  vec3 p = hit_point(r, h), d = v3_load(r->dir);
  float g[3], pp[3] = {p.x, p.y, p.z};
  fr_scene_geometric_normal(s, h->prim, pp, g);
  vec3 n = v3_norm(v3_load(g));
  return v3_dot(n, d) > 0.0f ? v3_scale(n, -1.0f) : n;
}

static vec3 cosine_dir(vec3 n, float u1, float u2) {
  vec3 t, b;
  v3_onb(n, &t, &b);
  float r = sqrtf(u1), phi = 2.0f * (float)M_PI * u2;
  float x = r * cosf(phi), y = r * sinf(phi), z = sqrtf(fmaxf(0.0f, 1.0f - u1));
  return v3_add(v3_add(v3_scale(t, x), v3_scale(b, y)), v3_scale(n, z));
}

static fr_ray make_ray(vec3 o, vec3 d, float tnear, float tfar) {
  fr_ray r = {{o.x, o.y, o.z}, tnear, {d.x, d.y, d.z}, tfar};
  return r;
}

static vec3 albedo(const fr_scene *s, uint32_t prim) {
  uint32_t m = fr_scene_prim_material(s, prim);
  const fr_material *mat = m == FR_INVALID_ID ? NULL : fr_scene_material(s, m);
  return mat ? v3(mat->diffuse[0], mat->diffuse[1], mat->diffuse[2]) : v3(0.8f, 0.8f, 0.8f);
}

void fr_camera_frusta(const fr_workload *w, const fr_tracer *t, int tx, int ty, fr_ray *rays, fr_hit *hits) {
  fr_mft_batch b;
  static _Thread_local fr_mft_hits h;
  const fr_mft_sets *cam_set = w->camera_set;
  fr_mft_batch_camera(&b, &w->cam, tx, ty);
  t->intersect_frusta(t->ctx, &b, cam_set, &h);
  fr_mft_active()->expand(&b, cam_set, &h, rays, hits);
}

/* Frusta that fetch more triangles than this each (the tile's first batch
 * tells) would be outrun by their rays: the rest of the tile goes as ray
 * streams. Triangles per frustum, 1024x1024, on average:
 * conference and sibenik ~1, kitchen ~5, dragon ~20 (pure frusta 0.4x the
 * rays there: fine triangles in wide frusta). The tile decides, not the
 * thread, so that a tile's image does not depend on which thread traced
 * what. */
#define SOFT_FRUSTA_MAX_TRIS 8
/* ... and visited more than this many nodes each. Many triangles fetched
 * in few node visits are a few large leaves the corner rays mostly cull,
 * which frusta still beat rays on: the first batches of conference's
 * fallen-back tiles visited 6 nodes per frustum on average, kitchen's 18.
 * Interleaved, 2 threads, 1024x1024, soft16 mft, 3 pairs: conference
 * 1.125x, kitchen 1.051x, sibenik 1.026x (3/3 each), dragon 0.99-1.02x;
 * 8 gained half as much, 16 the same as 12. */
#define SOFT_FRUSTA_MAX_NODES 12
/* Such a tile's rays part ways at the scale of its triangles, and ray
 * streams (trace/bvhn_stream.c) beat hybrid packets there. Until session 43
 * only tiles whose first batch fetched more than 16 triangles per frustum
 * went as streams, the rest as packets; now the first batch stops as soon
 * as the verdict above is certain (see soft_shadows), so that bound can no
 * longer be read, and all go as streams: interleaved, 2 threads,
 * 1024x1024, soft16 mft, 4 pairs, against stopping at 16: kitchen 1.028x
 * and 1.057x (3/4, 4/4), dragon 1.022x (4/4); conference's instructions
 * +0.2% (callgrind; it falls back in 14 tiles). Timed per batch (rdtsc,
 * warm caches, 1 thread), streams and packets cost the same on the
 * batches between 8 and 16 triangles per frustum: kitchen 0.153 and 0.156
 * Gcycles, dragon 0.080 and 0.081. A tile whose camera frusta had fetched
 * more than 32 triangles each used to skip shadow frusta altogether
 * (dragon 1.07x while first batches ran to their end); with them stopped
 * early that rule no longer paid (without it, 3 pairs: dragon 1.012x,
 * kitchen 1.002x) and is gone. */

/* Every tile first builds its shaft (fr_mft_shaft: the leaves that
 * segments from the box of its hit points to the light can reach); where
 * it lists at most FR_MFT_SHAFT_MAX leaves, all its batches test those
 * leaves' boxes instead of walking the tree from the root. Kitchen at
 * 1024x1024: shafts held 7 leaves on average against the batches' 31
 * node visits. Interleaved, 2 threads, 1024x1024, soft16 mft, shafts
 * against none: kitchen 1.076x, conference 1.043x, sibenik 1.042x, dragon
 * 0.997x (4/4 each but dragon) when built after the tile's first batch,
 * and only where that batch's walk visited at most 3 nodes per frustum
 * (bounds of 2 and 6 read 0.991x and 0.990x of that); built before it,
 * for every tile, and then used by the first batch too, against that:
 * sibenik 1.039x, kitchen and conference 1.007x, dragon 0.987x (3/3 each;
 * dragon's shafts mostly give up, lost work). At most 64 leaves read the
 * same as 32 and 128; a build that gives up after 96 node visits rather
 * than 256, sibenik 0.979x.
 *
 * A tile whose shaft gave up and whose first batch fetched more than
 * SOFT_SHAFT_DECIDES_TRIS triangles and visited more than
 * SOFT_SHAFT_DECIDES_NODES nodes per frustum, but stayed within the
 * fall-back's bounds (SOFT_FRUSTA_MAX_*), falls back too: its batches
 * would walk as many nodes as the first. Lowering the fall-back's own
 * bounds to these gained kitchen 1.037x but cost conference 0.950x and
 * sibenik 0.974x (3 pairs each); decided by the shaft, kitchen 1.024x,
 * dragon 1.042x, conference 0.990x, sibenik 0.997x. Tris 2 or 3 read the
 * same as 4; nodes 10 gave kitchen 1.011x. Such a first batch stops as
 * soon as it passes these bounds, as at the fall-back's own: kitchen
 * 1.014x, dragon 1.014x, sibenik 1.008x, conference 1.003x (3/3, 2/3, 4/4,
 * 3/4). */
#define SOFT_SHAFT_DECIDES_TRIS 4u
#define SOFT_SHAFT_DECIDES_NODES 8u

/* The box of a tile's n pixels' shadow rays' origins (their primary hit
 * points) and the box of their ends (the quad light); 0 where no pixel has
 * a hit. */
typedef struct tile_box { float plo[3], phi[3], qlo[3], qhi[3]; } tile_box;

static int tile_box_of(const fr_workload *w, const buffers *B, int n, tile_box *tb) {
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
 * -mpopcnt, where __builtin_popcount is a call into libgcc: one per shadow
 * frustum was about 1.5% of conference soft16's multi-frusta samples. */
static inline int bits16(unsigned x) {
  x = x - ((x >> 1) & 0x5555u);
  x = (x & 0x3333u) + ((x >> 2) & 0x3333u);
  x = (x + (x >> 4)) & 0x0F0Fu;
  return (int)((x + (x >> 8)) & 0x1Fu);
}

/* Soft shadows: pixels 16 j .. 16 j + 15 with a primary hit are the frusta of
 * batch j: origin p, rays p + t (c + s e1 + q e2 - p) for the samples of the
 * pixel's interleaved set, t in (eps / |light centre - p|, 1 - 1e-4). Returns
 * the shadow rays traced; lit[i] gets pixel i's unoccluded fraction. */
static uint64_t soft_shadows(const fr_workload *w, const fr_tracer *t, buffers *B, int n, float *lit) {
  const fr_mft_sets *T = w->light_sets;
  vec3 centre = v3_add(w->view.area_c, v3_scale(v3_add(w->view.area_e1, w->view.area_e2), 0.5f));
  uint64_t rays = 0;
  int m = 0, nheld = 0, as_rays = !t->occluded_frusta, as_streams = 0;
  uint8_t by_rays[TILE_PIX] = {0};
  /* one per tile, so that what a batch costs does not depend on which
   * thread traced the tile before */
  fr_mft_occluders cache = {{0}, 0, NULL, 0};
  fr_mft_shaft shaft;
  /* the tile's shaft: which planar occluders its rays may cross, and the
   * leaves they may reach (see SOFT_SHAFT_DECIDES_*) */
  tile_box tb;
  const fr_bvh2 *shaft_tree = t->occluded_frusta && t->shaft_tree && !w->mft_no_shaft ? t->shaft_tree(t->ctx) : NULL;
  if (shaft_tree && !tile_box_of(w, B, n, &tb)) shaft_tree = NULL;
  if (shaft_tree) {
    cache.planes_off = fr_mft_shaft_planes_off(shaft_tree, tb.plo, tb.phi, tb.qlo, tb.qhi);
    if (tile_shaft(shaft_tree, &tb, &shaft)) cache.shaft = &shaft;
  }
  for (int jj = 0; jj < (n + 15) / 16; jj++) {
    /* a full tile's 4x4 blocks in serpentine order: each batch borrows the
     * occluders of a neighbour */
    const int row = jj / (TILE / 4), col = jj % (TILE / 4);
    const int j = n == TILE_PIX ? row * (TILE / 4) + (row & 1 ? TILE / 4 - 1 - col : col) : jj;
    fr_mft_batch b;
    memset(&b, 0, sizeof b);
    for (int f = 0; f < 16 && 16 * j + f < n; f++) {
      int i = 16 * j + f;
      const fr_hit *h = &B->prim_hit[i];
      if (h->prim == FR_INVALID_ID) continue;
      vec3 p = hit_point(&B->prim_ray[i], h), st = v3_sub(w->view.area_c, p);
      b.org[0][f] = p.x; b.org[1][f] = p.y; b.org[2][f] = p.z;
      b.start[0][f] = st.x; b.start[1][f] = st.y; b.start[2][f] = st.z;
      b.tfar[f] = 1.0f - 1e-4f;
      b.set[f] = (uint8_t)fr_mft_light_set(B->px[i], B->py[i]);
      b.valid |= 1u << f;
    }
    /* tnear for all 16 lanes in a loop the compiler vectorizes (the same
     * operations as eps / v3_len(centre - p)); lanes without a hit are
     * never read */
    for (int f = 0; f < 16; f++) {
      const float dx = centre.x - b.org[0][f], dy = centre.y - b.org[1][f], dz = centre.z - b.org[2][f];
      b.tnear[f] = w->eps / sqrtf(dx * dx + dy * dy + dz * dz);
    }
    rays += 16u * (uint64_t)bits16(b.valid);
    uint16_t occ[FR_MFT_FRUSTA] = {0};
    const int framed = !as_rays; /* traced as frusta (planar occluders included) */
    if (!as_rays) {
      /* The batch stops as soon as the rule below is sure to send the rest
       * of the tile to ray streams, and its rays still open join them:
       * counts only grow, so the verdict is the same as the whole batch's
       * but costs a fraction of it (on dragon these first batches of
       * fallen-back tiles took a quarter of soft16's shadow time, at up to
       * 7 times their rays' cost as streams; stopping them gained dragon
       * soft16 1.09x, 4/4 interleaved pairs, kitchen 1.00x). */
      const unsigned nf = (unsigned)bits16(b.valid);
      fr_mft_budget budget = {0, 0, 0, 0, 0};
      if (!w->mft_no_fallback) {
        /* a tile's first batch without a shaft: the lower bounds decide */
        const int lower = jj == 0 && shaft_tree && !cache.shaft;
        budget.nodes = (lower ? SOFT_SHAFT_DECIDES_NODES : SOFT_FRUSTA_MAX_NODES) * nf + 1;
        budget.tris = (lower ? SOFT_SHAFT_DECIDES_TRIS : SOFT_FRUSTA_MAX_TRIS) * nf + 1;
      }
      const unsigned fetched = t->occluded_frusta(t->ctx, &b, T, occ, &budget, &cache);
      as_rays = as_streams = !w->mft_no_fallback && fetched > SOFT_FRUSTA_MAX_TRIS * nf &&
                             budget.visited > SOFT_FRUSTA_MAX_NODES * nf;
      /* a first batch between the bounds: the tile's shaft decides (a
       * listed shaft keeps a batch's visits far below them) */
      if (jj == 0 && !as_rays && !w->mft_no_fallback && shaft_tree && !cache.shaft &&
          fetched > SOFT_SHAFT_DECIDES_TRIS * nf && budget.visited > SOFT_SHAFT_DECIDES_NODES * nf)
        as_rays = as_streams = 1;
      if (!budget.stopped) {
        float open[FR_MFT_FRUSTA]; /* all lanes at once, vectorized */
        for (int f = 0; f < FR_MFT_FRUSTA; f++) open[f] = (float)(16 - bits16(occ[f])) / 16.0f;
        for (unsigned v = b.valid; v; v &= v - 1) lit[16 * j + __builtin_ctz(v)] = open[__builtin_ctz(v)];
        continue;
      }
      FR_COUNT(mft_stopped_batches, 1);
    }
    if (t->occluded_frusta && b.valid) FR_COUNT(mft_ray_batches, 1);
    if (as_streams && b.valid) FR_COUNT(mft_stream_batches, 1);
    if (as_streams) { /* frusta fell back: traced below, but for the rays they found occluded */
      if (!framed && b.valid) {
        /* the batches after the tile's verdict: the planar occluders still
         * end the rays they cover, which the streams would trace */
        fr_mft_budget planes = {0, 0, 0, 0, 1};
        t->occluded_frusta(t->ctx, &b, T, occ, &planes, &cache);
      }
      for (unsigned v = b.valid; v; v &= v - 1) by_rays[16 * j + __builtin_ctz(v)] = 1;
      B->held[nheld] = b;
      memcpy(B->held_occ[nheld], occ, sizeof occ);
      B->held_j[nheld++] = j;
      continue;
    }
    /* a tracer without frusta: each pixel's 16 rays in a row, a packet */
    for (unsigned v = b.valid; v; v &= v - 1) {
      int f = __builtin_ctz(v);
      by_rays[16 * j + f] = 1;
      for (int k = 0; k < FR_MFT_RAYS; k++) {
        fr_ray *r = &B->rays[m];
        fr_mft_ray(&b, T, f, k, r->org, r->dir);
        r->tnear = b.tnear[f];
        r->tfar = b.tfar[f];
        B->owner[m++] = 16 * j + f;
      }
    }
  }
  /* An occluded ray adds nothing to its pixel's count, so the held
   * batches' rays the frusta found occluded are not traced again.
   * Streams take the held batches' rays four samples at a time: the sets
   * are consecutive runs of one Sobol (0,8,2)-net, so sample k of every
   * set lies in the same 1/16-wide strip of the light along e1 (the first
   * coordinate's top bits are k's, reversed), and a pixel's two samples of
   * a pair of korder in one quarter by half of it (a four of korder in
   * one quarter of it). A stream of 64 rays then runs from 16 pixels to a
   * quarter of the light rather than from 4 pixels to all of it.
   * Interleaved, 2 threads, 1024x1024, soft16 mft, against pixel by pixel
   * (session 43): pairs of samples kitchen 1.054x (4/4 pairs), dragon
   * 1.007x (noise); fours kitchen 1.037x, dragon 1.012x (3/3 each); one
   * sample (64 pixels to one strip) kitchen 1.062x but dragon 0.970x
   * (0/3). Dragon's shadow rays start among the fine triangles that
   * occlude them, where, we think, a stream's rays part ways by origin
   * sooner than by direction. Since tile shafts and the lower bounds that
   * send more of dragon's tiles to streams (session 59), fours against
   * pairs: dragon 1.024x (3/3), kitchen 1.005x and 1.002x, conference
   * 1.004x; one sample against pairs, dragon 0.986x. */
  static const int korder[16] = {0, 12, 4, 8, 5, 9, 1, 13, 6, 10, 2, 14, 3, 15, 7, 11};
  for (int q = 0; q < 4; q++)
    for (int h = 0; h < nheld; h++) {
      const fr_mft_batch *hb = &B->held[h];
      for (unsigned v = hb->valid; v; v &= v - 1)
        for (int kk = 0; kk < 4; kk++) {
          int f = __builtin_ctz(v), k = korder[4 * q + kk];
          if ((B->held_occ[h][f] >> k) & 1) continue;
          fr_ray *r = &B->rays[m];
          fr_mft_ray(hb, T, f, k, r->org, r->dir);
          r->tnear = hb->tnear[f];
          r->tfar = hb->tfar[f];
          B->owner[m++] = 16 * B->held_j[h] + f;
        }
    }
  if (m) {
    t->occluded(t->ctx, B->rays, B->occ, (size_t)m, as_streams ? FR_RAYS_DIVERGENT : 0);
    int cnt[TILE_PIX] = {0};
    for (int k = 0; k < m; k++) cnt[B->owner[k]] += !B->occ[k];
    for (int i = 0; i < n; i++)
      if (by_rays[i]) lit[i] = (float)cnt[i] / 16.0f;
  }
  return rays;
}

/* One tile: returns rays traced; writes shaded pixels when w->image is set. */
static uint64_t run_tile(const fr_workload *w, const fr_tracer *t, buffers *B, int tx, int ty) {
  const int W = w->cam.width, H = w->cam.height;
  int n = 0;
  /* a full tile's camera rays come from the frusta tracer, made on demand */
  const int frusta = t->intersect_frusta && tx + TILE <= W && ty + TILE <= H;
  /* pixels in 4x4 blocks, so groups of 16 rays are coherent */
  for (int by = 0; by < TILE; by += 4)
    for (int bx = 0; bx < TILE; bx += 4)
      for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++) {
          int X = tx + bx + x, Y = ty + by + y;
          if (X >= W || Y >= H) continue;
          B->px[n] = X; B->py[n] = Y;
          if (!frusta) {
            B->prim_ray[n] = fr_camera_ray(&w->cam, X, Y);
            B->rays[n] = B->prim_ray[n];
          }
          n++;
        }
  uint64_t rays = (uint64_t)n;
  if (frusta)
    fr_camera_frusta(w, t, tx, ty, B->prim_ray, B->prim_hit);
  else
    t->intersect(t->ctx, B->rays, B->prim_hit, (size_t)n, 1);
  float lit[TILE_PIX];
  for (int i = 0; i < n; i++) lit[i] = 1.0f;

  int m = 0;
  switch (w->kind) {
  case FR_WL_PRIMARY:
    break;
  case FR_WL_SOFT16:
    for (int i = 0; i < n; i++) lit[i] = 0.0f;
    rays += soft_shadows(w, t, B, n, lit);
    break;
  case FR_WL_SHADOW:
  case FR_WL_AO16: {
    int per = w->kind == FR_WL_SHADOW ? 1 : 16;
    for (int i = 0; i < n; i++) {
      const fr_hit *h = &B->prim_hit[i];
      if (h->prim == FR_INVALID_ID) continue;
      vec3 p = hit_point(&B->prim_ray[i], h), nn = facing_normal(w->scene, h, &B->prim_ray[i]);
      fr_rng rng = fr_rng_seed(w->seed, (uint64_t)B->py[i] * (uint64_t)W + (uint64_t)B->px[i]);
      for (int k = 0; k < per; k++) {
        vec3 dir;
        float tfar;
        if (w->kind == FR_WL_AO16) {
          dir = cosine_dir(nn, fr_rng_float(&rng), fr_rng_float(&rng));
          tfar = INFINITY;
        } else {
          vec3 L = w->view.light;
          vec3 to = v3_sub(L, p);
          float dist = v3_len(to);
          dir = v3_scale(to, 1.0f / dist);
          tfar = dist * (1.0f - 1e-4f);
        }
        B->rays[m] = make_ray(p, dir, w->eps, tfar);
        B->owner[m++] = i;
      }
    }
    rays += (uint64_t)m;
    t->occluded(t->ctx, B->rays, B->occ, (size_t)m, 0);
    int cnt[TILE_PIX] = {0};
    for (int k = 0; k < m; k++) cnt[B->owner[k]] += !B->occ[k];
    for (int i = 0; i < n; i++) lit[i] = (float)cnt[i] / (float)per;
    break;
  }
  case FR_WL_DIFFUSE8:
  case FR_WL_SPECULAR8: {
    fr_rng rng[TILE_PIX];
    fr_ray cur[TILE_PIX];
    fr_hit ch[TILE_PIX];
    int alive[TILE_PIX], na = 0;
    for (int i = 0; i < n; i++)
      if (B->prim_hit[i].prim != FR_INVALID_ID) {
        alive[na++] = i;
        cur[i] = B->prim_ray[i];
        ch[i] = B->prim_hit[i];
        rng[i] = fr_rng_seed(w->seed, (uint64_t)B->py[i] * (uint64_t)W + (uint64_t)B->px[i]);
      }
    for (int bounce = 0; bounce < 8 && na > 0; bounce++) {
      for (int a = 0; a < na; a++) {
        int i = alive[a];
        vec3 d = v3_load(cur[i].dir), p = hit_point(&cur[i], &ch[i]), nn = facing_normal(w->scene, &ch[i], &cur[i]);
        vec3 nd = w->kind == FR_WL_DIFFUSE8 ? cosine_dir(nn, fr_rng_float(&rng[i]), fr_rng_float(&rng[i]))
                                            : v3_sub(d, v3_scale(nn, 2.0f * v3_dot(d, nn)));
        cur[i] = make_ray(p, nd, w->eps, INFINITY);
        B->rays[a] = cur[i]; /* the tracer may overwrite its copy */
      }
      rays += (uint64_t)na;
      t->intersect(t->ctx, B->rays, B->hits, (size_t)na, 0);
      int nn2 = 0;
      for (int a = 0; a < na; a++) {
        int i = alive[a];
        if (B->hits[a].prim == FR_INVALID_ID) continue;
        ch[i] = B->hits[a];
        alive[nn2++] = i;
      }
      na = nn2;
    }
    break;
  }
  default:
    break;
  }

  if (w->gbuf_vis) {
    for (int i = 0; i < n; i++) {
      size_t px = (size_t)B->py[i] * (size_t)W + (size_t)B->px[i];
      const fr_hit *h = &B->prim_hit[i];
      vec3 nn = v3(0, 0, 0);
      if (h->prim != FR_INVALID_ID) nn = facing_normal(w->scene, h, &B->prim_ray[i]);
      w->gbuf_vis[px] = h->prim == FR_INVALID_ID ? 0.0f : lit[i];
      w->gbuf_depth[px] = h->prim == FR_INVALID_ID ? INFINITY : h->t;
      w->gbuf_normal[3 * px] = nn.x; w->gbuf_normal[3 * px + 1] = nn.y; w->gbuf_normal[3 * px + 2] = nn.z;
      vec3 al = h->prim == FR_INVALID_ID ? v3(0, 0, 0) : albedo(w->scene, h->prim);
      w->gbuf_albedo[3 * px] = al.x; w->gbuf_albedo[3 * px + 1] = al.y; w->gbuf_albedo[3 * px + 2] = al.z;
    }
  }
  if (w->image) {
    for (int i = 0; i < n; i++) {
      float *px = w->image + 3 * ((size_t)B->py[i] * (size_t)W + (size_t)B->px[i]);
      const fr_hit *h = &B->prim_hit[i];
      if (h->prim == FR_INVALID_ID) { px[0] = px[1] = px[2] = 0.05f; continue; }
      vec3 d = v3_load(B->prim_ray[i].dir), nn = facing_normal(w->scene, h, &B->prim_ray[i]), c;
      float cosv = fabsf(v3_dot(nn, d));
      if (w->shade == FR_SHADE_NORMALS) {
        c = v3_scale(v3_add(nn, v3(1, 1, 1)), 0.5f);
      } else if (w->shade == FR_SHADE_LIGHT && w->kind == FR_WL_SHADOW) {
        vec3 p = hit_point(&B->prim_ray[i], h), L = v3_norm(v3_sub(w->view.light, p));
        c = v3_scale(albedo(w->scene, h->prim), 0.15f * cosv + 0.85f * lit[i] * fmaxf(0.0f, v3_dot(nn, L)));
      } else if (w->shade == FR_SHADE_LIGHT) {
        c = v3_scale(albedo(w->scene, h->prim), lit[i] * (0.25f + 0.75f * cosv));
      } else {
        c = v3_scale(albedo(w->scene, h->prim), cosv);
      }
      px[0] = c.x; px[1] = c.y; px[2] = c.z;
    }
  }
  return rays;
}

/* order[i]: the i-th tile to trace (y * tiles_x + x), in Morton order, so
 * that the tiles in flight at a time, and those traced one after another,
 * lie close together and share the tree's nodes in the caches. Row order
 * sent both threads along a row 64 tiles long at 1024 x 1024, which on
 * dragon (a 48 MB tree) kept fetching the same nodes anew. Against row
 * order, interleaved pairs, 2 threads, 1024 x 1024 (session 61): dragon
 * soft16 mft 1.036x, packet16 1.029x, Embree's stream mode 1.016x, the
 * other scenes and workloads 0.996-1.014x; blocks of 8 x 8 tiles had read
 * about the same (Morton against them 1.008x). The grid is cut along its
 * long side into squares of a power-of-two side, at least its short side,
 * and each square's codes are walked in order, those outside the grid
 * skipped: at most six codes a tile, and no sort (a qsort of 4,096 tiles'
 * codes cost conference primary 2.7%). NULL without memory: the caller
 * keeps row order. */
static uint32_t *tile_order(int tiles_x, int tiles_y) {
  const uint32_t nx = (uint32_t)tiles_x, ny = (uint32_t)tiles_y, across = nx >= ny;
  const uint32_t along = across ? nx : ny, short_side = across ? ny : nx;
  uint32_t side = 1;
  while (side < short_side) side *= 2;
  uint32_t *order = malloc((size_t)nx * ny * sizeof *order);
  if (!order) return NULL;
  size_t k = 0;
  for (uint32_t base = 0; base < along; base += side)
    for (uint64_t code = 0; code < (uint64_t)side * side; code++) {
      uint32_t u = 0, v = 0; /* u along the long side, v across */
      for (int bit = 0; (side >> bit) > 1; bit++) {
        u |= (uint32_t)((code >> (2 * bit)) & 1u) << bit;
        v |= (uint32_t)((code >> (2 * bit + 1)) & 1u) << bit;
      }
      const uint32_t x = across ? base + u : v, y = across ? v : base + u;
      if (x < nx && y < ny) order[k++] = y * nx + x;
    }
  return order;
}

fr_workload_result fr_workload_run(const fr_workload *w0, const fr_tracer *t) {
  /* the ray sets of this frame, shared by every tile */
  fr_workload run = *w0, *w = &run;
  fr_mft_sets *sets = fr_alloc_aligned(2 * sizeof(fr_mft_sets), 64);
  if (!sets) { fr_workload_result none = {0, 0.0, {0}}; return none; }
  float e1[3] = {w->view.area_e1.x, w->view.area_e1.y, w->view.area_e1.z};
  float e2[3] = {w->view.area_e2.x, w->view.area_e2.y, w->view.area_e2.z};
  fr_mft_sets_light(&sets[0], e1, e2, w->seed, w->light_sets_kind);
  fr_mft_sets_camera(&sets[1], &w->cam);
  run.light_sets = &sets[0];
  run.camera_set = &sets[1];
  const int whitted = w->kind == FR_WL_WHITTED, tile = whitted ? FR_WHITTED_TILE : TILE;
  const int tiles_x = (w->cam.width + tile - 1) / tile, tiles_y = (w->cam.height + tile - 1) / tile;
  const int ntiles = tiles_x * tiles_y;
  uint64_t total = 0;
  double stage[FR_STAGES] = {0};
  int done = 0, last_pct = -1;
  double t0 = fr_seconds();
  uint32_t *order = tile_order(tiles_x, tiles_y);
#pragma omp parallel num_threads(w->threads) reduction(+ : total)
  {
    buffers *B = whitted ? NULL : malloc(sizeof(buffers));
    fr_whitted_scratch *WS = whitted ? fr_whitted_scratch_new() : NULL;
#pragma omp for schedule(dynamic, 1)
    for (int i = 0; i < ntiles; i++) {
      const int k = order ? (int)order[i] : i;
      const int tx = (k % tiles_x) * tile, ty = (k / tiles_x) * tile;
      if (WS) total += fr_whitted_tile(w, t, WS, tx, ty);
      else if (B) total += run_tile(w, t, B, tx, ty);
      if (w->progress) {
        int d, pct;
#pragma omp atomic capture
        d = ++done;
        pct = (int)(100.0 * d / ntiles);
        if (pct / 10 != last_pct / 10 && fr_seconds() - t0 > 1.0) {
#pragma omp critical
          {
            if (pct / 10 != last_pct / 10) { last_pct = pct; fprintf(stderr, "\rrender: %3d%%", pct); fflush(stderr); }
          }
        }
      }
    }
    free(B);
#pragma omp critical
    fr_whitted_scratch_stages(WS, stage);
    fr_whitted_scratch_free(WS);
#ifdef FRUSTA_COUNTERS
    fr_counters_flush();
#endif
  }
  fr_workload_result r = {total, fr_seconds() - t0, {0}};
  free(order);
  memcpy(r.stage, stage, sizeof stage);
  if (w->progress && last_pct >= 0) fprintf(stderr, "\n");
  fr_free_aligned(sets);
  return r;
}

static void frusta_intersect(void *ctx, const fr_ray *rays, fr_hit *hits, size_t n, int coherent) {
  (void)coherent;
  fr_intersect_stream((const fr_scene *)ctx, rays, hits, n);
}

static void frusta_occluded(void *ctx, const fr_ray *rays, uint8_t *occ, size_t n, int coherent) {
  (void)coherent;
  fr_occluded_stream((const fr_scene *)ctx, rays, occ, n);
}

fr_tracer fr_tracer_frusta(const fr_scene *s) {
  fr_tracer t = {(void *)s, frusta_intersect, frusta_occluded, NULL, NULL, 0, NULL};
  return t;
}

static void mft_intersect(void *ctx, const fr_ray *rays, fr_hit *hits, size_t n, int coherent) {
  (void)coherent;
  fr_intersect_stream(((const fr_mft_tracer *)ctx)->scene, rays, hits, n);
}

static void mft_occluded(void *ctx, const fr_ray *rays, uint8_t *occ, size_t n, int coherent) {
  const fr_scene *s = ((const fr_mft_tracer *)ctx)->scene;
  if (coherent == FR_RAYS_DIVERGENT) fr_occluded_raystream(s, rays, occ, n);
  else fr_occluded_stream(s, rays, occ, n);
}

static unsigned mft_intersect_frusta(void *ctx, const fr_mft_batch *b, const fr_mft_sets *t, fr_mft_hits *hits) {
  const fr_mft_tracer *m = ctx;
  return fr_mft_active()->intersect(m->bvh, &m->opts, b, t, hits);
}

static unsigned mft_occluded_frusta(void *ctx, const fr_mft_batch *b, const fr_mft_sets *t,
                                    uint16_t occ[FR_MFT_FRUSTA], fr_mft_budget *budget, fr_mft_occluders *cache) {
  const fr_mft_tracer *m = ctx;
  return fr_mft_active()->occluded(m->shadow_bvh ? m->shadow_bvh : m->bvh, &m->opts, b, t, occ, budget, cache);
}

static const fr_bvh2 *mft_shaft_tree(void *ctx) {
  const fr_mft_tracer *m = ctx;
  return m->shadow_bvh ? m->shadow_bvh : m->bvh;
}

fr_mft_tracer fr_mft_tracer_of(const fr_scene *s, fr_mft_opts opts) {
  fr_mft_tracer m = {s, &s->bvh2_mft, opts, &s->bvh2};
  return m;
}

fr_tracer fr_tracer_mft(const fr_mft_tracer *ctx) {
  fr_tracer t = {(void *)ctx, mft_intersect, mft_occluded, mft_intersect_frusta, mft_occluded_frusta, 0, mft_shaft_tree};
  return t;
}

/* one large packet per thread: about 100 KB, too big for the stack */
static _Thread_local fr_lpacket *lp_packet;

static fr_lpacket *thread_packet(void) {
  if (!lp_packet) lp_packet = fr_alloc_aligned(sizeof(fr_lpacket), 64);
  return lp_packet;
}

/* consecutive packets of side x side rays; closest hits into hits, or any hits into occ */
static void lp_trace(const fr_lp_tracer *c, const fr_ray *rays, fr_hit *hits, uint8_t *occ, size_t n) {
  fr_lpacket *p = thread_packet();
  const size_t size = (size_t)c->side * (size_t)c->side;
  const fr_lp_scene *g = &c->geom;
  for (size_t a = 0; a < n; a += size) {
    int m = (int)(n - a < size ? n - a : size);
    if (!p) { /* no memory for the packet: the same answers from the streams */
      if (occ) fr_occluded_stream(c->scene, rays + a, occ + a, (size_t)m);
      else fr_intersect_stream(c->scene, rays + a, hits + a, (size_t)m);
      continue;
    }
    fr_lpacket_load(p, rays + a, m);
    if (occ) {
      fr_lp_active()->occluded(g, &c->opts, p);
      for (int i = 0; i < m; i++) occ[a + (size_t)i] = (uint8_t)((p->occ[i / 16] >> (i % 16)) & 1);
    } else {
      fr_lp_active()->intersect(g, &c->opts, p);
      fr_lpacket_hits(p, g, hits + a);
    }
  }
}

static void lp_intersect(void *ctx, const fr_ray *rays, fr_hit *hits, size_t n, int coherent) {
  (void)coherent;
  lp_trace(ctx, rays, hits, NULL, n);
}

static void lp_occluded(void *ctx, const fr_ray *rays, uint8_t *occ, size_t n, int coherent) {
  (void)coherent;
  lp_trace(ctx, rays, NULL, occ, n);
}

fr_tracer fr_tracer_lp(const fr_lp_tracer *ctx) {
  fr_tracer t = {(void *)ctx, lp_intersect, lp_occluded, NULL, NULL, ctx->side, NULL};
  return t;
}
