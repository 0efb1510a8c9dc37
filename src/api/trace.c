/* The public tracing calls: single rays, packets of 16, streams, and the
 * choice between the kernels (trace/kernels.h) they make. */
#include <stddef.h>
#include <string.h>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif
#include "base/error.h"
#include "scene.h"
#include "trace/bvh2_reference.h"
#include "trace/kernels.h"
#include "trace/sphere_traverse.h"

/* The single-ray kernels and BVH of the chosen width. */
static inline const fr_trace_fns *single_fns(const fr_scene *s, const fr_bvhn **b) {
  const fr_kernels *k = fr_kernels_active();
  if (s->single_width == 4) { *b = &s->bvh4; return k->w4; }
  *b = &s->bvh8;
  return k->w8;
}

/* The packet kernels of the given size on the packet BVH, with their
 * options. */
static const fr_packet_fns *packet_fns(const fr_scene *s, int size, int threshold, fr_packet_opts *po,
                                       const fr_bvhn **b) {
  const fr_kernels *k = fr_kernels_active();
  int w8 = s->trace.packet_bvh_width == 8;
  *b = w8 ? &s->bvh8 : &s->bvh4;
  po->hybrid_threshold = threshold;
  po->uniform_threshold = threshold < s->trace.coherent_threshold ? threshold : s->trace.coherent_threshold;
  po->mailbox = s->trace.mailbox;
  po->axis_aligned = s->trace.axis_aligned;
  po->ia_cull = s->trace.ia_cull;
  po->quad_leaves = s->trace.quad_leaves;
  po->single = w8 ? k->w8 : k->w4;
  po->use = NULL;
  if (size == 8) return w8 ? k->p8w8 : k->p8w4;
  return w8 ? k->p16w8 : k->p16w4;
}

/* Spheres are traced after the triangles, 16 consecutive rays at a time
 * (trace/sphere_packet.c), each ray's closest hit bounded by the
 * triangles'; a scene without spheres skips this. */
static inline int has_spheres(const fr_scene *s) { return s->sphere_bvh.nprims != 0; }

/* Lane i of R gets ray r, bounded by tfar. */
static void sphere_lane(fr_sphere_rays16 *R, int i, const fr_ray *r, float tfar) {
  for (int a = 0; a < 3; a++) R->o[a][i] = r->org[a], R->d[a][i] = r->dir[a];
  R->tnear[i] = r->tnear, R->tfar[i] = tfar;
}

/* rays[0..m) (m <= 16) but those of `done` against the spheres: closest
 * hits where hits is not NULL (each ray bounded by its hit so far, which a
 * nearer sphere overwrites), else any hits, the rays occluded returned. */
static unsigned spheres_group(const fr_scene *s, const fr_ray *rays, int m, unsigned done, fr_hit *hits) {
  fr_sphere_rays16 R;
  memset(&R, 0, sizeof R);
  unsigned active = 0;
  for (int i = 0; i < m; i++) {
    const fr_ray *r = &rays[i];
    if ((done >> i) & 1 || fr_ray_invalid(r)) continue;
    sphere_lane(&R, i, r, hits && hits[i].prim != FR_INVALID_ID ? hits[i].t : r->tfar);
    active |= 1u << i;
  }
  const unsigned found = fr_kernels_active()->spheres16(&s->sphere_bvh, &R, active, !hits);
  if (hits)
    for (unsigned f = found; f; f &= f - 1) {
      const int i = __builtin_ctz(f);
      fr_spheres_hit(&s->sphere_bvh, fr_scene_sphere_base(s), &rays[i], R.li[i], R.tfar[i], &hits[i]);
    }
  return found;
}

static void spheres_stream(const fr_scene *s, const fr_ray *rays, fr_hit *hits, size_t n) {
  for (size_t g = 0; g < n; g += 16)
    spheres_group(s, rays + g, n - g < 16 ? (int)(n - g) : 16, 0, hits + g);
}

