/*
 * The path tracer's materials, statistically (as pbrt and Mitsuba test
 * theirs):
 *   - chi-square: the directions each material samples follow the pdf it
 *     states, binned over the sphere, at several angles of incidence; the
 *     share of delta lobes is what the smooth pdf leaves over;
 *   - every sample's weight is f cos / pdf of eval, and its pdf eval's;
 *   - albedo: the mean weight (the reflected energy) is at most 1, and
 *     where nothing is absorbed (white Lambert, white plastic, glass) it is 1;
 *   - reciprocity of the smooth lobes, f(wo, wi) = f(wi, wo).
 */
#include "test_util.h"
#include "material/bsdf.h"
#include "material/fresnel.h"

#define NT 24 /* bins in theta over [0, pi] */
#define NP 32 /* bins in phi */
#define SUB 24 /* each bin integrated on SUB x SUB points */

typedef struct config {
  const char *what;
  fr_bsdf m;
  fr_shading_point sp;
} config;

static vec3 dir_of(float ct, float phi) {
  const float st = sqrtf(fmaxf(0.0f, 1.0f - ct * ct));
  return v3(st * cosf(phi), st * sinf(phi), ct);
}

/* The integral of the stated pdf over bin (i, j) of theta and phi. */
static double bin_integral(const config *c, vec3 wo, int i, int j) {
  const double dth = M_PI / NT, dphi = 2.0 * M_PI / NP;
  double s = 0.0;
  for (int a = 0; a < SUB; a++)
    for (int b = 0; b < SUB; b++) {
      const double th = dth * (i + (a + 0.5) / SUB);
      const float phi = (float)(dphi * (j + (b + 0.5) / SUB));
      float pdf;
      fr_bsdf_eval(&c->m, &c->sp, wo, dir_of((float)cos(th), phi), &pdf);
      s += pdf * sin(th);
    }
  return s * dth * dphi / (SUB * SUB);
}

static void chi_square(const config *c, float theta_o, int n) {
  const vec3 wo = dir_of(cosf(theta_o), 0.7f);
  static double expect[NT * NP];
  static long count[NT * NP];
  memset(count, 0, sizeof count);
  long delta = 0;
  fr_rng r = fr_rng_seed(7, (uint64_t)(theta_o * 1000.0f));
  for (int k = 0; k < n; k++) {
    fr_bsdf_sample s;
    /* no direction (a microfacet normal that reflects below the surface)
     * falls, as the delta lobes do, outside the smooth pdf */
    if (!fr_bsdf_sample_dir(&c->m, &c->sp, wo, fr_rng_float(&r), fr_rng_float(&r), fr_rng_float(&r), &s)) { delta++; continue; }
    assert_true(fabsf(v3_len(s.wi) - 1.0f) < 1e-3f);
    if (s.delta) { delta++; continue; }
    /* the sample agrees with eval */
    float pdf;
    const vec3 f = fr_bsdf_eval(&c->m, &c->sp, wo, s.wi, &pdf);
    assert_true(fabsf(pdf - s.pdf) <= 1e-3f * pdf + 1e-6f);
    const float want[3] = {f.x / pdf, f.y / pdf, f.z / pdf}, got[3] = {s.weight.x, s.weight.y, s.weight.z};
    for (int ch = 0; ch < 3; ch++) assert_true(fabsf(want[ch] - got[ch]) <= 2e-3f * fabsf(want[ch]) + 1e-5f);
    int i = (int)(acosf(fmaxf(-1.0f, fminf(1.0f, s.wi.z))) / (float)M_PI * NT), j = (int)(atan2f(s.wi.y, s.wi.x) / (2.0f * (float)M_PI) * NP + NP) % NP;
    if (i >= NT) i = NT - 1;
    if (i < 0) i = 0;
    count[i * NP + j]++;
  }
  double smooth = 0.0;
  for (int i = 0; i < NT; i++)
    for (int j = 0; j < NP; j++) smooth += (expect[i * NP + j] = bin_integral(c, wo, i, j) * n);
  /* Pearson's statistic, bins expecting fewer than 5 pooled */
  double chi2 = 0.0, pool_e = 0.0, pool_o = 0.0;
  int df = 0;
  for (int b = 0; b < NT * NP; b++) {
    if (expect[b] < 5.0) { pool_e += expect[b]; pool_o += (double)count[b]; continue; }
    chi2 += (count[b] - expect[b]) * (count[b] - expect[b]) / expect[b];
    df++;
  }
  if (pool_e >= 5.0) { chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e; df++; }
  else assert_true(pool_o <= pool_e + 5.0 * sqrt(pool_e + 1.0) + 5.0); /* nothing where the pdf says nothing */
  const double delta_e = fmax(0.0, n - smooth);
  if (delta_e >= 5.0) { chi2 += (delta - delta_e) * (delta - delta_e) / delta_e; df++; }
  else assert_true(delta <= delta_e + 5.0 * sqrt(delta_e + 1.0) + 5.0);
  /* about five standard deviations of a chi-square of df degrees */
  const double bound = df + 5.0 * sqrt(2.0 * df) + 10.0;
  print_message("%-34s theta_o %4.1f: chi2 %8.1f, df %3d (bound %6.1f), delta or none %.4f of %.4f\n", c->what,
                (double)theta_o * 180.0 / M_PI, chi2, df, bound, (double)delta / n, delta_e / n);
  assert_true(chi2 < bound);
}

