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

/* The ray of c through pixel (x, y) is b + right sx, b = fwd + up sy, of
 * squared length b2 + rr sx^2 (the basis is orthogonal): a row's b and b2
 * are made once, and its directions take one root a pixel. */
typedef struct camera_row { float bx, by, bz, b2; } camera_row;

static camera_row camera_row_of(const fr_camera *c, int y) {
  const vec3 f = c->fwd, u = c->up;
  const float sy = 1.0f - 2.0f * ((float)y + 0.5f) / (float)c->height;
  return (camera_row){f.x + u.x * sy, f.y + u.y * sy, f.z + u.z * sy, v3_dot(f, f) + v3_dot(u, u) * sy * sy};
}
static float pixel_sx(const fr_camera *c, int x) { return 2.0f * ((float)x + 0.5f) / (float)c->width - 1.0f; }

/* The last frame's camera as reprojection uses it: a point's offset d
 * from its eye meets its image at sx = (d . rs) / (d . fwd), sy the same
 * with us (rs, us: right and up over their squared lengths). */
typedef struct projector { vec3 eye, fwd, rs, us; float w, h; } projector;

static projector projector_of(const fr_camera *c) {
  return (projector){c->eye, c->fwd, v3_scale(c->right, 1.0f / v3_dot(c->right, c->right)),
                     v3_scale(c->up, 1.0f / v3_dot(c->up, c->up)), (float)c->width, (float)c->height};
}

/* The last frame shown, carried to cam: hist and hist_worth per pixel
 * (worth 0 where no earlier pixel is the same surface). Row by row, first
 * where each pixel's point falls in the last image (the directions made
 * as remember() makes them, one root and one division each), then the
 * four earlier pixels around it, each taken where it is the same surface
 * (the normal and plane tests squared: no roots). */
