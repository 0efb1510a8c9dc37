#include "mesh.h"
#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"

void fr_mesh_init(fr_mesh *m) { memset(m, 0, sizeof *m); }

void fr_mesh_free(fr_mesh *m) {
  if (!m->borrowed) {
    free(m->pos);
    free(m->idx);
  }
  free(m->mat);
  free(m->mats);
  free(m->nrm.val);
  free(m->nrm.idx);
  free(m->uv.val);
  free(m->uv.idx);
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
  if (m->borrowed) return fr_fail(FR_ERR_STATE, "a mesh on shared buffers takes no more vertices");
  if (!grow((void **)&m->pos, &m->cap_verts, m->nverts, 3 * sizeof(float)))
    return fr_fail(FR_ERR_NOMEM, "out of memory at vertex %zu", m->nverts);
  float *p = m->pos + 3 * m->nverts++;
  p[0] = x; p[1] = y; p[2] = z;
  return FR_OK;
}

fr_error fr_mesh_add_triangle(fr_mesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t mat) {
  if (m->borrowed) return fr_fail(FR_ERR_STATE, "a mesh on shared buffers takes no more triangles");
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
  fr_corner_attr *attrs[2] = {&m->nrm, &m->uv};
  for (int k = 0; k < 2; k++) { /* corner indices: like the materials */
    fr_corner_attr *a = attrs[k];
    if (a->idx && m->cap_tris != old_cap) {
      uint32_t *q = realloc(a->idx, fr_mul_size(m->cap_tris, 3 * sizeof(uint32_t)));
      if (!q) return fr_fail(FR_ERR_NOMEM, "out of memory at triangle %zu", m->ntris);
      a->idx = q;
    }
    if (a->idx) a->idx[3 * m->ntris] = a->idx[3 * m->ntris + 1] = a->idx[3 * m->ntris + 2] = FR_INVALID_ID;
  }
  uint32_t *t = m->idx + 3 * m->ntris++;
  t[0] = a; t[1] = b; t[2] = c;
  return FR_OK;
}

static fr_error attr_add(fr_corner_attr *a, const float *v, int dim, const char *what) {
  if (a->n >= 0xFFFFFFF0u) return fr_fail(FR_ERR_UNSUPPORTED, "too many %s", what);
  if (!grow((void **)&a->val, &a->cap, a->n, (size_t)dim * sizeof(float)))
    return fr_fail(FR_ERR_NOMEM, "out of memory at %s %zu", what, a->n);
  memcpy(a->val + (size_t)dim * a->n++, v, (size_t)dim * sizeof(float));
  return FR_OK;
}

static fr_error attr_set(const fr_mesh *m, fr_corner_attr *a, size_t t, uint32_t i, uint32_t j, uint32_t k) {
  if (!a->idx) {
    a->idx = malloc(fr_mul_size(m->cap_tris ? m->cap_tris : 1, 3 * sizeof(uint32_t)));
    if (!a->idx) return fr_fail(FR_ERR_NOMEM, "out of memory for corner indices");
    for (size_t q = 0; q < 3 * m->ntris; q++) a->idx[q] = FR_INVALID_ID;
  }
  a->idx[3 * t] = i; a->idx[3 * t + 1] = j; a->idx[3 * t + 2] = k;
  return FR_OK;
}

static int attr_has(const fr_corner_attr *a, size_t t) {
  if (!a->idx) return 0;
  for (int k = 0; k < 3; k++)
    if (a->idx[3 * t + k] >= a->n) return 0;
  return 1;
}

fr_error fr_mesh_add_normal(fr_mesh *m, float x, float y, float z) {
  const double l = sqrt((double)x * x + (double)y * y + (double)z * z);
  float n[3] = {0.0f, 0.0f, 0.0f};
  if (l > 0.0 && l < INFINITY) n[0] = (float)(x / l), n[1] = (float)(y / l), n[2] = (float)(z / l);
  return attr_add(&m->nrm, n, 3, "normals");
}

fr_error fr_mesh_set_normals(fr_mesh *m, size_t t, uint32_t a, uint32_t b, uint32_t c) { return attr_set(m, &m->nrm, t, a, b, c); }

int fr_mesh_has_normals(const fr_mesh *m, size_t t) {
  if (!attr_has(&m->nrm, t)) return 0;
  for (int k = 0; k < 3; k++) {
    const float *n = m->nrm.val + 3 * (size_t)m->nrm.idx[3 * t + k];
    if (n[0] == 0.0f && n[1] == 0.0f && n[2] == 0.0f) return 0;
  }
  return 1;
}

fr_error fr_mesh_add_uv(fr_mesh *m, float u, float v) {
  const float uv[2] = {isfinite(u) ? u : 0.0f, isfinite(v) ? v : 0.0f};
  return attr_add(&m->uv, uv, 2, "texture coordinates");
}

fr_error fr_mesh_set_uvs(fr_mesh *m, size_t t, uint32_t a, uint32_t b, uint32_t c) { return attr_set(m, &m->uv, t, a, b, c); }

int fr_mesh_has_uvs(const fr_mesh *m, size_t t) { return attr_has(&m->uv, t); }

