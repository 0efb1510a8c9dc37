#include "workload.h"
#include <string.h>

static const char *names[FR_WL_COUNT] = {"primary", "shadow", "soft16", "ao16", "diffuse8", "specular8", "whitted", "path"};

const char *fr_workload_name(fr_workload_kind k) { return k < FR_WL_COUNT ? names[k] : "?"; }

int fr_workload_parse(const char *name, fr_workload_kind *k) {
  for (int i = 0; i < FR_WL_COUNT; i++)
    if (strcmp(name, names[i]) == 0) { *k = (fr_workload_kind)i; return 1; }
  return 0;
}
