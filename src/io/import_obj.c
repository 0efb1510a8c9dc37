/*
 * Wavefront OBJ + MTL reader. Faces are fan-triangulated in file order (so
 * triangle numbers match the PLY of the same scene); `usemtl` sets each
 * triangle's material, `mtllib` files are looked up beside the OBJ, also as
 * NAME.zst, and never outside its folder. Normals, texture coordinates,
 * groups and smoothing are ignored.
 */
#include <stdio.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"
#include "io/file_read.h"
#include "io/import.h"
#include "io/scene_path.h"

#define MAX_POLY 4096
#define MAX_LINE 65536

typedef struct lines { const char *p, *end; size_t lineno; } lines;

/* Next line (without its newline) into buf; 0 at end of data. */
static int next_line(lines *l, const char **s, size_t *len) {
  if (l->p >= l->end) return 0;
  const char *nl = memchr(l->p, '\n', (size_t)(l->end - l->p));
  const char *e = nl ? nl : l->end;
  *s = l->p;
  *len = (size_t)(e - l->p);
  l->p = nl ? nl + 1 : l->end;
  l->lineno++;
  return 1;
}

static const char *skip_ws(const char *p, const char *e) {
  while (p < e && (*p == ' ' || *p == '\t' || *p == '\r')) p++;
  return p;
}

static int parse_floats(const char *p, const char *e, float *out, int n) {
  for (int i = 0; i < n; i++) {
    p = skip_ws(p, e);
    if (p >= e) return i;
    char *q;
    out[i] = strtof(p, &q);
    if (q == p || q > e) return i;
    p = q;
  }
  return n;
}

/* Copies the first word after the keyword into name (NUL-terminated). */
static void parse_name(const char *p, const char *e, char *name, size_t cap) {
  p = skip_ws(p, e);
  const char *q = e;
  while (q > p && (q[-1] == ' ' || q[-1] == '\t' || q[-1] == '\r')) q--;
  size_t n = (size_t)(q - p);
  if (n >= cap) n = cap - 1;
  memcpy(name, p, n);
  name[n] = 0;
}

/* A 1-based OBJ index at *p (negative: counting back from the last of
 * count), 0-based into *out; advances *p. 0 if malformed or out of range. */
static int parse_index(const char **p, const char *e, long long count, long long *out) {
  char *q;
  errno = 0;
  long long v = strtoll(*p, &q, 10);
  if (q == *p || q > e || errno) return 0;
  *p = q;
  if (v < 0) v = count + v;
  else if (v > 0) v -= 1;
  else return 0;
  if (v < 0 || v >= count) return 0;
  *out = v;
  return 1;
}

static int keyword(const char *s, size_t len, const char *kw) {
  size_t k = strlen(kw);
  return len > k && memcmp(s, kw, k) == 0 && (s[k] == ' ' || s[k] == '\t');
}

/* An MTL is a few kilobytes of text: one larger than this is not one. */
#define MAX_MTL_BYTES ((size_t)64 << 20)

/* The MTL the OBJ names, beside it (as NAME or NAME.zst), never outside the
 * OBJ's folder (io/scene_path.h). */
static void load_mtllib(const char *objpath, const char *name, fr_mesh *m) {
  char ref[4096], path[8192];
  const char *cands[2] = {"", ".zst"};
  for (int i = 0; i < 2; i++) {
    snprintf(ref, sizeof ref, "%s%s", name, cands[i]);
    if (!fr_scene_ref_path(objpath, ref, path, sizeof path)) continue;
    char *data;
    size_t size;
    if (fr_read_file_max(path, MAX_MTL_BYTES, &data, &size) == FR_OK) {
      fr_import_mtl(path, data, size, m); /* a broken MTL leaves default materials */
      free(data);
    }
    return;
  }
  /* a missing MTL is not fatal: triangles keep their (default) named materials */
}

