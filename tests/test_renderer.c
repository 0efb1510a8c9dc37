/*
 * The public renderer (fr_renderer): every shade renders the built-in scene
 * to finite, non-black images with guides; one-pass shades are done at
 * once, progressive ones after spp / 16 (or spp / 8 for path) passes and
 * equal to the mean of their passes; the same description renders the
 * same bits twice and on 1 and 3 threads; a new camera restarts; errors;
 * fr_image_save writes what the readers read back.
 * That it renders what `frusta render` does is checked from Python
 * (tests/python), byte for byte against the command.
 */
#include <unistd.h>
#include "io/image_read.h"
#include "test_util.h"

#define W 64
#define H 48

static float *render(const fr_scene *s, fr_render_desc d, int *spp) {
  fr_renderer *r;
  if (fr_renderer_new(s, &d, &r) != FR_OK) fail_msg("fr_renderer_new: %s", fr_last_error());
  assert_int_equal(fr_renderer_render(r), FR_OK);
  float *img = malloc((size_t)W * H * 10 * sizeof(float));
  assert_int_equal(fr_renderer_image(r, 0, img, img + 3 * W * H, img + 6 * W * H, img + 9 * W * H), FR_OK);
  if (spp) *spp = fr_renderer_spp(r);
  fr_renderer_release(r);
  return img;
}

static void every_shade(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  for (int shade = FR_RENDER_EYELIGHT; shade <= FR_RENDER_PATH; shade++) {
    fr_render_desc d = {.camera = {.width = W, .height = H}, .shade = (fr_render_shade)shade, .threads = 2};
    if (shade == FR_RENDER_PATH) d.spp = 4;
    if (shade == FR_RENDER_AO || shade == FR_RENDER_SOFTSHADOW) d.spp = 32;
    int spp;
    float *a = render(s, d, &spp);
    double sum = 0.0;
    int hits = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
      for (int k = 0; k < 3; k++) {
        assert_true(isfinite(a[3 * i + k]) && a[3 * i + k] >= 0.0f);
        sum += a[3 * i + k];
      }
      hits += a[9 * W * H + i] < 1e29f;
    }
    assert_true(sum > 0.01 * W * H);
    assert_true(hits > W * H / 4); /* the depth guide sees the scene */
    const int want_spp[] = {1, 1, 1, 32, 1, 32, 4};
    assert_int_equal(spp, want_spp[shade]);
    /* deterministic: the same bits again, and on other thread counts */
    d.threads = shade == FR_RENDER_PATH ? 3 : 1;
    float *b = render(s, d, NULL);
    assert_memory_equal(a, b, (size_t)W * H * 3 * sizeof(float));
    free(a);
    free(b);
  }
  fr_scene_release(s);
}

static void passes_camera_and_errors(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  fr_render_desc d = {.camera = {.width = W, .height = H}, .shade = FR_RENDER_AO, .spp = 48};
  fr_renderer *r = NULL;
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_ERR_STATE);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_OK);
  int done = 0, passes = 0;
  while (!done) {
    assert_int_equal(fr_renderer_pass(r, &done), FR_OK);
    passes++;
  }
  assert_int_equal(passes, 3);
  assert_int_equal(fr_renderer_spp(r), 48);
  fr_pinhole cam = {{0.0f, 3.0f, 9.0f}, {0.0f, 0.5f, 0.0f}, {0.0f, 1.0f, 0.0f}, 50.0f, W, H};
  assert_int_equal(fr_renderer_set_camera(r, &cam), FR_OK);
  assert_int_equal(fr_renderer_spp(r), 0);
  assert_int_equal(fr_renderer_pass(r, &done), FR_OK);
  assert_int_equal(fr_renderer_spp(r), 16);
  cam.width = W + 1;
  assert_int_equal(fr_renderer_set_camera(r, &cam), FR_ERR_ARG);
  cam.width = W;
  cam.fov_deg = 200.0f;
  assert_int_equal(fr_renderer_set_camera(r, &cam), FR_ERR_ARG);
  /* display values: path through the filmic curve stays below 1 */
  fr_renderer_release(r);
  d.shade = FR_RENDER_PATH;
  d.spp = 2;
  d.denoise = 1;
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_OK);
  assert_int_equal(fr_renderer_render(r), FR_OK);
  float *img = malloc((size_t)W * H * 3 * sizeof(float));
  assert_int_equal(fr_renderer_image(r, 1, img, NULL, NULL, NULL), FR_OK); /* denoised without the caller's guides */
  for (size_t i = 0; i < (size_t)W * H * 3; i++) assert_true(img[i] >= 0.0f && img[i] < 1.0f);
  free(img);
  fr_renderer_release(r);
  /* errors */
  d.spp = 20;
  d.shade = FR_RENDER_AO;
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_ERR_ARG);
  d.spp = 16;
  d.shade = (fr_render_shade)9;
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_ERR_ARG);
  d.shade = FR_RENDER_PATH;
  d.environment = "/nonexistent/sky.hdr";
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_ERR_IO);
  assert_true(r == NULL);
  d.environment = NULL;
  d.camera.width = 0;
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_ERR_ARG);
  assert_int_equal(fr_renderer_new(NULL, &d, &r), FR_ERR_ARG);
  fr_renderer_release(NULL);
  fr_scene_release(s);
}

