/*
 * Planar occluders (accel/plane_occluders.h): which patches qualify, and
 * that every ray one claims is occluded by the scene's own triangles (the
 * single-ray kernel and a double-precision brute force), also far from the
 * origin.
 */
#include <math.h>
#include "accel/plane_occluders.h"
#include "api/scene.h"
#include "random_scene.h"
#include "test_util.h"
#include "trace/kernels.h"

/* An n x n grid of quads over [x0, x0 + size] x [z0, z0 + size] at y = c,
 * two triangles each, all wound the same way but for quad `flip`; quad
 * `hole` left out; quads with i, j >= n - cut left out (an L). */
static void add_grid(scene_data *sd, int n, float x0, float z0, float size, float c, int hole, int flip, int cut) {
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      const int q = i * n + j;
      if (q == hole || (i >= n - cut && j >= n - cut)) continue;
      const float s = size / (float)n;
      vec3 a = v3(x0 + s * (float)i, c, z0 + s * (float)j), b = v3(x0 + s * (float)(i + 1), c, z0 + s * (float)j);
      vec3 d = v3(x0 + s * (float)i, c, z0 + s * (float)(j + 1)), e = v3(x0 + s * (float)(i + 1), c, z0 + s * (float)(j + 1));
      if (q == flip) {
        add_tri(sd, a, b, e);
        add_tri(sd, a, e, d);
      } else {
        add_tri(sd, a, e, b);
        add_tri(sd, a, d, e);
      }
    }
}

/* A fan of n triangles around (x0, c, z0): a convex n-gon of radius r. */
static void add_disc(scene_data *sd, int n, float x0, float z0, float r, float c) {
  for (int i = 0; i < n; i++) {
    const double a0 = 2.0 * M_PI * i / n, a1 = 2.0 * M_PI * (i + 1) / n;
    add_tri(sd, v3(x0, c, z0), v3(x0 + r * (float)cos(a1), c, z0 + r * (float)sin(a1)),
            v3(x0 + r * (float)cos(a0), c, z0 + r * (float)sin(a0)));
  }
}

static scene_data new_scene(void) {
  scene_data sd = {malloc(4096 * 9 * sizeof(float)), malloc(4096 * 3 * sizeof(uint32_t)), 0, 0};
  /* something else in the scene, off the plane */
  add_tri(&sd, v3(-3, -1, -3), v3(-2, 2, -3), v3(-3, 1, -2));
  return sd;
}

static size_t occluders_of(const scene_data *sd, fr_plane_occluders *out) {
  fr_scene *s = commit_scene(sd);
  size_t n = s->planes.n;
  out->n = n;
  out->list = NULL;
  if (n) {
    out->list = malloc(n * sizeof *out->list);
    memcpy(out->list, s->planes.list, n * sizeof *out->list);
  }
  fr_scene_release(s);
  return n;
}

