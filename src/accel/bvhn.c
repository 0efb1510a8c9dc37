#include "bvhn.h"
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"
#include "base/tuning.h"
#include "geom/tri_watertight.h"

typedef struct conv {
  const fr_build_tree *t;
  const fr_mesh *m;
  fr_bvhn *b;
  size_t node_bytes;
  int max_blocks; /* per leaf */
  /* The optimal collapse (see plan_node): per binary node of more than
   * FR_BUILD_MAX_LEAF triangles, its row in the tables below, else -1. */
  int32_t *row;
  float *cost;   /* [row * W + s - 1]: least cost of the subtree as s roots */
  uint8_t *pick; /* [row * (W + 1) + s]: how (see plan_node) */
  int dp;        /* 0: the greedy collapse (FRUSTA_COLLAPSE=greedy) */
  /* Triangle areas summed in leaf order (area[i]: prims[0..i)), so a
   * subtree's area is one difference; NULL keeps the collapse's slot order
   * (FRUSTA_CHILD_ORDER=tree, for measurements). */
  double *area;
  int too_many; /* more nodes than a ref can address */
} conv;

static void fill_block(conv *c, fr_tri4 *blk, uint32_t first, uint32_t count) {
  for (int l = 0; l < 4; l++) {
    if ((uint32_t)l < count) {
      uint32_t prim = c->t->prims[first + l];
      const uint32_t *ix = c->m->idx + 3 * (size_t)prim;
      for (int a = 0; a < 3; a++) {
        blk->v0[a][l] = c->m->pos[3 * (size_t)ix[0] + a];
        blk->v1[a][l] = c->m->pos[3 * (size_t)ix[1] + a];
        blk->v2[a][l] = c->m->pos[3 * (size_t)ix[2] + a];
      }
      const int thin = fr_tri_thin(blk->v0[0][l], blk->v0[1][l], blk->v0[2][l], blk->v1[0][l], blk->v1[1][l],
                                   blk->v1[2][l], blk->v2[0][l], blk->v2[1][l], blk->v2[2][l]);
      blk->prim[l] = prim | (thin ? FR_TRI4_THIN : 0u);
      fr_tri_shevtsov *rec = &c->b->shev[4 * (size_t)(blk - c->b->tris) + (size_t)l];
      vec3 p0 = v3(blk->v0[0][l], blk->v0[1][l], blk->v0[2][l]);
      vec3 p1 = v3(blk->v1[0][l], blk->v1[1][l], blk->v1[2][l]);
      vec3 p2 = v3(blk->v2[0][l], blk->v2[1][l], blk->v2[2][l]);
      if (!fr_tri_shevtsov_make(rec, p0, p1, p2, prim)) {
        /* NaN plane: t is NaN for every ray, which fails every compare */
        memset(rec, 0, sizeof *rec);
        rec->a_k = NAN;
        rec->axis_aligned = 1;
        rec->prim = prim;
      }
    } else {
      fr_tri_shevtsov *rec = &c->b->shev[4 * (size_t)(blk - c->b->tris) + (size_t)l];
      memset(rec, 0, sizeof *rec);
      rec->a_k = NAN;
      rec->axis_aligned = 1;
      rec->prim = FR_INVALID_ID;
      for (int a = 0; a < 3; a++) blk->v0[a][l] = blk->v1[a][l] = blk->v2[a][l] = NAN;
      blk->prim[l] = FR_INVALID_ID;
    }
  }
}

/* Packs the node's triangles into consecutive blocks, in leaf order. */
static uint32_t make_leaf(conv *c, const fr_build_node *n) {
  uint32_t nb = n->count ? (n->count + 3) / 4 : 1;
  uint32_t first = (uint32_t)c->b->nblocks;
  c->b->nblocks += nb;
  c->b->nleaves++;
  for (uint32_t k = 0; k < nb; k++) {
    uint32_t rest = n->count - 4 * k;
    fill_block(c, &c->b->tris[first + k], n->first + 4 * k, rest < 4 ? rest : 4);
  }
  return FR_BVHN_LEAF_REF(first, nb);
}

/* A node's cost as one leaf by SAH: its area times its 4-triangle blocks. */
static float leaf_cost(const fr_build_node *n) { return aabb_half_area(n->box) * fr_build_blocks(n->count); }

/* Whether a node of more than four triangles ends as a leaf of several
 * blocks: when testing all its blocks costs no more than visiting it and
 * testing its two halves' blocks (Embree's rule, node visit and block test
 * both costing 1). Without it every node of 5-12 triangles became a node of
 * two or three children, and the BVH8 had twice Embree's node count. */
