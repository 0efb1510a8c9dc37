/* Whole-file reads, with .zst files decompressed transparently. */
#ifndef FR_IO_FILE_READ_H
#define FR_IO_FILE_READ_H
#include <stddef.h>
#include "frusta.h"

#define FR_MAX_FILE_BYTES ((size_t)8 << 30) /* refuse to inflate past 8 GiB */

/* Reads path (decompressing it if it ends in .zst) into a malloc'd buffer with
 * a NUL byte after the data (not counted in *size). */
fr_error fr_read_file(const char *path, char **data, size_t *size);
int fr_has_suffix(const char *s, const char *suffix);
int fr_file_exists(const char *path);
#endif