static void spheres_occluded_stream(const fr_scene *s, const fr_ray *rays, uint8_t *occ, size_t n) {
  for (size_t g = 0; g < n; g += 16) {
    const int m = n - g < 16 ? (int)(n - g) : 16;
    unsigned done = 0;
    for (int i = 0; i < m; i++) done |= (unsigned)(occ[g + (size_t)i] != 0) << i;
    if (done == (1u << m) - 1u) continue;
    const unsigned o = spheres_group(s, rays + g, m, done, NULL);
    for (int i = 0; i < m; i++) occ[g + (size_t)i] |= (uint8_t)((o >> i) & 1);
  }
}

static fr_ray lane_ray(const fr_ray16 *r, int i) {
  fr_ray o = {{r->org_x[i], r->org_y[i], r->org_z[i]}, r->tnear[i], {r->dir_x[i], r->dir_y[i], r->dir_z[i]}, r->tfar[i]};
  return o;
}

/* Rays whose range starts behind the origin (tnear < 0) take the scalar
 * reference traversal: the SIMD kernels' box tests widen an exit distance
 * tf as tf * (1 + 2^-20), which narrows it when tf < 0, so they could miss
 * a flat box behind the origin; widening by |tf| there would cost every
 * ray. Such rays are rare. */
static int behind(const fr_ray *r) { return r->tnear < 0.0f; }

/* (a scene of spheres alone has no triangle tree) */
static void intersect_behind(const fr_scene *s, const fr_ray *ray, fr_hit *hit) {
  if (s->bvh2.nprims) fr_bvh2_intersect_reference(&s->bvh2, &s->mesh, ray, hit);
  else fr_hit_miss(hit);
}

static int occluded_behind(const fr_scene *s, const fr_ray *ray) {
  return s->bvh2.nprims && fr_bvh2_occluded_reference(&s->bvh2, &s->mesh, ray);
}

/* Tracing on an uncommitted scene finds nothing rather than crashing. */
void fr_intersect1(const fr_scene *s, const fr_ray *ray, fr_hit *hit) {
  if (!s->committed) { fr_hit_miss(hit); return; }
  const fr_bvhn *b;
  if (behind(ray)) intersect_behind(s, ray, hit);
  else single_fns(s, &b)->intersect1(b, ray, hit);
  if (has_spheres(s)) fr_spheres_intersect1(&s->sphere_bvh, fr_scene_sphere_base(s), ray, hit);
}

int fr_occluded1(const fr_scene *s, const fr_ray *ray) {
  if (!s->committed) return 0;
  const fr_bvhn *b;
  return (behind(ray) ? occluded_behind(s, ray) : single_fns(s, &b)->occluded1(b, ray)) ||
         (has_spheres(s) && fr_spheres_occluded1(&s->sphere_bvh, ray));
}

/* The lanes of valid whose range starts behind the origin. */
static unsigned behind16(const fr_ray16 *r, unsigned valid) {
  unsigned m = 0;
  for (int i = 0; i < 16; i++) m |= (unsigned)(r->tnear[i] < 0.0f) << i;
  return m & valid & 0xFFFF;
}

static void hit16_set(fr_hit16 *h, int i, const fr_hit *x) {
  h->t[i] = x->t; h->u[i] = x->u; h->v[i] = x->v; h->prim[i] = x->prim;
  h->ng_x[i] = x->ng[0]; h->ng_y[i] = x->ng[1]; h->ng_z[i] = x->ng[2];
}

static void hit16_miss(unsigned valid, fr_hit16 *h) {
  for (unsigned m = valid & 0xFFFF; m; m &= m - 1) {
    int i = __builtin_ctz(m);
    h->t[i] = __builtin_inff();
    h->u[i] = h->v[i] = 0.0f;
    h->prim[i] = FR_INVALID_ID;
    h->ng_x[i] = h->ng_y[i] = h->ng_z[i] = 0.0f;
  }
}

