/*
 * The internal tuning interface: every switch that exists to measure or to
 * test, in one place, out of the public header. The tools (bench, stats)
 * and the tests set them; the library reads them here and nowhere else.
 *
 * Two kinds:
 *  - fr_tuning: how a scene's packets and streams are traced, per scene
 *    (fr_scene_set_tuning in api/scene.h; the public trace mode is its
 *    first field). Only speed depends on them, not the answers, except
 *    where a field says otherwise.
 *  - fr_env_tuning: process-wide overrides read from FRUSTA_* environment
 *    variables at the moment they apply (scene creation, commit, the
 *    first kernel call), so a test may set them between scenes.
 */
#ifndef FR_BASE_TUNING_H
#define FR_BASE_TUNING_H
#include "frusta.h"

typedef struct fr_tuning {
  fr_trace_mode mode;     /* the public trace mode (fr_scene_set_trace_mode) */
  int hybrid_threshold;   /* 0..16, default 7 (the MIC paper's) */
  int packet_bvh_width;   /* 8 (default, measured faster) or 4 (the MIC paper's) */
  int mailbox;            /* inverse mailboxing in packet leaves (default off: it never finds a repeat) */
  int axis_aligned;       /* Shevtsov's axis-aligned path (default on) */
  int ia_cull;            /* interval-arithmetic culling of nodes for whole packets (default on) */
  int quad_leaves;        /* packet leaves reached by a few active rays test four of them against four
                             triangles at once with the watertight test (default on) */
  int prefetch;           /* prefetching of deferred children: 1 on, 0 off, -1 (default) on for rays
                             when the BVH and triangles exceed 32 MB, for packets when the BVH and
                             their Shevtsov records do */
  float stream_spread;    /* FR_TRACE_AUTO: a group of 16 goes as a packet when its unit directions
                             lie within this distance of its first ray's (probed at 3 rays), else in
                             a ray stream; 0..2 (default FR_STREAM_SPREAD_DEFAULT) */
  int coherent_threshold; /* packets known to be coherent drop to single rays at this many active
                             rays, 0..16 (default 2): FR_TRACE_AUTO's coherent groups, and
                             FR_TRACE_HYBRID16's packets whose rays share a direction octant */
  int occluder_cache;     /* 1 (default): FR_TRACE_SINGLE's shadow streams first test the four
                             triangles that occluded the stream's last occluded ray; 0: never */
  int anyhit_order;       /* FR_TRACE_SINGLE's shadow streams: -1 (default) the child order each
                             thread measured cheaper per chunk of 32 rays, 0 the builder's occlusion
                             rank, 1 nearest first */
} fr_tuning;
#define FR_STREAM_SPREAD_DEFAULT 0.1f

/* The defaults above. */
void fr_tuning_default(fr_tuning *t);
/* FR_ERR_ARG (with a message) for a field out of its range. */
fr_error fr_tuning_check(const fr_tuning *t);

typedef struct fr_env_tuning {
  fr_isa isa;           /* FRUSTA_ISA=avx512|avx2|scalar ... */
  int isa_given;        /* ... 1 if set to one of those, -1 if set to anything else, 0 unset */
  int bvh_width;        /* FRUSTA_BVH_WIDTH=4|8: the single-ray BVH of new scenes (default 8) */
  int presplit;         /* FRUSTA_PRESPLIT=off|on: -1 (unset) lets the build decide */
  int planes;           /* FRUSTA_PLANES=off: 0, else 1 (find planar occluders at commit) */
  int leaf_blocks;      /* FRUSTA_LEAF_BLOCKS=1..8: blocks per BVH4/BVH8 leaf, 0 the default */
  int greedy_collapse;  /* FRUSTA_COLLAPSE=greedy: open the largest child rather than the optimal collapse */
  int tree_child_order; /* FRUSTA_CHILD_ORDER=tree: keep the collapse's child order */
} fr_env_tuning;

/* Reads the FRUSTA_* variables now. */
void fr_env_tuning_read(fr_env_tuning *e);
#endif
