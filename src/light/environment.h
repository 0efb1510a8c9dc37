/*
 * The environment: light arriving from infinitely far away, either one
 * colour from every direction or a latitude-longitude (equirectangular)
 * HDR image, its zenith along the scene's up vector, turned about it by
 * `rotate` degrees and scaled by `intensity`. An image is importance-sampled
 * by a piecewise-constant distribution over its pixels weighted by
 * luminance times sin(theta), the solid angle a pixel covers.
 */
#ifndef FR_LIGHT_ENVIRONMENT_H
#define FR_LIGHT_ENVIRONMENT_H
#include "base/vec3.h"
#include <math.h>
#include "base/trig.h"
#include "light/distribution2d.h"

typedef struct fr_env {
  vec3 color;       /* the constant environment (no image) */
  int w, h;
  float *rgb;       /* the image, or NULL */
  float *texels;    /* per texel its r, g, b and the distribution's density there, so that a
                       lookup of both takes one cache line (the image's own array serves the
                       bilinear background) */
  fr_dist2d dist;
  vec3 ax, ay, az;  /* world frame: az the zenith */
  float intensity;
  float rotate;     /* turns about the zenith, in [0, 1) */
  int black;        /* emits nothing: never sampled */
} fr_env;

/* A constant environment of the given radiance. */
void fr_env_constant(fr_env *e, vec3 color);
/* An image (EXR or Radiance HDR, read with io/image_read.h); errors name the file. */
fr_error fr_env_load(fr_env *e, const char *path);
/* An image already in memory (taken over: freed by fr_env_free). */
fr_error fr_env_from_image(fr_env *e, float *rgb, int w, int h);
/* Orientation and scale; call before use. */
void fr_env_orient(fr_env *e, vec3 up, float rotate_deg, float intensity);
void fr_env_free(fr_env *e);

/* Radiance arriving along -dir (dir points from the scene to the sky). */
vec3 fr_env_eval(const fr_env *e, vec3 dir);
/* A direction toward the sky with its solid-angle pdf, and the radiance from
 * it; pdf 0 when the environment is black. */
vec3 fr_env_sample(const fr_env *e, float u1, float u2, vec3 *dir, float *pdf);
/* n samples as fr_env_sample makes each (the same bits), radiance in
 * le[i]: for a batch of paths, whose table and texel lookups then overlap
 * rather than wait one after another. */
void fr_env_sample_batch(const fr_env *e, size_t n, const float *u1, const float *u2, vec3 *dir, vec3 *le, float *pdf);
float fr_env_pdf(const fr_env *e, vec3 dir);
/* An image environment's texel that fr_env_eval and fr_env_eval_pdf read
 * for dir, and sin theta there; then its radiance, and the pdf of dir when
 * pdf is not NULL: fr_env_eval_pdf in two steps, for a caller that fetches
 * the texels of many directions before it reads them. */
const float *fr_env_texel(const fr_env *e, vec3 dir, float *sin_t);
vec3 fr_env_texel_radiance(const fr_env *e, const float *texel, float sin_t, float *pdf);
/* The same, interpolated bilinearly between texels: for the background
 * seen straight from the camera, where the map's texels would show. */
vec3 fr_env_eval_smooth(const fr_env *e, vec3 dir);
/* Its second step for an image: the radiance at (fx, fy) (fr_env_smooth_at). */
vec3 fr_env_smooth_radiance(const fr_env *e, float fx, float fy);
/* fr_env_eval and fr_env_pdf at once (one lookup). */
vec3 fr_env_eval_pdf(const fr_env *e, vec3 dir, float *pdf);
/* fr_env_texel for n directions (x, y, z arrays): texel[i] and sin_t[i]
 * the same as fr_env_texel gives for direction i, made as vector code
 * (light/environment_lanes.c). An image environment. */
void fr_env_texel_batch(const fr_env *e, size_t n, const float *x, const float *y, const float *z,
                        const float **texel, float *sin_t);
/* fr_env_eval_smooth for n directions (x, y, z arrays) into le[i], the
 * same bits; an image's coordinates made as vector code. */
