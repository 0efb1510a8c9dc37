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
/* fr_env_eval and fr_env_pdf at once (one lookup). */
vec3 fr_env_eval_pdf(const fr_env *e, vec3 dir, float *pdf);
#endif
