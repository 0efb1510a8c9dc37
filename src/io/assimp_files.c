#include "assimp_files.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "io/scene_path.h"

static FILE *file_of(struct aiFile *f) { return (FILE *)f->UserData; }

static size_t file_read(struct aiFile *f, char *buf, size_t size, size_t count) {
  return size && count ? fread(buf, size, count, file_of(f)) : 0;
}
static size_t file_write(struct aiFile *f, const char *buf, size_t size, size_t count) { return 0; }
static size_t file_tell(struct aiFile *f) {
  long p = ftell(file_of(f));
  return p < 0 ? 0 : (size_t)p;
}
static size_t file_size(struct aiFile *f) {
  FILE *fp = file_of(f);
  long here = ftell(fp);
  if (here < 0 || fseek(fp, 0, SEEK_END)) return 0;
  long end = ftell(fp);
  fseek(fp, here, SEEK_SET);
  return end < 0 ? 0 : (size_t)end;
}
static enum aiReturn file_seek(struct aiFile *f, size_t off, enum aiOrigin origin) {
  int whence = origin == aiOrigin_SET ? SEEK_SET : origin == aiOrigin_CUR ? SEEK_CUR : SEEK_END;
  return fseek(file_of(f), (long)off, whence) ? aiReturn_FAILURE : aiReturn_SUCCESS;
}
static void file_flush(struct aiFile *f) {}

/* The scene file by its own name; anything else only as a name inside the
 * scene's folder, relative to it (Assimp prefixes the folder). */
static struct aiFile *file_open(struct aiFileIO *io, const char *name, const char *mode) {
  const char *scene = io->UserData;
  if (!name || strchr(mode, 'w') || strchr(mode, 'a') || strchr(mode, '+')) return NULL;
  char path[4096];
  if (strcmp(name, scene) == 0) {
    snprintf(path, sizeof path, "%s", scene);
  } else {
    const char *slash = strrchr(scene, '/');
    const size_t dir = slash ? (size_t)(slash - scene) + 1 : 0;
    const char *ref = dir && strncmp(name, scene, dir) == 0 ? name + dir : name;
    if (!fr_scene_ref_path(scene, ref, path, sizeof path)) return NULL;
  }
  FILE *fp = fopen(path, "rb");
  if (!fp) return NULL;
  struct aiFile *f = calloc(1, sizeof *f);
  if (!f) { fclose(fp); return NULL; }
  *f = (struct aiFile){file_read, file_write, file_tell, file_size, file_seek, file_flush, (aiUserData)fp};
  return f;
}

static void file_close(struct aiFileIO *io, struct aiFile *f) {
  if (!f) return;
  fclose(file_of(f));
  free(f);
}

void fr_assimp_files(struct aiFileIO *io, const char *scene) {
  io->OpenProc = file_open;
  io->CloseProc = file_close;
  io->UserData = (aiUserData)scene;
}
