/*
 * fr_intersect_all: every crossing, once, in order.
 *  - the traversal against the same exact test on every triangle (brute
 *    force): the same list, prim by prim and bit by bit;
 *  - against Möller-Trumbore in double: every triangle clearly crossed is
 *    listed, every listed one is at least nearly crossed at its t;
 *  - through closed surfaces, with rays aimed exactly at shared vertices
 *    and edges: exactly one crossing per passage (odd from inside, 2 from
 *    outside through a star-shaped solid), which no inclusive edge test gives;
 *  - the first crossing is fr_intersect1's hit; max_hits truncates and
 *    counts stay whole; errors.
 */
#include "random_scene.h"
#include "trace/all_hits.h"

static int by_t_prim(const void *pa, const void *pb) {
  const fr_hit *a = pa, *b = pb;
  if (a->t != b->t) return a->t < b->t ? -1 : 1;
  return (a->prim > b->prim) - (a->prim < b->prim);
}

/* The triangles the scene traces (not skipped as degenerate). */
static uint8_t *traced_prims(const fr_scene *s) {
  uint8_t *in = calloc(s->mesh.ntris + 1, 1);
  for (size_t i = 0; i < s->bvh2.nprims; i++) in[s->bvh2.prims[i]] = 1;
  return in;
}

/* Every triangle tested by the exact kernel, in triangle order, then sorted. */
static size_t brute_crossings(const fr_scene *s, const uint8_t *traced, const fr_ray *r, fr_hit *out, size_t cap) {
  size_t n = 0;
  for (uint32_t p = 0; p < s->mesh.ntris; p++) {
    if (!traced[p]) continue;
    const uint32_t *ix = s->mesh.idx + 3 * (size_t)p;
    fr_hit h = {0};
    if (!fr_tri_crossing(r, s->mesh.pos + 3 * (size_t)ix[0], s->mesh.pos + 3 * (size_t)ix[1],
                         s->mesh.pos + 3 * (size_t)ix[2], &h.t, &h.u, &h.v))
      continue;
    h.prim = p;
    if (n < cap) out[n] = h;
    n++;
  }
  if (n > 1) qsort(out, n < cap ? n : cap, sizeof *out, by_t_prim);
  return n;
}

/* Möller-Trumbore in double: t and the least barycentric; 0 where the ray
 * (nearly) lies in the triangle's plane. */
static int moller(const fr_scene *s, uint32_t p, const fr_ray *r, double *t, double *margin) {
  const uint32_t *ix = s->mesh.idx + 3 * (size_t)p;
  const float *a = s->mesh.pos + 3 * (size_t)ix[0], *b = s->mesh.pos + 3 * (size_t)ix[1], *c = s->mesh.pos + 3 * (size_t)ix[2];
  double e1[3], e2[3], q[3], d[3] = {r->dir[0], r->dir[1], r->dir[2]};
  for (int k = 0; k < 3; k++) { e1[k] = (double)b[k] - a[k]; e2[k] = (double)c[k] - a[k]; q[k] = (double)r->org[k] - a[k]; }
  double pv[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
  double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
  double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  if (fabs(det) <= 1e-6 * sqrt((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2])))
    return 0;
  double b1 = (q[0] * pv[0] + q[1] * pv[1] + q[2] * pv[2]) / det;
  double qv[3] = {q[1] * e1[2] - q[2] * e1[1], q[2] * e1[0] - q[0] * e1[2], q[0] * e1[1] - q[1] * e1[0]};
  double b2 = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) / det;
  *t = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
  double m = b1 < b2 ? b1 : b2;
  *margin = m < 1.0 - b1 - b2 ? m : 1.0 - b1 - b2;
  return 1;
}

#define MAXH 64

