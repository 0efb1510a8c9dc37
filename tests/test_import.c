/* Importers: the formats they must read, and the broken or hostile files they
 * must refuse with a one-line message instead of crashing. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zstd.h>
#include "test_util.h"
#include "io/image_write.h"
#include "material/texture.h"
#include "render/path.h"

static char tmpdir[256];

static const char *write_file(const char *name, const void *data, size_t n) {
  static char path[512];
  snprintf(path, sizeof path, "%s/%s", tmpdir, name);
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fwrite(data, 1, n, f), n);
  fclose(f);
  return path;
}

static fr_error load(const char *name, const void *data, size_t n, fr_scene **s) {
  return fr_scene_load(write_file(name, data, n), s);
}

static void expect_error(const char *name, const void *data, size_t n, fr_error want) {
  fr_scene *s = (fr_scene *)1;
  fr_error e = load(name, data, n, &s);
  if (e != want) print_message("%s: got %d (%s), wanted %d\n", name, e, fr_last_error(), want);
  assert_int_equal(e, want);
  assert_null(s);
  const char *msg = fr_last_error();
  assert_true(strlen(msg) > 5);
  assert_null(strchr(msg, '\n'));
}

static const char ply_ascii[] =
    "ply\nformat ascii 1.0\ncomment test\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n4 0 1 2 3\n3 0 1 4\n";

static void test_ply_ascii_fan(void **st) {
  (void)st;
  fr_scene *s;
  assert_int_equal(load("a.ply", ply_ascii, strlen(ply_ascii), &s), FR_OK);
  assert_int_equal(fr_scene_triangle_count(s), 3);
  const uint32_t *ix = fr_scene_indices(s);
  uint32_t want[9] = {0, 1, 2, 0, 2, 3, 0, 1, 4}; /* fan order of rayfile.md */
  assert_memory_equal(ix, want, sizeof want);
  fr_scene_release(s);
}

static size_t binary_ply(unsigned char *buf, int big_endian, uint32_t nv_claim, uint32_t nf_claim, int bad_index, float nan_vertex) {
  size_t n = (size_t)sprintf((char *)buf,
                             "ply\nformat %s 1.0\nelement vertex %u\nproperty float x\nproperty float y\nproperty float z\n"
                             "element face %u\nproperty list uchar int vertex_indices\nend_header\n",
                             big_endian ? "binary_big_endian" : "binary_little_endian", nv_claim, nf_claim);
  float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  v[4] = nan_vertex;
  for (int i = 0; i < 9; i++) {
    unsigned char b[4];
    memcpy(b, &v[i], 4);
    for (int k = 0; k < 4; k++) buf[n++] = b[big_endian ? 3 - k : k];
  }
  buf[n++] = 3;
  int32_t idx[3] = {0, 1, bad_index ? bad_index : 2};
  for (int i = 0; i < 3; i++) {
    unsigned char b[4];
    memcpy(b, &idx[i], 4);
    for (int k = 0; k < 4; k++) buf[n++] = b[big_endian ? 3 - k : k];
  }
  return n;
}

static void test_ply_binary(void **st) {
  (void)st;
  unsigned char buf[1024];
  for (int be = 0; be < 2; be++) {
    size_t n = binary_ply(buf, be, 3, 1, 0, 0.0f);
    fr_scene *s;
    assert_int_equal(load(be ? "be.ply" : "le.ply", buf, n, &s), FR_OK);
    assert_int_equal(fr_scene_triangle_count(s), 1);
    assert_true(fr_scene_vertices(s)[3] == 1.0f);
    fr_scene_release(s);
  }
}

