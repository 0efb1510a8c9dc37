/* Temporal reprojection (film/temporal.h) on an analytic scene, a
 * patterned floor under a sky: the first frame passes through; along a
 * moving camera the blend cuts the noise of each frame at least in half
 * against the truth and reuses nearly every pixel; where the surface
 * changed nothing is carried over; at rest the history fades out and the
 * image becomes the progressive one exactly. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "base/rng.h"
#include "film/temporal.h"
#include "render/progressive.h"

enum { W = 97, H = 71 };
#define NP ((size_t)W * H)

typedef struct frame {
  fr_camera cam;
  float rgb[3 * NP], truth[3 * NP], normal[3 * NP], depth[NP];
} frame;

/* The camera orbiting the origin, angle a about the vertical. */
static fr_camera orbit(float a) {
  fr_camera c;
  const vec3 eye = v3(5.0f * sinf(a), 2.0f, -5.0f * cosf(a));
  assert_int_equal(fr_camera_setup(&c, eye, v3(0, 0, 0), v3(0, 1, 0), 60.0f, W, H), FR_OK);
  return c;
}

/* The floor y = floor_y with a smooth pattern, the sky a gradient; noise
 * of standard deviation sigma (seeded) on every pixel. */
static void render(frame *f, const fr_camera *c, float floor_y, float sigma, uint64_t seed) {
  fr_rng rng = fr_rng_seed(seed, 3);
  f->cam = *c;
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      const size_t i = (size_t)y * W + (size_t)x;
      const fr_ray r = fr_camera_ray(c, x, y);
      const float t = r.dir[1] < 0.0f ? (floor_y - r.org[1]) / r.dir[1] : -1.0f;
      float v[3];
      if (t > 0.0f) {
        const float px = r.org[0] + t * r.dir[0], pz = r.org[2] + t * r.dir[2];
        const float g = 0.5f + 0.4f * sinf(1.3f * px) * cosf(1.1f * pz);
        v[0] = g, v[1] = 0.8f * g, v[2] = 0.5f;
        f->depth[i] = t;
        f->normal[3 * i] = 0.0f, f->normal[3 * i + 1] = 1.0f, f->normal[3 * i + 2] = 0.0f;
      } else {
        v[0] = 0.3f, v[1] = 0.5f + 0.5f * r.dir[1], v[2] = 1.0f;
        f->depth[i] = FR_DEPTH_MISS;
        f->normal[3 * i] = f->normal[3 * i + 1] = f->normal[3 * i + 2] = 0.0f;
      }
      for (int ch = 0; ch < 3; ch++) {
        const float u1 = fmaxf(fr_rng_float(&rng), 1e-7f), u2 = fr_rng_float(&rng);
        f->truth[3 * i + ch] = v[ch];
        f->rgb[3 * i + ch] = v[ch] + sigma * sqrtf(-2.0f * logf(u1)) * cosf(6.2831853f * u2);
      }
    }
}

static double mse(const float *a, const float *b) {
  double s = 0.0;
  for (size_t i = 0; i < 3 * NP; i++) s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
  return s / (double)(3 * NP);
}

static void first_frame_unchanged(void **st) {
  (void)st;
  static frame f;
  static float before[3 * NP];
  fr_temporal *t;
  assert_int_equal(fr_temporal_new(W, H, &t), FR_OK);
  const fr_camera c = orbit(0.0f);
  render(&f, &c, 0.0f, 0.2f, 1);
  memcpy(before, f.rgb, sizeof before);
  fr_temporal_apply(t, &f.cam, 1, f.depth, f.normal, f.rgb, 2);
  assert_memory_equal(before, f.rgb, sizeof before);
  assert_true(fr_temporal_reused(t) == 0.0f);
  fr_temporal_free(t);
}

static void moving_camera_less_noise(void **st) {
  (void)st;
  static frame f;
  fr_temporal *t;
  assert_int_equal(fr_temporal_new(W, H, &t), FR_OK);
  double raw = 0.0, blended = 0.0;
  for (int k = 0; k < 10; k++) {
    const fr_camera c = orbit(0.01f * (float)k);
    render(&f, &c, 0.0f, 0.2f, 100 + (uint64_t)k);
    const double e0 = mse(f.rgb, f.truth);
    fr_temporal_apply(t, &f.cam, 1, f.depth, f.normal, f.rgb, 2);
    if (k >= 5) raw += e0, blended += mse(f.rgb, f.truth);
    if (k > 0) assert_true(fr_temporal_reused(t) > 0.9f);
  }
  print_message("squared error over frames 5-9: %.3g per frame, %.3g blended\n", raw / 5, blended / 5);
  assert_true(blended < 0.5 * raw);
  fr_temporal_free(t);
}

static void changed_surface_not_reused(void **st) {
  (void)st;
  static frame a, b;
  static float before[3 * NP];
  fr_temporal *t;
  assert_int_equal(fr_temporal_new(W, H, &t), FR_OK);
  fr_camera c = orbit(0.0f);
  render(&a, &c, 0.0f, 0.2f, 1);
  fr_temporal_apply(t, &a.cam, 1, a.depth, a.normal, a.rgb, 2);
  c = orbit(0.02f);
  render(&b, &c, 0.6f, 0.2f, 2); /* the floor rose: every hit is another surface */
  memcpy(before, b.rgb, sizeof before);
  fr_temporal_apply(t, &b.cam, 1, b.depth, b.normal, b.rgb, 2);
  size_t hits = 0;
  for (size_t i = 0; i < NP; i++)
    if (b.depth[i] < FR_DEPTH_MISS) {
      hits++;
      assert_memory_equal(before + 3 * i, b.rgb + 3 * i, 3 * sizeof(float));
    }
  assert_true(hits > NP / 3);
  fr_temporal_free(t);
}

static void rest_fades_to_exact(void **st) {
  (void)st;
  static frame a, b;
  static float before[3 * NP];
  fr_temporal *t;
  assert_int_equal(fr_temporal_new(W, H, &t), FR_OK);
  fr_camera c = orbit(0.0f);
  render(&a, &c, 0.0f, 0.2f, 1);
  fr_temporal_apply(t, &a.cam, 1, a.depth, a.normal, a.rgb, 2);
  c = orbit(0.02f);
  for (int passes = 1; passes <= FR_TEMPORAL_FADE; passes++) {
    render(&b, &c, 0.0f, 0.2f / sqrtf((float)passes), 10 + (uint64_t)passes);
    memcpy(before, b.rgb, sizeof before);
    fr_temporal_apply(t, &b.cam, passes, b.depth, b.normal, b.rgb, 2);
    const int same = memcmp(before, b.rgb, sizeof before) == 0;
    if (passes < FR_TEMPORAL_FADE) assert_false(same);
    else assert_true(same);
  }
  fr_temporal_free(t);
}

static void bad_sizes(void **st) {
  (void)st;
  fr_temporal *t = (fr_temporal *)1;
  assert_int_equal(fr_temporal_new(0, 5, &t), FR_ERR_ARG);
  assert_null(t);
  assert_int_equal(fr_temporal_new(1 << 15, 1 << 15, &t), FR_ERR_ARG);
  fr_temporal_free(NULL);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(first_frame_unchanged),
      cmocka_unit_test(moving_camera_less_noise),
      cmocka_unit_test(changed_surface_not_reused),
      cmocka_unit_test(rest_fades_to_exact),
      cmocka_unit_test(bad_sizes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
