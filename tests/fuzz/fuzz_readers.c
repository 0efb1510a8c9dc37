/*
 * libFuzzer harness for every reader of untrusted bytes (FRUSTA_FUZZ=ON with
 * clang): the first byte picks the reader, the rest is the file.
 *   0 PLY, 1 OBJ, 2 MTL: from memory, as fr_import hands them over;
 *   3 ray file, 4 hit file, 5 occlusion file, 6 zstd-compressed ray file:
 *     through a file, as frusta trace reads them (first bytes 0..251, by
 *     their value modulo 7);
 *   248 and 249 an 8-bit texture image (PNG, JPEG, TGA, BMP) from memory;
 *   250 and 251 a scene file (JSON), its references resolved against /tmp
 *     and confined there;
 *   252 (and 254) a Radiance HDR, 253 (and 255) an OpenEXR environment map:
 *     through a file, as --env loads them, with the sampling distribution
 *     built over the image.
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
#include "io/image_read.h"
#include "io/scene_file.h"
#include "light/environment.h"

static void environment_through_file(int exr, const uint8_t *data, size_t size) {
  static char path[64];
  snprintf(path, sizeof path, "/tmp/frusta_fuzz_%d%s", (int)getpid(), exr ? ".exr" : ".hdr");
  FILE *f = fopen(path, "wb");
  if (!f) return;
  fwrite(data, 1, size, f);
  fclose(f);
  fr_env e;
  if (!fr_env_load(&e, path)) {
    vec3 d;
    float pdf;
    fr_env_orient(&e, v3(0, 1, 0), 10.0f, 1.0f);
    fr_env_sample(&e, 0.3f, 0.7f, &d, &pdf);
    fr_env_eval(&e, v3(0, 0, 1));
    fr_env_free(&e);
  }
  remove(path);
}

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
  if (data[0] >= 252) {
    environment_through_file(data[0] & 1, data + 1, size - 1);
    return 0;
  }
  if (data[0] >= 248 && data[0] < 250) {
    int w, h;
    float *rgb;
    if (!fr_image_decode_ldr("fuzz.png", data + 1, size - 1, &w, &h, &rgb)) free(rgb);
    return 0;
  }
  if (data[0] >= 250) {
    char *json = malloc(size);
    if (!json) return 0;
    memcpy(json, data + 1, size - 1);
    json[size - 1] = 0;
    fr_scene_file f;
    if (!fr_scene_file_parse("fuzz.json", json, "/tmp", NULL, &f)) fr_scene_file_free(&f);
    free(json);
    return 0;
  }
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