fr_error fr_import_obj(const char *path, const char *data, size_t size, fr_mesh *m) {
  lines l = {data, data + size, 0};
  const char *s;
  size_t len;
  uint32_t mat = FR_INVALID_ID;
  long long poly[MAX_POLY], pnrm[MAX_POLY], ptex[MAX_POLY];
  while (next_line(&l, &s, &len)) {
    if (len > MAX_LINE) return fr_fail(FR_ERR_FORMAT, "%s:%zu: line too long", path, l.lineno);
    const char *e = s + len;
    s = skip_ws(s, e);
    len = (size_t)(e - s);
    if (keyword(s, len, "v")) {
      float xyz[3];
      if (parse_floats(s + 1, e, xyz, 3) != 3) return fr_fail(FR_ERR_FORMAT, "%s:%zu: vertex needs three numbers", path, l.lineno);
      fr_error err = fr_mesh_add_vertex(m, xyz[0], xyz[1], xyz[2]);
      if (err) return err;
    } else if (keyword(s, len, "vt")) {
      float st[3] = {0, 0, 0};
      if (parse_floats(s + 2, e, st, 3) < 2) return fr_fail(FR_ERR_FORMAT, "%s:%zu: texture coordinate needs two numbers", path, l.lineno);
      fr_error err = fr_mesh_add_uv(m, st[0], st[1]);
      if (err) return err;
    } else if (keyword(s, len, "vn")) {
      float xyz[3];
      if (parse_floats(s + 2, e, xyz, 3) != 3) return fr_fail(FR_ERR_FORMAT, "%s:%zu: normal needs three numbers", path, l.lineno);
      fr_error err = fr_mesh_add_normal(m, xyz[0], xyz[1], xyz[2]);
      if (err) return err;
    } else if (keyword(s, len, "f")) {
      int n = 0, normals = 1, texcoords = 1;
      const char *p = s + 1;
      for (;;) {
        p = skip_ws(p, e);
        if (p >= e) break;
        if (n == MAX_POLY) return fr_fail(FR_ERR_FORMAT, "%s:%zu: face has more than %d vertices", path, l.lineno, MAX_POLY);
        long long v;
        if (!parse_index(&p, e, (long long)m->nverts, &v))
          return fr_fail(FR_ERR_FORMAT, "%s:%zu: bad face index (%zu vertices so far)", path, l.lineno, m->nverts);
        poly[n] = v;
        /* v/vt, v/vt/vn or v//vn: the texture coordinate's and the normal's
         * indices; a bad one only loses them */
        long long vt = -1, vn = -1;
        if (p < e && *p == '/') {
          p++;
          if (p < e && *p != '/' && !parse_index(&p, e, (long long)m->uv.n, &vt)) vt = -1;
          while (p < e && *p != '/' && *p != ' ' && *p != '\t' && *p != '\r') p++;
          if (p < e && *p == '/') {
            p++;
            if (!parse_index(&p, e, (long long)m->nrm.n, &vn)) vn = -1;
          }
        }
        while (p < e && *p != ' ' && *p != '\t' && *p != '\r') p++;
        ptex[n] = vt;
        texcoords &= vt >= 0;
        pnrm[n++] = vn;
        normals &= vn >= 0;
      }
      for (int j = 2; j < n; j++) {
        fr_error err = fr_mesh_add_triangle(m, (uint32_t)poly[0], (uint32_t)poly[j - 1], (uint32_t)poly[j], mat);
        if (!err && normals)
          err = fr_mesh_set_normals(m, m->ntris - 1, (uint32_t)pnrm[0], (uint32_t)pnrm[j - 1], (uint32_t)pnrm[j]);
        if (!err && texcoords)
          err = fr_mesh_set_uvs(m, m->ntris - 1, (uint32_t)ptex[0], (uint32_t)ptex[j - 1], (uint32_t)ptex[j]);
        if (err) return err;
      }
    } else if (keyword(s, len, "usemtl")) {
      char name[64];
      parse_name(s + 6, e, name, sizeof name);
      fr_error err = fr_mesh_material(m, name, &mat);
      if (err) return err;
    } else if (keyword(s, len, "mtllib")) {
      char name[1024];
      parse_name(s + 6, e, name, sizeof name);
      if (name[0]) load_mtllib(path, name, m);
    }
    /* g, o, s, l and comments: not needed */
  }
  return FR_OK;
}

fr_error fr_import_mtl(const char *path, const char *data, size_t size, fr_mesh *m) {
  lines l = {data, data + size, 0};
  const char *s;
  size_t len;
  fr_material *cur = NULL;
  while (next_line(&l, &s, &len)) {
    const char *e = s + len;
    s = skip_ws(s, e);
    len = (size_t)(e - s);
    if (keyword(s, len, "newmtl")) {
      char name[64];
      uint32_t id;
      parse_name(s + 6, e, name, sizeof name);
      fr_error err = fr_mesh_material(m, name, &id);
      if (err) return err;
      cur = &m->mats[id];
      continue;
    }
    if (!cur) continue;
    float f[3];
    int n;
    if (keyword(s, len, "Kd") && parse_floats(s + 2, e, f, 3) == 3) memcpy(cur->diffuse, f, sizeof f);
    else if (keyword(s, len, "Ks") && parse_floats(s + 2, e, f, 3) == 3) memcpy(cur->specular, f, sizeof f);
    else if (keyword(s, len, "Ke") && parse_floats(s + 2, e, f, 3) == 3) memcpy(cur->emission, f, sizeof f);
    else if (keyword(s, len, "Tf") && (n = parse_floats(s + 2, e, f, 3)) >= 1) {
      for (int i = 0; i < 3; i++) cur->transmission[i] = f[n == 3 ? i : 0];
    } else if (keyword(s, len, "Ns") && parse_floats(s + 2, e, f, 1) == 1) cur->shininess = f[0];
    else if (keyword(s, len, "Ni") && parse_floats(s + 2, e, f, 1) == 1) cur->ior = f[0];
    else if (keyword(s, len, "map_Kd")) {
      /* options (-s, -o, -bm ...) come first: the file is the last word */
      const char *w = e;
      while (w > s + 6 && (w[-1] == ' ' || w[-1] == '\t' || w[-1] == '\r')) w--;
      const char *b = w;
      while (b > s + 6 && b[-1] != ' ' && b[-1] != '\t') b--;
      char ref[512];
      if (w > b && (size_t)(w - b) < sizeof ref) {
        memcpy(ref, b, (size_t)(w - b));
        ref[w - b] = 0;
        if (!fr_scene_ref_path(path, ref, cur->map_kd, sizeof cur->map_kd)) cur->map_kd[0] = 0; /* missing or outside */
      }
    } else if (keyword(s, len, "illum") && parse_floats(s + 5, e, f, 1) == 1 && f[0] >= 0.0f && f[0] < 100.0f)
      cur->illum = (int)f[0];
    else if (keyword(s, len, "d") && parse_floats(s + 1, e, f, 1) == 1) {
      if (cur->transmission[0] == 0 && cur->transmission[1] == 0 && cur->transmission[2] == 0)
        cur->transmission[0] = cur->transmission[1] = cur->transmission[2] = 1.0f - f[0];
    }
  }
  return FR_OK;
}
