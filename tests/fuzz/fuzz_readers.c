/*
 * libFuzzer harness for every reader of untrusted bytes (FRUSTA_FUZZ=ON with
 * clang): the first byte picks the reader, the rest is the file.
 *   0 PLY, 1 OBJ, 2 MTL: from memory, as fr_import hands them over;
 *   3 ray file, 4 hit file, 5 occlusion file, 6 zstd-compressed ray file:
 *     through a file, as frusta trace reads them.
 * Without libFuzzer the same entry point is driven by fuzz_replay.c over the
 * kept corpus, as a test.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "geom/mesh.h"
#include "io/import.h"
#include "io/rayfile.h"

static void read_through_file(int kind, const uint8_t *data, size_t size) {
  static char path[64];
  static const char *const ext[] = {".rays", ".hits", ".occl", ".rays.zst"};
  snprintf(path, sizeof path, "/tmp/frusta_fuzz_%d%s", (int)getpid(), ext[kind]);
  FILE *f = fopen(path, "wb");
  if (!f) return;
  fwrite(data, 1, size, f);
  fclose(f);
  void *out = NULL;
  size_t n = 0;
  if (kind == 0 || kind == 3) fr_rays_read(path, (fr_ray **)&out, &n);
  else if (kind == 1) fr_hits_read(path, (fr_hit_record **)&out, &n);
  else fr_occl_read(path, (uint8_t **)&out, &n);
  free(out);
  remove(path);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1) return 0;
  const int kind = data[0] % 7;
  if (kind >= 3) {
    read_through_file(kind - 3, data + 1, size - 1);
    return 0;
  }
  char *buf = malloc(size); /* the readers want a NUL after the data */
  if (!buf) return 0;
  memcpy(buf, data + 1, size - 1);
  buf[size - 1] = 0;
  fr_mesh m;
  fr_mesh_init(&m);
  fr_error e = kind == 0 ? fr_import_ply("fuzz.ply", buf, size - 1, &m)
               : kind == 1 ? fr_import_obj("fuzz.obj", buf, size - 1, &m)
                           : fr_import_mtl("fuzz.mtl", buf, size - 1, &m);
  if (!e && kind < 2) fr_mesh_validate(&m, "fuzz");
  fr_mesh_free(&m);
  free(buf);
  return 0;
}
