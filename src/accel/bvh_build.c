#include "bvh_build.h"
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"

#define NBINS 32
#define PAR_BIN 65536   /* nodes with more primitives bin in parallel */
#define JOB_MIN 4096    /* below PAR_BIN, subtrees become jobs */
#define SMALL 12        /* nodes this small get an exact SAH sweep instead of bins */

typedef struct ref { aabb box; vec3 c2; uint32_t id; } ref; /* c2: twice the centroid */

typedef struct builder {
  ref *refs;
  fr_build_node *nodes;
} builder;

typedef struct bin { aabb box; uint32_t count; } bin;
typedef struct bins { bin b[3][NBINS]; } bins;

typedef struct split { int axis, pos; float cost; } split;

static inline int bin_of(float c, float lo, float scale) {
  int i = (int)((c - lo) * scale);
  return i < 0 ? 0 : i >= NBINS ? NBINS - 1 : i;
}

static void bins_clear(bins *b) {
  for (int a = 0; a < 3; a++)
    for (int i = 0; i < NBINS; i++) { b->b[a][i].box = aabb_empty(); b->b[a][i].count = 0; }
}

static void bins_add(bins *b, const ref *r, aabb cb, const float scale[3]) {
  for (int a = 0; a < 3; a++) {
    int i = bin_of(v3_get(r->c2, a), v3_get(cb.lo, a), scale[a]);
    b->b[a][i].box = aabb_merge(b->b[a][i].box, r->box);
    b->b[a][i].count++;
  }
}

/* The binned split of least SAH cost, in fr_build_blocks units (a node
 * visit costs 1). */
static split best_split(const bins *b, const float scale[3]) {
  split best = {-1, 0, INFINITY};
  for (int a = 0; a < 3; a++) {
    if (scale[a] <= 0.0f) continue;
    float rarea[NBINS];
    uint32_t rcount[NBINS];
    aabb acc = aabb_empty();
    uint32_t cnt = 0;
    for (int i = NBINS - 1; i > 0; i--) {
      acc = aabb_merge(acc, b->b[a][i].box);
      cnt += b->b[a][i].count;
      rarea[i] = aabb_half_area(acc);
      rcount[i] = cnt;
    }
    acc = aabb_empty();
    cnt = 0;
    for (int i = 1; i < NBINS; i++) {
      acc = aabb_merge(acc, b->b[a][i - 1].box);
      cnt += b->b[a][i - 1].count;
      if (cnt == 0 || rcount[i] == 0) continue;
      float cost = aabb_half_area(acc) * fr_build_blocks(cnt) + rarea[i] * fr_build_blocks(rcount[i]);
      if (cost < best.cost) { best.cost = cost; best.axis = a; best.pos = i; }
    }
  }
  return best;
}

static aabb centroid_bounds(const ref *refs, size_t b, size_t e) {
  aabb cb = aabb_empty();
  for (size_t i = b; i < e; i++) cb = aabb_grow(cb, refs[i].c2);
  return cb;
}

/* Partitions [b,e) by the split; returns the middle. Falls back to the index
 * median when no useful split exists (all centroids equal, or too deep). */
static size_t partition(ref *refs, size_t b, size_t e, split s, aabb cb, const float scale[3]) {
  if (s.axis < 0) return b + (e - b) / 2;
  size_t i = b, j = e;
  float lo = v3_get(cb.lo, s.axis), sc = scale[s.axis];
  while (i < j) {
    if (bin_of(v3_get(refs[i].c2, s.axis), lo, sc) < s.pos) i++;
    else { j--; ref t = refs[i]; refs[i] = refs[j]; refs[j] = t; }
  }
  if (i == b || i == e) return b + (e - b) / 2;
  return i;
}

static void make_scale(aabb cb, float scale[3]) {
  for (int a = 0; a < 3; a++) {
    float ext = v3_get(cb.hi, a) - v3_get(cb.lo, a);
    scale[a] = ext > 0.0f ? (float)NBINS * (1.0f - 1e-5f) / ext : 0.0f;
  }
}

