/*
 * PLY reader (ASCII, binary little- and big-endian). Reads vertex x, y, z and
 * the face index lists, fan-triangulating polygons in file order so triangle
 * numbers match rayfile.md's `prim`; every other element and property is
 * skipped. Every read is bounds-checked: a file that lies about its counts or
 * ends early is an error, never an overrun.
 */
#include <stdio.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"
#include "io/import.h"

enum { T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64, T_BAD };
enum { F_ASCII, F_LE, F_BE };

#define MAX_ELEMS 16
#define MAX_PROPS 32
#define MAX_POLY 4096

typedef struct prop { char name[32]; int type, list, count_type; } prop;
typedef struct elem { char name[32]; uint64_t count; prop props[MAX_PROPS]; int nprops; } elem;

typedef struct cursor {
  const unsigned char *p, *end;
  int format;
  const char *path;
} cursor;

static const int type_size[] = {1, 1, 2, 2, 4, 4, 4, 8};

static int parse_type(const char *s) {
  static const struct { const char *n; int t; } names[] = {
      {"char", T_I8}, {"int8", T_I8}, {"uchar", T_U8}, {"uint8", T_U8}, {"short", T_I16}, {"int16", T_I16},
      {"ushort", T_U16}, {"uint16", T_U16}, {"int", T_I32}, {"int32", T_I32}, {"uint", T_U32}, {"uint32", T_U32},
      {"float", T_F32}, {"float32", T_F32}, {"double", T_F64}, {"float64", T_F64}};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
    if (strcmp(s, names[i].n) == 0) return names[i].t;
  return T_BAD;
}

/* Reads one value as a double; returns 0 at end of data or on a bad token. */
static int read_value(cursor *c, int type, double *out) {
  if (c->format == F_ASCII) {
    while (c->p < c->end && (*c->p == ' ' || *c->p == '\t' || *c->p == '\n' || *c->p == '\r')) c->p++;
    if (c->p >= c->end) return 0;
    char *e;
    errno = 0;
    double v = strtod((const char *)c->p, &e);
    if (e == (const char *)c->p || (const unsigned char *)e > c->end) return 0;
    c->p = (const unsigned char *)e;
    *out = v;
    return 1;
  }
  int n = type_size[type];
  if (c->end - c->p < n) return 0;
  unsigned char b[8];
  for (int i = 0; i < n; i++) b[i] = c->p[c->format == F_LE ? i : n - 1 - i];
  c->p += n;
  switch (type) {
  case T_I8: *out = (int8_t)b[0]; break;
  case T_U8: *out = b[0]; break;
  case T_I16: { int16_t v; memcpy(&v, b, 2); *out = v; break; }
  case T_U16: { uint16_t v; memcpy(&v, b, 2); *out = v; break; }
  case T_I32: { int32_t v; memcpy(&v, b, 4); *out = v; break; }
  case T_U32: { uint32_t v; memcpy(&v, b, 4); *out = v; break; }
  case T_F32: { float v; memcpy(&v, b, 4); *out = v; break; }
  default: { double v; memcpy(&v, b, 8); *out = v; break; }
  }
  return 1;
}

static fr_error truncated(cursor *c, const char *what, uint64_t i) {
  return fr_fail(FR_ERR_FORMAT, "%s: PLY data ends early or is malformed at %s %llu", c->path, what, (unsigned long long)i);
}

