/* Embree 3 on the same scene, rays and threads, for side-by-side runs and as
 * the oracle in tests. Never on frusta's own tracing path. */
#ifndef FR_TOOL_EMBREE_TRACER_H
#define FR_TOOL_EMBREE_TRACER_H
#include <stddef.h>
#include "frusta.h"
#include "render/workload.h"

typedef enum ebr_mode { EBR_SINGLE, EBR_PACKET4, EBR_PACKET8, EBR_PACKET16, EBR_STREAM, EBR_MODE_COUNT } ebr_mode;

typedef struct ebr_scene ebr_scene;

typedef struct ebr_options {
  int threads;
  int quality;   /* 0 low, 1 medium, 2 high (spatial splits) */
  int robust;    /* RTC_SCENE_FLAG_ROBUST: watertight, slower */
  int verbose;   /* Embree's device verbosity: 2 prints the tree's statistics on stdout at commit */
} ebr_options;

fr_error ebr_create(const fr_scene *s, ebr_options opt, ebr_scene **out);
void ebr_release(ebr_scene *e);
double ebr_build_seconds(const ebr_scene *e);
size_t ebr_bytes(const ebr_scene *e);   /* memory Embree allocated for the scene */

const char *ebr_mode_name(ebr_mode m);
int ebr_mode_parse(const char *name, ebr_mode *m);
fr_tracer ebr_tracer(ebr_scene *e, ebr_mode m);

void ebr_intersect1(ebr_scene *e, const fr_ray *r, fr_hit *h);
int ebr_occluded1(ebr_scene *e, const fr_ray *r);

/* SAH costs (per triangle and per 4-wide block, as fr_wide_stats) and seconds
 * of Embree's own BVH builder (rtcBuildBVH: 4-wide, leaves of at most 4, SAH
 * block size 4; quality 2 adds spatial splits) on the scene's triangles. */
fr_error ebr_builder_sah(const fr_scene *s, int threads, int quality, double *sah, double *sah_blocks, double *seconds);
#endif
