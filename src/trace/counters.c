#include "counters.h"
#include <string.h>

void fr_counters_add(fr_counters *acc, const fr_counters *c) {
#define FR_COUNTER_SUM(f) acc->f += c->f;
  FR_COUNTER_FIELDS(FR_COUNTER_SUM)
#undef FR_COUNTER_SUM
}

#ifdef FRUSTA_COUNTERS
_Thread_local fr_counters fr_tls_counters;
static fr_counters total;

void fr_counters_flush(void) {
#pragma omp critical(fr_counters)
  {
#define FR_COUNTER_ADD(f) total.f += fr_tls_counters.f;
    FR_COUNTER_FIELDS(FR_COUNTER_ADD)
#undef FR_COUNTER_ADD
  }
  memset(&fr_tls_counters, 0, sizeof fr_tls_counters);
}
int fr_counters_enabled(void) { return 1; }
void fr_counters_reset(void) { memset(&total, 0, sizeof total); memset(&fr_tls_counters, 0, sizeof fr_tls_counters); }
fr_counters fr_counters_read(void) { return total; }
#else
int fr_counters_enabled(void) { return 0; }
void fr_counters_reset(void) {}
fr_counters fr_counters_read(void) { fr_counters c; memset(&c, 0, sizeof c); return c; }
#endif
