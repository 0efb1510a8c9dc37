/* The file system Assimp reads a scene through: the scene file itself (or
 * its inflated bytes, for a .zst) and what it names inside its folder
 * (io/scene_path.h), nothing else. */
#ifndef FR_IO_ASSIMP_FILES_H
#define FR_IO_ASSIMP_FILES_H
#include <assimp/cfileio.h>
#include <stddef.h>

typedef struct fr_assimp_fs {
  const char *scene;      /* the scene file's path: its folder bounds the rest */
  const char *name;       /* the name Assimp opens the scene by */
  const char *data;       /* its bytes, or NULL to read the file named scene */
  size_t size;
} fr_assimp_fs;

/* io's callbacks; fs must outlive every import that uses io. */
void fr_assimp_files(struct aiFileIO *io, const fr_assimp_fs *fs);
#endif
