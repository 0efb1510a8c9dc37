#include "embree_tracer.h"
#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "base/timer.h"
#include "base/vec3.h"

struct ebr_scene {
  RTCDevice dev;
  RTCScene scene;
  double build_seconds;
  uint32_t sphere_base;   /* frusta's prim of Embree's sphere 0 (geometry 1) */
  _Atomic long long bytes;
  struct ebr_ctx {
    struct ebr_scene *e;
    ebr_mode mode;
    ebr_flag flag;
    ebr_packing packing;
  } ctx[EBR_MODE_COUNT][EBR_FLAG_COUNT][EBR_PACK_COUNT];
};

static const char *mode_names[EBR_MODE_COUNT] = {"single", "packet4", "packet8", "packet16", "stream"};
const char *ebr_mode_name(ebr_mode m) { return m < EBR_MODE_COUNT ? mode_names[m] : "?"; }
int ebr_mode_parse(const char *name, ebr_mode *m) {
  for (int i = 0; i < EBR_MODE_COUNT; i++)
    if (strcmp(name, mode_names[i]) == 0) { *m = (ebr_mode)i; return 1; }
  return 0;
}

static bool memory_monitor(void *user, ssize_t bytes, bool post) {
  (void)post;
  ebr_scene *e = user;
  atomic_fetch_add(&e->bytes, (long long)bytes);
  return true;
}

fr_error ebr_create(const fr_scene *s, ebr_options opt, ebr_scene **out) {
  *out = NULL;
  ebr_scene *e = calloc(1, sizeof *e);
  if (!e) return FR_ERR_NOMEM;
  char cfg[64];
  snprintf(cfg, sizeof cfg, "threads=%d,verbose=%d", opt.threads > 0 ? opt.threads : 0, opt.verbose);
  e->dev = rtcNewDevice(cfg);
  if (!e->dev) { free(e); return FR_ERR_UNSUPPORTED; }
  rtcSetDeviceMemoryMonitorFunction(e->dev, memory_monitor, e);
  e->scene = rtcNewScene(e->dev);
  rtcSetSceneFlags(e->scene, opt.robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
  rtcSetSceneBuildQuality(e->scene, opt.quality == 2 ? RTC_BUILD_QUALITY_HIGH : opt.quality == 0 ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM);
  enum RTCBuildQuality quality = opt.quality == 2 ? RTC_BUILD_QUALITY_HIGH : opt.quality == 0 ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM;
  size_t nv = fr_scene_vertex_count(s), nt = fr_scene_triangle_count(s), ns = fr_scene_sphere_count(s);
  e->sphere_base = (uint32_t)nt;
  if (nt) { /* geometry 0: the triangles */
    RTCGeometry g = rtcNewGeometry(e->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    /* Embree reads 16 bytes per vertex: pad the last one */
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv + 1);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt);
    if (!vb || !ib) { rtcReleaseGeometry(g); ebr_release(e); return FR_ERR_NOMEM; }
    memcpy(vb, fr_scene_vertices(s), nv * 3 * sizeof(float));
    memcpy(ib, fr_scene_indices(s), nt * 3 * sizeof(unsigned));
    rtcSetGeometryBuildQuality(g, quality);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(e->scene, g, 0);
    rtcReleaseGeometry(g);
  }
  if (ns) { /* geometry 1: the spheres, as Embree's sphere points (x, y, z, r) */
    RTCGeometry g = rtcNewGeometry(e->dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    float *pb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), ns);
    if (!pb) { rtcReleaseGeometry(g); ebr_release(e); return FR_ERR_NOMEM; }
    for (size_t i = 0; i < ns; i++) fr_scene_sphere(s, i, pb + 4 * i, pb + 4 * i + 3);
    rtcSetGeometryBuildQuality(g, quality);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(e->scene, g, 1);
    rtcReleaseGeometry(g);
  }
  atomic_store(&e->bytes, 0); /* count the acceleration structure, not the copied buffers */
  double t0 = fr_seconds();
  rtcCommitScene(e->scene);
  e->build_seconds = fr_seconds() - t0;
  if (rtcGetDeviceError(e->dev) != RTC_ERROR_NONE) { ebr_release(e); return FR_ERR_UNSUPPORTED; }
  for (int i = 0; i < EBR_MODE_COUNT; i++)
    for (int f = 0; f < EBR_FLAG_COUNT; f++)
      for (int p = 0; p < EBR_PACK_COUNT; p++)
        e->ctx[i][f][p] = (struct ebr_ctx){e, (ebr_mode)i, (ebr_flag)f, (ebr_packing)p};
  *out = e;
  return FR_OK;
}

