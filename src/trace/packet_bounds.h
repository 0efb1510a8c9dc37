/*
 * Bounds of a whole ray packet, and the tests that cull a box, a triangle or
 * a sphere for every ray of it at once (Boulos, Wald, Shirley, "Geometric and
 * Arithmetic Culling Methods for Entire Ray Packets"; Overbeck et al.'s
 * frusta). Any packet: shared origin or not, mixed direction signs.
 *
 *   interval arithmetic  boxes of the origins, directions and reciprocal
 *                        directions, and of (tnear, tfar);
 *   bounding planes      when every direction has the same sign on an axis
 *                        k (the major axis), the rays are lines
 *                        u = u(knear) + s_u (k - knear) in the other two
 *                        axes u, v; min and max slope and intercept give four
 *                        planes that hold every ray point with k >= knear,
 *                        plus the near and far planes k = knear, k = kfar
 *                        (Overbeck's frustum; k is mapped so rays go +k);
 *   corner rays          the four edges where those planes meet: the packet
 *                        lies in the sheared box they span at each k.
 *
 * The tests are conservative: a cull never rejects what one of the rays
 * hits, with slack for the rays' own float rounding (tests/test_cull.c
 * checks this on millions of random packets). Everything is in double; a
 * packet's bounds are made once and each test is a few dozen flops, small
 * against the 16-ray SIMD tests they save.
 */
#ifndef FR_TRACE_PACKET_BOUNDS_H
#define FR_TRACE_PACKET_BOUNDS_H
#include <stdint.h>

typedef enum fr_cull {
  FR_CULL_OFF,      /* no whole-packet test */
  FR_CULL_IA,       /* interval arithmetic */
  FR_CULL_PLANES,   /* bounding planes one at a time (IA where there are none) */
  FR_CULL_CORNERS,  /* corner rays: the exact packet-volume test for boxes, edges for triangles */
  FR_CULL_COUNT
} fr_cull;

const char *fr_cull_name(fr_cull c);
int fr_cull_parse(const char *name, fr_cull *out);

typedef struct fr_pbounds {
  int empty;                  /* no valid rays */
  /* interval arithmetic */
  double olo[3], ohi[3];      /* origins */
  double dlo[3], dhi[3];      /* directions */
  double rlo[3], rhi[3];      /* reciprocals, on the axes in `uniform` */
  unsigned uniform;           /* bit a: every direction has the same nonzero sign on axis a */
  double tmin, tmax;          /* min tnear, max tfar */
  /* bounding planes, when has_planes: axis k with sign sk (K = sk x_k grows
   * along every ray), u, v the other axes */
  int has_planes, k, u, v;
  double sk;
  double knear, kfar;         /* K of the nearest ray start, of the farthest end (may be +inf) */
  double ulo, uhi, vlo, vhi;  /* the rays' u, v at K = knear */
  double sulo, suhi, svlo, svhi; /* slopes du/dK, dv/dK */
  double scale;               /* magnitude of the coordinates, for rounding slack */
} fr_pbounds;

/* The rays i < n with bit (i % 16) of mask[i / 16] set (mask NULL: all):
 * origin (ox, oy, oz)[i], direction (dx, dy, dz)[i], in (tnear, tfar). */
typedef struct fr_ray_soa {
  const float *o[3], *d[3], *tnear, *tfar;
  const uint16_t *mask;
  int n;
} fr_ray_soa;

void fr_pbounds_build(fr_pbounds *b, const fr_ray_soa *r);

/* 1 when no ray of the packet can hit the box, triangle or sphere. */
int fr_pbounds_cull_box(const fr_pbounds *b, fr_cull c, const float lo[3], const float hi[3]);
int fr_pbounds_cull_tri(const fr_pbounds *b, fr_cull c, const float v0[3], const float v1[3], const float v2[3]);
int fr_pbounds_cull_sphere(const fr_pbounds *b, fr_cull c, const float centre[3], float radius);
#endif
