/*
 * The Whitted renderer's shading, 16 hits at a time: what each hit adds to
 * its pixel, and the shadow, reflection and refraction rays it spawns.
 * Compiled once per ISA (src/render/whitted_shade.c); every level gives the
 * same bits as the others.
 *
 * The renderer (whitted.c) fetches what each hit needs from memory, its
 * surface record (geometric normal and material); fr_whitted_shade16 does
 * the arithmetic, which as scalar code with a branch per material kind took
 * about a third of a Whitted frame, reading rays and records whole; and
 * fr_whitted_emit16 writes the new rays out 16 at a time.
 */
#ifndef FR_RENDER_WHITTED_SHADE_H
#define FR_RENDER_WHITTED_SHADE_H
#include <stdint.h>
#include "frusta.h"
#include "render/whitted.h"

#define FR_WS_LANES 16

/* What a ray of a generation carries, beside the ray itself (kept in an
 * array of its own, so the tracers read a generation in place): the weight,
 * its pixel, its packet key (block * 2 + kind: 0 camera or reflection, 1
 * refraction). */
typedef struct fr_wpath {
  float w[3];
  uint16_t pix;
  uint16_t key;
} fr_wpath;

/* Materials as structure of arrays: field f of material i at soa[f * count + i]. */
enum {
  FR_WM_KD = 0,    /* 3: diffuse colour */
  FR_WM_KS = 3,    /* 3: Phong highlight, or the mirror's reflectance */
  FR_WM_KT = 6,    /* 3: glass: transmitted fraction */
  FR_WM_NS = 9,    /* Phong exponent */
  FR_WM_IOR,       /* glass: index of refraction */
  FR_WM_GLASS,     /* 1 for glass, else 0 */
  FR_WM_BOUNCES,   /* 1 for mirrors and glass: spawns reflection (and refraction) */
  FR_WM_LIGHTS,    /* 1 where the point light adds colour: a shadow ray */
  FR_WM_PHONG,     /* 1 for a diffuse surface with a highlight */
  FR_WM_FIELDS
};

typedef struct fr_wshade_in {
  const fr_ray *ray;    /* 16 rays (lanes past `valid` are not read) */
  const fr_wpath *path; /* what they carry */
  const fr_hit *hit;    /* their hits */
  const fr_surface *surf; /* per ray: geometric normal (not unit) and material index
                                 (any valid index for a miss) */
  unsigned valid, hits; /* lanes present; lanes that hit */
  const float *mats;    /* the material table, FR_WM_FIELDS x mat_count */
  size_t mat_count;
  float light[3];
  int bounce;           /* whether hits still spawn reflection and refraction */
} fr_wshade_in;

typedef struct fr_wshade_out {
  float add[3][FR_WS_LANES] __attribute__((aligned(64))); /* colour added to the pixel */
  float p[3][FR_WS_LANES] __attribute__((aligned(64)));   /* hit point: the new rays' origin */
  float l[3][FR_WS_LANES] __attribute__((aligned(64))), ldist[FR_WS_LANES] __attribute__((aligned(64)));
  float lw[3][FR_WS_LANES] __attribute__((aligned(64)));  /* shadow ray: direction to the light, distance, weight if unoccluded */
  float rd[3][FR_WS_LANES] __attribute__((aligned(64))), rw[3][FR_WS_LANES] __attribute__((aligned(64)));
  float td[3][FR_WS_LANES] __attribute__((aligned(64))), tw[3][FR_WS_LANES] __attribute__((aligned(64)));
  uint32_t pk[FR_WS_LANES] __attribute__((aligned(64))); /* each lane's pix | key << 16, as read */
  unsigned shadow, refl, refr; /* lanes that spawn a shadow, reflection, refraction ray */
} fr_wshade_out;

/* Where new rays go: n of them so far, room for 16 more (32 for a sink that
 * takes reflection and refraction rays). */
typedef struct fr_wsink {
  fr_ray *r;
  fr_wpath *p;
  size_t n;
} fr_wsink;

#define FR_WHITTED_MIN_WEIGHT 0.01f /* secondary rays carrying less are not traced */
#define FR_WHITTED_AMBIENT 0.1f
#define FR_WHITTED_BACKGROUND 0.05f

#define FR_DECLARE_WSHADE(isa) void fr_whitted_shade16_##isa(const fr_wshade_in *in, fr_wshade_out *out);
FR_DECLARE_WSHADE(avx512)
FR_DECLARE_WSHADE(avx2)
FR_DECLARE_WSHADE(scalar)
/* The rays 16 shaded hits spawn, appended in lane order: shadow rays
 * (traced from the light to eps short of the hit; see whitted.c) to
 * `shadow`, then the reflection rays and then the refraction rays to
 * `next` (whose order within a packet the renderer's sort by key keeps). */
#define FR_DECLARE_WEMIT(isa)                                                                                  \
  void fr_whitted_emit16_##isa(const fr_wshade_out *out, const float light[3], float eps, fr_wsink *shadow, \
                               fr_wsink *next);
FR_DECLARE_WEMIT(avx512)
FR_DECLARE_WEMIT(avx2)
FR_DECLARE_WEMIT(scalar)
/* the level fr_kernels_active() chose */
void fr_whitted_shade16(const fr_wshade_in *in, fr_wshade_out *out);
void fr_whitted_emit16(const fr_wshade_out *out, const float light[3], float eps, fr_wsink *shadow, fr_wsink *next);
#endif
