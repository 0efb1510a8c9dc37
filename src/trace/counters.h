/*
 * Traversal counters for reproducing the papers' tables: node visits, box
 * tests, triangle tests, leaf visits, rays. Compiled in only with
 * -DFRUSTA_COUNTERS=ON (cmake), so the measured kernels pay nothing otherwise.
 * Each thread counts into its own block; fr_counters_read sums them.
 */
#ifndef FR_TRACE_COUNTERS_H
#define FR_TRACE_COUNTERS_H
#include <stdint.h>

typedef struct fr_counters {
  uint64_t rays, nodes, box_tests, leaves, tri_tests;
} fr_counters;

#ifdef FRUSTA_COUNTERS
extern _Thread_local fr_counters fr_tls_counters;
void fr_counters_flush(void);   /* adds this thread's counts to the total */
#define FR_COUNT(field, n) (fr_tls_counters.field += (uint64_t)(n))
#else
#define FR_COUNT(field, n) ((void)0)
#endif

/* 1 if counters were compiled in. */
int fr_counters_enabled(void);
void fr_counters_reset(void);
fr_counters fr_counters_read(void);
#endif
