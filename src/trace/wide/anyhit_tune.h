/*
 * The order a thread's single-ray any-hit walks visit the children they
 * hit, chosen while tracing: by the builder's occlusion rank (arm 0) or
 * nearest first (arm 1). Which finds occluders in fewer visits depends on
 * the scene (trace/bvhn_single.c, occluded_stream), so the kernel measures,
 * chunk by chunk of a stream's rays with an end.
 *
 * A probe chunk traces its rays alternately by either order and times each
 * ray: neighbouring rays of a stream cost about the same, so the two sums
 * compare like with like. Timing whole chunks of one order instead
 * compared the rare chunks of the other order with whatever their place in
 * the stream made them cost: on the hairball's point-light shadows, whose
 * chunks range from rays that leave the hair at once to rays that cross
 * it, that sent chunks the worse way. The other chunks take
 * nearest first only where it measured FR_ANYHIT_TUNE_MARGIN of the rank's
 * cost or less, so that the two coming close does not toggle it.
 */
#ifndef FR_TRACE_ANYHIT_TUNE_H
#define FR_TRACE_ANYHIT_TUNE_H
#include <stdint.h>
#include <string.h>

#define FR_ANYHIT_TUNE_PROBE 32u      /* one chunk in so many is a probe ... */
#define FR_ANYHIT_TUNE_PROBE_FAR 256u /* ... where one order measured over FR_ANYHIT_TUNE_FAR times the other's cost */
#define FR_ANYHIT_TUNE_FAR 1.25
#define FR_ANYHIT_TUNE_WINDOW 1024u   /* chunks: the sums halve, so the choice follows a workload's phases */
#define FR_ANYHIT_TUNE_MARGIN 0.9
#define FR_ANYHIT_PROBE 2             /* fr_anyhit_tune_pick's answer for a probe */

typedef struct fr_anyhit_tune {
  const void *owner;   /* the BVH the sums were measured on; another resets them */
  uint64_t cycles[2];  /* per arm, over the probes' rays */
  uint64_t rays[2];
  unsigned count;      /* chunks so far */
} fr_anyhit_tune;

/* The next chunk's order on owner's tree: 0 rank, 1 nearest first, or
 * FR_ANYHIT_PROBE. */
static inline int fr_anyhit_tune_pick(fr_anyhit_tune *t, const void *owner) {
  if (t->owner != owner) {
    memset(t, 0, sizeof *t);
    t->owner = owner;
  }
  const unsigned c = t->count++;
  if (c % FR_ANYHIT_TUNE_WINDOW == FR_ANYHIT_TUNE_WINDOW - 1)
    for (int k = 0; k < 2; k++) t->cycles[k] /= 2, t->rays[k] /= 2;
  if (!t->rays[0] || !t->rays[1]) return FR_ANYHIT_PROBE;
  const double cost0 = (double)t->cycles[0] / (double)t->rays[0];
  const double cost1 = (double)t->cycles[1] / (double)t->rays[1];
  const int nearest = cost1 < FR_ANYHIT_TUNE_MARGIN * cost0;
  const int far = cost0 > FR_ANYHIT_TUNE_FAR * cost1 || cost1 > FR_ANYHIT_TUNE_FAR * cost0;
  return c % (far ? FR_ANYHIT_TUNE_PROBE_FAR : FR_ANYHIT_TUNE_PROBE) == 0 ? FR_ANYHIT_PROBE : nearest;
}

/* One probe ray traced by order arm in `cycles`. */
static inline void fr_anyhit_tune_record(fr_anyhit_tune *t, int arm, uint64_t cycles) {
  t->cycles[arm] += cycles;
  t->rays[arm]++;
}
#endif