void ebr_release(ebr_scene *e) {
  if (!e) return;
  if (e->scene) rtcReleaseScene(e->scene);
  if (e->dev) rtcReleaseDevice(e->dev);
  free(e);
}

double ebr_build_seconds(const ebr_scene *e) { return e->build_seconds; }
size_t ebr_bytes(const ebr_scene *e) { long long b = atomic_load(&e->bytes); return b > 0 ? (size_t)b : 0; }

static void to_rayhit1(const fr_ray *r, struct RTCRayHit *rh) {
  rh->ray.org_x = r->org[0]; rh->ray.org_y = r->org[1]; rh->ray.org_z = r->org[2];
  rh->ray.dir_x = r->dir[0]; rh->ray.dir_y = r->dir[1]; rh->ray.dir_z = r->dir[2];
  rh->ray.tnear = r->tnear; rh->ray.tfar = r->tfar;
  rh->ray.time = 0; rh->ray.mask = 0xFFFFFFFFu; rh->ray.id = 0; rh->ray.flags = 0;
  rh->hit.geomID = RTC_INVALID_GEOMETRY_ID; rh->hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

static void from_hit(const ebr_scene *e, float tfar, unsigned geom, unsigned prim, float u, float v, float nx, float ny,
                     float nz, fr_hit *h) {
  if (geom == RTC_INVALID_GEOMETRY_ID) {
    h->t = INFINITY; h->u = h->v = 0; h->prim = FR_INVALID_ID; h->ng[0] = h->ng[1] = h->ng[2] = 0;
    return;
  }
  h->t = tfar; h->u = u; h->v = v; h->prim = geom == 1 ? e->sphere_base + prim : prim;
  h->ng[0] = nx; h->ng[1] = ny; h->ng[2] = nz;
}

void ebr_intersect1(ebr_scene *e, const fr_ray *r, fr_hit *h) {
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  struct RTCRayHit rh;
  to_rayhit1(r, &rh);
  rtcIntersect1(e->scene, &ctx, &rh);
  from_hit(e, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z, h);
}

int ebr_occluded1(ebr_scene *e, const fr_ray *r) {
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  struct RTCRayHit rh;
  to_rayhit1(r, &rh);
  rtcOccluded1(e->scene, &ctx, &rh.ray);
  return rh.ray.tfar < 0.0f;
}

/* Packets of width W through rtcIntersectW / rtcOccludedW (SoA layouts). */
#define PACKET_FUNCS(W)                                                                                   \
  static void intersect_p##W(ebr_scene *e, struct RTCIntersectContext *ctx, const fr_ray *r, fr_hit *h, size_t n) { \
    for (size_t b = 0; b < n; b += W) {                                                                   \
      struct RTCRayHit##W rh;                                                                             \
      int valid[W] __attribute__((aligned(64))); /* aligned as the packet: Embree loads it so */          \
      for (int i = 0; i < W; i++) {                                                                       \
        size_t k = b + (size_t)i < n ? b + (size_t)i : b;                                                 \
        valid[i] = b + (size_t)i < n ? -1 : 0;                                                            \
        rh.ray.org_x[i] = r[k].org[0]; rh.ray.org_y[i] = r[k].org[1]; rh.ray.org_z[i] = r[k].org[2];     \
        rh.ray.dir_x[i] = r[k].dir[0]; rh.ray.dir_y[i] = r[k].dir[1]; rh.ray.dir_z[i] = r[k].dir[2];     \
        rh.ray.tnear[i] = r[k].tnear; rh.ray.tfar[i] = r[k].tfar; rh.ray.time[i] = 0;                    \
        rh.ray.mask[i] = 0xFFFFFFFFu; rh.ray.id[i] = 0; rh.ray.flags[i] = 0;                             \
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID; rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;       \
      }                                                                                                   \
      rtcIntersect##W(valid, e->scene, ctx, &rh);                                                         \
      for (int i = 0; i < W && b + (size_t)i < n; i++)                                                    \
        from_hit(e, rh.ray.tfar[i], rh.hit.geomID[i], rh.hit.primID[i], rh.hit.u[i], rh.hit.v[i],           \
                 rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i], &h[b + (size_t)i]);                      \
    }                                                                                                     \
  }                                                                                                       \
  static void occluded_p##W(ebr_scene *e, struct RTCIntersectContext *ctx, const fr_ray *r, uint8_t *o, size_t n) { \
    for (size_t b = 0; b < n; b += W) {                                                                   \
      struct RTCRay##W ry;                                                                                \
      int valid[W] __attribute__((aligned(64))); /* aligned as the packet: Embree loads it so */          \
      for (int i = 0; i < W; i++) {                                                                       \
        size_t k = b + (size_t)i < n ? b + (size_t)i : b;                                                 \
        valid[i] = b + (size_t)i < n ? -1 : 0;                                                            \
        ry.org_x[i] = r[k].org[0]; ry.org_y[i] = r[k].org[1]; ry.org_z[i] = r[k].org[2];                 \
        ry.dir_x[i] = r[k].dir[0]; ry.dir_y[i] = r[k].dir[1]; ry.dir_z[i] = r[k].dir[2];                 \
        ry.tnear[i] = r[k].tnear; ry.tfar[i] = r[k].tfar; ry.time[i] = 0;                                \
        ry.mask[i] = 0xFFFFFFFFu; ry.id[i] = 0; ry.flags[i] = 0;                                         \
      }                                                                                                   \
      rtcOccluded##W(valid, e->scene, ctx, &ry);                                                          \
      for (int i = 0; i < W && b + (size_t)i < n; i++) o[b + (size_t)i] = ry.tfar[i] < 0.0f;             \
    }                                                                                                     \
  }
