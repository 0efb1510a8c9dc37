/*
 * The hybrid's threshold tuner (trace/hybrid_tune.h) on made-up costs: it
 * settles on the cheaper arm, keeps trying the other, follows a change of
 * costs, and starts afresh on another tree. And whatever it picks, the
 * answers stay the same: the same rays traced again and again, after
 * other rays, and on eight threads at once, get the same t, u and v bits
 * and the same triangle but where two triangles tie at one t.
 */
#include <pthread.h>
#include "random_scene.h"
#include "test_util.h"
#include "trace/wide/hybrid_tune.h"

/* Runs n packets of 16 rays whose arm a costs cost[a] cycles per ray;
 * returns how many took arm 1, and counts the timed ones in *timed. */
static unsigned run(fr_hybrid_tune *t, const void *owner, unsigned n, const double cost[2], unsigned *timed) {
  unsigned alone = 0;
  for (unsigned i = 0; i < n; i++) {
    int tm;
    const int arm = fr_hybrid_tune_pick(t, owner, &tm);
    alone += (unsigned)arm;
    if (tm) {
      fr_hybrid_tune_record(t, arm, (uint64_t)(16.0 * cost[arm]), 16);
      if (timed) (*timed)++;
    }
  }
  return alone;
}

static void settles_on_the_cheaper_arm(void **st) {
  (void)st;
  static const int owner;
  fr_hybrid_tune t = {0};
  const double alone_cheaper[2] = {2000.0, 1700.0}, hybrid_cheaper[2] = {480.0, 580.0};
  unsigned timed = 0;
  run(&t, &owner, 256, alone_cheaper, NULL);
  unsigned alone = run(&t, &owner, 8192, alone_cheaper, &timed);
  /* the other arm a packet in 64 at most, and some of the time */
  assert_true(alone >= 8192 - 8192 / FR_HYBRID_TUNE_EXPLORE);
  assert_true(alone < 8192);
  assert_int_equal(timed, 8192 / FR_HYBRID_TUNE_TIMED);
  /* the costs turn round: within two windows the choice does too */
  run(&t, &owner, 2 * FR_HYBRID_TUNE_WINDOW, hybrid_cheaper, NULL);
  alone = run(&t, &owner, 8192, hybrid_cheaper, NULL);
  assert_true(alone <= 8192 / FR_HYBRID_TUNE_EXPLORE);
  assert_true(alone > 0);
}

static void explores_less_when_far_apart(void **st) {
  (void)st;
  static const int owner;
  fr_hybrid_tune t = {0};
  const double far[2] = {300.0, 420.0}; /* ao16's: every ray alone 1.4 times as costly */
  run(&t, &owner, 1024, far, NULL);
  const unsigned alone = run(&t, &owner, 16384, far, NULL);
  assert_true(alone <= 16384 / FR_HYBRID_TUNE_EXPLORE_FAR);
  assert_true(alone > 0);
}

static void another_tree_starts_afresh(void **st) {
  (void)st;
  static const int a, b;
  fr_hybrid_tune t = {0};
  const double cost[2] = {100.0, 300.0};
  run(&t, &a, 1000, cost, NULL);
  assert_true(t.rays[0] > 0);
  int timed;
  fr_hybrid_tune_pick(&t, &b, &timed);
  assert_ptr_equal(t.owner, &b);
  assert_int_equal(t.rays[0], 0);
  assert_int_equal(t.rays[1], 0);
  assert_int_equal(t.count, 1);
  assert_true(timed);
}

enum { NRAYS = 4096, RUNS = 4 };

typedef struct trace_job {
  fr_scene *s;
  const fr_ray *rays, *other;
  fr_hit *hits; /* RUNS * NRAYS */
} trace_job;

/* The rays RUNS times, each after a different number of other rays, so
 * that the tuner's state differs from run to run. */
