/*
 * Ray-by-ray agreement with Embree (robust mode) on the built-in scene, the
 * sphereflake (analytic spheres), and every scene of ../shared/scenes, by the rule of rayfile.md: camera rays,
 * shadow rays from their hits, hemisphere rays, and random rays, at every ISA.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "embree_tracer.h"
#include "io/rayfile.h"
#include "render/camera.h"
#include "render/views.h"
#include "test_util.h"

#define SIDE (FR_TEST_SANITIZED ? 40 : 80)

/* Camera rays in 4x4 pixel blocks, then a shadow ray and a hemisphere ray
 * from each hit (in the same order), then random rays through the bounds: as
 * coherent in groups of 16 as the renderers' rays, for the packet modes. */
static size_t make_rays(const fr_scene *s, fr_ray *rays, size_t cap) {
  fr_view v = fr_view_of(s->name, s->bounds);
  fr_camera cam;
  assert_int_equal(fr_camera_setup(&cam, v.eye, v.at, v.up, v.fov, SIDE, SIDE), FR_OK);
  float eps = 1e-4f * v3_len(v3_sub(s->bounds.hi, s->bounds.lo));
  fr_rng r = fr_rng_seed(5, 5);
  size_t n = 0;
  for (int by = 0; by < SIDE; by += 4)
    for (int bx = 0; bx < SIDE; bx += 4)
      for (int k = 0; k < 16; k++) rays[n++] = fr_camera_ray(&cam, bx + (k & 3), by + (k >> 2));
  size_t ncam = n, nshadow;
  for (int pass = 0; pass < 2; pass++) {
    if (pass == 1) nshadow = n;
    for (size_t i = 0; i < ncam && n < cap; i++) {
      fr_hit h;
      fr_intersect1_reference(s, &rays[i], &h);
      if (h.prim == FR_INVALID_ID) continue;
      vec3 p = v3_add(v3_load(rays[i].org), v3_scale(v3_load(rays[i].dir), h.t));
      if (pass == 0) {
        vec3 L = v3_sub(v.light, p);
        rays[n++] = (fr_ray){{p.x, p.y, p.z}, eps, {L.x, L.y, L.z}, 1.0f - 1e-4f};
      } else {
        vec3 d = v3(urand(&r, -1, 1), urand(&r, -1, 1), urand(&r, -1, 1));
        rays[n++] = (fr_ray){{p.x, p.y, p.z}, eps, {d.x, d.y, d.z}, INFINITY};
      }
    }
  }
  (void)nshadow;
  vec3 ext = v3_sub(s->bounds.hi, s->bounds.lo);
  while (n < cap) { /* random rays through the bounds */
    vec3 o = v3_add(s->bounds.lo, v3_mul(ext, v3(urand(&r, -0.2f, 1.2f), urand(&r, -0.2f, 1.2f), urand(&r, -0.2f, 1.2f))));
    vec3 d = v3(urand(&r, -1, 1), urand(&r, -1, 1), urand(&r, -1, 1));
    rays[n++] = (fr_ray){{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
  }
  return n;
}

/* The packet and ray-stream modes through the stream calls, at every ISA: against Embree's
 * answers eh/eo. Returns the most disagreements (closest + any) of one mode
 * at one ISA. */
static long check_packet_modes(fr_scene *s, const fr_ray *rays, size_t n, const fr_hit *eh, const uint8_t *eo) {
  static const fr_trace_mode modes[] = {FR_TRACE_PACKET8, FR_TRACE_PACKET16, FR_TRACE_HYBRID16, FR_TRACE_AUTO,
                                        FR_TRACE_RAYSTREAM};
  static const char *names[] = {"packet8", "packet16", "hybrid16", "auto", "raystream"};
  fr_hit *h = malloc(n * sizeof *h);
  uint8_t *occ = malloc(n);
  long total = 0;
  char line[512];
  int len = snprintf(line, sizeof line, "%-12s packets:", s->name);
  for (int isa = 0; isa < 3; isa++) {
    if (!fr_isa_supported((fr_isa)isa)) continue;
    fr_set_isa((fr_isa)isa);
    for (int m = 0; m < 5; m++) {
      fr_tuning o;
      fr_tuning_default(&o);
      o.mode = modes[m];
      assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
      memset(h, 0x5A, n * sizeof *h); /* every ray must be answered */
      memset(occ, 0x5A, n);
      fr_intersect_stream(s, rays, h, n);
      fr_occluded_stream(s, rays, occ, n);
      long bad = 0;
      for (size_t i = 0; i < n; i++) {
        bad += !fr_hits_agree(h[i].t, eh[i].t);
        bad += occ[i] != eo[i] && !fr_occlusion_near_boundary(&rays[i], h[i].t) &&
               !fr_occlusion_near_boundary(&rays[i], eh[i].t);
      }
      len += snprintf(line + len, sizeof line - (size_t)len, " %s/%s=%ld", fr_isa_name((fr_isa)isa), names[m], bad);
      if (bad > total) total = bad;
    }
  }
  fr_tuning o;
  fr_tuning_default(&o);
  fr_scene_set_tuning(s, &o);
  print_message("%s\n", line);
  free(h);
  free(occ);
  return total;
}

static void check_scene(const char *path) {
  fr_scene *s;
  fr_error e = strcmp(path, "--builtin") == 0               ? fr_scene_builtin(&s)
               : strcmp(path, "--builtin=sphereflake") == 0 ? fr_scene_builtin_sphereflake(3, &s)
                                                            : fr_scene_load(path, &s);
  if (e) fail_msg("%s: %s", path, fr_last_error());
  assert_int_equal(fr_scene_commit(s), FR_OK);
  ebr_scene *eb;
  ebr_options o = {.threads = 2, .quality = 1, .robust = 1}; /* robust */
  assert_int_equal(ebr_create(s, o, &eb), FR_OK);
  size_t cap = 4 * SIDE * SIDE;
  fr_ray *rays = malloc(cap * sizeof *rays);
  size_t n = make_rays(s, rays, cap);
  long bad_hit[6] = {0}, bad_occ[6] = {0}, hits = 0;
  fr_hit *ehits = malloc(n * sizeof *ehits);
  uint8_t *eoccs = malloc(n);
  fr_tuning single;
  fr_tuning_default(&single);
  single.mode = FR_TRACE_SINGLE;
  fr_scene_set_tuning(s, &single);
  for (size_t i = 0; i < n; i++) {
    fr_hit eh;
    ebr_intersect1(eb, &rays[i], &eh);
    int eo = ebr_occluded1(eb, &rays[i]);
    ehits[i] = eh;
    eoccs[i] = (uint8_t)eo;
    hits += eh.prim != FR_INVALID_ID;
    for (int isa = 0; isa < 6; isa++) { /* ISA x BVH width */
      if (!fr_isa_supported((fr_isa)(isa % 3))) continue;
      fr_set_isa((fr_isa)(isa % 3));
      fr_scene_set_bvh_width(s, isa < 3 ? 4 : 8);
      fr_hit h;
      fr_intersect1(s, &rays[i], &h);
      if (!fr_hits_agree(h.t, eh.t)) bad_hit[isa]++;
      int fo = fr_occluded1(s, &rays[i]);
      if (fo != eo && !fr_occlusion_near_boundary(&rays[i], h.t) && !fr_occlusion_near_boundary(&rays[i], eh.t)) bad_occ[isa]++;
    }
  }
  print_message("%-12s tris=%8zu rays=%zu hits=%ld disagree closest %ld/%ld/%ld|%ld/%ld/%ld any %ld/%ld/%ld|%ld/%ld/%ld"
                " (bvh4|bvh8, scalar/avx2/avx512)\n", s->name, fr_scene_triangle_count(s), n, hits, bad_hit[0], bad_hit[1],
                bad_hit[2], bad_hit[3], bad_hit[4], bad_hit[5], bad_occ[0], bad_occ[1], bad_occ[2], bad_occ[3], bad_occ[4], bad_occ[5]);
  /* Every scene agrees on every ray today; a ray within float rounding of a
   * silhouette edge may one day land differently in two correct tracers (or on
   * another CPU, where Embree picks other kernels), so one per scene is let
   * pass. Before the closest hit's t was refined (fr_tri_refine_t) conference
   * and sibenik had 3 such rays, all frusta's error. */
  for (int i = 0; i < 6; i++) {
    assert_true(bad_hit[i] <= 1);
    assert_true(bad_occ[i] <= 1);
  }
  assert_true(hits > (long)n / 10);
  /* Packets test triangles with Shevtsov's test, which is not watertight: a
   * ray exactly through a shared edge or vertex may slip through. Two rays of
   * spd_tetra do (in pure packet modes; the hybrid finishes them with the
   * watertight single-ray test), so two per mode are let pass. */
  long bad_packets = check_packet_modes(s, rays, n, ehits, eoccs);
  assert_true(bad_packets <= 2);
  free(ehits);
  free(eoccs);
  free(rays);
  ebr_release(eb);
  fr_scene_release(s);
}

static void test_builtin(void **st) { (void)st; check_scene("--builtin"); }
/* analytic spheres against Embree's sphere points */
static void test_sphereflake(void **st) { (void)st; check_scene("--builtin=sphereflake"); }

static void check_scene_path(const char *path, void *ctx) { (void)ctx; check_scene(path); }

static void test_shared_scenes(void **st) {
  (void)st;
  assert_true(for_each_shared_scene(check_scene_path, NULL) >= 14);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_builtin), cmocka_unit_test(test_sphereflake),
                                     cmocka_unit_test(test_shared_scenes)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
