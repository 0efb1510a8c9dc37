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
/* The library's version, "MAJOR.MINOR", and its build: the ISAs compiled
 * in, as "0.1 (avx512 avx2 scalar)". Compare with the macros to detect a
 * header and a library from different releases. */
const char *fr_version(void);

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
  char map_kd[512];      /* map_Kd: the diffuse colour's texture file, resolved and confined to the
                            scene's folder ("" for none) */
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
/* A scene from the caller's buffers: vertex i's x, y, z are the first 3
 * floats at positions + i * vertex_stride bytes, triangle j's indices the
 * first 3 at indices + j * index_stride (a stride of 0: tightly packed).
 * Copied, or with FR_SHARE_BUFFERS (tightly packed buffers only) used in
 * place: the scene then reads them until fr_scene_release, and the caller
 * keeps them alive and unchanged until then (the BVH is built on them).
 * Errors: FR_ERR_ARG (NULL, strides that are not whole records, sharing
 * strided buffers, unknown flags), FR_ERR_FORMAT (an index out of range, a
 * non-finite vertex, no triangles), FR_ERR_NOMEM. */
#define FR_SHARE_BUFFERS 1u
fr_error fr_scene_from_buffers(const float *positions, size_t nverts, size_t vertex_stride, const uint32_t *indices,
                               size_t ntris, size_t index_stride, unsigned flags, fr_scene **out);
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
/* The material showcase: six unit spheres (materials lambert, plastic,
 * chrome, gold, glass, carpaint) on a floor (material "floor") at y = 0. */
fr_error fr_scene_builtin_materials(fr_scene **out);

/* Smooth shading normals for the triangles whose file gives none (OBJ vn,
 * PLY nx ny nz and Assimp's are kept): angle-weighted vertex normals shared
 * between faces within crease_deg (0..180) of each other, so edges sharper
 * than that stay sharp. Before the commit (FR_ERR_STATE after). The
 * renderers shade with them; tracing never uses them. */
fr_error fr_scene_smooth(fr_scene *s, float crease_deg);

/* Builds the acceleration structures; must be called before tracing.
 * Triangles that are degenerate or too small for float arithmetic (edge
 * cross products that underflow) are left out (fr_scene_skipped_triangles);
 * a scene reaching beyond FR_MAX_COORDINATE from the origin is refused with
 * FR_ERR_UNSUPPORTED, rather than traced wrongly. */
#define FR_MAX_COORDINATE 1e11f
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
  fr_wide_stats bvh4, bvh8;      /* bvh4: zeros unless a 4-wide layout was asked for */
  size_t references;             /* triangles in the BVHs' leaves: more than the scene's where
                                    long thin ones were split into pieces before the build */
  double build_seconds;          /* fr_scene_commit: SAH build + the layouts it makes */
  int single_width;              /* the BVH width fr_intersect1 traverses: 8 (4 for measurements) */
} fr_bvh_stats;
fr_error fr_scene_stats(const fr_scene *s, fr_bvh_stats *out);

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
 * traverses the 8-wide BVH together and,
 * when few of its rays are left in a subtree, continues them one by one (the
 * hybrid of Benthin et al.). Answers agree with
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
 * group of 16 whose directions are coherent is traced as a hybrid packet;
 * the other rays of the octant go as ray streams of up to 64. An occlusion
 * call whose packets reach most leaves with at most half of their rays
 * (rays that part at the scale of the triangles) sends its remaining
 * groups as ray streams too; the choice rests on the call's rays alone.
 * Order rays so that neighbours are coherent to profit (for example, pixels
 * in 4x4 blocks). The other modes trace consecutive rays together, unsorted. */
void fr_intersect_stream(const fr_scene *s, const fr_ray *rays, fr_hit *hits, size_t n);
void fr_occluded_stream(const fr_scene *s, const fr_ray *rays, uint8_t *occluded, size_t n);

/* How fr_intersect_stream, fr_occluded_stream and fr_intersect16 trace: the
 * choice of Table VIII of the MIC paper. Every mode gives the same answers
 * (t, and the triangle up to which of two that meet the ray at one t, at a
 * shared edge or where two cross, it reports; u and v to rounding); only
 * speed differs. Within a mode the same ray gets the same t, u and v bits
 * every time, on every thread, and the same triangle but at such a tie in
 * FR_TRACE_HYBRID16 and FR_TRACE_AUTO, whose per-thread tuning may trace it
 * in the packet or the single-ray phase. Set it while no thread traces the
 * scene. */
