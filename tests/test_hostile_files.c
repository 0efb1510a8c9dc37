/*
 * Scene files as an attacker writes them. A scene may open only files inside
 * its own folder (io/scene_path.h), whichever reader handles it: an OBJ's
 * mtllib and a glTF's buffer that name an absolute path, a path two folders
 * up, or a symlink out are never read. Memory follows a file's real size,
 * not its claims: a small .zst that inflates to hundreds of megabytes and
 * an OFF header claiming 10^11 vertices end in a one-line error, quickly.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>
#include <zstd.h>
#include "base/timer.h"
#include "io/file_read.h"
#include "test_util.h"

static char root[256]; /* root/scene holds the scenes, root/outside what they must not reach */

static void put(const char *rel, const void *data, size_t n) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", root, rel);
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(data, 1, n, f), n);
  fclose(f);
}

static void puts_file(const char *rel, const char *text) { put(rel, text, strlen(text)); }

static const char *at(const char *rel) {
  static char path[512];
  snprintf(path, sizeof path, "%s/%s", root, rel);
  return path;
}

/* The diffuse colour the OBJ's one material got: (1, 0, 0) only if the
 * named MTL was read. */
static int read_red_mtl(const char *obj_rel) {
  fr_scene *s;
  if (fr_scene_load(at(obj_rel), &s) != FR_OK) fail_msg("%s: %s", obj_rel, fr_last_error());
  int red = 0;
  for (size_t i = 0; i < fr_scene_material_count(s); i++) {
    const fr_material *m = fr_scene_material(s, i);
    red |= !strcmp(m->name, "red") && m->diffuse[0] == 1.0f && m->diffuse[1] == 0.0f;
  }
  fr_scene_release(s);
  return red;
}

static const char red_mtl[] = "newmtl red\nKd 1 0 0\n";
static const char tri_obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";

static void mtllib_stays_inside(void **state) {
  (void)state;
  puts_file("outside/secret.mtl", red_mtl);
  puts_file("scene/own.mtl", red_mtl);
  char obj[1024];
  /* beside the OBJ: read */
  snprintf(obj, sizeof obj, "mtllib own.mtl\n%s", tri_obj);
  puts_file("scene/a.obj", obj);
  assert_true(read_red_mtl("scene/a.obj"));
  /* two folders up, by absolute path, through a symlink: never read */
  snprintf(obj, sizeof obj, "mtllib ../outside/secret.mtl\n%s", tri_obj);
  puts_file("scene/b.obj", obj);
  assert_false(read_red_mtl("scene/b.obj"));
  snprintf(obj, sizeof obj, "mtllib %s\n%s", at("outside/secret.mtl"), tri_obj);
  puts_file("scene/c.obj", obj);
  assert_false(read_red_mtl("scene/c.obj"));
  char target[512];
  snprintf(target, sizeof target, "%s", at("outside/secret.mtl"));
  assert_int_equal(symlink(target, at("scene/link.mtl")), 0);
  snprintf(obj, sizeof obj, "mtllib link.mtl\n%s", tri_obj);
  puts_file("scene/d.obj", obj);
  assert_false(read_red_mtl("scene/d.obj"));
  /* /etc/passwd: not read (and no error: a missing MTL is not fatal) */
  snprintf(obj, sizeof obj, "mtllib /etc/passwd\n%s", tri_obj);
  puts_file("scene/e.obj", obj);
  assert_false(read_red_mtl("scene/e.obj"));
}

/* A glTF whose one triangle lives in a buffer file named by uri. */
static void gltf_with_buffer(const char *rel, const char *uri) {
  char json[2048];
  snprintf(json, sizeof json,
           "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
           "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
           "\"buffers\":[{\"uri\":\"%s\",\"byteLength\":36}],"
           "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":36}],"
           "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\","
           "\"min\":[0,0,0],\"max\":[1,1,0]}]}",
           uri);
  puts_file(rel, json);
}

static void gltf_buffers_stay_inside(void **state) {
  (void)state;
  const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  put("scene/tri.bin", tri, sizeof tri);
  put("outside/tri.bin", tri, sizeof tri);
  fr_scene *s;
  gltf_with_buffer("scene/inside.gltf", "tri.bin");
  if (fr_scene_load(at("scene/inside.gltf"), &s) != FR_OK) fail_msg("inside.gltf: %s", fr_last_error());
  assert_int_equal(fr_scene_triangle_count(s), 1);
  fr_scene_release(s);
  gltf_with_buffer("scene/up.gltf", "../outside/tri.bin");
  assert_int_not_equal(fr_scene_load(at("scene/up.gltf"), &s), FR_OK);
  assert_null(strchr(fr_last_error(), '\n'));
  gltf_with_buffer("scene/abs.gltf", at("outside/tri.bin"));
  assert_int_not_equal(fr_scene_load(at("scene/abs.gltf"), &s), FR_OK);
  gltf_with_buffer("scene/passwd.gltf", "/etc/passwd");
  assert_int_not_equal(fr_scene_load(at("scene/passwd.gltf"), &s), FR_OK);
}

/* The resident set's peak, in bytes. */
static size_t peak_rss(void) {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return (size_t)ru.ru_maxrss * 1024;
}

