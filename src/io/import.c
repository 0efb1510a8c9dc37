#include "import.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"
#include "io/file_read.h"

/* The extension of path without a trailing .zst, lower case, e.g. "ply". */
static void extension(const char *path, char *ext, size_t cap) {
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s", path);
  size_t n = strlen(tmp);
  if (fr_has_suffix(tmp, ".zst")) tmp[n - 4] = 0;
  const char *slash = strrchr(tmp, '/');
  const char *dot = strrchr(slash ? slash : tmp, '.');
  snprintf(ext, cap, "%s", dot ? dot + 1 : "");
  for (char *p = ext; *p; p++) *p = (char)(*p >= 'A' && *p <= 'Z' ? *p + 32 : *p);
}

fr_error fr_import(const char *path, fr_mesh *m) {
  if (!path || !*path) return fr_fail(FR_ERR_ARG, "no scene file given");
  fr_error e = fr_regular_file(path, NULL);
  if (e) return e;
  char ext[32];
  extension(path, ext, sizeof ext);
  if (strcmp(ext, "ply") == 0 || strcmp(ext, "obj") == 0) {
    char *data;
    size_t size;
    e = fr_read_file(path, &data, &size);
    if (e) return e;
    e = ext[0] == 'p' ? fr_import_ply(path, data, size, m) : fr_import_obj(path, data, size, m);
    free(data);
    if (e == FR_ERR_UNSUPPORTED) {
      /* a construct frusta's strict readers do not read (a nonstandard PLY
       * header line, say): what Assimp reads of the file is still a scene.
       * Broken files (lying counts, truncation) are refused at once. */
      char why[512];
      snprintf(why, sizeof why, "%s", fr_last_error());
      fr_mesh_free(m);
      fr_mesh_init(m);
      if (fr_import_assimp(path, ext, m) == FR_OK) return fr_mesh_validate(m, path);
      fr_mesh_free(m);
      fr_mesh_init(m);
      return fr_fail(FR_ERR_FORMAT, "%s", why);
    }
  } else {
    e = fr_import_assimp(path, ext, m);
  }
  if (e) return e;
  return fr_mesh_validate(m, path);
}