typedef enum fr_trace_mode {
  FR_TRACE_AUTO,      /* default: coherent groups of 16 as hybrid packets, the rest sorted by
                         octant into hybrid packets or ray streams */
  FR_TRACE_SINGLE,    /* every ray alone */
  FR_TRACE_PACKET8,   /* packets of 8 consecutive rays, no single-ray phase */
  FR_TRACE_PACKET16,  /* packets of 16 consecutive rays, no single-ray phase */
  FR_TRACE_HYBRID16,  /* packets of 16 dropping to single rays when few rays are left in a subtree */
  FR_TRACE_RAYSTREAM  /* sorted by octant, then groups of up to 64 rays traverse together, each
                         ray tested alone (ray streams) */
} fr_trace_mode;

/* FR_ERR_ARG for a NULL scene or an unknown mode. */
fr_error fr_scene_set_trace_mode(fr_scene *s, fr_trace_mode mode);
fr_trace_mode fr_scene_get_trace_mode(const fr_scene *s);

/* ---- every hit along a ray ------------------------------------------------------
 * For each of the n rays, every triangle it crosses in (tnear, tfar), in
 * order of t (ties by triangle number), each triangle once: a ray through
 * an edge or vertex shared by consistently oriented triangles crosses
 * exactly one of them, so counts[i] is the number of times ray i passes
 * through a closed surface (odd from inside, even from outside). The first
 * min(counts[i], max_hits) crossings go to hits[i * max_hits ...], t being
 * the plane's distance in double rounded once; the rest of ray i's
 * max_hits slots read as misses. max_hits may be 0 (hits may then be NULL)
 * to count only. The answers are the same in every trace mode and on every
 * thread. Caller-owned arrays; may be called from several threads at once.
 * Errors: FR_ERR_ARG (NULL arrays, n * max_hits overflowing), FR_ERR_STATE
 * (not committed), FR_ERR_UNSUPPORTED (the scene has spheres),
 * FR_ERR_NOMEM. */
fr_error fr_intersect_all(const fr_scene *s, const fr_ray *rays, size_t n, fr_hit *hits, size_t max_hits,
                          uint32_t *counts);

/* ---- camera rays by multi-frusta --------------------------------------------------
 * A pinhole camera: eye looking at `at`, `up` roughly up, vertical field of
 * view fov_deg (0..180) over height pixels, square pixels, rays through the
 * pixel centres, row 0 at the top. */
typedef struct fr_pinhole {
  float eye[3], at[3], up[3];
  float fov_deg;
  int width, height;
} fr_pinhole;

/* The closest hits of the camera rays of image rows [y0, y0 + rows), traced
 * as multi-frusta (Benthin & Wald): 16x16 pixel tiles as 16 frusta of 4x4
 * rays, made from the camera on the fly; pixels of 4x4 blocks the image
 * cuts off go as single rays. hits[(y - y0) * width + x] is pixel (x, y);
 * rays (may be NULL) gets the rays traced, directions normalized, and hits'
 * t is in units of them. Each answer is the one fr_intersect1 gives for that
 * ray (t to rounding; the triangle up to ties). Bands of 16 rows starting at
 * multiples of 16 waste no work; threads may trace different bands of one
 * image at once. flags: FR_CAMERA_NO_NORMALS leaves ng zero (it costs a
 * fetch of the triangle per pixel). Caller-owned arrays. Errors:
 * FR_ERR_ARG (NULL, a bad camera, rows outside the image, unknown flags),
 * FR_ERR_STATE (not committed), FR_ERR_UNSUPPORTED (the scene has
 * spheres). */
#define FR_CAMERA_NO_NORMALS 1u
fr_error fr_intersect_camera(const fr_scene *s, const fr_pinhole *camera, int y0, int rows, unsigned flags,
                             fr_ray *rays, fr_hit *hits);

/* Answers as arrays, element i for ray or pixel i: the layout numpy and
 * other array code hold. A NULL member is not written. */