/* fr_image_save writes what the image readers read back (EXR to half
 * precision, PNG to a step of 8-bit sRGB) and PFM's floats exactly; bad
 * arguments are refused and write nothing. */
static void images_save(void **state) {
  (void)state;
  float img[W * H * 3];
  for (int i = 0; i < W * H * 3; i++) img[i] = (float)(i % 97) / 96.0f;
  char dir[] = "/tmp/frusta_image_save_XXXXXX";
  assert_non_null(mkdtemp(dir));
  char pfm[256], exr[256], png[256], bad[256];
  snprintf(pfm, sizeof pfm, "%s/a.pfm", dir);
  snprintf(exr, sizeof exr, "%s/a.exr", dir);
  snprintf(png, sizeof png, "%s/a.png", dir);
  snprintf(bad, sizeof bad, "%s/a.bmp", dir);
  assert_int_equal(fr_image_save(pfm, W, H, img), FR_OK);
  assert_int_equal(fr_image_save(exr, W, H, img), FR_OK);
  assert_int_equal(fr_image_save(png, W, H, img), FR_OK);
  int w, h;
  float *back;
  assert_int_equal(fr_image_read(exr, &w, &h, &back), FR_OK);
  assert_int_equal(w, W);
  assert_int_equal(h, H);
  for (int i = 0; i < W * H * 3; i++) assert_true(fabsf(back[i] - img[i]) <= 1e-3f);
  free(back);
  assert_int_equal(fr_image_read_ldr(png, &w, &h, &back), FR_OK); /* 8-bit sRGB: within a step */
  for (int i = 0; i < W * H * 3; i++) assert_true(fabsf(back[i] - img[i]) <= 0.01f);
  free(back);
  FILE *f = fopen(pfm, "rb"); /* a header, then the floats, bottom row first */
  assert_non_null(f);
  fseek(f, 0, SEEK_END);
  const long size = ftell(f);
  assert_true(size > W * H * 12 && size < W * H * 12 + 64);
  float last[3];
  fseek(f, size - 12, SEEK_SET);
  assert_int_equal(fread(last, sizeof(float), 3, f), 3);
  fclose(f);
  assert_memory_equal(last, img + 3 * (W - 1), sizeof last); /* the top row's last pixel */
  assert_int_equal(fr_image_save(bad, W, H, img), FR_ERR_ARG);
  assert_int_equal(access(bad, F_OK), -1);
  assert_int_equal(fr_image_save(png, 0, H, img), FR_ERR_ARG);
  assert_int_equal(fr_image_save(NULL, W, H, img), FR_ERR_ARG);
  assert_int_equal(fr_image_save(png, W, H, NULL), FR_ERR_ARG);
  char missing[300];
  snprintf(missing, sizeof missing, "%s/no/such/dir/a.png", dir);
  assert_int_equal(fr_image_save(missing, W, H, img), FR_ERR_IO);
  remove(pfm), remove(exr), remove(png);
  rmdir(dir);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(every_shade),
      cmocka_unit_test(passes_camera_and_errors),
      cmocka_unit_test(images_save),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
