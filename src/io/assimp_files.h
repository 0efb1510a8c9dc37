/* The file system Assimp reads a scene through: the scene file itself and
 * what it names inside its folder (io/scene_path.h), nothing else. */
#ifndef FR_IO_ASSIMP_FILES_H
#define FR_IO_ASSIMP_FILES_H
#include <assimp/cfileio.h>

/* io's callbacks read through stdio; scene must outlive every import that
 * uses io. */
void fr_assimp_files(struct aiFileIO *io, const char *scene);
#endif