typedef struct fr_hit_arrays {
  float *t;        /* +inf on a miss */
  float *u, *v;    /* as fr_hit's */
  uint32_t *prim;  /* FR_INVALID_ID on a miss */
  float *ng;       /* 3 per element: fr_hit's ng, zero on a miss */
  float *dir;      /* 3 per element: the ray's unit direction (its origin is the eye) */
} fr_hit_arrays;

/* fr_intersect_camera's answers written as arrays: element
 * (y - y0) * width + x of each member of out is pixel (x, y). The same
 * rays, answers and bands as fr_intersect_camera, without the records in
 * between; normals are fetched only where out->ng is set. Caller-owned
 * arrays; may be called from several threads at once (on different
 * arrays). Errors: as fr_intersect_camera's (FR_ERR_ARG for a NULL out). */
fr_error fr_intersect_camera_arrays(const fr_scene *s, const fr_pinhole *camera, int y0, int rows,
                                    const fr_hit_arrays *out);

/* Whether each of n points (xyz, 3 floats each) is in shadow of a point
 * light: occluded[i] = 1 if a triangle or sphere lies on the segment from
 * light to points[i], leaving out its last eps (scene units; for a point on
 * a surface) and its first 1e-4 of the length (for a light on one). Traced
 * from the light as multi-frusta (16 consecutive points make a frustum),
 * so order the points coherently: an image's hit points in 4x4 blocks or
 * rows. The answers are those of fr_occluded1 on the same segments. A
 * point nearer than eps, or not finite, is not occluded. May be called from
 * several threads at once. Errors: FR_ERR_ARG (NULL, a light or eps not
 * finite), FR_ERR_STATE (not committed). */
fr_error fr_occluded_point_light(const fr_scene *s, const float light[3], const float *points, size_t n, float eps,
                                 uint8_t *occluded);

/* The fraction of a quad area light (corner + a e1 + b e2, a and b in
 * [0, 1)) each of n points sees: visibility[i] from `samples` shadow rays
 * (a multiple of 16 in 16..4096: per pass of 16, one stratified 4x4 over
 * the whole quad from the interleaved sets of a (0,2)-net scrambled by
 * seed + pass). Traced as multi-frusta (Benthin & Wald): a point's 16 rays
 * a frustum, 16 consecutive points a batch, so give neighbouring points
 * together (an image's hit points in 4x4 blocks); where frusta meet many
 * small triangles, a run of 256 points goes as ray streams. A ray leaves
 * out eps (scene units) at the point and 1e-4 of the way at the light. A
 * point not finite gets 0. Each ray's answer is fr_occluded1's on that ray
 * up to rounding at edges. May be called from several threads at once.
 * Errors: FR_ERR_ARG (NULL, samples, a light or eps not finite),
 * FR_ERR_STATE, FR_ERR_NOMEM. */
fr_error fr_visibility_area_light(const fr_scene *s, const float corner[3], const float e1[3], const float e2[3],
                                  const float *points, size_t n, int samples, uint64_t seed, float eps,
                                  float *visibility);

/* ---- rendering --------------------------------------------------------------------
 * frusta's renderers behind one handle: a camera, a shade mode and its
 * options, progressive passes, and the image with its guides (AOVs). */
typedef enum fr_render_shade {
  FR_RENDER_EYELIGHT,   /* headlight shading: one pass */
  FR_RENDER_NORMALS,    /* the normal as colour: one pass */
  FR_RENDER_SHADOWS,    /* a point light's hard shadows: one pass */
  FR_RENDER_SOFTSHADOW, /* an area light's soft shadows by multi-frusta: spp 16 is the filtered
                          real-time frame, more are passes of 16 spread samples summed */
  FR_RENDER_WHITTED,    /* mirrors, glass and shadows (Whitted): one pass */
  FR_RENDER_AO,         /* ambient occlusion: 16 hemisphere rays a pass */
  FR_RENDER_PATH        /* path tracing (materials from the MTL, environment and area light) */
} fr_render_shade;

/* The path tracer's sample patterns. */
typedef enum fr_render_sampler {
  FR_SAMPLER_HAMMERSLEY, /* padded replication of a scrambled Hammersley pattern (the MIC paper's) */
  FR_SAMPLER_SOBOL       /* scrambled Sobol points */
} fr_render_sampler;

