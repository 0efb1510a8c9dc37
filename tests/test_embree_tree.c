/*
 * Embree's own tree statistics as `frusta stats --embree` reads them from its
 * build log (tools/frusta/embree_tree.c): the parser on a log as Embree 3.13
 * prints it, with a second tree after the triangles' and with the lines
 * missing, and the whole path on the built-in scene, whose SAH must be what
 * frusta's BVH8 statistics are compared with.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>
#include "embree_tree.h"

static const char *LOG =
    "general:\n"
    "  build threads      = 2\n"
    "  verbosity          = 2\n"
    "building BVH8<triangle4> using avx::BVH8BuilderFastSpatialSAH ...\n"
    "finished BVH8<triangle4> : 29.41ms, 11.26 Mprim/s, 0.75 GB/s\n"
    "  primitives = 331179, vertices = 0, depth = 13\n"
    "  total            : sah =  11.133 (100.00%), #bytes =   22.08 MB (100.00%), #nodes =  102447 ( 82.67% filled), "
    "#bytes/prim =  66.68\n"
    "  getAABBNodes     : sah =   6.564 ( 58.96%), #bytes =    4.64 MB ( 21.03%), #nodes =   18137 ( 70.61% filled), "
    "#bytes/prim =  14.02\n"
    "  leaves           : sah =   4.569 ( 41.04%), #bytes =   17.44 MB ( 78.97%), #nodes =   84310 ( 87.09% filled), "
    "#bytes/prim =  52.66\n"
    "    histogram      :  87.38%   9.37%   2.26%   0.51%   0.33%   0.10%   0.04%   0.00% \n"
    "building BVH4<object> using sse2::BVH4BuilderSAH ...\n"
    "  primitives = 10, vertices = 0, depth = 2\n"
    "  total            : sah =   9.000 (100.00%), #bytes =    0.01 MB (100.00%), #nodes =  3 ( 50.00% filled), "
    "#bytes/prim =  1.00\n"
    "created scene intersector\n";

static void parses_the_triangle_tree(void **st) {
  (void)st;
  ebr_tree t;
  assert_int_equal(ebr_tree_parse(LOG, &t), FR_OK);
  assert_string_equal(t.accel, "BVH8<triangle4>");
  assert_string_equal(t.builder, "avx::BVH8BuilderFastSpatialSAH");
  assert_int_equal(t.width, 8);
  assert_int_equal(t.block_size, 4);
  assert_int_equal(t.depth, 13);
  assert_true(fabs(t.sah - 11.133) < 1e-9 && fabs(t.node_sah - 6.564) < 1e-9 && fabs(t.leaf_sah - 4.569) < 1e-9);
  assert_int_equal(t.inner, 18137);
  assert_int_equal(t.leaves, 84310);
  assert_true(fabs(t.node_fill - 0.7061 * 8) < 1e-9);
  assert_true(fabs(t.block_fill - 0.8709 * 4) < 1e-9);
  assert_true(fabs(t.one_block - 0.8738) < 1e-9);
}

static void missing_lines_are_unsupported(void **st) {
  (void)st;
  ebr_tree t;
  assert_int_equal(ebr_tree_parse("", &t), FR_ERR_UNSUPPORTED);
  assert_int_equal(ebr_tree_parse("general:\n  verbosity = 2\n", &t), FR_ERR_UNSUPPORTED);
  /* the log cut short after the totals */
  const char *cut = strstr(LOG, "  getAABBNodes");
  char buf[2048];
  memcpy(buf, LOG, (size_t)(cut - LOG));
  buf[cut - LOG] = '\0';
  assert_int_equal(ebr_tree_parse(buf, &t), FR_ERR_UNSUPPORTED);
  /* only a tree of something else */
  assert_int_equal(ebr_tree_parse(strstr(LOG, "building BVH4<object>"), &t), FR_ERR_UNSUPPORTED);
}

/* Embree's tree of the built-in scene: read, plausible, and its SAH within a
 * factor of two of frusta's BVH8 by the same measure. */
static void builtin_scene(void **st) {
  (void)st;
  fr_scene *s;
  assert_int_equal(fr_scene_builtin(&s), FR_OK);
  assert_int_equal(fr_scene_commit(s), FR_OK);
  ebr_tree t;
  assert_int_equal(ebr_tree_stats(s, 2, &t), FR_OK);
  fr_bvh_stats bs;
  fr_scene_stats(s, &bs);
  print_message("embree %s: sah %.3f, frusta bvh8 %.3f\n", t.accel, t.sah, bs.bvh8.sah_blocks);
  assert_true(t.width == 4 || t.width == 8);
  assert_true(t.depth > 0 && t.inner > 0 && t.leaves > 0);
  assert_true(t.node_fill > 1.0 && t.node_fill <= t.width);
  assert_true(t.block_fill > 0.0 && t.block_fill <= t.block_size);
  assert_true(fabs(t.sah - (t.node_sah + t.leaf_sah)) < 0.01 * t.sah);
  assert_true(bs.bvh8.sah_blocks > 0.5 * t.sah && bs.bvh8.sah_blocks < 2.0 * t.sah);
  fr_scene_release(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(parses_the_triangle_tree),
                                     cmocka_unit_test(missing_lines_are_unsupported), cmocka_unit_test(builtin_scene)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
