#include "cli.h"
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "render/whitted.h"
#include "render/workload.h"

int cli_error(int code, const char *fmt, ...) {
  char msg[1024];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  for (char *p = msg; *p; p++)
    if (*p == '\n') *p = ' ';
  fprintf(stderr, "frusta: %s\n", msg);
  return code;
}

int cli_parse_float(const char *s, float *out) {
  char *e;
  errno = 0;
  float v = strtof(s, &e);
  if (e == s || *e || errno || !isfinite(v)) return 0;
  *out = v;
  return 1;
}

int cli_parse_int(const char *s, int lo, int hi, int *out) {
  char *e;
  errno = 0;
  long v = strtol(s, &e, 10);
  if (e == s || *e || errno || v < lo || v > hi) return 0;
  *out = (int)v;
  return 1;
}

int cli_parse_vec3(const char *s, vec3 *out) {
  char buf[256];
  snprintf(buf, sizeof buf, "%s", s);
  float f[3];
  char *save = NULL, *tok = strtok_r(buf, ",", &save);
  for (int i = 0; i < 3; i++) {
    if (!tok || !cli_parse_float(tok, &f[i])) return 0;
    tok = strtok_r(NULL, ",", &save);
  }
  if (tok) return 0;
  *out = v3(f[0], f[1], f[2]);
  return 1;
}

int cli_parse_size(const char *s, int *w, int *h) {
  char buf[64];
  snprintf(buf, sizeof buf, "%s", s);
  char *x = strchr(buf, 'x');
  if (!x) return 0;
  *x = 0;
  return cli_parse_int(buf, 1, 32768, w) && cli_parse_int(x + 1, 1, 32768, h);
}

static int need_value(int argc, char **argv, int i) {
  if (i + 1 >= argc) { cli_error(CLI_USAGE_ERROR, "%s needs a value", argv[i]); return 0; }
  return 1;
}

int cli_view_flag(int argc, char **argv, int *i, cli_view *v) {
  const char *f = argv[*i];
  static const char *vecs[] = {"--eye", "--at", "--up", "--light"};
  for (int k = 0; k < 4; k++) {
    if (strcmp(f, vecs[k]) != 0) continue;
    if (!need_value(argc, argv, *i)) return -1;
    vec3 *dst = k == 0 ? &v->eye : k == 1 ? &v->at : k == 2 ? &v->up : &v->light;
    if (!cli_parse_vec3(argv[*i + 1], dst)) { cli_error(CLI_USAGE_ERROR, "%s wants x,y,z, got '%s'", f, argv[*i + 1]); return -1; }
    *(k == 0 ? &v->has_eye : k == 1 ? &v->has_at : k == 2 ? &v->has_up : &v->has_light) = 1;
    (*i)++;
    return 1;
  }
  if (strcmp(f, "--fov") == 0) {
    if (!need_value(argc, argv, *i)) return -1;
    if (!cli_parse_float(argv[*i + 1], &v->fov) || !(v->fov > 0 && v->fov < 180)) {
      cli_error(CLI_USAGE_ERROR, "--fov wants degrees in (0, 180), got '%s'", argv[*i + 1]);
      return -1;
    }
    v->has_fov = 1;
    (*i)++;
    return 1;
  }
  if (strcmp(f, "--area") == 0) {
    if (!need_value(argc, argv, *i)) return -1;
    char buf[512];
    snprintf(buf, sizeof buf, "%s", argv[*i + 1]);
    float a[9];
    int n = 0;
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
      if (n == 9 || !cli_parse_float(tok, &a[n])) { n = -1; break; }
      n++;
    }
    if (n != 9) { cli_error(CLI_USAGE_ERROR, "--area wants cx,cy,cz,e1x,e1y,e1z,e2x,e2y,e2z"); return -1; }
    for (int k = 0; k < 3; k++) v->area[k] = v3(a[3 * k], a[3 * k + 1], a[3 * k + 2]);
    v->has_area = 1;
    (*i)++;
    return 1;
  }
  if (strcmp(f, "--size") == 0) {
    if (!need_value(argc, argv, *i)) return -1;
    if (!cli_parse_size(argv[*i + 1], &v->width, &v->height)) {
      cli_error(CLI_USAGE_ERROR, "--size wants WxH with 1 <= W, H <= 32768, got '%s'", argv[*i + 1]);
      return -1;
    }
    (*i)++;
    return 1;
  }
  return 0;
}

fr_view cli_resolve_view(const fr_scene *s, const cli_view *v) {
  fr_view view;
  if (!fr_view_lookup(s->name, &view)) view = fr_view_from_bounds(s->bounds);
  if (v->has_eye) view.eye = v->eye;
  if (v->has_at) view.at = v->at;
  if (v->has_up) view.up = v->up;
  if (v->has_fov) view.fov = v->fov;
  if (v->has_light) view.light = v->light;
  if (v->has_area) { view.area_c = v->area[0]; view.area_e1 = v->area[1]; view.area_e2 = v->area[2]; }
  return view;
}

int cli_is_builtin(const char *arg) { return strcmp(arg, "--builtin") == 0 || strncmp(arg, "--builtin=", 10) == 0; }

