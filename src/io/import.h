/* Scene import: file name in, validated mesh out. */
#ifndef FR_IO_IMPORT_H
#define FR_IO_IMPORT_H
#include <stddef.h>
#include "geom/mesh.h"

/* Chooses the reader by extension (after stripping .zst), then validates. */
fr_error fr_import(const char *path, fr_mesh *m);

/* The readers; data is NUL-terminated (data[size] == 0). */
fr_error fr_import_ply(const char *path, const char *data, size_t size, fr_mesh *m);
fr_error fr_import_obj(const char *path, const char *data, size_t size, fr_mesh *m);
fr_error fr_import_mtl(const char *path, const char *data, size_t size, fr_mesh *m);
fr_error fr_import_assimp(const char *path, const char *ext, fr_mesh *m);
#endif
