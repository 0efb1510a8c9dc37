/*
 * The geometry of a block of the path tracer's hits, made lane by lane as
 * vector code (path_frames.c, compiled once per ISA): the hit point, the
 * geometric normal turned to the side shaded, the shading normal and the
 * frame about it, and the direction back along the ray in that frame. The
 * arithmetic is the scalar shader's, operation for operation, so every ISA
 * makes the same bits.
 */
#ifndef FR_RENDER_PATH_FRAMES_H
#define FR_RENDER_PATH_FRAMES_H
#include <stddef.h>
#include <stdint.h>
#include "frusta.h"
#include "material/bsdf.h"
#include "render/surfaces.h"

#define FR_PATH_FRAMES 64 /* hits per block, at most */

/* What the lanes read of the scene. */
typedef struct fr_path_geometry {
  const fr_surface *surf;   /* per triangle: its normal and material */
  uint32_t nsurf;           /* triangles; other prims (spheres) are not made here */
  const fr_bsdf *mats;      /* the surfaces' materials: glass takes the outward normal */
  const uint32_t *nrm_idx;  /* the corners' shading normal indices (FR_INVALID_ID: none), or NULL */
  const float *nrm_val;     /* the shading normals, 3 floats each */
  uint32_t nrm_n;           /* how many */
} fr_path_geometry;

/* The block's frames, one lane per hit, component arrays. */
typedef struct fr_path_frames {
  float px[FR_PATH_FRAMES], py[FR_PATH_FRAMES], pz[FR_PATH_FRAMES];    /* the point */
  float gx[FR_PATH_FRAMES], gy[FR_PATH_FRAMES], gz[FR_PATH_FRAMES];    /* unit geometric normal, the shaded side */
  float nx[FR_PATH_FRAMES], ny[FR_PATH_FRAMES], nz[FR_PATH_FRAMES];    /* shading normal */
  float tx[FR_PATH_FRAMES], ty[FR_PATH_FRAMES], tz[FR_PATH_FRAMES];    /* frame: t, b, n */
  float bx[FR_PATH_FRAMES], by[FR_PATH_FRAMES], bz[FR_PATH_FRAMES];
  float wx[FR_PATH_FRAMES], wy[FR_PATH_FRAMES], wz[FR_PATH_FRAMES];    /* -dir in the frame */
  int32_t mat[FR_PATH_FRAMES];
  uint8_t front[FR_PATH_FRAMES]; /* the ray met the geometric normal's side */
  uint8_t made[FR_PATH_FRAMES];  /* 1: a triangle hit, made here; 0: a miss or a sphere */
} fr_path_frames;

/* f's lanes 0 .. m - 1 (m <= FR_PATH_FRAMES) for ray[j] and its hit[j],
 * one function per ISA. */
#define FR_PATH_FRAMES_FNS(isa)                                                                                      \
  void fr_path_frames_make_##isa(const fr_path_geometry *g, const fr_ray *ray, const fr_hit *hit, size_t m,         \
                                 fr_path_frames *f);
FR_PATH_FRAMES_FNS(scalar)
FR_PATH_FRAMES_FNS(avx2)
FR_PATH_FRAMES_FNS(avx512)
#endif
