/* Whole-file reads, with .zst files decompressed transparently. */
#ifndef FR_IO_FILE_READ_H
#define FR_IO_FILE_READ_H
#include <stddef.h>
#include "frusta.h"

#define FR_MAX_FILE_BYTES ((size_t)8 << 30) /* no file, read or inflated, past 8 GiB */
/* A compressed file inflates to at most this many times its size, plus
 * FR_INFLATE_SLACK: memory follows what a file holds, not what it claims
 * (meshes compress 2-10x; a few kilobytes that inflate to gigabytes are a
 * bomb). */
#define FR_INFLATE_RATIO 64u
#define FR_INFLATE_SLACK ((size_t)64 << 20)

/* Reads path (decompressing it if it ends in .zst) into a malloc'd buffer with
 * a NUL byte after the data (not counted in *size). FR_ERR_UNSUPPORTED for
 * more than max bytes (read or inflated; 0: FR_MAX_FILE_BYTES), found before
 * the memory is taken. */
fr_error fr_read_file_max(const char *path, size_t max, char **data, size_t *size);
fr_error fr_read_file(const char *path, char **data, size_t *size);
int fr_has_suffix(const char *s, const char *suffix);
int fr_file_exists(const char *path);
/* FR_OK where path is a regular file (its size in *bytes, when not NULL),
 * else FR_ERR_IO saying why ("PATH: No such file or directory", "PATH: not
 * a regular file"). */
fr_error fr_regular_file(const char *path, size_t *bytes);
#endif
