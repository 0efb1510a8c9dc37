/*
 * Multi-frusta for library users, against the ray calls ray by ray, at
 * every ISA: fr_intersect_camera (whole images and odd bands, image sizes
 * that cut 4x4 blocks and 16x16 tiles) against fr_intersect1 on the rays it
 * returns and on the camera's own rays, and fr_intersect_camera_arrays
 * against it bit for bit; fr_occluded_point_light against fr_occluded1 on
 * the same segments, those segments as each ISA makes them against the
 * scalar formula bit for bit, and the frusta made straight from the points
 * against those made from the segments. A disagreement must be a ray
 * within rounding of an edge or of its range's ends (rayfile.md's rule).
 * Errors.
 */
#include "test_util.h"
#include "render/camera.h"
#include "render/mft_rays.h"

typedef struct tally { long rays, hits, disagree, excused; } tally;

static void check_hit(const fr_scene *s, const mesh_ref *m, const fr_ray *r, const fr_hit *got, tally *tl) {
  fr_hit want;
  fr_intersect1(s, r, &want);
  tl->rays++;
  tl->hits += got->prim != FR_INVALID_ID;
  int agree = (got->prim == FR_INVALID_ID && want.prim == FR_INVALID_ID) ||
              (got->prim != FR_INVALID_ID && want.prim != FR_INVALID_ID &&
               fabsf(got->t - want.t) <= 1e-4f * fmaxf(1.0f, fabsf(want.t)));
  if (agree && got->prim == want.prim)
    for (int k = 0; k < 3; k++) assert_true(fabsf(got->ng[k] - want.ng[k]) <= 1e-5f * (fabsf(want.ng[0]) + fabsf(want.ng[1]) + fabsf(want.ng[2])));
  if (agree) return;
  tl->disagree++;
  if (!ambiguous(m, r)) fail_msg("ray (%g %g %g) -> (%g %g %g): got prim %u t %g, fr_intersect1 prim %u t %g", r->org[0],
                                 r->org[1], r->org[2], r->dir[0], r->dir[1], r->dir[2], got->prim, got->t, want.prim,
                                 want.t);
  tl->excused++;
}

/* fr_intersect_camera_arrays gives fr_intersect_camera's answers (rays and
 * hits of rows [y0, y0 + rows), normals or not) bit for bit, with every
 * array and with some left NULL, which it must not write. */
static void arrays_match_records(const fr_scene *s, const fr_pinhole *p, int y0, int rows, const fr_ray *rays,
                                 const fr_hit *hits) {
  size_t n = (size_t)rows * (size_t)p->width;
  float *t = malloc((n + 1) * sizeof *t), *u = malloc((n + 1) * sizeof *u), *v = malloc((n + 1) * sizeof *v);
  float *ng = malloc((3 * n + 1) * sizeof *ng), *dir = malloc((3 * n + 1) * sizeof *dir);
  uint32_t *prim = malloc((n + 1) * sizeof *prim);
  fr_hit_arrays all = {t, u, v, prim, ng, dir};
  assert_int_equal(fr_intersect_camera_arrays(s, p, y0, rows, &all), FR_OK);
  for (size_t i = 0; i < n; i++) {
    assert_memory_equal(&t[i], &hits[i].t, sizeof(float));
    assert_memory_equal(&u[i], &hits[i].u, sizeof(float));
    assert_memory_equal(&v[i], &hits[i].v, sizeof(float));
    assert_int_equal(prim[i], hits[i].prim);
    assert_memory_equal(ng + 3 * i, hits[i].ng, 3 * sizeof(float));
    assert_memory_equal(dir + 3 * i, rays[i].dir, 3 * sizeof(float));
  }
  /* t and prim alone: the same, and nothing else written */
  memset(u, 0x7f, n * sizeof *u);
  for (size_t i = 0; i < n; i++) t[i] = -1.0f, prim[i] = 7u;
  fr_hit_arrays some = {t, NULL, NULL, prim, NULL, NULL};
  assert_int_equal(fr_intersect_camera_arrays(s, p, y0, rows, &some), FR_OK);
  for (size_t i = 0; i < n; i++) {
    assert_memory_equal(&t[i], &hits[i].t, sizeof(float));
    assert_int_equal(prim[i], hits[i].prim);
    assert_int_equal(((const uint32_t *)u)[i], 0x7f7f7f7fu);
  }
  free(t); free(u); free(v); free(ng); free(dir); free(prim);
}

