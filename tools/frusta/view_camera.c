#include "view_camera.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "io/file_read.h"

#define MAX_PATH_VIEWS 1000000

int view_camera_equal(const view_camera *a, const view_camera *b) {
  return !memcmp(&a->eye, &b->eye, sizeof(vec3)) && !memcmp(&a->at, &b->at, sizeof(vec3)) &&
         !memcmp(&a->up, &b->up, sizeof(vec3)) && a->fov == b->fov;
}

/* v turned by angle about the unit axis k (Rodrigues). */
static vec3 rotate(vec3 v, vec3 k, float angle) {
  const float c = cosf(angle), s = sinf(angle);
  return v3_add(v3_add(v3_scale(v, c), v3_scale(v3_cross(k, v), s)), v3_scale(k, v3_dot(k, v) * (1.0f - c)));
}

void view_camera_orbit(view_camera *c, float yaw, float pitch) {
  const vec3 up = v3_norm(c->up);
  vec3 off = v3_sub(c->eye, c->at);
  off = rotate(off, up, yaw);
  const vec3 right = v3_norm(v3_cross(v3_scale(off, -1.0f), up));
  const float r = v3_len(off), elev = asinf(fmaxf(-1.0f, fminf(1.0f, v3_dot(off, up) / r)));
  const float lim = 1.55f; /* short of the pole, where right is undefined */
  const float p = fmaxf(-lim, fminf(lim, elev + pitch)) - elev;
  if (v3_finite(right) && v3_len(right) > 0.5f) off = rotate(off, right, -p);
  c->eye = v3_add(c->at, off);
}

static void basis(const view_camera *c, vec3 *fwd, vec3 *right, vec3 *up) {
  *fwd = v3_norm(v3_sub(c->at, c->eye));
  *right = v3_norm(v3_cross(*fwd, c->up));
  *up = v3_cross(*right, *fwd);
}

void view_camera_pan(view_camera *c, float right, float upward) {
  vec3 f, r, u;
  basis(c, &f, &r, &u);
  const float d = v3_len(v3_sub(c->at, c->eye));
  const vec3 m = v3_add(v3_scale(r, right * d), v3_scale(u, upward * d));
  c->eye = v3_add(c->eye, m);
  c->at = v3_add(c->at, m);
}

void view_camera_zoom(view_camera *c, float factor) {
  const vec3 off = v3_sub(c->eye, c->at);
  const float d = v3_len(off);
  if (d * factor < 1e-6f) return;
  c->eye = v3_add(c->at, v3_scale(off, factor));
}

void view_camera_fly(view_camera *c, float forward, float right, float rise) {
  vec3 f, r, u;
  basis(c, &f, &r, &u);
  const vec3 m = v3_add(v3_add(v3_scale(f, forward), v3_scale(r, right)), v3_scale(v3_norm(c->up), rise));
  c->eye = v3_add(c->eye, m);
  c->at = v3_add(c->at, m);
}

void view_camera_print(FILE *out, const view_camera *c) {
  fprintf(out, "--eye %g,%g,%g --at %g,%g,%g --up %g,%g,%g --fov %g\n", (double)c->eye.x, (double)c->eye.y,
          (double)c->eye.z, (double)c->at.x, (double)c->at.y, (double)c->at.z, (double)c->up.x, (double)c->up.y,
          (double)c->up.z, (double)c->fov);
}

void view_camera_path_write(FILE *out, const view_camera *c) {
  fprintf(out, "%.9g,%.9g,%.9g %.9g,%.9g,%.9g %.9g,%.9g,%.9g %.9g\n", (double)c->eye.x, (double)c->eye.y,
          (double)c->eye.z, (double)c->at.x, (double)c->at.y, (double)c->at.z, (double)c->up.x, (double)c->up.y,
          (double)c->up.z, (double)c->fov);
}

int view_camera_path_read(const char *path, view_camera **cams, size_t *n) {
  *cams = NULL;
  *n = 0;
  char *data;
  size_t size;
  if (fr_read_file_max(path, (size_t)64 << 20, &data, &size)) return cli_error(1, "%s", fr_last_error());
  if (memchr(data, 0, size)) { free(data); return cli_error(1, "%s: not a camera path (a binary file)", path); }
  size_t cap = 0, line = 0;
  int rc = 0;
  char *save = NULL;
  for (char *ln = data, *next; ln && !rc; ln = next) {
    next = strchr(ln, '\n');
    if (next) *next++ = 0;
    line++;
    char *p = ln + strspn(ln, " \t\r");
    if (!*p || *p == '#') continue;
    char *tok[5];
    int k = 0;
    for (char *t = strtok_r(p, " \t\r", &save); t && k < 5; t = strtok_r(NULL, " \t\r", &save)) tok[k++] = t;
    view_camera c;
    if (k != 4 || !cli_parse_vec3(tok[0], &c.eye) || !cli_parse_vec3(tok[1], &c.at) || !cli_parse_vec3(tok[2], &c.up) ||
        !cli_parse_float(tok[3], &c.fov) || !(c.fov > 0.0f && c.fov < 180.0f)) {
      rc = cli_error(1, "%s:%zu: a camera path line is 'ex,ey,ez ax,ay,az ux,uy,uz fov' with fov in (0, 180)", path, line);
      break;
    }
    if (*n == MAX_PATH_VIEWS) { rc = cli_error(1, "%s: more than %d views", path, MAX_PATH_VIEWS); break; }
    if (*n == cap) {
      cap = cap ? 2 * cap : 64;
      view_camera *grown = realloc(*cams, cap * sizeof **cams);
      if (!grown) { rc = cli_error(1, "out of memory for a camera path"); break; }
      *cams = grown;
    }
    (*cams)[(*n)++] = c;
  }
  free(data);
  if (!rc && *n == 0) rc = cli_error(1, "%s: no views in the camera path", path);
  if (rc) { free(*cams); *cams = NULL; *n = 0; }
  return rc;
}
