/*
 * The path tracer (render/path.h) as a whole:
 *   - white furnace: inside a constant environment of radiance 1, a closed
 *     white Lambert sphere and a clear glass sphere render 1 everywhere
 *     (mean within 0.5% at 256 samples per pixel);
 *   - Radiance HDR files decode alike flat and run-length encoded;
 *   - the environment's importance sampling (render/light) has the same
 *     mean as uniform sampling, and states the pdf it samples by;
 *   - the samplers stratify: n points of a pixel's pattern fall one per
 *     stratum of 1/n in each coordinate;
 *   - points made many at a time (Sobol's as vector code, on every ISA)
 *     are the bits fr_sample2d makes one at a time;
 *   - the hit frames made as vector code (render/path_frames.h), on every
 *     ISA, are the bits of the scalar shader's arithmetic;
 *   - the camera hits' shadow rays to a point light, traced by multi-frusta
 *     from the light, give the image their rays give;
 *   - the image is the same bits on 1 and 3 threads and in every trace mode
 *     (up to rays that graze an edge: none on these spheres), and equals
 *     the one traced through Embree with the same seed but for a few
 *     pixels.
 */
#include "test_util.h"
#include "embree_tracer.h"
#include "io/image_read.h"
#include "light/environment.h"
#include "base/rng.h"
#include "render/path.h"
#include "render/path_camera.h"
#include "render/path_frames.h"
#include "base/trig.h"
#include "render/progressive.h"
#include "material/texture.h"
#include "render/sampler.h"
#include "render/surfaces.h"

typedef struct furnace {
  fr_scene *s;
  fr_bsdf mats[2];
  fr_env env;
  fr_path_setup P;
  fr_workload w;
} furnace;

/* A unit sphere of material kind at the origin, seen from z = 3.5, in a
 * constant white environment. */
static void furnace_setup(furnace *f, fr_bsdf m, int size, int spp) {
  memset(f, 0, sizeof *f);
  assert_int_equal(fr_scene_new(&f->s), FR_OK);
  fr_material mt;
  memset(&mt, 0, sizeof mt);
  snprintf(mt.name, sizeof mt.name, "ball");
  uint32_t id;
  assert_int_equal(fr_scene_add_material(f->s, &mt, &id), FR_OK);
  const float c[3] = {0, 0, 0};
  assert_int_equal(fr_scene_add_sphere(f->s, c, 1.0f, id), FR_OK);
  assert_int_equal(fr_scene_commit(f->s), FR_OK);
  f->mats[0] = m;
  f->mats[1] = fr_bsdf_default(FR_BSDF_LAMBERT);
  fr_env_constant(&f->env, v3(1, 1, 1));
  f->P.mats = f->mats, f->P.count = 2;
  f->P.lights.env = &f->env;
  f->P.max_depth = 13, f->P.sampler = FR_SAMPLER_HAMMERSLEY, f->P.spp = spp, f->P.spp_end = spp;
  f->P.focus = 3.5f;
  fr_workload *w = &f->w;
  w->kind = FR_WL_PATH;
  w->scene = f->s;
  assert_int_equal(fr_camera_setup(&w->cam, v3(0, 0, 3.5f), v3(0, 0, 0), v3(0, 1, 0), 40.0f, size, size), FR_OK);
  w->view.up = v3(0, 1, 0);
  w->eps = 1e-4f;
  w->threads = 2;
  f->P.seed = 3;
  w->path = &f->P;
  w->image = calloc((size_t)size * size * 3, sizeof(float));
}

static void furnace_free(furnace *f) {
  free(f->w.image);
  fr_env_free(&f->env);
  fr_scene_release(f->s);
}

static double render_mean(furnace *f, const fr_tracer *t, uint64_t *rays) {
  const fr_workload_result r = fr_workload_run(&f->w, t);
  if (rays) *rays = r.rays;
  const size_t n = (size_t)f->w.cam.width * f->w.cam.height * 3;
  double sum = 0.0;
  for (size_t i = 0; i < n; i++) sum += f->w.image[i];
  return sum / (double)n / f->P.spp;
}

