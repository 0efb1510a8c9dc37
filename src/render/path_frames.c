/*
 * The path tracer's hit frames, lane by lane (render/path_frames.h),
 * compiled once per ISA: plain arithmetic over component arrays, every
 * branch of the scalar shader a select, which the compiler turns into
 * vector code.
 */
#include <math.h>
#include "base/simd.h"
#include "render/path_frames.h"

void FR_ISA_FN(fr_path_frames_make)(const fr_path_frame_in *restrict in, size_t m, fr_path_frames *restrict f) {
  for (size_t j = 0; j < m; j++) {
    const float t = in->t[j], x0 = in->dx[j], y0 = in->dy[j], z0 = in->dz[j];
    f->px[j] = in->ox[j] + x0 * t;
    f->py[j] = in->oy[j] + y0 * t;
    f->pz[j] = in->oz[j] + z0 * t;
    /* the unit geometric normal (v3_norm), turned */
    const float ax = in->ax[j], ay = in->ay[j], az = in->az[j];
    const float l = sqrtf(ax * ax + ay * ay + az * az), il = 1.0f / l;
    const float ux = l > 0.0f ? ax * il : ax, uy = l > 0.0f ? ay * il : ay, uz = l > 0.0f ? az * il : az;
    const int front = ux * x0 + uy * y0 + uz * z0 < 0.0f;
    const int out = in->glass[j] || front;
    const float gx = out ? ux : ux * -1.0f, gy = out ? uy : uy * -1.0f, gz = out ? uz : uz * -1.0f;
    /* the shading normal, on the side of the turned one, where it sees the
     * ray on the geometric normal's side */
    float sx = in->sx[j], sy = in->sy[j], sz = in->sz[j];
    const int flip = sx * gx + sy * gy + sz * gz < 0.0f;
    sx = flip ? sx * -1.0f : sx, sy = flip ? sy * -1.0f : sy, sz = flip ? sz * -1.0f : sz;
    const int use = in->shading[j] && (sx * x0 + sy * y0 + sz * z0 < 0.0f) == (gx * x0 + gy * y0 + gz * z0 < 0.0f);
    const float nx = use ? sx : gx, ny = use ? sy : gy, nz = use ? sz : gz;
    /* the frame about n (v3_onb) and wo = -dir in it */
    const float sign = copysignf(1.0f, nz), ka = -1.0f / (sign + nz), kb = nx * ny * ka;
    const float tx = 1.0f + sign * nx * nx * ka, ty = sign * kb, tz = -sign * nx;
    const float bx = kb, by = sign + ny * ny * ka, bz = -ny;
    const float wx = x0 * -1.0f, wy = y0 * -1.0f, wz = z0 * -1.0f;
    f->gx[j] = gx, f->gy[j] = gy, f->gz[j] = gz;
    f->nx[j] = nx, f->ny[j] = ny, f->nz[j] = nz;
    f->tx[j] = tx, f->ty[j] = ty, f->tz[j] = tz;
    f->bx[j] = bx, f->by[j] = by, f->bz[j] = bz;
    f->wx[j] = wx * tx + wy * ty + wz * tz;
    f->wy[j] = wx * bx + wy * by + wz * bz;
    f->wz[j] = wx * nx + wy * ny + wz * nz;
    f->front[j] = (uint8_t)front;
  }
}