static fr_error parse_header(const char *path, const char *data, size_t size, elem *elems, int *nelems,
                             int *format, size_t *body) {
  if (size < 4 || memcmp(data, "ply", 3) != 0 || (data[3] != '\n' && data[3] != '\r'))
    return fr_fail(FR_ERR_FORMAT, "%s: not a PLY file (no 'ply' magic)", path);
  const char *p = data, *end = data + size;
  *nelems = 0;
  *format = -1;
  for (;;) {
    const char *nl = memchr(p, '\n', (size_t)(end - p));
    if (!nl) return fr_fail(FR_ERR_FORMAT, "%s: PLY header has no end_header", path);
    char line[256];
    size_t len = (size_t)(nl - p);
    if (len >= sizeof line) return fr_fail(FR_ERR_FORMAT, "%s: PLY header line too long", path);
    memcpy(line, p, len);
    line[len] = 0;
    if (len && line[len - 1] == '\r') line[len - 1] = 0;
    p = nl + 1;
    char w[4][64];
    int nw = sscanf(line, "%63s %63s %63s %63s", w[0], w[1], w[2], w[3]);
    if (nw <= 0 || strcmp(w[0], "comment") == 0 || strcmp(w[0], "obj_info") == 0 || strcmp(w[0], "ply") == 0) continue;
    if (strcmp(w[0], "end_header") == 0) break;
    if (strcmp(w[0], "format") == 0 && nw >= 2) {
      *format = strcmp(w[1], "ascii") == 0 ? F_ASCII : strcmp(w[1], "binary_little_endian") == 0 ? F_LE
              : strcmp(w[1], "binary_big_endian") == 0 ? F_BE : -2;
      if (*format == -2) return fr_fail(FR_ERR_UNSUPPORTED, "%s: unknown PLY format '%s'", path, w[1]);
    } else if (strcmp(w[0], "element") == 0 && nw >= 3) {
      if (*nelems == MAX_ELEMS) return fr_fail(FR_ERR_UNSUPPORTED, "%s: more than %d PLY elements", path, MAX_ELEMS);
      elem *e = &elems[(*nelems)++];
      memset(e, 0, sizeof *e);
      snprintf(e->name, sizeof e->name, "%s", w[1]);
      char *ep;
      errno = 0;
      unsigned long long cnt = strtoull(w[2], &ep, 10);
      if (*ep || w[2][0] == '-' || errno) return fr_fail(FR_ERR_FORMAT, "%s: bad count '%s' for element %s", path, w[2], w[1]);
      e->count = cnt;
    } else if (strcmp(w[0], "property") == 0 && nw >= 3) {
      if (*nelems == 0) return fr_fail(FR_ERR_FORMAT, "%s: PLY property before any element", path);
      elem *e = &elems[*nelems - 1];
      if (e->nprops == MAX_PROPS) return fr_fail(FR_ERR_UNSUPPORTED, "%s: more than %d properties in %s", path, MAX_PROPS, e->name);
      prop *pr = &e->props[e->nprops++];
      memset(pr, 0, sizeof *pr);
      if (strcmp(w[1], "list") == 0) {
        if (nw < 4) return fr_fail(FR_ERR_FORMAT, "%s: malformed PLY list property", path);
        char name[64];
        if (sscanf(line, "%*s %*s %*s %*s %63s", name) != 1) return fr_fail(FR_ERR_FORMAT, "%s: PLY list property has no name", path);
        pr->list = 1;
        pr->count_type = parse_type(w[2]);
        pr->type = parse_type(w[3]);
        if (pr->count_type == T_BAD || pr->type == T_BAD || pr->count_type == T_F32 || pr->count_type == T_F64)
          return fr_fail(FR_ERR_UNSUPPORTED, "%s: PLY list types '%s %s'", path, w[2], w[3]);
        snprintf(pr->name, sizeof pr->name, "%s", name);
      } else {
        pr->type = parse_type(w[1]);
        if (pr->type == T_BAD) return fr_fail(FR_ERR_UNSUPPORTED, "%s: unknown PLY type '%s'", path, w[1]);
        snprintf(pr->name, sizeof pr->name, "%s", w[2]);
      }
    } else {
      return fr_fail(FR_ERR_UNSUPPORTED, "%s: unexpected PLY header line '%.40s'", path, line);
    }
  }
  if (*format < 0) return fr_fail(FR_ERR_FORMAT, "%s: PLY header has no format line", path);
  *body = (size_t)(p - data);
  return FR_OK;
}

static int prop_index(const elem *e, const char *name) {
  for (int i = 0; i < e->nprops; i++)
    if (strcmp(e->props[i].name, name) == 0) return i;
  return -1;
}

static fr_error read_vertices(cursor *c, const elem *e, fr_mesh *m) {
  int ix = prop_index(e, "x"), iy = prop_index(e, "y"), iz = prop_index(e, "z");
  int inx = prop_index(e, "nx"), iny = prop_index(e, "ny"), inz = prop_index(e, "nz");
  const int normals = inx >= 0 && iny >= 0 && inz >= 0; /* one per vertex, as Blender and most tools write them */
  if (ix < 0 || iy < 0 || iz < 0) return fr_fail(FR_ERR_FORMAT, "%s: PLY vertex element lacks x, y or z", c->path);
  for (uint64_t i = 0; i < e->count; i++) {
    double xyz[3] = {0, 0, 0}, nrm[3] = {0, 0, 0};
    for (int k = 0; k < e->nprops; k++) {
      const prop *pr = &e->props[k];
      double v;
      if (pr->list) {
        double n;
        if (!read_value(c, pr->count_type, &n) || n < 0 || n > MAX_POLY) return truncated(c, "vertex", i);
        for (int j = 0; j < (int)n; j++)
          if (!read_value(c, pr->type, &v)) return truncated(c, "vertex", i);
        continue;
      }
      if (!read_value(c, pr->type, &v)) return truncated(c, "vertex", i);
      if (k == ix) xyz[0] = v; else if (k == iy) xyz[1] = v; else if (k == iz) xyz[2] = v;
      else if (k == inx) nrm[0] = v; else if (k == iny) nrm[1] = v; else if (k == inz) nrm[2] = v;
    }
    fr_error err = fr_mesh_add_vertex(m, (float)xyz[0], (float)xyz[1], (float)xyz[2]);
    if (!err && normals) err = fr_mesh_add_normal(m, (float)nrm[0], (float)nrm[1], (float)nrm[2]);
    if (err) return err;
  }
  return FR_OK;
}

