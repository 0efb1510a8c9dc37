/*
 * A committed scene traced from many threads at once: 8 threads, each
 * making every kind of call (single rays, packets of 16, streams, closest
 * hit and occlusion) over the same rays, must give the answers one thread
 * gives. Run also under the sanitizers. (fr_intersect16's hybrid picks its
 * switch point by each thread's measured cost, which may decide between two
 * triangles at the same t and the last bits of u and v: its t is compared.)
 */
#include <pthread.h>
#include <string.h>
#include "random_scene.h"
#include "test_util.h"

enum { NRAYS = 4096, THREADS = 8, ROUNDS = 3 };

typedef struct answers {
  fr_hit single[NRAYS], stream[NRAYS];
  float packet_t[NRAYS];
  uint8_t occ1[NRAYS], occ_stream[NRAYS], occ16[NRAYS];
} answers;

typedef struct job { const fr_scene *s; const fr_ray *rays; answers *out; } job;

static void trace_all(const fr_scene *s, const fr_ray *rays, answers *a) {
  for (int i = 0; i < NRAYS; i++) {
    fr_intersect1(s, &rays[i], &a->single[i]);
    a->occ1[i] = (uint8_t)fr_occluded1(s, &rays[i]);
  }
  fr_intersect_stream(s, rays, a->stream, NRAYS);
  fr_occluded_stream(s, rays, a->occ_stream, NRAYS);
  for (int p = 0; p < NRAYS; p += 16) {
    fr_ray16 r;
    for (int k = 0; k < 16; k++) {
      const fr_ray *q = &rays[p + k];
      r.org_x[k] = q->org[0]; r.org_y[k] = q->org[1]; r.org_z[k] = q->org[2]; r.tnear[k] = q->tnear;
      r.dir_x[k] = q->dir[0]; r.dir_y[k] = q->dir[1]; r.dir_z[k] = q->dir[2]; r.tfar[k] = q->tfar;
    }
    fr_hit16 h;
    fr_intersect16(s, 0xFFFF, &r, &h);
    const unsigned occ = fr_occluded16(s, 0xFFFF, &r);
    for (int k = 0; k < 16; k++) {
      a->packet_t[p + k] = h.t[k];
      a->occ16[p + k] = (uint8_t)((occ >> k) & 1);
    }
  }
}

static void *worker(void *arg) {
  job *j = arg;
  for (int r = 0; r < ROUNDS; r++) trace_all(j->s, j->rays, j->out);
  return NULL;
}

static void threads_agree(void **state) {
  (void)state;
  fr_rng rng = fr_rng_seed(11, 5);
  scene_data sd = make_scene(&rng, 3000, v3(0, 0, 0), 1.0f);
  fr_scene *s = commit_scene(&sd);
  static fr_ray rays[NRAYS];
  for (int i = 0; i < NRAYS; i++) { /* coherent groups and scattered rays alike */
    vec3 o = i % 32 < 16 ? v3(0.1f * (float)(i % 4), 2.0f, 0.1f * (float)(i % 7))
                         : v3(fr_rng_float(&rng) - 0.5f, fr_rng_float(&rng) - 0.5f, fr_rng_float(&rng) - 0.5f);
    vec3 d = v3_norm(v3(fr_rng_float(&rng) - 0.5f, -1.0f + (i % 32 < 16 ? 0.0f : 2.0f * fr_rng_float(&rng)),
                        fr_rng_float(&rng) - 0.5f));
    rays[i] = (fr_ray){{o.x, o.y, o.z}, 0.0f, {d.x, d.y, d.z}, i % 3 ? INFINITY : 0.7f};
  }
  static answers ref, out[THREADS];
  trace_all(s, rays, &ref);
  pthread_t th[THREADS];
  job jobs[THREADS];
  for (int t = 0; t < THREADS; t++) {
    jobs[t] = (job){s, rays, &out[t]};
    assert_int_equal(pthread_create(&th[t], NULL, worker, &jobs[t]), 0);
  }
  for (int t = 0; t < THREADS; t++) pthread_join(th[t], NULL);
  long hits = 0;
  for (int t = 0; t < THREADS; t++) {
    assert_memory_equal(out[t].single, ref.single, sizeof ref.single);
    assert_memory_equal(out[t].stream, ref.stream, sizeof ref.stream);
    assert_memory_equal(out[t].occ1, ref.occ1, sizeof ref.occ1);
    assert_memory_equal(out[t].occ_stream, ref.occ_stream, sizeof ref.occ_stream);
    assert_memory_equal(out[t].occ16, ref.occ16, sizeof ref.occ16);
    assert_memory_equal(out[t].packet_t, ref.packet_t, sizeof ref.packet_t);
  }
  for (int i = 0; i < NRAYS; i++) hits += ref.single[i].prim != FR_INVALID_ID;
  print_message("%d threads x %d rounds of every call agree with one thread (%ld of %d rays hit)\n", THREADS, ROUNDS,
                hits, NRAYS);
  assert_true(hits > NRAYS / 10);
  fr_scene_release(s);
  free_scene(&sd);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(threads_agree)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
