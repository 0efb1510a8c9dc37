/* Ray, hit and occlusion files: round trips and refusals (rayfile.md). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "io/rayfile.h"
#include "test_util.h"

static char dir[256];

static const char *path(const char *name) {
  static char p[512];
  snprintf(p, sizeof p, "%s/%s", dir, name);
  return p;
}

static void test_round_trip(void **st) {
  (void)st;
  fr_ray rays[3] = {{{1, 2, 3}, 0.5f, {0, 0, 1}, INFINITY}, {{-1, 0, 0}, 0, {1, 1, 0}, 10}, {{0, 0, 0}, 0, {0, -1, 0}, 1}};
  assert_int_equal(fr_rays_write(path("a.rays"), rays, 3), FR_OK);
  fr_ray *back;
  size_t n;
  assert_int_equal(fr_rays_read(path("a.rays"), &back, &n), FR_OK);
  assert_int_equal(n, 3);
  assert_memory_equal(back, rays, sizeof rays);
  free(back);
  fr_hit hits[2] = {{2.5f, 0.25f, 0.5f, 7, {0, 0, 1}}, {INFINITY, 0.3f, 0.3f, FR_INVALID_ID, {0, 0, 0}}};
  assert_int_equal(fr_hits_write(path("a.hits"), hits, 2), FR_OK);
  fr_hit_record *hr;
  assert_int_equal(fr_hits_read(path("a.hits"), &hr, &n), FR_OK);
  assert_int_equal(n, 2);
  assert_true(hr[0].t == 2.5f && hr[0].prim == 7 && hr[0].u == 0.25f && hr[0].v == 0.5f);
  assert_true(isinf(hr[1].t) && hr[1].prim == FR_INVALID_ID && hr[1].u == 0 && hr[1].v == 0); /* miss record per spec */
  free(hr);
  uint8_t occ[4] = {1, 0, 0, 1}, *ob;
  assert_int_equal(fr_occl_write(path("a.occl"), occ, 4), FR_OK);
  assert_int_equal(fr_occl_read(path("a.occl"), &ob, &n), FR_OK);
  assert_int_equal(n, 4);
  assert_memory_equal(ob, occ, 4);
  free(ob);
}

static void test_refusals(void **st) {
  (void)st;
  fr_ray *r;
  size_t n;
  FILE *f = fopen(path("lie.rays"), "wb");
  uint64_t cnt = 1000;
  fwrite("RAYS0001", 1, 8, f);
  fwrite(&cnt, 8, 1, f);
  float rec[8] = {0};
  fwrite(rec, 4, 8, f);
  fclose(f);
  assert_int_equal(fr_rays_read(path("lie.rays"), &r, &n), FR_ERR_FORMAT);
  assert_int_equal(fr_rays_read(path("a.hits"), &r, &n), FR_ERR_FORMAT); /* wrong magic */
  assert_int_equal(fr_rays_read(path("missing.rays"), &r, &n), FR_ERR_IO);
  f = fopen(path("huge.rays"), "wb");
  cnt = UINT64_MAX / 2;
  fwrite("RAYS0001", 1, 8, f);
  fwrite(&cnt, 8, 1, f);
  fclose(f);
  assert_int_equal(fr_rays_read(path("huge.rays"), &r, &n), FR_ERR_FORMAT);
  /* writing into a missing folder fails and leaves nothing */
  fr_hit h = {1, 0, 0, 0, {0, 0, 0}};
  assert_int_equal(fr_hits_write("/nonexistent-dir/x.hits", &h, 1), FR_ERR_IO);
}

static void test_compare_rule(void **st) {
  (void)st;
  assert_true(fr_hits_agree(INFINITY, INFINITY));
  assert_false(fr_hits_agree(INFINITY, 1.0f));
  assert_true(fr_hits_agree(1000.0f, 1000.09f));
  assert_false(fr_hits_agree(1000.0f, 1000.2f));
  assert_true(fr_hits_agree(0.5f, 0.50009f));
  fr_ray r = {{0, 0, 0}, 0.1f, {1, 0, 0}, 10.0f};
  assert_true(fr_occlusion_near_boundary(&r, 0.10005f));
  assert_true(fr_occlusion_near_boundary(&r, 9.9995f));
  assert_false(fr_occlusion_near_boundary(&r, 5.0f));
}

int main(void) {
  snprintf(dir, sizeof dir, "/tmp/frusta_test_rayfile_%d", (int)getpid());
  char cmd[300];
  snprintf(cmd, sizeof cmd, "mkdir -p %s", dir);
  if (system(cmd) != 0) return 1;
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_round_trip), cmocka_unit_test(test_refusals), cmocka_unit_test(test_compare_rule)};
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
  if (system(cmd) != 0) rc = 1;
  return rc;
}
