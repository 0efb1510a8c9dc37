/*
 * Large packets against the single-ray kernels, ray by ray: camera packets
 * of 2x2 to 32x32 rays, shadow packets to a point light, reflection packets
 * off the camera hits, and incoherent packets (random origins, directions,
 * rays along edges and from surfaces), on random scenes and the built-in
 * scene. Every traversal (masked, ranged, partition), every cull (off, ia,
 * planes, corners) and every ISA must give the same bits; against
 * fr_intersect1 / fr_occluded1 a disagreement must be a ray within rounding
 * of an edge or of tnear/tfar (both tests are watertight but round
 * differently).
 */
#include <string.h>
#include "api/scene.h"
#include "random_scene.h"
#include "base/alloc.h"
#include "render/camera.h"
#include "test_util.h"
#include "trace/lpacket/lpacket.h"

static const fr_lp_fns *isa_fns[] = {&fr_lp_scalar, &fr_lp_avx2, &fr_lp_avx512};
static const fr_isa isas[] = {FR_ISA_SCALAR, FR_ISA_AVX2, FR_ISA_AVX512};

typedef struct tally { long rays, packets, disagree, self; } tally;

static fr_lpacket *lp;

static fr_lp_scene geom(const fr_scene *s) {
  fr_lp_scene g = {&s->bvh2, &s->sphere_bvh, fr_scene_sphere_base(s)};
  return g;
}

/* A ray that starts on a surface (tnear > 0) and meets a surface within a
 * few tnear of its start in one test and not in the other: a grazing ray
 * leaving its own triangle, where t is the rounding error of the plane
 * distance over a tiny d . n (the packet and single tests round it
 * differently). */
static long self_hits;
static int self_hit(const fr_scene *s, const fr_ray *r) {
  if (!(r->tnear > 0.0f)) return 0;
  self_hits++;
  fr_hit h;
  fr_lp_opts o = {FR_LP_MASKED, FR_CULL_OFF};
  fr_lpacket_load(lp, r, 1);
  fr_lp_scene g = geom(s);
  fr_lp_scalar.intersect(&g, &o, lp);
  fr_lpacket_hits(lp, &g, &h);
  fr_hit h1;
  fr_intersect1(s, r, &h1);
  return fminf(h.t, h1.t) < 10.0f * r->tnear;
}

static const char *config = ""; /* traversal/cull of the packet being checked, for messages */

static void check_against_single(const fr_scene *s, const fr_ray *rays, int n, const fr_hit *hits, const uint8_t *occ,
                                 tally *tl) {
  mesh_ref m = scene_mesh(s);
  tally dummy;
  if (!tl) tl = &dummy;
  for (int i = 0; i < n; i++) {
    tl->rays++;
    if (occ) {
      int single = fr_occluded1(s, &rays[i]);
      if (single == occ[i]) continue;
      tl->disagree++;
      if (!ambiguous(&m, &rays[i]) && !self_hit(s, &rays[i])) {
        uint32_t bp;
        double margin, bt = brute_force(m.pos, m.idx, m.nt, &rays[i], &bp, &margin, 1);
        fail_msg("%s ray %d: packet occluded %d, single %d (org %g %g %g dir %g %g %g range %g %g; double t %g prim %u)",
                 config, i, occ[i], single, rays[i].org[0], rays[i].org[1], rays[i].org[2], rays[i].dir[0], rays[i].dir[1],
                 rays[i].dir[2], rays[i].tnear, rays[i].tfar, bt, bp);
      }
      continue;
    }
    fr_hit h;
    fr_intersect1(s, &rays[i], &h);
    if (h.prim == hits[i].prim) {
      /* a ray (nearly) in the triangle's plane may meet it anywhere */
      if (h.prim != FR_INVALID_ID && fabsf(h.t - hits[i].t) > 1e-4f * fmaxf(1.0f, h.t) && !ambiguous(&m, &rays[i]) &&
          !self_hit(s, &rays[i]))
        fail_msg("ray %d: same triangle %u, t %g vs single %g (org %g %g %g dir %g %g %g range %g %g)", i, h.prim, hits[i].t, h.t, rays[i].org[0], rays[i].org[1], rays[i].org[2], rays[i].dir[0], rays[i].dir[1], rays[i].dir[2], rays[i].tnear, rays[i].tfar);
      continue;
    }
    if (h.prim != FR_INVALID_ID && hits[i].prim != FR_INVALID_ID && fabsf(h.t - hits[i].t) <= 1e-4f * fmaxf(1.0f, h.t))
      continue; /* the same distance on two triangles: either answer */
    tl->disagree++;
    if (!ambiguous(&m, &rays[i]) && !self_hit(s, &rays[i]))
      fail_msg("%s ray %d of %d: packet prim %u t %g, single prim %u t %g (org %a %a %a dir %a %a %a range %a %a)", config, i,
               n, hits[i].prim, hits[i].t, h.prim, h.t, rays[i].org[0], rays[i].org[1], rays[i].org[2], rays[i].dir[0],
               rays[i].dir[1], rays[i].dir[2], rays[i].tnear, rays[i].tfar);
  }
}

