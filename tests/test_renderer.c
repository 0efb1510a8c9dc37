/*
 * The public renderer (fr_renderer): every shade renders the built-in scene
 * to finite, non-black images with guides; one-pass shades are done at
 * once, progressive ones after spp / 16 (or spp / 8 for path) passes and
 * equal to the mean of their passes; the same description renders the
 * same bits twice and on 1 and 3 threads; a new camera restarts; an
 * update keeps the passes where only what is done with them changes and
 * renders as a new renderer would otherwise; cancelled passes add
 * nothing; the temporal blend carries the image to a moved camera; every
 * field out of range is refused; fr_image_save writes what the readers
 * read back.
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

static fr_render_desc desc_of(fr_render_shade shade, int spp) {
  fr_render_desc d;
  fr_render_desc_default(&d);
  d.camera.width = W, d.camera.height = H;
  d.shade = shade;
  d.spp = spp;
  return d;
}

static void every_shade(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  for (int shade = FR_RENDER_EYELIGHT; shade <= FR_RENDER_PATH; shade++) {
    fr_render_desc d = desc_of((fr_render_shade)shade, 16);
    d.threads = 2;
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
  fr_render_desc d = desc_of(FR_RENDER_AO, 48);
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

static float *image_of(fr_renderer *r) {
  float *img = malloc((size_t)W * H * 3 * sizeof(float));
  assert_int_equal(fr_renderer_image(r, 0, img, NULL, NULL, NULL), FR_OK);
  return img;
}

static void update_keeps_what_it_can(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin_materials(&s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  fr_render_desc d = desc_of(FR_RENDER_PATH, 4);
  d.pass_spp = 1;
  fr_renderer *r;
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_OK);
  assert_int_equal(fr_renderer_pass(r, NULL), FR_OK);
  assert_int_equal(fr_renderer_pass(r, NULL), FR_OK);
  assert_int_equal(fr_renderer_spp(r), 2);
  /* what is done with the sums: they stay */
  d.exposure = 1.5f, d.denoise = 1, d.threads = 1, d.pass_spp = 2;
  assert_int_equal(fr_renderer_update(r, &d), FR_OK);
  assert_int_equal(fr_renderer_spp(r), 2);
  assert_int_equal(fr_renderer_pass(r, NULL), FR_OK);
  assert_int_equal(fr_renderer_spp(r), 4);
  fr_render_desc got;
  fr_renderer_desc(r, &got);
  assert_true(got.exposure == 1.5f && got.pass_spp == 2);
  /* another seed, sampler and lights: rendered as a new renderer would */
  d.seed = 9, d.sampler = FR_SAMPLER_SOBOL, d.lights = FR_LIGHT_ENV | FR_LIGHT_POINT, d.denoise = 0;
  d.env_color[1] = 0.5f;
  assert_int_equal(fr_renderer_update(r, &d), FR_OK);
  assert_int_equal(fr_renderer_spp(r), 0);
  assert_int_equal(fr_renderer_render(r), FR_OK);
  float *a = image_of(r);
  fr_renderer *fresh;
  assert_int_equal(fr_renderer_new(s, &d, &fresh), FR_OK);
  assert_int_equal(fr_renderer_render(fresh), FR_OK);
  float *b = image_of(fresh);
  assert_memory_equal(a, b, (size_t)W * H * 3 * sizeof(float));
  free(b);
  /* a shade and back, a new camera: passes again */
  d.shade = FR_RENDER_EYELIGHT;
  assert_int_equal(fr_renderer_update(r, &d), FR_OK);
  assert_int_equal(fr_renderer_render(r), FR_OK);
  assert_int_equal(fr_renderer_spp(r), 1);
  d.shade = FR_RENDER_PATH;
  assert_int_equal(fr_renderer_update(r, &d), FR_OK);
  assert_int_equal(fr_renderer_render(r), FR_OK);
  b = image_of(r);
  assert_memory_equal(a, b, (size_t)W * H * 3 * sizeof(float));
  free(b);
  const fr_pinhole cam = {{0.0f, 2.0f, 12.0f}, {0.0f, 1.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, 45.0f, W, H};
  d.camera = cam;
  assert_int_equal(fr_renderer_update(r, &d), FR_OK);
  assert_int_equal(fr_renderer_spp(r), 0);
  /* a failed update leaves the renderer as it was */
  fr_render_desc bad = d;
  bad.environment = "/nonexistent/sky.exr";
  bad.seed = 3;
  assert_int_equal(fr_renderer_update(r, &bad), FR_ERR_IO);
  fr_renderer_desc(r, &got);
  assert_true(got.seed == 9 && got.environment == NULL);
  assert_int_equal(fr_renderer_render(r), FR_OK);
  assert_int_equal(fr_renderer_spp(r), 4);
  free(a);
  fr_renderer_release(fresh);
  fr_renderer_release(r);
  fr_scene_release(s);
}

