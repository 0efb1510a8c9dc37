/* The procedural built-in scene: a floor with a 12 x 12 grid of spheres and
 * boxes (about 340K triangles, many of them axis-aligned), needing no file. */
#ifndef FR_GEOM_BUILTIN_SCENE_H
#define FR_GEOM_BUILTIN_SCENE_H
#include "geom/mesh.h"
fr_error fr_builtin_scene(fr_mesh *m);
#endif