/* The packet through every traversal, cull and ISA: the ISAs give the same
 * bits, and every configuration agrees with the single-ray kernel. (Across
 * traversals the bits may differ on rays the single-ray test calls
 * ambiguous: a ray lying in a box face may pass one traversal's box test
 * and fail another's.) */
static void check_packet(const fr_scene *s, const fr_ray *rays, int n, int occluded, tally *tl) {
  static fr_hit ref[FR_LP_MAX], hits[FR_LP_MAX];
  static uint8_t ref_occ[FR_LP_MAX];
  tl->packets++;
  for (int t = 0; t < FR_LP_TRAVERSAL_COUNT; t++)
    for (int c = 0; c < FR_CULL_COUNT; c++) {
      int first = 1;
      for (int i = 0; i < 3; i++) {
        if (!fr_isa_supported(isas[i])) continue;
        fr_lp_opts o = {(fr_lp_traversal)t, (fr_cull)c};
        fr_lp_scene g = geom(s);
        fr_lpacket_load(lp, rays, n);
        if (occluded) {
          isa_fns[i]->occluded(&g, &o, lp);
          for (int k = 0; k < n; k++) {
            int bit = (lp->occ[k / 16] >> (k % 16)) & 1;
            if (first) ref_occ[k] = (uint8_t)bit;
            else if (bit != ref_occ[k])
              fail_msg("%s/%s/%s ray %d of %d: occluded %d, scalar %d", fr_lp_traversal_name(o.traversal),
                       fr_cull_name(o.cull), fr_isa_name(isas[i]), k, n, bit, ref_occ[k]);
          }
        } else {
          isa_fns[i]->intersect(&g, &o, lp);
          fr_lpacket_hits(lp, &g, first ? ref : hits);
          if (!first)
            for (int k = 0; k < n; k++)
              if (hits[k].prim != ref[k].prim || memcmp(&hits[k].t, &ref[k].t, sizeof(float)))
                fail_msg("%s/%s/%s ray %d of %d: prim %u t %a, scalar prim %u t %a", fr_lp_traversal_name(o.traversal),
                         fr_cull_name(o.cull), fr_isa_name(isas[i]), k, n, hits[k].prim, hits[k].t, ref[k].prim, ref[k].t);
        }
        first = 0;
      }
      char name[64];
      snprintf(name, sizeof name, "%s/%s", fr_lp_traversal_name((fr_lp_traversal)t), fr_cull_name((fr_cull)c));
      config = name;
      check_against_single(s, rays, n, occluded ? NULL : ref, occluded ? ref_occ : NULL, t == 0 && c == 0 ? tl : NULL);
    }
}

/* Camera packets of side x side pixels, then shadow and reflection packets
 * made from their hits. */
static void coherent_packets(const fr_scene *s, const fr_camera *cam, vec3 light, float eps, fr_rng *g, tally *tl) {
  static fr_ray rays[FR_LP_MAX], sec[FR_LP_MAX];
  static fr_hit hits[FR_LP_MAX];
  for (int side = 2; side <= 32; side *= 2) {
    int x0 = (int)(fr_rng_u32(g) % (uint32_t)(cam->width - side + 1)), y0 = (int)(fr_rng_u32(g) % (uint32_t)(cam->height - side + 1));
    int n = 0;
    for (int y = 0; y < side; y++)
      for (int x = 0; x < side; x++) rays[n++] = fr_camera_ray(cam, x0 + x, y0 + y);
    check_packet(s, rays, n, 0, tl);
    for (int i = 0; i < n; i++) fr_intersect1(s, &rays[i], &hits[i]);
    /* shadows to the light and mirror reflections from the hits */
    for (int kind = 0; kind < 2; kind++) {
      int m = 0;
      for (int i = 0; i < n; i++) {
        if (hits[i].prim == FR_INVALID_ID) continue;
        vec3 d = v3_load(rays[i].dir), p = v3_add(v3_load(rays[i].org), v3_scale(d, hits[i].t));
        vec3 nn = v3_norm(v3_load(hits[i].ng));
        if (v3_dot(nn, d) > 0.0f) nn = v3_scale(nn, -1.0f);
        fr_ray r = {{p.x, p.y, p.z}, eps, {0, 0, 0}, INFINITY};
        vec3 nd;
        if (kind == 0) {
          vec3 to = v3_sub(light, p);
          float dist = v3_len(to);
          nd = v3_scale(to, 1.0f / dist);
          r.tfar = dist * (1.0f - 1e-4f);
        } else {
          nd = v3_sub(d, v3_scale(nn, 2.0f * v3_dot(d, nn)));
        }
        r.dir[0] = nd.x; r.dir[1] = nd.y; r.dir[2] = nd.z;
        sec[m++] = r;
      }
      if (m) check_packet(s, sec, m, kind == 0, tl);
    }
  }
}