/* Patches that cover their convex hull qualify; the others do not. */
static void which_patches_qualify(void **state) {
  (void)state;
  fr_plane_occluders p;
  struct { int hole, flip, cut, dup, n; size_t want; } cases[] = {
      {-1, -1, 0, 0, 8, 1}, /* a full grid */
      {27, -1, 0, 0, 8, 0}, /* a hole */
      {-1, 27, 0, 0, 8, 0}, /* one quad wound the other way */
      {-1, -1, 3, 0, 8, 0}, /* an L: its hull is larger */
      {-1, -1, 0, 1, 8, 0}, /* a triangle twice */
      {-1, -1, 0, 0, 5, 0}, /* 50 triangles: too few */
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    scene_data sd = new_scene();
    add_grid(&sd, cases[k].n, 0.25f, -0.5f, 1.0f, 0.5f, cases[k].hole, cases[k].flip, cases[k].cut);
    if (cases[k].dup) add_tri(&sd, v3(0.25f, 0.5f, -0.5f), v3(0.375f, 0.5f, -0.375f), v3(0.375f, 0.5f, -0.5f));
    size_t n = occluders_of(&sd, &p);
    if (n != cases[k].want) fail_msg("case %zu: %zu occluders, want %zu", k, n, cases[k].want);
    if (n) {
      assert_int_equal(p.list[0].axis, 1);
      assert_true(p.list[0].c == 0.5f);
      assert_int_equal(p.list[0].nedges, 4);
      assert_true(fabs(p.list[0].area - 1.0) < 1e-6);
      assert_int_equal(p.list[0].tris, 128);
    }
    fr_plane_occluders_free(&p);
    free_scene(&sd);
  }
  /* a disc of 96 triangles: 16 of its hull's 96 vertices, inscribed */
  scene_data sd = new_scene();
  add_disc(&sd, 96, 1.0f, 2.0f, 0.5f, -0.25f);
  assert_int_equal(occluders_of(&sd, &p), 1);
  assert_int_equal(p.list[0].nedges, FR_PLANE_OCCLUDER_EDGES);
  const double inscribed16 = 0.5 * 16 * 0.25 * sin(2.0 * M_PI / 16);
  assert_true(fabs(p.list[0].area - inscribed16) < 1e-4);
  fr_plane_occluders_free(&p);
  free_scene(&sd);
}

/* Rays at a patch: every one an occluder claims is occluded in the scene,
 * by the single-ray kernel and by brute force in double; most rays aimed
 * at the middle are claimed (the margins are small). */
static void check_rays(const scene_data *sd, vec3 centre, float size, long *claimed_out, long *rays_out) {
  fr_scene *s = commit_scene(sd);
  assert_int_equal(s->planes.n, 1);
  const fr_plane_occluder *p = &s->planes.list[0];
  fr_rng r = fr_rng_seed(11, 0);
  long claimed = 0, rays = 0;
  fr_ray16 pk;
  uint8_t single[16];
  int np = 0;
  const mesh_ref m = scene_mesh(s);
  fr_tuning topt;
  fr_tuning_default(&topt);
  topt.mode = FR_TRACE_PACKET16;
  assert_int_equal(fr_scene_set_tuning(s, &topt), FR_OK);
  for (int i = 0; i < 20000; i++) {
    /* from below to above the plane, aimed anywhere over twice the patch */
    vec3 o = v3_add(centre, v3((fr_rng_float(&r) - 0.5f) * 4 * size, -size * (0.01f + fr_rng_float(&r)),
                               (fr_rng_float(&r) - 0.5f) * 4 * size));
    vec3 e = v3_add(centre, v3((fr_rng_float(&r) - 0.5f) * 2 * size, size * (0.01f + fr_rng_float(&r)),
                               (fr_rng_float(&r) - 0.5f) * 2 * size));
    if (i & 1) { vec3 t = o; o = e; e = t; }
    fr_ray ray = {{o.x, o.y, o.z}, 0.0f, {e.x - o.x, e.y - o.y, e.z - o.z}, 1.0f};
    /* ranges that end near the plane too */
    if (i % 5 == 0) ray.tnear = fr_rng_float(&r);
    if (i % 7 == 0) ray.tfar = fr_rng_float(&r);
    if (ray.tnear > ray.tfar) continue;
    rays++;
    /* packets of 16 agree with single rays, both testing the occluders
     * first, but where a ray is within rounding of an edge or an end */
    pk.org_x[np] = ray.org[0]; pk.org_y[np] = ray.org[1]; pk.org_z[np] = ray.org[2];
    pk.dir_x[np] = ray.dir[0]; pk.dir_y[np] = ray.dir[1]; pk.dir_z[np] = ray.dir[2];
    pk.tnear[np] = ray.tnear; pk.tfar[np] = ray.tfar;
    single[np] = (uint8_t)fr_occluded1(s, &ray);
    {
      fr_bvhn bare = s->bvh8;
      bare.planes = NULL;
      if (single[np] != fr_trace_w8_scalar.occluded1(&bare, &ray) && !ambiguous(&m, &ray))
        fail_msg("ray %d: single rays with and without occluders disagree", i);
    }
    if (++np == 16) {
      const unsigned got = fr_occluded16(s, 0xFFFFu, &pk);
      for (int k = 0; k < 16; k++) {
        if ((int)((got >> k) & 1) == single[k]) continue;
        fr_ray q = {{pk.org_x[k], pk.org_y[k], pk.org_z[k]}, pk.tnear[k], {pk.dir_x[k], pk.dir_y[k], pk.dir_z[k]}, pk.tfar[k]};
        if (!ambiguous(&m, &q)) fail_msg("ray %d of a packet: packet %u single %u", k, (got >> k) & 1, single[k]);
      }
      np = 0;
    }
    if (!fr_plane_occluder_hit(p, ray.org, ray.dir, ray.tnear, ray.tfar)) continue;
    claimed++;
    /* the kernels test the occluders themselves: ask one without them */
    fr_bvhn bare = s->bvh8;
    bare.planes = NULL;
    if (!fr_trace_w8_scalar.occluded1(&bare, &ray)) {
      uint32_t bp;
      double bm, bt = brute_force(fr_scene_vertices(s), fr_scene_indices(s), fr_scene_triangle_count(s), &ray, &bp, &bm, 1);
      fail_msg("ray %d claimed by the occluder but not occluded (o %g %g %g d %g %g %g t %g..%g; brute force t %g)", i,
               ray.org[0], ray.org[1], ray.org[2], ray.dir[0], ray.dir[1], ray.dir[2], ray.tnear, ray.tfar, bt);
    }
    uint32_t prim;
    double margin;
    if (!isfinite(brute_force(fr_scene_vertices(s), fr_scene_indices(s), fr_scene_triangle_count(s), &ray, &prim, &margin, 1)))
      fail_msg("ray %d claimed by the occluder but brute force finds no hit", i);
  }
  fr_scene_release(s);
  *claimed_out = claimed;
  *rays_out = rays;
}

