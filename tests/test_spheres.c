/*
 * Analytic spheres: the float ray test against a double-precision one
 * (rays far away, grazing, from inside, from the surface, tiny and huge
 * spheres), the sphere tree against brute force, the packet and stream
 * calls against fr_intersect1 in every mode and ISA, and the API's checks.
 */
#include <string.h>
#include "api/scene.h"
#include "geom/sphere.h"
#include "test_util.h"

/* Distance of the line o + t d from c, and the nearest root in (tnear, tfar), in double. */
static int sphere_hit_double(const fr_sphere *s, const fr_ray *r, double *t, double *dist) {
  double f[3], d[3], a = 0, b = 0, ff = 0;
  for (int k = 0; k < 3; k++) {
    f[k] = (double)r->org[k] - s->c[k];
    d[k] = r->dir[k];
    a += d[k] * d[k];
    b += f[k] * d[k];
    ff += f[k] * f[k];
  }
  double tc = -b / a, l2 = 0;
  for (int k = 0; k < 3; k++) l2 += (f[k] + tc * d[k]) * (f[k] + tc * d[k]);
  *dist = sqrt(l2);
  double h = (double)s->r * s->r - l2;
  if (h < 0) return 0;
  double sq = sqrt(h / a), t0 = tc - sq, t1 = tc + sq;
  double th = t0 > r->tnear ? t0 : t1;
  if (!(th > r->tnear && th < r->tfar)) return 0;
  *t = th;
  (void)ff;
  return 1;
}

static fr_ray random_sphere_ray(fr_rng *g, const fr_sphere *s, int kind) {
  vec3 c = v3(s->c[0], s->c[1], s->c[2]);
  vec3 d = v3_norm(v3(urand(g, -1, 1), urand(g, -1, 1), urand(g, -1, 1)));
  vec3 n = v3_norm(v3(urand(g, -1, 1), urand(g, -1, 1), urand(g, -1, 1)));
  float len = urand(g, 0.1f, 3.0f);
  fr_ray r = {{0, 0, 0}, 0.0f, {d.x * len, d.y * len, d.z * len}, INFINITY};
  vec3 o;
  switch (kind) {
  case 0: /* from far away, towards a point near the sphere (some graze it) */
    o = v3_sub(v3_add(c, v3_scale(n, s->r * urand(g, 0.0f, 1.2f))), v3_scale(d, s->r * urand(g, 2.0f, 1e4f)));
    break;
  case 1: o = v3_add(c, v3_scale(n, s->r * urand(g, 0.0f, 0.99f))); break; /* inside */
  case 2: /* on the surface, leaving or entering, tnear just past it */
    o = v3_add(c, v3_scale(n, s->r));
    r.tnear = 1e-4f * s->r / len;
    break;
  default: /* tangent: the ray passes at exactly r in exact arithmetic */
  {
    vec3 p = v3_cross(d, n);
    o = v3_sub(v3_add(c, v3_scale(v3_norm(p), s->r)), v3_scale(d, 3.0f * s->r));
    break;
  }
  }
  r.org[0] = o.x; r.org[1] = o.y; r.org[2] = o.z;
  if (fr_rng_u32(g) % 4 == 0) r.tfar = urand(g, 0.0f, 4.0f * s->r / len);
  return r;
}

