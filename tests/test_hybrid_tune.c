/*
 * The hybrid's threshold tuner (trace/hybrid_tune.h) on made-up costs: it
 * settles on the cheaper arm, keeps trying the other, follows a change of
 * costs, and starts afresh on another tree. (That the threshold never
 * changes an answer is test_packet's: its hybrid configurations tune.)
 */
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

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(settles_on_the_cheaper_arm),
      cmocka_unit_test(explores_less_when_far_apart),
      cmocka_unit_test(another_tree_starts_afresh),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