void fr_env_eval_smooth_batch(const fr_env *e, size_t n, const float *x, const float *y, const float *z, vec3 *le);

#define FR_ENV_BATCH_FNS(isa)                                                                                     \
  void fr_env_sample_batch_##isa(const fr_env *e, size_t n, const float *u1, const float *u2, vec3 *dir, vec3 *le,  \
                                 float *pdf);                                                                        \
  void fr_env_texel_batch_##isa(const fr_env *e, size_t n, const float *x, const float *y, const float *z,          \
                                int *texel, float *sin_t);                                                         \
  void fr_env_smooth_at_batch_##isa(const fr_env *e, size_t n, const float *x, const float *y, const float *z,     \
                                    float *fx, float *fy);
FR_ENV_BATCH_FNS(scalar)
FR_ENV_BATCH_FNS(avx2)
FR_ENV_BATCH_FNS(avx512)

/* The arithmetic of the lookups and samples, inline so that the scalar
 * calls and the batch code compiled per ISA make the same bits. */

#define FR_ENV_PI 3.14159265358979323846f

/* dir to image coordinates (u, v) in [0, 1)^2 and sin(theta): theta =
 * acos(z) is atan2(sin theta, z), both angles in turns (base/trig.h). */
static inline void fr_env_to_uv(const fr_env *e, float dx, float dy, float dz, float *u, float *v, float *sin_t) {
  const float dotz = dx * e->az.x + dy * e->az.y + dz * e->az.z;
  const float z = fr_maxf(-1.0f, fr_minf(1.0f, dotz)), st = sqrtf(fr_maxf(0.0f, 1.0f - z * z));
  float uu = fr_atan2_turns(dx * e->ay.x + dy * e->ay.y + dz * e->ay.z, dx * e->ax.x + dy * e->ax.y + dz * e->ax.z) -
             e->rotate;
  uu -= floorf(uu);
  *u = uu < 1.0f ? uu : 0.0f;
  *v = fr_minf(2.0f * fr_atan2_turns(st, z), 0.99999994f);
  *sin_t = st;
}

/* The index of the texel at (u, v) (4 w h < 2^31: fr_env_from_image). */
static inline int fr_env_texel_index(const fr_env *e, float u, float v) {
  int x = (int)(u * (float)e->w), y = (int)(v * (float)e->h);
  x = x >= e->w ? e->w - 1 : x;
  y = y >= e->h ? e->h - 1 : y;
  return y * e->w + x;
}

/* Where fr_env_eval_smooth interpolates for dir, in texels (texel i's
 * centre at i): around in x, clamped at the poles in y. */
static inline void fr_env_smooth_at(const fr_env *e, float dx, float dy, float dz, float *fx, float *fy) {
  float u, v, s;
  fr_env_to_uv(e, dx, dy, dz, &u, &v, &s);
  *fx = u * (float)e->w - 0.5f;
  *fy = v * (float)e->h - 0.5f;
}

/* The light sample at image point (u, v) in a texel of density puv (its
 * fourth float): its direction (d[3]) and pdf, and whether there is one
 * (0 where the density or sin theta is 0: then pdf 0, radiance 0 and d
 * meaningless). Its radiance: the texel's colour times the intensity. */
static inline int fr_env_sample_dir(const fr_env *e, float u, float v, float puv, float d[3], float *pdf) {
  /* theta = pi v, phi = 2 pi u + rotate: both in turns */
  float st, ct, sp, cp, turns = u + e->rotate;
  fr_sincos_turns(0.5f * v, &st, &ct);
  fr_sincos_turns(turns < 1.0f ? turns : turns - 1.0f, &sp, &cp);
  const float lx = st * cp, ly = st * sp;
  d[0] = e->ax.x * lx + e->ay.x * ly + e->az.x * ct;
  d[1] = e->ax.y * lx + e->ay.y * ly + e->az.y * ct;
  d[2] = e->ax.z * lx + e->ay.z * ly + e->az.z * ct;
  const int some = (puv > 0.0f) & (st > 0.0f);
  const float p = puv / (2.0f * FR_ENV_PI * FR_ENV_PI * st);
  *pdf = some ? p : 0.0f;
  return some;
}
#endif