static void camera_against_rays(const fr_scene *s, const fr_pinhole *p, tally *tl) {
  mesh_ref m = scene_mesh(s);
  size_t n = (size_t)p->width * (size_t)p->height;
  fr_ray *rays = malloc(n * sizeof *rays);
  fr_hit *hits = malloc(n * sizeof *hits);
  assert_int_equal(fr_intersect_camera(s, p, 0, p->height, 0, rays, hits), FR_OK);
  fr_camera cam;
  assert_int_equal(fr_camera_setup(&cam, v3_load(p->eye), v3_load(p->at), v3_load(p->up), p->fov_deg, p->width, p->height),
                   FR_OK);
  for (int y = 0; y < p->height; y++)
    for (int x = 0; x < p->width; x++) {
      size_t i = (size_t)y * (size_t)p->width + (size_t)x;
      fr_ray own = fr_camera_ray(&cam, x, y);
      for (int k = 0; k < 3; k++) {
        assert_true(rays[i].org[k] == p->eye[k]);
        assert_true(fabsf(rays[i].dir[k] - own.dir[k]) <= 1e-5f);
      }
      check_hit(s, &m, &rays[i], &hits[i], tl);
    }
  arrays_match_records(s, p, 0, p->height, rays, hits);
  /* a band starting off the tiles' grid: its own frusta, the same answers */
  int y0 = 5, rows = p->height - 9 < 37 ? p->height - 9 : 37;
  fr_ray *br = malloc((size_t)rows * (size_t)p->width * sizeof *br);
  fr_hit *bh = malloc((size_t)rows * (size_t)p->width * sizeof *bh);
  assert_int_equal(fr_intersect_camera(s, p, y0, rows, 0, br, bh), FR_OK);
  for (size_t i = 0; i < (size_t)rows * (size_t)p->width; i++) check_hit(s, &m, &br[i], &bh[i], tl);
  arrays_match_records(s, p, y0, rows, br, bh);
  /* rays may be NULL; without normals, the same hits and ng zero */
  fr_hit *nn = malloc((size_t)rows * (size_t)p->width * sizeof *nn);
  assert_int_equal(fr_intersect_camera(s, p, y0, rows, FR_CAMERA_NO_NORMALS, NULL, nn), FR_OK);
  for (size_t i = 0; i < (size_t)rows * (size_t)p->width; i++) {
    assert_true(nn[i].t == bh[i].t && nn[i].prim == bh[i].prim && nn[i].u == bh[i].u);
    assert_true(nn[i].ng[0] == 0.0f && nn[i].ng[1] == 0.0f && nn[i].ng[2] == 0.0f);
  }
  free(nn);
  assert_int_equal(fr_intersect_camera(s, p, y0, rows, 2, NULL, bh), FR_ERR_ARG);
  free(br); free(bh);

  /* shadows of the image's hit points towards a point light */
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  float light[3] = {0.5f * (lo[0] + hi[0]), hi[1] - 0.05f * (hi[1] - lo[1]), 0.5f * (lo[2] + hi[2])};
  float eps = 1e-5f * v3_len(v3_sub(v3_load(hi), v3_load(lo)));
  float *pts = malloc(3 * n * sizeof *pts);
  size_t np = 0;
  for (size_t i = 0; i < n; i++) {
    if (hits[i].prim == FR_INVALID_ID) continue;
    for (int k = 0; k < 3; k++) pts[3 * np + k] = rays[i].org[k] + hits[i].t * rays[i].dir[k];
    np++;
  }
  /* the segments, 16 at a time in this ISA, are the scalar ones bit for bit;
     a point at the light or not finite makes an empty ray */
  {
    float odd[3 * 37];
    for (int i = 0; i < 37; i++)
      for (int k = 0; k < 3; k++) odd[3 * i + k] = pts[3 * ((size_t)i % (np ? np : 1)) + k]; /* neighbours */
    memcpy(odd + 3 * 5, light, sizeof light);
    odd[3 * 9 + 1] = NAN;
    odd[3 * 36 + 2] = INFINITY;
    fr_ray got[37];
    fr_mft_active()->rays_to_points(light, odd, 37, eps, got);
    for (int i = 0; i < 37; i++) {
      const float *q = odd + 3 * i;
      float d[3] = {q[0] - light[0], q[1] - light[1], q[2] - light[2]};
      float dist = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      fr_ray want = {{light[0], light[1], light[2]}, 1e-4f * dist, {d[0] / dist, d[1] / dist, d[2] / dist}, dist - eps};
      if (!(want.tfar > want.tnear)) want.tnear = want.tfar = want.dir[0] = want.dir[1] = want.dir[2] = 0.0f;
      assert_memory_equal(&got[i], &want, sizeof want);
      if (i == 5 || i == 9 || i == 36) assert_true(got[i].tfar == 0.0f);
    }
    /* frusta made straight from the points are those made from the segments */
    static fr_mft_sets ta, tb;
    fr_mft_batch ba, bb;
    memset(&ta, 0, sizeof ta);
    memset(&tb, 0, sizeof tb);
    const unsigned va = fr_mft_active()->from_rays(&ba, &ta, got, 37);
    const unsigned vb = fr_mft_active()->from_points(&bb, &tb, light, odd, 37, eps);
    assert_int_equal(va, vb);
    assert_true(va != 0); /* some frusta made */
    assert_memory_equal(&ba, &bb, sizeof ba);
    assert_memory_equal(&ta, &tb, sizeof ta);
  }
  uint8_t *occ = malloc(np + 1);
  assert_int_equal(fr_occluded_point_light(s, light, pts, np, eps, occ), FR_OK);
  long shadowed = 0;
  for (size_t i = 0; i < np; i++) {
    const float *q = pts + 3 * i;
    float d[3] = {q[0] - light[0], q[1] - light[1], q[2] - light[2]};
    float dist = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    fr_ray r = {{light[0], light[1], light[2]}, 1e-4f * dist, {d[0] / dist, d[1] / dist, d[2] / dist}, dist - eps};
    int want = fr_occluded1(s, &r);
    shadowed += occ[i];
    tl->rays++;
    if (occ[i] == want) continue;
    tl->disagree++;
    if (!ambiguous(&m, &r)) fail_msg("point %zu: occluded %d, fr_occluded1 %d", i, occ[i], want);
    tl->excused++;
  }
  assert_true(shadowed > 0 && shadowed < (long)np); /* the light is neither everywhere nor nowhere */

  /* an area light over the scene: each point's 16 rays against fr_occluded1 */
  const float qc[3] = {light[0] - 0.2f * (hi[0] - lo[0]), light[1], light[2] - 0.2f * (hi[2] - lo[2])};
  const float qe1[3] = {0.4f * (hi[0] - lo[0]), 0.0f, 0.0f}, qe2[3] = {0.0f, 0.0f, 0.4f * (hi[2] - lo[2])};
  float *vis = malloc((np + 1) * sizeof *vis), *vis2 = malloc((np + 1) * sizeof *vis2);
  assert_int_equal(fr_visibility_area_light(s, qc, qe1, qe2, pts, np, 16, 7, eps, vis), FR_OK);
  fr_mft_sets T;
  fr_mft_sets_light(&T, qe1, qe2, 7, FR_LIGHT_SETS_SPREAD);
  const vec3 centre = v3_add(v3_load(qc), v3_scale(v3_add(v3_load(qe1), v3_load(qe2)), 0.5f));
  int partial = 0;
  for (size_t i = 0; i < np; i++) {
    const size_t j = i % 256;
    fr_mft_batch b;
    memset(&b, 0, sizeof b);
    const vec3 q = v3_load(pts + 3 * i), st = v3_sub(v3_load(qc), q);
    b.org[0][0] = q.x, b.org[1][0] = q.y, b.org[2][0] = q.z;
    b.start[0][0] = st.x, b.start[1][0] = st.y, b.start[2][0] = st.z;
    b.tnear[0] = eps / v3_len(v3_sub(centre, q));
    b.tfar[0] = 1.0f - 1e-4f;
    b.set[0] = (uint8_t)fr_mft_light_set((int)(j & 3), (int)((j >> 2) & 3));
    fr_ray r16[16];
    int open = 0;
    for (int k = 0; k < 16; k++) {
      fr_mft_ray(&b, &T, 0, k, r16[k].org, r16[k].dir);
      r16[k].tnear = b.tnear[0], r16[k].tfar = b.tfar[0];
      open += !fr_occluded1(s, &r16[k]);
    }
    partial += open > 0 && open < 16;
    tl->rays += 16;
    if (vis[i] == (float)open / 16.0f) continue;
    tl->disagree++;
    int unsure = 0; /* the brute force in double, only where they differ */
    for (int k = 0; k < 16 && !unsure; k++) unsure = ambiguous(&m, &r16[k]);
    if (!unsure) fail_msg("point %zu: visibility %g, fr_occluded1 %d of 16", i, vis[i], open);
    tl->excused++;
  }
  assert_true(partial > 0); /* penumbrae */
  /* 32 samples: the mean of two passes of 16, the second scrambled anew */
  assert_int_equal(fr_visibility_area_light(s, qc, qe1, qe2, pts, np, 32, 7, eps, vis2), FR_OK);
  float *vis8 = malloc((np + 1) * sizeof *vis8);
  assert_int_equal(fr_visibility_area_light(s, qc, qe1, qe2, pts, np, 16, 8, eps, vis8), FR_OK);
  for (size_t i = 0; i < np; i++) assert_true(vis2[i] == (vis[i] + vis8[i]) / 2.0f);
  free(vis); free(vis2); free(vis8);
  free(pts); free(occ); free(rays); free(hits);
}

