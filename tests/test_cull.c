/*
 * Whole-packet culling is conservative: on random packets of every kind
 * (primary, point-light shadow, reflection and refraction off a sphere,
 * arbitrary origins and directions), no cull of any mode rejects a box,
 * triangle or sphere that one of the packet's rays hits. Hits are decided
 * in double precision, boundaries included. The test also counts how often
 * each mode culls, so it cannot pass by never culling. The bounds are
 * checked both as fr_pbounds_build makes them (in double) and as the large
 * packets make them (in float, 16 lanes at a time) on every ISA.
 */
#include "test_util.h"
#include "trace/lpacket/lpacket.h"
#include "trace/lpacket/packet_bounds.h"

#define MAXR 256

typedef struct packet {
  float o[3][MAXR], d[3][MAXR], tnear[MAXR], tfar[MAXR];
  int n;
  const char *kind;
} packet;

static void unit(double v[3]) {
  double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (int a = 0; a < 3; a++) v[a] /= l;
}

static void rand_dir(fr_rng *g, double v[3]) {
  do {
    for (int a = 0; a < 3; a++) v[a] = urand(g, -1, 1);
  } while (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] > 1.0 || v[0] * v[0] + v[1] * v[1] + v[2] * v[2] < 1e-4);
  unit(v);
}

static void set_ray(packet *p, int i, const double o[3], const double d[3], float tn, float tf) {
  for (int a = 0; a < 3; a++) { p->o[a][i] = (float)o[a]; p->d[a][i] = (float)d[a]; }
  p->tnear[i] = tn;
  p->tfar[i] = tf;
}

/* A sphere the primary rays of a packet look at: for reflection/refraction */
static int sphere_hit_d(const double o[3], const double d[3], const double c[3], double r, double *t0, double *t1) {
  double oc[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
  double A = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], B = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
  double C = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r, disc = B * B - A * C;
  if (disc < 0.0) return 0;
  double s = sqrt(disc);
  *t0 = (-B - s) / A;
  *t1 = (-B + s) / A;
  return 1;
}

static void make_packet(fr_rng *g, packet *p, int kind) {
  int side = 2 << (int)(fr_rng_float(g) * 4.0f); /* 2, 4, 8, 16 */
  p->n = side * side;
  double eye[3], fwd[3], right[3], up[3];
  double shift = fr_rng_float(g) < 0.3f ? 1000.0 : 1.0; /* far from the origin too */
  for (int a = 0; a < 3; a++) eye[a] = urand(g, -2, 2) * shift;
  rand_dir(g, fwd);
  double tmp[3];
  rand_dir(g, tmp);
  right[0] = fwd[1] * tmp[2] - fwd[2] * tmp[1];
  right[1] = fwd[2] * tmp[0] - fwd[0] * tmp[2];
  right[2] = fwd[0] * tmp[1] - fwd[1] * tmp[0];
  unit(right);
  up[0] = right[1] * fwd[2] - right[2] * fwd[1];
  up[1] = right[2] * fwd[0] - right[0] * fwd[2];
  up[2] = right[0] * fwd[1] - right[1] * fwd[0];
  double ext = urand(g, 0.001f, 0.8f); /* angular size of the packet */
  double cx = urand(g, -0.5f, 0.5f), cy = urand(g, -0.5f, 0.5f);
  double sc[3], sr = urand(g, 0.3f, 1.5f); /* the sphere reflections and refractions come from */
  for (int a = 0; a < 3; a++) sc[a] = eye[a] + 4.0 * fwd[a];
  double L[3];
  for (int a = 0; a < 3; a++) L[a] = eye[a] + urand(g, -3, 3);
  double base[3];
  rand_dir(g, base);
  for (int i = 0; i < p->n; i++) {
    double x = cx + ext * ((i % side) + 0.5) / side - 0.5 * ext, y = cy + ext * ((i / side) + 0.5) / side - 0.5 * ext;
    double d[3], o[3];
    for (int a = 0; a < 3; a++) d[a] = fwd[a] + x * right[a] + y * up[a];
    unit(d);
    if (kind == 0) { p->kind = "primary"; set_ray(p, i, eye, d, 0.0f, INFINITY); continue; }
    if (kind == 1) {
      /* shadow rays from points on a patch to the point light */
      p->kind = "shadow";
      for (int a = 0; a < 3; a++) o[a] = eye[a] + 3.0 * d[a] + urand(g, -0.01f, 0.01f);
      double to[3] = {L[0] - o[0], L[1] - o[1], L[2] - o[2]};
      double dist = sqrt(to[0] * to[0] + to[1] * to[1] + to[2] * to[2]);
      for (int a = 0; a < 3; a++) to[a] /= dist;
      set_ray(p, i, o, to, 1e-4f, (float)(dist * (1.0 - 1e-4)));
      continue;
    }
    if (kind == 2 || kind == 3) {
      /* secondary rays off a curved surface: reflection or refraction (ior 1.5) */
      double t0, t1;
      double dd[3] = {d[0], d[1], d[2]};
      for (int a = 0; a < 3; a++) dd[a] = sc[a] - eye[a] + (x * right[a] + y * up[a]) * 4.0 * sr;
      unit(dd);
      if (!sphere_hit_d(eye, dd, sc, sr, &t0, &t1)) {
        /* rays that miss the sphere keep going (a mixed packet) */
        set_ray(p, i, eye, dd, 0.0f, INFINITY);
        continue;
      }
      double h[3], n[3], r[3];
      for (int a = 0; a < 3; a++) { h[a] = eye[a] + t0 * dd[a]; n[a] = (h[a] - sc[a]) / sr; }
      double c = -(dd[0] * n[0] + dd[1] * n[1] + dd[2] * n[2]);
      if (kind == 2) {
        p->kind = "reflection";
        for (int a = 0; a < 3; a++) r[a] = dd[a] + 2.0 * c * n[a];
      } else {
        p->kind = "refraction";
        double eta = 1.0 / 1.5, k = 1.0 - eta * eta * (1.0 - c * c);
        for (int a = 0; a < 3; a++) r[a] = k < 0.0 ? dd[a] + 2.0 * c * n[a] : eta * dd[a] + (eta * c - sqrt(k)) * n[a];
      }
      unit(r);
      set_ray(p, i, h, r, 1e-4f, INFINITY);
      continue;
    }
    /* arbitrary: origins in a box, directions around a base direction (or anywhere) */
    p->kind = "random";
    double spread = i == 0 || fr_rng_float(g) < 0.9f ? urand(g, 0, 0.5f) : 2.0;
    for (int a = 0; a < 3; a++) o[a] = eye[a] + urand(g, -0.5f, 0.5f);
    double rd[3];
    rand_dir(g, rd);
    for (int a = 0; a < 3; a++) d[a] = base[a] + spread * rd[a];
    unit(d);
    set_ray(p, i, o, d, urand(g, 0, 0.1f), fr_rng_float(g) < 0.5f ? INFINITY : urand(g, 0.5f, 6.0f));
  }
}

