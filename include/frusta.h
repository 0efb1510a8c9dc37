/*
 * frusta: a real-time ray tracing library for CPUs.
 *
 * Public API. Every symbol is prefixed fr_. Handles are opaque. Functions that
 * can fail return an fr_error; on failure fr_last_error() holds a one-line
 * message (per thread) naming the problem.
 *
 *   fr_scene *s;
 *   if (fr_scene_load("dragon.ply.zst", &s) != FR_OK) { puts(fr_last_error()); ... }
 *   if (fr_scene_commit(s) != FR_OK) ...
 *   fr_ray r = {{0,0,-1}, 0.0f, {0,0,1}, INFINITY};
 *   fr_hit h;
 *   fr_intersect1(s, &r, &h);   // h.prim == FR_INVALID_ID on a miss
 *   fr_scene_release(s);
 */
#ifndef FRUSTA_H
#define FRUSTA_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define FR_VERSION_MAJOR 0
#define FR_VERSION_MINOR 1

#define FR_INVALID_ID 0xFFFFFFFFu

typedef enum fr_error {
  FR_OK = 0,
  FR_ERR_ARG,         /* an argument is invalid (NULL, zero size, unknown name) */
  FR_ERR_IO,          /* a file could not be opened, read or written */
  FR_ERR_FORMAT,      /* a file is malformed, truncated or lies about its counts */
  FR_ERR_NOMEM,       /* an allocation failed or a size would overflow */
  FR_ERR_UNSUPPORTED, /* the request is valid but not supported here */
  FR_ERR_STATE        /* the object is not in the state the call needs */
} fr_error;

/* The message of the last failing call on this thread ("" if none). */
const char *fr_last_error(void);
const char *fr_error_name(fr_error e);

/* ---- instruction set ------------------------------------------------------
 * Kernels exist for AVX-512, AVX2 and plain C. At start-up the best one the CPU
 * supports is chosen; the environment variable FRUSTA_ISA=avx512|avx2|scalar
 * forces one. fr_set_isa changes it for the whole process. */
typedef enum fr_isa { FR_ISA_SCALAR = 0, FR_ISA_AVX2 = 1, FR_ISA_AVX512 = 2 } fr_isa;
fr_error fr_set_isa(fr_isa isa);   /* FR_ERR_UNSUPPORTED if the CPU lacks it */
fr_isa fr_get_isa(void);
const char *fr_isa_name(fr_isa isa);
int fr_isa_supported(fr_isa isa);

/* ---- scenes ---------------------------------------------------------------- */
typedef struct fr_scene fr_scene;

typedef struct fr_material {
  char name[64];
  float diffuse[3];      /* Kd */
  float specular[3];     /* Ks */
  float shininess;       /* Ns */
  float transmission[3]; /* Tf, or 1-d */
  float ior;             /* Ni */
  float emission[3];     /* Ke */
  int illum;             /* MTL illumination model (3: mirror reflection), 0 if not given */
} fr_material;

/* Loads a scene file: PLY and OBJ(+MTL) by frusta's own readers (triangle
 * numbers follow the file's face order after fan triangulation), any other
 * format Assimp reads through Assimp. A trailing .zst is decompressed
 * transparently (also for the MTL an OBJ names). */
fr_error fr_scene_load(const char *path, fr_scene **out);
/* The procedural built-in scene (spheres and boxes on a floor, ~300K triangles). */
fr_error fr_scene_builtin(fr_scene **out);
/* A scene from arrays (copied). idx holds 3 indices per triangle. */
fr_error fr_scene_from_arrays(const float *xyz, size_t nverts, const uint32_t *idx,
                              size_t ntris, fr_scene **out);
/* An empty scene, for adding spheres and materials to. */
fr_error fr_scene_new(fr_scene **out);
void fr_scene_release(fr_scene *s);