static void test_ply_hostile(void **st) {
  (void)st;
  unsigned char buf[1024];
  size_t n = binary_ply(buf, 0, 3, 1, 0, 0.0f);
  expect_error("trunc.ply", buf, n - 5, FR_ERR_FORMAT);               /* truncated */
  n = binary_ply(buf, 0, 4000000000u, 1, 0, 0.0f);
  expect_error("liar.ply", buf, n, FR_ERR_FORMAT);                   /* lying vertex count */
  n = binary_ply(buf, 0, 3, 1, 7, 0.0f);
  expect_error("range.ply", buf, n, FR_ERR_FORMAT);                  /* index out of range */
  n = binary_ply(buf, 0, 3, 1, -2, 0.0f);
  expect_error("neg.ply", buf, n, FR_ERR_FORMAT);                    /* negative index */
  n = binary_ply(buf, 0, 3, 1, 0, NAN);
  expect_error("nan.ply", buf, n, FR_ERR_FORMAT);                    /* NaN vertex */
  n = binary_ply(buf, 0, 3, 1, 0, INFINITY);
  expect_error("inf.ply", buf, n, FR_ERR_FORMAT);                    /* Inf vertex */
  n = binary_ply(buf, 0, 3, 0, 0, 0.0f);
  expect_error("empty.ply", buf, n, FR_ERR_FORMAT);                  /* no triangles */
  expect_error("garbage.ply", "\x01\x02garbage", 9, FR_ERR_FORMAT);
  expect_error("zero.ply", "", 0, FR_ERR_FORMAT);
  const char *hdr = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n";
  expect_error("noend.ply", hdr, strlen(hdr), FR_ERR_FORMAT);
  const char *bigpoly = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n200 0 1 2\n";
  expect_error("shortpoly.ply", bigpoly, strlen(bigpoly), FR_ERR_FORMAT);
  fr_scene *s = (fr_scene *)1;
  assert_int_equal(fr_scene_load("/nonexistent/x.ply", &s), FR_ERR_IO);
  assert_null(s);
  /* an element of 2^64-1 records with no properties holds no bytes: loads at once (was a hang) */
  const char *empty_elem = "ply\nformat ascii 1.0\nelement junk 18446744073709551615\nelement vertex 3\nproperty float x\n"
                           "property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  assert_int_equal(load("junk.ply", empty_elem, strlen(empty_elem), &s), FR_OK);
  assert_int_equal(fr_scene_triangle_count(s), 1);
  fr_scene_release(s);
}