static void cancel_stats_and_temporal(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  fr_render_desc d = desc_of(FR_RENDER_PATH, 8);
  d.pass_spp = 1, d.temporal = 1, d.denoise = 1;
  fr_renderer *r;
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_OK);
  fr_render_stats st;
  fr_renderer_set_cancel(r, 1);
  assert_int_equal(fr_renderer_pass(r, NULL), FR_OK);
  fr_renderer_stats(r, &st);
  assert_true(st.cancelled && st.rays == 0);
  assert_int_equal(fr_renderer_spp(r), 0);
  fr_renderer_set_cancel(r, 0);
  assert_int_equal(fr_renderer_pass(r, NULL), FR_OK);
  assert_int_equal(fr_renderer_pass(r, NULL), FR_OK);
  fr_renderer_stats(r, &st);
  assert_true(!st.cancelled && st.rays > (uint64_t)W * H && st.seconds > 0.0);
  assert_int_equal(fr_renderer_spp(r), 2);
  float *img = image_of(r);
  fr_renderer_stats(r, &st);
  assert_true(st.denoise_seconds > 0.0);
  /* a small turn of the camera: most pixels take the image carried over */
  fr_pinhole cam;
  fr_render_desc now;
  fr_renderer_desc(r, &now);
  cam = now.camera;
  const fr_pinhole turned = {{0.2f, 3.0f, 9.0f}, {0.0f, 0.5f, 0.0f}, {0.0f, 1.0f, 0.0f}, 50.0f, W, H};
  const fr_pinhole start = {{0.0f, 3.0f, 9.0f}, {0.0f, 0.5f, 0.0f}, {0.0f, 1.0f, 0.0f}, 50.0f, W, H};
  (void)cam;
  assert_int_equal(fr_renderer_set_camera(r, &start), FR_OK);
  assert_int_equal(fr_renderer_pass(r, NULL), FR_OK);
  assert_int_equal(fr_renderer_set_camera(r, &turned), FR_OK);
  assert_int_equal(fr_renderer_pass(r, NULL), FR_OK);
  fr_renderer_stats(r, &st);
  assert_true(st.reused > 0.5f);
  free(img);
  img = image_of(r);
  for (size_t i = 0; i < (size_t)W * H * 3; i++) assert_true(isfinite(img[i]) && img[i] >= 0.0f);
  free(img);
  fr_renderer_release(r);
  fr_scene_release(s);
}

static void fields_out_of_range(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin_materials(&s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  const fr_render_desc good = desc_of(FR_RENDER_PATH, 4);
  fr_renderer *r = NULL;
  fr_render_desc d;
#define REFUSED(change)                                       \
  d = good;                                                   \
  change;                                                     \
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_ERR_ARG);   \
  assert_null(r);
  REFUSED(d.spp = 0);
  REFUSED(d.max_depth = 65);
  REFUSED((d.shade = FR_RENDER_WHITTED, d.max_depth = 9));
  REFUSED(d.max_depth = -1);
  REFUSED(d.lights = 8);
  REFUSED(d.sampler = (fr_render_sampler)2);
  REFUSED(d.aperture = -0.1f);
  REFUSED(d.focus = NAN);
  REFUSED((d.has_light = 1, d.light[1] = INFINITY));
  REFUSED((d.has_area = 1, d.area_e1[0] = NAN));
  REFUSED(d.area_radiance[2] = -1.0f);
  REFUSED(d.light_intensity[0] = NAN);
  REFUSED(d.env_color[0] = -0.5f);
  REFUSED(d.env_intensity = -1.0f);
  REFUSED(d.env_rotate = 400.0f);
  REFUSED(d.exposure = 31.0f);
  REFUSED(d.pass_spp = 0);
  REFUSED(d.threads = -2);
  REFUSED(d.mirror = "no_such_material");
#undef REFUSED
  /* a scene not from a scene file describes the defaults */
  fr_render_desc of, def;
  fr_render_desc_default(&def);
  assert_int_equal(fr_render_desc_of_scene(s, &of), FR_OK);
  assert_memory_equal(&of, &def, sizeof of);
  assert_int_equal(fr_render_desc_of_scene(NULL, &of), FR_ERR_ARG);
  fr_scene *raw;
  assert_int_equal(fr_scene_builtin_materials(&raw), FR_OK);
  assert_int_equal(fr_render_desc_of_scene(raw, &of), FR_ERR_STATE);
  fr_scene_release(raw);
  d = good;
  d.mirror = "lambert"; /* the showcase's Lambert sphere made chrome */
  assert_int_equal(fr_renderer_new(s, &d, &r), FR_OK);
  fr_renderer_release(r);
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
      cmocka_unit_test(update_keeps_what_it_can),
      cmocka_unit_test(cancel_stats_and_temporal),
      cmocka_unit_test(fields_out_of_range),
      cmocka_unit_test(images_save),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
