/* The procedural built-in scene: a floor with a 12 x 12 grid of spheres and
 * boxes (about 340K triangles, many of them axis-aligned), needing no file. */
#ifndef FR_GEOM_BUILTIN_SCENE_H
#define FR_GEOM_BUILTIN_SCENE_H
#include "geom/mesh.h"
#include "geom/sphere.h"
fr_error fr_builtin_scene(fr_mesh *m);
/* A sphereflake of analytic spheres (builtin_sphereflake.c): a sphere of
 * radius 0.5 at the origin, nine children a third its size on each sphere
 * down to depth levels, above a floor quad at z = -0.5. */
fr_error fr_builtin_sphereflake(int depth, fr_mesh *m, fr_spheres *spheres);
/* The material showcase (builtin_materials.c): six unit spheres on a floor
 * at y = 0, one per path-tracing material. */
fr_error fr_builtin_materials(fr_mesh *m, fr_spheres *spheres);
#endif
