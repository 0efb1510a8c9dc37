#include "camera.h"
#include "base/error.h"

fr_error fr_camera_setup(fr_camera *c, vec3 eye, vec3 at, vec3 up, float fov_deg, int width, int height) {
  if (width <= 0 || height <= 0) return fr_fail(FR_ERR_ARG, "image size %dx%d is empty", width, height);
  if (!(fov_deg > 0.0f && fov_deg < 180.0f)) return fr_fail(FR_ERR_ARG, "field of view %g is not in (0, 180)", fov_deg);
  vec3 f = v3_norm(v3_sub(at, eye));
  vec3 r = v3_norm(v3_cross(f, up));
  if (!v3_finite(eye) || !v3_finite(f) || !v3_finite(r) || v3_len(r) < 0.5f || v3_len(f) < 0.5f)
    return fr_fail(FR_ERR_ARG, "camera eye/at/up do not define a view");
  vec3 u = v3_cross(r, f);
  float th = tanf(0.5f * fov_deg * (float)M_PI / 180.0f);
  float aspect = (float)width / (float)height;
  c->eye = eye;
  c->fwd = f;
  c->right = v3_scale(r, th * aspect);
  c->up = v3_scale(u, th);
  c->width = width;
  c->height = height;
  return FR_OK;
}
