#include "views.h"
#include <string.h>

typedef struct named_view { const char *name; float v[22]; } named_view;

/* eye, at, up, fov, point light, area c, e1, e2: from ../shared/scenes/README.md */
static const named_view table[] = {
    {"bunny", {-0.18f, 0.20f, 0.28f, -0.0169f, 0.1101f, -0.0015f, 0, 1, 0, 40, 0.20f, 0.45f, 0.35f, -0.067f, 0.45f, -0.052f, 0.1f, 0, 0, 0, 0, 0.1f}},
    {"dragon", {-0.12f, 0.20f, 0.33f, -0.0059f, 0.125f, -0.0046f, 0, 1, 0, 40, 0.20f, 0.45f, 0.35f, -0.066f, 0.45f, -0.065f, 0.12f, 0, 0, 0, 0, 0.12f}},
    {"sibenik", {-18, -11, 0, 10, -8, 0, 0, 1, 0, 60, -5, 0, 0, -7, 3.5f, -1, 4, 0, 0, 0, 0, 2}},
    {"conference", {1400, 400, -700, -500, 150, 300, 0, 1, 0, 60, 300, 550, -200, 150, 640, -275, 300, 0, 0, 0, 0, 150}},
    {"kitchen", {3.75f, 2.30f, 3.60f, 3.4365f, 1.8802f, 2.7482f, -0.127f, 0.907f, -0.4005f, 40, 2.25f, 2.00f, 1.00f, 2.0f, 2.28f, 1.8f, 0.6f, 0, 0, 0, 0, 0.6f}},
    {"museum", {0, 1.6f, -6, 0, 1.6f, 0, 0, 1, 0, 45, -4, 4.5f, 0, -1, 4.95f, -1, 2, 0, 0, 0, 0, 2}},
    {"spd_balls", {2.1f, 1.3f, 1.7f, 0, 0, 0, 0, 0, 1, 45, 4, 3, 2, -0.5f, -0.5f, 3, 0, 1, 0, 1, 0, 0}},
    /* the analytic sphereflake (fr_scene_builtin_sphereflake) stands where spd_balls does */
    {"sphereflake", {2.1f, 1.3f, 1.7f, 0, 0, 0, 0, 0, 1, 45, 4, 3, 2, -0.5f, -0.5f, 3, 0, 1, 0, 1, 0, 0}},
    {"spd_gears", {-1.1f, -2.1f, 2.6f, 0, 0, 0, 0, 0, 1, 45, 2, 4, 4, -0.75f, -0.75f, 4, 0, 1.5f, 0, 1.5f, 0, 0}},
    {"spd_mount", {-1.6f, 1.6f, 1.7f, 0, 0, 0, 0, 0, 1, 45, -100, -100, 100, -0.5f, -0.5f, 3, 0, 1, 0, 1, 0, 0}},
    {"spd_rings", {-1, -2.61313f, 0.5f, -1, -1.61313f, 0.5f, 0, 0, 1, 45, 3, -2.61313f, 3, -2.5f, 4.5f, 9, 0, 3, 0, 3, 0, 0}},
    {"spd_teapot", {4.86f, 7.2f, 5.4f, 0, 0, 0, 0, 0, 1, 45, -3.1f, 9.8f, 12.1f, -1, -1, 7, 0, 2, 0, 2, 0, 0}},
    {"spd_tetra", {1.02285f, -3.17715f, -2.17451f, -0.004103f, -0.004103f, 0.216539f, -0.816497f, -0.816497f, 0.816497f, 45, 2, -18, -5, -1.8815f, -1.1744f, 2.1403f, 0.7071f, -0.7071f, 0, -0.4082f, -0.4082f, -0.8165f}},
    {"spd_tree", {4.5f, 0.4f, 2.0f, 0, 0, 1.5f, 0, 0, 1, 45, -5, 5, 50, -1, -1, 6, 0, 2, 0, 2, 0, 0}},
    {"hairball", {0, 0.3f, 2.4f, 0, 0, 0, 0, 1, 0, 45, 2, 3, 2, -0.5f, 1.5f, -0.5f, 1, 0, 0, 0, 0, 1}},
    /* built-in scene: looking over the grid; quad light above its centre facing down */
    /* the material showcase: the row of spheres from the front, a little above */
    {"materials", {0, 2.2f, 9.0f, 0, 0.9f, 0, 0, 1, 0, 50, 4, 10, 6, -2, 8, -2, 4, 0, 0, 0, 0, 4}},
    {"builtin", {11, 7, 13, 0, 0, 0, 0, 1, 0, 40, 6, 12, 4, -2, 10, -2, 4, 0, 0, 0, 0, 4}},
};

static vec3 at3(const float *p) { return v3(p[0], p[1], p[2]); }

int fr_view_lookup(const char *name, fr_view *v) {
  for (size_t i = 0; i < sizeof table / sizeof table[0]; i++) {
    if (strcmp(table[i].name, name) != 0) continue;
    const float *f = table[i].v;
    v->eye = at3(f); v->at = at3(f + 3); v->up = at3(f + 6); v->fov = f[9];
    v->light = at3(f + 10);
    v->area_c = at3(f + 13); v->area_e1 = at3(f + 16); v->area_e2 = at3(f + 19);
    return 1;
  }
  return 0;
}

fr_view fr_view_from_bounds(aabb b) {
  vec3 c = v3_scale(v3_add(b.lo, b.hi), 0.5f), d = v3_sub(b.hi, b.lo);
  float r = 0.5f * v3_len(d);
  fr_view v;
  v.at = c;
  v.eye = v3_add(c, v3(1.2f * r, 0.8f * r, 1.6f * r));
  v.up = v3(0, 1, 0);
  v.fov = 45.0f;
  v.light = v3_add(c, v3(0.5f * r, 2.0f * r, 0.8f * r));
  v.area_c = v3_add(c, v3(-0.2f * r, 1.5f * r, -0.2f * r));
  v.area_e1 = v3(0.4f * r, 0, 0);  /* e1 x e2 points down (-y) */
  v.area_e2 = v3(0, 0, 0.4f * r);
  return v;
}

void fr_view_surfaces(const char *name, const char **mirror, const char **glass) {
  if (!strcmp(name, "kitchen")) { *mirror = "shiny_metal,metal"; *glass = "glass,glass_dragon"; }
  else if (!strcmp(name, "museum")) { *mirror = "museum5_0"; *glass = "museum5_1"; }
}

int fr_names_contain(const char *list, const char *name) {
  const size_t n = strlen(name);
  for (const char *p = list; p && *p;) {
    const char *e = strchr(p, ',');
    const size_t len = e ? (size_t)(e - p) : strlen(p);
    if (len == n && !memcmp(p, name, n)) return 1;
    p = e ? e + 1 : NULL;
  }
  return 0;
}

fr_view fr_view_of(const char *name, aabb bounds) {
  fr_view v;
  if (!fr_view_lookup(name, &v)) v = fr_view_from_bounds(bounds);
  return v;
}