void fr_intersect16(const fr_scene *s, unsigned valid, const fr_ray16 *rays, fr_hit16 *hits) {
  if (!s->committed) { hit16_miss(valid, hits); return; }
  fr_packet_opts po;
  const fr_bvhn *b;
  const unsigned back = behind16(rays, valid);
  packet_fns(s, 16, s->trace.hybrid_threshold, &po, &b)->intersect(b, &po, valid & 0xFFFF & ~back, rays, hits);
  for (unsigned m = back; m; m &= m - 1) {
    int i = __builtin_ctz(m);
    fr_ray r = lane_ray(rays, i);
    fr_hit h;
    intersect_behind(s, &r, &h);
    hit16_set(hits, i, &h);
  }
  if (!has_spheres(s)) return;
  fr_ray r[16];
  fr_hit h[16];
  int lane[16], k = 0;
  for (unsigned m = valid & 0xFFFF; m; m &= m - 1, k++) {
    const int i = lane[k] = __builtin_ctz(m);
    r[k] = lane_ray(rays, i);
    h[k] = (fr_hit){hits->t[i], hits->u[i], hits->v[i], hits->prim[i], {hits->ng_x[i], hits->ng_y[i], hits->ng_z[i]}};
  }
  spheres_group(s, r, k, 0, h);
  for (int j = 0; j < k; j++) hit16_set(hits, lane[j], &h[j]);
}

unsigned fr_occluded16(const fr_scene *s, unsigned valid, const fr_ray16 *rays) {
  if (!s->committed) return 0;
  fr_packet_opts po;
  const fr_bvhn *b;
  const unsigned back = behind16(rays, valid);
  unsigned occ = packet_fns(s, 16, s->trace.hybrid_threshold, &po, &b)->occluded(b, &po, valid & 0xFFFF & ~back, rays);
  for (unsigned m = back; m; m &= m - 1) {
    int i = __builtin_ctz(m);
    fr_ray r = lane_ray(rays, i);
    occ |= (unsigned)occluded_behind(s, &r) << i;
  }
  if (has_spheres(s)) {
    fr_ray r[16];
    memset(r, 0, sizeof r);
    int lane[16], k = 0;
    unsigned done = 0;
    for (unsigned m = valid & 0xFFFF; m; m &= m - 1, k++) {
      const int i = lane[k] = __builtin_ctz(m);
      r[k] = lane_ray(rays, i);
      done |= ((occ >> i) & 1u) << k;
    }
    const unsigned o = spheres_group(s, r, k, done, NULL);
    for (int j = 0; j < k; j++) occ |= ((o >> j) & 1u) << lane[j];
  }
  return occ;
}

/* ---- streams ----
 * The explicit packet modes trace consecutive rays together, as the papers
 * measure them. FR_TRACE_AUTO and FR_TRACE_RAYSTREAM first sort each chunk of
 * the stream by direction octant (keeping stream order within an octant), as
 * Embree's stream mode does: rays of neighbouring pixels that leave in the
 * same octant then share a packet or a ray stream, which traverse with one
 * set of near planes. */
#define STREAM_CHUNK 1024

/* A ray's direction octant: bit a is dir[a]'s sign bit. dir and tfar are one
 * 16-byte row of fr_ray, so SSE reads the three bits with one move mask (a
 * third of chunk_order's instructions went to the scalar form). */
_Static_assert(offsetof(fr_ray, tfar) == offsetof(fr_ray, dir) + 3 * sizeof(float), "dir and tfar share a row");
static inline unsigned ray_octant(const fr_ray *r) {
#if defined(__SSE__)
  return (unsigned)_mm_movemask_ps(_mm_loadu_ps(r->dir)) & 7u;
#else
  const float *d = r->dir;
  return (unsigned)((__builtin_signbit(d[0]) != 0) | (__builtin_signbit(d[1]) != 0) << 1 | (__builtin_signbit(d[2]) != 0) << 2);
#endif
}

/* The order in which rays[sel[0..n)] are grouped (sel NULL: rays[0..n)):
 * run_end[r] ends the r-th run, the rays of one octant. Returns the number
 * of runs. */
