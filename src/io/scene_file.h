/*
 * Scene files (JSON): the meshes of a scene, the materials of the path
 * tracer by name, camera, lights, environment and render settings, so a
 * render needs no wall of flags. docs/scenefile.md is the format.
 *
 * Every file a scene file names (meshes, the environment map) resolves
 * against the scene file's folder and may not leave `root` (by default
 * that folder; io/scene_path.h's rule). Every error names the file, the
 * key and what was expected.
 */
#ifndef FR_IO_SCENE_FILE_H
#define FR_IO_SCENE_FILE_H
#include <limits.h>
#include "base/vec3.h"
#include "frusta.h"
#include "material/bsdf.h"

#define FR_SCENE_FILE_MAX_MESHES 256
#define FR_SCENE_FILE_MAX_MATERIALS 1024

typedef struct fr_scene_file_mesh {
  char path[PATH_MAX];  /* resolved */
  char material[64];    /* every triangle's material ("" keeps the file's) */
  vec3 scale, translate; /* p' = p * scale + translate */
} fr_scene_file_mesh;

typedef struct fr_scene_file_material {
  char name[64];
  fr_bsdf bsdf;
} fr_scene_file_material;

/* has_* say which optional settings the file gives. */
typedef struct fr_scene_file {
  fr_scene_file_mesh *meshes;
  int nmeshes;
  fr_scene_file_material *materials;
  int nmaterials;
  int has_eye, has_at, has_up, has_fov, has_aperture, has_focus;
  vec3 eye, at, up;
  float fov, aperture, focus;
  int has_env_file, has_env_color, has_env_intensity, has_env_rotate;
  char env_file[PATH_MAX];
  vec3 env_color;
  float env_intensity, env_rotate;
  int has_lights; /* a "lights" object: exactly its lights (and the environment) shine */
  int has_area, has_area_radiance, has_point, has_point_intensity;
  vec3 area[3], area_radiance, point, point_intensity;
  int has_shade, has_size, has_spp, has_max_depth, has_sampler, has_seed;
  char shade[32], sampler[32];
  int width, height, spp, max_depth, seed;
} fr_scene_file;

/* path's JSON into f; root: the folder named files must stay in (NULL:
 * the scene file's own). */
fr_error fr_scene_file_read(const char *path, const char *root, fr_scene_file *f);
/* The same from memory (data NUL-terminated); files resolve against dir. */
fr_error fr_scene_file_parse(const char *what, const char *data, const char *dir, const char *root, fr_scene_file *f);
void fr_scene_file_free(fr_scene_file *f);
/* The path tracer's material of that name in f, or NULL. */
const fr_bsdf *fr_scene_file_find_material(const fr_scene_file *f, const char *name);
#endif