/* Unit face normal of triangle t (in double, kept as float), and its angle at each corner. */
static void face_normal(const fr_mesh *m, size_t t, float nf[6]) {
  double n[3], angle[3];
  const float *p[3];
  for (int k = 0; k < 3; k++) p[k] = m->pos + 3 * (size_t)m->idx[3 * t + k];
  double e[3][3];
  for (int k = 0; k < 3; k++)
    for (int a = 0; a < 3; a++) e[k][a] = (double)p[(k + 1) % 3][a] - p[k][a];
  n[0] = e[0][1] * -e[2][2] - e[0][2] * -e[2][1];
  n[1] = e[0][2] * -e[2][0] - e[0][0] * -e[2][2];
  n[2] = e[0][0] * -e[2][1] - e[0][1] * -e[2][0];
  const double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int a = 0; a < 3; a++) n[a] = l > 0.0 ? n[a] / l : 0.0;
  for (int k = 0; k < 3; k++) { /* between the edges leaving corner k */
    const double *u = e[k], *w = e[(k + 2) % 3];
    const double lu = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]), lw = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    const double c = lu > 0.0 && lw > 0.0 ? -(u[0] * w[0] + u[1] * w[1] + u[2] * w[2]) / (lu * lw) : 1.0;
    angle[k] = acos(c < -1.0 ? -1.0 : c > 1.0 ? 1.0 : c);
  }
  for (int a = 0; a < 3; a++) nf[a] = (float)n[a], nf[3 + a] = (float)angle[a];
}

fr_error fr_mesh_smooth_normals(fr_mesh *m, float crease_deg) {
  const size_t nt = m->ntris, nv = m->nverts;
  size_t todo = 0;
  for (size_t t = 0; t < nt; t++) todo += !fr_mesh_has_normals(m, t);
  if (!todo) return FR_OK;
  /* the faces around each vertex (CSR) and every face's normal and angles */
  size_t *start = calloc(nv + 1, sizeof *start);
  uint32_t *faces = malloc(fr_mul_size(nt ? nt : 1, 3 * sizeof(uint32_t)));
  float *fn = malloc(fr_mul_size(nt ? nt : 1, 6 * sizeof(float)));
  fr_error e = FR_OK;
  if (!start || !faces || !fn) { e = fr_fail(FR_ERR_NOMEM, "out of memory for smooth normals"); goto done; }
  for (size_t t = 0; t < nt; t++) {
    face_normal(m, t, fn + 6 * t);
    for (int k = 0; k < 3; k++) start[m->idx[3 * t + k] + 1]++;
  }
  for (size_t v = 0; v < nv; v++) start[v + 1] += start[v];
  for (size_t t = 0; t < nt; t++)
    for (int k = 0; k < 3; k++) faces[start[m->idx[3 * t + k]]++] = (uint32_t)t;
  for (size_t v = nv; v > 0; v--) start[v] = start[v - 1];
  start[0] = 0;
  const double cos_crease = cos((double)crease_deg * 3.14159265358979323846 / 180.0);
  /* vertex by vertex, so that the normals one vertex makes lie together and
   * equal ones (a smooth vertex's corners) are stored once */
  for (size_t v = 0; v < nv && !e; v++) {
    const size_t first = m->nrm.n;
    for (size_t i = start[v]; i < start[v + 1] && !e; i++) {
      const size_t t = faces[i];
      if (fr_mesh_has_normals(m, t) || (i > start[v] && faces[i - 1] == t)) continue;
      int k = 0;
      while (k < 3 && m->idx[3 * t + k] != v) k++;
      const float *nt0 = fn + 6 * t;
      double s[3] = {0, 0, 0};
      for (size_t j = start[v]; j < start[v + 1]; j++) {
        const size_t f = faces[j];
        if (j > start[v] && faces[j - 1] == f) continue; /* a face that uses v twice counts once */
        const float *nf = fn + 6 * f;
        if ((double)nf[0] * nt0[0] + (double)nf[1] * nt0[1] + (double)nf[2] * nt0[2] < cos_crease) continue;
        int c = 0;
        while (c < 3 && m->idx[3 * f + c] != v) c++;
        for (int a = 0; a < 3; a++) s[a] += (double)nf[a] * nf[3 + c];
      }
      const double l = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
      const float n[3] = {l > 0.0 ? (float)(s[0] / l) : 0.0f, l > 0.0 ? (float)(s[1] / l) : 0.0f, l > 0.0 ? (float)(s[2] / l) : 0.0f};
      uint32_t id = FR_INVALID_ID;
      for (size_t q = first; q < m->nrm.n && id == FR_INVALID_ID; q++)
        if (!memcmp(m->nrm.val + 3 * q, n, sizeof n)) id = (uint32_t)q;
      if (id == FR_INVALID_ID) {
        id = (uint32_t)m->nrm.n;
        e = attr_add(&m->nrm, n, 3, "normals");
      }
      if (!e && !m->nrm.idx) e = fr_mesh_set_normals(m, t, FR_INVALID_ID, FR_INVALID_ID, FR_INVALID_ID);
      if (!e) m->nrm.idx[3 * t + k] = id;
    }
  }
done:
  free(start);
  free(faces);
  free(fn);
  return e;
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
