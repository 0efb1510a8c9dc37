/*
 * Watertightness: from inside a closed mesh every ray must hit, including rays
 * aimed exactly at shared vertices and along shared edges' midpoints, at every
 * ISA level. A test that is not watertight lets a few of these slip through.
 */
#include <stdlib.h>
#include "test_util.h"

static void shoot_from_inside(vec3 center, float radius) {
  fr_rng r = fr_rng_seed(99, (uint64_t)(radius * 1000));
  float *pos;
  size_t nv;
  fr_scene *s = closed_latlong_sphere(&r, center, radius, 24, 48, &pos, &nv);
  const uint32_t *idx = fr_scene_indices(s);
  size_t nt = fr_scene_triangle_count(s);
  long missed[6] = {0}, shot = 0;
  for (int k = 0; k < 20000; k++) {
    vec3 o = v3_add(center, v3(urand(&r, -0.3f, 0.3f) * radius, urand(&r, -0.3f, 0.3f) * radius, urand(&r, -0.3f, 0.3f) * radius));
    vec3 target;
    int mode = k % 3;
    if (mode == 0) target = v3_load(pos + 3 * (fr_rng_u32(&r) % nv));           /* a vertex exactly */
    else if (mode == 1) {                                                          /* an edge midpoint */
      size_t t = fr_rng_u32(&r) % nt;
      int e = (int)(fr_rng_u32(&r) % 3);
      target = v3_scale(v3_add(v3_load(pos + 3 * idx[3 * t + e]), v3_load(pos + 3 * idx[3 * t + (e + 1) % 3])), 0.5f);
    } else target = v3_add(o, v3(urand(&r, -1, 1), urand(&r, -1, 1), urand(&r, -1, 1)));
    vec3 d = v3_sub(target, o);
    if (v3_len(d) == 0.0f) continue;
    fr_ray ray = {{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
    shot++;
    for (int k = 0; k < 6; k++) { /* ISA x BVH width */
      if (!fr_isa_supported((fr_isa)(k % 3))) continue;
      fr_set_isa((fr_isa)(k % 3));
      fr_scene_set_bvh_width(s, k < 3 ? 4 : 8);
      fr_hit h;
      fr_intersect1(s, &ray, &h);
      missed[k] += h.prim == FR_INVALID_ID;
      missed[k] += !fr_occluded1(s, &ray);
    }
  }
  print_message("closed sphere r=%g at (%g,%g,%g): %ld rays, missed bvh4 %ld/%ld/%ld bvh8 %ld/%ld/%ld (scalar/avx2/avx512)\n",
                radius, center.x, center.y, center.z, shot, missed[0], missed[1], missed[2], missed[3], missed[4], missed[5]);
  for (int i = 0; i < 6; i++) assert_int_equal(missed[i], 0);
  fr_scene_release(s);
  free(pos);
}

static void test_closed_unit(void **st) { (void)st; shoot_from_inside(v3(0, 0, 0), 1.0f); }
static void test_closed_far(void **st) { (void)st; shoot_from_inside(v3(3e3f, -1e3f, 7e2f), 2.0f); }
static void test_closed_small(void **st) { (void)st; shoot_from_inside(v3(0.01f, 0.02f, 0.0f), 1e-3f); }

/* The built-in scene's spheres and boxes are closed too: from each object's
 * centre, rays at every one of its vertices must hit. */
static void test_builtin_objects_closed(void **st) {
  (void)st;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  const float *pos = fr_scene_vertices(s);
  /* the sphere at grid (0,0) and the box at grid (0,1), see geom/builtin_scene.c */
  vec3 centers[2] = {v3(-8.25f, 0.45f, -8.25f), v3(-8.25f, 0.3f, -6.75f)};
  long missed = 0, shot = 0;
  for (size_t v = 4; v < fr_scene_vertex_count(s); v++) {
    vec3 p = v3_load(pos + 3 * v);
    for (int c = 0; c < 2; c++) {
      vec3 d = v3_sub(p, centers[c]);
      if (v3_len(d) > 0.8f) continue;
      fr_ray ray = {{centers[c].x, centers[c].y, centers[c].z}, 0, {d.x, d.y, d.z}, INFINITY};
      fr_hit h;
      fr_intersect1(s, &ray, &h);
      shot++;
      missed += h.prim == FR_INVALID_ID;
    }
  }
  assert_true(shot > 1000);
  assert_int_equal(missed, 0);
  fr_scene_release(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_closed_unit),
      cmocka_unit_test(test_closed_far),
      cmocka_unit_test(test_closed_small),
      cmocka_unit_test(test_builtin_objects_closed),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
