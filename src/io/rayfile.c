#include "rayfile.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"
#include "io/atomic_file.h"
#include "io/file_read.h"

/* Reads a file with an 8-byte magic, a uint64 count and count records of rec bytes. */
static fr_error read_counted(const char *path, const char *magic, size_t rec, char **data, size_t *count) {
  char *buf = NULL;
  size_t size;
  fr_error e = fr_read_file(path, &buf, &size);
  if (e) return e;
  if (size < 16 || memcmp(buf, magic, 8) != 0) {
    free(buf);
    return fr_fail(FR_ERR_FORMAT, "%s: not a %.8s file", path, magic);
  }
  uint64_t n;
  memcpy(&n, buf + 8, 8);
  if (n > (size - 16) / rec || n * rec != size - 16) {
    free(buf);
    return fr_fail(FR_ERR_FORMAT, "%s: header says %llu records but the file holds %zu bytes of records", path,
                   (unsigned long long)n, size - 16);
  }
  *data = buf;
  *count = (size_t)n;
  return FR_OK;
}

static fr_error write_counted(const char *path, const char *magic, const void *recs, size_t rec, size_t count) {
  size_t bytes = fr_mul_size(count, rec);
  if (bytes == SIZE_MAX || bytes > SIZE_MAX - 16) return fr_fail(FR_ERR_NOMEM, "%s: too many records", path);
  char *buf = malloc(bytes + 16);
  if (!buf) return fr_fail(FR_ERR_NOMEM, "%s: out of memory", path);
  memcpy(buf, magic, 8);
  uint64_t n = count;
  memcpy(buf + 8, &n, 8);
  if (bytes) memcpy(buf + 16, recs, bytes);
  fr_error e = fr_atomic_write(path, buf, bytes + 16);
  free(buf);
  return e;
}

fr_error fr_rays_read(const char *path, fr_ray **rays, size_t *count) {
  char *buf = NULL;
  fr_error e = read_counted(path, "RAYS0001", 32, &buf, count);
  if (e) return e;
  fr_ray *r = malloc(fr_mul_size(*count ? *count : 1, sizeof(fr_ray)));
  if (!r) { free(buf); return fr_fail(FR_ERR_NOMEM, "%s: out of memory", path); }
  for (size_t i = 0; i < *count; i++) {
    float f[8];
    memcpy(f, buf + 16 + 32 * i, 32);
    fr_ray *x = &r[i];
    x->org[0] = f[0]; x->org[1] = f[1]; x->org[2] = f[2];
    x->dir[0] = f[3]; x->dir[1] = f[4]; x->dir[2] = f[5];
    x->tnear = f[6]; x->tfar = f[7];
  }
  free(buf);
  *rays = r;
  return FR_OK;
}

fr_error fr_rays_write(const char *path, const fr_ray *rays, size_t count) {
  float *f = malloc(fr_mul_size(count ? count : 1, 32));
  if (!f) return fr_fail(FR_ERR_NOMEM, "%s: out of memory", path);
  for (size_t i = 0; i < count; i++) {
    const fr_ray *x = &rays[i];
    float *o = f + 8 * i;
    o[0] = x->org[0]; o[1] = x->org[1]; o[2] = x->org[2];
    o[3] = x->dir[0]; o[4] = x->dir[1]; o[5] = x->dir[2];
    o[6] = x->tnear; o[7] = x->tfar;
  }
  fr_error e = write_counted(path, "RAYS0001", f, 32, count);
  free(f);
  return e;
}

fr_error fr_hits_write(const char *path, const fr_hit *hits, size_t count) {
  fr_hit_record *r = malloc(fr_mul_size(count ? count : 1, sizeof *r));
  if (!r) return fr_fail(FR_ERR_NOMEM, "%s: out of memory", path);
  for (size_t i = 0; i < count; i++) {
    int miss = hits[i].prim == FR_INVALID_ID;
    r[i].t = miss ? INFINITY : hits[i].t;
    r[i].prim = hits[i].prim;
    r[i].u = miss ? 0.0f : hits[i].u;
    r[i].v = miss ? 0.0f : hits[i].v;
  }
  fr_error e = write_counted(path, "HITS0001", r, sizeof *r, count);
  free(r);
  return e;
}

fr_error fr_hits_read(const char *path, fr_hit_record **hits, size_t *count) {
  char *buf = NULL;
  fr_error e = read_counted(path, "HITS0001", 16, &buf, count);
  if (e) return e;
  fr_hit_record *r = malloc(fr_mul_size(*count ? *count : 1, sizeof *r));
  if (!r) { free(buf); return fr_fail(FR_ERR_NOMEM, "%s: out of memory", path); }
  if (*count) memcpy(r, buf + 16, *count * sizeof *r);
  free(buf);
  *hits = r;
  return FR_OK;
}

fr_error fr_occl_write(const char *path, const uint8_t *occ, size_t count) {
  return write_counted(path, "OCCL0001", occ, 1, count);
}

fr_error fr_occl_read(const char *path, uint8_t **occ, size_t *count) {
  char *buf = NULL;
  fr_error e = read_counted(path, "OCCL0001", 1, &buf, count);
  if (e) return e;
  memmove(buf, buf + 16, *count);
  *occ = (uint8_t *)buf;
  return FR_OK;
}

int fr_hits_agree(float t1, float t2) {
  int m1 = !(t1 < INFINITY), m2 = !(t2 < INFINITY);
  if (m1 || m2) return m1 && m2;
  return fabsf(t1 - t2) <= 1e-4f * fmaxf(1.0f, fabsf(t1));
}

int fr_occlusion_near_boundary(const fr_ray *ray, float t) {
  if (!(t < INFINITY)) return 0;
  float tol = 1e-4f * fmaxf(1.0f, fabsf(t));
  return fabsf(t - ray->tnear) <= tol || fabsf(t - ray->tfar) <= tol;
}
