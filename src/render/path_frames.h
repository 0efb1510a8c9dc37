/*
 * The geometry of a block of the path tracer's hits, lane by lane as
 * vector code (path_frames.c, compiled once per ISA): the hit point, the
 * geometric normal turned to the side shaded, the shading normal and the
 * frame about it, and the direction back along the ray in that frame. The
 * shader gathers what each hit reads; the arithmetic is the scalar
 * shader's, operation for operation, so every ISA makes the same bits.
 */
#ifndef FR_RENDER_PATH_FRAMES_H
#define FR_RENDER_PATH_FRAMES_H
#include <stddef.h>
#include <stdint.h>

#define FR_PATH_FRAMES 64 /* hits per block, at most */

/* What the lanes read, one lane per hit, component arrays. */
typedef struct fr_path_frame_in {
  float ox[FR_PATH_FRAMES], oy[FR_PATH_FRAMES], oz[FR_PATH_FRAMES]; /* the ray */
  float dx[FR_PATH_FRAMES], dy[FR_PATH_FRAMES], dz[FR_PATH_FRAMES];
  float t[FR_PATH_FRAMES];                                           /* the hit's distance */
  float ax[FR_PATH_FRAMES], ay[FR_PATH_FRAMES], az[FR_PATH_FRAMES];  /* geometric normal, not unit */
  float sx[FR_PATH_FRAMES], sy[FR_PATH_FRAMES], sz[FR_PATH_FRAMES];  /* unit shading normal, where `shading` */
  int32_t glass[FR_PATH_FRAMES];   /* the frame takes the outward normal */
  int32_t shading[FR_PATH_FRAMES]; /* the hit has a shading normal */
} fr_path_frame_in;

/* The block's frames. */
typedef struct fr_path_frames {
  float px[FR_PATH_FRAMES], py[FR_PATH_FRAMES], pz[FR_PATH_FRAMES];    /* the point */
  float gx[FR_PATH_FRAMES], gy[FR_PATH_FRAMES], gz[FR_PATH_FRAMES];    /* unit geometric normal, the shaded side */
  float nx[FR_PATH_FRAMES], ny[FR_PATH_FRAMES], nz[FR_PATH_FRAMES];    /* shading normal */
  float tx[FR_PATH_FRAMES], ty[FR_PATH_FRAMES], tz[FR_PATH_FRAMES];    /* frame: t, b, n */
  float bx[FR_PATH_FRAMES], by[FR_PATH_FRAMES], bz[FR_PATH_FRAMES];
  float wx[FR_PATH_FRAMES], wy[FR_PATH_FRAMES], wz[FR_PATH_FRAMES];    /* -dir in the frame */
  uint8_t front[FR_PATH_FRAMES]; /* the ray met the geometric normal's side */
} fr_path_frames;

/* f's lanes 0 .. m - 1 (m <= FR_PATH_FRAMES) from in's, one function per
 * ISA. Every lane is computed; lanes of misses may hold any numbers. */
#define FR_PATH_FRAMES_FNS(isa) \
  void fr_path_frames_make_##isa(const fr_path_frame_in *in, size_t m, fr_path_frames *f);
FR_PATH_FRAMES_FNS(scalar)
FR_PATH_FRAMES_FNS(avx2)
FR_PATH_FRAMES_FNS(avx512)
#endif
