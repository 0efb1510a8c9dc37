#ifndef FR_BASE_TIMER_H
#define FR_BASE_TIMER_H
#include <stdint.h>
#include <time.h>
static inline double fr_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A cheap clock for timing short stretches of code on one thread: the time
 * stamp counter where there is one, else nanoseconds. */
static inline uint64_t fr_cycles(void) {
#if defined(__x86_64__) || defined(__i386__)
  return __builtin_ia32_rdtsc();
#else
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
#endif
}
#endif
