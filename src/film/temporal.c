/* Temporal reprojection (see temporal.h). */
#include "film/temporal.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"
#include "render/progressive.h"

#define MISS FR_DEPTH_MISS

struct fr_temporal {
  int w, h;
  /* the last frame shown: its image, guides (and the points seen),
   * camera and worth in passes */
  float *out, *depth, *normal, *pos, *worth;
  fr_camera cam;
  int have_out;
  /* the history carried to the camera of the frames since it last moved */
  float *hist, *hist_worth;
  fr_camera hist_cam;
  int have_hist;
  float reused, mean_worth;
};

fr_error fr_temporal_new(int width, int height, fr_temporal **t) {
  *t = NULL;
  if (width < 1 || height < 1 || (size_t)width * (size_t)height > ((size_t)1 << 28))
    return fr_fail(FR_ERR_ARG, "temporal reprojection: bad image size %dx%d", width, height);
  fr_temporal *p = calloc(1, sizeof *p);
  const size_t np = (size_t)width * (size_t)height;
  if (p) p->out = malloc(np * 15 * sizeof(float));
  if (!p || !p->out) {
    free(p);
    return fr_fail(FR_ERR_NOMEM, "out of memory for temporal reprojection of %dx%d", width, height);
  }
  p->w = width, p->h = height;
  p->depth = p->out + 3 * np;
  p->normal = p->depth + np;
  p->pos = p->normal + 3 * np;
  p->worth = p->pos + 3 * np;
  p->hist = p->worth + np;
  p->hist_worth = p->hist + 3 * np;
  *t = p;
  return FR_OK;
}

void fr_temporal_free(fr_temporal *t) {
  if (!t) return;
  free(t->out);
  free(t);
}

void fr_temporal_reset(fr_temporal *t) { t->have_out = t->have_hist = 0; }

float fr_temporal_reused(const fr_temporal *t) { return t->reused; }
float fr_temporal_worth(const fr_temporal *t) { return t->mean_worth; }

/* fr_camera is four vec3 of floats and two ints: no padding */
static int same_camera(const fr_camera *a, const fr_camera *b) { return memcmp(a, b, sizeof *a) == 0; }

/* Where direction d from c's eye meets c's image, in pixels (centres at
 * integers); 0 when it points away from the image plane. */
static int project(const fr_camera *c, vec3 d, float *px, float *py) {
  const float f = v3_dot(d, c->fwd);
  if (!(f > 1e-6f * v3_len(d))) return 0;
  const float sx = v3_dot(d, c->right) / (v3_dot(c->right, c->right) * f);
  const float sy = v3_dot(d, c->up) / (v3_dot(c->up, c->up) * f);
  *px = (sx + 1.0f) * 0.5f * (float)c->width - 0.5f;
  *py = (1.0f - sy) * 0.5f * (float)c->height - 0.5f;
  return isfinite(*px) && isfinite(*py);
}

static vec3 unit_or_zero(vec3 v) {
  const float l = v3_len(v);
  return l > 0.0f ? v3_scale(v, 1.0f / l) : v3(0, 0, 0);
}

/* The last frame shown, carried to cam: hist and hist_worth per pixel
 * (worth 0 where no earlier pixel is the same surface). */
static void reproject(fr_temporal *t, const fr_camera *cam, const float *depth, const float *normal, int threads) {
  const int W = t->w, H = t->h;
  const fr_camera *pc = &t->cam;
  int reused = 0;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(+ : reused)
  for (int y = 0; y < H; y++)
    for (int x = 0; x < W; x++) {
      const size_t i = (size_t)y * (size_t)W + (size_t)x;
      float *hc = t->hist + 3 * i;
      hc[0] = hc[1] = hc[2] = 0.0f;
      t->hist_worth[i] = 0.0f;
      const fr_ray r = fr_camera_ray(cam, x, y);
      const int miss = !(depth[i] < MISS);
      const vec3 dir = v3_load(r.dir);
      /* the point seen, from the last camera: for the background, the same direction */
      const vec3 p = v3_add(cam->eye, v3_scale(dir, depth[i]));
      const vec3 d = miss ? dir : v3_sub(p, pc->eye);
      const float dist = miss ? 0.0f : v3_len(d);
      const vec3 n = unit_or_zero(v3_load(normal + 3 * i));
      float fx, fy;
      if (!project(pc, d, &fx, &fy) || fx < -0.5f || fy < -0.5f || fx > (float)W - 0.5f || fy > (float)H - 0.5f) continue;
      /* bilinear over the four pixels around it, each only if the same surface */
      const int x0 = (int)floorf(fx), y0 = (int)floorf(fy);
      const float ax = fx - (float)x0, ay = fy - (float)y0;
      float sum = 0.0f, c[3] = {0, 0, 0}, worth = 0.0f;
      for (int k = 0; k < 4; k++) {
        const int qx = x0 + (k & 1), qy = y0 + (k >> 1);
        if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
        const size_t q = (size_t)qy * (size_t)W + (size_t)qx;
        const int qmiss = !(t->depth[q] < MISS);
        if (qmiss != miss) continue;
        /* the same surface: as far from the eye, facing alike, and the
         * earlier point on this one's tangent plane (at grazing angles a
         * neighbouring pixel of another surface can be as far away) */
        if (!miss) {
          const vec3 nq = v3_load(t->normal + 3 * q);
          const float cn = v3_dot(nq, n); /* n is unit, nq need not be */
          if (!(fabsf(t->depth[q] - dist) <= FR_TEMPORAL_DEPTH_TOL * dist) ||
              !(cn > 0.0f && cn * cn >= FR_TEMPORAL_NORMAL_COS * FR_TEMPORAL_NORMAL_COS * v3_dot(nq, nq)) ||
              !(fabsf(v3_dot(v3_sub(v3_load(t->pos + 3 * q), p), n)) <= FR_TEMPORAL_PLANE_TOL * dist))
            continue;
        }
        const float wk = ((k & 1) ? ax : 1.0f - ax) * ((k >> 1) ? ay : 1.0f - ay);
        sum += wk;
        worth += wk * t->worth[q];
        for (int ch = 0; ch < 3; ch++) c[ch] += wk * t->out[3 * q + ch];
      }
      if (!(sum > 1e-3f)) continue;
      for (int ch = 0; ch < 3; ch++) hc[ch] = c[ch] / sum;
      t->hist_worth[i] = worth / sum;
      reused++;
    }
  t->reused = (float)reused / (float)((size_t)W * (size_t)H);
}

