/* The ray streams' two-ray block test (tri4_test2, trace/bvhn_ray.h)
 * compiled for one ISA, called by test_kernels through a plain-C
 * signature. Returns 1 when its results for rays a and b are tri4_test's
 * for each ray alone: the same lanes hit, and the same bits of t, e1, e2
 * and 1/det in those lanes; 0 otherwise. */
#include <string.h>
#include "base/simd.h"
#include "trace/wide/bvhn_ray.h"

#define NAME2(isa) fr_test_tri4_pair_##isa
#define NAME(isa) NAME2(isa)

static int same_result(const tri4_result *x, const tri4_result *y) {
  if (x->mask != y->mask) return 0;
  float fx[4][4] __attribute__((aligned(16))), fy[4][4] __attribute__((aligned(16)));
  vf4_store(fx[0], x->t); vf4_store(fx[1], x->e1); vf4_store(fx[2], x->e2); vf4_store(fx[3], x->inv);
  vf4_store(fy[0], y->t); vf4_store(fy[1], y->e1); vf4_store(fy[2], y->e2); vf4_store(fy[3], y->inv);
  for (int i = 0; i < 4; i++)
    if ((x->mask >> i) & 1)
      for (int k = 0; k < 4; k++)
        if (memcmp(&fx[k][i], &fy[k][i], sizeof(float))) return 0;
  return 1;
}

int NAME(FR_ISA_SUFFIX)(const fr_tri4 *block, const fr_ray *a, const fr_ray *b, int *hits);
int NAME(FR_ISA_SUFFIX)(const fr_tri4 *block, const fr_ray *a, const fr_ray *b, int *hits) {
  ray_pre pa, pb;
  ray_setup(&pa, a);
  ray_setup(&pb, b);
  tri4_result alone_a, alone_b, pair_a, pair_b;
  memset(&alone_a, 0, sizeof alone_a); /* tri4_test leaves t, e1, e2, inv unset when nothing is hit */
  memset(&alone_b, 0, sizeof alone_b);
  tri4_test(block, &pa, a->tfar, &alone_a);
  tri4_test(block, &pb, b->tfar, &alone_b);
  tri4_test2(block, &pa, a->tfar, &pb, b->tfar, &pair_a, &pair_b);
  *hits = (alone_a.mask != 0) + (alone_b.mask != 0);
  return same_result(&pair_a, &alone_a) && same_result(&pair_b, &alone_b);
}