static void test_random_scenes(void **state) {
  (void)state;
  lp = fr_alloc_aligned(sizeof *lp, 64);
  fr_rng g = fr_rng_seed(11, 0);
  tally tl = {0, 0, 0, 0};
  for (int sc = 0; sc < FR_TEST_ROUNDS(12); sc++) {
    vec3 center = sc % 3 == 2 ? v3(1000, -2000, 500) : v3(0, 0, 0);
    float size = sc % 4 == 3 ? 0.01f : 1.0f;
    scene_data sd = make_scene(&g, 200 + 400 * (size_t)sc, center, size);
    fr_scene *s = commit_scene(&sd);
    static fr_ray rays[FR_LP_MAX];
    for (int k = 0; k < 6; k++) {
      int n = 1 + (int)(fr_rng_u32(&g) % FR_LP_MAX);
      for (int i = 0; i < n; i++) {
        uint32_t src;
        rays[i] = random_ray(&g, center, size, &sd, (int)(fr_rng_u32(&g) % 4), &src);
      }
      /* and a few rays no test may answer: NaN, zero direction, empty range */
      rays[0].dir[1] = NAN;
      if (n > 2) { rays[1].dir[0] = rays[1].dir[1] = rays[1].dir[2] = 0.0f; rays[2].tnear = 2.0f; rays[2].tfar = 1.0f; }
      check_packet(s, rays, n, k & 1, &tl);
    }
    fr_camera cam;
    vec3 eye = v3_add(center, v3(2.5f * size, 1.5f * size, 3.0f * size));
    fr_camera_setup(&cam, eye, center, v3(0, 1, 0), 50.0f, 64, 64);
    coherent_packets(s, &cam, v3_add(center, v3(-size, 3 * size, size)), 1e-4f * size, &g, &tl);
    fr_scene_release(s);
    free_scene(&sd);
  }
  print_message("random scenes: %ld packets, %ld rays, %ld disagreements with single rays (all at edges or range ends, "
                "%ld self-hit checks)\n", tl.packets, tl.rays, tl.disagree, self_hits);
  fr_free_aligned(lp);
}

static void test_builtin(void **state) {
  (void)state;
  lp = fr_alloc_aligned(sizeof *lp, 64);
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  fr_rng g = fr_rng_seed(5, 0);
  tally tl = {0, 0, 0, 0};
  fr_camera cam;
  fr_camera_setup(&cam, v3(0, 3, 9), v3(0, 0.5f, 0), v3(0, 1, 0), 50.0f, 256, 256);
  for (int k = 0; k < 4; k++) coherent_packets(s, &cam, v3(3, 8, 4), 1e-3f, &g, &tl);
  print_message("built-in scene: %ld packets, %ld rays, %ld disagreements with single rays\n", tl.packets, tl.rays,
                tl.disagree);
  fr_scene_release(s);
  fr_free_aligned(lp);
}

/* Spheres: the sphereflake, and random spheres among random triangles (some
 * rays start inside a sphere, some on one). Sphere tests are the same float
 * operations in both paths, so a sphere hit must agree exactly. */