/* Keeps the frame shown (rgb, its guides and the points seen) for the
 * next camera move. The points are made along fr_camera_ray's directions,
 * written out so that the loop vectorizes: the camera's basis is
 * orthogonal, so a direction's squared length is a sum of a row's and a
 * column's terms. */
static void remember(fr_temporal *t, const fr_camera *cam, const float *rgb, const float *depth, const float *normal,
                     int threads) {
  const int W = t->w, H = t->h;
  const size_t np = (size_t)W * (size_t)H;
  memcpy(t->out, rgb, np * 3 * sizeof(float));
  memcpy(t->depth, depth, np * sizeof(float));
  memcpy(t->normal, normal, np * 3 * sizeof(float));
  const vec3 e = cam->eye, f = cam->fwd, r = cam->right, u = cam->up;
  const float ff = v3_dot(f, f), rr = v3_dot(r, r), uu = v3_dot(u, u);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < H; y++) {
    const float sy = 1.0f - 2.0f * ((float)y + 0.5f) / (float)H;
    const float bx = f.x + u.x * sy, by = f.y + u.y * sy, bz = f.z + u.z * sy, b2 = ff + uu * sy * sy;
    const float *dep = depth + (size_t)y * (size_t)W;
    float *pos = t->pos + 3 * (size_t)y * (size_t)W;
    for (int x = 0; x < W; x++) {
      const float sx = 2.0f * ((float)x + 0.5f) / (float)W - 1.0f;
      const float k = dep[x] / sqrtf(b2 + rr * sx * sx);
      pos[3 * x] = e.x + (bx + r.x * sx) * k;
      pos[3 * x + 1] = e.y + (by + r.y * sx) * k;
      pos[3 * x + 2] = e.z + (bz + r.z * sx) * k;
    }
  }
  t->cam = *cam;
  t->have_out = 1;
}

void fr_temporal_apply(fr_temporal *t, const fr_camera *cam, int passes, const float *depth, const float *normal,
                       float *rgb, int threads) {
  const size_t np = (size_t)t->w * (size_t)t->h;
  if (cam->width != t->w || cam->height != t->h) return;
  /* a history is made when the camera moves, and kept while it rests: the
   * passes at rest are in rgb already */
  if (t->have_out && !same_camera(cam, &t->cam)) {
    reproject(t, cam, depth, normal, threads);
    t->hist_cam = *cam;
    t->have_hist = 1;
  } else if (t->have_hist && !same_camera(cam, &t->hist_cam)) {
    t->have_hist = 0;
  }
  const float k = (float)(passes > 0 ? passes : 1);
  const float fade = 1.0f - k / (float)FR_TEMPORAL_FADE;
  if (!t->have_hist || fade <= 0.0f) {
    for (size_t i = 0; i < np; i++) t->worth[i] = fminf(k, (float)FR_TEMPORAL_HISTORY);
    if (!t->have_hist) t->reused = 0.0f;
  } else {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (size_t i = 0; i < np; i++) {
      const float wh = t->hist_worth[i] * fade;
      if (wh > 0.0f) {
        const float inv = 1.0f / (wh + k);
        for (int ch = 0; ch < 3; ch++) rgb[3 * i + ch] = (t->hist[3 * i + ch] * wh + rgb[3 * i + ch] * k) * inv;
      }
      t->worth[i] = fminf(wh + k, (float)FR_TEMPORAL_HISTORY);
    }
  }
  double wsum = 0.0;
  if (t->have_hist && fade > 0.0f)
    for (size_t i = 0; i < np; i++) wsum += t->hist_worth[i] * fade;
  t->mean_worth = (float)(wsum / (double)np / k);
  remember(t, cam, rgb, depth, normal, threads);
}