/* The lights that shine on the path tracer's paths (fr_render_desc.lights). */
#define FR_LIGHT_ENV 1u   /* the environment */
#define FR_LIGHT_AREA 2u  /* the quad area light */
#define FR_LIGHT_POINT 4u /* the point light */

/* What a renderer draws. Begin with fr_render_desc_default, which sets
 * every field to its default (given in brackets), then change what you
 * need: a field left zero means zero, not its default. The strings are
 * copied by fr_renderer_new and fr_renderer_update. */
typedef struct fr_render_desc {
  fr_pinhole camera;      /* the view; fov_deg 0: the scene's own view (the shared scenes'
                             views, else one framing its bounds) at camera.width x camera.height
                             [fov_deg 0; the size 0 by 0: set it] */
  fr_render_shade shade;  /* [FR_RENDER_EYELIGHT] */
  int spp;                /* samples per pixel in all: path samples, ao's hemisphere and
                             softshadow's light samples (multiples of 16 for those two) [16] */
  int has_light;          /* 1: light is the point light (shadows, whitted, path's FR_LIGHT_POINT);
                             0: the scene's view's [0] */
  float light[3];
  const char *environment; /* path: a lat-long .hdr or .exr environment [NULL: env_color] */
  float exposure;         /* path: stops, for fr_renderer_image's display values [0] */
  int denoise;            /* 1: fr_renderer_image denoises path, ao and softshadow sums [0] */
  int threads;            /* [0: all cores] */
  float light_intensity[3]; /* path: the point light's intensity, W/sr [0: as bright as makes a white
                             surface where the camera looks, facing it, as bright as under a white sky] */
  int has_area;           /* 1: the quad area light is area_corner + a area_e1 + b area_e2 (a, b in
                             [0, 1]), shining from the side area_e1 x area_e2 faces; 0: the view's [0] */
  float area_corner[3], area_e1[3], area_e2[3];
  float area_radiance[3]; /* path: the area light's radiance [0: automatic, as light_intensity] */
  unsigned lights;        /* path: the lights that shine, FR_LIGHT_* [FR_LIGHT_ENV | FR_LIGHT_AREA] */
  float env_color[3];     /* path: the environment's radiance without a file [1, 1, 1] */
  float env_intensity;    /* path: scales the environment [1] */
  float env_rotate;       /* path: the environment turned about the view's up, degrees [0] */
  const char *mirror;     /* path, whitted: comma-separated names of the scene's materials made
                             mirrors (chrome) [NULL: the scene's suggestions] */
  const char *glass;      /* the same for glass [NULL] */
  int max_depth;          /* path: segments per path, 1..64 [13]; whitted: reflection and refraction
                             depth, 1..8 [4]; 0: the shade's default */
  fr_render_sampler sampler; /* path [FR_SAMPLER_HAMMERSLEY] */
  uint32_t seed;          /* path: the sampler's scramble [1] */
  float aperture;         /* path: the thin lens's radius, scene units [0: a pinhole] */
  float focus;            /* path: the distance in focus [0: from the eye to camera.at] */
  int temporal;           /* path, ao: after fr_renderer_set_camera, blend the last image carried to the
                             new view into the new one while it has few passes (SVGF's reprojection) [0] */
  int camera_frusta;      /* 1: camera rays, hard and soft shadows as multi-frusta where the scene has
                             no spheres (path: the shadow rays from the camera's hits to the point
                             light); 0: every ray as the scene's trace mode [1] */
  int pass_spp;           /* path: samples per pixel one pass adds, at least 1 [8]; 1 suits an
                             interactive frame. Any split sums to the same image. */
} fr_render_desc;

/* The defaults, as listed above. */
void fr_render_desc_default(fr_render_desc *d);
/* The description a scene file gives (docs/scenefile.md): the defaults,
 * with what the file s was loaded from sets (camera, lens, size, shade,
 * spp, max_depth, sampler, seed, lights and their brightness, which
 * lights shine, the environment); the camera fields it leaves out are the
 * scene's own view's. For a scene not loaded from a scene file, the
 * defaults. The strings point into s. Errors: FR_ERR_ARG (NULL),
 * FR_ERR_STATE (not committed: the scene's own view needs its bounds),
 * FR_ERR_FORMAT (a shade or sampler the file names that frusta lacks). */
fr_error fr_render_desc_of_scene(const fr_scene *s, fr_render_desc *d);

