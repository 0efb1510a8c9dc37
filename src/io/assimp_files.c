#include "assimp_files.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "io/scene_path.h"

static FILE *file_of(struct aiFile *f) { return (FILE *)f->UserData; }

/* The scene's own bytes, already in memory. */
typedef struct mem_file { const char *data; size_t size, pos; } mem_file;
static mem_file *mem_of(struct aiFile *f) { return (mem_file *)f->UserData; }

static size_t mem_read(struct aiFile *f, char *buf, size_t size, size_t count) {
  mem_file *m = mem_of(f);
  if (!size) return 0;
  size_t n = (m->size - m->pos) / size;
  if (n > count) n = count;
  memcpy(buf, m->data + m->pos, n * size);
  m->pos += n * size;
  return n;
}
static size_t mem_tell(struct aiFile *f) { return mem_of(f)->pos; }
static size_t mem_size(struct aiFile *f) { return mem_of(f)->size; }
static enum aiReturn mem_seek(struct aiFile *f, size_t off, enum aiOrigin origin) {
  mem_file *m = mem_of(f);
  const size_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? m->pos : m->size;
  if (off > m->size - base) return aiReturn_FAILURE;
  m->pos = base + off;
  return aiReturn_SUCCESS;
}

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
  const fr_assimp_fs *fs = (const fr_assimp_fs *)io->UserData;
  const char *scene = fs->scene;
  if (!name || strchr(mode, 'w') || strchr(mode, 'a') || strchr(mode, '+')) return NULL;
  if (fs->data && strcmp(name, fs->name) == 0) {
    struct aiFile *f = calloc(1, sizeof *f);
    mem_file *m = calloc(1, sizeof *m);
    if (!f || !m) { free(f); free(m); return NULL; }
    *m = (mem_file){fs->data, fs->size, 0};
    *f = (struct aiFile){mem_read, file_write, mem_tell, mem_size, mem_seek, file_flush, (aiUserData)m};
    return f;
  }
  char path[4096];
  if (!fs->data && strcmp(name, scene) == 0) {
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
  if (f->ReadProc == mem_read) free(mem_of(f));
  else fclose(file_of(f));
  free(f);
}

void fr_assimp_files(struct aiFileIO *io, const fr_assimp_fs *fs) {
  io->OpenProc = file_open;
  io->CloseProc = file_close;
  io->UserData = (aiUserData)fs;
}