static void scenes_at_every_isa(void **state) {
  (void)state;
  fr_scene *b;
  assert_int_equal(fr_scene_builtin(&b), FR_OK);
  assert_int_equal(fr_scene_commit(b), FR_OK);
  fr_pinhole pb = {{0.0f, 3.0f, 9.0f}, {0.0f, 0.5f, 0.0f}, {0.0f, 1.0f, 0.0f}, 50.0f, 150, 98};
  char path[512];
  shared_scene_path(path, sizeof path, "kitchen/kitchen.ply.zst");
  fr_scene *k = NULL;
  if (fr_scene_load(path, &k) == FR_OK) assert_int_equal(fr_scene_commit(k), FR_OK);
  else k = NULL;
  fr_pinhole pk = {{3.75f, 2.30f, 3.60f}, {3.4365f, 1.8802f, 2.7482f}, {-0.127f, 0.907f, -0.4005f}, 40.0f, 130, 77};
  const fr_isa isas[] = {FR_ISA_SCALAR, FR_ISA_AVX2, FR_ISA_AVX512};
  fr_isa was = fr_get_isa();
  for (int i = 0; i < 3; i++) {
    if (!fr_isa_supported(isas[i])) continue;
    assert_int_equal(fr_set_isa(isas[i]), FR_OK);
    tally tl = {0};
    camera_against_rays(b, &pb, &tl);
    if (k) camera_against_rays(k, &pk, &tl);
    printf("%s: %ld rays (%ld hits), %ld disagree, all within rounding of an edge or range end\n",
           fr_isa_name(isas[i]), tl.rays, tl.hits, tl.disagree);
    assert_true(tl.hits > 10000);
    assert_true(tl.disagree <= tl.rays / 1000);
  }
  fr_set_isa(was);
  if (k) fr_scene_release(k);
  fr_scene_release(b);
}