static void random_scenes_against_brute_force(void **state) {
  (void)state;
  fr_rng r = fr_rng_seed(77, 1);
  vec3 centres[2] = {v3(0, 0, 0), v3(3e3f, -2e3f, 1e3f)};
  for (int sc = 0; sc < 2; sc++) {
    scene_data sd = make_scene(&r, 12000, centres[sc], 10.0f);
    fr_scene *s = commit_scene(&sd);
    uint8_t *traced = traced_prims(s);
    enum { N = 1500 };
    fr_ray *rays = malloc(N * sizeof *rays);
    for (int i = 0; i < N; i++) {
      uint32_t src;
      rays[i] = random_ray(&r, centres[sc], 10.0f, &sd, i % 4, &src);
    }
    fr_hit *hits = malloc((size_t)N * MAXH * sizeof *hits);
    uint32_t *counts = malloc(N * sizeof *counts);
    assert_int_equal(fr_intersect_all(s, rays, N, hits, MAXH, counts), FR_OK);
    size_t total = 0, checked_clear = 0, agree = 0, touched = 0;
    for (int i = 0; i < N; i++) {
      fr_hit want[MAXH];
      size_t nb = brute_crossings(s, traced, &rays[i], want, MAXH);
      assert_int_equal(counts[i], nb);
      total += nb;
      const fr_hit *got = hits + (size_t)i * MAXH;
      for (size_t j = 0; j < MAXH; j++) {
        if (j >= nb) { assert_int_equal(got[j].prim, FR_INVALID_ID); continue; }
        assert_int_equal(got[j].prim, want[j].prim);
        assert_true(got[j].t == want[j].t && got[j].u == want[j].u && got[j].v == want[j].v);
        if (j) assert_true(got[j - 1].t <= got[j].t);
        double t, margin;
        /* a listed crossing is at least nearly a crossing, at its t */
        if (moller(s, got[j].prim, &rays[i], &t, &margin)) {
          assert_true(margin > -1e-3);
          assert_true(fabs(t - got[j].t) <= 1e-4 * fmax(1.0, fabs(t)));
        }
      }
      /* every triangle clearly crossed by the double test is listed */
      if (nb > MAXH) continue;
      for (uint32_t p = 0; p < s->mesh.ntris; p++) {
        double t, margin;
        if (!traced[p] || !moller(s, p, &rays[i], &t, &margin) || margin < 1e-4) continue;
        double dt = 1e-4 * fmax(1.0, fabs(t));
        if (!(t > rays[i].tnear + dt && t < rays[i].tfar - dt)) continue;
        int listed = 0;
        for (size_t j = 0; j < nb; j++) listed |= got[j].prim == p;
        assert_true(listed);
        checked_clear++;
      }
      /* the first crossing is the closest hit; where they differ,
         fr_intersect1's inclusive test took a triangle the ray only
         touches (along an edge, in its plane) or the two tie */
      fr_hit h;
      fr_intersect1(s, &rays[i], &h);
      int same = nb ? h.prim == got[0].prim && fabsf(h.t - got[0].t) <= 1e-5f * fmaxf(1.0f, fabsf(h.t))
                    : h.prim == FR_INVALID_ID;
      int tie = nb && h.prim != FR_INVALID_ID && fabsf(h.t - got[0].t) <= 1e-5f * fmaxf(1.0f, fabsf(h.t));
      if (!same && !tie) {
        double t, margin;
        assert_true(h.prim != FR_INVALID_ID);
        assert_true(!moller(s, h.prim, &rays[i], &t, &margin) || fabs(margin) < 1e-3);
        touched++;
      }
      agree += same;
    }
    assert_true(agree > N * 9 / 10);
    printf("scene %d: %zu crossings, %zu clear ones checked, closest hit agrees on %zu of %d rays, %zu only touched\n", sc, total,
           checked_clear, agree, N, touched);
    assert_true(total > N);        /* the rays do cross things */
    assert_true(checked_clear > N / 2);
    free(traced); free(rays); free(hits); free(counts);
    fr_scene_release(s);
    free_scene(&sd);
  }
}