static void *trace_runs(void *arg) {
  trace_job *j = arg;
  static _Thread_local fr_hit scratch[NRAYS];
  for (int k = 0; k < RUNS; k++) {
    fr_intersect_stream(j->s, j->other, scratch, (size_t)(k * NRAYS / RUNS));
    fr_intersect_stream(j->s, j->rays, j->hits + (size_t)k * NRAYS, NRAYS);
  }
  return NULL;
}

static long compare(const fr_hit *a, const fr_hit *b, long *ties) {
  long differ = 0;
  for (int i = 0; i < NRAYS; i++) {
    if (a[i].prim == b[i].prim) {
      differ += memcmp(&a[i].t, &b[i].t, sizeof(float)) || memcmp(&a[i].u, &b[i].u, sizeof(float)) ||
                memcmp(&a[i].v, &b[i].v, sizeof(float));
      continue;
    }
    const int tie = a[i].prim != FR_INVALID_ID && b[i].prim != FR_INVALID_ID &&
                    fabsf(a[i].t - b[i].t) <= 1e-6f * fmaxf(1.0f, a[i].t);
    *ties += tie;
    differ += !tie;
  }
  return differ;
}

static void answers_do_not_depend_on_the_arm(void **st) {
  (void)st;
  fr_rng r = fr_rng_seed(71, 3);
  scene_data sd = make_scene(&r, 6000, v3(0, 0, 0), 1.0f);
  fr_scene *s = commit_scene(&sd);
  static fr_ray rays[NRAYS], other[NRAYS];
  /* groups of 16 from one point into a narrow cone, so that packets find
   * hits as packets under one arm and as single rays under the other */
  for (int g = 0; g < NRAYS / 16; g++) {
    const vec3 o = v3(urand(&r, -2, 2), urand(&r, -2, 2), urand(&r, -2, 2)), at = v3(urand(&r, -1, 1), 0, urand(&r, -1, 1));
    for (int i = 16 * g; i < 16 * g + 16; i++) {
      uint32_t src;
      const vec3 d = v3_sub(v3_add(at, v3(urand(&r, -0.05f, 0.05f), urand(&r, -0.05f, 0.05f), 0)), o);
      rays[i] = (fr_ray){{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, INFINITY};
      other[i] = random_ray(&r, v3(0, 0, 0), 1.0f, &sd, i % 3, &src);
    }
  }
  static const fr_trace_mode modes[] = {FR_TRACE_HYBRID16, FR_TRACE_AUTO};
  for (int m = 0; m < 2; m++) {
    assert_int_equal(fr_scene_set_trace_mode(s, modes[m]), FR_OK);
    enum { THREADS = 8 };
    static fr_hit hits[THREADS + 1][RUNS * NRAYS];
    trace_job jobs[THREADS + 1];
    pthread_t th[THREADS];
    for (int t = 0; t <= THREADS; t++) jobs[t] = (trace_job){s, rays, other, hits[t]};
    trace_runs(&jobs[THREADS]); /* this thread first, alone */
    for (int t = 0; t < THREADS; t++) assert_int_equal(pthread_create(&th[t], NULL, trace_runs, &jobs[t]), 0);
    for (int t = 0; t < THREADS; t++) pthread_join(th[t], NULL);
    long differ = 0, ties = 0;
    for (int t = 0; t <= THREADS; t++)
      for (int k = 0; k < RUNS; k++) differ += compare(hits[THREADS], hits[t] + (size_t)k * NRAYS, &ties);
    print_message("%s: %d threads x %d runs of %d rays: %ld answers differ, %ld ties at one t\n",
                  m ? "auto" : "hybrid16", THREADS + 1, RUNS, NRAYS, differ, ties);
    assert_int_equal(differ, 0);
  }
  fr_scene_release(s);
  free_scene(&sd);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(answers_do_not_depend_on_the_arm),
      cmocka_unit_test(settles_on_the_cheaper_arm),
      cmocka_unit_test(explores_less_when_far_apart),
      cmocka_unit_test(another_tree_starts_afresh),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
