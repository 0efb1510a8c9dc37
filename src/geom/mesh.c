#include "mesh.h"
#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"

void fr_mesh_init(fr_mesh *m) { memset(m, 0, sizeof *m); }

void fr_mesh_free(fr_mesh *m) {
  free(m->pos);
  free(m->idx);
  free(m->mat);
  free(m->mats);
  fr_mesh_init(m);
}

/* Grows *p (elements of size elem, n in use, *cap allocated) to hold one more. */
static int grow(void **p, size_t *cap, size_t n, size_t elem) {
  if (n < *cap) return 1;
  size_t nc = *cap ? *cap * 2 : 1024;
  void *q = realloc(*p, fr_mul_size(nc, elem));
  if (!q) return 0;
  *p = q;
  *cap = nc;
  return 1;
}

fr_error fr_mesh_add_vertex(fr_mesh *m, float x, float y, float z) {
  if (!grow((void **)&m->pos, &m->cap_verts, m->nverts, 3 * sizeof(float)))
    return fr_fail(FR_ERR_NOMEM, "out of memory at vertex %zu", m->nverts);
  float *p = m->pos + 3 * m->nverts++;
  p[0] = x; p[1] = y; p[2] = z;
  return FR_OK;
}

fr_error fr_mesh_add_triangle(fr_mesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t mat) {
  size_t old_cap = m->cap_tris;
  if (!grow((void **)&m->idx, &m->cap_tris, m->ntris, 3 * sizeof(uint32_t)))
    return fr_fail(FR_ERR_NOMEM, "out of memory at triangle %zu", m->ntris);
  /* Per-triangle materials exist from the first triangle that has one on,
   * with the same capacity as the indices; earlier triangles get none. */
  if (m->mat && m->cap_tris != old_cap) {
    uint32_t *q = realloc(m->mat, fr_mul_size(m->cap_tris, sizeof(uint32_t)));
    if (!q) return fr_fail(FR_ERR_NOMEM, "out of memory at triangle %zu", m->ntris);
    m->mat = q;
  } else if (!m->mat && mat != FR_INVALID_ID) {
    m->mat = malloc(fr_mul_size(m->cap_tris, sizeof(uint32_t)));
    if (!m->mat) return fr_fail(FR_ERR_NOMEM, "out of memory at triangle %zu", m->ntris);
    for (size_t i = 0; i < m->ntris; i++) m->mat[i] = FR_INVALID_ID;
  }
  if (m->mat) m->mat[m->ntris] = mat;
  uint32_t *t = m->idx + 3 * m->ntris++;
  t[0] = a; t[1] = b; t[2] = c;
  return FR_OK;
}

void fr_material_default(fr_material *mat, const char *name) {
  memset(mat, 0, sizeof *mat);
  snprintf(mat->name, sizeof mat->name, "%s", name);
  mat->diffuse[0] = mat->diffuse[1] = mat->diffuse[2] = 0.8f;
  mat->shininess = 1.0f;
  mat->ior = 1.0f;
}

fr_error fr_mesh_material(fr_mesh *m, const char *name, uint32_t *out) {
  for (size_t i = 0; i < m->nmats; i++)
    if (strncmp(m->mats[i].name, name, sizeof m->mats[i].name - 1) == 0) { *out = (uint32_t)i; return FR_OK; }
  if (!grow((void **)&m->mats, &m->cap_mats, m->nmats, sizeof(fr_material)))
    return fr_fail(FR_ERR_NOMEM, "out of memory at material %s", name);
  fr_material_default(&m->mats[m->nmats], name);
  *out = (uint32_t)m->nmats++;
  return FR_OK;
}

fr_error fr_mesh_validate(const fr_mesh *m, const char *what) {
  if (m->ntris == 0) return fr_fail(FR_ERR_FORMAT, "%s: scene has no triangles", what);
  if (m->ntris >= (1u << 27)) return fr_fail(FR_ERR_UNSUPPORTED, "%s: %zu triangles, at most %u supported", what, m->ntris, 1u << 27);
  for (size_t t = 0; t < m->ntris; t++) {
    for (int k = 0; k < 3; k++) {
      uint32_t i = m->idx[3 * t + k];
      if (i >= m->nverts)
        return fr_fail(FR_ERR_FORMAT, "%s: triangle %zu uses vertex %u but there are only %zu vertices", what, t, i, m->nverts);
      const float *p = m->pos + 3 * (size_t)i;
      if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
        return fr_fail(FR_ERR_FORMAT, "%s: vertex %u is not finite (%g %g %g)", what, i, p[0], p[1], p[2]);
    }
  }
  return FR_OK;
}

int fr_mesh_triangle_traceable(const fr_mesh *m, size_t tri) {
  return !fr_mesh_triangle_degenerate(m, tri) && fr_mesh_triangle_resolvable(m, tri);
}

int fr_mesh_triangle_resolvable(const fr_mesh *m, size_t tri) {
  const uint32_t *t = m->idx + 3 * tri;
  const float *a = m->pos + 3 * (size_t)t[0], *b = m->pos + 3 * (size_t)t[1], *c = m->pos + 3 * (size_t)t[2];
  float e1[3], e2[3];
  for (int k = 0; k < 3; k++) { e1[k] = b[k] - a[k]; e2[k] = c[k] - a[k]; }
  const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const int zero = n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f;
  return !zero && isfinite(n[0]) && isfinite(n[1]) && isfinite(n[2]);
}

int fr_mesh_triangle_degenerate(const fr_mesh *m, size_t tri) {
  const uint32_t *t = m->idx + 3 * tri;
  const float *a = m->pos + 3 * (size_t)t[0], *b = m->pos + 3 * (size_t)t[1], *c = m->pos + 3 * (size_t)t[2];
  double e1[3], e2[3];
  for (int k = 0; k < 3; k++) { e1[k] = (double)b[k] - a[k]; e2[k] = (double)c[k] - a[k]; }
  double nx = e1[1] * e2[2] - e1[2] * e2[1];
  double ny = e1[2] * e2[0] - e1[0] * e2[2];
  double nz = e1[0] * e2[1] - e1[1] * e2[0];
  return nx == 0.0 && ny == 0.0 && nz == 0.0;
}
