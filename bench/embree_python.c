/*
 * Embree 3 called from Python the way embreex and pyembree call it: numpy
 * arrays of origins and directions are packed into RTCRayHit records and
 * traced with rtcIntersect1M / rtcOccluded1M, the rays split over threads.
 * For the comparison in bench/python_vs_embree.py only (loaded with
 * ctypes); it also offers Embree's 16-wide packets, so that the benchmark
 * can give Embree its faster packing and coherence flag for each workload.
 *
 *   cc -O2 -fPIC -shared -fopenmp bench/embree_python.c -lembree3 -o libembree_python.so
 */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#define CHUNK 1024

typedef struct ebp_scene {
  RTCDevice dev;
  RTCScene scene;
} ebp_scene;

/* The high-quality build of one triangle mesh (copied). NULL on failure. */
ebp_scene *ebp_scene_new(const float *v, size_t nv, const uint32_t *t, size_t nt) {
  ebp_scene *s = calloc(1, sizeof *s);
  if (!s) return NULL;
  s->dev = rtcNewDevice(NULL);
  if (!s->dev) { free(s); return NULL; }
  s->scene = rtcNewScene(s->dev);
  rtcSetSceneBuildQuality(s->scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry g = rtcNewGeometry(s->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv + 1);
  unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt);
  memcpy(vb, v, nv * 3 * sizeof(float));
  memcpy(ib, t, nt * 3 * sizeof(unsigned));
  rtcSetGeometryBuildQuality(g, RTC_BUILD_QUALITY_HIGH);
  rtcCommitGeometry(g);
  rtcAttachGeometry(s->scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(s->scene);
  return s;
}

void ebp_scene_free(ebp_scene *s) {
  if (!s) return;
  rtcReleaseScene(s->scene);
  rtcReleaseDevice(s->dev);
  free(s);
}

static void context(struct RTCIntersectContext *c, int coherent) {
  rtcInitIntersectContext(c);
  c->flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
}

static void pack(struct RTCRay *r, const float *o, const float *d, const float *tnear, const float *tfar, size_t i) {
  r->org_x = o[3 * i]; r->org_y = o[3 * i + 1]; r->org_z = o[3 * i + 2];
  r->dir_x = d[3 * i]; r->dir_y = d[3 * i + 1]; r->dir_z = d[3 * i + 2];
  r->tnear = tnear ? tnear[i] : 0.0f; r->tfar = tfar ? tfar[i] : INFINITY;
  r->time = 0; r->mask = 0xFFFFFFFFu; r->id = 0; r->flags = 0;
}

/* Rays [first, first + 16) of n as a packet; lanes past n repeat ray
 * first and are left out of valid. */
static void pack16(struct RTCRay16 *r, int valid[16], const float *o, const float *d, const float *tnear,
                   const float *tfar, size_t first, size_t n) {
  for (int l = 0; l < 16; l++) {
    size_t i = first + (size_t)l;
    valid[l] = i < n ? -1 : 0;
    if (!valid[l]) i = first;
    r->org_x[l] = o[3 * i]; r->org_y[l] = o[3 * i + 1]; r->org_z[l] = o[3 * i + 2];
    r->dir_x[l] = d[3 * i]; r->dir_y[l] = d[3 * i + 1]; r->dir_z[l] = d[3 * i + 2];
    r->tnear[l] = tnear ? tnear[i] : 0.0f; r->tfar[l] = tfar ? tfar[i] : INFINITY;
    r->time[l] = 0; r->mask[l] = 0xFFFFFFFFu; r->id[l] = 0; r->flags[l] = 0;
  }
}

/* Closest hits: t (inf on a miss) and prim (0xFFFFFFFF on a miss), u, v.
 * tnear and tfar: one per ray, or NULL for 0 and inf. packet16:
 * rtcIntersect16 on consecutive rays instead of rtcIntersect1M. */
void ebp_intersect(const ebp_scene *s, const float *o, const float *d, size_t n, const float *tnear, const float *tfar,
                   float *t, uint32_t *prim, float *u, float *v, int coherent, int packet16, int threads) {
  size_t chunks = (n + CHUNK - 1) / CHUNK;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (size_t c = 0; c < chunks; c++) {
    struct RTCIntersectContext ctx;
    context(&ctx, coherent);
    size_t i0 = c * CHUNK, k = n - i0 < CHUNK ? n - i0 : CHUNK;
    if (!packet16) {
      struct RTCRayHit rh[CHUNK];
      for (size_t j = 0; j < k; j++) {
        pack(&rh[j].ray, o, d, tnear, tfar, i0 + j);
        rh[j].hit.geomID = rh[j].hit.primID = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect1M(s->scene, &ctx, rh, (unsigned)k, sizeof(struct RTCRayHit));
      for (size_t j = 0; j < k; j++) {
        int hit = rh[j].hit.geomID != RTC_INVALID_GEOMETRY_ID;
        t[i0 + j] = hit ? rh[j].ray.tfar : INFINITY;
        prim[i0 + j] = hit ? rh[j].hit.primID : 0xFFFFFFFFu;
        u[i0 + j] = rh[j].hit.u; v[i0 + j] = rh[j].hit.v;
      }
      continue;
    }
    for (size_t b = 0; b < k; b += 16) {
      struct RTCRayHit16 rh;
      int valid[16];
      pack16(&rh.ray, valid, o, d, tnear, tfar, i0 + b, i0 + k);
      for (int l = 0; l < 16; l++) rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect16(valid, s->scene, &ctx, &rh);
      for (int l = 0; l < 16 && b + (size_t)l < k; l++) {
        size_t i = i0 + b + (size_t)l;
        int hit = rh.hit.geomID[l] != RTC_INVALID_GEOMETRY_ID;
        t[i] = hit ? rh.ray.tfar[l] : INFINITY;
        prim[i] = hit ? rh.hit.primID[l] : 0xFFFFFFFFu;
        u[i] = rh.hit.u[l]; v[i] = rh.hit.v[l];
      }
    }
  }
}

/* occ[i] = 1 where anything lies in (tnear, tfar). */
void ebp_occluded(const ebp_scene *s, const float *o, const float *d, size_t n, const float *tnear, const float *tfar,
                  uint8_t *occ, int coherent, int packet16, int threads) {
  size_t chunks = (n + CHUNK - 1) / CHUNK;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (size_t c = 0; c < chunks; c++) {
    struct RTCIntersectContext ctx;
    context(&ctx, coherent);
    size_t i0 = c * CHUNK, k = n - i0 < CHUNK ? n - i0 : CHUNK;
    if (!packet16) {
      struct RTCRay r[CHUNK];
      for (size_t j = 0; j < k; j++) pack(&r[j], o, d, tnear, tfar, i0 + j);
      rtcOccluded1M(s->scene, &ctx, r, (unsigned)k, sizeof(struct RTCRay));
      for (size_t j = 0; j < k; j++) occ[i0 + j] = r[j].tfar < 0.0f;
      continue;
    }
    for (size_t b = 0; b < k; b += 16) {
      struct RTCRay16 r;
      int valid[16];
      pack16(&r, valid, o, d, tnear, tfar, i0 + b, i0 + k);
      rtcOccluded16(valid, s->scene, &ctx, &r);
      for (int l = 0; l < 16 && b + (size_t)l < k; l++) occ[i0 + b + (size_t)l] = r.tfar[l] < 0.0f;
    }
  }
}