static int chunk_order(const fr_ray *rays, const uint32_t *sel, size_t n, uint32_t *order, size_t *run_end) {
  size_t start[9] = {0};
  uint8_t oct[STREAM_CHUNK];
  unsigned some = 0, every = 7;
  for (size_t i = 0; i < n; i++) {
    oct[i] = (uint8_t)ray_octant(&rays[sel ? sel[i] : i]);
    some |= oct[i];
    every &= oct[i];
  }
  if (some == every) { /* one octant, as most packets of a renderer's calls: no sort */
    for (size_t i = 0; i < n; i++) order[i] = sel ? sel[i] : (uint32_t)i;
    run_end[0] = n;
    return 1;
  }
  /* counted apart from the scan above: one counter incremented ray after ray
   * is a chain through memory, and most chunks never need the counts */
  for (size_t i = 0; i < n; i++) start[oct[i] + 1]++;
  int runs = 0;
  for (int o = 0; o < 8; o++) {
    start[o + 1] += start[o];
    if (start[o + 1] > start[o]) run_end[runs++] = start[o + 1];
  }
  for (size_t i = 0; i < n; i++) order[start[oct[i]]++] = sel ? sel[i] : (uint32_t)i;
  return runs;
}

static const uint32_t identity_idx[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};

/* Whether a packet of these rays pays: their unit directions lie within
 * chord length spread of the first ray's. A packet's rays then visit nearly
 * the same nodes; past that, lanes die early and a ray stream, which tests
 * each ray alone but shares the node fetches, does better.
 * Three rays spread over the group stand for it: a primary ray takes only
 * ~36 ns of a core, and normalizing all 16 directions would cost more
 * than the probe saves. No
 * square root: with c = 1 - spread^2 / 2 the cosine test
 * dot >= c |d0| |di| is squared. */
static int group_coherent(const fr_ray *rays, const uint32_t *idx, size_t m, float spread) {
  const float *d0 = rays[idx[0]].dir;
  const float n0 = d0[0] * d0[0] + d0[1] * d0[1] + d0[2] * d0[2];
  const float c = 1.0f - 0.5f * spread * spread, c2 = c * c;
  if (c <= 0.0f) return 1; /* no two directions of one octant lie more than 90 degrees apart */
  const size_t probe[3] = {m / 3, 2 * m / 3, m - 1};
  for (int k = 0; k < 3; k++) {
    const float *d = rays[idx[probe[k]]].dir;
    float dot = d0[0] * d[0] + d0[1] * d[1] + d0[2] * d[2];
    float nd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    /* written so that a NaN direction counts as incoherent */
    if (!(dot > 0.0f && dot * dot >= c2 * n0 * nd)) return 0;
  }
  return 1;
}

typedef struct stream_ctx {
  const fr_stream_fns *st;
  const fr_bvhn *sb;           /* the single-ray BVH the streams traverse */
  const fr_packet_fns *pf;     /* packets of 16, for coherent groups */
  const fr_bvhn *pb;
  fr_packet_opts po;
} stream_ctx;

/* One ray stream of rays[idx[0..m)]: occ (any hit) or hits (closest hit). */
static inline void stream_group(const stream_ctx *c, const fr_ray *rays, const uint32_t *idx, int m,
                                uint8_t *occ, fr_hit *hits) {
  if (hits) { c->st->intersect(c->sb, rays, idx, m, hits); return; }
  uint64_t o = c->st->occluded(c->sb, rays, idx, m);
  for (int i = 0; i < m; i++) occ[idx[i]] = (uint8_t)((o >> i) & 1);
}

/* One packet of rays[idx[0..m)]. */
static inline void packet_group(const stream_ctx *c, const fr_ray *rays, const uint32_t *idx, int m,
                                uint8_t *occ, fr_hit *hits) {
  if (hits) { c->pf->intersect_idx(c->pb, &c->po, rays, idx, m, hits); return; }
  unsigned o = c->pf->occluded_idx(c->pb, &c->po, rays, idx, m);
  for (int i = 0; i < m; i++) occ[idx[i]] = (uint8_t)((o >> i) & 1);
}

