/*
 * Traversal counters for reproducing the papers' tables: node visits, box
 * tests, triangle tests, leaf visits, rays. Compiled in only with
 * -DFRUSTA_COUNTERS=ON (cmake), so the measured kernels pay nothing otherwise.
 * Each thread counts into its own block; fr_counters_read sums them.
 */
#ifndef FR_TRACE_COUNTERS_H
#define FR_TRACE_COUNTERS_H
#include <stdint.h>

/* Single-ray work (also the hybrid's single-ray phase) counts one test per
 * ray and box or triangle; packet work counts SIMD tests (pk_*) and the
 * active rays in them (pk_*_lanes), and quad tests (pk_quad_tests: up to
 * four rays against a four-triangle block, trace/tri4_quad.h).
 * Multi-frusta work (mft_*): batches of 16 frusta, SIMD box tests (one
 * box, 16 frusta) and the active frusta in them, triangles fetched by
 * leaves, frustum-triangle pairs before and after the corner-ray cull
 * (each pair left is one 16-ray test), soft-shadow batches traced as rays
 * instead (render/soft_tile.c), tiles' shafts built and given up (too
 * many leaves), the child boxes their builds tested against a shaft
 * (mft_shaft_box_tests: one box against one tile's shaft) and the batches
 * traced through one (mft_shaft*). Large packets (lp_*): packets, stack
 * entries popped, boxes culled for the whole packet, 16-ray box tests,
 * leaves, prims (triangles and spheres) reached, triangles culled for the whole
 * packet, 16-ray triangle tests. Spheres: single-ray box and sphere tests
 * in the sphere tree (sp_*), spheres culled for a whole large packet,
 * 16-ray sphere tests. Single-ray streams' occluder cache: rays that tried
 * their stream's last occluder, and those it occluded (cache_*). */
#define FR_COUNTER_FIELDS(X)                                                   \
  X(rays) X(nodes) X(box_tests) X(leaves) X(tri_tests) X(tri_hit_tests) X(tri_plane_t) \
  X(packets) X(pk_nodes) X(pk_box_tests) X(pk_box_lanes) X(pk_tri_tests)       \
  X(pk_tri_lanes) X(pk_quad_tests) X(ia_culled) X(mailbox_hits) X(switches) X(switch_rays)    \
  X(mft_batches) X(mft_nodes) X(mft_box_tests) X(mft_box_lanes) X(mft_tris)   \
  X(mft_tri_frusta) X(mft_tri_left) X(mft_ray_batches) X(mft_stream_batches) X(mft_cached_leaves)  \
  X(mft_stopped_batches) X(mft_shafts) X(mft_shaft_fails) X(mft_shaft_box_tests) X(mft_shaft_batches) X(mft_plane_rays) X(mft_plane_frusta) X(mft_plane_whole) X(pk_plane_rays) X(cache_tries) X(cache_hits)                                   \
  X(lp_packets) X(lp_nodes) X(lp_culled) X(lp_box_chunks) X(lp_leaves) X(lp_tris) \
  X(lp_tri_culled) X(lp_tri_chunks)                                          \
  X(sp_box_tests) X(sp_tests) X(lp_sph_culled) X(lp_sph_chunks)

typedef struct fr_counters {
#define FR_COUNTER_DECL(f) uint64_t f;
  FR_COUNTER_FIELDS(FR_COUNTER_DECL)
#undef FR_COUNTER_DECL
} fr_counters;

#ifdef FRUSTA_COUNTERS
extern _Thread_local fr_counters fr_tls_counters;
void fr_counters_flush(void);   /* adds this thread's counts to the total */
#define FR_COUNT(field, n) (fr_tls_counters.field += (uint64_t)(n))
#else
#define FR_COUNT(field, n) ((void)0)
#endif

/* 1 if counters were compiled in. */
int fr_counters_enabled(void);
void fr_counters_reset(void);
fr_counters fr_counters_read(void);
/* acc += c, field by field */
void fr_counters_add(fr_counters *acc, const fr_counters *c);
#endif
