/*
 * Assimp's own test models (Debian's assimp-testmodels, some 450 files in
 * about 40 formats, many broken on purpose), each loaded and committed: no
 * crash, no hang, no runaway memory, whichever reader handles it, and every
 * error one line. A file frusta refuses must be one from which Assimp reads
 * no traceable triangle either (or a non-finite vertex, which frusta refuses
 * by design) (asked in a child process, so that Assimp's own
 * crashes do not end the test).
 */
#define _XOPEN_SOURCE 700
#include <ftw.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include "base/timer.h"
#include "test_util.h"

#define CORPUS "/usr/share/assimp/models"

typedef struct tally { int files, loaded, refused, refused_readable; double slowest; char slowest_name[512]; } tally;
static tally T;

/* 1 for a triangle frusta traces, 0 for a degenerate one (zero area in
 * double), -1 for one with a vertex that is not finite, which frusta
 * refuses by design. */
static int triangle_kind(struct aiVector3D a, struct aiVector3D b, struct aiVector3D c) {
  const double p[3][3] = {{a.x, a.y, a.z}, {b.x, b.y, b.z}, {c.x, c.y, c.z}};
  for (int i = 0; i < 3; i++)
    for (int k = 0; k < 3; k++)
      if (!isfinite(p[i][k])) return -1;
  const double e1[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
  const double e2[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  return n[0] != 0 || n[1] != 0 || n[2] != 0;
}

/* Whether Assimp, alone, reads from path triangles frusta would trace, and
 * none it refuses by design: 1 yes, 0 no (or it crashed, which the child's
 * death tells). */
static int assimp_reads_triangles(const char *path) {
  pid_t pid = fork();
  if (pid == 0) {
    alarm(60);
    const struct aiScene *sc = aiImportFile(path, aiProcess_Triangulate | aiProcess_SortByPType);
    int good = 0, bad = 0;
    for (unsigned i = 0; sc && i < sc->mNumMeshes; i++) {
      const struct aiMesh *am = sc->mMeshes[i];
      for (unsigned f = 0; am && f < am->mNumFaces; f++) {
        const struct aiFace *fc = &am->mFaces[f];
        if (fc->mNumIndices != 3) continue;
        const int k = triangle_kind(am->mVertices[fc->mIndices[0]], am->mVertices[fc->mIndices[1]],
                                    am->mVertices[fc->mIndices[2]]);
        good |= k > 0;
        bad |= k < 0;
      }
    }
    _exit(good && !bad ? 0 : 1);
  }
  int st = 0;
  if (pid < 0 || waitpid(pid, &st, 0) < 0) return 0;
  return WIFEXITED(st) && WEXITSTATUS(st) == 0;
}

/* Formats: what Assimp claims, and frusta's own; not textures and buffers. */
static int is_model(const char *path) {
  const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
  if (!dot || (slash && dot < slash)) return 0;
  static const char *skip[] = {".png", ".jpg", ".jpeg", ".bmp", ".tga", ".dds", ".bin", ".mtl", ".txt", ".md", ".tif", ".gif"};
  for (size_t i = 0; i < sizeof skip / sizeof skip[0]; i++)
    if (!strcasecmp(dot, skip[i])) return 0;
  return aiIsExtensionSupported(dot) == AI_TRUE;
}

static int visit(const char *path, const struct stat *st, int type, struct FTW *ftw) {
  (void)st; (void)ftw;
  if (type != FTW_F || !is_model(path)) return 0;
  T.files++;
  const double t0 = fr_seconds();
  fr_scene *s = NULL;
  fr_error e = fr_scene_load(path, &s);
  if (!e) e = fr_scene_commit(s);
  const double dt = fr_seconds() - t0;
  if (dt > T.slowest) { T.slowest = dt; snprintf(T.slowest_name, sizeof T.slowest_name, "%s", path); }
  if (!e) {
    T.loaded++;
  } else {
    T.refused++;
    const char *msg = fr_last_error();
    if (!msg[0] || strchr(msg, '\n')) fail_msg("%s: not a one-line error: '%s'", path, msg);
    if (assimp_reads_triangles(path)) {
      T.refused_readable++;
      print_message("refused, though Assimp reads triangles: %s: %s\n", path, msg);
    }
  }
  fr_scene_release(s);
  return 0;
}

static void corpus(void **state) {
  (void)state;
  if (access(CORPUS, R_OK)) fail_msg("%s is missing: scripts/setup.sh installs assimp-testmodels", CORPUS);
  memset(&T, 0, sizeof T);
  assert_int_equal(nftw(CORPUS, visit, 16, FTW_PHYS), 0);
  print_message("assimp corpus: %d model files, %d loaded, %d refused (%d of them read as triangles by Assimp); "
                "slowest %.2f s (%s)\n",
                T.files, T.loaded, T.refused, T.refused_readable, T.slowest, T.slowest_name);
  assert_true(T.files > 400);
  assert_int_equal(T.refused_readable, 0);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(corpus)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
