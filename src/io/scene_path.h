/*
 * What a scene file may open besides itself: files it names (an OBJ's
 * mtllib, a glTF's buffers and images) resolve against the scene file's own
 * folder and may not leave it, so a hostile scene cannot make frusta read
 * /etc/passwd or a file two folders up. The same rule holds for every
 * reader, Assimp's included (import_assimp.c gives Assimp this file system).
 */
#ifndef FR_IO_SCENE_PATH_H
#define FR_IO_SCENE_PATH_H
#include <stddef.h>

/* The path of the file that scene names ref, in out: 1 if it exists inside
 * the scene's folder, 0 if it does not exist or would leave the folder (an
 * absolute name, a '..' component, a symlink whose target lies outside). */
int fr_scene_ref_path(const char *scene, const char *ref, char *out, size_t cap);
/* The same with the bound widened to the folder root, which the user
 * names (NULL: the scene's folder): ref may climb with '..' but the file
 * it names, symlinks followed, must lie under root. */
int fr_scene_ref_path_within(const char *scene, const char *ref, const char *root, char *out, size_t cap);
#endif