int cli_load_scene(const char *arg, fr_scene **s) {
  fr_error e;
  if (strcmp(arg, "--builtin") == 0 || strcmp(arg, "--builtin=default") == 0) e = fr_scene_builtin(s);
  else if (strcmp(arg, "--builtin=sphereflake") == 0) e = fr_scene_builtin_sphereflake(3, s);
  else if (cli_is_builtin(arg)) return cli_error(CLI_USAGE_ERROR, "unknown built-in scene '%s' (default or sphereflake)", arg + 10);
  else e = fr_scene_load(arg, s);
  if (e) return cli_error(1, "%s", fr_last_error());
  e = fr_scene_commit(*s);
  if (e) { fr_scene_release(*s); *s = NULL; return cli_error(1, "%s", fr_last_error()); }
  return 0;
}

int cli_set_isa(const char *name) {
  for (int i = FR_ISA_SCALAR; i <= FR_ISA_AVX512; i++)
    if (strcmp(name, fr_isa_name((fr_isa)i)) == 0) {
      if (fr_set_isa((fr_isa)i) != FR_OK) return cli_error(1, "%s", fr_last_error());
      return 0;
    }
  return cli_error(CLI_USAGE_ERROR, "unknown ISA '%s' (avx512, avx2 or scalar)", name);
}

float cli_scene_eps(const fr_scene *s) { return 1e-4f * v3_len(v3_sub(s->bounds.hi, s->bounds.lo)); }
const char *cli_scene_name(const fr_scene *s) { return s->name; }

fr_lp_scene cli_lp_scene(const fr_scene *s) {
  fr_lp_scene g = {&s->bvh2, &s->sphere_bvh, fr_scene_sphere_base(s)};
  return g;
}

int cli_workload_setup(const char *scene, const cli_view *v, int threads, fr_scene **s, fr_workload *w) {
  int rc = cli_load_scene(scene, s);
  if (rc) return rc;
  w->view = cli_resolve_view(*s, v);
  if (fr_camera_setup(&w->cam, w->view.eye, w->view.at, w->view.up, w->view.fov, v->width, v->height)) {
    fr_scene_release(*s);
    *s = NULL;
    return cli_error(CLI_USAGE_ERROR, "%s", fr_last_error());
  }
  w->scene = *s;
  w->eps = cli_scene_eps(*s);
  w->threads = threads;
  return 0;
}

void cli_whitted_default(cli_whitted *o) {
  memset(o, 0, sizeof *o);
  o->depth = 4;
  o->lp.traversal = FR_LP_RANGED;
  o->lp.cull = FR_CULL_OFF; /* measured: the culls cost more than they save (docs/performance-log.md) */
  o->packet = 16;
}

int cli_whitted_flag(int argc, char **argv, int *i, cli_whitted *o) {
  const char *a = argv[*i];
  if (strcmp(a, "--mirror") && strcmp(a, "--glass") && strcmp(a, "--depth") && strcmp(a, "--traversal") &&
      strcmp(a, "--cull") && strcmp(a, "--packet"))
    return 0;
  if (*i + 1 >= argc) { cli_error(CLI_USAGE_ERROR, "%s needs a value", a); return -1; }
  const char *val = argv[++*i];
  int ok = 1;
  o->large_flags |= !strcmp(a, "--traversal") || !strcmp(a, "--cull") || !strcmp(a, "--packet");
  if (!strcmp(a, "--mirror")) o->mirror = val;
  else if (!strcmp(a, "--glass")) o->glass = val;
  else if (!strcmp(a, "--depth")) {
    if (!(ok = cli_parse_int(val, 1, FR_WHITTED_MAX_DEPTH, &o->depth)))
      cli_error(CLI_USAGE_ERROR, "--depth wants 1..%d, got '%s'", FR_WHITTED_MAX_DEPTH, val);
  } else if (!strcmp(a, "--traversal")) {
    if (!(ok = fr_lp_traversal_parse(val, &o->lp.traversal)))
      cli_error(CLI_USAGE_ERROR, "--traversal is masked, ranged or partition, not '%s'", val);
  } else if (!strcmp(a, "--cull")) {
    if (!(ok = fr_cull_parse(val, &o->lp.cull)))
      cli_error(CLI_USAGE_ERROR, "--cull is off, ia, planes or corners, not '%s'", val);
  } else {
    ok = cli_parse_int(val, 2, 32, &o->packet) && (o->packet & (o->packet - 1)) == 0;
    if (!ok) cli_error(CLI_USAGE_ERROR, "--packet is 2, 4, 8, 16 or 32, not '%s'", val);
  }
  return ok ? 1 : -1;
}

int cli_whitted_setup(const fr_scene *s, const cli_whitted *o, fr_whitted_mats *mats, fr_workload *w) {
  if (fr_whitted_mats_build(s, o->mirror, o->glass, mats)) return cli_error(CLI_USAGE_ERROR, "%s", fr_last_error());
  size_t nm, ng;
  fr_whitted_mats_census(s, mats, &nm, &ng);
  printf("whitted depth=%d mirror_prims=%zu glass_prims=%zu\n", o->depth, nm, ng);
  w->mats = mats;
  w->max_depth = o->depth;
  return 0;
}