static void test_ray_sphere_precision(void **state) {
  (void)state;
  fr_rng g = fr_rng_seed(3, 1);
  long hits = 0, graze = 0, n = 0;
  for (int i = 0; i < 400000; i++) {
    float scale = powf(10.0f, urand(&g, -4.0f, 4.0f));
    vec3 off = fr_rng_u32(&g) % 3 ? v3(0, 0, 0) : v3(urand(&g, -1e4f, 1e4f), urand(&g, -1e4f, 1e4f), 0);
    fr_sphere s = {{off.x + urand(&g, -1, 1) * scale, off.y + urand(&g, -1, 1) * scale, off.z}, scale * urand(&g, 0.1f, 1.0f)};
    fr_ray r = random_sphere_ray(&g, &s, i % 4);
    double td, dist;
    int hd = sphere_hit_double(&s, &r, &td, &dist);
    float tf = 0.0f;
    int hf = fr_sphere_hit(&s, r.org, r.dir, r.tnear, r.tfar, &tf);
    n++;
    /* within rounding of the silhouette, or of tnear / tfar, either answer is right */
    double f = 0, len = v3_len(v3_load(r.dir));
    for (int k = 0; k < 3; k++) f += ((double)r.org[k] - s.c[k]) * ((double)r.org[k] - s.c[k]);
    double scale_t = (sqrt(f) + s.r) / len, tol = 1e-5 * scale_t;
    int near_edge = fabs(dist - s.r) <= 1e-5 * (sqrt(f) + s.r);
    if (hd != hf) {
      int near_range = hd ? (fabs(td - r.tnear) <= tol || fabs(td - r.tfar) <= tol)
                          : (fabs((double)tf - r.tnear) <= tol || fabs((double)tf - r.tfar) <= tol);
      /* a surface ray's own start root is within tol of 0 */
      int near_start = !hd && fabs((double)tf) <= tol;
      if (!near_edge && !near_range && !near_start)
        fail_msg("ray %d kind %d: float %s (t %g), double %s (t %g), distance %g r %g", i, i % 4, hf ? "hit" : "miss",
                 (double)tf, hd ? "hit" : "miss", td, dist, (double)s.r);
      graze++;
      continue;
    }
    if (!hd) continue;
    hits++;
    /* a ray leaving a surface: its own root is at t ~ 0 within rounding
     * that grows as it leaves at a grazing angle; tnear decides, and either
     * side of it is right when the root is that close */
    if (i % 4 == 2 && (fabs(td) <= 1e-3 * scale_t || fabs((double)tf) <= 1e-3 * scale_t) && fabs((double)tf - td) > tol) {
      graze++;
      continue;
    }
    /* near the silhouette both roots meet and t loses half its digits */
    double tol_t = near_edge ? 1e-2 * scale_t : tol;
    if (fabs((double)tf - td) > tol_t)
      fail_msg("ray %d kind %d: t %.9g, double %.9g (scale %g)", i, i % 4, (double)tf, td, scale_t);
  }
  print_message("%ld rays, %ld hits agree with double precision, %ld at the silhouette or range ends\n", n, hits, graze);
  assert_true(hits > n / 4);
}

/* A scene of spheres (and, if tris, random triangles among them). */
static fr_scene *sphere_scene(fr_rng *g, int nspheres, vec3 centre, float size, int with_tris) {
  fr_scene *s;
  if (with_tris) {
    float xyz[3 * 300];
    uint32_t idx[300];
    for (int i = 0; i < 300; i++) {
      xyz[3 * i] = centre.x + size * urand(g, -1, 1);
      xyz[3 * i + 1] = centre.y + size * urand(g, -1, 1);
      xyz[3 * i + 2] = centre.z + size * urand(g, -1, 1);
      idx[i] = (uint32_t)i;
    }
    assert_int_equal(fr_scene_from_arrays(xyz, 300, idx, 100, &s), FR_OK);
  } else {
    assert_int_equal(fr_scene_new(&s), FR_OK);
  }
  for (int i = 0; i < nspheres; i++) {
    float c[3] = {centre.x + size * urand(g, -1, 1), centre.y + size * urand(g, -1, 1), centre.z + size * urand(g, -1, 1)};
    assert_int_equal(fr_scene_add_sphere(s, c, size * urand(g, 0.002f, 0.2f), FR_INVALID_ID), FR_OK);
  }
  assert_int_equal(fr_scene_commit(s), FR_OK);
  return s;
}

static fr_ray scene_ray(fr_rng *g, const fr_scene *s, vec3 centre, float size) {
  if (fr_rng_u32(g) % 2 && fr_scene_sphere_count(s)) {
    fr_sphere sp;
    fr_scene_sphere(s, fr_rng_u32(g) % fr_scene_sphere_count(s), sp.c, &sp.r);
    return random_sphere_ray(g, &sp, (int)(fr_rng_u32(g) % 4));
  }
  vec3 o = v3_add(centre, v3_scale(v3(urand(g, -2, 2), urand(g, -2, 2), urand(g, -2, 2)), size));
  fr_ray r = {{o.x, o.y, o.z}, 0.0f, {urand(g, -1, 1), urand(g, -1, 1), urand(g, -1, 1)}, INFINITY};
  return r;
}

