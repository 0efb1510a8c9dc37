/*
 * The single-ray any-hit order's tuner (trace/anyhit_tune.h) on made-up
 * costs: it probes until both orders are measured, takes nearest-first only
 * where it is cheaper by the margin, probes less where the orders are far
 * apart, follows a change of costs, and starts afresh on another tree.
 * (That the order never changes an answer is test_occluder_cache's.)
 */
#include "test_util.h"
#include "trace/wide/anyhit_tune.h"

/* Runs n chunks; a probe's 32 rays cost cost[arm] cycles each, alternating.
 * Returns the chunks that went nearest-first, *probes the probes. */
static unsigned run(fr_anyhit_tune *t, const void *owner, unsigned n, const double cost[2], unsigned *probes) {
  unsigned nearest = 0;
  for (unsigned i = 0; i < n; i++) {
    const int how = fr_anyhit_tune_pick(t, owner);
    if (how == FR_ANYHIT_PROBE) {
      for (int k = 0; k < 32; k++) fr_anyhit_tune_record(t, k & 1, (uint64_t)cost[k & 1]);
      if (probes) (*probes)++;
    } else nearest += (unsigned)how;
  }
  return nearest;
}

static void probes_first(void **st) {
  (void)st;
  static const int owner;
  fr_anyhit_tune t = {0};
  assert_int_equal(fr_anyhit_tune_pick(&t, &owner), FR_ANYHIT_PROBE);
  fr_anyhit_tune_record(&t, 0, 1000);
  assert_int_equal(fr_anyhit_tune_pick(&t, &owner), FR_ANYHIT_PROBE); /* nearest-first not measured yet */
}

static void nearest_only_by_the_margin(void **st) {
  (void)st;
  static const int owner;
  fr_anyhit_tune t = {0};
  const double close[2] = {1000.0, 950.0}, clear[2] = {1000.0, 800.0};
  unsigned probes = 0;
  run(&t, &owner, 64, close, NULL);
  assert_int_equal(run(&t, &owner, 4096, close, &probes), 0); /* 5% cheaper is not enough */
  assert_int_equal(probes, 4096 / FR_ANYHIT_TUNE_PROBE);
  /* the costs change: within two windows the choice does too */
  run(&t, &owner, 2 * FR_ANYHIT_TUNE_WINDOW, clear, NULL);
  probes = 0;
  const unsigned nearest = run(&t, &owner, 4096, clear, &probes);
  assert_int_equal(nearest + probes, 4096); /* 20% is */
}

static void probes_less_when_far_apart(void **st) {
  (void)st;
  static const int owner;
  fr_anyhit_tune t = {0};
  const double far[2] = {1000.0, 1600.0};
  unsigned probes = 0;
  run(&t, &owner, 64, far, NULL);
  assert_int_equal(run(&t, &owner, 8192, far, &probes), 0);
  assert_int_equal(probes, 8192 / FR_ANYHIT_TUNE_PROBE_FAR);
}

static void another_tree_starts_afresh(void **st) {
  (void)st;
  static const int a, b;
  fr_anyhit_tune t = {0};
  const double cost[2] = {1000.0, 500.0};
  run(&t, &a, 100, cost, NULL);
  assert_true(t.rays[0] > 0 && t.rays[1] > 0);
  assert_int_equal(fr_anyhit_tune_pick(&t, &b), FR_ANYHIT_PROBE);
  assert_ptr_equal(t.owner, &b);
  assert_true(t.rays[0] == 0 && t.rays[1] == 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(probes_first),
      cmocka_unit_test(nearest_only_by_the_margin),
      cmocka_unit_test(probes_less_when_far_apart),
      cmocka_unit_test(another_tree_starts_afresh),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