static fr_error read_faces(cursor *c, const elem *e, fr_mesh *m) {
  int il = prop_index(e, "vertex_indices");
  if (il < 0) il = prop_index(e, "vertex_index");
  if (il < 0 || !e->props[il].list) return fr_fail(FR_ERR_FORMAT, "%s: PLY face element has no vertex_indices list", c->path);
  uint32_t poly[MAX_POLY];
  for (uint64_t i = 0; i < e->count; i++) {
    int npoly = 0;
    for (int k = 0; k < e->nprops; k++) {
      const prop *pr = &e->props[k];
      double v, n = 1;
      if (pr->list && (!read_value(c, pr->count_type, &n) || n < 0 || n > MAX_POLY || n != floor(n)))
        return fr_fail(FR_ERR_FORMAT, "%s: PLY face %llu has a bad vertex count", c->path, (unsigned long long)i);
      for (int j = 0; j < (int)n; j++) {
        if (!read_value(c, pr->type, &v)) return truncated(c, "face", i);
        if (k != il) continue;
        if (!(v >= 0 && v < 4294967295.0) || v != floor(v))
          return fr_fail(FR_ERR_FORMAT, "%s: PLY face %llu has a bad vertex index %g", c->path, (unsigned long long)i, v);
        poly[npoly++] = (uint32_t)v;
      }
    }
    for (int j = 2; j < npoly; j++) { /* fan: v0 v1 v2, v0 v2 v3, ... */
      fr_error err = fr_mesh_add_triangle(m, poly[0], poly[j - 1], poly[j], FR_INVALID_ID);
      /* per-vertex normals share the vertices' numbers */
      if (!err && m->nrm.n == m->nverts && m->nrm.n && poly[0] < m->nrm.n && poly[j - 1] < m->nrm.n && poly[j] < m->nrm.n)
        err = fr_mesh_set_normals(m, m->ntris - 1, poly[0], poly[j - 1], poly[j]);
      if (err) return err;
    }
  }
  return FR_OK;
}

static fr_error skip_element(cursor *c, const elem *e) {
  if (e->nprops == 0) return FR_OK; /* records of nothing: no bytes, whatever the count (found by fuzzing) */
  for (uint64_t i = 0; i < e->count; i++)
    for (int k = 0; k < e->nprops; k++) {
      const prop *pr = &e->props[k];
      double v, n = 1;
      if (pr->list && (!read_value(c, pr->count_type, &n) || n < 0 || n > MAX_POLY)) return truncated(c, e->name, i);
      for (int j = 0; j < (int)n; j++)
        if (!read_value(c, pr->type, &v)) return truncated(c, e->name, i);
    }
  return FR_OK;
}

fr_error fr_import_ply(const char *path, const char *data, size_t size, fr_mesh *m) {
  elem elems[MAX_ELEMS];
  int nelems = 0, format = F_ASCII;
  size_t body = 0;
  fr_error err = parse_header(path, data, size, elems, &nelems, &format, &body);
  if (err) return err;
  cursor c = {(const unsigned char *)data + body, (const unsigned char *)data + size, format, path};
  int have_v = 0, have_f = 0;
  for (int i = 0; i < nelems && !err; i++) {
    const elem *e = &elems[i];
    /* a count the remaining bytes cannot hold is a lie: fail before allocating */
    if (e->count > (uint64_t)(c.end - c.p) && e->nprops > 0)
      return fr_fail(FR_ERR_FORMAT, "%s: PLY says %llu %s records but only %zu bytes remain", path,
                     (unsigned long long)e->count, e->name, (size_t)(c.end - c.p));
    if (strcmp(e->name, "vertex") == 0 && !have_v) { have_v = 1; err = read_vertices(&c, e, m); }
    else if (strcmp(e->name, "face") == 0 && !have_f) { have_f = 1; err = read_faces(&c, e, m); }
    else err = skip_element(&c, e);
  }
  if (err) return err;
  if (!have_v || !have_f) return fr_fail(FR_ERR_FORMAT, "%s: PLY has no %s element", path, have_v ? "face" : "vertex");
  return FR_OK;
}