/* fr_intersect1 / fr_occluded1 (sphere tree) against brute force over every
 * sphere (fr_intersect1_reference): a grazing hit the tree's boxes lose must
 * be within rounding of the silhouette. */
static void test_tree_against_brute_force(void **state) {
  (void)state;
  fr_rng g = fr_rng_seed(9, 2);
  long rays = 0, hits = 0;
  for (int sc = 0; sc < 8; sc++) {
    vec3 centre = sc % 4 == 3 ? v3(3000, -1000, 200) : v3(0, 0, 0);
    float size = sc % 3 == 2 ? 0.01f : 1.0f;
    fr_scene *s = sphere_scene(&g, 50 + 300 * sc, centre, size, sc & 1);
    for (int isa = 0; isa < 3; isa++) {
      if (!fr_isa_supported((fr_isa)isa)) continue;
      fr_set_isa((fr_isa)isa);
      for (int i = 0; i < 3000; i++) {
        fr_ray r = scene_ray(&g, s, centre, size);
        fr_hit h, ref;
        fr_intersect1(s, &r, &h);
        fr_intersect1_reference(s, &r, &ref);
        rays++;
        hits += h.prim != FR_INVALID_ID;
        int occ = fr_occluded1(s, &r), occ_ref = fr_occluded1_reference(s, &r);
        if (h.prim == ref.prim && (h.prim == FR_INVALID_ID || h.t == ref.t) && occ == occ_ref) continue;
        /* spheres are tested by the same function in both: only a box of the
         * tree may drop a grazing hit, or a triangle edge decide */
        fr_hit *missing = h.prim == FR_INVALID_ID || (ref.prim != FR_INVALID_ID && ref.t < h.t) ? &ref : &h;
        uint32_t base = (uint32_t)fr_scene_triangle_count(s);
        if (missing->prim != FR_INVALID_ID && missing->prim < base) continue; /* a triangle: tested elsewhere */
        if (missing->prim != FR_INVALID_ID && fabsf(h.t - ref.t) <= 1e-5f * fmaxf(1.0f, ref.t)) continue;
        fr_sphere sp;
        double td, dist = 0;
        if (missing->prim != FR_INVALID_ID) {
          fr_scene_sphere(s, missing->prim - base, sp.c, &sp.r);
          sphere_hit_double(&sp, &r, &td, &dist);
          if (fabs(dist - sp.r) <= 1e-4 * sp.r) continue;
        }
        fail_msg("scene %d ray %d: tree prim %u t %g occ %d, brute force prim %u t %g occ %d", sc, i, h.prim, h.t, occ,
                 ref.prim, ref.t, occ_ref);
      }
    }
    fr_set_isa(FR_ISA_AVX512);
    fr_scene_release(s);
  }
  if (!fr_isa_supported(FR_ISA_AVX512)) fr_set_isa(FR_ISA_SCALAR);
  print_message("%ld rays, %ld hits, tree = brute force\n", rays, hits);
  assert_true(hits > rays / 10);
}

