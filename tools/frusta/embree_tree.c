#include "embree_tree.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "embree_tracer.h"

/* The number after `key` in line, as %lf: 1 if found. */
static int number_after(const char *line, const char *key, double *v) {
  const char *p = strstr(line, key);
  return p && sscanf(p + strlen(key), " %lf", v) == 1;
}

/* "#nodes = N ( F% filled)" of a statistics line */
static int nodes_filled(const char *line, size_t *n, double *filled) {
  const char *p = strstr(line, "#nodes =");
  return p && sscanf(p, "#nodes = %zu ( %lf", n, filled) == 2;
}

/* The first word after `key` in line, into out. */
static int word_after(const char *line, const char *key, char *out, size_t size) {
  const char *p = strstr(line, key);
  if (!p) return 0;
  p += strlen(key);
  size_t n = strcspn(p, " \t\n");
  if (!n || n >= size) return 0;
  memcpy(out, p, n);
  out[n] = '\0';
  return 1;
}

/* Embree's log (kernels/bvh/bvh_statistics.cpp) for each tree it builds:
 *   building BVH8<triangle4> using avx::BVH8BuilderFastSpatialSAH ...
 *     primitives = 331179, vertices = 0, depth = 13
 *     total            : sah =  11.133 (100.00%), ...
 *     getAABBNodes     : sah =   6.564 ( 58.96%), ... #nodes =   18137 ( 70.61% filled), ...
 *     leaves           : sah =   4.569 ( 41.04%), ... #nodes =   84310 ( 87.09% filled), ...
 *       histogram      :  87.38%   9.37% ...
 * The first triangle tree's lines are read; others (spheres) are skipped. */
fr_error ebr_tree_parse(const char *log, ebr_tree *out) {
  memset(out, 0, sizeof *out);
  int in = 0, got = 0;
  double v, filled;
  for (const char *line = log; line && *line;) {
    const char *end = strchr(line, '\n');
    char buf[512];
    size_t n = end ? (size_t)(end - line) : strlen(line);
    if (n >= sizeof buf) n = sizeof buf - 1;
    memcpy(buf, line, n);
    buf[n] = '\0';
    line = end ? end + 1 : NULL;
    if (strstr(buf, "building ") && strstr(buf, " using ")) {
      if (in) break; /* the next tree */
      if (!strstr(buf, "triangle")) continue;
      in = word_after(buf, "building ", out->accel, sizeof out->accel) &&
           word_after(buf, " using ", out->builder, sizeof out->builder);
      continue;
    }
    if (!in) continue;
    if (strstr(buf, "primitives =") && number_after(buf, "depth =", &v)) out->depth = (int)v, got |= 1;
    else if (strstr(buf, " total ") && number_after(buf, "sah =", &v)) out->sah = v, got |= 2;
    else if (strstr(buf, "getAABBNodes ") && number_after(buf, "sah =", &v) && nodes_filled(buf, &out->inner, &filled))
      out->node_sah = v, out->node_fill = filled / 100.0, got |= 4;
    else if (strstr(buf, " leaves ") && number_after(buf, "sah =", &v) && nodes_filled(buf, &out->leaves, &filled))
      out->leaf_sah = v, out->block_fill = filled / 100.0, got |= 8;
    else if (strstr(buf, "histogram") && number_after(buf, ":", &v))
      out->one_block = v / 100.0, got |= 16;
  }
  if (got != 31) return FR_ERR_UNSUPPORTED;
  /* the fill shares as counts: BVH8<triangle4> is 8 wide, blocks of 4 */
  if (sscanf(out->accel, "BVH%d", &out->width) != 1 || out->width < 2) return FR_ERR_UNSUPPORTED;
  const char *lt = strchr(out->accel, '<');
  size_t k = lt ? strcspn(lt, "0123456789") : 0;
  out->block_size = lt && lt[k] ? atoi(lt + k) : 1;
  if (out->block_size < 1) out->block_size = 1;
  out->node_fill *= out->width;
  out->block_fill *= out->block_size;
  return FR_OK;
}

fr_error ebr_tree_stats(const fr_scene *s, int threads, ebr_tree *out) {
  memset(out, 0, sizeof *out);
  /* Embree writes its log to stdout: point fd 1 at a scratch file meanwhile */
  FILE *log = tmpfile();
  if (!log) return FR_ERR_IO;
  fflush(stdout);
  int saved = dup(STDOUT_FILENO);
  if (saved < 0 || dup2(fileno(log), STDOUT_FILENO) < 0) {
    if (saved >= 0) close(saved);
    fclose(log);
    return FR_ERR_IO;
  }
  ebr_scene *e = NULL;
  ebr_options o = {.threads = threads, .quality = 2, .verbose = 2};
  fr_error err = ebr_create(s, o, &e);
  ebr_release(e);
  fflush(stdout);
  dup2(saved, STDOUT_FILENO);
  close(saved);
  if (err != FR_OK) { fclose(log); return err; }
  long size = ftell(log);
  char *text = size > 0 ? malloc((size_t)size + 1) : NULL;
  if (!text) { fclose(log); return size > 0 ? FR_ERR_NOMEM : FR_ERR_UNSUPPORTED; }
  rewind(log);
  size_t got = fread(text, 1, (size_t)size, log);
  text[got] = '\0';
  fclose(log);
  err = ebr_tree_parse(text, out);
  free(text);
  return err;
}
