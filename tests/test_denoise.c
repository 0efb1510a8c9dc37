/* The denoiser (film/denoise.h): every ISA gives the same bits, and
 * finite colour stays finite where guides are NaN or infinite; noise on a
 * flat lit plane falls tenfold in squared error; an edge between two
 * normals is not blurred across; background pixels pass through; albedo
 * detail survives; black specks at 1 spp take their neighbours' light,
 * the same bits on any number of threads. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "base/rng.h"
#include "film/denoise.h"
#include "render/progressive.h"

enum { W = 83, H = 61 }; /* not a multiple of the lanes */
#define NP ((size_t)W * H)

typedef struct image {
  float rgb[3 * NP], albedo[3 * NP], normal[3 * NP], depth[NP], truth[3 * NP];
} image;

/* A plane facing the camera at depth 5, lit 0.5, albedo 0.8 (or a checker
 * of 0.2 and 0.8), with noise of standard deviation sigma in its light. */
static void plane(image *im, float sigma, int checker) {
  fr_rng rng = fr_rng_seed(7, 1);
  for (size_t i = 0; i < NP; i++) {
    const int x = (int)(i % W), y = (int)(i / W);
    const float a = checker && ((x / 4 + y / 4) & 1) ? 0.2f : 0.8f;
    const float u1 = fmaxf(fr_rng_float(&rng), 1e-7f), u2 = fr_rng_float(&rng);
    const float g = sqrtf(-2.0f * logf(u1)) * cosf(6.2831853f * u2);
    for (int c = 0; c < 3; c++) {
      im->albedo[3 * i + c] = a;
      im->truth[3 * i + c] = 0.5f * a;
      im->rgb[3 * i + c] = (0.5f + sigma * g) * a;
    }
    im->normal[3 * i] = 0.0f, im->normal[3 * i + 1] = 0.0f, im->normal[3 * i + 2] = 1.0f;
    im->depth[i] = 5.0f;
  }
}

static double mse(const float *a, const float *b, size_t n) {
  double s = 0.0;
  for (size_t i = 0; i < n; i++) s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
  return s / (double)n;
}

static void every_isa_alike(void **st) {
  (void)st;
  static image im;
  plane(&im, 0.3f, 1);
  for (size_t i = 0; i < NP; i += 7) im.depth[i] = FR_DEPTH_MISS; /* background specks */
  for (size_t i = 0; i < NP; i++) im.normal[3 * i] = (float)(i % 5) * 0.1f;
  /* broken guides and colour: a NaN or infinite normal, an infinite colour */
  for (size_t i = 3; i < NP; i += 97) im.normal[3 * i + 1] = i % 2 ? NAN : INFINITY;
  for (size_t i = 5; i < NP; i += 89) im.rgb[3 * i] = INFINITY;
  fr_denoiser *d;
  assert_int_equal(fr_denoiser_new(W, H, &d), FR_OK);
  static float out[3][3 * NP];
  const fr_isa best = fr_get_isa();
  for (int isa = FR_ISA_SCALAR; isa <= (int)best; isa++) {
    assert_int_equal(fr_set_isa((fr_isa)isa), FR_OK);
    fr_denoise(d, im.rgb, im.albedo, im.normal, im.depth, 4, 2, out[isa]);
    if (isa > FR_ISA_SCALAR) assert_memory_equal(out[isa], out[FR_ISA_SCALAR], sizeof out[0]);
  }
  for (size_t i = 0; i < 3 * NP; i++) assert_true(isfinite(out[FR_ISA_SCALAR][i]) || !isfinite(im.rgb[i]));
  fr_set_isa(best);
  fr_denoiser_free(d);
}

static void flat_plane_smoothed(void **st) {
  (void)st;
  static image im;
  static float out[3 * NP];
  fr_denoiser *d;
  assert_int_equal(fr_denoiser_new(W, H, &d), FR_OK);
  for (int checker = 0; checker <= 1; checker++) {
    plane(&im, 0.25f, checker);
    fr_denoise(d, im.rgb, im.albedo, im.normal, im.depth, 1, 2, out);
    const double before = mse(im.rgb, im.truth, 3 * NP), after = mse(out, im.truth, 3 * NP);
    print_message("%s: squared error %.3g before, %.3g after\n", checker ? "checker albedo" : "flat albedo", before, after);
    assert_true(after < 0.1 * before);
  }
  fr_denoiser_free(d);
}

static void edges_kept(void **st) {
  (void)st;
  static image im;
  static float out[3 * NP];
  plane(&im, 0.0f, 0);
  for (size_t i = 0; i < NP; i++) {
    const int x = (int)(i % W), y = (int)(i / W);
    if (x >= W / 2) { /* a wall at right angles, lit 0.1 */
      im.normal[3 * i] = -1.0f, im.normal[3 * i + 2] = 0.0f;
      for (int c = 0; c < 3; c++) im.rgb[3 * i + c] = im.truth[3 * i + c] = 0.1f * 0.8f;
    }
    if (y < 3) { /* the sky */
      im.depth[i] = FR_DEPTH_MISS;
      for (int c = 0; c < 3; c++) im.rgb[3 * i + c] = im.truth[3 * i + c] = 3.0f + (float)c;
    }
  }
  fr_denoiser *d;
  assert_int_equal(fr_denoiser_new(W, H, &d), FR_OK);
  fr_denoise(d, im.rgb, im.albedo, im.normal, im.depth, 1, 2, out);
  for (size_t i = 0; i < 3 * NP; i++) assert_float_equal(out[i], im.truth[i], 1e-5f * fmaxf(1.0f, im.truth[i]));
  fr_denoiser_free(d);
}

/* At 1 spp a pixel whose path found no light is black: it takes its
 * neighbours' light, and the image is the same bits on 1 and 3 threads. */
static void black_specks_filled(void **st) {
  (void)st;
  static image im;
  static float out[2][3 * NP];
  plane(&im, 0.1f, 0);
  for (size_t i = 3 * W + 3; i < NP; i += 37)
    for (int c = 0; c < 3; c++) im.rgb[3 * i + c] = 0.0f;
  fr_denoiser *d;
  assert_int_equal(fr_denoiser_new(W, H, &d), FR_OK);
  fr_denoise(d, im.rgb, im.albedo, im.normal, im.depth, 1, 1, out[0]);
  fr_denoise(d, im.rgb, im.albedo, im.normal, im.depth, 1, 3, out[1]);
  assert_memory_equal(out[0], out[1], sizeof out[0]);
  for (size_t i = 3 * W + 3; i < NP; i += 37)
    for (int c = 0; c < 3; c++) assert_true(out[0][3 * i + c] > 0.5f * im.truth[3 * i + c]);
  fr_denoiser_free(d);
}

static void bad_sizes(void **st) {
  (void)st;
  fr_denoiser *d = (fr_denoiser *)1;
  assert_int_equal(fr_denoiser_new(0, 5, &d), FR_ERR_ARG);
  assert_null(d);
  assert_int_equal(fr_denoiser_new(5, 40000, &d), FR_ERR_ARG);
  fr_denoiser_free(NULL);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(every_isa_alike),
      cmocka_unit_test(flat_plane_smoothed),
      cmocka_unit_test(edges_kept),
      cmocka_unit_test(black_specks_filled),
      cmocka_unit_test(bad_sizes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