/* ---- spheres -------------------------------------------------------------------
 * Analytic spheres beside the triangles, added before fr_scene_commit. A hit
 * on sphere i reports prim = fr_scene_triangle_count(s) + i, u = v = 0 and
 * ng = hit point - centre (length: the radius); from inside a sphere a ray
 * hits its far side. Every tracing call sees them. The multi-frusta kernels
 * (frusta bench --mode mft, render --shade softshadow) do not, and refuse
 * scenes with spheres. */
fr_error fr_scene_add_sphere(fr_scene *s, const float center[3], float radius, uint32_t material);
size_t fr_scene_sphere_count(const fr_scene *s);
int fr_scene_sphere(const fr_scene *s, size_t i, float center[3], float *radius); /* 0 if out of range */
/* Adds a material (or overwrites the one of the same name); its index in *index. */
fr_error fr_scene_add_material(fr_scene *s, const fr_material *m, uint32_t *index);
/* Material of any hit prim, triangle or sphere (FR_INVALID_ID if none). */
uint32_t fr_scene_prim_material(const fr_scene *s, uint32_t prim);
/* Unnormalized geometric normal of prim at point p (p matters for spheres);
 * 0 if prim is not in the scene. */
int fr_scene_geometric_normal(const fr_scene *s, uint32_t prim, const float p[3], float n[3]);
/* The procedural sphereflake (after Haines' SPD "balls"): depth 3 gives 820
 * spheres (mirror material "flake") above a floor of two triangles (material
 * "floor"), seen with spd_balls' view. depth 0..5. */
fr_error fr_scene_builtin_sphereflake(int depth, fr_scene **out);

/* Builds the acceleration structures; must be called before tracing. */
fr_error fr_scene_commit(fr_scene *s);

size_t fr_scene_triangle_count(const fr_scene *s);
size_t fr_scene_vertex_count(const fr_scene *s);
const float *fr_scene_vertices(const fr_scene *s);    /* xyz per vertex */
const uint32_t *fr_scene_indices(const fr_scene *s);  /* 3 per triangle */
void fr_scene_bounds(const fr_scene *s, float lower[3], float upper[3]);
size_t fr_scene_material_count(const fr_scene *s);
const fr_material *fr_scene_material(const fr_scene *s, size_t i);
uint32_t fr_scene_triangle_material(const fr_scene *s, uint32_t prim); /* FR_INVALID_ID if none */
/* Triangles dropped from the BVH because they are degenerate or not finite. */
size_t fr_scene_skipped_triangles(const fr_scene *s);

/* SAH costs count a node visit (one SIMD test of all its boxes) as 1, and
 * a triangle test (sah) or a 4-triangle block test (sah_blocks, what the
 * 4-wide leaf test really costs) as 1, relative to the root's surface area. */
typedef struct fr_wide_stats {
  size_t inner, leaves;
  size_t node_bytes, tri_bytes;  /* nodes, leaf triangle blocks */
  double sah, sah_blocks;
  double node_fill;              /* mean children per inner node */
  double leaf_fill;              /* mean triangles per leaf */
  int depth;
  size_t packet_tri_bytes;       /* Shevtsov records the packet kernels test */
  size_t blocks;                 /* 4-triangle blocks: 1-3 per leaf by default */
  double block_fill;             /* mean triangles per block (of 4) */
} fr_wide_stats;

typedef struct fr_bvh_stats {
  size_t bvh2_inner, bvh2_leaves;
  double bvh2_sah, bvh2_leaf_fill;
  size_t bvh2_bytes;
  fr_wide_stats bvh4, bvh8;      /* bvh4: zeros until the BVH4 is built, which happens when a
                                    4-wide mode is chosen (fr_scene_set_bvh_width, packet_bvh_width) */
  size_t references;             /* triangles in the BVHs' leaves: more than the scene's where
                                    long thin ones were split into pieces before the build */
  double build_seconds;          /* fr_scene_commit: SAH build + the layouts it makes */
  int single_width;              /* the BVH fr_intersect1 uses: 4 or 8 */
} fr_bvh_stats;
fr_error fr_scene_stats(const fr_scene *s, fr_bvh_stats *out);