/* Any-hit packets pay while at most SPARSE_MOST of the leaves they visit
 * are reached by half of their rays or fewer. Coherent rays that part at
 * the scale of the triangles cross that (shadow rays of 4x4 pixel blocks at
 * 1024x1024: 0.87 of dragon's leaves, 0.81 of the hairball's, 0.18-0.32 on
 * the interiors), and ray streams, which test each ray alone, trace them
 * faster (the shadow workload in mft mode: dragon 1.11x, the hairball
 * 1.17x, the interiors 0.99-1.00x). A call decides after PACKET_USE_MIN
 * leaves of its own packets, so its answers depend on its rays alone. */
#define SPARSE_MOST 0.75
#define PACKET_USE_MIN 8

static int packets_pay(const fr_packet_use *u) {
  return u->leaves < PACKET_USE_MIN || (double)u->sparse_leaves <= SPARSE_MOST * (double)u->leaves;
}

/* FR_TRACE_AUTO and FR_TRACE_RAYSTREAM: each coherent group of 16
 * consecutive rays of a chunk goes as a hybrid packet while packets pay;
 * the other rays are sorted by octant, where a group of 16 of one run may
 * still be coherent, and the rest gather into ray streams of up to
 * FR_STREAM_MAX, the last one flushed at the run's end (a stream stays
 * within one octant). spread <= 0: streams only. */
static void octant_trace(const fr_scene *s, const fr_ray *rays, uint8_t *occ, fr_hit *hits, size_t n, float spread) {
  const fr_kernels *k = fr_kernels_active();
  stream_ctx c;
  c.st = s->single_width == 4 ? k->s4 : k->s8;
  c.sb = s->single_width == 4 ? &s->bvh4 : &s->bvh8;
  c.pf = packet_fns(s, 16, s->trace.coherent_threshold, &c.po, &c.pb);
  fr_packet_use use = {0, 0};
  if (occ) c.po.use = &use;
  int packets = spread > 0.0f;
  uint32_t order[STREAM_CHUNK], pend[FR_STREAM_MAX], rest[STREAM_CHUNK];
  size_t run_end[8];
  const size_t min_packet = (size_t)s->trace.hybrid_threshold + 1;
  for (size_t c0 = 0; c0 < n; c0 += STREAM_CHUNK) {
    size_t cn = n - c0 < STREAM_CHUNK ? n - c0 : STREAM_CHUNK;
    const fr_ray *cr = rays + c0;
    uint8_t *co = occ ? occ + c0 : NULL;
    fr_hit *ch = hits ? hits + c0 : NULL;
    const uint32_t *sel = NULL;
    size_t ns = cn;
    if (spread > 0.0f) {
      /* Coherent groups of 16 in the caller's order go as packets before any
       * sort: a renderer's neighbouring pixels are most often one coherent
       * group already, and then the octant sort only costs. */
      ns = 0;
      for (size_t g = 0, m; g < cn; g += m) {
        m = cn - g < 16 ? cn - g : 16;
        if (packets && m >= min_packet && group_coherent(cr + g, identity_idx, m, spread)) {
          packet_group(&c, cr + g, identity_idx, (int)m, co ? co + g : NULL, ch ? ch + g : NULL);
          packets = packets_pay(&use);
          continue;
        }
        for (size_t i = 0; i < m; i++) rest[ns++] = (uint32_t)(g + i);
      }
      if (!ns) continue;
      sel = rest;
    }
    int runs = chunk_order(cr, sel, ns, order, run_end);
    size_t g = 0;
    for (int r = 0; r < runs; r++) {
      int np = 0;
      for (size_t m; g < run_end[r]; g += m) {
        m = run_end[r] - g < 16 ? run_end[r] - g : 16;
        const uint32_t *idx = order + g;
        if (packets && m >= min_packet && group_coherent(cr, idx, m, spread)) {
          packet_group(&c, cr, idx, (int)m, co, ch);
          packets = packets_pay(&use);
          continue;
        }
        for (size_t i = 0; i < m; i++) {
          pend[np++] = idx[i];
          if (np == FR_STREAM_MAX) { stream_group(&c, cr, pend, np, co, ch); np = 0; }
        }
      }
      if (np) stream_group(&c, cr, pend, np, co, ch);
    }
  }
}

