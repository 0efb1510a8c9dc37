/*
 * The same rays get the same answers whatever the thread traced before and
 * however many threads trace at once, in every trace mode: the same t, u
 * and v bits and the same triangle, and the same occlusion. Every measured
 * choice a kernel makes (the occluder cache, the any-hit order) may change
 * speed only; which phase of a hybrid packet finds a hit depends on the
 * packet's rays alone, so even of two triangles that meet a ray at one t
 * the same one is reported.
 */
#include <pthread.h>
#include "random_scene.h"
#include "test_util.h"

enum { NRAYS = 4096, RUNS = 4, THREADS = 8 };

typedef struct trace_job {
  fr_scene *s;
  const fr_ray *rays, *other;
  fr_hit *hits;   /* RUNS * NRAYS */
  uint8_t *occ;   /* RUNS * NRAYS */
} trace_job;

/* The rays RUNS times, each after a different number of other rays, so
 * that whatever state a thread keeps differs from run to run. */
static void *trace_runs(void *arg) {
  trace_job *j = arg;
  static _Thread_local fr_hit scratch[NRAYS];
  static _Thread_local uint8_t scratch_occ[NRAYS];
  for (int k = 0; k < RUNS; k++) {
    const size_t n = (size_t)((k + 1) * NRAYS / RUNS) % NRAYS;
    fr_intersect_stream(j->s, j->other, scratch, n);
    fr_occluded_stream(j->s, j->other + (NRAYS - n), scratch_occ, n);
    fr_intersect_stream(j->s, j->rays, j->hits + (size_t)k * NRAYS, NRAYS);
    fr_occluded_stream(j->s, j->rays, j->occ + (size_t)k * NRAYS, NRAYS);
  }
  return NULL;
}

static void answers_do_not_depend_on_history(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(71, 3);
  scene_data sd = make_scene(&r, 6000, v3(0, 0, 0), 1.0f);
  fr_scene *s = commit_scene(&sd);
  static fr_ray rays[NRAYS], other[NRAYS];
  /* Half the groups of 16 from one point into a narrow cone, so that
   * hybrid packets find hits both as packets and as single rays; half
   * random (several octants), with an end on every third. */
  for (int g = 0; g < NRAYS / 16; g++) {
    const vec3 o = v3(urand(&r, -2, 2), urand(&r, -2, 2), urand(&r, -2, 2)), at = v3(urand(&r, -1, 1), 0, urand(&r, -1, 1));
    for (int i = 16 * g; i < 16 * g + 16; i++) {
      uint32_t src;
      if (g % 2) {
        rays[i] = random_ray(&r, v3(0, 0, 0), 1.0f, &sd, i % 3, &src);
        if (i % 3 == 0) rays[i].tfar = urand(&r, 0.5f, 3.0f);
      } else {
        const vec3 d = v3_sub(v3_add(at, v3(urand(&r, -0.05f, 0.05f), urand(&r, -0.05f, 0.05f), 0)), o);
        rays[i] = (fr_ray){{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
      }
      other[i] = random_ray(&r, v3(0, 0, 0), 1.0f, &sd, i % 3, &src);
    }
  }
  static const fr_trace_mode modes[] = {FR_TRACE_SINGLE,   FR_TRACE_PACKET8, FR_TRACE_PACKET16,
                                        FR_TRACE_HYBRID16, FR_TRACE_AUTO,    FR_TRACE_RAYSTREAM};
  static fr_hit hits[THREADS + 1][RUNS * NRAYS];
  static uint8_t occ[THREADS + 1][RUNS * NRAYS];
  for (size_t m = 0; m < sizeof modes / sizeof modes[0]; m++) {
    assert_int_equal(fr_scene_set_trace_mode(s, modes[m]), FR_OK);
    trace_job jobs[THREADS + 1];
    pthread_t th[THREADS];
    for (int t = 0; t <= THREADS; t++) jobs[t] = (trace_job){s, rays, other, hits[t], occ[t]};
    trace_runs(&jobs[THREADS]); /* this thread first, alone */
    for (int t = 0; t < THREADS; t++) assert_int_equal(pthread_create(&th[t], NULL, trace_runs, &jobs[t]), 0);
    for (int t = 0; t < THREADS; t++) pthread_join(th[t], NULL);
    long differ = 0, hit = 0;
    for (int t = 0; t <= THREADS; t++)
      for (int k = 0; k < RUNS; k++)
        for (int i = 0; i < NRAYS; i++) {
          const fr_hit *a = &hits[THREADS][i], *b = &hits[t][(size_t)k * NRAYS + i];
          differ += a->prim != b->prim || memcmp(&a->t, &b->t, sizeof(float)) ||
                    memcmp(&a->u, &b->u, sizeof(float)) || memcmp(&a->v, &b->v, sizeof(float)) ||
                    occ[THREADS][i] != occ[t][(size_t)k * NRAYS + i];
        }
    for (int i = 0; i < NRAYS; i++) hit += hits[THREADS][i].prim != FR_INVALID_ID;
    print_message("mode %d: %d threads x %d runs of %d rays (%ld hit): %ld answers differ\n", (int)modes[m],
                  THREADS + 1, RUNS, NRAYS, hit, differ);
    assert_true(hit > NRAYS / 4);
    assert_int_equal(differ, 0);
  }
  fr_scene_release(s);
  free_scene(&sd);
}

/* fr_intersect16 and fr_occluded16, a packet at a time, likewise. */
static void packets_do_not_depend_on_history(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(72, 3);
  scene_data sd = make_scene(&r, 6000, v3(0, 0, 0), 1.0f);
  fr_scene *s = commit_scene(&sd);
  enum { PACKETS = 256 };
  static fr_ray16 pk[PACKETS];
  static fr_hit16 first[PACKETS];
  static unsigned first_occ[PACKETS];
  for (int p = 0; p < PACKETS; p++)
    for (int i = 0; i < 16; i++) {
      uint32_t src;
      const fr_ray ray = random_ray(&r, v3(0, 0, 0), 1.0f, &sd, i % 3, &src);
      pk[p].org_x[i] = ray.org[0], pk[p].org_y[i] = ray.org[1], pk[p].org_z[i] = ray.org[2];
      pk[p].dir_x[i] = ray.dir[0], pk[p].dir_y[i] = ray.dir[1], pk[p].dir_z[i] = ray.dir[2];
      pk[p].tnear[i] = ray.tnear;
      pk[p].tfar[i] = ray.tfar;
    }
  long differ = 0;
  for (int round = 0; round < RUNS; round++)
    for (int p = 0; p < PACKETS; p++) {
      /* a different packet before each, so that any state differs */
      const int q = (p + 1 + round * 37) % PACKETS;
      fr_hit16 h;
      fr_intersect16(s, 0xFFFF, &pk[q], &h);
      fr_intersect16(s, 0xFFFF, &pk[p], &h);
      const unsigned o = fr_occluded16(s, 0xFFFF, &pk[p]);
      if (!round) first[p] = h, first_occ[p] = o;
      else differ += memcmp(&h, &first[p], sizeof h) != 0 || o != first_occ[p];
    }
  assert_int_equal(differ, 0);
  fr_scene_release(s);
  free_scene(&sd);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(answers_do_not_depend_on_history),
      cmocka_unit_test(packets_do_not_depend_on_history),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
