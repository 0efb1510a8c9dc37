/* A triangle mesh as imported: positions, triangles in file order, materials. */
#ifndef FR_GEOM_MESH_H
#define FR_GEOM_MESH_H
#include <stddef.h>
#include <stdint.h>
#include "frusta.h"

/* Values attached to triangle corners by index, as OBJ attaches them:
 * shading normals, texture coordinates. */
typedef struct fr_corner_attr {
  float *val;      /* dim floats per value */
  size_t n, cap;
  uint32_t *idx;   /* 3 indices per triangle (FR_INVALID_ID: none), or NULL while no triangle has any */
} fr_corner_attr;

typedef struct fr_mesh {
  float *pos;        /* 3 floats per vertex */
  size_t nverts, cap_verts;
  uint32_t *idx;     /* 3 per triangle, file order */
  uint32_t *mat;     /* material per triangle, or NULL */
  size_t ntris, cap_tris;
  fr_material *mats;
  size_t nmats, cap_mats;
  fr_corner_attr nrm; /* shading normals (unit; 0, 0, 0: none) */
  fr_corner_attr uv;  /* texture coordinates */
  int borrowed;       /* pos and idx are the caller's (fr_scene_from_buffers): never grown or freed */
} fr_mesh;

void fr_mesh_init(fr_mesh *m);
void fr_mesh_free(fr_mesh *m);
fr_error fr_mesh_add_vertex(fr_mesh *m, float x, float y, float z);
fr_error fr_mesh_add_triangle(fr_mesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t mat);
/* A shading normal (normalized here; a zero or non-finite one is kept as
 * 0, 0, 0, which means none). */
fr_error fr_mesh_add_normal(fr_mesh *m, float x, float y, float z);
/* Triangle t's corner normals, indices into nrm. */
fr_error fr_mesh_set_normals(fr_mesh *m, size_t t, uint32_t a, uint32_t b, uint32_t c);
/* A texture coordinate, and triangle t's corners' (indices into uv). */
fr_error fr_mesh_add_uv(fr_mesh *m, float u, float v);
fr_error fr_mesh_set_uvs(fr_mesh *m, size_t t, uint32_t a, uint32_t b, uint32_t c);
/* Whether triangle t has texture coordinates at all three corners. */
int fr_mesh_has_uvs(const fr_mesh *m, size_t t);
/* Gives the triangles without normals angle-weighted vertex normals: a
 * corner averages the normals of the faces around its vertex that lie
 * within crease_deg of its own face's, each weighted by its angle there
 * (so that a sharp edge stays sharp and a cube stays faceted). */
fr_error fr_mesh_smooth_normals(fr_mesh *m, float crease_deg);
/* Whether triangle t has normals at all three corners. */
int fr_mesh_has_normals(const fr_mesh *m, size_t t);
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
