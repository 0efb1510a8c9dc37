/*
 * The benchmark workloads of ../shared/spec/workloads.md, written once against
 * an abstract tracer so that frusta and Embree trace the same rays, made by the
 * same code, in the same run. The renderer uses the same engine with shading.
 */
#ifndef FR_RENDER_WORKLOAD_H
#define FR_RENDER_WORKLOAD_H
#include <stdint.h>
#include "frusta.h"
#include "render/camera.h"
#include "render/views.h"

typedef enum fr_workload_kind {
  FR_WL_PRIMARY, FR_WL_SHADOW, FR_WL_SOFT16, FR_WL_AO16, FR_WL_DIFFUSE8, FR_WL_SPECULAR8, FR_WL_COUNT
} fr_workload_kind;

const char *fr_workload_name(fr_workload_kind k);
int fr_workload_parse(const char *name, fr_workload_kind *k);

/* A tracer: rays come in tiles of up to 64 pixels, ordered in 4x4 blocks, so
 * consecutive groups of 16 are coherent when the workload is. Implementations
 * may overwrite the ray arrays. */
typedef struct fr_tracer {
  void *ctx;
  void (*intersect)(void *ctx, fr_ray *rays, fr_hit *hits, size_t n, int coherent);
  void (*occluded)(void *ctx, fr_ray *rays, uint8_t *occ, size_t n, int coherent);
} fr_tracer;

typedef enum fr_shade { FR_SHADE_NONE, FR_SHADE_EYELIGHT, FR_SHADE_NORMALS, FR_SHADE_LIGHT } fr_shade;

typedef struct fr_workload {
  fr_workload_kind kind;
  const fr_scene *scene;   /* for normals and materials (the same for every tracer) */
  fr_camera cam;
  fr_view view;
  float eps;               /* 1e-4 x scene diagonal */
  int threads;
  uint64_t seed;
  fr_shade shade;          /* with an image: what to write */
  float *image;            /* width*height*3, or NULL */
  int progress;            /* print progress to stderr */
} fr_workload;

typedef struct fr_workload_result { uint64_t rays; double seconds; } fr_workload_result;

fr_workload_result fr_workload_run(const fr_workload *w, const fr_tracer *t);

/* The frusta tracer (single-ray kernels on the scene). */
fr_tracer fr_tracer_frusta(const fr_scene *s);
#endif