static void claimed_rays_are_occluded(void **state) {
  (void)state;
  const float offsets[] = {0.0f, 1000.0f, -30000.0f};
  for (int k = 0; k < 3; k++) {
    const float f = offsets[k];
    scene_data sd = new_scene();
    add_grid(&sd, 12, f + 0.25f, f - 0.5f, 1.0f, f + 0.5f, -1, -1, 0);
    long claimed, rays;
    check_rays(&sd, v3(f + 0.75f, f + 0.5f, f), 1.0f, &claimed, &rays);
    print_message("grid at offset %g: %ld of %ld rays claimed\n", f, claimed, rays);
    /* not vacuous; at 30000 the margins (1e-5 of the magnitudes) leave little */
    if (fabsf(f) < 10000.0f) assert_true(claimed * 10 > rays);
    free_scene(&sd);
    sd = new_scene();
    add_disc(&sd, 200, f + 1.0f, f + 2.0f, 0.5f, f - 0.25f);
    check_rays(&sd, v3(f + 1.0f, f - 0.25f, f + 2.0f), 0.5f, &claimed, &rays);
    print_message("disc at offset %g: %ld of %ld rays claimed\n", f, claimed, rays);
    if (fabsf(f) < 10000.0f) assert_true(claimed * 10 > rays);
    free_scene(&sd);
  }
}

/* A grid of 131,072 triangles qualifies (the finder is sorts and linear
 * passes); a disc of 2,000 segments is passed over (its hull has more
 * vertices than the boundary check takes). */