static void errors(void **state) {
  (void)state;
  float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  uint32_t ix[3] = {0, 1, 2};
  fr_scene *s;
  assert_int_equal(fr_scene_from_arrays(p, 3, ix, 1, &s), FR_OK);
  fr_pinhole cam = {{0.2f, 0.2f, 2.0f}, {0.2f, 0.2f, 0.0f}, {0.0f, 1.0f, 0.0f}, 30.0f, 8, 8};
  fr_hit h[64];
  float light[3] = {0.2f, 0.2f, 5.0f}, pts[6] = {0.2f, 0.2f, -1.0f, 0.2f, 0.2f, 1.0f};
  uint8_t occ[2];
  float tt[64];
  const fr_hit_arrays ta = {tt, NULL, NULL, NULL, NULL, NULL};
  assert_int_equal(fr_intersect_camera(s, &cam, 0, 8, 0, NULL, h), FR_ERR_STATE);
  assert_int_equal(fr_intersect_camera_arrays(s, &cam, 0, 8, &ta), FR_ERR_STATE);
  assert_int_equal(fr_occluded_point_light(s, light, pts, 2, 0.0f, occ), FR_ERR_STATE);
  {
    float v1, c[3] = {0, 0, 5}, e[3] = {1, 0, 0}, f[3] = {0, 1, 0};
    assert_int_equal(fr_visibility_area_light(s, c, e, f, pts, 1, 16, 1, 0.0f, &v1), FR_ERR_STATE);
  }
  assert_int_equal(fr_scene_commit(s), FR_OK);
  assert_int_equal(fr_intersect_camera(s, &cam, 0, 8, 0, NULL, h), FR_OK);
  assert_true(h[27].prim == 0 && fabsf(h[27].t - 2.0f) < 0.01f); /* the middle sees the triangle */
  assert_int_equal(fr_intersect_camera(NULL, &cam, 0, 8, 0, NULL, h), FR_ERR_ARG);
  assert_int_equal(fr_intersect_camera_arrays(s, &cam, 0, 8, NULL), FR_ERR_ARG);
  assert_int_equal(fr_intersect_camera_arrays(s, &cam, 4, 5, &ta), FR_ERR_ARG);
  assert_int_equal(fr_intersect_camera_arrays(s, &cam, 0, 8, &ta), FR_OK);
  assert_true(tt[27] == h[27].t);
  assert_int_equal(fr_intersect_camera(s, &cam, 4, 5, 0, NULL, h), FR_ERR_ARG);
  assert_int_equal(fr_intersect_camera(s, &cam, -1, 2, 0, NULL, h), FR_ERR_ARG);
  cam.fov_deg = 180.0f;
  assert_int_equal(fr_intersect_camera(s, &cam, 0, 8, 0, NULL, h), FR_ERR_ARG);
  assert_int_equal(fr_occluded_point_light(s, light, pts, 2, 0.0f, occ), FR_OK);
  assert_true(occ[0] == 1 && occ[1] == 0); /* behind the triangle, in front of it */
  /* points at the light or not finite, among ordinary ones in one batch:
     not occluded, and the others still answered */
  {
    float many[3 * 40];
    uint8_t o40[40];
    for (int i = 0; i < 40; i++) {
      many[3 * i] = 0.1f + 0.005f * (float)i, many[3 * i + 1] = 0.2f, many[3 * i + 2] = -1.0f;
    }
    memcpy(many + 3 * 7, light, sizeof light);
    many[3 * 11 + 1] = NAN;
    many[3 * 13] = INFINITY;
    assert_int_equal(fr_occluded_point_light(s, light, many, 40, 0.0f, o40), FR_OK);
    for (int i = 0; i < 40; i++) assert_int_equal(o40[i], i == 7 || i == 11 || i == 13 ? 0 : 1);
  }
  assert_int_equal(fr_occluded_point_light(s, light, pts, 2, -1.0f, occ), FR_ERR_ARG);
  {
    const float c[3] = {-1.0f, -1.0f, 5.0f}, e1[3] = {3.0f, 0.0f, 0.0f}, e2[3] = {0.0f, 3.0f, 0.0f};
    float v[2], bad[6] = {0.2f, 0.2f, -10.0f, NAN, 0.0f, 0.0f};
    assert_int_equal(fr_visibility_area_light(s, c, e1, e2, bad, 2, 16, 1, 0.0f, v), FR_OK);
    assert_true(v[0] < 1.0f && v[0] > 0.0f && v[1] == 0.0f); /* half hidden by the triangle; not finite */
    assert_int_equal(fr_visibility_area_light(s, c, e1, e2, bad, 2, 20, 1, 0.0f, v), FR_ERR_ARG);
    assert_int_equal(fr_visibility_area_light(s, c, e1, e2, bad, 2, 16, 1, -1.0f, v), FR_ERR_ARG);
    assert_int_equal(fr_visibility_area_light(NULL, c, e1, e2, bad, 2, 16, 1, 0.0f, v), FR_ERR_ARG);
  }
  light[0] = NAN;
  assert_int_equal(fr_occluded_point_light(s, light, pts, 2, 0.0f, occ), FR_ERR_ARG);
  fr_scene_release(s);
  /* spheres: the camera call refuses them; point-light shadows see them */
  assert_int_equal(fr_scene_new(&s), FR_OK);
  float c[3] = {0.0f, 0.0f, 0.0f};
  assert_int_equal(fr_scene_add_sphere(s, c, 1.0f, FR_INVALID_ID), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  cam.fov_deg = 30.0f;
  assert_int_equal(fr_intersect_camera(s, &cam, 0, 8, 0, NULL, h), FR_ERR_UNSUPPORTED);
  assert_int_equal(fr_intersect_camera_arrays(s, &cam, 0, 8, &ta), FR_ERR_UNSUPPORTED);
  float l2[3] = {0.0f, 0.0f, 5.0f}, behind[3] = {0.0f, 0.0f, -5.0f};
  assert_int_equal(fr_occluded_point_light(s, l2, behind, 1, 0.0f, occ), FR_OK);
  assert_int_equal(occ[0], 1);
  fr_scene_release(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(scenes_at_every_isa),
      cmocka_unit_test(errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
