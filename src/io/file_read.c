#include "file_read.h"
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zstd.h>
#include "base/error.h"

int fr_has_suffix(const char *s, const char *suffix) {
  size_t a = strlen(s), b = strlen(suffix);
  return a >= b && strcasecmp(s + a - b, suffix) == 0;
}

int fr_file_exists(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

fr_error fr_regular_file(const char *path, size_t *bytes) {
  struct stat st;
  if (stat(path, &st) != 0) return fr_fail(FR_ERR_IO, "%s: %s", path, strerror(errno));
  if (!S_ISREG(st.st_mode)) return fr_fail(FR_ERR_IO, "%s: not a regular file", path);
  if (bytes) *bytes = (size_t)st.st_size;
  return FR_OK;
}

static fr_error read_raw(const char *path, size_t max, char **data, size_t *size) {
  size_t n;
  fr_error e = fr_regular_file(path, &n);
  if (e) return e;
  if (n > max) return fr_fail(FR_ERR_UNSUPPORTED, "%s: larger than %zu bytes", path, max);
  FILE *f = fopen(path, "rb");
  if (!f) return fr_fail(FR_ERR_IO, "%s: %s", path, strerror(errno));
  char *buf = malloc(n + 1);
  if (!buf) { fclose(f); return fr_fail(FR_ERR_NOMEM, "%s: cannot allocate %zu bytes", path, n); }
  size_t got = fread(buf, 1, n, f);
  int err = ferror(f);
  fclose(f);
  if (err || got != n) { free(buf); return fr_fail(FR_ERR_IO, "%s: read error", path); }
  buf[n] = 0;
  *data = buf;
  *size = n;
  return FR_OK;
}

static fr_error inflate_zst(const char *path, const char *in, size_t n, size_t max, char **data, size_t *size) {
  /* what the compressed bytes may honestly hold */
  const size_t bound = n > (max - FR_INFLATE_SLACK) / FR_INFLATE_RATIO ? max : n * FR_INFLATE_RATIO + FR_INFLATE_SLACK;
  const size_t limit = bound < max ? bound : max;
  ZSTD_DCtx *dc = ZSTD_createDCtx();
  if (!dc) return fr_fail(FR_ERR_NOMEM, "%s: cannot create zstd context", path);
  /* the shared scenes use --long=27; allow windows up to 2^31 */
  ZSTD_DCtx_setParameter(dc, ZSTD_d_windowLogMax, 31);
  unsigned long long hint = ZSTD_getFrameContentSize(in, n);
  size_t cap = (hint != ZSTD_CONTENTSIZE_UNKNOWN && hint != ZSTD_CONTENTSIZE_ERROR && hint < limit)
                   ? (size_t)hint + 1 : (n < limit / 4 ? n * 4 + 1024 : limit + 1);
  char *out = malloc(cap);
  if (!out) { ZSTD_freeDCtx(dc); return fr_fail(FR_ERR_NOMEM, "%s: cannot allocate %zu bytes", path, cap); }
  ZSTD_inBuffer ib = {in, n, 0};
  size_t used = 0, ret = 1;
  while (ib.pos < ib.size || ret != 0) {
    if (used + 1 >= cap) {
      if (cap > limit) {
        free(out); ZSTD_freeDCtx(dc);
        return fr_fail(FR_ERR_UNSUPPORTED, "%s: inflates past %zu bytes (%zu compressed)", path, limit, n);
      }
      /* grow, but never past the limit (and one byte to see it passed) */
      size_t nc = cap <= limit / 2 ? cap * 2 : limit + 1;
      char *q = realloc(out, nc);
      if (!q) { free(out); ZSTD_freeDCtx(dc); return fr_fail(FR_ERR_NOMEM, "%s: cannot allocate %zu bytes", path, nc); }
      out = q;
      cap = nc;
    }
    ZSTD_outBuffer ob = {out, cap - 1, used};
    size_t before_in = ib.pos;
    ret = ZSTD_decompressStream(dc, &ob, &ib);
    if (ZSTD_isError(ret)) {
      free(out); ZSTD_freeDCtx(dc);
      return fr_fail(FR_ERR_FORMAT, "%s: zstd: %s", path, ZSTD_getErrorName(ret));
    }
    int progressed = ob.pos != used || ib.pos != before_in;
    used = ob.pos;
    if (ib.pos == ib.size && ret != 0 && !progressed && used + 1 < cap) {
      free(out); ZSTD_freeDCtx(dc);
      return fr_fail(FR_ERR_FORMAT, "%s: truncated zstd stream", path);
    }
  }
  ZSTD_freeDCtx(dc);
  out[used] = 0;
  *data = out;
  *size = used;
  return FR_OK;
}

fr_error fr_read_file_max(const char *path, size_t max, char **data, size_t *size) {
  if (!max || max > FR_MAX_FILE_BYTES) max = FR_MAX_FILE_BYTES;
  char *raw = NULL;
  size_t n = 0;
  fr_error e = read_raw(path, max, &raw, &n);
  if (e || !fr_has_suffix(path, ".zst")) { if (!e) { *data = raw; *size = n; } return e; }
  e = inflate_zst(path, raw, n, max, data, size);
  free(raw);
  return e;
}

fr_error fr_read_file(const char *path, char **data, size_t *size) { return fr_read_file_max(path, 0, data, size); }