typedef struct fr_renderer fr_renderer;

/* A renderer of s as d says (the environment is loaded now, materials
 * and textures made). s must be committed and outlive the renderer. A
 * scene loaded from a scene file renders with the file's materials.
 * Errors: FR_ERR_ARG (an empty image, a bad camera, shade or light, a
 * field out of range, spp not a multiple of 16 where it must be, an
 * unknown mirror or glass name), FR_ERR_STATE (not committed), FR_ERR_IO
 * and FR_ERR_FORMAT (the environment, a texture), FR_ERR_NOMEM. */
fr_error fr_renderer_new(const fr_scene *s, const fr_render_desc *d, fr_renderer **out);
void fr_renderer_release(fr_renderer *r);
/* Renders as d says from now on, keeping what it can: a new exposure,
 * denoise, temporal, threads or pass_spp keeps the passes summed; a new camera of
 * the same size starts the passes again (as fr_renderer_set_camera); any
 * other change starts afresh, reusing the environment and materials where
 * their fields are unchanged. On an error the renderer is as before. The
 * errors of fr_renderer_new. */
fr_error fr_renderer_update(fr_renderer *r, const fr_render_desc *d);
/* The description the renderer follows (its strings live as long as it
 * or the next update). */
void fr_renderer_desc(const fr_renderer *r, fr_render_desc *d);
/* One more pass on all the renderer's threads; *done (may be NULL) becomes
 * 1 once another pass would change nothing (spp reached; at once for the
 * one-pass shades). A pass abandoned by fr_renderer_set_cancel adds
 * nothing (a path pass's partial sums are dropped: the passes start again).
 * FR_ERR_NOMEM. */
fr_error fr_renderer_pass(fr_renderer *r, int *done);
/* Passes until done. */
fr_error fr_renderer_render(fr_renderer *r);
/* 1 once another pass would change nothing. */
int fr_renderer_done(const fr_renderer *r);
/* While cancel is 1, a pass under way stops at its next tile and passes
 * started do nothing; 0 lets them run again. The one call that may come
 * from another thread while fr_renderer_pass runs (for an interactive
 * viewer whose input makes the frame in flight worthless). */
void fr_renderer_set_cancel(fr_renderer *r, int cancel);
/* Samples per pixel summed so far. */
int fr_renderer_spp(const fr_renderer *r);
/* A new view of the same image size: the passes start again (and with
 * temporal set, the next images blend in the last one). FR_ERR_ARG for a
 * bad camera or another size. */
fr_error fr_renderer_set_camera(fr_renderer *r, const fr_pinhole *camera);
/* The image so far, width * height RGB floats, row 0 at the top: linear
 * (display 0), or display values (display 1: path through the filmic
 * curve at the exposure; the other shades are in [0, 1] already), blended
 * and denoised where asked. albedo and normal (3 floats a pixel) and depth
 * (1; 1e30 where the camera sees nothing) get the guides when not NULL.
 * FR_ERR_NOMEM. */
fr_error fr_renderer_image(fr_renderer *r, int display, float *rgb, float *albedo, float *normal, float *depth);

typedef struct fr_render_stats {
  uint64_t rays;          /* traced by the last pass */
  double seconds;         /* the last pass's time */
  double denoise_seconds; /* the last fr_renderer_image's denoising */
  int cancelled;          /* 1: the last pass was abandoned */
  float reused;           /* temporal: the share of the last image's pixels blended with the one before */
} fr_render_stats;
void fr_renderer_stats(const fr_renderer *r, fr_render_stats *out);
/* A renderer serves one thread at a time, but for fr_renderer_set_cancel. */

/* ---- images ------------------------------------------------------------------------
 * Writes width * height RGB floats (row 0 at the top) by path's extension:
 * .png 8-bit sRGB of the values clamped to [0, 1] (display values, as
 * fr_renderer_image gives with display 1); .exr linear half floats; .pfm
 * linear floats. The file appears whole or not at all. May be called from
 * several threads at once. Errors: FR_ERR_ARG (NULL, an empty image, an
 * unknown extension), FR_ERR_IO, FR_ERR_NOMEM. */
fr_error fr_image_save(const char *path, int width, int height, const float *rgb);

#ifdef __cplusplus
}
#endif
#endif