/* The mean weight over incident light: at most 1, and `exact` where set. */
static void albedo(const config *c, float theta_o, float exact) {
  const vec3 wo = dir_of(cosf(theta_o), 0.3f);
  fr_rng r = fr_rng_seed(9, 1);
  const int n = FR_TEST_ROUNDS(200000);
  double sum[3] = {0, 0, 0};
  for (int k = 0; k < n; k++) {
    fr_bsdf_sample s;
    if (!fr_bsdf_sample_dir(&c->m, &c->sp, wo, fr_rng_float(&r), fr_rng_float(&r), fr_rng_float(&r), &s)) continue;
    sum[0] += s.weight.x, sum[1] += s.weight.y, sum[2] += s.weight.z;
  }
  for (int ch = 0; ch < 3; ch++) {
    const double a = sum[ch] / n;
    if (ch == 0) print_message("%-34s theta_o %4.1f: albedo %.4f\n", c->what, (double)theta_o * 180.0 / M_PI, a);
    assert_true(a <= 1.01);
    if (exact > 0.0f) assert_true(fabs(a - exact) < 0.02);
  }
}

static void reciprocity(const config *c) {
  fr_rng r = fr_rng_seed(11, 2);
  for (int k = 0; k < 2000; k++) {
    const vec3 a = dir_of(fr_rng_float(&r), 6.2831853f * fr_rng_float(&r));
    const vec3 b = dir_of(fr_rng_float(&r), 6.2831853f * fr_rng_float(&r));
    float p;
    const vec3 fab = v3_scale(fr_bsdf_eval(&c->m, &c->sp, a, b, &p), 1.0f / b.z);
    const vec3 fba = v3_scale(fr_bsdf_eval(&c->m, &c->sp, b, a, &p), 1.0f / a.z);
    assert_true(fabsf(fab.x - fba.x) <= 1e-3f * fmaxf(fab.x, 1e-3f));
  }
}

static config make(const char *what, fr_bsdf_kind kind) {
  config c;
  memset(&c, 0, sizeof c);
  c.what = what;
  c.m = fr_bsdf_default(kind);
  fr_bsdf_prepare(&c.m, v3(0, 0, 0), &c.sp);
  c.sp.flake = 0;
  return c;
}