/* Packets of 16 and streams in every mode: sphere answers are fr_intersect1's. */
static void test_packets_and_streams(void **state) {
  (void)state;
  fr_rng g = fr_rng_seed(4, 4);
  fr_scene *s = sphere_scene(&g, 500, v3(0, 0, 0), 1.0f, 1);
  enum { N = 4096 };
  static fr_ray rays[N];
  static fr_hit ref[N], h[N];
  static uint8_t occ_ref[N], occ[N];
  for (int i = 0; i < N; i++) rays[i] = scene_ray(&g, s, v3(0, 0, 0), 1.0f);
  /* a few rays no call may trace: NaN, an empty range, no direction */
  rays[5].dir[1] = NAN, rays[21].tnear = 2.0f, rays[21].tfar = 1.0f, rays[37].dir[0] = rays[37].dir[1] = rays[37].dir[2] = 0.0f;
  for (int i = 0; i < N; i++) {
    fr_intersect1(s, &rays[i], &ref[i]);
    occ_ref[i] = (uint8_t)fr_occluded1(s, &rays[i]);
  }
  static const fr_trace_mode modes[] = {FR_TRACE_SINGLE,   FR_TRACE_PACKET8, FR_TRACE_PACKET16,
                                        FR_TRACE_HYBRID16, FR_TRACE_AUTO,    FR_TRACE_RAYSTREAM};
  enum { MODES = sizeof modes / sizeof modes[0] };
  uint32_t base = (uint32_t)fr_scene_triangle_count(s);
  for (int isa = 0; isa < 3; isa++) {
    if (!fr_isa_supported((fr_isa)isa)) continue;
    fr_set_isa((fr_isa)isa);
    for (int m = 0; m < MODES; m++) {
      fr_tuning o;
      fr_tuning_default(&o);
      o.mode = modes[m];
      assert_int_equal(fr_scene_set_tuning(s, &o), FR_OK);
      fr_intersect_stream(s, rays, h, N);
      fr_occluded_stream(s, rays, occ, N);
      for (int i = 0; i < N; i++) {
        /* rays whose answer is a sphere (in either) must agree exactly */
        if (ref[i].prim < base || h[i].prim < base) continue;
        if (h[i].prim != ref[i].prim || (h[i].prim != FR_INVALID_ID && h[i].t != ref[i].t))
          fail_msg("%s mode %d ray %d: prim %u t %g, single prim %u t %g", fr_isa_name((fr_isa)isa), m, i, h[i].prim,
                   h[i].t, ref[i].prim, ref[i].t);
      }
      long occ_bad = 0;
      for (int i = 0; i < N; i++) occ_bad += occ[i] != occ_ref[i];
      assert_true(occ_bad <= 2); /* only triangle-edge rays may differ */
    }
    /* fr_intersect16 with a partial mask: lanes outside it untouched */
    fr_ray16 r16;
    fr_hit16 h16;
    memset(&h16, 0x5A, sizeof h16);
    for (int i = 0; i < 16; i++) {
      const fr_ray *r = &rays[i];
      r16.org_x[i] = r->org[0]; r16.org_y[i] = r->org[1]; r16.org_z[i] = r->org[2]; r16.tnear[i] = r->tnear;
      r16.dir_x[i] = r->dir[0]; r16.dir_y[i] = r->dir[1]; r16.dir_z[i] = r->dir[2]; r16.tfar[i] = r->tfar;
    }
    fr_intersect16(s, 0x7FFF, &r16, &h16);
    unsigned o16 = fr_occluded16(s, 0x7FFF, &r16);
    for (int i = 0; i < 15; i++) {
      if (ref[i].prim >= base) assert_int_equal(h16.prim[i], ref[i].prim);
      if (ref[i].prim >= base && ref[i].prim != FR_INVALID_ID) assert_true(h16.t[i] == ref[i].t);
      if (ref[i].prim >= base) assert_int_equal((o16 >> i) & 1, occ_ref[i]);
    }
    assert_int_equal(h16.prim[15], 0x5A5A5A5Au);
    assert_int_equal(o16 >> 15, 0);
  }
  fr_tuning o;
  fr_tuning_default(&o);
  fr_scene_set_tuning(s, &o);
  fr_set_isa(fr_isa_supported(FR_ISA_AVX512) ? FR_ISA_AVX512 : FR_ISA_SCALAR);
  fr_scene_release(s);
}