static void large_patches(void **state) {
  (void)state;
  scene_data sd = {malloc(140000 * 9 * sizeof(float)), malloc(140000 * 3 * sizeof(uint32_t)), 0, 0};
  add_grid(&sd, 256, -5.0f, -5.0f, 10.0f, 1.0f, -1, -1, 0);
  fr_plane_occluders p;
  assert_int_equal(occluders_of(&sd, &p), 1);
  assert_int_equal(p.list[0].tris, 2 * 256 * 256);
  fr_plane_occluders_free(&p);
  sd.nv = sd.nt = 0;
  add_disc(&sd, 2000, 0.0f, 0.0f, 1.0f, 0.0f);
  assert_int_equal(occluders_of(&sd, &p), 0);
  free_scene(&sd);
}

/* Ranges that start behind the origin (tnear < 0) find the flat patch
 * behind it, through every entry point and mode: the box tests' widening
 * narrowed negative exit distances, and single rays missed it. */
static void ranges_behind_the_origin(void **state) {
  (void)state;
  scene_data sd = new_scene();
  add_grid(&sd, 8, 0.25f, -0.5f, 1.0f, 0.5f, -1, -1, 0);
  fr_scene *s = commit_scene(&sd);
  const mesh_ref m = scene_mesh(s);
  const fr_trace_mode modes[] = {FR_TRACE_SINGLE, FR_TRACE_PACKET16, FR_TRACE_HYBRID16, FR_TRACE_AUTO, FR_TRACE_RAYSTREAM};
  fr_rng r = fr_rng_seed(5, 0);
  enum { N = 64 };
  fr_ray rays[N];
  double want[N];
  for (int i = 0; i < N; i++) {
    /* above the patch, going up; the patch lies at t in (tnear, 0) */
    const float x = 0.3f + 0.9f * fr_rng_float(&r), z = -0.45f + 0.9f * fr_rng_float(&r);
    fr_ray ray = {{x, 0.5f + 0.5f * fr_rng_float(&r), z}, -3.0f, {0.1f * (fr_rng_float(&r) - 0.5f), 1.0f, 0.1f * (fr_rng_float(&r) - 0.5f)}, 2.0f};
    uint32_t prim;
    double margin;
    want[i] = brute_force(m.pos, m.idx, m.nt, &ray, &prim, &margin, 1);
    assert_true(want[i] < 0.0);
    rays[i] = ray;
  }
  for (size_t k = 0; k < sizeof modes / sizeof modes[0]; k++) {
    fr_tuning o;
    fr_tuning_default(&o);
    o.mode = modes[k];
    assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
    fr_hit hits[N];
    uint8_t occ[N];
    fr_intersect_stream(s, rays, hits, N);
    fr_occluded_stream(s, rays, occ, N);
    for (int i = 0; i < N; i++) {
      if (!occ[i] || fabs(hits[i].t - want[i]) > 1e-4) fail_msg("mode %zu ray %d: occ %d t %g, want %g", k, i, occ[i], hits[i].t, want[i]);
      fr_hit h;
      fr_intersect1(s, &rays[i], &h);
      assert_true(fabs(h.t - want[i]) <= 1e-4 && fr_occluded1(s, &rays[i]));
    }
    fr_ray16 p;
    for (int j = 0; j < 16; j++) {
      p.org_x[j] = rays[j].org[0]; p.org_y[j] = rays[j].org[1]; p.org_z[j] = rays[j].org[2];
      p.dir_x[j] = rays[j].dir[0]; p.dir_y[j] = rays[j].dir[1]; p.dir_z[j] = rays[j].dir[2];
      p.tnear[j] = rays[j].tnear; p.tfar[j] = rays[j].tfar;
    }
    assert_int_equal(fr_occluded16(s, 0xFFFFu, &p), 0xFFFF);
    fr_hit16 h16;
    fr_intersect16(s, 0xFFFFu, &p, &h16);
    for (int j = 0; j < 16; j++) assert_true(fabs(h16.t[j] - want[j]) <= 1e-4);
  }
  fr_scene_release(s);
  free_scene(&sd);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(which_patches_qualify),
      cmocka_unit_test(claimed_rays_are_occluded),
      cmocka_unit_test(large_patches),
      cmocka_unit_test(ranges_behind_the_origin),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