/* Exact SAH for a few primitives: sort by centroid on each axis, sweep. */
static size_t small_split(ref *refs, size_t b, size_t e) {
  size_t n = e - b;
  float best = INFINITY;
  int best_axis = 0;
  size_t best_pos = n / 2;
  for (int a = 0; a < 3; a++) {
    for (size_t i = b + 1; i < e; i++) { /* insertion sort on axis a */
      ref x = refs[i];
      size_t j = i;
      while (j > b && v3_get(refs[j - 1].c2, a) > v3_get(x.c2, a)) { refs[j] = refs[j - 1]; j--; }
      refs[j] = x;
    }
    float left[SMALL];
    aabb acc = aabb_empty();
    for (size_t i = 0; i + 1 < n; i++) { acc = aabb_merge(acc, refs[b + i].box); left[i] = aabb_half_area(acc); }
    acc = aabb_empty();
    for (size_t i = n - 1; i >= 1; i--) {
      acc = aabb_merge(acc, refs[b + i].box);
      float cost = left[i - 1] * fr_build_blocks((uint32_t)i) + aabb_half_area(acc) * fr_build_blocks((uint32_t)(n - i));
      if (cost < best) { best = cost; best_axis = a; best_pos = i; }
    }
  }
  if (best_axis != 2) { /* restore the winning order */
    for (size_t i = b + 1; i < e; i++) {
      ref x = refs[i];
      size_t j = i;
      while (j > b && v3_get(refs[j - 1].c2, best_axis) > v3_get(x.c2, best_axis)) { refs[j] = refs[j - 1]; j--; }
      refs[j] = x;
    }
  }
  return b + best_pos;
}

/* Decides how node [b,e) splits; returns 0 for a single primitive, else the middle. */
static size_t decide(builder *bd, size_t b, size_t e, int depth, int parallel) {
  size_t n = e - b;
  if (n <= 1) return 0;
  if (n <= SMALL && depth < FR_BUILD_MAX_DEPTH) return small_split(bd->refs, b, e);
  ref *refs = bd->refs;
  aabb cb;
  float scale[3];
  bins bn;
  split s = {-1, 0, INFINITY};
  if (parallel) {
    cb = aabb_empty();
#pragma omp parallel
    {
      aabb local = aabb_empty();
#pragma omp for nowait
      for (size_t i = b; i < e; i++) local = aabb_grow(local, refs[i].c2);
#pragma omp critical
      cb = aabb_merge(cb, local);
    }
    make_scale(cb, scale);
    bins_clear(&bn);
#pragma omp parallel
    {
      bins *local = malloc(sizeof(bins));
      if (local) {
        bins_clear(local);
#pragma omp for nowait
        for (size_t i = b; i < e; i++) bins_add(local, &refs[i], cb, scale);
#pragma omp critical
        for (int a = 0; a < 3; a++)
          for (int k = 0; k < NBINS; k++) {
            bn.b[a][k].box = aabb_merge(bn.b[a][k].box, local->b[a][k].box);
            bn.b[a][k].count += local->b[a][k].count;
          }
        free(local);
      }
    }
    /* a failed scratch allocation would leave counts short: redo serially */
    uint32_t total = 0;
    for (int k = 0; k < NBINS; k++) total += bn.b[0][k].count;
    if (total != n) {
      bins_clear(&bn);
      for (size_t i = b; i < e; i++) bins_add(&bn, &refs[i], cb, scale);
    }
  } else {
    cb = centroid_bounds(refs, b, e);
    make_scale(cb, scale);
    bins_clear(&bn);
    for (size_t i = b; i < e; i++) bins_add(&bn, &refs[i], cb, scale);
  }
  if (depth < FR_BUILD_MAX_DEPTH) s = best_split(&bn, scale);
  return partition(refs, b, e, s, cb, scale);
}

static aabb range_box(const ref *refs, size_t b, size_t e) {
  aabb box = aabb_empty();
  for (size_t i = b; i < e; i++) box = aabb_merge(box, refs[i].box);
  return box;
}