PACKET_FUNCS(4)
PACKET_FUNCS(8)
PACKET_FUNCS(16)

static struct RTCIntersectContext make_context(ebr_flag flag, int coherent) {
  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  const int c = flag == EBR_FLAG_HINT ? coherent > 0 : flag == EBR_FLAG_COHERENT;
  ctx.flags = c ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  return ctx;
}

static void intersect_rays(ebr_scene *e, ebr_mode mode, struct RTCIntersectContext *ctx, const fr_ray *rays,
                           fr_hit *hits, size_t n) {
  switch (mode) {
  case EBR_PACKET4: intersect_p4(e, ctx, rays, hits, n); return;
  case EBR_PACKET8: intersect_p8(e, ctx, rays, hits, n); return;
  case EBR_PACKET16: intersect_p16(e, ctx, rays, hits, n); return;
  case EBR_STREAM: {
    struct RTCRayHit rh[64];
    for (size_t b = 0; b < n; b += 64) {
      size_t m = n - b < 64 ? n - b : 64;
      for (size_t i = 0; i < m; i++) to_rayhit1(&rays[b + i], &rh[i]);
      rtcIntersect1M(e->scene, ctx, rh, (unsigned)m, sizeof(struct RTCRayHit));
      for (size_t i = 0; i < m; i++)
        from_hit(e, rh[i].ray.tfar, rh[i].hit.geomID, rh[i].hit.primID, rh[i].hit.u, rh[i].hit.v, rh[i].hit.Ng_x,
                 rh[i].hit.Ng_y, rh[i].hit.Ng_z, &hits[b + i]);
    }
    return;
  }
  default:
    for (size_t i = 0; i < n; i++) {
      struct RTCRayHit rh;
      to_rayhit1(&rays[i], &rh);
      rtcIntersect1(e->scene, ctx, &rh);
      from_hit(e, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z,
               &hits[i]);
    }
  }
}

