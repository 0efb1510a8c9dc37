/*
 * The path tracer's hit frames, lane by lane (render/path_frames.h),
 * compiled once per ISA. One loop gathers what each hit reads (its ray, its
 * triangle's normal and material, its corners' shading normals) into
 * component arrays; a second, plain arithmetic in which every branch of the
 * scalar shader is a select, becomes vector code. A lane that is not a
 * triangle hit reads triangle 0 in place of its own and is marked not made.
 */
#include <math.h>
#include "base/simd.h"
#include "render/path_frames.h"

enum { N = FR_PATH_FRAMES };

void FR_ISA_FN(fr_path_frames_make)(const fr_path_geometry *g, const fr_ray *restrict ray, const fr_hit *restrict hit,
                                    size_t m, fr_path_frames *restrict f) {
  const uint32_t nsurf = g->nsurf, nn = g->nrm_n;
  const int normals = g->nrm_idx && nn;
  float ox[N], oy[N], oz[N], dx[N], dy[N], dz[N], th[N], hu[N], hv[N], ax[N], ay[N], az[N];
  float c[9][N]; /* the corners' shading normals, x y z of each */
  int32_t glass[N], some[N];
  for (size_t j = 0; j < m; j++) {
    const uint32_t prim = hit[j].prim;
    const int made = nsurf && prim < nsurf;
    const uint32_t q = made ? prim : 0u;
    f->made[j] = (uint8_t)made;
    ox[j] = ray[j].org[0], oy[j] = ray[j].org[1], oz[j] = ray[j].org[2];
    dx[j] = ray[j].dir[0], dy[j] = ray[j].dir[1], dz[j] = ray[j].dir[2];
    th[j] = hit[j].t, hu[j] = hit[j].u, hv[j] = hit[j].v;
    if (!made) { /* a miss or a sphere: any finite numbers, not used */
      ax[j] = ay[j] = 0.0f, az[j] = 1.0f, glass[j] = 0, some[j] = 0, f->mat[j] = 0;
      continue;
    }
    const fr_surface *s = &g->surf[q];
    ax[j] = s->ng[0], ay[j] = s->ng[1], az[j] = s->ng[2];
    f->mat[j] = s->mat;
    glass[j] = g->mats[s->mat].kind == FR_BSDF_GLASS;
    some[j] = 0;
    if (normals) {
      const uint32_t *ix = g->nrm_idx + 3 * (size_t)q;
      some[j] = ix[0] < nn && ix[1] < nn && ix[2] < nn;
      if (some[j])
        for (int k = 0; k < 3; k++)
          for (int a = 0; a < 3; a++) c[3 * k + a][j] = g->nrm_val[3 * (size_t)ix[k] + (size_t)a];
    }
    if (!some[j])
      for (int k = 0; k < 9; k++) c[k][j] = 0.0f;
  }
  for (size_t j = 0; j < m; j++) {
    const float t = th[j], x0 = dx[j], y0 = dy[j], z0 = dz[j];
    f->px[j] = ox[j] + x0 * t;
    f->py[j] = oy[j] + y0 * t;
    f->pz[j] = oz[j] + z0 * t;
    /* the unit geometric normal (v3_norm), turned */
    const float l = sqrtf(ax[j] * ax[j] + ay[j] * ay[j] + az[j] * az[j]), il = 1.0f / l;
    const float ux = l > 0.0f ? ax[j] * il : ax[j], uy = l > 0.0f ? ay[j] * il : ay[j], uz = l > 0.0f ? az[j] * il : az[j];
    const int front = ux * x0 + uy * y0 + uz * z0 < 0.0f;
    const int out = glass[j] || front;
    const float gx = out ? ux : ux * -1.0f, gy = out ? uy : uy * -1.0f, gz = out ? uz : uz * -1.0f;
    /* the interpolated normal (fr_scene_shading_normal), where it sees the
     * ray on the geometric normal's side */
    const float u = hu[j], v = hv[j], w = 1.0f - u - v;
    const float x = w * c[0][j] + u * c[3][j] + v * c[6][j];
    const float y = w * c[1][j] + u * c[4][j] + v * c[7][j];
    const float z = w * c[2][j] + u * c[5][j] + v * c[8][j];
    const float l2 = x * x + y * y + z * z, r = 1.0f / sqrtf(l2);
    float sx = x * r, sy = y * r, sz = z * r;
    const int flip = sx * gx + sy * gy + sz * gz < 0.0f;
    sx = flip ? sx * -1.0f : sx, sy = flip ? sy * -1.0f : sy, sz = flip ? sz * -1.0f : sz;
    const int use = some[j] && l2 > 1e-12f && (sx * x0 + sy * y0 + sz * z0 < 0.0f) == (gx * x0 + gy * y0 + gz * z0 < 0.0f);
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
