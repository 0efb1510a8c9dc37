/* Small 3-vector and box math used outside the SIMD kernels. */
#ifndef FR_BASE_VEC3_H
#define FR_BASE_VEC3_H
#include <math.h>

typedef struct vec3 { float x, y, z; } vec3;

static inline vec3 v3(float x, float y, float z) { vec3 r = {x, y, z}; return r; }
static inline vec3 v3_load(const float *p) { return v3(p[0], p[1], p[2]); }
static inline void v3_store(float *p, vec3 a) { p[0] = a.x, p[1] = a.y, p[2] = a.z; }
static inline vec3 v3_add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline vec3 v3_sub(vec3 a, vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline vec3 v3_mul(vec3 a, vec3 b) { return v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline vec3 v3_scale(vec3 a, float s) { return v3(a.x * s, a.y * s, a.z * s); }
/* ternaries, not fminf/fmaxf: they compile to minss/maxss (NaN never reaches boxes) */
static inline float fr_minf(float a, float b) { return a < b ? a : b; }
static inline float fr_maxf(float a, float b) { return a > b ? a : b; }
static inline vec3 v3_min(vec3 a, vec3 b) { return v3(fr_minf(a.x, b.x), fr_minf(a.y, b.y), fr_minf(a.z, b.z)); }
static inline vec3 v3_max(vec3 a, vec3 b) { return v3(fr_maxf(a.x, b.x), fr_maxf(a.y, b.y), fr_maxf(a.z, b.z)); }
static inline float v3_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline vec3 v3_cross(vec3 a, vec3 b) {
  return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float v3_len(vec3 a) { return sqrtf(v3_dot(a, a)); }
static inline vec3 v3_norm(vec3 a) {
  float l = v3_len(a);
  return l > 0.0f ? v3_scale(a, 1.0f / l) : a;
}
/* Two unit vectors t, b completing unit n to an orthonormal basis (Duff et
 * al., "Building an Orthonormal Basis, Revisited": no branch, no singularity). */
static inline void v3_onb(vec3 n, vec3 *t, vec3 *b) {
  float sign = copysignf(1.0f, n.z);
  float a = -1.0f / (sign + n.z), bb = n.x * n.y * a;
  *t = v3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
  *b = v3(bb, sign + n.y * n.y * a, -n.y);
}
static inline float v3_get(vec3 a, int axis) { return axis == 0 ? a.x : axis == 1 ? a.y : a.z; }
static inline int v3_finite(vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

typedef struct aabb { vec3 lo, hi; } aabb;

static inline aabb aabb_empty(void) {
  aabb b = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  return b;
}
static inline aabb aabb_grow(aabb b, vec3 p) { b.lo = v3_min(b.lo, p); b.hi = v3_max(b.hi, p); return b; }
static inline aabb aabb_merge(aabb a, aabb b) { a.lo = v3_min(a.lo, b.lo); a.hi = v3_max(a.hi, b.hi); return a; }
static inline float aabb_half_area(aabb b) {
  vec3 d = v3_sub(b.hi, b.lo);
  if (!(d.x >= 0.0f)) return 0.0f; /* empty box */
  return d.x * d.y + d.y * d.z + d.z * d.x;
}
static inline vec3 aabb_center2(aabb b) { return v3_add(b.lo, b.hi); } /* twice the centre */
#endif