/* The explicit packet modes: the packet size, and the hybrid threshold. */
static int packet_size(const fr_scene *s, int *threshold) {
  *threshold = s->trace.mode == FR_TRACE_HYBRID16 ? s->trace.hybrid_threshold : 0;
  return s->trace.mode == FR_TRACE_PACKET8 ? 8 : 16;
}

/* The triangles of a stream: any hit into occ, or closest hits into hits;
 * the spheres follow in the public calls. */
static void triangles_stream(const fr_scene *s, const fr_ray *rays, uint8_t *occ, fr_hit *hits, size_t n) {
  switch (s->trace.mode) {
  case FR_TRACE_SINGLE: {
    const fr_bvhn *sb;
    const fr_trace_fns *single = single_fns(s, &sb);
    if (hits) single->intersect_stream(sb, rays, hits, n);
    else single->occluded_stream(sb, rays, occ, n, s->trace.occluder_cache, s->trace.anyhit_order);
    return;
  }
  case FR_TRACE_AUTO: octant_trace(s, rays, occ, hits, n, s->trace.stream_spread); return;
  case FR_TRACE_RAYSTREAM: octant_trace(s, rays, occ, hits, n, -1.0f); return;
  default: break;
  }
  int threshold, size = packet_size(s, &threshold);
  fr_packet_opts po;
  const fr_bvhn *pb;
  const fr_packet_fns *pf = packet_fns(s, size, threshold, &po, &pb);
  for (size_t g = 0, m; g < n; g += m) {
    m = n - g < (size_t)size ? n - g : (size_t)size;
    if (hits) { pf->intersect_idx(pb, &po, rays + g, identity_idx, (int)m, hits + g); continue; }
    unsigned o = pf->occluded_idx(pb, &po, rays + g, identity_idx, (int)m);
    for (size_t i = 0; i < m; i++) occ[g + i] = (uint8_t)((o >> i) & 1);
  }
}

/* A stream's rays behind the origin, traced again by the reference (the
 * stream kernels saw them too: one pass over the stream afterwards keeps
 * every stream path as it is). */
static void stream_behind(const fr_scene *s, const fr_ray *rays, uint8_t *occ, fr_hit *hits, size_t n) {
  for (size_t i = 0; i < n; i++) {
    if (!behind(&rays[i])) continue;
    if (hits) intersect_behind(s, &rays[i], &hits[i]);
    else occ[i] = (uint8_t)occluded_behind(s, &rays[i]);
  }
}

void fr_intersect_stream(const fr_scene *s, const fr_ray *rays, fr_hit *hits, size_t n) {
  if (!s->committed) { for (size_t i = 0; i < n; i++) fr_hit_miss(&hits[i]); return; }
  triangles_stream(s, rays, NULL, hits, n);
  stream_behind(s, rays, NULL, hits, n);
  if (has_spheres(s)) spheres_stream(s, rays, hits, n);
}

void fr_occluded_raystream(const fr_scene *s, const fr_ray *rays, uint8_t *occ, size_t n) {
  if (!s->committed) { memset(occ, 0, n); return; }
  octant_trace(s, rays, occ, NULL, n, -1.0f);
  stream_behind(s, rays, occ, NULL, n);
  if (has_spheres(s)) spheres_occluded_stream(s, rays, occ, n);
}

void fr_occluded_stream(const fr_scene *s, const fr_ray *rays, uint8_t *occ, size_t n) {
  if (!s->committed) { memset(occ, 0, n); return; }
  triangles_stream(s, rays, occ, NULL, n);
  stream_behind(s, rays, occ, NULL, n);
  if (has_spheres(s)) spheres_occluded_stream(s, rays, occ, n);
}
