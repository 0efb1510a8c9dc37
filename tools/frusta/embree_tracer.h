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
/* Embree's context flag for a tracer's calls: the workload's hint
 * (coherent for the rays it knows to be coherent, such as camera rays),
 * or one flag for every call. */
typedef enum ebr_flag { EBR_FLAG_HINT, EBR_FLAG_COHERENT, EBR_FLAG_INCOHERENT, EBR_FLAG_COUNT } ebr_flag;
/* How a call's rays are grouped into packets and streams: consecutive rays
 * (EBR_PACK_RAYS: a 4x4 pixel block's camera or shadow rays, one pixel's 16
 * samples), or, where a call's rays come in runs of 16 per pixel, one
 * sample of 16 neighbouring pixels (EBR_PACK_SAMPLES). The rays traced are
 * the same either way. */
typedef enum ebr_packing { EBR_PACK_RAYS, EBR_PACK_SAMPLES, EBR_PACK_COUNT } ebr_packing;
const char *ebr_flag_name(ebr_flag f);
const char *ebr_packing_name(ebr_packing p);
int ebr_flag_parse(const char *name, ebr_flag *f);
int ebr_packing_parse(const char *name, ebr_packing *p);
fr_tracer ebr_tracer(ebr_scene *e, ebr_mode m, ebr_flag flag, ebr_packing packing);

void ebr_intersect1(ebr_scene *e, const fr_ray *r, fr_hit *h);
int ebr_occluded1(ebr_scene *e, const fr_ray *r);

/* SAH costs (per triangle and per 4-wide block, as fr_wide_stats) and seconds
 * of Embree's own BVH builder (rtcBuildBVH: 4-wide, leaves of at most 4, SAH
 * block size 4; quality 2 adds spatial splits) on the scene's triangles. */
fr_error ebr_builder_sah(const fr_scene *s, int threads, int quality, double *sah, double *sah_blocks, double *seconds);
#endif
