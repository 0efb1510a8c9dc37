/*
 * The single-ray streams' occluder cache (fr_tuning.occluder_cache):
 * on the built-in scene and every scene of ../shared/scenes, soft-shadow
 * rays from the camera's hit points to the scene's quad light, pixel by
 * pixel as the workloads make them, with hemisphere rays (no end, so never
 * cached) and an invalid ray mixed in. At every ISA, fr_occluded_stream in
 * single mode must give the same answer for every ray with the cache on
 * and off, with the any-hit walk by occlusion rank, nearest child first and
 * chosen by measurement (fr_tuning.anyhit_order), and the same as
 * fr_occluded1 ray by ray. A counters build also
 * checks that the cache was tried and hit (on the built-in scene, and over
 * the shared scenes).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "render/camera.h"
#include "render/views.h"
#include "test_util.h"
#include "trace/counters.h"

enum { SZ = FR_TEST_SANITIZED ? 24 : 40, SAMPLES = 16 };

/* cache tries and hits over the scenes checked (counters builds only) */
static long tally_tries, tally_hits;
static void check_tally(void) {
  if (!fr_counters_enabled()) return;
  assert_true(tally_tries > 0);
  assert_true(tally_hits > 0);
}

/* Rays from the hit points of a SZ x SZ camera: per pixel SAMPLES shadow
 * rays to the quad light (stratified 4 x 4, jittered), then one ray about
 * the normal-free hemisphere (tfar infinite); every 97th ray invalid. */
static size_t make_rays(fr_scene *s, const fr_view *v, fr_ray *rays) {
  fr_camera cam;
  assert_int_equal(fr_camera_setup(&cam, v->eye, v->at, v->up, v->fov, SZ, SZ), FR_OK);
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  const float eps = 1e-4f * v3_len(v3_sub(v3_load(hi), v3_load(lo)));
  fr_rng r = fr_rng_seed(55, 1);
  size_t n = 0;
  for (int y = 0; y < SZ; y++)
    for (int x = 0; x < SZ; x++) {
      fr_ray c = fr_camera_ray(&cam, x, y);
      fr_hit h;
      fr_intersect1(s, &c, &h);
      if (h.prim == FR_INVALID_ID) continue;
      const vec3 p = v3_add(v3_load(c.org), v3_scale(v3_load(c.dir), h.t));
      for (int k = 0; k < SAMPLES; k++) {
        const float a = ((float)(k % 4) + fr_rng_float(&r)) / 4.0f, b = ((float)(k / 4) + fr_rng_float(&r)) / 4.0f;
        const vec3 l = v3_add(v->area_c, v3_add(v3_scale(v->area_e1, a), v3_scale(v->area_e2, b)));
        const vec3 d = v3_sub(l, p);
        fr_ray sr = {{p.x, p.y, p.z}, eps / v3_len(d), {d.x, d.y, d.z}, 1.0f - 1e-4f};
        rays[n++] = sr;
      }
      const vec3 d = v3(urand(&r, -1, 1), urand(&r, -1, 1), urand(&r, -1, 1));
      fr_ray hr = {{p.x, p.y, p.z}, eps, {d.x, d.y, d.z}, INFINITY};
      rays[n++] = hr;
      if (n % 97 == 0) rays[n - 1].dir[0] = NAN;
    }
  return n;
}

static void check_scene(fr_scene *s, const fr_view *v) {
  fr_ray *rays = malloc((size_t)SZ * SZ * (SAMPLES + 1) * sizeof *rays);
  const size_t n = make_rays(s, v, rays);
  uint8_t *on = malloc(n), *off = malloc(n), *one = malloc(n), *ordered = malloc(n);
  fr_tuning o;
  fr_tuning_default(&o);
  assert_int_equal(o.occluder_cache, 1);
  o.mode = FR_TRACE_SINGLE;
  long occluded = 0;
  const fr_isa was = fr_get_isa();
  for (int isa = 0; isa < 3; isa++) {
    if (!fr_isa_supported((fr_isa)isa)) continue;
    assert_int_equal(fr_set_isa((fr_isa)isa), FR_OK);
    for (size_t i = 0; i < n; i++) one[i] = (uint8_t)fr_occluded1(s, &rays[i]);
    o.occluder_cache = 0;
    assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
    memset(off, 0x5A, n);
    fr_occluded_stream(s, rays, off, n);
    o.occluder_cache = 1;
    assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
    fr_counters_reset();
    memset(on, 0x5A, n);
    fr_occluded_stream(s, rays, on, n);
#ifdef FRUSTA_COUNTERS
    fr_counters_flush();
#endif
    const fr_counters c = fr_counters_read();
    tally_tries += (long)c.cache_tries;
    tally_hits += (long)c.cache_hits;
    for (int order = 0; order <= 1; order++) {
      o.anyhit_order = order;
      assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
      memset(ordered, 0x5A, n);
      fr_occluded_stream(s, rays, ordered, n);
      for (size_t i = 0; i < n; i++)
        if (ordered[i] != one[i])
          fail_msg("%s, %s, ray %zu: %s first %d, fr_occluded1 %d", s->name, fr_isa_name((fr_isa)isa), i,
                   order ? "nearest" : "rank", ordered[i], one[i]);
    }
    o.anyhit_order = -1;
    assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
    occluded = 0;
    for (size_t i = 0; i < n; i++) {
      if (on[i] != off[i] || on[i] != one[i])
        fail_msg("%s, %s, ray %zu: cache on %d, off %d, fr_occluded1 %d", s->name, fr_isa_name((fr_isa)isa), i, on[i],
                 off[i], one[i]);
      occluded += on[i];
    }
    print_message("%s %s: %zu rays, %ld occluded; cache tries %llu, hits %llu%s\n", s->name,
                  fr_isa_name((fr_isa)isa), n, occluded, (unsigned long long)c.cache_tries,
                  (unsigned long long)c.cache_hits, fr_counters_enabled() ? "" : " (no counters in this build)");
  }
  /* every scene's light is partly blocked from these points */
  assert_true(occluded > 0 && (size_t)occluded < n);
  assert_int_equal(fr_set_isa(was), FR_OK);
  free(rays);
  free(on);
  free(off);
  free(one);
  free(ordered);
}

/* Commits s, checks it from its own view, and releases it. */
static void check_and_release(fr_scene *s) {
  assert_int_equal(fr_scene_commit(s), FR_OK);
  fr_view v;
  if (!fr_view_lookup(s->name, &v)) fail_msg("%s: no view", s->name);
  check_scene(s, &v);
  fr_scene_release(s);
}

static void builtin_scene(void **st) {
  (void)st;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  tally_tries = tally_hits = 0;
  check_and_release(s);
  check_tally();
}

static void shared_one(const char *path, void *ctx) {
  (void)ctx;
  fr_scene *s;
  if (fr_scene_load(path, &s) != FR_OK) fail_msg("%s: %s", path, fr_last_error());
  check_and_release(s);
}

static void shared_scenes(void **st) {
  (void)st;
  tally_tries = tally_hits = 0;
  assert_true(for_each_shared_scene(shared_one, NULL) > 0);
  check_tally();
}

/* The option takes 0 or 1. */
static void option(void **st) {
  (void)st;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  fr_tuning o;
  fr_tuning_default(&o);
  o.occluder_cache = 2;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_ERR_ARG);
  o.occluder_cache = 0;
  assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
  fr_scene_release(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(option),
      cmocka_unit_test(builtin_scene),
      cmocka_unit_test(shared_scenes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
