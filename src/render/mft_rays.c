#include "mft_rays.h"
#include <string.h>
#include "base/rng.h"

void fr_mft_sets_camera(fr_mft_sets *t, const fr_camera *c) {
  memset(t, 0, sizeof *t);
  /* one pixel to the right, one pixel down, as fr_camera_ray steps */
  vec3 e1 = v3_scale(c->right, 2.0f / (float)c->width), e2 = v3_scale(c->up, -2.0f / (float)c->height);
  t->e1[0] = e1.x; t->e1[1] = e1.y; t->e1[2] = e1.z;
  t->e2[0] = e2.x; t->e2[1] = e2.y; t->e2[2] = e2.z;
  t->count = 1;
  for (int k = 0; k < FR_MFT_RAYS; k++) {
    t->set[0].a[k] = (float)(k & 3);
    t->set[0].b[k] = (float)(k >> 2);
  }
  fr_mft_set_finish(t, 0);
}

void fr_mft_batch_camera(fr_mft_batch *b, const fr_camera *c, int x0, int y0) {
  memset(b, 0, sizeof *b);
  for (int f = 0; f < FR_MFT_FRUSTA; f++) {
    int x = x0 + 4 * (f & 3), y = y0 + 4 * (f >> 2);
    float sx = 2.0f * ((float)x + 0.5f) / (float)c->width - 1.0f;
    float sy = 1.0f - 2.0f * ((float)y + 0.5f) / (float)c->height;
    vec3 d = v3_add(c->fwd, v3_add(v3_scale(c->right, sx), v3_scale(c->up, sy)));
    b->org[0][f] = c->eye.x; b->org[1][f] = c->eye.y; b->org[2][f] = c->eye.z;
    b->start[0][f] = d.x; b->start[1][f] = d.y; b->start[2][f] = d.z;
    b->tnear[f] = 0.0f;
    b->tfar[f] = __builtin_inff();
    b->set[f] = 0;
    if (x + 3 < c->width && y + 3 < c->height) b->valid |= 1u << f;
  }
}

static uint32_t bit_reverse(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
  x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
  return (x >> 16) | (x << 16);
}

/* second dimension of the Sobol sequence (the first is the van der Corput
 * radical inverse, a bit reversal) */
static uint32_t sobol2(uint32_t i) {
  uint32_t r = 0;
  for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1)
    if (i & 1) r ^= v;
  return r;
}

void fr_mft_sets_light(fr_mft_sets *t, const float e1[3], const float e2[3], uint64_t seed, fr_light_sets kind) {
  memset(t, 0, sizeof *t);
  memcpy(t->e1, e1, sizeof t->e1);
  memcpy(t->e2, e2, sizeof t->e2);
  t->count = FR_MFT_SETS;
  fr_rng rng = fr_rng_seed(seed, 0x51ad0u);
  uint32_t sx = fr_rng_u32(&rng), sy = fr_rng_u32(&rng);
  int fill[FR_MFT_SETS] = {0};
  for (uint32_t i = 0; i < FR_MFT_SETS * FR_MFT_RAYS; i++) {
    uint32_t x = bit_reverse(i) ^ sx, y = sobol2(i) ^ sy;
    /* spread: 16 consecutive points; cells: the 16 points in one quarter by
     * quarter of the light (a (0,8,2)-net has exactly 16 there) */
    int j = kind == FR_LIGHT_SETS_CELLS ? (int)((y >> 30) * 4 + (x >> 30)) : (int)(i / FR_MFT_RAYS);
    int k = fill[j]++;
    t->set[j].a[k] = (float)(x >> 8) * (1.0f / 16777216.0f);
    t->set[j].b[k] = (float)(y >> 8) * (1.0f / 16777216.0f);
  }
  for (int j = 0; j < FR_MFT_SETS; j++) fr_mft_set_finish(t, j);
}