/* Which BVH the single-ray calls traverse: 8-wide (default, fastest on AVX2
 * and AVX-512) or 4-wide (the MIC paper's). FRUSTA_BVH_WIDTH=4|8 sets the
 * default. The BVH4 is built when first chosen, here or by packet_bvh_width
 * (after the commit that is a second SAH build: choose it before the
 * commit, or while no thread traces the scene). */
fr_error fr_scene_set_bvh_width(fr_scene *s, int width);

/* ---- single rays ----------------------------------------------------------- */
typedef struct fr_ray {
  float org[3];
  float tnear;
  float dir[3];   /* need not be normalized; t is in units of dir */
  float tfar;     /* may be +inf */
} fr_ray;

typedef struct fr_hit {
  float t;        /* +inf on a miss */
  float u, v;     /* barycentric weights of the triangle's 2nd and 3rd vertex */
  uint32_t prim;  /* triangle number in file order, FR_INVALID_ID on a miss */
  float ng[3];    /* unnormalized geometric normal (v1-v0) x (v2-v0) */
} fr_hit;

/* Closest hit with tnear < t < tfar. Rays with NaN fields or tnear > tfar miss. */
void fr_intersect1(const fr_scene *s, const fr_ray *ray, fr_hit *hit);
/* 1 if anything lies in (tnear, tfar), else 0. */
int fr_occluded1(const fr_scene *s, const fr_ray *ray);

/* ---- packets of 16 rays ------------------------------------------------------
 * Structure of arrays, one lane per ray. valid has bit i set for each ray i
 * to trace; lanes not in valid are neither read nor written. The packet
 * traverses the BVH together (8-wide by default, see packet_bvh_width) and,
 * when few of its rays are left in a subtree, continues them one by one (the
 * hybrid of Benthin et al.); the threshold is fr_trace_options.hybrid_threshold (or 16, see
 * hybrid_tune), or for a packet whose rays share a direction octant coherent_threshold if
 * smaller. Answers agree with
 * fr_intersect1's ray by ray (same t; the packet's triangle test is not
 * watertight, so a ray exactly through a shared edge may report either
 * triangle, or, rarely, miss where fr_intersect1 hits). See
 * examples/trace_packet.c. */
typedef struct fr_ray16 {
  float org_x[16], org_y[16], org_z[16], tnear[16];
  float dir_x[16], dir_y[16], dir_z[16], tfar[16];
} fr_ray16;

typedef struct fr_hit16 {
  float t[16], u[16], v[16];
  uint32_t prim[16];
  float ng_x[16], ng_y[16], ng_z[16];
} fr_hit16;

void fr_intersect16(const fr_scene *s, unsigned valid, const fr_ray16 *rays, fr_hit16 *hits);
/* Returns the mask of valid rays with anything in (tnear, tfar). */
unsigned fr_occluded16(const fr_scene *s, unsigned valid, const fr_ray16 *rays);

/* ---- streams ------------------------------------------------------------------
 * n independent rays. In FR_TRACE_AUTO mode the rays are sorted by direction
 * octant (in chunks of 1024, keeping their order within an octant) and each
 * group of 16 whose directions are coherent (stream_spread) is traced as a
 * hybrid packet (coherent_threshold); the other rays of the octant go as
 * ray streams of up to 64.
 * Order rays so that neighbours are coherent to profit (for example, pixels
 * in 4x4 blocks). The other modes trace consecutive rays together, unsorted. */
void fr_intersect_stream(const fr_scene *s, const fr_ray *rays, fr_hit *hits, size_t n);
void fr_occluded_stream(const fr_scene *s, const fr_ray *rays, uint8_t *occluded, size_t n);

/* How the stream and packet calls trace; for measurement and tuning. Set it
 * while no thread traces the scene. */