static int leaf_pays(conv *c, const fr_build_node *n) {
  /* n has more than FR_BUILD_MAX_LEAF triangles, so it has two children */
  if (n->count > FR_BUILD_MAX_LEAF * (uint32_t)c->max_blocks) return 0;
  const fr_build_node *l = &c->t->nodes[n->left], *r = &c->t->nodes[n->right];
  return leaf_cost(n) <= aabb_half_area(n->box) + leaf_cost(l) + leaf_cost(r);
}

/* The float arrays of the node at ref (generic over the width). */
static float *node_floats(conv *c, uint32_t ref) { return (float *)((char *)c->b->nodes + (size_t)ref * FR_BVHN_NODE_UNIT); }
static uint32_t *node_children(conv *c, uint32_t ref) { return (uint32_t *)(node_floats(c, ref) + 6 * c->b->width); }

/* Any-hit traversal stops at the first triangle hit, so it pays to try
 * first the children that most likely hold one per unit of work: for a
 * search that stops at its first success, trying them in falling order of
 * p / c minimises the expected cost. Here p is the chance that a ray of
 * random direction through the child's box hits one of its triangles (their
 * area over the box's half area, capped at 1) and c its triangle count. The
 * estimate is crude, so children change places only across steps of a
 * factor of sqrt(2) (the rank is 2 log2(p / c) rounded down); within a
 * step they keep the collapse's order (the lower half of each split in the
 * lower slots). Any-hit takes the last slot first (trace/bvhn_single.h),
 * so the slots hold the children in rising rank. That collapse's order
 * tried upper halves first, which suits dragon's light above it and no
 * other light: from below, dragon soft16 took 11.7 node visits per ray
 * with it and 8.8 with a factor-2 step. Steps of sqrt(2) sit between the
 * unrounded rank (best on hairball, worst on dragon) and steps of 2. */
static int occlusion_rank(const conv *c, int32_t bi) {
  const fr_build_node *n = &c->t->nodes[bi];
  double a = c->area[n->first + n->count] - c->area[n->first], h = aabb_half_area(n->box);
  double p = h > 0.0 && a < h ? a / h : 1.0;
  if (!(p > 0.0)) return INT_MIN; /* no area: it can hold no hit */
  return (int)floor(2.0 * log2(p / (double)(n->count ? n->count : 1)));
}

static void order_for_occlusion(const conv *c, int32_t *kids, int nk) {
  int rank[8];
  for (int k = 0; k < nk; k++) rank[k] = occlusion_rank(c, kids[k]);
  for (int i = 1; i < nk; i++) { /* insertion sort: stable, so ties keep their order */
    int32_t x = kids[i];
    int r = rank[i], j = i - 1;
    for (; j >= 0 && rank[j] > r; j--) { kids[j + 1] = kids[j]; rank[j + 1] = rank[j]; }
    kids[j + 1] = x;
    rank[j + 1] = r;
  }
}

static fr_error area_prefix(conv *c) {
  const fr_build_tree *t = c->t;
  c->area = malloc(fr_mul_size(t->nprims + 1, sizeof *c->area));
  if (!c->area) return fr_fail(FR_ERR_NOMEM, "BVH%d: out of memory", c->b->width);
  c->area[0] = 0.0;
  for (size_t i = 0; i < t->nprims; i++) {
    const uint32_t *ix = c->m->idx + 3 * (size_t)t->prims[i];
    const float *p0 = c->m->pos + 3 * (size_t)ix[0], *p1 = c->m->pos + 3 * (size_t)ix[1], *p2 = c->m->pos + 3 * (size_t)ix[2];
    vec3 n = v3_cross(v3(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]), v3(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]));
    double a = 0.5 * sqrt((double)v3_dot(n, n));
    c->area[i + 1] = c->area[i] + (a == a ? a : 0.0); /* a NaN vertex adds nothing */
  }
  return FR_OK;
}

