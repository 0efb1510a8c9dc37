/*
 * Scattering at a surface: the path tracer's materials. Each kind keeps its
 * sample, eval and pdf together in its own file (lambert.c, plastic.c,
 * metal.c, glass.c, carpaint.c); bsdf.c dispatches.
 *
 * Directions are in the shading frame: z is the surface normal, which for
 * the opaque kinds the caller turns to face wo (wo.z >= 0), and which for
 * glass is the outward normal (wo.z < 0 inside). eval returns f * |cos wi|
 * of the smooth lobes only, and their pdf in solid angle; a delta lobe
 * (a perfect mirror, a smooth coat, glass) is reached only by sampling.
 */
#ifndef FR_MATERIAL_BSDF_H
#define FR_MATERIAL_BSDF_H
#include "base/vec3.h"

/* GGX alpha (roughness^2) below which a metal is a perfect mirror */
#define FR_BSDF_MIRROR_ALPHA 1e-3f

typedef enum fr_bsdf_kind {
  FR_BSDF_LAMBERT,  /* diffuse */
  FR_BSDF_PLASTIC,  /* a smooth dielectric coat over Lambert, Fresnel-weighted */
  FR_BSDF_METAL,    /* a conductor, GGX roughness (0: a perfect mirror) */
  FR_BSDF_GLASS,    /* a smooth dielectric, Beer absorption inside */
  FR_BSDF_CARPAINT, /* a clear coat over metallic flakes over a coloured base */
  FR_BSDF_KINDS
} fr_bsdf_kind;

typedef struct fr_bsdf {
  fr_bsdf_kind kind;
  vec3 color;          /* Lambert, plastic: diffuse reflectance; car paint: the base colour */
  int color_tex;       /* the texture that gives color instead (path setup's textures), or -1 */
  vec3 emission;       /* radiance the surface emits (MTL Ke) */
  float ior;           /* glass; the coat of plastic and car paint */
  /* metal */
  vec3 eta, k;         /* complex index of refraction per RGB channel */
  float roughness;     /* metal, plastic's coat: GGX roughness (alpha = roughness^2); 0 a mirror */
  /* glass: the colour white light takes on after attenuation_distance inside */
  vec3 attenuation_color;
  float attenuation_distance;
  /* car paint, named as OSPRay's carPaint names them */
  float coat;              /* clear coat strength 0..1 */
  vec3 flake_color;        /* reflectance of the flakes at normal incidence */
  float flake_density;     /* fraction of the surface covered by flakes, 0..1 */
  float flake_scale;       /* flakes per unit length */
  float flake_spread;      /* how far flake normals tilt, 0..1 */
  float flake_jitter;      /* randomness of flake placement within their cells, 0..1 */
  float flake_roughness;   /* GGX roughness of a flake */
  vec3 flipflop_color;     /* the base colour seen at grazing angles */
  float flipflop_falloff;  /* 0..1: how soon the base colour gives way to it */
} fr_bsdf;

/* What a hit contributes to its material beyond the directions: the car
 * paint's flake normal there (in the shading frame), set by fr_bsdf_prepare. */
typedef struct fr_shading_point {
  int flake;      /* a flake covers the point */
  vec3 flake_n;   /* its normal, shading frame */
} fr_shading_point;

typedef struct fr_bsdf_sample {
  vec3 wi;
  vec3 weight;  /* f |cos wi| / pdf: what the path's throughput is multiplied by */
  float pdf;    /* solid angle pdf of wi (for a delta lobe: its probability, for MIS never used) */
  int delta;    /* wi came from a delta lobe */
} fr_bsdf_sample;

/* Defaults for each kind (white Lambert, clear glass of ior 1.5, chrome,
 * a red metallic car paint...). */
fr_bsdf fr_bsdf_default(fr_bsdf_kind kind);
/* Conductor presets: "chrome", "gold", "copper", "aluminium", "silver";
 * 0 for an unknown name. */
int fr_bsdf_metal_preset(const char *name, fr_bsdf *m);
/* The point's texture: p in world units, n the shading normal (world). */
void fr_bsdf_prepare(const fr_bsdf *m, vec3 p, fr_shading_point *sp);
/* Samples wi from u (uc picks a lobe, u1 u2 the direction); 0 where no
 * direction could be made (the path ends). */
int fr_bsdf_sample_dir(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, float uc, float u1, float u2,
                       fr_bsdf_sample *out);
/* f |cos wi| of the smooth lobes, and their pdf of sampling wi. */
vec3 fr_bsdf_eval(const fr_bsdf *m, const fr_shading_point *sp, vec3 wo, vec3 wi, float *pdf);
/* Whether the material has a smooth lobe at all (next-event estimation pays). */
int fr_bsdf_has_smooth(const fr_bsdf *m, const fr_shading_point *sp);
/* The colour a denoiser is guided by (the first hit's albedo AOV). */
vec3 fr_bsdf_albedo(const fr_bsdf *m);

const char *fr_bsdf_kind_name(fr_bsdf_kind k);
int fr_bsdf_kind_parse(const char *name, fr_bsdf_kind *k);
#endif