static void zstd_bomb(void **state) {
  (void)state;
  /* 512 MiB of zeros compress to a few kilobytes */
  ZSTD_CStream *cs = ZSTD_createCStream();
  ZSTD_initCStream(cs, 19);
  static char zeros[1 << 20], out[1 << 16];
  FILE *f = fopen(at("scene/bomb.ply.zst"), "wb");
  assert_non_null(f);
  for (int i = 0; i < 512; i++) {
    ZSTD_inBuffer in = {zeros, sizeof zeros, 0};
    while (in.pos < in.size) {
      ZSTD_outBuffer o = {out, sizeof out, 0};
      ZSTD_compressStream(cs, &o, &in);
      fwrite(out, 1, o.pos, f);
    }
  }
  size_t left;
  do {
    ZSTD_outBuffer o = {out, sizeof out, 0};
    left = ZSTD_endStream(cs, &o);
    fwrite(out, 1, o.pos, f);
  } while (left);
  fclose(f);
  ZSTD_freeCStream(cs);
  const size_t before = peak_rss();
  const double t0 = fr_seconds();
  char *data;
  size_t size;
  assert_int_equal(fr_read_file(at("scene/bomb.ply.zst"), &data, &size), FR_ERR_UNSUPPORTED);
  const double secs = fr_seconds() - t0;
  const size_t grew = peak_rss() - before;
  print_message("zstd bomb: refused in %.2f s, peak memory +%zu MiB: %s\n", secs, grew >> 20, fr_last_error());
  assert_true(grew < ((size_t)160 << 20)); /* the limit, 64 MiB and 64x the file, and its buffer's growth */
  fr_scene *s;
  assert_int_equal(fr_scene_load(at("scene/bomb.ply.zst"), &s), FR_ERR_UNSUPPORTED);
}

static void off_claims(void **state) {
  (void)state;
  /* Assimp reads OFF: a header claiming 10^11 vertices */
  puts_file("scene/claims.off", "OFF\n353535235358 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const double t0 = fr_seconds();
  fr_scene *s;
  assert_int_not_equal(fr_scene_load(at("scene/claims.off"), &s), FR_OK);
  print_message("OFF claiming 3.5e11 vertices: refused in %.2f s: %s\n", fr_seconds() - t0, fr_last_error());
  /* (without the child's memory limit, which the sanitizers' shadow memory
   * rules out, Assimp takes longer to fail there) */
  assert_true(fr_seconds() - t0 < (FR_TEST_SANITIZED ? 240.0 : 30.0));
  assert_null(strchr(fr_last_error(), '\n'));
}

/* Geometry float arithmetic cannot resolve is refused or left out, never
 * traced wrongly: a scene at 1e30 is refused at commit; one at 2e10 is
 * traced (rays at a triangle hit it, in every mode); a triangle of denormal
 * size is left out and counted. */
static void unresolvable_geometry(void **state) {
  (void)state;
  for (int far = 0; far < 2; far++) {
    const float k = far ? 1e30f : 1e10f;
    const float xyz[9] = {-k, -k, 2 * k, k, -k, 2 * k, 0, k, 2 * k};
    const uint32_t idx[3] = {0, 1, 2};
    fr_scene *s;
    assert_int_equal(fr_scene_from_arrays(xyz, 3, idx, 1, &s), FR_OK);
    fr_error e = fr_scene_commit(s);
    if (far) {
      assert_int_equal(e, FR_ERR_UNSUPPORTED);
      assert_non_null(strstr(fr_last_error(), "coordinates"));
    } else {
      assert_int_equal(e, FR_OK);
      static const fr_trace_mode modes[] = {FR_TRACE_SINGLE, FR_TRACE_PACKET16, FR_TRACE_HYBRID16, FR_TRACE_AUTO,
                                            FR_TRACE_RAYSTREAM};
      fr_ray r[16];
      for (int i = 0; i < 16; i++) r[i] = (fr_ray){{0.01f * k * (float)(i % 4), -0.01f * k * (float)(i / 4), 0}, 0, {0, 0, 1}, INFINITY};
      for (int m = 0; m < 5; m++) {
        fr_hit h[16];
        assert_int_equal(fr_scene_set_trace_mode(s, modes[m]), FR_OK);
        fr_intersect_stream(s, r, h, 16);
        for (int i = 0; i < 16; i++) {
          if (h[i].prim != 0) fail_msg("mode %d ray %d misses a triangle at %g", m, i, (double)k);
          assert_true(fabsf(h[i].t - 2 * k) <= 1e-4f * 2 * k);
        }
      }
    }
    fr_scene_release(s);
  }
  const float xyz[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1e-39f, 1e-39f, 0, 1e-39f, 0, 1e-39f, 1e-39f};
  const uint32_t idx[6] = {0, 1, 2, 3, 4, 5};
  fr_scene *s;
  assert_int_equal(fr_scene_from_arrays(xyz, 6, idx, 2, &s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  assert_int_equal(fr_scene_skipped_triangles(s), 1);
  fr_scene_release(s);
}

static int setup(void **state) {
  (void)state;
  snprintf(root, sizeof root, "/tmp/frusta_test_hostile_%d", (int)getpid());
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf %s && mkdir -p %s/scene %s/outside", root, root, root);
  return system(cmd);
}

static int teardown(void **state) {
  (void)state;
  char cmd[300];
  snprintf(cmd, sizeof cmd, "rm -rf %s", root);
  return system(cmd);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(mtllib_stays_inside),
      cmocka_unit_test(gltf_buffers_stay_inside),
      cmocka_unit_test(zstd_bomb),
      cmocka_unit_test(off_claims),
      cmocka_unit_test(unresolvable_geometry),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