/* Emits a wide node over the binary subtrees kids[0..nk) and converts them. */
static uint32_t convert(conv *c, int32_t bi, int depth);
static uint32_t emit_node(conv *c, int32_t *kids, int nk, int depth) {
  const int W = c->b->width;
  const size_t index = c->b->nnodes++, units = c->node_bytes / FR_BVHN_NODE_UNIT;
  if ((index + 1) * units > FR_BVHN_LEAF) c->too_many = 1;
  const uint32_t self = c->too_many ? 0 : (uint32_t)(index * units);
  if (c->area) order_for_occlusion(c, kids, nk);
  float *f = node_floats(c, self);
  uint32_t *child = node_children(c, self);
  child[W] = (uint32_t)nk; /* nchildren follows the child array */
  for (int k = 0; k < W; k++) {
    aabb bx = k < nk ? c->t->nodes[kids[k]].box : (aabb){{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    f[k] = bx.lo.x; f[W + k] = bx.hi.x;
    f[2 * W + k] = bx.lo.y; f[3 * W + k] = bx.hi.y;
    f[4 * W + k] = bx.lo.z; f[5 * W + k] = bx.hi.z;
    child[k] = FR_BVHN_EMPTY;
  }
  for (int k = 0; k < nk; k++) {
    uint32_t r = convert(c, kids[k], depth + 1);
    node_children(c, self)[k] = r;
  }
  return self;
}

/* Node bi's pick row, or NULL for a subtree of at most four triangles. */
static uint8_t *plan_pick(const conv *c, int32_t bi) {
  int32_t r = c->row[bi];
  return r < 0 ? NULL : c->pick + (size_t)r * (size_t)(c->b->width + 1);
}

/* The optimal collapse (Ylitie, Karras, Laine, "Efficient Incoherent Ray
 * Traversal on GPUs Through Compressed Wide BVHs", HPG 2017, §3): bottom up,
 * the least SAH cost of each binary subtree when it fills s = 1..W slots of
 * its wide parent, with Embree's costs (a node visit and a block test both
 * 1, times the box's area). One slot: a leaf (at most max_blocks blocks) or
 * a wide node whose W slots are shared out between the two children. More
 * slots: the subtree as one root, or its children sharing them. Subtrees of
 * at most four triangles stay one leaf, as in the greedy collapse.
 * pick[s] for s >= 2: 0 = as one root, k = k slots to the left child;
 * pick[0]: the left child's share when the node is a wide node; pick[1]: 1
 * when it is a wide node rather than a leaf. */
static float plan_cost(const conv *c, int32_t bi, int s) {
  int32_t r = c->row[bi];
  if (r < 0) return leaf_cost(&c->t->nodes[bi]);
  return c->cost[(size_t)r * (size_t)c->b->width + (size_t)s - 1];
}

static void plan_node(conv *c, int32_t bi) {
  const fr_build_node *n = &c->t->nodes[bi];
  const int W = c->b->width;
  if (c->row[bi] < 0) return;
  plan_node(c, n->left);
  plan_node(c, n->right);
  float *cost = c->cost + (size_t)c->row[bi] * (size_t)W;
  uint8_t *pick = plan_pick(c, bi);
  float share[8 + 1];
  uint8_t share_k[8 + 1];
  for (int s = 2; s <= W; s++) {
    share[s] = INFINITY;
    share_k[s] = 1;
    for (int k = 1; k < s; k++) {
      float x = plan_cost(c, n->left, k) + plan_cost(c, n->right, s - k);
      if (x < share[s]) { share[s] = x; share_k[s] = (uint8_t)k; }
    }
  }
  float a = aabb_half_area(n->box);
  float leaf = n->count <= FR_BUILD_MAX_LEAF * (uint32_t)c->max_blocks ? leaf_cost(n) : INFINITY;
  float inner = a + share[W];
  cost[0] = leaf <= inner ? leaf : inner;
  pick[0] = share_k[W];
  pick[1] = !(leaf <= inner);
  for (int s = 2; s <= W; s++) {
    int split = share[s] < cost[s - 2];
    cost[s - 1] = split ? share[s] : cost[s - 2];
    pick[s] = split ? share_k[s] : 0;
  }
}

/* The binary subtrees that fill s slots of a wide node, as planned. */
static void plan_roots(const conv *c, int32_t bi, int s, int32_t *kids, int *nk) {
  const uint8_t *pick = plan_pick(c, bi);
  while (s > 1 && (!pick || pick[s] == 0)) s--;
  if (s == 1) { kids[(*nk)++] = bi; return; }
  plan_roots(c, c->t->nodes[bi].left, pick[s], kids, nk);
  plan_roots(c, c->t->nodes[bi].right, s - pick[s], kids, nk);
}

/* Collapses the binary tree. With the plan: as planned. Greedily: a node
 * adopts the children of its largest child that holds more than four
 * triangles until it has W children; children of at most four triangles
 * become leaves. (Opening those small leaves too, to fill every slot as
 * Embree does, lowers the per-triangle SAH but leaves 4-wide triangle tests
 * 40-60% empty: measured slower for BVH8, no faster for BVH4, and 40% more
 * memory.) */
static uint32_t convert(conv *c, int32_t bi, int depth) {
  const fr_build_node *n = &c->t->nodes[bi];
  const int W = c->b->width;
  if (depth > c->b->depth) c->b->depth = depth;
  int32_t kids[8];
  int nk = 0;
  if (c->dp) {
    const uint8_t *pick = plan_pick(c, bi);
    if (!pick || !pick[1]) return make_leaf(c, n);
    plan_roots(c, n->left, pick[0], kids, &nk);
    plan_roots(c, n->right, W - pick[0], kids, &nk);
    return emit_node(c, kids, nk, depth);
  }
  if (n->count <= FR_BUILD_MAX_LEAF || leaf_pays(c, n)) return make_leaf(c, n);
  kids[0] = n->left; kids[1] = n->right;
  nk = 2;
  while (nk < W) {
    int best = -1;
    float area = -1.0f;
    for (int k = 0; k < nk; k++) {
      const fr_build_node *ch = &c->t->nodes[kids[k]];
      if (ch->count > FR_BUILD_MAX_LEAF && aabb_half_area(ch->box) > area) { area = aabb_half_area(ch->box); best = k; }
    }
    if (best < 0) break;
    const fr_build_node *ch = &c->t->nodes[kids[best]];
    kids[best] = ch->left;
    kids[nk++] = ch->right;
  }
  return emit_node(c, kids, nk, depth);
}

/* Rows of the plan's tables for the nodes of more than four triangles. */
static fr_error plan_tables(conv *c) {
  const size_t nn = c->t->nnodes, W = (size_t)c->b->width;
  c->row = malloc(fr_mul_size(nn, sizeof *c->row));
  size_t rows = 0;
  if (c->row)
    for (size_t i = 0; i < nn; i++) c->row[i] = c->t->nodes[i].count > FR_BUILD_MAX_LEAF ? (int32_t)rows++ : -1;
  c->cost = fr_alloc_aligned(fr_mul_size(rows ? rows : 1, W * sizeof *c->cost), 64); /* 2 MiB pages, as the build's */
  c->pick = malloc(fr_mul_size(rows ? rows : 1, W + 1));
  if (!c->row || !c->cost || !c->pick) {
    free(c->row); fr_free_aligned(c->cost); free(c->pick);
    return fr_fail(FR_ERR_NOMEM, "BVH%d: out of memory", c->b->width);
  }
  return FR_OK;
}

fr_error fr_bvhn_from_build(const fr_build_tree *t, const fr_mesh *m, int width, fr_bvhn *out) {
  memset(out, 0, sizeof *out);
  if (width != 4 && width != 8) return fr_fail(FR_ERR_ARG, "BVH width %d (4 or 8)", width);
  out->width = width;
  if (t->nprims > FR_BVHN_MAX_BLOCKS) /* every block holds a triangle */
    return fr_fail(FR_ERR_ARG, "BVH%d: %zu triangles are more than a leaf reference can address", width, t->nprims);
  size_t node_bytes = width == 4 ? sizeof(fr_bvh4_node) : sizeof(fr_bvh8_node);
  size_t np = t->nprims ? t->nprims : 1; /* an empty tree is one empty leaf */
  out->nodes = fr_alloc_aligned(fr_mul_size(np, node_bytes), 64);
  out->tris = fr_alloc_aligned(fr_mul_size(np, sizeof(fr_tri4)), 64);
  out->shev = fr_alloc_aligned(fr_mul_size(np, 4 * sizeof(fr_tri_shevtsov)), 64);
  if (!out->nodes || !out->tris || !out->shev) {
    fr_bvhn_free(out);
    return fr_fail(FR_ERR_NOMEM, "BVH%d: out of memory", width);
  }
  out->bounds = t->nodes[0].box;
  fr_env_tuning env; /* FRUSTA_LEAF_BLOCKS, FRUSTA_COLLAPSE, FRUSTA_CHILD_ORDER: for measurements */
  fr_env_tuning_read(&env);
  const int mb = env.leaf_blocks ? env.leaf_blocks : FR_BVHN_DEFAULT_LEAF_BLOCKS;
  conv c = {t, m, out, node_bytes, mb, NULL, NULL, NULL, 1, NULL, 0};
  if (env.greedy_collapse || !t->nprims) c.dp = 0; /* no triangles: one empty leaf */
  fr_error e = FR_OK;
  if (t->nprims && !env.tree_child_order) e = area_prefix(&c);
  if (!e && c.dp) e = plan_tables(&c);
  if (e) { free(c.area); fr_bvhn_free(out); return e; }
  if (c.dp) plan_node(&c, 0);
  out->root = convert(&c, 0, 1);
  free(c.row); fr_free_aligned(c.cost); free(c.pick); free(c.area);
  if (c.too_many) {
    fr_bvhn_free(out);
    return fr_fail(FR_ERR_ARG, "BVH%d: %zu triangles need more nodes than a node reference can address", width, t->nprims);
  }
  out->prefetch = fr_bvhn_prefetch_auto(out);
  out->packet_prefetch = fr_bvhn_packet_prefetch_auto(out);
  return FR_OK;
}

int fr_bvhn_prefetch_auto(const fr_bvhn *b) {
  size_t node_bytes = b->width == 4 ? sizeof(fr_bvh4_node) : sizeof(fr_bvh8_node);
  return b->nnodes * node_bytes + b->nblocks * sizeof(fr_tri4) > FR_BVHN_PREFETCH_BYTES;
}

int fr_bvhn_packet_prefetch_auto(const fr_bvhn *b) {
  size_t node_bytes = b->width == 4 ? sizeof(fr_bvh4_node) : sizeof(fr_bvh8_node);
  return b->nnodes * node_bytes + 4 * b->nblocks * sizeof(fr_tri_shevtsov) > FR_BVHN_PACKET_PREFETCH_BYTES;
}

void fr_bvhn_free(fr_bvhn *b) {
  fr_free_aligned(b->nodes);
  fr_free_aligned(b->tris);
  fr_free_aligned(b->shev);
  memset(b, 0, sizeof *b);
}

static int leaf_count(const fr_bvhn *b, uint32_t ref) {
  const fr_tri4 *t = &b->tris[FR_BVHN_LEAF_FIRST(ref)];
  int n = 0;
  for (uint32_t k = 0; k < FR_BVHN_LEAF_BLOCKS(ref); k++)
    for (int l = 0; l < 4; l++) n += t[k].prim[l] != FR_INVALID_ID;
  return n;
}

void fr_bvhn_stats_get(const fr_bvhn *b, fr_bvhn_stats *st) {
  const int W = b->width;
  size_t node_bytes = W == 4 ? sizeof(fr_bvh4_node) : sizeof(fr_bvh8_node);
  double root = aabb_half_area(b->bounds);
  size_t kids = 0, tris = 0;
  double cost = 1.0, cost_blocks = 1.0;
  if (b->root & FR_BVHN_LEAF) {
    tris = (size_t)leaf_count(b, b->root);
    cost = (double)tris;
    cost_blocks = FR_BVHN_LEAF_BLOCKS(b->root);
  }
  for (size_t i = 0; i < b->nnodes; i++) {
    const float *f = (const float *)((const char *)b->nodes + i * node_bytes);
    const uint32_t *child = (const uint32_t *)(f + 6 * W);
    uint32_t nc = child[W];
    kids += nc;
    for (uint32_t k = 0; k < nc; k++) {
      double dx = f[W + k] - f[k], dy = f[3 * W + k] - f[2 * W + k], dz = f[5 * W + k] - f[4 * W + k];
      double w = root > 0.0 ? (dx * dy + dy * dz + dz * dx) / root : 0.0;
      if (child[k] & FR_BVHN_LEAF) {
        int cnt = leaf_count(b, child[k]);
        tris += (size_t)cnt;
        cost += w * cnt;
        cost_blocks += w * FR_BVHN_LEAF_BLOCKS(child[k]);
      } else {
        cost += w;
        cost_blocks += w;
      }
    }
  }
  st->inner = b->nnodes;
  st->leaves = b->nleaves;
  st->blocks = b->nblocks;
  st->node_bytes = b->nnodes * node_bytes;
  st->tri_bytes = b->nblocks * sizeof(fr_tri4);
  st->packet_tri_bytes = b->nblocks * 4 * sizeof(fr_tri_shevtsov);
  st->sah = cost;
  st->sah_blocks = cost_blocks;
  st->node_fill = b->nnodes ? (double)kids / (double)b->nnodes : 0.0;
  st->leaf_fill = b->nleaves ? (double)tris / (double)b->nleaves : 0.0;
  st->block_fill = b->nblocks ? (double)tris / (double)b->nblocks : 0.0;
  st->depth = b->depth;
}
