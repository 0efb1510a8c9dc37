/*
 * Pre-splitting before the SAH build (early split clipping, Ernst & Greiner
 * 2007, with Embree's grid-aligned split planes). A long thin triangle lying
 * across the axes has a box far larger than itself, and every ray through
 * that box must test it; where boxes overlap like that, no object split can
 * separate them (SPD rings: frusta's SAH was 3.2x Embree's spatial-split
 * build). So the triangles whose boxes exceed their own area most get
 * several references, each bounding the triangle's part in one cell of
 * their box, and the build places those like small triangles. The same
 * triangle may then sit in several leaves; the kernels test whole
 * triangles, so answers do not change.
 */
#ifndef FR_ACCEL_BVH_PRESPLIT_H
#define FR_ACCEL_BVH_PRESPLIT_H
#include <stddef.h>
#include <stdint.h>
#include "base/vec3.h"
#include "frusta.h"
#include "geom/mesh.h"

/* Extra references, as a fraction of the triangles, the presplit may add. */
#define FR_PRESPLIT_BUDGET 1.0f
/* A triangle is cut when its box's area is more than this many times the
 * tightest box's for its area... */
#define FR_PRESPLIT_RATIO 4.0f
/* ... and only when such boxes' excess area is this share of all boxes'
 * area: SPD rings 0.96, hairball 0.67, conference 0.30, dragon 0.06. */
#define FR_PRESPLIT_MIN_SHARE 0.75
/* The presplit tree replaces the plain one when its SAH is below this
 * fraction of the plain one's. */
#define FR_PRESPLIT_MIN_GAIN 0.67

/* boxes/ids (n triangles' boxes and ids) are replaced by arrays of at most
 * n * (1 + budget) references; *n gets their number. Every triangle's
 * references together cover it: each is its part within a box, bounds
 * rounded outward. budget <= 0, or an excess below min_share of the boxes'
 * area, keeps them as they are (*n unchanged). The caller decides by SAH
 * whether the references made a better tree. */
fr_error fr_presplit(const fr_mesh *m, aabb scene, float budget, double min_share, aabb **boxes, uint32_t **ids,
                     size_t *n);
#endif
