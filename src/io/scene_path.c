#include "scene_path.h"
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "io/file_read.h"

/* Whether ref names something below its folder: not absolute, no '..'. */
static int stays_below(const char *ref) {
  if (!ref[0] || ref[0] == '/' || ref[0] == '\\' || strchr(ref, ':')) return 0;
  for (const char *p = ref; *p;) {
    size_t n = strcspn(p, "/\\");
    if (n == 2 && p[0] == '.' && p[1] == '.') return 0;
    p += n;
    if (*p) p++;
  }
  return 1;
}

int fr_scene_ref_path(const char *scene, const char *ref, char *out, size_t cap) {
  if (!stays_below(ref)) return 0;
  char dir[PATH_MAX];
  snprintf(dir, sizeof dir, "%s", scene);
  char *slash = strrchr(dir, '/');
  if (slash) slash[1] = 0;
  else snprintf(dir, sizeof dir, "./");
  if ((size_t)snprintf(out, cap, "%s%s", dir, ref) >= cap || !fr_file_exists(out)) return 0;
  /* a symlink, the name's or a folder's on the way, may not lead out */
  char real_dir[PATH_MAX], real[PATH_MAX];
  if (!realpath(dir, real_dir) || !realpath(out, real)) return 0;
  const size_t n = strlen(real_dir);
  return strncmp(real, real_dir, n) == 0 && (real_dir[n - 1] == '/' || real[n] == '/');
}

int fr_scene_ref_path_within(const char *scene, const char *ref, const char *root, char *out, size_t cap) {
  if (!root) return fr_scene_ref_path(scene, ref, out, cap);
  if (!ref[0] || ref[0] == '/' || ref[0] == '\\' || strchr(ref, ':')) return 0;
  char dir[PATH_MAX];
  snprintf(dir, sizeof dir, "%s", scene);
  char *slash = strrchr(dir, '/');
  if (slash) slash[1] = 0;
  else snprintf(dir, sizeof dir, "./");
  if ((size_t)snprintf(out, cap, "%s%s", dir, ref) >= cap || !fr_file_exists(out)) return 0;
  char real_root[PATH_MAX], real[PATH_MAX];
  if (!realpath(root, real_root) || !realpath(out, real)) return 0;
  const size_t n = strlen(real_root);
  return strncmp(real, real_root, n) == 0 && (real_root[n - 1] == '/' || real[n] == '/');
}
