/*
 * A sphereflake in the spirit of Eric Haines' SPD "balls": every sphere
 * carries nine spheres a third its radius, touching it, six around its
 * equator and three above, each oriented away from its parent. Depth 3 gives
 * 1 + 9 + 81 + 729 = 820 spheres, as SPD balls at size 3 has.
 */
#include <math.h>
#include "builtin_scene.h"
#include "base/vec3.h"

#define RATIO (1.0f / 3.0f)

static fr_error flake(fr_spheres *set, vec3 c, float r, vec3 axis, int depth, uint32_t mat) {
  float cc[3] = {c.x, c.y, c.z};
  fr_error e = fr_spheres_add(set, cc, r, mat);
  if (e || depth == 0) return e;
  vec3 u, v;
  v3_onb(axis, &u, &v);
  float rc = r * RATIO, dist = r + rc;
  for (int k = 0; k < 9 && !e; k++) {
    /* six on the equator every 60 degrees, three at 50 degrees up between them */
    float az = k < 6 ? (float)k * (float)M_PI / 3.0f : ((float)(k - 6) * 2.0f + 0.5f) * (float)M_PI / 3.0f;
    float el = k < 6 ? 0.0f : 50.0f * (float)M_PI / 180.0f;
    vec3 d = v3_add(v3_add(v3_scale(u, cosf(el) * cosf(az)), v3_scale(v, cosf(el) * sinf(az))), v3_scale(axis, sinf(el)));
    d = v3_norm(d);
    e = flake(set, v3_add(c, v3_scale(d, dist)), rc, d, depth - 1, mat);
  }
  return e;
}

fr_error fr_builtin_sphereflake(int depth, fr_mesh *m, fr_spheres *spheres) {
  uint32_t floor_mat, flake_mat;
  fr_error e = fr_mesh_material(m, "floor", &floor_mat);
  if (!e) e = fr_mesh_material(m, "flake", &flake_mat);
  if (e) return e;
  fr_material *fl = &m->mats[floor_mat], *fk = &m->mats[flake_mat];
  for (int a = 0; a < 3; a++) {
    fl->diffuse[a] = 0.6f;
    fk->diffuse[a] = a == 0 ? 0.35f : a == 1 ? 0.25f : 0.15f;
    fk->specular[a] = 0.6f;
  }
  fk->shininess = 50.0f;
  fk->illum = 3; /* a mirror for the Whitted renderer */
  const float F = 12.0f, Z = -0.5f;
  for (int i = 0; i < 4 && !e; i++) e = fr_mesh_add_vertex(m, (i & 1) ? F : -F, (i & 2) ? F : -F, Z);
  if (!e) e = fr_mesh_add_triangle(m, 0, 1, 3, floor_mat);
  if (!e) e = fr_mesh_add_triangle(m, 0, 3, 2, floor_mat);
  if (!e) e = flake(spheres, v3(0, 0, 0), 0.5f, v3(0, 0, 1), depth, flake_mat);
  return e;
}