static void occluded_rays(ebr_scene *e, ebr_mode mode, struct RTCIntersectContext *ctx, const fr_ray *rays,
                          uint8_t *occ, size_t n) {
  switch (mode) {
  case EBR_PACKET4: occluded_p4(e, ctx, rays, occ, n); return;
  case EBR_PACKET8: occluded_p8(e, ctx, rays, occ, n); return;
  case EBR_PACKET16: occluded_p16(e, ctx, rays, occ, n); return;
  case EBR_STREAM: {
    struct RTCRay r[64];
    for (size_t b = 0; b < n; b += 64) {
      size_t m = n - b < 64 ? n - b : 64;
      for (size_t i = 0; i < m; i++) { struct RTCRayHit t; to_rayhit1(&rays[b + i], &t); r[i] = t.ray; }
      rtcOccluded1M(e->scene, ctx, r, (unsigned)m, sizeof(struct RTCRay));
      for (size_t i = 0; i < m; i++) occ[b + i] = r[i].tfar < 0.0f;
    }
    return;
  }
  default:
    for (size_t i = 0; i < n; i++) {
      struct RTCRayHit rh;
      to_rayhit1(&rays[i], &rh);
      rtcOccluded1(e->scene, ctx, &rh.ray);
      occ[i] = rh.ray.tfar < 0.0f;
    }
  }
}

/* EBR_PACK_SAMPLES: the rays come in runs of 16 per pixel (soft16, ao16);
 * each chunk of up to 16 runs is traced sample by sample, so that a packet
 * holds one sample of up to 16 neighbouring pixels. perm[j] is the call's
 * ray that goes j-th in a chunk of runs runs. */
#define EBR_CHUNK 256
static void sample_order(size_t runs, uint16_t *perm) {
  for (size_t k = 0; k < 16; k++)
    for (size_t p = 0; p < runs; p++) perm[k * runs + p] = (uint16_t)(16 * p + k);
}

static void ebr_intersect(void *c, const fr_ray *rays, fr_hit *hits, size_t n, int coherent) {
  struct ebr_ctx *x = c;
  struct RTCIntersectContext ctx = make_context(x->flag, coherent);
  if (x->packing != EBR_PACK_SAMPLES || n % 16) { intersect_rays(x->e, x->mode, &ctx, rays, hits, n); return; }
  fr_ray r[EBR_CHUNK];
  fr_hit h[EBR_CHUNK];
  uint16_t perm[EBR_CHUNK];
  for (size_t b = 0; b < n; b += EBR_CHUNK) {
    const size_t m = n - b < EBR_CHUNK ? n - b : EBR_CHUNK;
    sample_order(m / 16, perm);
    for (size_t j = 0; j < m; j++) r[j] = rays[b + perm[j]];
    intersect_rays(x->e, x->mode, &ctx, r, h, m);
    for (size_t j = 0; j < m; j++) hits[b + perm[j]] = h[j];
  }
}

static void ebr_occluded(void *c, const fr_ray *rays, uint8_t *occ, size_t n, int coherent) {
  struct ebr_ctx *x = c;
  struct RTCIntersectContext ctx = make_context(x->flag, coherent);
  if (x->packing != EBR_PACK_SAMPLES || n % 16) { occluded_rays(x->e, x->mode, &ctx, rays, occ, n); return; }
  fr_ray r[EBR_CHUNK];
  uint8_t o[EBR_CHUNK];
  uint16_t perm[EBR_CHUNK];
  for (size_t b = 0; b < n; b += EBR_CHUNK) {
    const size_t m = n - b < EBR_CHUNK ? n - b : EBR_CHUNK;
    sample_order(m / 16, perm);
    for (size_t j = 0; j < m; j++) r[j] = rays[b + perm[j]];
    occluded_rays(x->e, x->mode, &ctx, r, o, m);
    for (size_t j = 0; j < m; j++) occ[b + perm[j]] = o[j];
  }
}

