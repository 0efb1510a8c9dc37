#include "builtin_scene.h"
#include <math.h>

#define GRID 12
#define STACKS 32
#define SLICES 64
#define BOX_SUB 8

static fr_error quad(fr_mesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t d, uint32_t mat) {
  fr_error e = fr_mesh_add_triangle(m, a, b, c, mat);
  return e ? e : fr_mesh_add_triangle(m, a, c, d, mat);
}

/* UV sphere with single pole vertices, so the mesh is closed. */
static fr_error sphere(fr_mesh *m, float cx, float cy, float cz, float r, uint32_t mat) {
  uint32_t base = (uint32_t)m->nverts;
  fr_error e = fr_mesh_add_vertex(m, cx, cy + r, cz);
  for (int i = 1; i < STACKS && !e; i++) {
    float th = (float)M_PI * (float)i / STACKS;
    for (int j = 0; j < SLICES && !e; j++) {
      float ph = 2.0f * (float)M_PI * (float)j / SLICES;
      e = fr_mesh_add_vertex(m, cx + r * sinf(th) * cosf(ph), cy + r * cosf(th), cz + r * sinf(th) * sinf(ph));
    }
  }
  if (!e) e = fr_mesh_add_vertex(m, cx, cy - r, cz);
  uint32_t south = (uint32_t)m->nverts - 1;
#define RING(i, j) (base + 1 + (uint32_t)((i) - 1) * SLICES + (uint32_t)((j) % SLICES))
  for (int j = 0; j < SLICES && !e; j++) e = fr_mesh_add_triangle(m, base, RING(1, j + 1), RING(1, j), mat);
  for (int i = 1; i < STACKS - 1 && !e; i++)
    for (int j = 0; j < SLICES && !e; j++) e = quad(m, RING(i, j), RING(i, j + 1), RING(i + 1, j + 1), RING(i + 1, j), mat);
  for (int j = 0; j < SLICES && !e; j++) e = fr_mesh_add_triangle(m, south, RING(STACKS - 1, j), RING(STACKS - 1, j + 1), mat);
#undef RING
  return e;
}

/* Axis-aligned box, each face a BOX_SUB x BOX_SUB grid (faces do not share vertices). */
static fr_error box(fr_mesh *m, const float lo[3], const float hi[3], uint32_t mat) {
  fr_error e = FR_OK;
  for (int axis = 0; axis < 3 && !e; axis++) {
    for (int side = 0; side < 2 && !e; side++) {
      int u = (axis + 1) % 3, v = (axis + 2) % 3;
      uint32_t base = (uint32_t)m->nverts;
      for (int i = 0; i <= BOX_SUB && !e; i++)
        for (int j = 0; j <= BOX_SUB && !e; j++) {
          float p[3];
          p[axis] = side ? hi[axis] : lo[axis];
          p[u] = lo[u] + (hi[u] - lo[u]) * (float)i / BOX_SUB;
          p[v] = lo[v] + (hi[v] - lo[v]) * (float)j / BOX_SUB;
          e = fr_mesh_add_vertex(m, p[0], p[1], p[2]);
        }
      for (int i = 0; i < BOX_SUB && !e; i++)
        for (int j = 0; j < BOX_SUB && !e; j++) {
          uint32_t a = base + (uint32_t)(i * (BOX_SUB + 1) + j), b = a + BOX_SUB + 1;
          e = side ? quad(m, a, b, b + 1, a + 1, mat) : quad(m, a, a + 1, b + 1, b, mat);
        }
    }
  }
  return e;
}

fr_error fr_builtin_scene(fr_mesh *m) {
  static const struct { const char *name; float kd[3], ks[3]; } mats[] = {
      {"floor", {0.7f, 0.7f, 0.65f}, {0, 0, 0}},
      {"red", {0.8f, 0.2f, 0.15f}, {0, 0, 0}},
      {"blue", {0.2f, 0.35f, 0.8f}, {0, 0, 0}},
      {"mirror", {0.1f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f}},
  };
  uint32_t id[4];
  fr_error e = FR_OK;
  for (int i = 0; i < 4 && !e; i++) {
    e = fr_mesh_material(m, mats[i].name, &id[i]);
    for (int k = 0; k < 3 && !e; k++) { m->mats[id[i]].diffuse[k] = mats[i].kd[k]; m->mats[id[i]].specular[k] = mats[i].ks[k]; }
  }
  if (e) return e;
  /* floor: 20 x 20 at y = 0 */
  uint32_t f = (uint32_t)m->nverts;
  e = fr_mesh_add_vertex(m, -10, 0, -10);
  if (!e) e = fr_mesh_add_vertex(m, 10, 0, -10);
  if (!e) e = fr_mesh_add_vertex(m, 10, 0, 10);
  if (!e) e = fr_mesh_add_vertex(m, -10, 0, 10);
  if (!e) e = quad(m, f, f + 3, f + 2, f + 1, id[0]);
  for (int i = 0; i < GRID && !e; i++)
    for (int j = 0; j < GRID && !e; j++) {
      float x = -8.25f + 1.5f * (float)i, z = -8.25f + 1.5f * (float)j;
      if ((i + j) & 1) {
        float h = 0.3f + 0.05f * (float)((i * 7 + j * 3) % 10);
        float lo[3] = {x - 0.5f, 0.0f, z - 0.5f}, hi[3] = {x + 0.5f, h * 2.0f, z + 0.5f};
        e = box(m, lo, hi, id[2]);
      } else {
        float r = 0.45f + 0.02f * (float)((i * 5 + j) % 5);
        e = sphere(m, x, r, z, r, ((i + j) % 4 == 0) ? id[3] : id[1]);
      }
    }
  return e;
}
