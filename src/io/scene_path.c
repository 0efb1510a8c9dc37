#include "scene_path.h"
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "io/file_read.h"

/* Whether ref is a relative name: not empty, not absolute, no drive. */
static int relative(const char *ref) { return ref[0] && ref[0] != '/' && ref[0] != '\\' && !strchr(ref, ':'); }

/* Whether ref names something below its folder: relative, no '..'. */
static int stays_below(const char *ref) {
  if (!relative(ref)) return 0;
  for (const char *p = ref; *p;) {
    size_t n = strcspn(p, "/\\");
    if (n == 2 && p[0] == '.' && p[1] == '.') return 0;
    p += n;
    if (*p) p++;
  }
  return 1;
}

/* The folder of scene, with its '/', in dir. */
static void folder_of(const char *scene, char *dir, size_t cap) {
  snprintf(dir, cap, "%s", scene);
  char *slash = strrchr(dir, '/');
  if (slash) slash[1] = 0;
  else snprintf(dir, cap, "./");
}

/* Whether file, symlinks followed, lies under folder, symlinks followed. */
static int lies_under(const char *file, const char *folder) {
  char real_dir[PATH_MAX], real[PATH_MAX];
  if (!realpath(folder, real_dir) || !realpath(file, real)) return 0;
  const size_t n = strlen(real_dir);
  return strncmp(real, real_dir, n) == 0 && (real_dir[n - 1] == '/' || real[n] == '/');
}

/* dir + ref in out, if it fits and exists. */
static int joined(const char *dir, const char *ref, char *out, size_t cap) {
  return (size_t)snprintf(out, cap, "%s%s", dir, ref) < cap && fr_file_exists(out);
}

int fr_scene_ref_path(const char *scene, const char *ref, char *out, size_t cap) {
  if (!stays_below(ref)) return 0;
  char dir[PATH_MAX];
  folder_of(scene, dir, sizeof dir);
  /* a symlink, the name's or a folder's on the way, may not lead out */
  return joined(dir, ref, out, cap) && lies_under(out, dir);
}

int fr_scene_ref_path_within(const char *scene, const char *ref, const char *root, char *out, size_t cap) {
  if (!root) return fr_scene_ref_path(scene, ref, out, cap);
  if (!relative(ref)) return 0;
  char dir[PATH_MAX];
  folder_of(scene, dir, sizeof dir);
  return joined(dir, ref, out, cap) && lies_under(out, root);
}