static void test_api(void **state) {
  (void)state;
  fr_scene *s;
  assert_int_equal(fr_scene_new(&s), FR_OK);
  float c[3] = {0, 0, 0}, bad[3] = {0, NAN, 0};
  assert_int_equal(fr_scene_add_sphere(s, c, 0.0f, FR_INVALID_ID), FR_ERR_ARG);
  assert_non_null(strstr(fr_last_error(), "radius"));
  assert_int_equal(fr_scene_add_sphere(s, c, -1.0f, FR_INVALID_ID), FR_ERR_ARG);
  assert_int_equal(fr_scene_add_sphere(s, c, INFINITY, FR_INVALID_ID), FR_ERR_ARG);
  assert_int_equal(fr_scene_add_sphere(s, c, NAN, FR_INVALID_ID), FR_ERR_ARG);
  assert_int_equal(fr_scene_add_sphere(s, bad, 1.0f, FR_INVALID_ID), FR_ERR_ARG);
  assert_int_equal(fr_scene_add_sphere(s, c, 1.0f, 0), FR_ERR_ARG); /* no material 0 yet */
  assert_int_equal(fr_scene_add_sphere(NULL, c, 1.0f, FR_INVALID_ID), FR_ERR_ARG);
  /* nothing to build yet */
  assert_int_equal(fr_scene_commit(s), FR_ERR_FORMAT);
  fr_material m;
  memset(&m, 0, sizeof m);
  snprintf(m.name, sizeof m.name, "red");
  m.diffuse[0] = 1.0f;
  uint32_t mi;
  assert_int_equal(fr_scene_add_material(s, &m, &mi), FR_OK);
  assert_int_equal(fr_scene_add_sphere(s, c, 1.0f, mi), FR_OK);
  float c2[3] = {3, 0, 0};
  assert_int_equal(fr_scene_add_sphere(s, c2, 0.5f, FR_INVALID_ID), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  assert_int_equal(fr_scene_add_sphere(s, c, 1.0f, FR_INVALID_ID), FR_ERR_STATE);
  assert_int_equal(fr_scene_add_material(s, &m, &mi), FR_ERR_STATE);
  assert_int_equal(fr_scene_sphere_count(s), 2);
  assert_int_equal(fr_scene_triangle_count(s), 0);
  float lo[3], hi[3];
  fr_scene_bounds(s, lo, hi);
  assert_true(lo[0] <= -1.0f && hi[0] >= 3.5f && lo[1] <= -1.0f && hi[2] >= 1.0f);
  /* a ray along x from the left hits sphere 0 at t = 4, normal (-1, 0, 0) */
  fr_ray r = {{-5, 0, 0}, 0.0f, {1, 0, 0}, INFINITY};
  fr_hit h;
  fr_intersect1(s, &r, &h);
  assert_int_equal(h.prim, 0);
  assert_true(h.t == 4.0f && h.u == 0.0f && h.v == 0.0f);
  assert_true(h.ng[0] == -1.0f && h.ng[1] == 0.0f && h.ng[2] == 0.0f);
  assert_int_equal(fr_scene_prim_material(s, h.prim), mi);
  assert_int_equal(fr_scene_prim_material(s, 1), FR_INVALID_ID);
  assert_int_equal(fr_scene_prim_material(s, 2), FR_INVALID_ID);
  float p[3] = {3.5f, 0, 0}, n[3];
  assert_int_equal(fr_scene_geometric_normal(s, 1, p, n), 1);
  assert_true(n[0] == 0.5f && n[1] == 0.0f);
  assert_int_equal(fr_scene_geometric_normal(s, 7, p, n), 0);
  /* from inside sphere 0: its far side; then sphere 1 beyond it */
  r = (fr_ray){{0, 0, 0}, 0.0f, {1, 0, 0}, INFINITY};
  fr_intersect1(s, &r, &h);
  assert_true(h.prim == 0 && h.t == 1.0f);
  r.tnear = 1.5f;
  fr_intersect1(s, &r, &h);
  assert_true(h.prim == 1 && h.t == 2.5f);
  r.tfar = 2.0f;
  assert_int_equal(fr_occluded1(s, &r), 0);
  r.tfar = 2.6f;
  assert_int_equal(fr_occluded1(s, &r), 1);
  /* NaN rays and zero directions miss */
  r = (fr_ray){{-5, 0, 0}, 0.0f, {NAN, 0, 0}, INFINITY};
  fr_intersect1(s, &r, &h);
  assert_int_equal(h.prim, FR_INVALID_ID);
  r = (fr_ray){{-5, 0, 0}, 0.0f, {0, 0, 0}, INFINITY};
  assert_int_equal(fr_occluded1(s, &r), 0);
  fr_scene_release(s);
  /* the sphereflake */
  assert_int_equal(fr_scene_builtin_sphereflake(6, &s), FR_ERR_ARG);
  assert_int_equal(fr_scene_builtin_sphereflake(3, &s), FR_OK);
  assert_int_equal(fr_scene_sphere_count(s), 820);
  assert_int_equal(fr_scene_triangle_count(s), 2);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  fr_scene_release(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_api),
      cmocka_unit_test(test_ray_sphere_precision),
      cmocka_unit_test(test_tree_against_brute_force),
      cmocka_unit_test(test_packets_and_streams),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
