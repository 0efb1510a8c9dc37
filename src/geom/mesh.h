/* A triangle mesh as imported: positions, triangles in file order, materials. */
#ifndef FR_GEOM_MESH_H
#define FR_GEOM_MESH_H
#include <stddef.h>
#include <stdint.h>
#include "frusta.h"

typedef struct fr_mesh {
  float *pos;        /* 3 floats per vertex */
  size_t nverts, cap_verts;
  uint32_t *idx;     /* 3 per triangle, file order */
  uint32_t *mat;     /* material per triangle, or NULL */
  size_t ntris, cap_tris;
  fr_material *mats;
  size_t nmats, cap_mats;
} fr_mesh;

void fr_mesh_init(fr_mesh *m);
void fr_mesh_free(fr_mesh *m);
fr_error fr_mesh_add_vertex(fr_mesh *m, float x, float y, float z);
fr_error fr_mesh_add_triangle(fr_mesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t mat);
/* Index of the material called name, created with defaults if new. */
fr_error fr_mesh_material(fr_mesh *m, const char *name, uint32_t *out);
void fr_material_default(fr_material *mat, const char *name);
/* Rejects out-of-range indices, non-finite vertices used by a triangle, and
 * meshes with no triangles, with a message naming the first problem. */
fr_error fr_mesh_validate(const fr_mesh *m, const char *what);
/* Twice-area test in double: zero-area triangles never enter the BVH. */
int fr_mesh_triangle_degenerate(const fr_mesh *m, size_t tri);
/* Whether float arithmetic resolves a triangle that is not degenerate: its
 * edge cross product, in float as the kernels form it, is neither zero (a
 * triangle of denormal size) nor infinite. */
int fr_mesh_triangle_resolvable(const fr_mesh *m, size_t tri);
/* Not degenerate and resolvable: triangles that fail never enter the BVH. */
int fr_mesh_triangle_traceable(const fr_mesh *m, size_t tri);
#endif
