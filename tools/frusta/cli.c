#include "cli.h"
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "api/scene.h"
#include "cli_scene_file.h"
#include "cluster/cluster.h"
#include "io/file_read.h"
#include "render/whitted.h"
#include "render/workload.h"

static char last_msg[1024];
static int quiet;

int cli_error(int code, const char *fmt, ...) {
  char msg[sizeof last_msg];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  for (char *p = msg; *p; p++)
    if (*p == '\n') *p = ' ';
  memcpy(last_msg, msg, sizeof msg);
  if (!quiet) fprintf(stderr, "frusta: %s\n", msg);
  fr_cluster_told(code); /* rank 0 has said why: a stop by the launcher adds nothing */
  return code;
}

const char *cli_last_error(void) { return last_msg; }
void cli_set_quiet(int q) { quiet = q; }

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

int cli_view_from_args(const cli_args *a, cli_view *v) {
  memset(v, 0, sizeof *v);
  v->width = v->height = 1024;
  v->smooth = 30.0f;
  int rc = cli_arg_float(a, F_SMOOTH, 0.0f, 180.0f, &v->smooth);
  if (rc) return rc;
  static const cli_flag_id vecs[] = {F_EYE, F_AT, F_UP, F_LIGHT};
  vec3 *dst[] = {&v->eye, &v->at, &v->up, &v->light};
  int *has[] = {&v->has_eye, &v->has_at, &v->has_up, &v->has_light};
  for (int k = 0; k < 4; k++) {
    const char *s = a->val[vecs[k]];
    if (!s) continue;
    if (!cli_parse_vec3(s, dst[k])) return cli_error(CLI_USAGE_ERROR, "%s wants x,y,z, got '%s'", cli_flags[vecs[k]].name, s);
    *has[k] = 1;
  }
  if (a->val[F_FOV]) {
    if (!cli_parse_float(a->val[F_FOV], &v->fov) || !(v->fov > 0 && v->fov < 180))
      return cli_error(CLI_USAGE_ERROR, "--fov wants degrees in (0, 180), got '%s'", a->val[F_FOV]);
    v->has_fov = 1;
  }
  if (a->val[F_AREA]) {
    char buf[512];
    snprintf(buf, sizeof buf, "%s", a->val[F_AREA]);
    float f[9];
    int n = 0;
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
      if (n == 9 || !cli_parse_float(tok, &f[n])) { n = -1; break; }
      n++;
    }
    if (n != 9) return cli_error(CLI_USAGE_ERROR, "--area wants cx,cy,cz,e1x,e1y,e1z,e2x,e2y,e2z");
    for (int k = 0; k < 3; k++) v->area[k] = v3(f[3 * k], f[3 * k + 1], f[3 * k + 2]);
    v->has_area = 1;
  }
  if (a->val[F_SIZE] && !cli_parse_size(a->val[F_SIZE], &v->width, &v->height))
    return cli_error(CLI_USAGE_ERROR, "--size wants WxH with 1 <= W, H <= 32768, got '%s'", a->val[F_SIZE]);
  return 0;
}

int cli_common_from_args(const cli_args *a, int *threads) {
  int rc = cli_arg_int(a, F_THREADS, 1, 1024, threads);
  if (!rc && a->val[F_ISA]) rc = cli_set_isa(a->val[F_ISA]);
  return rc;
}

fr_view cli_resolve_view(const fr_scene *s, const cli_view *v) {
  fr_view view = fr_view_of(s->name, s->bounds);
  if (v->has_eye) view.eye = v->eye;
  if (v->has_at) view.at = v->at;
  if (v->has_up) view.up = v->up;
  if (v->has_fov) view.fov = v->fov;
  if (v->has_light) view.light = v->light;
  if (v->has_area) { view.area_c = v->area[0]; view.area_e1 = v->area[1]; view.area_e2 = v->area[2]; }
  return view;
}

int cli_is_builtin(const char *arg) { return strcmp(arg, "--builtin") == 0 || strncmp(arg, "--builtin=", 10) == 0; }

