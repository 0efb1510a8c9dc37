/*
 * The material showcase: six spheres in a row on a large floor, one per
 * material (materials named lambert, plastic, chrome, gold, glass and
 * carpaint; the floor's "floor"). Their path-tracing parameters are
 * render/path_materials.c's; as MTL data they read as Lambert, plastic,
 * mirrors and glass for the other renderers.
 */
#include "builtin_scene.h"

fr_error fr_builtin_materials(fr_mesh *m, fr_spheres *spheres) {
  static const struct { const char *name; float kd[3], ks[3], tf; int illum; } mats[] = {
      {"lambert", {0.25f, 0.45f, 0.75f}, {0, 0, 0}, 0, 1},
      {"plastic", {0.75f, 0.12f, 0.08f}, {1, 1, 1}, 0, 2},
      {"chrome", {0, 0, 0}, {0.55f, 0.56f, 0.55f}, 0, 3},
      {"gold", {0, 0, 0}, {1.0f, 0.78f, 0.34f}, 0, 3},
      {"glass", {0, 0, 0}, {0, 0, 0}, 1, 4},
      {"carpaint", {0.6f, 0.04f, 0.03f}, {1, 1, 1}, 0, 2},
  };
  uint32_t floor_mat, id[6];
  fr_error e = fr_mesh_material(m, "floor", &floor_mat);
  for (int i = 0; i < 6 && !e; i++) {
    e = fr_mesh_material(m, mats[i].name, &id[i]);
    if (e) break;
    fr_material *mt = &m->mats[id[i]];
    for (int a = 0; a < 3; a++) {
      mt->diffuse[a] = mats[i].kd[a];
      mt->specular[a] = mats[i].ks[a];
      mt->transmission[a] = mats[i].tf;
    }
    mt->shininess = 100.0f;
    mt->ior = 1.5f;
    mt->illum = mats[i].illum;
  }
  if (e) return e;
  for (int a = 0; a < 3; a++) m->mats[floor_mat].diffuse[a] = 0.5f;
  const float F = 40.0f;
  for (int i = 0; i < 4 && !e; i++) e = fr_mesh_add_vertex(m, (i & 1) ? F : -F, 0.0f, (i & 2) ? F : -F);
  if (!e) e = fr_mesh_add_triangle(m, 0, 2, 3, floor_mat);
  if (!e) e = fr_mesh_add_triangle(m, 0, 3, 1, floor_mat);
  for (int i = 0; i < 6 && !e; i++) {
    const float c[3] = {-5.5f + 2.2f * (float)i, 1.0f, 0.0f};
    e = fr_spheres_add(spheres, c, 1.0f, id[i]);
  }
  return e;
}