static void every_kind(void **st) {
  (void)st;
  config cs[10];
  int n = 0;
  cs[n++] = make("lambert", FR_BSDF_LAMBERT);
  cs[n] = make("plastic", FR_BSDF_PLASTIC); cs[n++].m.color = v3(0.5f, 0.3f, 0.9f);
  cs[n] = make("plastic roughness 0.4", FR_BSDF_PLASTIC); cs[n].m.color = v3(0.2f, 0.6f, 0.3f); cs[n++].m.roughness = 0.4f;
  cs[n] = make("metal gold roughness 0.3", FR_BSDF_METAL); fr_bsdf_metal_preset("gold", &cs[n].m); cs[n++].m.roughness = 0.3f;
  cs[n] = make("metal aluminium roughness 0.7", FR_BSDF_METAL); fr_bsdf_metal_preset("aluminium", &cs[n].m); cs[n++].m.roughness = 0.7f;
  cs[n++] = make("metal chrome mirror", FR_BSDF_METAL);
  cs[n++] = make("carpaint base", FR_BSDF_CARPAINT);
  cs[n] = make("carpaint on a tilted flake", FR_BSDF_CARPAINT);
  cs[n].sp.flake = 1; cs[n].sp.flake_n = v3_norm(v3(0.2f, -0.1f, 1.0f)); cs[n++].m.flake_roughness = 0.4f;
  const int samples = FR_TEST_ROUNDS(400000);
  const float angles[3] = {0.15f, 0.8f, 1.35f};
  for (int i = 0; i < n; i++) {
    for (int a = 0; a < 3; a++) {
      chi_square(&cs[i], angles[a], samples);
      albedo(&cs[i], angles[a], 0.0f);
    }
    reciprocity(&cs[i]);
  }
}

/* Nothing absorbed, nothing lost: white Lambert reflects everything, and a
 * white plastic (coat plus base) does up to the Fresnel fit's accuracy. */
static void energy_conserved(void **st) {
  (void)st;
  config l = make("lambert white", FR_BSDF_LAMBERT);
  l.m.color = v3(1, 1, 1);
  config p = make("plastic white", FR_BSDF_PLASTIC);
  p.m.color = v3(1, 1, 1);
  config r = make("plastic white, roughness 0.3", FR_BSDF_PLASTIC);
  r.m.color = v3(1, 1, 1);
  r.m.roughness = 0.3f;
  for (int a = 0; a < 3; a++) {
    const float th = 0.2f + 0.5f * (float)a;
    albedo(&l, th, 1.0f);
    albedo(&p, th, 1.0f);
    albedo(&r, th, 0.0f); /* at most 1, less what the microfacets lose */
  }
}

/* Glass: reflection with the Fresnel probability, refraction by Snell's law
 * otherwise, from outside and from inside, total internal reflection past
 * the critical angle. */
static void glass_lobes(void **st) {
  (void)st;
  const config c = make("glass", FR_BSDF_GLASS);
  fr_rng r = fr_rng_seed(5, 5);
  const float cos_o[4] = {0.9f, 0.3f, -0.9f, -0.5f}; /* the last past the critical angle from inside (sin 0.87 > 1/1.5) */
  for (int a = 0; a < 4; a++) {
    const vec3 wo = dir_of(cos_o[a], 1.1f);
    const float f = fr_fresnel_dielectric(cos_o[a], c.m.ior, NULL);
    const int n = 100000;
    int refl = 0;
    for (int k = 0; k < n; k++) {
      fr_bsdf_sample s;
      assert_true(fr_bsdf_sample_dir(&c.m, &c.sp, wo, fr_rng_float(&r), fr_rng_float(&r), fr_rng_float(&r), &s));
      assert_true(s.delta);
      if ((s.wi.z > 0.0f) == (wo.z > 0.0f)) {
        refl++;
        assert_true(fabsf(s.wi.x + wo.x) < 1e-5f && fabsf(s.wi.z - wo.z) < 1e-5f);
      } else { /* Snell: n1 sin1 = n2 sin2, in the plane of incidence */
        const float n1 = wo.z > 0.0f ? 1.0f : c.m.ior, n2 = wo.z > 0.0f ? c.m.ior : 1.0f;
        const float s1 = sqrtf(wo.x * wo.x + wo.y * wo.y), s2 = sqrtf(s.wi.x * s.wi.x + s.wi.y * s.wi.y);
        assert_true(fabsf(n1 * s1 - n2 * s2) < 1e-4f);
        assert_true(wo.x * s.wi.x <= 0.0f && wo.y * s.wi.y <= 0.0f);
      }
      assert_true(fabsf(s.weight.x - 1.0f) < 1e-6f);
    }
    print_message("glass cos_o %5.2f: reflected %.4f, Fresnel %.4f\n", (double)cos_o[a], (double)refl / n, (double)f);
    assert_true(fabs((double)refl / n - f) < 5.0 * sqrt(f * (1.0 - f) / n) + 1e-9);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(every_kind),
      cmocka_unit_test(energy_conserved),
      cmocka_unit_test(glass_lobes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
