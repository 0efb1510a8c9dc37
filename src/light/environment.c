#include "light/environment.h"
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/bilinear.h"
#include "base/error.h"
#include "base/trig.h"
#include "io/image_read.h"

void fr_env_constant(fr_env *e, vec3 color) {
  memset(e, 0, sizeof *e);
  e->color = color;
  e->black = !(color.x > 0.0f || color.y > 0.0f || color.z > 0.0f);
  fr_env_orient(e, v3(0, 1, 0), 0.0f, 1.0f);
}

fr_error fr_env_from_image(fr_env *e, float *rgb, int w, int h) {
  memset(e, 0, sizeof *e);
  e->rgb = rgb, e->w = w, e->h = h;
  if (w <= 0 || h <= 0 || (int64_t)w * h > (INT64_C(1) << 29)) { /* texel indices (4 floats each) are ints */
    fr_env_free(e);
    return fr_fail(FR_ERR_ARG, "an environment image of %dx%d pixels: at most 2^29 pixels", w, h);
  }
  float *weight = fr_malloc_array(fr_mul_size((size_t)w, (size_t)h), sizeof(float));
  if (!weight) { fr_env_free(e); return fr_fail(FR_ERR_NOMEM, "out of memory for the environment's distribution"); }
  for (int y = 0; y < h; y++) {
    const float s = sinf(FR_ENV_PI * ((float)y + 0.5f) / (float)h);
    for (int x = 0; x < w; x++) {
      const float *c = rgb + 3 * ((size_t)y * w + x);
      weight[(size_t)y * w + x] = (0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]) * s;
    }
  }
  fr_error err = fr_dist2d_build(&e->dist, weight, w, h);
  free(weight);
  if (err == FR_ERR_ARG) e->black = 1, err = FR_OK; /* an all-black image lights nothing */
  if (!err && !(e->texels = fr_malloc_array(fr_mul_size((size_t)w, (size_t)h), 4 * sizeof(float))))
    err = fr_fail(FR_ERR_NOMEM, "out of memory for the environment's texels");
  if (err) { fr_env_free(e); return err; }
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      const size_t i = (size_t)y * w + x;
      memcpy(e->texels + 4 * i, rgb + 3 * i, 3 * sizeof(float));
      e->texels[4 * i + 3] = e->black ? 0.0f : fr_dist2d_pdf(&e->dist, x, y);
    }
  fr_env_orient(e, v3(0, 1, 0), 0.0f, 1.0f);
  return FR_OK;
}

fr_error fr_env_load(fr_env *e, const char *path) {
  memset(e, 0, sizeof *e);
  int w, h;
  float *rgb;
  fr_error err = fr_image_read(path, &w, &h, &rgb);
  if (err) return err;
  return fr_env_from_image(e, rgb, w, h);
}

void fr_env_orient(fr_env *e, vec3 up, float rotate_deg, float intensity) {
  e->az = v3_norm(up);
  v3_onb(e->az, &e->ax, &e->ay);
  const float turns = rotate_deg / 360.0f;
  e->rotate = turns - floorf(turns);
  if (!(e->rotate < 1.0f)) e->rotate = 0.0f; /* a tiny negative turn rounds up to a whole one */
  e->intensity = intensity;
}

void fr_env_free(fr_env *e) {
  free(e->rgb);
  free(e->texels);
  fr_dist2d_free(&e->dist);
  memset(e, 0, sizeof *e);
}

static void to_uv(const fr_env *e, vec3 d, float *u, float *v, float *sin_t) {
  fr_env_to_uv(e, d.x, d.y, d.z, u, v, sin_t);
}

/* The texel at (u, v): its r, g, b and density */
static const float *texel(const fr_env *e, float u, float v) { return e->texels + 4 * (size_t)fr_env_texel_index(e, u, v); }

vec3 fr_env_eval(const fr_env *e, vec3 dir) {
  if (!e->rgb) return v3_scale(e->color, e->intensity);
  float u, v, s;
  to_uv(e, dir, &u, &v, &s);
  return v3_scale(v3_load(texel(e, u, v)), e->intensity);
}

/* The light sample at image point (u, v) in texel (x, y). */
static vec3 sample_at(const fr_env *e, float u, float v, int x, int y, vec3 *dir, float *pdf) {
  const float *t = e->texels + 4 * ((size_t)y * e->w + x);
  float d[3];
  if (!fr_env_sample_dir(e, u, v, t[3], d, pdf)) return v3(0, 0, 0);
  *dir = v3_load(d);
  return v3_scale(v3_load(t), e->intensity);
}

vec3 fr_env_sample(const fr_env *e, float u1, float u2, vec3 *dir, float *pdf) {
  if (e->black) { *pdf = 0.0f; return v3(0, 0, 0); }
  if (!e->rgb) { /* uniform over the sphere */
    const float z = 1.0f - 2.0f * u1, r = sqrtf(fr_maxf(0.0f, 1.0f - z * z));
    float s, c;
    fr_sincos_turns(u2, &s, &c);
    *dir = v3(r * c, r * s, z);
    *pdf = 1.0f / (4.0f * FR_ENV_PI);
    return v3_scale(e->color, e->intensity);
  }
  float u, v;
  int x, y;
  fr_dist2d_sample(&e->dist, u1, u2, &u, &v, &x, &y);
  return sample_at(e, u, v, x, y, dir, pdf);
}

float fr_env_pdf(const fr_env *e, vec3 dir) {
  float pdf;
  fr_env_eval_pdf(e, dir, &pdf);
  return pdf;
}

const float *fr_env_texel(const fr_env *e, vec3 dir, float *sin_t) {
  float u, v;
  to_uv(e, dir, &u, &v, sin_t);
  return texel(e, u, v);
}

vec3 fr_env_texel_radiance(const fr_env *e, const float *t, float sin_t, float *pdf) {
  if (pdf) *pdf = !(sin_t > 0.0f) ? 0.0f : t[3] / (2.0f * FR_ENV_PI * FR_ENV_PI * sin_t); /* 0 where black */
  return v3_scale(v3_load(t), e->intensity);
}

vec3 fr_env_eval_pdf(const fr_env *e, vec3 dir, float *pdf) {
  if (!e->rgb) {
    *pdf = e->black ? 0.0f : 1.0f / (4.0f * FR_ENV_PI);
    return v3_scale(e->color, e->intensity);
  }
  float s;
  const float *t = fr_env_texel(e, dir, &s);
  return fr_env_texel_radiance(e, t, s, pdf);
}

vec3 fr_env_eval_smooth(const fr_env *e, vec3 dir) {
  if (!e->rgb) return v3_scale(e->color, e->intensity);
  float fx, fy;
  fr_env_smooth_at(e, dir.x, dir.y, dir.z, &fx, &fy);
  return fr_env_smooth_radiance(e, fx, fy);
}

vec3 fr_env_smooth_radiance(const fr_env *e, float fx, float fy) {
  return v3_scale(fr_rgb_bilinear(e->rgb, e->w, e->h, fx, fy, 1), e->intensity);
}
