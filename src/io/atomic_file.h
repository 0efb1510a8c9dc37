/* Outputs appear whole or not at all: write to a temporary file beside the
 * target, then rename it into place. */
#ifndef FR_IO_ATOMIC_FILE_H
#define FR_IO_ATOMIC_FILE_H
#include <stddef.h>
#include "frusta.h"

/* tmp gets "<dir>/.<name>.tmp.<pid>" for target path. */
void fr_atomic_tmp_path(const char *path, char *tmp, size_t cap);
/* Renames tmp to path, or removes tmp and fails. */
fr_error fr_atomic_commit(const char *tmp, const char *path);
/* Writes a whole buffer atomically. */
fr_error fr_atomic_write(const char *path, const void *data, size_t size);
#endif