int cli_load_scene(const char *arg, fr_scene **s) { return cli_load_scene_smooth(arg, 0.0f, s); }

int cli_load_scene_smooth(const char *arg, float smooth, fr_scene **s) {
  fr_error e;
  if (strcmp(arg, "--builtin") == 0 || strcmp(arg, "--builtin=default") == 0) e = fr_scene_builtin(s);
  else if (strcmp(arg, "--builtin=sphereflake") == 0) e = fr_scene_builtin_sphereflake(3, s);
  else if (strcmp(arg, "--builtin=materials") == 0) e = fr_scene_builtin_materials(s);
  else if (cli_is_builtin(arg))
    return cli_error(CLI_USAGE_ERROR, "unknown built-in scene '%s' (default, sphereflake or materials)", arg + 10);
  else if (fr_has_suffix(arg, ".json")) e = fr_scene_load_json(arg, cli_scene_root(), s);
  else e = fr_scene_load(arg, s);
  if (e) return cli_error(1, "%s", fr_last_error());
  if (smooth > 0.0f) e = fr_scene_smooth(*s, smooth);
  if (!e) e = fr_scene_commit(*s);
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
  int rc = cli_load_scene_smooth(scene, v->smooth, s);
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
  o->lp.cull = FR_CULL_OFF; /* the culls cost more than they save on the Whitted scenes */
  o->packet = 16;
}

int cli_whitted_from_args(const cli_args *a, cli_whitted *o) {
  cli_whitted_default(o);
  o->mirror = a->val[F_MIRROR];
  o->glass = a->val[F_GLASS];
  o->large_flags = a->val[F_TRAVERSAL] || a->val[F_CULL] || a->val[F_PACKET];
  int rc = cli_arg_int(a, F_DEPTH, 1, FR_WHITTED_MAX_DEPTH, &o->depth);
  if (!rc && a->val[F_TRAVERSAL] && !fr_lp_traversal_parse(a->val[F_TRAVERSAL], &o->lp.traversal))
    rc = cli_error(CLI_USAGE_ERROR, "--traversal is masked, ranged or partition, not '%s'", a->val[F_TRAVERSAL]);
  if (!rc && a->val[F_CULL] && !fr_cull_parse(a->val[F_CULL], &o->lp.cull))
    rc = cli_error(CLI_USAGE_ERROR, "--cull is off, ia, planes or corners, not '%s'", a->val[F_CULL]);
  if (!rc && a->val[F_PACKET] &&
      !(cli_parse_int(a->val[F_PACKET], 2, 32, &o->packet) && (o->packet & (o->packet - 1)) == 0))
    rc = cli_error(CLI_USAGE_ERROR, "--packet is 2, 4, 8, 16 or 32, not '%s'", a->val[F_PACKET]);
  return rc;
}

void cli_whitted_print(const fr_scene *s, const fr_whitted_mats *m, int depth) {
  size_t nm, ng;
  fr_whitted_mats_census(s, m, &nm, &ng);
  printf("whitted depth=%d mirror_prims=%zu glass_prims=%zu\n", depth, nm, ng);
}

void cli_desc_view(const fr_view *v, fr_render_desc *d) {
  v3_store(d->camera.eye, v->eye), v3_store(d->camera.at, v->at), v3_store(d->camera.up, v->up);
  d->camera.fov_deg = v->fov;
  d->has_light = 1, v3_store(d->light, v->light);
  d->has_area = 1;
  v3_store(d->area_corner, v->area_c), v3_store(d->area_e1, v->area_e1), v3_store(d->area_e2, v->area_e2);
}

int cli_whitted_setup(const fr_scene *s, const cli_whitted *o, fr_whitted_mats *mats, fr_workload *w) {
  if (fr_whitted_mats_build(s, o->mirror, o->glass, mats)) return cli_error(CLI_USAGE_ERROR, "%s", fr_last_error());
  cli_whitted_print(s, mats, o->depth);
  w->mats = mats;
  w->max_depth = o->depth;
  return 0;
}