static void make_leaf(builder *bd, size_t node, size_t b, size_t e) {
  fr_build_node *nd = &bd->nodes[node];
  nd->left = nd->right = -1;
  nd->first = (uint32_t)b;
  nd->count = (uint32_t)(e - b);
}

/* next: the job's next free node slot (see fr_build_sah) */
static void build_serial(builder *bd, size_t *next, size_t node, size_t b, size_t e, int depth) {
  size_t mid = decide(bd, b, e, depth, 0);
  if (!mid) { make_leaf(bd, node, b, e); return; }
  size_t c = *next;
  *next += 2;
  bd->nodes[node].left = (int32_t)c;
  bd->nodes[node].right = (int32_t)(c + 1);
  bd->nodes[node].first = (uint32_t)b;
  bd->nodes[node].count = (uint32_t)(e - b);
  bd->nodes[c].box = range_box(bd->refs, b, mid);
  bd->nodes[c + 1].box = range_box(bd->refs, mid, e);
  build_serial(bd, next, c, b, mid, depth + 1);
  build_serial(bd, next, c + 1, mid, e, depth + 1);
}

/* base, used: the job's block of node slots (fr_build_sah) */
typedef struct job { size_t node, b, e; int depth; size_t base, used; } job;
typedef struct jobs { job *v; size_t n, cap; } jobs;

static int jobs_push(jobs *js, job j) {
  if (js->n == js->cap) {
    size_t nc = js->cap ? 2 * js->cap : 64;
    job *q = realloc(js->v, nc * sizeof(job));
    if (!q) return 0;
    js->v = q;
    js->cap = nc;
  }
  js->v[js->n++] = j;
  return 1;
}

static int job_cmp(const void *x, const void *y) {
  size_t a = ((const job *)x)->e - ((const job *)x)->b, b = ((const job *)y)->e - ((const job *)y)->b;
  return a < b ? 1 : a > b ? -1 : 0;
}