fr_tracer ebr_tracer(ebr_scene *e, ebr_mode m, ebr_flag flag, ebr_packing packing) {
  fr_tracer t = {&e->ctx[m][flag][packing], ebr_intersect, ebr_occluded, NULL, NULL, 0, NULL};
  return t;
}

static const char *flag_names[EBR_FLAG_COUNT] = {"hint", "coherent", "incoherent"};
static const char *packing_names[EBR_PACK_COUNT] = {"rays", "samples"};
const char *ebr_flag_name(ebr_flag f) { return f < EBR_FLAG_COUNT ? flag_names[f] : "?"; }
const char *ebr_packing_name(ebr_packing p) { return p < EBR_PACK_COUNT ? packing_names[p] : "?"; }
int ebr_flag_parse(const char *name, ebr_flag *f) {
  for (int i = 0; i < EBR_FLAG_COUNT; i++)
    if (strcmp(name, flag_names[i]) == 0) { *f = (ebr_flag)i; return 1; }
  return 0;
}
int ebr_packing_parse(const char *name, ebr_packing *p) {
  for (int i = 0; i < EBR_PACK_COUNT; i++)
    if (strcmp(name, packing_names[i]) == 0) { *p = (ebr_packing)i; return 1; }
  return 0;
}

/* ---- Embree's builder on its own, for the SAH comparison ----------------- */

typedef struct bnode { int leaf; unsigned n; struct bnode *kids[4]; struct RTCBounds box[4]; } bnode;

static void *create_node(RTCThreadLocalAllocator a, unsigned count, void *u) {
  bnode *n = rtcThreadLocalAlloc(a, sizeof(bnode), 16);
  memset(n, 0, sizeof *n);
  n->n = count;
  return n;
}
static void set_children(void *p, void **kids, unsigned count, void *u) {
  bnode *n = p;
  for (unsigned i = 0; i < count; i++) n->kids[i] = kids[i];
}
static void set_bounds(void *p, const struct RTCBounds **b, unsigned count, void *u) {
  bnode *n = p;
  for (unsigned i = 0; i < count; i++) n->box[i] = *b[i];
}
static void *create_leaf(RTCThreadLocalAllocator a, const struct RTCBuildPrimitive *prims, size_t count, void *u) {
  bnode *n = rtcThreadLocalAlloc(a, sizeof(bnode), 16);
  memset(n, 0, sizeof *n);
  n->leaf = 1;
  n->n = (unsigned)count;
  return n;
}

/* Exact bounds of the two halves of a triangle cut by an axis plane. */
static void split_prim(const struct RTCBuildPrimitive *p, unsigned dim, float pos, struct RTCBounds *l, struct RTCBounds *r, void *u) {
  const fr_scene *s = u;
  const float *v = fr_scene_vertices(s);
  const uint32_t *ix = fr_scene_indices(s) + 3 * (size_t)p->primID;
  aabb L = aabb_empty(), R = aabb_empty();
  for (int i = 0; i < 3; i++) {
    vec3 a = v3_load(v + 3 * (size_t)ix[i]), b = v3_load(v + 3 * (size_t)ix[(i + 1) % 3]);
    float da = v3_get(a, (int)dim), db = v3_get(b, (int)dim);
    if (da <= pos) L = aabb_grow(L, a);
    if (da >= pos) R = aabb_grow(R, a);
    if ((da < pos && db > pos) || (da > pos && db < pos)) {
      float t = (pos - da) / (db - da);
      vec3 c = v3_add(a, v3_scale(v3_sub(b, a), t));
      if (dim == 0) c.x = pos; else if (dim == 1) c.y = pos; else c.z = pos;
      L = aabb_grow(L, c);
      R = aabb_grow(R, c);
    }
  }
  /* clamp to the primitive's current (possibly already split) box */
  aabb P = {{p->lower_x, p->lower_y, p->lower_z}, {p->upper_x, p->upper_y, p->upper_z}};
  L.lo = v3_max(L.lo, P.lo); L.hi = v3_min(L.hi, P.hi);
  R.lo = v3_max(R.lo, P.lo); R.hi = v3_min(R.hi, P.hi);
  *l = (struct RTCBounds){L.lo.x, L.lo.y, L.lo.z, 0, L.hi.x, L.hi.y, L.hi.z, 0};
  *r = (struct RTCBounds){R.lo.x, R.lo.y, R.lo.z, 0, R.hi.x, R.hi.y, R.hi.z, 0};
}

