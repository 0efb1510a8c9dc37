#include "sphere.h"
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"

void fr_spheres_free(fr_spheres *set) {
  free(set->s);
  free(set->mat);
  memset(set, 0, sizeof *set);
}

fr_error fr_spheres_add(fr_spheres *set, const float c[3], float r, uint32_t mat) {
  if (!isfinite(c[0]) || !isfinite(c[1]) || !isfinite(c[2]))
    return fr_fail(FR_ERR_ARG, "sphere %zu: centre is not finite", set->n);
  if (!(r > 0.0f) || !isfinite(r)) return fr_fail(FR_ERR_ARG, "sphere %zu: radius %g (must be finite and > 0)", set->n, r);
  /* r * r must stay finite and normal for the ray test */
  if (r > 1e18f || r < 1e-18f) return fr_fail(FR_ERR_ARG, "sphere %zu: radius %g out of range (1e-18 .. 1e18)", set->n, r);
  if (set->n == set->cap) {
    size_t nc = set->cap ? 2 * set->cap : 64;
    fr_sphere *s = realloc(set->s, fr_mul_size(nc, sizeof *s));
    if (!s) return fr_fail(FR_ERR_NOMEM, "out of memory at sphere %zu", set->n);
    set->s = s;
    uint32_t *m = realloc(set->mat, fr_mul_size(nc, sizeof *m));
    if (!m) return fr_fail(FR_ERR_NOMEM, "out of memory at sphere %zu", set->n);
    set->mat = m;
    set->cap = nc;
  }
  set->s[set->n] = (fr_sphere){{c[0], c[1], c[2]}, r};
  set->mat[set->n++] = mat;
  return FR_OK;
}
