/*
 * Path-tracing materials from what an MTL file (or Assimp) says of a
 * surface:
 *   - transmissive (illum 4, 6 or 7, or Tf > 0, or d < 1): glass of index
 *     Ni (1.5 when absent), tinted by Tf over `scale` units;
 *   - illum 3 with a specular colour Ks and no diffuse colour of its own
 *     (Kd at most FR_MTL_METAL_MAX_KD): a mirror-like metal whose
 *     reflectance at normal incidence is Ks;
 *   - Kd with Ks > 0 (illum 3 included, as Whitted-era files such as
 *     BART's mark polished paint and wood): plastic, Kd under a coat of
 *     index Ni (1.5) whose roughness follows the Phong exponent Ns
 *     (alpha = sqrt(2 / (Ns + 2)); smooth without Ns or past 1000);
 *   - Kd alone: Lambert.
 * Ke is the emission of any of them.
 */
#ifndef FR_MATERIAL_MATERIAL_MTL_H
#define FR_MATERIAL_MATERIAL_MTL_H
#include "frusta.h"
#include "material/bsdf.h"

/* scale: a length in scene units (the scene's size) over which glass of
 * colour Tf shows that colour. */
#define FR_MTL_METAL_MAX_KD 0.05f

fr_bsdf fr_bsdf_from_mtl(const fr_material *m, float scale);
/* A conductor whose reflectance at normal incidence is f0 (eta 1). */
void fr_bsdf_metal_from_reflectance(fr_bsdf *b, vec3 f0);
#endif
