#include "atomic_file.h"
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>
#include "base/error.h"

void fr_atomic_tmp_path(const char *path, char *tmp, size_t cap) {
  const char *slash = strrchr(path, '/');
  int dirlen = slash ? (int)(slash - path + 1) : 0;
  snprintf(tmp, cap, "%.*s.%s.tmp.%ld", dirlen, path, slash ? slash + 1 : path, (long)getpid());
}

fr_error fr_atomic_commit(const char *tmp, const char *path) {
  if (rename(tmp, path) != 0) {
    int err = errno;
    remove(tmp);
    return fr_fail(FR_ERR_IO, "%s: %s", path, strerror(err));
  }
  return FR_OK;
}

fr_error fr_atomic_write(const char *path, const void *data, size_t size) {
  char tmp[4200];
  fr_atomic_tmp_path(path, tmp, sizeof tmp);
  FILE *f = fopen(tmp, "wb");
  if (!f) return fr_fail(FR_ERR_IO, "%s: %s", path, strerror(errno));
  size_t put = fwrite(data, 1, size, f);
  int bad = put != size || fflush(f) != 0;
  bad |= fclose(f) != 0;
  if (bad) { remove(tmp); return fr_fail(FR_ERR_IO, "%s: write failed", path); }
  return fr_atomic_commit(tmp, path);
}
