/*
 * The Whitted workload and renderer: primary rays, a shadow ray to the point
 * light at every hit that is not a pure mirror, mirror reflection, and
 * refraction with Fresnel through dielectrics, to a settable depth (<= 4 by
 * workloads.md; up to 8 here).
 *
 * Rays travel in generations: the camera rays of a 32x32 tile, then the
 * shadow rays of their hits, then their reflection and refraction rays,
 * and so on. Within a generation the rays stay grouped by the block of
 * side x side pixels they descend from and by kind (reflection, refraction),
 * so a packet tracer sees Overbeck's secondary packets: the rays of one
 * primary packet that met mirrors, or glass.
 */
#ifndef FR_RENDER_WHITTED_H
#define FR_RENDER_WHITTED_H
#include <stdint.h>
#include "frusta.h"
#include "render/surfaces.h"
#include "render/workload.h"

#define FR_WHITTED_MAX_DEPTH 8

typedef enum fr_whitted_kind { FR_SURF_DIFFUSE, FR_SURF_MIRROR, FR_SURF_GLASS } fr_whitted_kind;

typedef struct fr_whitted_mat {
  fr_whitted_kind kind;
  float kd[3];   /* diffuse colour */
  float ks[3];   /* Phong highlight, or the mirror's reflectance */
  float ns;      /* Phong exponent */
  float kt[3];   /* glass: transmitted fraction */
  float ior;
} fr_whitted_mat;

/* One entry per scene material, and one more (the last) for triangles
 * without a material; and the per-triangle records. */
typedef struct fr_whitted_mats {
  fr_whitted_mat *mat;
  size_t count;
  float *soa;          /* the same as the shading kernel reads it (render/whitted_shade.h) */
  fr_surface *tri; /* one per scene triangle */
  size_t ntris;
} fr_whitted_mats;

/* Which materials mirror and which refract. mirror and glass are
 * comma-separated material names ("all" for mirror: every surface reflects
 * half the light), or NULL for the defaults: the scenes README's
 * suggestions for kitchen and museum, else MTL illum 3 with a specular
 * colour is a mirror and any transmission is glass. FR_ERR_ARG names an
 * unknown material. */
fr_error fr_whitted_mats_build(const fr_scene *s, const char *mirror, const char *glass, fr_whitted_mats *out);
void fr_whitted_mats_free(fr_whitted_mats *m);
/* Fills m->soa (allocated, FR_WM_FIELDS x count) from m->mat. */
void fr_whitted_mats_soa(fr_whitted_mats *m);
/* How many prims (triangles and spheres) are mirrors and glass. */
void fr_whitted_mats_census(const fr_scene *s, const fr_whitted_mats *m, size_t *mirror_prims, size_t *glass_prims);
/* The Whitted workload's tiles (render/whitted.c): 32x32 pixels. */
#define FR_WHITTED_TILE 32
typedef struct fr_whitted_scratch fr_whitted_scratch;
fr_whitted_scratch *fr_whitted_scratch_new(void);
void fr_whitted_scratch_free(fr_whitted_scratch *s);
/* Adds the time s's tiles spent in each stage to stage[]. */
void fr_whitted_scratch_stages(const fr_whitted_scratch *s, double stage[FR_STAGES]);
uint64_t fr_whitted_tile(const fr_workload *w, const fr_tracer *t, fr_whitted_scratch *s, int tx, int ty);
#endif