static void test_spheres(void **state) {
  (void)state;
  lp = fr_alloc_aligned(sizeof *lp, 64);
  fr_rng g = fr_rng_seed(17, 0);
  tally tl = {0, 0, 0, 0};
  fr_scene *s;
  assert_int_equal(fr_scene_builtin_sphereflake(3, &s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  fr_camera cam;
  fr_camera_setup(&cam, v3(2.1f, 1.3f, 1.7f), v3(0, 0, 0), v3(0, 0, 1), 45.0f, 128, 128);
  for (int k = 0; k < 4; k++) coherent_packets(s, &cam, v3(4, 3, 2), 1e-4f, &g, &tl);
  fr_scene_release(s);
  for (int sc = 0; sc < 4; sc++) {
    vec3 center = sc == 3 ? v3(1000, -2000, 500) : v3(0, 0, 0);
    scene_data sd = make_scene(&g, 300, center, 1.0f);
    s = commit_scene_with(&sd, 0);
    for (int i = 0; i < 200; i++) {
      float c[3] = {center.x + 2.0f * fr_rng_float(&g) - 1.0f, center.y + 2.0f * fr_rng_float(&g) - 1.0f,
                    center.z + 2.0f * fr_rng_float(&g) - 1.0f};
      assert_int_equal(fr_scene_add_sphere(s, c, 0.01f + 0.2f * fr_rng_float(&g), FR_INVALID_ID), FR_OK);
    }
    assert_int_equal(fr_scene_commit(s), FR_OK);
    static fr_ray rays[FR_LP_MAX];
    for (int k = 0; k < 6; k++) {
      int n = 1 + (int)(fr_rng_u32(&g) % FR_LP_MAX);
      for (int i = 0; i < n; i++) {
        uint32_t src;
        rays[i] = random_ray(&g, center, 1.0f, &sd, (int)(fr_rng_u32(&g) % 4), &src);
      }
      check_packet(s, rays, n, k & 1, &tl);
    }
    fr_camera_setup(&cam, v3_add(center, v3(2.5f, 1.5f, 3.0f)), center, v3(0, 1, 0), 50.0f, 64, 64);
    coherent_packets(s, &cam, v3_add(center, v3(-1, 3, 1)), 1e-4f, &g, &tl);
    fr_scene_release(s);
    free_scene(&sd);
  }
  print_message("spheres among triangles: %ld packets, %ld rays, %ld disagreements with single rays (at triangle edges)\n",
                tl.packets, tl.rays, tl.disagree);
  /* spheres alone (the triangle trees are empty): no edges, so no
   * disagreement at all, for rays from anywhere, from inside spheres and
   * from their surfaces */
  tally ts = {0, 0, 0, 0};
  assert_int_equal(fr_scene_new(&s), FR_OK);
  fr_sphere sp[300];
  for (int i = 0; i < 300; i++) {
    sp[i] = (fr_sphere){{2.0f * fr_rng_float(&g) - 1.0f, 2.0f * fr_rng_float(&g) - 1.0f, 2.0f * fr_rng_float(&g) - 1.0f},
                        0.001f + 0.2f * fr_rng_float(&g)};
    assert_int_equal(fr_scene_add_sphere(s, sp[i].c, sp[i].r, FR_INVALID_ID), FR_OK);
  }
  assert_int_equal(fr_scene_commit(s), FR_OK);
  assert_int_equal(fr_scene_triangle_count(s), 0);
  static fr_ray rays[FR_LP_MAX];
  for (int k = 0; k < 12; k++) {
    int n = 1 + (int)(fr_rng_u32(&g) % FR_LP_MAX);
    for (int i = 0; i < n; i++) {
      vec3 d = v3(2.0f * fr_rng_float(&g) - 1.0f, 2.0f * fr_rng_float(&g) - 1.0f, 2.0f * fr_rng_float(&g) - 1.0f);
      vec3 o = v3(3.0f * fr_rng_float(&g) - 1.5f, 3.0f * fr_rng_float(&g) - 1.5f, 3.0f * fr_rng_float(&g) - 1.5f);
      const fr_sphere *q = &sp[fr_rng_u32(&g) % 300];
      int kind = (int)(fr_rng_u32(&g) % 3);
      if (kind == 1) o = v3(q->c[0], q->c[1], q->c[2]); /* from inside */
      if (kind == 2) o = v3_add(v3(q->c[0], q->c[1], q->c[2]), v3_scale(v3_norm(d), q->r)); /* from the surface */
      rays[i] = (fr_ray){{o.x, o.y, o.z}, kind == 2 ? 1e-4f : 0.0f, {d.x, d.y, d.z}, k % 3 ? INFINITY : 0.7f};
    }
    check_packet(s, rays, n, k & 1, &ts);
  }
  fr_camera_setup(&cam, v3(2.5f, 1.5f, 3.0f), v3(0, 0, 0), v3(0, 1, 0), 50.0f, 64, 64);
  coherent_packets(s, &cam, v3(-1, 3, 1), 1e-4f, &g, &ts);
  assert_int_equal(ts.disagree, 0);
  fr_scene_release(s);
  print_message("spheres alone: %ld packets, %ld rays, %ld disagreements\n", ts.packets, ts.rays, ts.disagree);
  fr_free_aligned(lp);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_random_scenes),
      cmocka_unit_test(test_builtin),
      cmocka_unit_test(test_spheres),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