/* An axis-aligned cube of 12 triangles, consistently wound. */
static fr_scene *cube(float lo, float hi) {
  float p[8][3];
  for (int i = 0; i < 8; i++) { p[i][0] = i & 1 ? hi : lo; p[i][1] = i & 2 ? hi : lo; p[i][2] = i & 4 ? hi : lo; }
  static const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  uint32_t idx[36];
  for (int f = 0; f < 6; f++) {
    const uint32_t *k = q[f];
    uint32_t tri[6] = {k[0], k[1], k[2], k[0], k[2], k[3]};
    for (int j = 0; j < 6; j++) idx[6 * f + j] = tri[j];
  }
  fr_scene *s;
  assert_int_equal(fr_scene_from_arrays(&p[0][0], 8, idx, 12, &s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  return s;
}

static uint32_t count_of(const fr_scene *s, fr_ray r) {
  uint32_t n = 99;
  assert_int_equal(fr_intersect_all(s, &r, 1, NULL, 0, &n), FR_OK);
  return n;
}

static void once_through_vertices_and_edges(void **state) {
  (void)state;
  fr_rng r = fr_rng_seed(5, 2);
  vec3 centres[2] = {v3(0.1f, 0.2f, 0.3f), v3(-7e3f, 1e3f, 2e4f)};
  for (int sc = 0; sc < 2; sc++) {
    vec3 c = centres[sc];
    float *pos;
    size_t nv;
    fr_scene *s = closed_latlong_sphere(&r, c, 1.0f, 12, 24, &pos, &nv);
    size_t aims = 0;
    for (size_t v = 0; v < nv; v++)
      for (int kind = 0; kind < 3; kind++) {
        /* at vertex v, at the midpoint of the edge to the next vertex, and
           at the vertex from a random inside point */
        vec3 a = v3_load(pos + 3 * v), b = v3_load(pos + 3 * ((v + 1) % nv));
        vec3 target = kind == 1 ? v3_scale(v3_add(a, b), 0.5f) : a;
        vec3 o = kind == 2 ? v3_add(c, v3(urand(&r, -0.2f, 0.2f), urand(&r, -0.2f, 0.2f), urand(&r, -0.2f, 0.2f))) : c;
        vec3 d = v3_sub(target, o);
        if (v3_len(d) < 0.5f) continue; /* the poles' midpoint is the centre */
        fr_ray in = {{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
        assert_int_equal(count_of(s, in), 1);
        /* the same line from outside, through the solid */
        vec3 far = v3_sub(o, v3_scale(d, 4.0f));
        fr_ray through = {{far.x, far.y, far.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
        assert_int_equal(count_of(s, through), 2);
        aims++;
      }
    assert_true(aims > 500);
    free(pos);
    fr_scene_release(s);
  }
  /* a cube: rays through its face diagonals (shared edges), its edges and
     its corners, from outside along the axes and diagonals */
  fr_scene *s = cube(-1.0f, 1.0f);
  const float offs[5] = {-1.0f, -0.5f, 0.0f, 0.5f, 1.0f};
  int aimed = 0;
  for (int ax = 0; ax < 3; ax++)
    for (int i = 0; i < 5; i++)
      for (int j = 0; j < 5; j++) {
        float o[3], d[3] = {0, 0, 0};
        o[ax] = -3.0f;
        o[(ax + 1) % 3] = offs[i];
        o[(ax + 2) % 3] = offs[j];
        d[ax] = 1.0f;
        fr_ray ray = {{o[0], o[1], o[2]}, 0.0f, {d[0], d[1], d[2]}, INFINITY};
        uint32_t n = count_of(s, ray);
        /* through the solid or along its boundary (where grazing faces
           may count), never once */
        int inside = fabsf(offs[i]) < 1.0f && fabsf(offs[j]) < 1.0f;
        if (inside) assert_int_equal(n, 2);
        else assert_true(n % 2 == 0);
        aimed++;
      }
  for (int k = 0; k < 200; k++) { /* diagonal lines through the shared diagonal edges */
    float x = urand(&r, -0.9f, 0.9f);
    fr_ray ray = {{x, -3.0f, -3.0f}, 0.0f, {0.0f, 1.0f, 1.0f}, INFINITY};
    assert_int_equal(count_of(s, ray), 2);
  }
  assert_true(aimed == 75);
  fr_scene_release(s);
}

static void truncation_counts_and_errors(void **state) {
  (void)state;
  fr_scene *s = cube(-1.0f, 1.0f);
  fr_ray r = {{0.3f, 0.2f, -5.0f}, 0.0f, {0.0f, 0.0f, 1.0f}, INFINITY};
  fr_hit h[3];
  uint32_t n = 0;
  assert_int_equal(fr_intersect_all(s, &r, 1, h, 1, &n), FR_OK);
  assert_int_equal(n, 2);
  assert_true(fabsf(h[0].t - 4.0f) < 1e-6f);
  assert_int_equal(fr_intersect_all(s, &r, 1, h, 3, &n), FR_OK);
  assert_true(fabsf(h[1].t - 6.0f) < 1e-6f && h[2].prim == FR_INVALID_ID && h[2].t == INFINITY);
  assert_true(h[0].ng[2] * h[1].ng[2] < 0.0f); /* entering and leaving faces face apart */
  r.tnear = 4.5f; /* starting inside */
  assert_int_equal(fr_intersect_all(s, &r, 1, h, 3, &n), FR_OK);
  assert_int_equal(n, 1);
  r.tnear = NAN;
  assert_int_equal(fr_intersect_all(s, &r, 1, h, 3, &n), FR_OK);
  assert_int_equal(n, 0);
  assert_int_equal(fr_intersect_all(s, &r, 1, NULL, 3, &n), FR_ERR_ARG);
  assert_int_equal(fr_intersect_all(s, &r, 1, h, 3, NULL), FR_ERR_ARG);
  assert_int_equal(fr_intersect_all(NULL, &r, 1, h, 3, &n), FR_ERR_ARG);
  assert_int_equal(fr_intersect_all(s, &r, 4, h, SIZE_MAX / 2, &n), FR_ERR_ARG);
  assert_int_equal(fr_intersect_all(s, NULL, 0, NULL, 0, NULL), FR_OK);
  fr_scene_release(s);
  fr_scene *open;
  float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  uint32_t ix[3] = {0, 1, 2};
  assert_int_equal(fr_scene_from_arrays(p, 3, ix, 1, &open), FR_OK);
  assert_int_equal(fr_intersect_all(open, &r, 1, h, 3, &n), FR_ERR_STATE);
  float c[3] = {0, 0, 5};
  assert_int_equal(fr_scene_add_sphere(open, c, 1.0f, FR_INVALID_ID), FR_OK);
  assert_int_equal(fr_scene_commit(open), FR_OK);
  assert_int_equal(fr_intersect_all(open, &r, 1, h, 3, &n), FR_ERR_UNSUPPORTED);
  assert_true(strstr(fr_last_error(), "spheres") != NULL);
  fr_scene_release(open);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(random_scenes_against_brute_force),
      cmocka_unit_test(once_through_vertices_and_edges),
      cmocka_unit_test(truncation_counts_and_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