fr_error fr_build_sah(const aabb *boxes, const uint32_t *ids, size_t n, fr_build_tree *out) {
  memset(out, 0, sizeof *out);
  if (n == 0) { /* one empty leaf: a scene of spheres only has no triangles */
    out->nodes = fr_alloc_aligned(sizeof(fr_build_node), 64);
    if (!out->nodes) return fr_fail(FR_ERR_NOMEM, "BVH build: out of memory");
    out->nodes[0] = (fr_build_node){aabb_empty(), -1, -1, 0, 0};
    out->nnodes = 1;
    return FR_OK;
  }
  builder bd;
  /* on 2 MiB pages where the kernel allows (fr_alloc_aligned): first
   * touches of 4 KiB pages were a fifth of a commit's time in this VM */
  bd.refs = fr_alloc_aligned(fr_mul_size(n, sizeof(ref)), 64);
  bd.nodes = fr_alloc_aligned(fr_mul_size(2 * n, sizeof(fr_build_node)), 64);
  jobs todo = {0}, stack = {0};
  if (!bd.refs || !bd.nodes) goto oom;
  size_t nnodes = 1;
#pragma omp parallel for schedule(static)
  for (size_t i = 0; i < n; i++) {
    bd.refs[i].box = boxes[i];
    bd.refs[i].c2 = aabb_center2(boxes[i]);
    bd.refs[i].id = ids[i];
  }
  aabb root = aabb_empty();
  for (size_t i = 0; i < n; i++) root = aabb_merge(root, boxes[i]);
  bd.nodes[0].box = root;

  /* Phase 1: split large nodes top-down (binning them with all threads) until
   * the pieces are small enough to be jobs. */
  if (!jobs_push(&stack, (job){0, 0, n, 0, 0, 0})) goto oom;
  while (stack.n) {
    job j = stack.v[--stack.n];
    size_t cnt = j.e - j.b;
    int par = cnt >= PAR_BIN;
    if (!par && (n >= PAR_BIN || cnt < JOB_MIN)) {
      if (!jobs_push(&todo, j)) goto oom;
      continue;
    }
    size_t mid = decide(&bd, j.b, j.e, j.depth, par);
    if (!mid) { make_leaf(&bd, j.node, j.b, j.e); continue; }
    size_t c = nnodes;
    nnodes += 2;
    bd.nodes[j.node].left = (int32_t)c;
    bd.nodes[j.node].right = (int32_t)(c + 1);
    bd.nodes[j.node].first = (uint32_t)j.b;
    bd.nodes[j.node].count = (uint32_t)cnt;
    bd.nodes[c].box = range_box(bd.refs, j.b, mid);
    bd.nodes[c + 1].box = range_box(bd.refs, mid, j.e);
    if (!jobs_push(&stack, (job){c + 1, mid, j.e, j.depth + 1, 0, 0})) goto oom;
    if (!jobs_push(&stack, (job){c, j.b, mid, j.depth + 1, 0, 0})) goto oom;
  }
  /* Phase 2: independent subtrees, largest first. Each job fills a block of
   * its own, sized for the most nodes its m primitives can need below its
   * root (2m - 2), and the blocks are closed up afterwards. Drawing nodes
   * from one shared counter instead put both threads' nodes side by side:
   * the counter and the nodes' cache lines went back and forth between
   * the cores, and those stores were three quarters of the subtree
   * builds' time on conference. The blocks fit: the phase-1 nodes and
   * every block together are at most 2n - 1 slots. */
  qsort(todo.v, todo.n, sizeof(job), job_cmp);
  for (size_t i = 0, at = nnodes; i < todo.n; i++) {
    todo.v[i].base = at;
    at += 2 * (todo.v[i].e - todo.v[i].b) - 2;
  }
#pragma omp parallel for schedule(dynamic, 1)
  for (size_t i = 0; i < todo.n; i++) {
    job *j = &todo.v[i];
    size_t next = j->base;
    build_serial(&bd, &next, j->node, j->b, j->e, j->depth);
    j->used = next - j->base;
  }
  /* close the gaps: blocks move down in order, their links with them */
  for (size_t i = 0; i < todo.n; i++) {
    const job *j = &todo.v[i];
    if (!j->used) continue;
    const int32_t shift = (int32_t)(j->base - nnodes);
    if (shift) {
      memmove(bd.nodes + nnodes, bd.nodes + j->base, j->used * sizeof(fr_build_node));
      for (size_t k = nnodes; k < nnodes + j->used; k++)
        if (bd.nodes[k].left >= 0) { bd.nodes[k].left -= shift; bd.nodes[k].right -= shift; }
      bd.nodes[j->node].left -= shift;
      bd.nodes[j->node].right -= shift;
    }
    nnodes += j->used;
  }

  out->nnodes = nnodes;
  out->nodes = bd.nodes;
  out->nprims = n;
  out->prims = malloc(fr_mul_size(n, sizeof(uint32_t)));
  if (!out->prims) goto oom;
  for (size_t i = 0; i < n; i++) out->prims[i] = bd.refs[i].id;
  fr_free_aligned(bd.refs); free(todo.v); free(stack.v);
  return FR_OK;
oom:
  fr_free_aligned(bd.refs); fr_free_aligned(bd.nodes); free(todo.v); free(stack.v);
  memset(out, 0, sizeof *out);
  return fr_fail(FR_ERR_NOMEM, "BVH build: out of memory for %zu primitives", n);
}

double fr_build_tree_sah(const fr_build_tree *t) {
  if (!t->nnodes) return 0.0;
  double root = aabb_half_area(t->nodes[0].box), sum = 0.0;
  if (!(root > 0.0)) return 0.0;
  for (size_t i = 0; i < t->nnodes; i++) sum += aabb_half_area(t->nodes[i].box) * (t->nodes[i].left < 0 ? t->nodes[i].count : 1);
  return sum / root;
}

void fr_build_tree_free(fr_build_tree *t) {
  fr_free_aligned(t->nodes);
  free(t->prims);
  memset(t, 0, sizeof *t);
}