static void reproject(fr_temporal *t, const fr_camera *cam, const float *depth, const float *normal, int threads) {
  const int W = t->w, H = t->h;
  const projector pc = projector_of(&t->cam);
  const vec3 e = cam->eye, r = cam->right;
  const float rr = v3_dot(r, r);
  const float cos2 = FR_TEMPORAL_NORMAL_COS * FR_TEMPORAL_NORMAL_COS, plane2 = FR_TEMPORAL_PLANE_TOL * FR_TEMPORAL_PLANE_TOL;
  const float hw = 0.5f * pc.w, hh = 0.5f * pc.h, xmax = pc.w - 0.5f, ymax = pc.h - 0.5f;
  int reused = 0, failed = 0;
#pragma omp parallel num_threads(threads) reduction(+ : reused, failed)
  {
    /* per row: the point seen (p), its distance from the last eye and its
     * place in the last image (fx, fy; NaN where it has none) */
    float *row = malloc((size_t)W * 6 * sizeof(float));
    float *px = row, *py = px + W, *pz = py + W, *dist = pz + W, *fxs = dist + W, *fys = fxs + W;
    if (!row) failed = 1;
#pragma omp for schedule(static)
    for (int y = 0; y < H; y++) {
      const size_t i0 = (size_t)y * (size_t)W;
      for (int x = 0; x < W; x++) {
        float *hc = t->hist + 3 * (i0 + (size_t)x);
        hc[0] = hc[1] = hc[2] = 0.0f;
        t->hist_worth[i0 + (size_t)x] = 0.0f;
      }
      if (!row) continue;
      const camera_row cr = camera_row_of(cam, y);
      const float *dep = depth + i0;
      for (int x = 0; x < W; x++) {
        const float sx = pixel_sx(cam, x);
        const float k = 1.0f / sqrtf(cr.b2 + rr * sx * sx);
        const float dx = (cr.bx + r.x * sx) * k, dy = (cr.by + r.y * sx) * k, dz = (cr.bz + r.z * sx) * k; /* unit */
        const float dv = dep[x];
        const int hit = dv < MISS;
        const float z = hit ? dv : 0.0f;
        const float qx = e.x + dx * z, qy = e.y + dy * z, qz = e.z + dz * z;
        px[x] = qx, py[x] = qy, pz[x] = qz;
        /* the background: the same direction */
        const vec3 o = hit ? v3(qx - pc.eye.x, qy - pc.eye.y, qz - pc.eye.z) : v3(dx, dy, dz);
        const float len = v3_len(o);
        dist[x] = len;
        const float fw = v3_dot(o, pc.fwd), inv = 1.0f / fw;
        const float fx = (v3_dot(o, pc.rs) * inv + 1.0f) * hw - 0.5f;
        const float fy = (1.0f - v3_dot(o, pc.us) * inv) * hh - 0.5f;
        const int in = (fw > 1e-6f * len) & (fx >= -0.5f) & (fy >= -0.5f) & (fx <= xmax) & (fy <= ymax);
        fxs[x] = in ? fx : NAN;
        fys[x] = fy;
      }
      for (int x = 0; x < W; x++) {
        const float fx = fxs[x], fy = fys[x];
        if (!(fx == fx)) continue;
        const size_t i = i0 + (size_t)x;
        const int miss = !(dep[x] < MISS);
        const vec3 p = v3(px[x], py[x], pz[x]);
        const float dd = dist[x];
        const vec3 n = v3_load(normal + 3 * i); /* not unit */
        const float nn = v3_dot(n, n);
        /* bilinear over the four pixels around it (fx, fy >= -0.5: the
         * truncations of fx + 1 and fy + 1 are their floors plus 1) */
        const int x0 = (int)(fx + 1.0f) - 1, y0 = (int)(fy + 1.0f) - 1;
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
            const float cn = v3_dot(nq, n), pl = v3_dot(v3_sub(v3_load(t->pos + 3 * q), p), n);
            if (!(fabsf(t->depth[q] - dd) <= FR_TEMPORAL_DEPTH_TOL * dd) ||
                !(cn > 0.0f && cn * cn >= cos2 * v3_dot(nq, nq) * nn) || !(pl * pl <= plane2 * dd * dd * nn))
              continue;
          }
          const float wk = ((k & 1) ? ax : 1.0f - ax) * ((k >> 1) ? ay : 1.0f - ay);
          sum += wk;
          worth += wk * t->worth[q];
          for (int ch = 0; ch < 3; ch++) c[ch] += wk * t->out[3 * q + ch];
        }
        if (!(sum > 1e-3f)) continue;
        const float inv = 1.0f / sum;
        float *hc = t->hist + 3 * i;
        for (int ch = 0; ch < 3; ch++) hc[ch] = c[ch] * inv;
        t->hist_worth[i] = worth * inv;
        reused++;
      }
    }
    free(row);
  }
  /* without scratch no pixel carries over: the frame starts afresh */
  t->reused = failed ? 0.0f : (float)reused / (float)((size_t)W * (size_t)H);
}

/* Keeps the frame shown (rgb, its guides and the points seen) for the
 * next camera move, the points made along the camera's rays row by row
 * (camera_row). */
static void remember(fr_temporal *t, const fr_camera *cam, const float *rgb, const float *depth, const float *normal,
                     int threads) {
  const int W = t->w, H = t->h;
  const vec3 e = cam->eye, r = cam->right;
  const float rr = v3_dot(r, r);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < H; y++) {
    const camera_row cr = camera_row_of(cam, y);
    const size_t row = (size_t)y * (size_t)W;
    memcpy(t->out + 3 * row, rgb + 3 * row, (size_t)W * 3 * sizeof(float));
    memcpy(t->depth + row, depth + row, (size_t)W * sizeof(float));
    memcpy(t->normal + 3 * row, normal + 3 * row, (size_t)W * 3 * sizeof(float));
    const float *dep = depth + row;
    float *pos = t->pos + 3 * row;
    for (int x = 0; x < W; x++) {
      const float sx = pixel_sx(cam, x);
      const float k = dep[x] / sqrtf(cr.b2 + rr * sx * sx);
      pos[3 * x] = e.x + (cr.bx + r.x * sx) * k;
      pos[3 * x + 1] = e.y + (cr.by + r.y * sx) * k;
      pos[3 * x + 2] = e.z + (cr.bz + r.z * sx) * k;
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
  if (t->have_hist && fade > 0.0f) {
#pragma omp parallel for schedule(static) num_threads(threads) reduction(+ : wsum)
    for (size_t i = 0; i < np; i++) wsum += t->hist_worth[i] * fade;
  }
  t->mean_worth = (float)(wsum / (double)np / k);
  remember(t, cam, rgb, depth, normal, threads);
}
