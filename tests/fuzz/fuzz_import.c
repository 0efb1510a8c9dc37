/*
 * libFuzzer harness for the PLY and OBJ readers (FRUSTA_FUZZ=ON with clang):
 * the first byte picks the reader, the rest is the file. Without libFuzzer the
 * same entry point is driven by fuzz_replay.c over the kept corpus, as a test.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "geom/mesh.h"
#include "io/import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size < 1) return 0;
  char *buf = malloc(size); /* the readers want a NUL after the data */
  if (!buf) return 0;
  memcpy(buf, data + 1, size - 1);
  buf[size - 1] = 0;
  fr_mesh m;
  fr_mesh_init(&m);
  fr_error e = (data[0] & 1) ? fr_import_obj("fuzz.obj", buf, size - 1, &m) : fr_import_ply("fuzz.ply", buf, size - 1, &m);
  if (!e) fr_mesh_validate(&m, "fuzz");
  fr_mesh_free(&m);
  free(buf);
  return 0;
}
