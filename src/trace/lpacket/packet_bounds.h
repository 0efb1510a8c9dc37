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
 *                        Boxes: the exact test of that volume. Triangles:
 *                        the planes, the triangle's plane against the
 *                        volume's corners, and, for a shared origin, all
 *                        four corner rays outside one edge.
 *
 * The tests are conservative: a cull never rejects what one of the rays
 * hits, with slack for the rays' own float rounding (tests/test_cull.c
 * checks this on millions of random packets). fr_pbounds_build makes the
 * bounds in double, once per packet; the large packets make theirs
 * themselves, 16 lanes at a time in float, each bound pushed outward by its
 * own rounding error (trace/lpacket_traverse.c; test_cull checks both).
 * The box tests and the triangle plane test run in float, with that
 * rounding inside their slack; the corner-ray triangle tests in double.
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

/* Stored in float, every bound rounded outward, so the box test is a few
 * float operations inline in the traversal. */
typedef struct fr_pbounds {
  int empty;                  /* no valid rays */
  /* interval arithmetic */
  float olo[3], ohi[3];       /* origins */
  float dlo[3], dhi[3];       /* directions */
  float rlo[3], rhi[3];       /* reciprocals, on the axes in `uniform` */
  unsigned uniform;           /* bit a: every direction has the same nonzero sign on axis a */
  float tmin, tmax;           /* min tnear, max tfar */
  /* bounding planes, when has_planes: axis k with sign sk (K = sk x_k grows
   * along every ray), u, v the other axes */
  int has_planes, k, u, v;
  float sk;
  float knear, kfar;          /* K of the nearest ray start, of the farthest end (may be +inf) */
  float ulo, uhi, vlo, vhi;   /* the rays' u, v at K = knear */
  float sulo, suhi, svlo, svhi; /* slopes du/dK, dv/dK */
  float scale;                /* magnitude of the origins, for rounding slack */
  int shared_origin;          /* every ray starts at the same point */
} fr_pbounds;

/* The rays i < n with bit (i % 16) of mask[i / 16] set (mask NULL: all):
 * origin (ox, oy, oz)[i], direction (dx, dy, dz)[i], in (tnear, tfar). */
typedef struct fr_ray_soa {
  const float *o[3], *d[3], *tnear, *tfar;
  const uint16_t *mask;
  int n;
} fr_ray_soa;

/* The bounds in double, rounded outward. The large packets make their own
 * in float (trace/lpacket_traverse.c); test_cull checks both. */
void fr_pbounds_build(fr_pbounds *b, const fr_ray_soa *r);

/* 1 when no ray of the packet can hit the box, triangle or sphere. */
static inline int fr_pbounds_cull_box(const fr_pbounds *b, fr_cull c, const float lo[3], const float hi[3]);
int fr_pbounds_cull_tri(const fr_pbounds *b, fr_cull c, const float v0[3], const float v1[3], const float v2[3]);
int fr_pbounds_cull_sphere(const fr_pbounds *b, fr_cull c, const float centre[3], float radius);

/* Slack of every cull, relative to the coordinates' magnitude: the rays'
 * own float tests round by about 2^-20 relative, so a box, triangle or
 * sphere is grown by 1e-5 of its distance from the world's origin (and the
 * packet's) before it may be culled. */
#define FR_PBOUNDS_SLACK 1e-5f

static inline float fr_pb_min(float a, float b) { return a < b ? a : b; }
static inline float fr_pb_max(float a, float b) { return a > b ? a : b; }

