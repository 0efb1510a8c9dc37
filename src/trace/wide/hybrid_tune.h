/*
 * The hybrid's switch threshold for packets whose rays span several
 * direction octants, chosen while tracing.
 *
 * The MIC paper's threshold (7) suits scenes whose incoherent packets still
 * share the top of the tree; where rays part ways at once (the hairball's
 * diffuse bounces, among strands finer than a packet's spread), the packet
 * phase costs more than it saves and rays traced alone from the root are
 * faster. Which holds depends on the scene and the rays, not on anything a
 * packet shows before it is traced, so the kernel measures: each
 * thread keeps, per kernel, the cycles per ray of packets traced with the
 * hybrid threshold (arm 0) and with every ray alone (arm 1), timing one
 * packet in FR_HYBRID_TUNE_TIMED; it traces most packets with the cheaper
 * arm and one in FR_HYBRID_TUNE_EXPLORE (or _FAR) with the other, and
 * halves its sums every FR_HYBRID_TUNE_WINDOW packets so that the choice
 * follows a workload's phases. Only speed depends on it: the packet
 * kernel makes t, u and v from the ray and the triangle it reports when it
 * finishes, whichever phase found it, so they are the same bits either way;
 * the triangle is too, up to which of two triangles that tie at one t (a
 * ray exactly through their shared edge) is reported.
 */
#ifndef FR_TRACE_HYBRID_TUNE_H
#define FR_TRACE_HYBRID_TUNE_H
#include <stdint.h>
#include <string.h>

#define FR_HYBRID_TUNE_TIMED 8u /* one packet in so many is timed: two time stamps are ~2% of an AO packet */
/* One packet in so many tries the other arm (multiples of the above), the
 * second where the other arm measured over 1.1 times as costly: on
 * conference ao16, where it costs 1.4 times as much, one packet in 64
 * comes to 0.6% */
#define FR_HYBRID_TUNE_EXPLORE 64u
#define FR_HYBRID_TUNE_EXPLORE_FAR 512u
#define FR_HYBRID_TUNE_WINDOW 4096u

typedef struct fr_hybrid_tune {
  const void *owner;           /* the BVH the sums were measured on; another resets them */
  uint64_t cycles[2], rays[2]; /* per arm */
  unsigned count;              /* packets so far */
} fr_hybrid_tune;

/* The arm for the next packet on owner's tree: 0 the hybrid threshold, 1
 * every ray alone; *timed: whether to time it (fr_hybrid_tune_record). */
static inline int fr_hybrid_tune_pick(fr_hybrid_tune *t, const void *owner, int *timed) {
  if (t->owner != owner) {
    memset(t, 0, sizeof *t);
    t->owner = owner;
  }
  const unsigned c = t->count++;
  /* cycles per ray (an arm not yet measured reads as free, so each is
   * tried at once) */
  const double cost0 = (double)t->cycles[0] / (double)(t->rays[0] + 1);
  const double cost1 = (double)t->cycles[1] / (double)(t->rays[1] + 1);
  const int alone = cost1 < cost0;
  const int far = alone ? cost0 > 1.1 * cost1 : cost1 > 1.1 * cost0;
  if (c % FR_HYBRID_TUNE_WINDOW == FR_HYBRID_TUNE_WINDOW - 1)
    for (int k = 0; k < 2; k++) t->cycles[k] /= 2, t->rays[k] /= 2;
  *timed = c % FR_HYBRID_TUNE_TIMED == 0;
  return c % (far ? FR_HYBRID_TUNE_EXPLORE_FAR : FR_HYBRID_TUNE_EXPLORE) == 0 ? !alone : alone;
}

/* Whether the next packet that asks fr_hybrid_tune_pick is to be timed (so
 * that the clock is read before it only then). */
static inline int fr_hybrid_tune_due(const fr_hybrid_tune *t) { return t->count % FR_HYBRID_TUNE_TIMED == 0; }

static inline void fr_hybrid_tune_record(fr_hybrid_tune *t, int arm, uint64_t cycles, unsigned rays) {
  t->cycles[arm] += cycles;
  t->rays[arm] += rays;
}
#endif