static void white_furnace(void **st) {
  (void)st;
  fr_bsdf kinds[2] = {fr_bsdf_default(FR_BSDF_LAMBERT), fr_bsdf_default(FR_BSDF_GLASS)};
  kinds[0].color = v3(1, 1, 1);
  const char *names[2] = {"white Lambert", "clear glass"};
  for (int k = 0; k < 2; k++) {
    furnace f;
    furnace_setup(&f, kinds[k], FR_TEST_SANITIZED ? 16 : 32, FR_TEST_SANITIZED ? 64 : 256);
    const fr_tracer t = fr_tracer_frusta(f.s);
    const double mean = render_mean(&f, &t, NULL);
    /* the sphere's own pixels too: the largest deviation of any 4x4 block */
    const int W = f.w.cam.width;
    double worst = 0.0;
    for (int by = 0; by < W; by += 4)
      for (int bx = 0; bx < W; bx += 4) {
        double s = 0.0;
        for (int y = by; y < by + 4; y++)
          for (int x = bx; x < bx + 4; x++) s += f.w.image[3 * ((size_t)y * W + x)];
        worst = fmax(worst, fabs(s / 16.0 / f.P.spp - 1.0));
      }
    print_message("%s sphere in a white furnace: mean %.5f, worst 4x4 block off by %.4f\n", names[k], mean, worst);
    assert_true(fabs(mean - 1.0) < 0.005);
    assert_true(worst < 0.05);
    furnace_free(&f);
  }
}

static void environment_sampling(void **st) {
  (void)st;
  /* a made-up sky: a gradient, a hot spot (a sun) and a black band */
  const int w = 128, h = 64;
  float *rgb = malloc((size_t)w * h * 3 * sizeof(float));
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++) {
      float *c = rgb + 3 * ((size_t)y * w + x);
      const float sun = (abs(x - 90) < 3 && abs(y - 14) < 2) ? 2000.0f : 0.0f;
      c[0] = 0.2f + (float)y / h + sun, c[1] = 0.5f + sun, c[2] = y > 40 && y < 44 ? 0.0f : 1.0f + sun;
      if (y > 40 && y < 44) c[0] = c[1] = 0.0f;
    }
  fr_env env;
  assert_int_equal(fr_env_from_image(&env, rgb, w, h), FR_OK);
  fr_env_orient(&env, v3(0.2f, 1, 0.1f), 30.0f, 1.5f);
  fr_rng r = fr_rng_seed(3, 3);
  const int n = FR_TEST_ROUNDS(2000000);
  double imp = 0.0, uni = 0.0, uni2 = 0.0, imp2 = 0.0;
  int other_texel = 0;
  for (int k = 0; k < n; k++) {
    vec3 d;
    float pdf;
    const vec3 le = fr_env_sample(&env, fr_rng_float(&r), fr_rng_float(&r), &d, &pdf);
    assert_true(pdf > 0.0f);
    /* the pdf it states is the pdf fr_env_pdf gives, and the radiance eval's,
     * but where rounding puts the direction on a neighbouring texel */
    const vec3 le2 = fr_env_eval(&env, d);
    other_texel += !(fabsf(fr_env_pdf(&env, d) - pdf) <= 2e-3f * pdf && fabsf(le2.y - le.y) <= 1e-5f * le2.y);
    const double x = le2.y / pdf;
    imp += x, imp2 += x * x;
    /* uniform over the sphere */
    const float z = 1.0f - 2.0f * fr_rng_float(&r), rr = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 6.2831853f * fr_rng_float(&r);
    const double y = fr_env_eval(&env, v3(rr * cosf(phi), rr * sinf(phi), z)).y * 4.0 * M_PI;
    uni += y, uni2 += y * y;
  }
  imp /= n, uni /= n;
  assert_true(other_texel <= n / 10000);
  const double se_imp = sqrt((imp2 / n - imp * imp) / n), se_uni = sqrt((uni2 / n - uni * uni) / n);
  print_message("environment: importance %.4f +- %.4f, uniform %.4f +- %.4f (%d of %d samples on a neighbouring texel)\n",
                imp, se_imp, uni, se_uni, other_texel, n);
  assert_true(fabs(imp - uni) < 4.0 * sqrt(se_imp * se_imp + se_uni * se_uni));
  /* and the exact integral: each texel's radiance times its solid angle */
  double exact = 0.0;
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      exact += env.rgb[3 * ((size_t)y * w + x) + 1] * env.intensity * (2.0 * M_PI / w) *
               (cos(M_PI * y / h) - cos(M_PI * (y + 1) / h));
  print_message("environment: exact %.4f\n", exact);
  assert_true(fabs(imp - exact) < 4.0 * se_imp + 1e-4 * exact);
  assert_true(se_imp < se_uni); /* and it pays */
  /* the batched samples and lookups (the filtered one too), in every ISA,
   * and the two-step lookups are the one-at-a-time bits */
  enum { B = 200 }; /* more than three chunks of 64, and a part */
  float u1[B], u2[B], pdf[B], dx[B], dy[B], dz[B], sin_b[B];
  vec3 dir[B], le[B];
  const float *tex[B];
  for (int k = 0; k < B; k++) u1[k] = fr_rng_float(&r), u2[k] = k % 7 ? fr_rng_float(&r) : 0.9999999f;
  const fr_isa best = fr_get_isa();
  for (int isa = FR_ISA_SCALAR; isa <= (int)best; isa++) {
    assert_int_equal(fr_set_isa((fr_isa)isa), FR_OK);
    fr_env_sample_batch(&env, B, u1, u2, dir, le, pdf);
    for (int k = 0; k < B; k++) {
      vec3 d1 = v3(0, 0, 0);
      float p1;
      const vec3 l1 = fr_env_sample(&env, u1[k], u2[k], &d1, &p1);
      assert_memory_equal(&l1, &le[k], sizeof l1);
      assert_memory_equal(&p1, &pdf[k], sizeof p1);
      if (p1 > 0.0f) assert_memory_equal(&d1, &dir[k], sizeof d1);
      float pe, s, pt;
      const vec3 a = fr_env_eval_pdf(&env, dir[k], &pe);
      const float *t = fr_env_texel(&env, dir[k], &s);
      const vec3 b = fr_env_texel_radiance(&env, t, s, &pt);
      assert_memory_equal(&a, &b, sizeof a);
      assert_memory_equal(&pe, &pt, sizeof pe);
      /* the batch lookup's directions: the samples', and the poles and seams */
      const vec3 q = k % 5 ? dir[k] : v3(k % 2 ? 0.0f : 1.0f, k % 3 ? 1.0f : -1.0f, 0.0f);
      dx[k] = q.x, dy[k] = q.y, dz[k] = q.z;
    }
    fr_env_texel_batch(&env, B, dx, dy, dz, tex, sin_b);
    for (int k = 0; k < B; k++) {
      float s;
      const float *t = fr_env_texel(&env, v3(dx[k], dy[k], dz[k]), &s);
      assert_ptr_equal(t, tex[k]);
      assert_memory_equal(&s, &sin_b[k], sizeof s);
    }
    fr_env_eval_smooth_batch(&env, B, dx, dy, dz, le);
    for (int k = 0; k < B; k++) {
      const vec3 a = fr_env_eval_smooth(&env, v3(dx[k], dy[k], dz[k]));
      assert_memory_equal(&a, &le[k], sizeof a);
    }
  }
  fr_set_isa(best);
  fr_env_free(&env);
}