static inline int fr_pbounds_box_ia(const fr_pbounds *b, const float lo[3], const float hi[3]) {
  float tn = b->tmin, tf = b->tmax;
  for (int a = 0; a < 3; a++) {
    if (!((b->uniform >> a) & 1)) continue; /* directions of both signs: no bound on this axis */
    float nearp = b->dlo[a] > 0.0f ? lo[a] : hi[a], farp = b->dlo[a] > 0.0f ? hi[a] : lo[a];
    /* (plane - o) / d over o and 1/d in their intervals: bilinear, extremes at the corners */
    float n0 = nearp - b->olo[a], n1 = nearp - b->ohi[a], f0 = farp - b->olo[a], f1 = farp - b->ohi[a];
    tn = fr_pb_max(tn, fr_pb_min(fr_pb_min(n0 * b->rlo[a], n0 * b->rhi[a]), fr_pb_min(n1 * b->rlo[a], n1 * b->rhi[a])));
    tf = fr_pb_min(tf, fr_pb_max(fr_pb_max(f0 * b->rlo[a], f0 * b->rhi[a]), fr_pb_max(f1 * b->rlo[a], f1 * b->rhi[a])));
  }
  return tn > tf;
}

/* max / min of s x over x in [xa, xb], xb possibly +inf, xa finite */
static inline float fr_pb_span_max(float s, float xa, float xb) { return s > 0.0f ? s * xb : s < 0.0f ? s * xa : 0.0f; }
static inline float fr_pb_span_min(float s, float xa, float xb) { return s > 0.0f ? s * xa : s < 0.0f ? s * xb : 0.0f; }

/* s x <= c narrows [*xa, *xb]; 0 when nothing is left */
static inline int fr_pb_narrow(float s, float c, float *xa, float *xb) {
  if (s > 0.0f) *xb = fr_pb_min(*xb, c / s);
  else if (s < 0.0f) *xa = fr_pb_max(*xa, c / s);
  else if (c < 0.0f) return 0;
  return *xa <= *xb;
}

static inline int fr_pbounds_cull_box(const fr_pbounds *b, fr_cull c, const float lo_in[3], const float hi_in[3]) {
  if (b->empty) return 1;
  if (c == FR_CULL_OFF) return 0;
  float mag = 0.0f;
  for (int a = 0; a < 3; a++) mag = fr_pb_max(mag, fr_pb_max(fr_pb_max(lo_in[a], -lo_in[a]), fr_pb_max(hi_in[a], -hi_in[a])));
  const float tol = FR_PBOUNDS_SLACK * (b->scale + mag);
  float lo[3], hi[3];
  for (int a = 0; a < 3; a++) { lo[a] = lo_in[a] - tol; hi[a] = hi_in[a] + tol; }
  if (c == FR_CULL_IA || !b->has_planes) return fr_pbounds_box_ia(b, lo, hi);
  /* the box's K range clipped to the packet's [knear, kfar], from knear */
  float Klo = b->sk > 0.0f ? lo[b->k] : -hi[b->k], Khi = b->sk > 0.0f ? hi[b->k] : -lo[b->k];
  float da = fr_pb_max(Klo, b->knear) - b->knear, db = fr_pb_min(Khi, b->kfar) - b->knear;
  if (!(da <= db)) return 1;
  const int u = b->u, v = b->v;
  if (c == FR_CULL_PLANES)
    return lo[u] > b->uhi + fr_pb_span_max(b->suhi, da, db) || hi[u] < b->ulo + fr_pb_span_min(b->sulo, da, db) ||
           lo[v] > b->vhi + fr_pb_span_max(b->svhi, da, db) || hi[v] < b->vlo + fr_pb_span_min(b->svlo, da, db);
  /* corners: the packet's cross section at K is the rectangle between the
   * corner rays; it meets the box's cross section for K in an interval,
   * found edge by edge: the exact test of the packet volume and the box */
  return !(fr_pb_narrow(b->sulo, hi[u] - b->ulo, &da, &db) && fr_pb_narrow(-b->suhi, b->uhi - lo[u], &da, &db) &&
           fr_pb_narrow(b->svlo, hi[v] - b->vlo, &da, &db) && fr_pb_narrow(-b->svhi, b->vhi - lo[v], &da, &db));
}
#endif