typedef enum fr_trace_mode {
  FR_TRACE_AUTO,      /* sorted by octant, then hybrid packets of 16 or ray streams */
  FR_TRACE_SINGLE,    /* every ray alone (BVH of fr_scene_set_bvh_width) */
  FR_TRACE_PACKET8,   /* packets of 8 on the BVH4, no single-ray phase */
  FR_TRACE_PACKET16,  /* packets of 16 on the BVH4, no single-ray phase */
  FR_TRACE_HYBRID16,  /* packets of 16 dropping to single rays (hybrid_threshold) */
  FR_TRACE_RAYSTREAM  /* sorted by octant, then groups of up to 64 rays traverse together,
                         each ray tested alone (ray streams); any hit and closest hit */
} fr_trace_mode;

typedef struct fr_trace_options {
  fr_trace_mode mode;     /* default FR_TRACE_AUTO */
  int hybrid_threshold;   /* 0..16, default 7 (the MIC paper's) */
  int packet_bvh_width;   /* 8 (default, measured faster) or 4 (the MIC paper's) */
  int mailbox;            /* inverse mailboxing in packet leaves (default off, see README) */
  int axis_aligned;       /* Shevtsov's axis-aligned fast path (default on) */
  int ia_cull;            /* interval-arithmetic culling of nodes for whole packets (default on) */
  int quad_leaves;        /* packet leaves reached by only a few active rays test four of them against
                             four triangles at once, with the single-ray kernel's watertight test
                             (default on, see docs/performance-log.md) */
  int prefetch;           /* rays and packets prefetch the children they defer: 1 on, 0 off, -1
                             (default) on for rays when the BVH and triangles exceed 32 MB, for
                             packets when the BVH and their triangle records exceed 32 MB (see
                             docs/performance-log.md) */
  float stream_spread;    /* FR_TRACE_AUTO: a group of 16 goes as a packet when its unit directions
                             lie within this distance of its first ray's (probed at 3 rays), else
                             in a ray stream; 0..2: 0 streams every group, 2 none (default
                             FR_STREAM_SPREAD_DEFAULT) */
  int coherent_threshold; /* packets known to be coherent drop to single rays at this many active
                             rays, 0..16 (default 2, as Embree's coherent packets): FR_TRACE_AUTO's
                             coherent groups, and FR_TRACE_HYBRID16's packets whose rays share a
                             direction octant (those take the smaller of the two thresholds) */
  int hybrid_tune;        /* 1 (default): FR_TRACE_HYBRID16's and fr_intersect16/fr_occluded16's
                             packets whose rays span several direction octants switch either at
                             hybrid_threshold or at once (every ray alone), whichever each thread
                             has measured to cost fewer cycles per ray on this scene; 0: always at
                             hybrid_threshold. Only speed depends on the choice, and the last
                             bits of u and v (t and the triangle are fr_intersect1's either way) */
  int occluder_cache;     /* 1 (default): FR_TRACE_SINGLE's fr_occluded_stream tests each ray that
                             ends (finite tfar: shadow rays) against the four triangles that
                             occluded the stream's last occluded ray before it traverses, while
                             that keeps paying; 0: never. Answers do not depend on it */
  int anyhit_order;       /* FR_TRACE_SINGLE's fr_occluded_stream: the order a ray's any-hit walk
                             visits the children it hits. -1 (default): rays that end (shadow
                             rays) go in chunks of 32, each by whichever order the thread has
                             measured to cost fewer cycles per ray on this scene (nearest first
                             only where it measured 10% cheaper), other rays by rank; 0: by the
                             builder's occlusion rank; 1: nearest first. Answers do not depend
                             on it */
} fr_trace_options;
#define FR_STREAM_SPREAD_DEFAULT 0.1f

void fr_trace_options_default(fr_trace_options *o);
fr_error fr_scene_set_trace_options(fr_scene *s, const fr_trace_options *o);
void fr_scene_get_trace_options(const fr_scene *s, fr_trace_options *o);

/* ---- reference paths (for tests and measurement, not speed) ---------------- */
/* Plain scalar traversal of the binary BVH with the scalar watertight test. */
void fr_intersect1_reference(const fr_scene *s, const fr_ray *ray, fr_hit *hit);
int fr_occluded1_reference(const fr_scene *s, const fr_ray *ray);

#ifdef __cplusplus
}
#endif
#endif