static void test_obj_mtl_and_zst(void **st) {
  (void)st;
  const char *mtl = "newmtl glass\nKd 0.1 0.2 0.3\nKs 1 1 1\nNs 50\nNi 1.5\nd 0.25\n";
  const char *obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl glass\nf 1/1/1 2/2/2 3/3/3 4/4/4\nusemtl other\nf -4 -3 -1\n";
  /* the MTL only as .zst: found through the fallback */
  size_t cap = ZSTD_compressBound(strlen(mtl));
  char *z = malloc(cap);
  size_t zn = ZSTD_compress(z, cap, mtl, strlen(mtl), 3);
  write_file("m.mtl.zst", z, zn);
  free(z);
  fr_scene *s;
  assert_int_equal(load("a.obj", obj, strlen(obj), &s), FR_OK);
  assert_int_equal(fr_scene_triangle_count(s), 3);
  uint32_t m0 = fr_scene_triangle_material(s, 0), m2 = fr_scene_triangle_material(s, 2);
  const fr_material *g = fr_scene_material(s, m0);
  assert_string_equal(g->name, "glass");
  assert_true(g->diffuse[2] == 0.3f && g->ior == 1.5f && g->transmission[0] == 0.75f);
  assert_string_equal(fr_scene_material(s, m2)->name, "other");
  const uint32_t want[9] = {0, 1, 2, 0, 2, 3, 0, 1, 3};
  assert_memory_equal(fr_scene_indices(s), want, sizeof want);
  fr_scene_release(s);
  /* the OBJ itself compressed */
  cap = ZSTD_compressBound(strlen(obj));
  z = malloc(cap);
  zn = ZSTD_compress(z, cap, obj, strlen(obj), 3);
  assert_int_equal(load("b.obj.zst", z, zn, &s), FR_OK);
  assert_int_equal(fr_scene_triangle_count(s), 3);
  fr_scene_release(s);
  expect_error("trunc.obj.zst", z, zn / 2, FR_ERR_FORMAT);
  free(z);
  expect_error("bad.obj", "v 0 0 0\nf 1 2 3\n", 16, FR_ERR_FORMAT);
  expect_error("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", 32, FR_ERR_FORMAT);
  expect_error("nanv.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 34, FR_ERR_FORMAT);
  expect_error("empty.obj", "# nothing\n", 10, FR_ERR_FORMAT);
}

static void test_assimp_path(void **st) {
  (void)st;
  /* an STL (not PLY/OBJ) goes through Assimp */
  const char *stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
  fr_scene *s;
  assert_int_equal(load("t.stl", stl, strlen(stl), &s), FR_OK);
  assert_int_equal(fr_scene_triangle_count(s), 1);
  fr_scene_release(s);
  expect_error("bad.stl", "solid x\nfacet garbage", 21, FR_ERR_FORMAT);
}

/* A scene path that is missing or not a file says which, by its path. */
static void test_not_a_file(void **st) {
  (void)st;
  fr_scene *s = NULL;
  assert_int_equal(fr_scene_load(tmpdir, &s), FR_ERR_IO);
  char want[300];
  snprintf(want, sizeof want, "%s: not a regular file", tmpdir);
  assert_string_equal(fr_last_error(), want);
  assert_int_equal(fr_scene_load("/nonexistent-dir/x.ply", &s), FR_ERR_IO);
  assert_string_equal(fr_last_error(), "/nonexistent-dir/x.ply: No such file or directory");
  assert_null(s);
}

static void test_degenerate_only(void **st) {
  (void)st;
  const float v[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
  const uint32_t ix[3] = {0, 1, 2};
  fr_scene *s;
  assert_int_equal(fr_scene_from_arrays(v, 3, ix, 1, &s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_ERR_FORMAT);
  fr_ray r = {{0.5f, 0.5f, -1}, 0, {0, 0, 1}, INFINITY};
  fr_hit h;
  fr_intersect1(s, &r, &h); /* not committed: a miss, not a crash */
  assert_int_equal(h.prim, FR_INVALID_ID);
  fr_scene_release(s);
}

/* Shading normals: read from OBJ (vn), PLY (nx ny nz) and Assimp, made
 * where a file has none (angle-weighted, sharp past the crease angle). */
static void expect_normal(const fr_scene *s, uint32_t prim, float u, float v, float x, float y, float z) {
  float n[3];
  assert_true(fr_scene_shading_normal(s, prim, u, v, n));
  if (fabsf(n[0] - x) > 1e-5f || fabsf(n[1] - y) > 1e-5f || fabsf(n[2] - z) > 1e-5f)
    print_message("prim %u at (%g, %g): normal %g %g %g, wanted %g %g %g\n", prim, u, v, n[0], n[1], n[2], x, y, z);
  assert_true(fabsf(n[0] - x) <= 1e-5f && fabsf(n[1] - y) <= 1e-5f && fabsf(n[2] - z) <= 1e-5f);
}

static void test_normals(void **st) {
  (void)st;
  fr_scene *s;
  const float r = 0.70710678f;
  /* OBJ: v//vn and v/vt/vn corners; a face without normals has none */
  const char *obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvn 0 0 1\nvn 1 0 1\n"
                    "f 1//1 2//2 3//1\nf 2/1/2 4/1/2 3/1/1\nf 1 2 4\n";
  assert_int_equal(load("n.obj", obj, strlen(obj), &s), FR_OK);
  expect_normal(s, 0, 0.0f, 0.0f, 0, 0, 1);
  expect_normal(s, 0, 1.0f, 0.0f, r, 0, r);
  float n[3];
  assert_false(fr_scene_shading_normal(s, 2, 0.3f, 0.3f, n));
  fr_scene_release(s);
  /* PLY: per-vertex nx ny nz */
  const char *ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "property float nx\nproperty float ny\nproperty float nz\nelement face 1\n"
                    "property list uchar int vertex_indices\nend_header\n0 0 0 0 0 2\n1 0 0 0 1 0\n0 1 0 1 0 0\n3 0 1 2\n";
  assert_int_equal(load("n.ply", ply, strlen(ply), &s), FR_OK);
  expect_normal(s, 0, 0.0f, 0.0f, 0, 0, 1);
  expect_normal(s, 0, 0.0f, 1.0f, 1, 0, 0);
  expect_normal(s, 0, 0.5f, 0.0f, 0, r, r);
  fr_scene_release(s);
  /* Assimp (an OFF file has no normals: none; glTF with NORMAL would) */
  const char *off = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  assert_int_equal(load("n.off", off, strlen(off), &s), FR_OK);
  assert_false(fr_scene_shading_normal(s, 0, 0.3f, 0.3f, n));
  fr_scene_release(s);
  /* made: a cube's faces meet at 90 degrees and stay flat at a crease of
   * 30; a gentle fold of 20 degrees is smoothed across, to the mean */
  const char *cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                     "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  assert_int_equal(load("cube.obj", cube, strlen(cube), &s), FR_OK);
  assert_int_equal(fr_scene_smooth(s, 30.0f), FR_OK);
  for (uint32_t t = 0; t < 12; t++) {
    float g[3], p[3] = {0, 0, 0};
    fr_scene_geometric_normal(s, t, p, g);
    const float l = sqrtf(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    for (int c = 0; c < 3; c++) expect_normal(s, t, c == 1 ? 1.0f : 0.0f, c == 2 ? 1.0f : 0.0f, g[0] / l, g[1] / l, g[2] / l);
  }
  assert_int_equal(fr_scene_commit(s), FR_OK);
  assert_int_equal(fr_scene_smooth(s, 30.0f), FR_ERR_STATE);
  fr_scene_release(s);
  const float c20 = cosf(20.0f * (float)M_PI / 180.0f), s20 = sinf(20.0f * (float)M_PI / 180.0f);
  char fold[256];
  snprintf(fold, sizeof fold, "v 0 0 0\nv 0 1 0\nv -1 0 0\nv %.7f 0 %.7f\nf 1 2 3\nf 1 4 2\n", c20, s20);
  assert_int_equal(load("fold.obj", fold, strlen(fold), &s), FR_OK);
  assert_int_equal(fr_scene_smooth(s, 30.0f), FR_OK);
  /* the shared edge's corners: the mean of the two faces' normals (equal angles there) */
  float g0[3], g1[3], p[3] = {0, 0, 0};
  fr_scene_geometric_normal(s, 0, p, g0);
  fr_scene_geometric_normal(s, 1, p, g1);
  float m[3];
  for (int a = 0; a < 3; a++) m[a] = g0[a] / sqrtf(g0[0] * g0[0] + g0[1] * g0[1] + g0[2] * g0[2]) + g1[a] / sqrtf(g1[0] * g1[0] + g1[1] * g1[1] + g1[2] * g1[2]);
  const float ml = sqrtf(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  expect_normal(s, 0, 0.0f, 0.0f, m[0] / ml, m[1] / ml, m[2] / ml);
  expect_normal(s, 1, 0.0f, 1.0f, m[0] / ml, m[1] / ml, m[2] / ml);
  fr_scene_release(s);
  assert_int_equal(load("fold.obj", fold, strlen(fold), &s), FR_OK);
  assert_int_equal(fr_scene_smooth(s, 10.0f), FR_OK); /* a crease under the fold: flat */
  fr_scene_geometric_normal(s, 0, p, g0);
  const float gl = sqrtf(g0[0] * g0[0] + g0[1] * g0[1] + g0[2] * g0[2]);
  expect_normal(s, 0, 0.0f, 0.0f, g0[0] / gl, g0[1] / gl, g0[2] / gl);
  assert_int_equal(fr_scene_smooth(s, 200.0f), FR_ERR_ARG);
  fr_scene_release(s);
}

/* An image that cannot be made fails with the user's path and the reason,
 * and leaves no file, whatever the format. */
static void test_image_write_fails(void **st) {
  (void)st;
  const float px[3] = {1, 0, 0};
  const char *paths[3] = {"/nonexistent-dir/x.png", "/nonexistent-dir/x.exr", "/nonexistent-dir/x.pfm"};
  for (int i = 0; i < 3; i++) {
    assert_int_equal(fr_image_write(paths[i], 1, 1, px), FR_ERR_IO);
    char want[200];
    snprintf(want, sizeof want, "%s: No such file or directory", paths[i]);
    assert_string_equal(fr_last_error(), want);
  }
}

/* Texture coordinates (OBJ vt) and diffuse textures (map_Kd), confined to
 * the scene's folder, looked up by the path tracer's materials. */
static void test_textures(void **st) {
  (void)st;
  /* a 2x2 image: red, green / blue, white (row 0 at the top) */
  const float px[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1};
  char png[600];
  snprintf(png, sizeof png, "%s/checker.png", tmpdir);
  assert_int_equal(fr_image_write(png, 2, 2, px), FR_OK);
  const char *mtl = "newmtl tex\nKd 1 1 1\nmap_Kd -s 1 1 1 checker.png\nnewmtl away\nmap_Kd ../checker.png\n";
  write_file("t.mtl", mtl, strlen(mtl));
  const char *obj = "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3\n"
                    "usemtl away\nf 1 2 3\n";
  fr_scene *s;
  assert_int_equal(load("t.obj", obj, strlen(obj), &s), FR_OK);
  const fr_material *mt = fr_scene_material(s, 0), *away = fr_scene_material(s, 1);
  assert_string_equal(mt->name, "tex");
  assert_non_null(strstr(mt->map_kd, "checker.png"));
  assert_string_equal(away->map_kd, ""); /* outside the folder: not taken */
  float stc[2];
  assert_true(fr_scene_texcoord(s, 0, 0.25f, 0.5f, stc));
  assert_true(fabsf(stc[0] - 0.25f) < 1e-6f && fabsf(stc[1] - 0.5f) < 1e-6f);
  assert_false(fr_scene_texcoord(s, 1, 0.25f, 0.5f, stc));
  assert_int_equal(fr_scene_commit(s), FR_OK);
  fr_bsdf *mats;
  size_t count, ntex;
  fr_texture *tex;
  assert_int_equal(fr_path_mats_build(s, NULL, NULL, &mats, &count, &tex, &ntex), FR_OK);
  assert_int_equal(ntex, 1);
  assert_int_equal(mats[0].color_tex, 0);
  assert_int_equal(mats[1].color_tex, -1);
  /* texel centres: (0.25, 0.75) is the top-left texel, red; (0.75, 0.25) the bottom-right, white */
  vec3 c = fr_texture_lookup(&tex[0], 0.25f, 0.75f);
  assert_true(fabsf(c.x - 1.0f) < 1e-5f && fabsf(c.y) < 1e-5f && fabsf(c.z) < 1e-5f);
  c = fr_texture_lookup(&tex[0], 0.75f, 0.25f);
  assert_true(fabsf(c.x - 1.0f) < 1e-5f && fabsf(c.y - 1.0f) < 1e-5f && fabsf(c.z - 1.0f) < 1e-5f);
  c = fr_texture_lookup(&tex[0], 1.25f, -0.25f); /* repeats: as (0.25, 0.75) */
  assert_true(fabsf(c.x - 1.0f) < 1e-5f && fabsf(c.y) < 1e-5f);
  c = fr_texture_lookup(&tex[0], 0.5f, 0.75f); /* halfway between red and green */
  assert_true(fabsf(c.x - 0.5f) < 1e-5f && fabsf(c.y - 0.5f) < 1e-5f);
  free(mats);
  fr_path_textures_free(tex, ntex);
  fr_scene_release(s);
  /* a texture that is not an image: the build says which */
  write_file("checker.png", "not a png", 9);
  assert_int_equal(load("t.obj", obj, strlen(obj), &s), FR_OK);
  assert_int_not_equal(fr_path_mats_build(s, NULL, NULL, &mats, &count, &tex, &ntex), FR_OK);
  assert_non_null(strstr(fr_last_error(), "checker.png"));
  fr_scene_release(s);
}

/* Scenes on the caller's buffers: strided copies and shared buffers give
 * the same answers as fr_scene_from_arrays; sharing reads the caller's
 * memory in place and never frees it (ASan would see a double free). */
static void test_from_buffers(void **state) {
  (void)state;
  fr_scene *ref;
  assert_int_equal(fr_scene_builtin(&ref), FR_OK);
  size_t nv = fr_scene_vertex_count(ref), nt = fr_scene_triangle_count(ref);
  const float *pos = fr_scene_vertices(ref);
  const uint32_t *idx = fr_scene_indices(ref);
  /* strided: 5 floats per vertex, 4 indices per triangle */
  float *v5 = malloc(nv * 5 * sizeof(float));
  uint32_t *t4 = malloc(nt * 4 * sizeof(uint32_t));
  for (size_t i = 0; i < nv; i++) {
    memcpy(v5 + 5 * i, pos + 3 * i, 3 * sizeof(float));
    v5[5 * i + 3] = NAN; /* padding is never read */
    v5[5 * i + 4] = -1.0f;
  }
  for (size_t j = 0; j < nt; j++) {
    memcpy(t4 + 4 * j, idx + 3 * j, 3 * sizeof(uint32_t));
    t4[4 * j + 3] = 0xDEADBEEFu;
  }
  float *v3 = malloc(nv * 3 * sizeof(float));
  uint32_t *t3 = malloc(nt * 3 * sizeof(uint32_t));
  memcpy(v3, pos, nv * 3 * sizeof(float));
  memcpy(t3, idx, nt * 3 * sizeof(uint32_t));
  fr_scene *strided, *shared;
  assert_int_equal(fr_scene_from_buffers(v5, nv, 5 * sizeof(float), t4, nt, 4 * sizeof(uint32_t), 0, &strided), FR_OK);
  assert_int_equal(fr_scene_from_buffers(v3, nv, 0, t3, nt, 0, FR_SHARE_BUFFERS, &shared), FR_OK);
  assert_true(fr_scene_vertices(shared) == v3 && fr_scene_indices(shared) == t3); /* not copied */
  assert_true(fr_scene_vertices(strided) != v5);
  assert_int_equal(fr_scene_commit(ref), FR_OK);
  assert_int_equal(fr_scene_commit(strided), FR_OK);
  assert_int_equal(fr_scene_commit(shared), FR_OK);
  assert_int_equal(fr_scene_add_sphere(shared, v3, 1.0f, FR_INVALID_ID), FR_ERR_STATE); /* committed */
  fr_rng r = fr_rng_seed(3, 4);
  float lo[3], hi[3];
  fr_scene_bounds(ref, lo, hi);
  int hits = 0;
  for (int i = 0; i < 2000; i++) {
    fr_ray ray = {{urand(&r, lo[0], hi[0]), urand(&r, lo[1], hi[1]), urand(&r, lo[2], hi[2])}, 0.0f,
                  {urand(&r, -1, 1), urand(&r, -1, 1), urand(&r, -1, 1)}, INFINITY};
    fr_hit a, b, c;
    fr_intersect1(ref, &ray, &a);
    fr_intersect1(strided, &ray, &b);
    fr_intersect1(shared, &ray, &c);
    assert_true(a.prim == b.prim && a.prim == c.prim && a.t == b.t && a.t == c.t);
    hits += a.prim != FR_INVALID_ID;
  }
  assert_true(hits > 500);
  fr_scene_release(shared); /* leaves v3 and t3 to us */
  assert_true(v3[0] == pos[0] && t3[2] == idx[2]);
  fr_scene_release(strided);
  /* errors */
  fr_scene *s = NULL;
  assert_int_equal(fr_scene_from_buffers(v5, nv, 5 * sizeof(float), t3, nt, 0, FR_SHARE_BUFFERS, &s), FR_ERR_ARG);
  assert_true(strstr(fr_last_error(), "tightly packed") != NULL);
  assert_int_equal(fr_scene_from_buffers(v3, nv, 10, t3, nt, 0, 0, &s), FR_ERR_ARG);
  assert_int_equal(fr_scene_from_buffers(v3, nv, 0, t3, nt, 0, 8, &s), FR_ERR_ARG);
  assert_int_equal(fr_scene_from_buffers(NULL, nv, 0, t3, nt, 0, 0, &s), FR_ERR_ARG);
  t3[5] = (uint32_t)nv; /* out of range: refused, shared or not */
  assert_int_equal(fr_scene_from_buffers(v3, nv, 0, t3, nt, 0, FR_SHARE_BUFFERS, &s), FR_ERR_FORMAT);
  assert_true(s == NULL);
  assert_true(strncmp(fr_version(), "0.1 ", 4) == 0);
  free(v5); free(t4); free(v3); free(t3);
  fr_scene_release(ref);
}

int main(void) {
  snprintf(tmpdir, sizeof tmpdir, "/tmp/frusta_test_import_%d", (int)getpid());
  char cmd[300];
  snprintf(cmd, sizeof cmd, "mkdir -p %s", tmpdir);
  if (system(cmd) != 0) return 1;
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_ply_ascii_fan),  cmocka_unit_test(test_ply_binary),   cmocka_unit_test(test_ply_hostile),
      cmocka_unit_test(test_obj_mtl_and_zst), cmocka_unit_test(test_assimp_path), cmocka_unit_test(test_degenerate_only),
      cmocka_unit_test(test_not_a_file),
      cmocka_unit_test(test_normals),     cmocka_unit_test(test_textures),    cmocka_unit_test(test_image_write_fails),
      cmocka_unit_test(test_from_buffers),
  };
  int rc = cmocka_run_group_tests(tests, NULL, NULL);
  snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
  if (system(cmd) != 0) rc = 1;
  return rc;
}
