/*
 * Ray-by-ray agreement with Embree (robust mode) on the built-in scene and on
 * every scene of ../shared/scenes, by the rule of rayfile.md: camera rays,
 * shadow rays from their hits, hemisphere rays, and random rays, at every ISA.
 */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "embree_tracer.h"
#include "io/rayfile.h"
#include "render/camera.h"
#include "render/views.h"
#include "test_util.h"

#define SIDE 80

static size_t make_rays(const fr_scene *s, fr_ray *rays, size_t cap) {
  fr_view v;
  if (!fr_view_lookup(s->name, &v)) v = fr_view_from_bounds(s->bounds);
  fr_camera cam;
  assert_int_equal(fr_camera_setup(&cam, v.eye, v.at, v.up, v.fov, SIDE, SIDE), FR_OK);
  float eps = 1e-4f * v3_len(v3_sub(s->bounds.hi, s->bounds.lo));
  fr_rng r = fr_rng_seed(5, 5);
  size_t n = 0;
  for (int y = 0; y < SIDE; y++)
    for (int x = 0; x < SIDE; x++) {
      fr_ray pr = fr_camera_ray(&cam, x, y);
      rays[n++] = pr;
      fr_hit h;
      fr_intersect1_reference(s, &pr, &h);
      if (h.prim == FR_INVALID_ID || n + 3 > cap) continue;
      vec3 p = v3_add(v3_load(pr.org), v3_scale(v3_load(pr.dir), h.t));
      vec3 L = v3_sub(v.light, p);
      rays[n++] = (fr_ray){{p.x, p.y, p.z}, eps, {L.x, L.y, L.z}, 1.0f - 1e-4f};
      vec3 d = v3(urand(&r, -1, 1), urand(&r, -1, 1), urand(&r, -1, 1));
      rays[n++] = (fr_ray){{p.x, p.y, p.z}, eps, {d.x, d.y, d.z}, INFINITY};
    }
  vec3 ext = v3_sub(s->bounds.hi, s->bounds.lo);
  while (n < cap) { /* random rays through the bounds */
    vec3 o = v3_add(s->bounds.lo, v3_mul(ext, v3(urand(&r, -0.2f, 1.2f), urand(&r, -0.2f, 1.2f), urand(&r, -0.2f, 1.2f))));
    vec3 d = v3(urand(&r, -1, 1), urand(&r, -1, 1), urand(&r, -1, 1));
    rays[n++] = (fr_ray){{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
  }
  return n;
}

static void check_scene(const char *path) {
  fr_scene *s;
  fr_error e = strcmp(path, "--builtin") == 0 ? fr_scene_builtin(&s) : fr_scene_load(path, &s);
  if (e) fail_msg("%s: %s", path, fr_last_error());
  assert_int_equal(fr_scene_commit(s), FR_OK);
  ebr_scene *eb;
  ebr_options o = {2, 1, 1}; /* robust */
  assert_int_equal(ebr_create(s, o, &eb), FR_OK);
  size_t cap = 4 * SIDE * SIDE;
  fr_ray *rays = malloc(cap * sizeof *rays);
  size_t n = make_rays(s, rays, cap);
  long bad_hit[6] = {0}, bad_occ[6] = {0}, hits = 0;
  for (size_t i = 0; i < n; i++) {
    fr_hit eh;
    ebr_intersect1(eb, &rays[i], &eh);
    int eo = ebr_occluded1(eb, &rays[i]);
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
  free(rays);
  ebr_release(eb);
  fr_scene_release(s);
}

static void test_builtin(void **st) { (void)st; check_scene("--builtin"); }

static void test_shared_scenes(void **st) {
  (void)st;
  const char *root = getenv("FRUSTA_SHARED");
  char dir[1024];
  snprintf(dir, sizeof dir, "%s/scenes", root ? root : "../shared");
  DIR *d = opendir(dir);
  if (!d) fail_msg("cannot open %s: the shared scenes must sit beside the repository", dir);
  int count = 0;
  struct dirent *ent;
  char names[64][256];
  while ((ent = readdir(d)) && count < 64)
    if (ent->d_name[0] != '.') snprintf(names[count++], 256, "%s", ent->d_name);
  closedir(d);
  int checked = 0;
  for (int i = 0; i < count; i++) {
    char sub[1400];
    snprintf(sub, sizeof sub, "%s/%s", dir, names[i]);
    DIR *sd = opendir(sub);
    if (!sd) continue;
    while ((ent = readdir(sd)))
      if (strstr(ent->d_name, ".ply.zst")) {
        char path[2000];
        snprintf(path, sizeof path, "%s/%s", sub, ent->d_name);
        check_scene(path);
        checked++;
      }
    closedir(sd);
  }
  assert_true(checked >= 14);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_builtin), cmocka_unit_test(test_shared_scenes)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