/* ---- exact (double) hit tests ----------------------------------------------- */

static void ray_d(const packet *p, int i, double o[3], double d[3]) {
  for (int a = 0; a < 3; a++) { o[a] = p->o[a][i]; d[a] = p->d[a][i]; }
}

static int hits_box(const packet *p, int i, const float lo[3], const float hi[3]) {
  double o[3], d[3], tn = p->tnear[i], tf = p->tfar[i];
  ray_d(p, i, o, d);
  for (int a = 0; a < 3; a++) {
    if (d[a] == 0.0) {
      if (o[a] < lo[a] || o[a] > hi[a]) return 0;
      continue;
    }
    double t0 = (lo[a] - o[a]) / d[a], t1 = (hi[a] - o[a]) / d[a];
    if (t0 > t1) { double s = t0; t0 = t1; t1 = s; }
    tn = fmax(tn, t0);
    tf = fmin(tf, t1);
  }
  return tn <= tf;
}

static int hits_tri(const packet *p, int i, const float *v0, const float *v1, const float *v2) {
  double o[3], d[3], e1[3], e2[3], s[3];
  ray_d(p, i, o, d);
  for (int a = 0; a < 3; a++) { e1[a] = (double)v1[a] - v0[a]; e2[a] = (double)v2[a] - v0[a]; s[a] = o[a] - v0[a]; }
  double q[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
  double det = e1[0] * q[0] + e1[1] * q[1] + e1[2] * q[2];
  if (det == 0.0) return 0;
  double u = (s[0] * q[0] + s[1] * q[1] + s[2] * q[2]) / det;
  double r[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
  double v = (d[0] * r[0] + d[1] * r[1] + d[2] * r[2]) / det;
  double t = (e2[0] * r[0] + e2[1] * r[1] + e2[2] * r[2]) / det;
  return u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t >= p->tnear[i] && t <= p->tfar[i];
}

static int hits_sphere(const packet *p, int i, const float c[3], float r) {
  double o[3], d[3], C[3] = {c[0], c[1], c[2]}, t0, t1;
  ray_d(p, i, o, d);
  if (!sphere_hit_d(o, d, C, r, &t0, &t1)) return 0;
  return t1 >= p->tnear[i] && t0 <= p->tfar[i];
}

/* an object near a random ray of the packet, at a random distance along it */
static void near_point(fr_rng *g, const packet *p, float c[3], float *size) {
  int i = (int)(fr_rng_float(g) * (float)p->n) % p->n;
  float tf = isinf(p->tfar[i]) ? 8.0f : p->tfar[i];
  float t = urand(g, -0.2f, 1.2f) * tf;
  *size = urand(g, 0.001f, 0.5f);
  for (int a = 0; a < 3; a++) c[a] = p->o[a][i] + t * p->d[a][i] + urand(g, -0.6f, 0.6f);
}

/* Bounds of packet p for each maker: [0] fr_pbounds_build, then per ISA
 * the large packets' own, [1 + 2 isa] for the IA cull and [2 + 2 isa] for
 * planes and corners. */
#define MAKERS 7
static const fr_lp_fns *lp_isa_fns[] = {&fr_lp_scalar, &fr_lp_avx2, &fr_lp_avx512};
static const fr_isa lp_isas[] = {FR_ISA_SCALAR, FR_ISA_AVX2, FR_ISA_AVX512};

static void make_bounds(const packet *p, fr_pbounds b[MAKERS]) {
  static fr_lpacket lp;
  static fr_ray rays[MAXR];
  fr_ray_soa soa = {{p->o[0], p->o[1], p->o[2]}, {p->d[0], p->d[1], p->d[2]}, p->tnear, p->tfar, NULL, p->n};
  fr_pbounds_build(&b[0], &soa);
  for (int i = 0; i < p->n; i++) {
    for (int a = 0; a < 3; a++) { rays[i].org[a] = p->o[a][i]; rays[i].dir[a] = p->d[a][i]; }
    rays[i].tnear = p->tnear[i];
    rays[i].tfar = p->tfar[i];
  }
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 2; j++) {
      fr_lp_opts o = {FR_LP_RANGED, j ? FR_CULL_PLANES : FR_CULL_IA};
      b[1 + 2 * i + j] = b[0]; /* an ISA this CPU lacks: the double bounds again */
      if (!fr_isa_supported(lp_isas[i])) continue;
      fr_lpacket_load(&lp, rays, p->n);
      lp_isa_fns[i]->bounds(&o, &lp);
      b[1 + 2 * i + j] = lp.bounds;
    }
}

static const char *maker_name(int j) {
  static const char *names[MAKERS] = {"double", "scalar ia", "scalar planes", "avx2 ia", "avx2 planes", "avx512 ia", "avx512 planes"};
  return names[j];
}

static void check_packets(int npackets, uint64_t seed) {
  fr_rng g = fr_rng_seed(seed, 0);
  static packet p;
  long tests = 0, culled[3][FR_CULL_COUNT] = {{0}}, hit_objects = 0, lp_culled[MAKERS] = {0}, planes[MAKERS] = {0};
  for (int k = 0; k < npackets; k++) {
    make_packet(&g, &p, k % 5);
    fr_pbounds bs[MAKERS];
    make_bounds(&p, bs);
    const fr_pbounds b = bs[0];
    for (int j = 0; j < MAKERS; j++) planes[j] += bs[j].has_planes;
    for (int obj = 0; obj < 6; obj++) {
      float c[3], s;
      near_point(&g, &p, c, &s);
      float lo[3], hi[3], v[3][3];
      for (int a = 0; a < 3; a++) { lo[a] = c[a] - s * fr_rng_float(&g); hi[a] = c[a] + s * fr_rng_float(&g); }
      for (int j = 0; j < 3; j++)
        for (int a = 0; a < 3; a++) v[j][a] = c[a] + urand(&g, -s, s) * 2.0f;
      float radius = s;
      int hb = 0, ht = 0, hs = 0;
      for (int i = 0; i < p.n && !(hb && ht && hs); i++) {
        hb = hb || hits_box(&p, i, lo, hi);
        ht = ht || hits_tri(&p, i, v[0], v[1], v[2]);
        hs = hs || hits_sphere(&p, i, c, radius);
      }
      hit_objects += hb + ht + hs;
      for (int m = FR_CULL_IA; m < FR_CULL_COUNT; m++) {
        int cb = fr_pbounds_cull_box(&b, (fr_cull)m, lo, hi);
        int ct = fr_pbounds_cull_tri(&b, (fr_cull)m, v[0], v[1], v[2]);
        int cs = fr_pbounds_cull_sphere(&b, (fr_cull)m, c, radius);
        if ((cb && hb) || (ct && ht) || (cs && hs))
          fail_msg("%s packet %d (%d rays): cull %s rejects a %s one of its rays hits", p.kind, k, p.n,
                   fr_cull_name((fr_cull)m), cb && hb ? "box" : ct && ht ? "triangle" : "sphere");
        culled[0][m] += cb;
        culled[1][m] += ct;
        culled[2][m] += cs;
        tests += 3;
        for (int j = 1; j < MAKERS; j++) {
          /* the IA bounds serve the IA cull, the plane bounds all three */
          if (j % 2 == 1 && m != FR_CULL_IA) continue;
          cb = fr_pbounds_cull_box(&bs[j], (fr_cull)m, lo, hi);
          ct = fr_pbounds_cull_tri(&bs[j], (fr_cull)m, v[0], v[1], v[2]);
          cs = fr_pbounds_cull_sphere(&bs[j], (fr_cull)m, c, radius);
          if ((cb && hb) || (ct && ht) || (cs && hs))
            fail_msg("%s packet %d (%d rays), %s bounds: cull %s rejects a %s one of its rays hits", p.kind, k, p.n,
                     maker_name(j), fr_cull_name((fr_cull)m), cb && hb ? "box" : ct && ht ? "triangle" : "sphere");
          lp_culled[j] += cb + ct + cs;
        }
      }
    }
  }
  print_message("%ld packet-object tests, %ld objects hit; culled (ia/planes/corners): boxes %ld/%ld/%ld, "
                "triangles %ld/%ld/%ld, spheres %ld/%ld/%ld\n",
                tests, hit_objects, culled[0][1], culled[0][2], culled[0][3], culled[1][1], culled[1][2], culled[1][3],
                culled[2][1], culled[2][2], culled[2][3]);
  /* the large packets' bounds cull, and find planes where the double build does */
  for (int j = 1; j < MAKERS; j++) {
    if (!fr_isa_supported(lp_isas[(j - 1) / 2])) continue;
    print_message("%s bounds: %ld culls, planes in %ld of %ld packets (double: %ld)\n", maker_name(j), lp_culled[j],
                  planes[j], (long)npackets, planes[0]);
    assert_true(lp_culled[j] > tests / 100);
    if (j % 2 == 0) assert_true(planes[j] >= planes[0] - planes[0] / 1000);
  }
  /* the culls must do something, and corners (exact for boxes) at least as much as planes */
  for (int o = 0; o < 3; o++)
    for (int m = FR_CULL_IA; m < FR_CULL_COUNT; m++) assert_true(culled[o][m] > tests / 200);
  assert_true(culled[0][FR_CULL_CORNERS] >= culled[0][FR_CULL_PLANES]);
  assert_true(culled[1][FR_CULL_CORNERS] >= culled[1][FR_CULL_PLANES]);
}

static void test_conservative(void **state) {
  (void)state;
  check_packets(60000, 1);
}

/* A culled box is culled for every sub-packet too, and planes never cull
 * more boxes than corners: spot checks of the tests' relations. */
static void test_degenerate_packets(void **state) {
  (void)state;
  static packet p;
  /* all rays the same: the packet is one ray */
  fr_rng g = fr_rng_seed(3, 0);
  make_packet(&g, &p, 0);
  for (int i = 1; i < p.n; i++)
    for (int a = 0; a < 3; a++) { p.o[a][i] = p.o[a][0]; p.d[a][i] = p.d[a][0]; }
  fr_ray_soa soa = {{p.o[0], p.o[1], p.o[2]}, {p.d[0], p.d[1], p.d[2]}, p.tnear, p.tfar, NULL, p.n};
  fr_pbounds b;
  fr_pbounds_build(&b, &soa);
  assert_true(b.has_planes);
  /* an axis-parallel direction: two axes straddle zero exactly */
  for (int i = 0; i < p.n; i++) { p.d[0][i] = 1.0f; p.d[1][i] = 0.0f; p.d[2][i] = 0.0f; }
  fr_pbounds_build(&b, &soa);
  assert_int_equal(b.k, 0);
  float lo[3] = {p.o[0][0] + 1.0f, p.o[1][0] - 0.5f, p.o[2][0] - 0.5f}, hi[3] = {lo[0] + 1.0f, lo[1] + 1.0f, lo[2] + 1.0f};
  for (int m = FR_CULL_IA; m < FR_CULL_COUNT; m++) assert_false(fr_pbounds_cull_box(&b, (fr_cull)m, lo, hi));
  lo[1] += 2.0f; hi[1] += 2.0f;
  assert_true(fr_pbounds_cull_box(&b, FR_CULL_CORNERS, lo, hi));
  /* no valid ray: everything is culled */
  uint16_t none[MAXR / 16] = {0};
  soa.mask = none;
  fr_pbounds_build(&b, &soa);
  assert_true(b.empty && fr_pbounds_cull_box(&b, FR_CULL_IA, lo, hi));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_conservative),
      cmocka_unit_test(test_degenerate_packets),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
