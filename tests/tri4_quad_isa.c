/* The packets' four-rays-by-four-triangles block test (quad_test,
 * trace/tri4_quad.h) compiled for one ISA and packet size, called by
 * test_kernels through a plain-C signature. Rays rays[0..n) (n <= P) sit in
 * scattered packet lanes; returns 1 when each ray's lanes of the quad test
 * are what tri4_test (trace/bvhn_ray.h) gives for that ray alone: the same
 * triangles hit, and the same bits of t, e1, e2 and 1/det in those lanes; 0
 * when they differ; -1 when the rays do not share the shear axes
 * (quad_setup declines them, and packets then keep their one-triangle
 * test). */
#include <string.h>
#include "base/simd.h"
#include "trace/wide/bvhn_ray.h"
#include "base/simd_packet.h"
#include "trace/wide/tri4_quad.h"

#define NAME3(p, isa) fr_test_tri4_quad##p##_##isa
#define NAME2(p, isa) NAME3(p, isa)
#define NAME NAME2(FR_PACKET, FR_ISA_SUFFIX)

int NAME(const fr_tri4 *block, const fr_ray *rays, int n, int *hits);
int NAME(const fr_tri4 *block, const fr_ray *rays, int n, int *hits) {
  float o[3][P] __attribute__((aligned(64))), d[3][P] __attribute__((aligned(64)));
  float tn[P] __attribute__((aligned(64))), tf[P] __attribute__((aligned(64)));
  int ray_of[P];
  unsigned valid = 0;
  for (int l = 0; l < P; l++) ray_of[l] = 0; /* lanes without a ray hold ray 0, invalid */
  for (int k = 0; k < n; k++) { /* ray k in lane (5k + 3) % P: 5 is prime to P */
    ray_of[(5 * k + 3) % P] = k;
    valid |= 1u << ((5 * k + 3) % P);
  }
  for (int l = 0; l < P; l++) {
    const fr_ray *r = &rays[ray_of[l]];
    for (int a = 0; a < 3; a++) { o[a][l] = r->org[a]; d[a][l] = r->dir[a]; }
    tn[l] = r->tnear;
    tf[l] = r->tfar;
  }
  quad_rays q = {.ok = -1};
  quad_setup(&q, (const float(*)[P])o, (const float(*)[P])d, valid);
  if (!q.ok) return -1;
  *hits = 0;
  for (unsigned left = valid; left;) {
    quad_group g;
    left = quad_gather(&q, tn, tf, left, &g);
    quad_hit h;
    memset(&h, 0, sizeof h);
    const unsigned hit = quad_test(block, &q, &g, quad_live(&g), &h);
    float v[4][P] __attribute__((aligned(64)));
    vp_store(v[0], h.t); vp_store(v[1], h.e1); vp_store(v[2], h.e2); vp_store(v[3], h.inv);
    for (int j = 0; j < g.n; j++) {
      ray_pre pre;
      ray_setup(&pre, &rays[ray_of[g.lane[j]]]);
      tri4_result alone;
      memset(&alone, 0, sizeof alone);
      tri4_test(block, &pre, rays[ray_of[g.lane[j]]].tfar, &alone);
      const int m = (int)((hit >> (4 * j)) & 0xFu);
      if (m != alone.mask) return 0;
      *hits += m != 0;
      float a[4][4] __attribute__((aligned(16)));
      vf4_store(a[0], alone.t); vf4_store(a[1], alone.e1); vf4_store(a[2], alone.e2); vf4_store(a[3], alone.inv);
      for (int i = 0; i < 4; i++)
        if ((m >> i) & 1)
          for (int k = 0; k < 4; k++)
            if (memcmp(&v[k][4 * j + i], &a[k][i], sizeof(float))) return 0;
    }
  }
  return 1;
}
