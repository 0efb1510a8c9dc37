/* The ray, hit and occlusion files of docs/rayfile.md. */
#ifndef FR_IO_RAYFILE_H
#define FR_IO_RAYFILE_H
#include <stddef.h>
#include <stdint.h>
#include "frusta.h"

/* One record, as on disk. */
typedef struct fr_hit_record { float t; uint32_t prim; float u, v; } fr_hit_record;

fr_error fr_rays_read(const char *path, fr_ray **rays, size_t *count);
fr_error fr_rays_write(const char *path, const fr_ray *rays, size_t count);
fr_error fr_hits_write(const char *path, const fr_hit *hits, size_t count);
fr_error fr_hits_read(const char *path, fr_hit_record **hits, size_t *count);
fr_error fr_occl_write(const char *path, const uint8_t *occ, size_t count);
fr_error fr_occl_read(const char *path, uint8_t **occ, size_t *count);

/* The comparison rule of rayfile.md. */
int fr_hits_agree(float t1, float t2);
int fr_occlusion_near_boundary(const fr_ray *ray, float t_nearest);
#endif
