#include "bvh4.h"
#include <math.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"

typedef struct conv { const fr_build_tree *t; const fr_mesh *m; fr_bvh4 *b; } conv;

static uint32_t make_leaf(conv *c, const fr_build_node *n) {
  uint32_t li = (uint32_t)c->b->nleaves++;
  fr_tri4 *blk = &c->b->tris[li];
  for (int l = 0; l < 4; l++) {
    if ((uint32_t)l < n->count) {
      uint32_t prim = c->t->prims[n->first + l];
      const uint32_t *ix = c->m->idx + 3 * (size_t)prim;
      for (int a = 0; a < 3; a++) {
        blk->v0[a][l] = c->m->pos[3 * (size_t)ix[0] + a];
        blk->v1[a][l] = c->m->pos[3 * (size_t)ix[1] + a];
        blk->v2[a][l] = c->m->pos[3 * (size_t)ix[2] + a];
      }
      blk->prim[l] = prim;
    } else {
      for (int a = 0; a < 3; a++) blk->v0[a][l] = blk->v1[a][l] = blk->v2[a][l] = NAN;
      blk->prim[l] = FR_INVALID_ID;
    }
  }
  return FR_BVH4_LEAF | li;
}

/* Collapses the binary tree: a node adopts the children of its largest child
 * that holds more than one triangle until it has four children (Embree's BVH4
 * builders do the same); children of at most four triangles become leaves. */
static uint32_t convert(conv *c, int32_t bi, int depth) {
  const fr_build_node *n = &c->t->nodes[bi];
  if (depth > c->b->depth) c->b->depth = depth;
  if (n->count <= FR_BUILD_MAX_LEAF) return make_leaf(c, n);
  int32_t kids[4] = {n->left, n->right, -1, -1};
  int nk = 2;
  while (nk < 4) {
    int best = -1;
    float area = -1.0f;
    for (int k = 0; k < nk; k++) {
      const fr_build_node *ch = &c->t->nodes[kids[k]];
      if (ch->left >= 0 && aabb_half_area(ch->box) > area) { area = aabb_half_area(ch->box); best = k; }
    }
    if (best < 0) break;
    const fr_build_node *ch = &c->t->nodes[kids[best]];
    kids[best] = ch->left;
    kids[nk++] = ch->right;
  }
  uint32_t self = (uint32_t)c->b->nnodes++;
  fr_bvh4_node *d = &c->b->nodes[self];
  d->nchildren = (uint32_t)nk;
  for (int k = 0; k < 4; k++) {
    if (k < nk) {
      aabb bx = c->t->nodes[kids[k]].box;
      d->lo_x[k] = bx.lo.x; d->hi_x[k] = bx.hi.x;
      d->lo_y[k] = bx.lo.y; d->hi_y[k] = bx.hi.y;
      d->lo_z[k] = bx.lo.z; d->hi_z[k] = bx.hi.z;
    } else {
      d->lo_x[k] = d->lo_y[k] = d->lo_z[k] = INFINITY;
      d->hi_x[k] = d->hi_y[k] = d->hi_z[k] = -INFINITY;
      d->child[k] = FR_BVH4_EMPTY;
    }
  }
  for (int k = 0; k < nk; k++) {
    uint32_t r = convert(c, kids[k], depth + 1);
    c->b->nodes[self].child[k] = r;
  }
  return self;
}

fr_error fr_bvh4_from_build(const fr_build_tree *t, const fr_mesh *m, fr_bvh4 *out) {
  memset(out, 0, sizeof *out);
  size_t leaves = t->nprims, inner = t->nprims;
  out->nodes = fr_alloc_aligned(fr_mul_size(inner, sizeof(fr_bvh4_node)), 64);
  out->tris = fr_alloc_aligned(fr_mul_size(leaves, sizeof(fr_tri4)), 64);
  if (!out->nodes || !out->tris) {
    fr_bvh4_free(out);
    return fr_fail(FR_ERR_NOMEM, "BVH4: out of memory");
  }
  out->bounds = t->nodes[0].box;
  conv c = {t, m, out};
  out->root = convert(&c, 0, 1);
  return FR_OK;
}

void fr_bvh4_free(fr_bvh4 *b) {
  fr_free_aligned(b->nodes);
  fr_free_aligned(b->tris);
  memset(b, 0, sizeof *b);
}

static double slot_area(const fr_bvh4_node *n, int k) {
  double dx = n->hi_x[k] - n->lo_x[k], dy = n->hi_y[k] - n->lo_y[k], dz = n->hi_z[k] - n->lo_z[k];
  return dx * dy + dy * dz + dz * dx;
}

static int leaf_count(const fr_bvh4 *b, uint32_t ref) {
  const fr_tri4 *t = &b->tris[ref & ~FR_BVH4_LEAF];
  int n = 0;
  for (int l = 0; l < 4; l++) n += t->prim[l] != FR_INVALID_ID;
  return n;
}

/* SAH with a node visit (four box tests) and a triangle test both costing 1. */
double fr_bvh4_sah(const fr_bvh4 *b, double *node_fill, double *leaf_fill) {
  double root = aabb_half_area(b->bounds);
  size_t kids = 0, tris = 0;
  double cost = (b->root & FR_BVH4_LEAF) ? leaf_count(b, b->root) : 1.0;
  if (b->root & FR_BVH4_LEAF) tris += (size_t)leaf_count(b, b->root);
  for (size_t i = 0; i < b->nnodes; i++) {
    const fr_bvh4_node *n = &b->nodes[i];
    kids += n->nchildren;
    for (uint32_t k = 0; k < n->nchildren; k++) {
      double w = root > 0.0 ? slot_area(n, (int)k) / root : 0.0;
      uint32_t r = n->child[k];
      if (r & FR_BVH4_LEAF) {
        int c = leaf_count(b, r);
        tris += (size_t)c;
        cost += w * c;
      } else {
        cost += w;
      }
    }
  }
  if (node_fill) *node_fill = b->nnodes ? (double)kids / (double)b->nnodes : 0.0;
  if (leaf_fill) *leaf_fill = b->nleaves ? (double)tris / (double)b->nleaves : 0.0;
  return cost;
}