static double area(const struct RTCBounds *b) {
  double dx = b->upper_x - b->lower_x, dy = b->upper_y - b->lower_y, dz = b->upper_z - b->lower_z;
  return dx * dy + dy * dz + dz * dx;
}

/* cost of a leaf: per triangle (blocks == 0) or per 4-triangle block */
static double sah_rec(const bnode *n, double node_area, double root, int blocks) {
  if (n->leaf) return node_area / root * (blocks ? (n->n + 3) / 4 : n->n);
  double c = node_area / root;
  for (unsigned i = 0; i < n->n; i++) c += sah_rec(n->kids[i], area(&n->box[i]), root, blocks);
  return c;
}

fr_error ebr_builder_sah(const fr_scene *s, int threads, int quality, double *sah, double *sah_blocks, double *seconds) {
  char cfg[64];
  snprintf(cfg, sizeof cfg, "threads=%d", threads > 0 ? threads : 0);
  RTCDevice dev = rtcNewDevice(cfg);
  if (!dev) return FR_ERR_UNSUPPORTED;
  size_t nt = fr_scene_triangle_count(s), cap = quality == 2 ? 2 * nt : nt, n = 0;
  struct RTCBuildPrimitive *prims = malloc(cap * sizeof *prims);
  if (!prims) { rtcReleaseDevice(dev); return FR_ERR_NOMEM; }
  const float *v = fr_scene_vertices(s);
  const uint32_t *ix = fr_scene_indices(s);
  aabb root = aabb_empty();
  for (size_t t = 0; t < nt; t++) {
    if (!fr_mesh_triangle_traceable(&s->mesh, t)) continue; /* the triangles frusta builds over, no more */
    aabb b = aabb_empty();
    for (int k = 0; k < 3; k++) b = aabb_grow(b, v3_load(v + 3 * (size_t)ix[3 * t + k]));
    prims[n] = (struct RTCBuildPrimitive){b.lo.x, b.lo.y, b.lo.z, 0, b.hi.x, b.hi.y, b.hi.z, (unsigned)t};
    n++;
    root = aabb_merge(root, b);
  }
  RTCBVH bvh = rtcNewBVH(dev);
  struct RTCBuildArguments a = rtcDefaultBuildArguments();
  a.buildQuality = quality == 2 ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
  a.maxBranchingFactor = 4;
  a.maxDepth = 64;
  a.sahBlockSize = 4;
  a.minLeafSize = 1;
  a.maxLeafSize = 4;
  a.bvh = bvh;
  a.primitives = prims;
  a.primitiveCount = n;
  a.primitiveArrayCapacity = cap;
  a.createNode = create_node;
  a.setNodeChildren = set_children;
  a.setNodeBounds = set_bounds;
  a.createLeaf = create_leaf;
  a.splitPrimitive = quality == 2 ? split_prim : NULL;
  a.userPtr = (void *)s;
  double t0 = fr_seconds();
  bnode *r = rtcBuildBVH(&a);
  *seconds = fr_seconds() - t0;
  struct RTCBounds rb = {root.lo.x, root.lo.y, root.lo.z, 0, root.hi.x, root.hi.y, root.hi.z, 0};
  double ra = area(&rb);
  *sah = r ? sah_rec(r, ra, ra, 0) : 0.0;
  *sah_blocks = r ? sah_rec(r, ra, ra, 1) : 0.0;
  rtcReleaseBVH(bvh);
  free(prims);
  rtcReleaseDevice(dev);
  return r ? FR_OK : FR_ERR_UNSUPPORTED;
}