/* Radiance RGBE: flat and run-length encoded scanlines give the same
 * values, (m + 0.5) 2^(e - 136); truncated or lying files are refused. */
static void radiance_hdr(void **st) {
  (void)st;
  const char head_flat[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n";
  unsigned char flat[sizeof head_flat - 1 + 32], rle[sizeof head_flat - 1 + 4 + 4 * 2];
  memcpy(flat, head_flat, sizeof head_flat - 1);
  memcpy(rle, head_flat, sizeof head_flat - 1);
  const unsigned char px[4] = {100, 50, 25, 130};
  for (int x = 0; x < 8; x++) memcpy(flat + sizeof head_flat - 1 + 4 * x, px, 4);
  unsigned char *r = rle + sizeof head_flat - 1;
  r[0] = 2, r[1] = 2, r[2] = 0, r[3] = 8; /* new RLE, width 8: each component as a run of 8 */
  for (int c = 0; c < 4; c++) r[4 + 2 * c] = 128 + 8, r[5 + 2 * c] = px[c];
  int w, h;
  float *a, *b;
  assert_int_equal(fr_hdr_decode("flat", flat, sizeof flat, &w, &h, &a), FR_OK);
  assert_true(w == 8 && h == 1);
  assert_int_equal(fr_hdr_decode("rle", rle, sizeof rle, &w, &h, &b), FR_OK);
  assert_memory_equal(a, b, 24 * sizeof(float));
  assert_true(fabsf(a[0] - 100.5f / 64.0f) < 1e-6f && fabsf(a[2] - 25.5f / 64.0f) < 1e-6f); /* 2^(130 - 136) */
  free(a); free(b);
  assert_int_not_equal(fr_hdr_decode("cut", rle, sizeof rle - 3, &w, &h, &a), FR_OK);
  assert_int_not_equal(fr_hdr_decode("cut", flat, sizeof flat - 1, &w, &h, &a), FR_OK);
  const char liar[] = "#?RADIANCE\n\n-Y 60000 +X 60000\n";
  assert_int_not_equal(fr_hdr_decode("liar", (const unsigned char *)liar, sizeof liar - 1, &w, &h, &a), FR_OK);
  assert_int_not_equal(fr_hdr_decode("xyze", (const unsigned char *)"#?R\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n1234", 40, &w, &h, &a), FR_OK);
}

static void samplers_stratify(void **st) {
  (void)st;
  for (int k = 0; k < FR_SAMPLER_COUNT; k++)
    for (uint32_t n = 1; n <= 256; n *= 4)
      for (uint32_t pixel = 0; pixel < 50; pixel++)
        for (uint32_t d = 0; d < 6; d++) {
          unsigned char hit1[256] = {0}, hit2[256] = {0};
          for (uint32_t i = 0; i < n; i++) {
            float u1, u2;
            fr_sample2d((fr_sampler_kind)k, fr_sampler_pixel_key(7, pixel), i, n, d, &u1, &u2);
            assert_true(u1 >= 0.0f && u1 < 1.0f && u2 >= 0.0f && u2 < 1.0f);
            hit1[(int)(u1 * n)]++, hit2[(int)(u2 * n)]++;
          }
          for (uint32_t i = 0; i < n; i++) assert_true(hit1[i] == 1 && hit2[i] == 1);
        }
}

static void batch_points_alike(void **st) {
  (void)st;
  enum { N = 203 }; /* not a multiple of any vector's lanes */
  uint32_t keys[N], idx[N];
  for (uint32_t i = 0; i < N; i++) keys[i] = fr_sampler_pixel_key(11, i * 7919u), idx[i] = (i * 37u) % 64u;
  const fr_isa best = fr_get_isa();
  static const uint32_t spps[] = {1, 48, 64}; /* Hammersley's: one at a time, and vectors */
  for (int k = 0; k < FR_SAMPLER_COUNT; k++)
    for (int isa = FR_ISA_SCALAR; isa <= (int)best; isa++) {
      assert_int_equal(fr_set_isa((fr_isa)isa), FR_OK);
      for (uint32_t d = 0; d < 40; d += 3)
        for (size_t n = 0; n <= N; n += n < 20 ? 1 : 61) {
          const uint32_t spp = spps[(d + n) % 3];
          uint32_t ix[N];
          float u1[N], u2[N];
          for (size_t i = 0; i < n; i++) ix[i] = idx[i] % spp;
          fr_sample2d_batch((fr_sampler_kind)k, keys, ix, spp, d, n, u1, u2);
          for (size_t i = 0; i < n; i++) {
            float v1, v2;
            fr_sample2d((fr_sampler_kind)k, keys[i], ix[i], spp, d, &v1, &v2);
            assert_memory_equal(&u1[i], &v1, sizeof v1);
            assert_memory_equal(&u2[i], &v2, sizeof v2);
          }
        }
    }
  fr_set_isa(best);
}

/* The built-in materials scene set up for path tracing: a constant sky,
 * the scene's lamp and point light, 8 samples of the given sampler. */
typedef struct materials_scene {
  fr_scene *s;
  fr_bsdf *mats;
  fr_texture *tex;
  size_t count, ntex, nsurf;
  fr_surface *surf;
  fr_env env;
  fr_path_setup P;
  fr_workload w;
} materials_scene;

static void materials_scene_setup(materials_scene *m, fr_sampler_kind sampler, uint32_t seed) {
  memset(m, 0, sizeof *m);
  assert_int_equal(fr_scene_builtin_materials(&m->s), FR_OK);
  assert_int_equal(fr_scene_commit(m->s), FR_OK);
  assert_int_equal(fr_path_mats_build(m->s, NULL, NULL, &m->mats, &m->count, &m->tex, &m->ntex), FR_OK);
  assert_int_equal(m->ntex, 0);
  fr_env_constant(&m->env, v3(0.6f, 0.7f, 1.0f));
  fr_view v;
  assert_true(fr_view_lookup("materials", &v));
  assert_int_equal(fr_surfaces_build(m->s, (int32_t)m->count - 1, &m->surf, &m->nsurf), FR_OK);
  const fr_path_lights L = {&m->env, 1, v.area_c, v.area_e1, v.area_e2, v3(20, 20, 20), 1, v.light, v3(50, 50, 50)};
  m->P = (fr_path_setup){.mats = m->mats, .count = m->count, .surf = m->surf, .nsurf = m->nsurf, .lights = L,
                         .max_depth = 13, .sampler = sampler, .seed = seed, .spp = 8, .spp_begin = 0, .spp_end = 8};
  m->w.kind = FR_WL_PATH, m->w.scene = m->s, m->w.view = v, m->w.eps = 1e-4f * 60.0f, m->w.path = &m->P;
}

static void materials_scene_free(materials_scene *m) {
  free(m->mats);
  free(m->surf);
  fr_path_textures_free(m->tex, m->ntex);
  fr_env_free(&m->env);
  fr_scene_release(m->s);
}

/* The hit frames' lanes on every ISA against the scalar shader's
 * arithmetic (vec3.h's, as v3_norm and v3_onb do it), bit for bit: with
 * and without a shading normal, one facing either way, glass and not, and
 * a zero geometric normal. */
static void frames_lanes_match_scalar(void **st) {
  (void)st;
  enum { M = FR_PATH_FRAMES };
  fr_path_frame_in in;
  fr_rng r = fr_rng_seed(7, 1);
  for (int j = 0; j < M; j++) {
    float *f[12] = {in.ox, in.oy, in.oz, in.dx, in.dy, in.dz, in.ax, in.ay, in.az, in.sx, in.sy, in.sz};
    for (int k = 0; k < 12; k++) f[k][j] = 2.0f * fr_rng_float(&r) - 1.0f;
    const vec3 sn = v3_norm(v3(in.sx[j], in.sy[j], in.sz[j]));
    in.sx[j] = sn.x, in.sy[j] = sn.y, in.sz[j] = sn.z;
    if (j == 5) in.ax[j] = in.ay[j] = in.az[j] = 0.0f;
    in.t[j] = 3.0f * fr_rng_float(&r);
    in.glass[j] = j % 3 == 0;
    in.shading[j] = j % 7 != 1;
  }
  fr_path_frames ref;
  size_t shaded = 0;
  for (int j = 0; j < M; j++) { /* the scalar shader's steps */
    const vec3 d = v3(in.dx[j], in.dy[j], in.dz[j]), p = v3_add(v3(in.ox[j], in.oy[j], in.oz[j]), v3_scale(d, in.t[j]));
    const vec3 ng = v3_norm(v3(in.ax[j], in.ay[j], in.az[j]));
    const int front = v3_dot(ng, d) < 0.0f;
    const vec3 ngo = in.glass[j] || front ? ng : v3_scale(ng, -1.0f);
    vec3 n = ngo;
    if (in.shading[j]) {
      vec3 ns = v3(in.sx[j], in.sy[j], in.sz[j]);
      if (v3_dot(ns, ngo) < 0.0f) ns = v3_scale(ns, -1.0f);
      if ((v3_dot(ns, d) < 0.0f) == (v3_dot(ngo, d) < 0.0f)) n = ns, shaded++;
    }
    vec3 t, b;
    v3_onb(n, &t, &b);
    const vec3 w = v3_scale(d, -1.0f);
    const float got[18] = {p.x, p.y, p.z, ngo.x, ngo.y, ngo.z, n.x, n.y, n.z, t.x, t.y, t.z, b.x, b.y, b.z,
                           v3_dot(w, t), v3_dot(w, b), v3_dot(w, n)};
    float *dst[18] = {ref.px, ref.py, ref.pz, ref.gx, ref.gy, ref.gz, ref.nx, ref.ny, ref.nz,
                      ref.tx, ref.ty, ref.tz, ref.bx, ref.by, ref.bz, ref.wx, ref.wy, ref.wz};
    for (int k = 0; k < 18; k++) dst[k][j] = got[k];
    ref.front[j] = (uint8_t)front;
  }
  assert_true(shaded > M / 4 && shaded < M); /* both choices taken */
  const fr_isa best = fr_get_isa();
  for (int isa = FR_ISA_SCALAR; isa <= (int)best; isa++) {
    fr_path_frames f;
    if (isa == FR_ISA_SCALAR) fr_path_frames_make_scalar(&in, M, &f);
    if (isa == FR_ISA_AVX2) fr_path_frames_make_avx2(&in, M, &f);
    if (isa == FR_ISA_AVX512) fr_path_frames_make_avx512(&in, M, &f);
    const float *a[18] = {f.px, f.py, f.pz, f.gx, f.gy, f.gz, f.nx, f.ny, f.nz, f.tx, f.ty, f.tz, f.bx, f.by, f.bz, f.wx, f.wy, f.wz};
    const float *b[18] = {ref.px, ref.py, ref.pz, ref.gx, ref.gy, ref.gz, ref.nx, ref.ny, ref.nz,
                          ref.tx, ref.ty, ref.tz, ref.bx, ref.by, ref.bz, ref.wx, ref.wy, ref.wz};
    for (int j = 0; j < M; j++) {
      for (int k = 0; k < 18; k++) assert_memory_equal(&a[k][j], &b[k][j], sizeof(float));
      assert_int_equal(f.front[j], ref.front[j]);
    }
    print_message("isa %d: %d lanes (%zu on their shading normal), every value the scalar bits\n", isa, M, shaded);
  }
}

/* The camera rays' lanes are the scalar camera's bits in every ISA, through
 * a pinhole and a lens: d = fwd + right sx + up sy, o on the lens, toward
 * the point in focus, normalized as v3_norm does. */
static void camera_lanes_match_scalar(void **st) {
  (void)st;
  enum { M = 150 }; /* two chunks of 64 and a part */
  fr_camera c;
  assert_int_equal(fr_camera_setup(&c, v3(1.5f, -2.0f, 7.0f), v3(0.3f, 0.1f, -1.0f), v3(0.1f, 1.0f, 0.0f), 52.0f, 640, 360), FR_OK);
  const vec3 ru = v3_norm(c.right), uu = v3_norm(c.up);
  fr_rng r = fr_rng_seed(7, 3);
  float x[M], y[M], jx[M], jy[M], lx[M], ly[M];
  for (int j = 0; j < M; j++) {
    x[j] = (float)(fr_rng_u32(&r) % 640), y[j] = (float)(fr_rng_u32(&r) % 360);
    jx[j] = fr_rng_float(&r), jy[j] = fr_rng_float(&r), lx[j] = fr_rng_float(&r), ly[j] = fr_rng_float(&r);
  }
  for (int lens = 0; lens < 2; lens++) {
    const float aperture = lens ? 0.07f : 0.0f, focus = 6.5f;
    const fr_path_camera k = {{c.eye.x, c.eye.y, c.eye.z}, {c.fwd.x, c.fwd.y, c.fwd.z}, {c.right.x, c.right.y, c.right.z},
                              {c.up.x, c.up.y, c.up.z}, {ru.x, ru.y, ru.z}, {uu.x, uu.y, uu.z}, 640.0f, 360.0f,
                              aperture, focus};
    fr_ray ref[M];
    for (int j = 0; j < M; j++) {
      const float sx = 2.0f * (x[j] + jx[j]) / 640.0f - 1.0f, sy = 1.0f - 2.0f * (y[j] + jy[j]) / 360.0f;
      vec3 d = v3_add(c.fwd, v3_add(v3_scale(c.right, sx), v3_scale(c.up, sy))), o = c.eye;
      if (lens) {
        float sn, cs;
        fr_sincos_turns(ly[j], &sn, &cs);
        const float rr = aperture * sqrtf(lx[j]);
        const vec3 f = v3_add(c.eye, v3_scale(d, focus));
        o = v3_add(o, v3_add(v3_scale(ru, rr * cs), v3_scale(uu, rr * sn)));
        d = v3_sub(f, o);
      }
      d = v3_norm(d);
      ref[j] = (fr_ray){{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
    }
    const fr_isa best = fr_get_isa();
    for (int isa = FR_ISA_SCALAR; isa <= (int)best; isa++) {
      fr_ray got[M];
      const float *a = lens ? lx : NULL, *b = lens ? ly : NULL;
      if (isa == FR_ISA_SCALAR) fr_path_camera_rays_scalar(&k, M, x, y, jx, jy, a, b, got);
      if (isa == FR_ISA_AVX2) fr_path_camera_rays_avx2(&k, M, x, y, jx, jy, a, b, got);
      if (isa == FR_ISA_AVX512) fr_path_camera_rays_avx512(&k, M, x, y, jx, jy, a, b, got);
      for (int j = 0; j < M; j++) assert_memory_equal(&got[j], &ref[j], sizeof got[j]);
    }
  }
}

/* The same image on 1 and 3 threads, in every trace mode, and through Embree. */
static void same_image_everywhere(void **st) {
  (void)st;
  materials_scene m;
  materials_scene_setup(&m, FR_SAMPLER_SOBOL, 5);
  fr_scene *s = m.s;
  fr_view v = m.w.view;
  m.P.aperture = 0.05f, m.P.focus = 9.0f;
  fr_workload w = m.w;
  const int W = FR_TEST_SANITIZED ? 48 : 96, H = W / 2;
  assert_int_equal(fr_camera_setup(&w.cam, v.eye, v.at, v.up, v.fov, W, H), FR_OK);
  const size_t n = (size_t)W * H * 3;
  float *ref = calloc(n, sizeof(float)), *img = calloc(n, sizeof(float));
  w.image = ref, w.threads = 1;
  fr_tracer t = fr_tracer_frusta(s);
  fr_workload_run(&w, &t);
  static const fr_trace_mode modes[] = {FR_TRACE_AUTO, FR_TRACE_SINGLE, FR_TRACE_PACKET16, FR_TRACE_HYBRID16, FR_TRACE_RAYSTREAM};
  for (size_t m = 0; m < sizeof modes / sizeof modes[0]; m++) {
    assert_int_equal(fr_scene_set_trace_mode(s, modes[m]), FR_OK);
    memset(img, 0, n * sizeof(float));
    w.image = img, w.threads = 3;
    fr_workload_run(&w, &t);
    size_t differ = 0;
    for (size_t i = 0; i < n; i++) differ += memcmp(&img[i], &ref[i], sizeof(float)) != 0;
    print_message("trace mode %d on 3 threads: %zu of %zu values differ from auto on 1 thread\n", (int)modes[m], differ, n);
    assert_int_equal(differ, 0);
  }
  assert_int_equal(fr_scene_set_trace_mode(s, FR_TRACE_AUTO), FR_OK);
  /* Embree: its own t, u, v bits move the paths by rounding; pixels agree
   * to within noise of their own, and the image's mean to 0.2% */
  ebr_options eo = {2, 2, 1, 0};
  ebr_scene *e;
  assert_int_equal(ebr_create(s, eo, &e), FR_OK);
  fr_tracer et = ebr_tracer(e, EBR_STREAM, EBR_FLAG_HINT, EBR_PACK_RAYS);
  memset(img, 0, n * sizeof(float));
  w.image = img, w.threads = 2;
  fr_workload_run(&w, &et);
  size_t far = 0;
  double sa = 0.0, sb = 0.0;
  for (size_t i = 0; i < n; i++) {
    sa += ref[i], sb += img[i];
    far += fabsf(img[i] - ref[i]) > 1e-3f * fmaxf(1.0f, ref[i]);
  }
  print_message("through Embree: %zu of %zu values differ by more than 0.1%%; means %.5f and %.5f\n", far, n, sa / n, sb / n);
  assert_true(far <= n / 50);
  assert_true(fabs(sa - sb) <= 2e-3 * sa);
  ebr_release(e);
  free(ref); free(img);
  materials_scene_free(&m);
}

/* fr_mft_occluded_frusta, counted: that the frusta were asked at all */
static unsigned (*mft_occluded_frusta)(void *, const fr_mft_batch *, const fr_mft_sets *, uint16_t *, fr_mft_budget *,
                                       fr_mft_occluders *);
static unsigned frusta_calls;
static unsigned counted_occluded_frusta(void *ctx, const fr_mft_batch *b, const fr_mft_sets *t, uint16_t *occ,
                                        fr_mft_budget *budget, fr_mft_occluders *cache) {
  __atomic_add_fetch(&frusta_calls, 1u, __ATOMIC_RELAXED);
  return mft_occluded_frusta(ctx, b, t, occ, budget, cache);
}

/* The camera hits' shadow rays to a point light, traced from the light by
 * multi-frusta, give the image their rays give: a Lambert floor under a
 * fog of 600 small triangles, lit by a point light above it alone,
 * direct light (one segment) and full paths, 8 samples per pixel: the same
 * bits but where a segment grazes a fog triangle's edge, which rays from
 * either end may see either way (the rule of the multi-frusta tests). */
static void point_shadows_by_frusta(void **st) {
  (void)st;
  enum { FOG = 600, NV = 4 + 3 * FOG, NT = 2 + FOG };
  float *pos = malloc(3 * NV * sizeof(float));
  uint32_t *idx = malloc(3 * NT * sizeof(uint32_t));
  const float floor[12] = {-4, 0, -4, 4, 0, -4, 4, 0, 4, -4, 0, 4};
  memcpy(pos, floor, sizeof floor);
  const uint32_t quad[6] = {0, 2, 1, 0, 3, 2};
  memcpy(idx, quad, sizeof quad);
  fr_rng r = fr_rng_seed(11, 0);
  for (int k = 0; k < FOG; k++) {
    const float cx = 6.0f * fr_rng_float(&r) - 3.0f, cy = 0.3f + 1.5f * fr_rng_float(&r), cz = 6.0f * fr_rng_float(&r) - 3.0f;
    for (int v = 0; v < 3; v++) {
      float *q = pos + 3 * (4 + 3 * k + v);
      q[0] = cx + 0.3f * fr_rng_float(&r) - 0.15f, q[1] = cy + 0.3f * fr_rng_float(&r) - 0.15f;
      q[2] = cz + 0.3f * fr_rng_float(&r) - 0.15f;
      idx[3 * (2 + k) + v] = (uint32_t)(4 + 3 * k + v);
    }
  }
  fr_scene *s;
  assert_int_equal(fr_scene_from_arrays(pos, NV, idx, NT, &s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  fr_bsdf mats[1] = {fr_bsdf_default(FR_BSDF_LAMBERT)};
  fr_env black;
  fr_env_constant(&black, v3(0, 0, 0));
  fr_path_setup P = {.mats = mats, .count = 1, .max_depth = 1, .sampler = FR_SAMPLER_SOBOL, .seed = 4, .spp = 8,
                     .spp_begin = 0, .spp_end = 8};
  P.lights.env = &black;
  P.lights.point = 1, P.lights.point_pos = v3(0.5f, 6.0f, 0.3f), P.lights.point_intensity = v3(30, 30, 30);
  fr_workload w;
  memset(&w, 0, sizeof w);
  w.kind = FR_WL_PATH, w.scene = s, w.eps = 1e-4f * 12.0f, w.path = &P, w.threads = 2;
  w.view.up = v3(0, 1, 0);
  const int W = FR_TEST_SANITIZED ? 32 : 64;
  assert_int_equal(fr_camera_setup(&w.cam, v3(0, 5, 7), v3(0, 0, 0), v3(0, 1, 0), 50.0f, W, W), FR_OK);
  const size_t n = (size_t)W * W * 3;
  float *ref = malloc(n * sizeof(float)), *img = malloc(n * sizeof(float));
  const fr_mft_tracer mctx = fr_mft_tracer_of(s, fr_mft_opts_default());
  fr_tracer by_rays = fr_tracer_frusta(s), by_frusta = fr_tracer_mft(&mctx);
  mft_occluded_frusta = by_frusta.occluded_frusta;
  by_frusta.occluded_frusta = counted_occluded_frusta;
  for (int depth = 1; depth <= 13; depth += 12) {
    P.max_depth = depth;
    memset(ref, 0, n * sizeof(float));
    w.image = ref;
    fr_workload_run(&w, &by_rays);
    memset(img, 0, n * sizeof(float));
    w.image = img;
    frusta_calls = 0;
    fr_workload_run(&w, &by_frusta);
    double lit = 0.0, lit_f = 0.0;
    size_t dark = 0, differ = 0;
    for (size_t i = 0; i < n; i += 3) {
      lit += ref[i], lit_f += img[i], dark += ref[i] == 0.0f;
      differ += memcmp(&img[i], &ref[i], 3 * sizeof(float)) != 0;
    }
    print_message("paths of %d segments: %u frusta calls, %zu of %zu pixels in shadow, %zu differ, means %.5f and %.5f\n",
                  depth, frusta_calls, dark, n / 3, differ, lit / (double)(n / 3), lit_f / (double)(n / 3));
    assert_true(frusta_calls > 0);
    assert_true(dark > n / 3 / 50 && dark < n / 3 / 2); /* shadows and light both */
    /* a segment that grazes an edge of the fog may go either way from
     * either end: one pixel's sample in a thousand at most */
    assert_true(differ <= n / 3 / 1000);
    assert_true(fabs(lit_f - lit) <= 1e-3 * lit);
  }
  free(ref); free(img); free(pos); free(idx);
  fr_env_free(&black);
  fr_scene_release(s);
}

/* A run of samples split into passes of 1, 3 or 8 sums to the same bits
 * (render/path.h), so the viewer at rest and render agree; a pass
 * abandoned through the cancel flag restarts the sums. */
static void passes_split_anyhow(void **st) {
  (void)st;
  materials_scene m;
  materials_scene_setup(&m, FR_SAMPLER_SOBOL, 3);
  fr_scene *s = m.s;
  fr_view v = m.w.view;
  fr_workload w = m.w;
  w.threads = 2;
  const int W = 40, H = 24;
  assert_int_equal(fr_camera_setup(&w.cam, v.eye, v.at, v.up, v.fov, W, H), FR_OK);
  const size_t n = (size_t)W * H * 3;
  float *img[3];
  fr_tracer t = fr_tracer_frusta(s);
  static const int per[3] = {8, 3, 1};
  for (int k = 0; k < 3; k++) {
    fr_progressive p;
    assert_int_equal(fr_progressive_init(&p, &w, FR_SM_PATH), FR_OK);
    p.spp_per_pass = per[k];
    fr_workload_result r;
    if (k == 2) { /* an abandoned pass first */
      int cancel = 1;
      fr_progressive_pass(&p, &t, &cancel, &r);
      assert_true(r.cancelled);
      assert_int_equal(r.rays, 0);
      assert_int_equal(fr_progressive_spp(&p), 0);
    }
    while (!fr_progressive_done(&p)) fr_progressive_pass(&p, &t, NULL, &r);
    assert_int_equal(fr_progressive_spp(&p), 8);
    img[k] = malloc(n * sizeof(float));
    fr_progressive_resolve(&p, img[k], NULL, NULL, NULL);
    fr_progressive_free(&p);
  }
  assert_memory_equal(img[0], img[1], n * sizeof(float));
  assert_memory_equal(img[0], img[2], n * sizeof(float));
  for (int k = 0; k < 3; k++) free(img[k]);
  materials_scene_free(&m);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(white_furnace),
      cmocka_unit_test(environment_sampling),
      cmocka_unit_test(radiance_hdr),
      cmocka_unit_test(samplers_stratify),
      cmocka_unit_test(batch_points_alike),
      cmocka_unit_test(point_shadows_by_frusta),
      cmocka_unit_test(frames_lanes_match_scalar),
      cmocka_unit_test(camera_lanes_match_scalar),
      cmocka_unit_test(same_image_everywhere),
      cmocka_unit_test(passes_split_anyhow),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
