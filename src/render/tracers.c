/*
 * frusta's tracers for the workloads (render/tracer.h): streams as the
 * scene's trace mode says, multi-frusta, and large packets.
 */
#include "render/tracer.h"
#include "api/scene.h"
#include "base/alloc.h"

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

