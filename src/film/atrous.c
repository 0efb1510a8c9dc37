/*
 * The à-trous level's inner loop (film/atrous.h), 16 pixels of a row at a
 * time. Weights of tap q for pixel p, all in [0, 1]:
 *   kernel  (1/4, 1/2, 1/4) per axis
 *   normal  max(0, n_p . n_q)^16
 *   depth   max(0, 1 - |z_p - z_q| / (sigma_z * zgrad_p * distance + 1e-3 z_p))
 *   colour  max(0, 1 - |l_p - l_q| / (2 sigma_l (l_p + l_floor) + 1e-4))
 * (l_floor, the frame's mean over spp, lets a pixel whose samples found
 * no light, l_p = 0, take its neighbours' light instead of staying black)
 * Polynomial falloffs rather than exponentials, and denominators that
 * depend on p and the tap's distance only (four divisions per pixel),
 * keep the taps to adds and multiplies.
 */
#include "film/atrous.h"
#include "base/simd.h"
#include "base/simd_packet.h"

FR_INLINE vpf luminance(vpf r, vpf g, vpf b) {
  return vp_add(vp_add(vp_mul(vp(0.2126f), r), vp_mul(vp(0.7152f), g)), vp_mul(vp(0.0722f), b));
}

void FR_ISA_FN(fr_atrous_rows)(const fr_atrous_level *L, int y0, int y1) {
  static const float kern[3] = {0.25f, 0.5f, 0.25f};
  const ptrdiff_t st = (ptrdiff_t)L->stride, s = L->step;
  const vpf zero = vp(0.0f), one = vp(1.0f), miss = vp(1e29f);
  const vpf unit2 = vp(1.0f / (FR_ATROUS_NORMAL_ONE * FR_ATROUS_NORMAL_ONE)); /* the normals' dot product to cosines */
  for (int y = y0; y < y1; y++)
    for (int x = 0; x < L->width; x += FR_ATROUS_LANES) {
      const ptrdiff_t o = (ptrdiff_t)(y + FR_ATROUS_PAD) * st + x + FR_ATROUS_PAD;
      const vpf zp = vp_load(L->z + o), gp = vp_load(L->zgrad + o);
      const vpf npx = vp_loadu_i16(L->nrm[0] + o), npy = vp_loadu_i16(L->nrm[1] + o), npz = vp_loadu_i16(L->nrm[2] + o);
      const vpf cr = vp_load(L->in[0] + o), cg = vp_load(L->in[1] + o), cb = vp_load(L->in[2] + o);
      const vpf lp = luminance(cr, cg, cb);
      const vpf inv_l = vp_div(one, vp_add(vp_mul(vp(2.0f * L->sigma_l), vp_add(lp, vp(L->lum_floor))), vp(1e-4f)));
      vpf inv_z[3]; /* by the tap's distance in steps: 0, 1 or 2 */
      for (int k = 0; k < 3; k++)
        inv_z[k] = vp_div(one, vp_add(vp_add(vp_mul(vp(L->sigma_z * (float)(s * k)), gp), vp_mul(vp(1e-3f), zp)), vp(1e-20f)));
      vpf sr = zero, sg = zero, sb = zero, sw = zero;
      for (int j = -1; j <= 1; j++)
        for (int i = -1; i <= 1; i++) {
          const ptrdiff_t q = o + j * s * st + i * s;
          const vpf zq = vp_loadu(L->z + q);
          const vpf qr = vp_loadu(L->in[0] + q), qg = vp_loadu(L->in[1] + q), qb = vp_loadu(L->in[2] + q);
          vpf dn = vp_add(vp_add(vp_mul(npx, vp_loadu_i16(L->nrm[0] + q)), vp_mul(npy, vp_loadu_i16(L->nrm[1] + q))),
                          vp_mul(npz, vp_loadu_i16(L->nrm[2] + q)));
          dn = vp_mul(vp_max(zero, dn), unit2);
          dn = vp_mul(dn, dn), dn = vp_mul(dn, dn), dn = vp_mul(dn, dn), dn = vp_mul(dn, dn);
          const vpf wz = vp_max(zero, vp_sub(one, vp_mul(vp_abs(vp_sub(zp, zq)), inv_z[(i != 0) + (j != 0)])));
          const vpf wl = vp_max(zero, vp_sub(one, vp_mul(vp_abs(vp_sub(lp, luminance(qr, qg, qb))), inv_l)));
          const vpf w = vp_mul(vp(kern[i + 1] * kern[j + 1]), vp_mul(dn, vp_mul(wz, wl)));
          sr = vp_add(sr, vp_mul(w, qr)), sg = vp_add(sg, vp_mul(w, qg)), sb = vp_add(sb, vp_mul(w, qb));
          sw = vp_add(sw, w);
        }
      /* the centre tap's weight is at least 1/4 where p sees geometry */
      const vpm keep = vp_ge(zp, miss);
      const vpf inv = vp_div(one, vp_max(sw, vp(1e-20f)));
      vp_store(L->out[0] + o, vp_select(keep, cr, vp_mul(sr, inv)));
      vp_store(L->out[1] + o, vp_select(keep, cg, vp_mul(sg, inv)));
      vp_store(L->out[2] + o, vp_select(keep, cb, vp_mul(sb, inv)));
    }
}
