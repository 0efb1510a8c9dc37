/* Reads high-dynamic-range images: OpenEXR (through the OpenEXR library)
 * and Radiance RGBE (.hdr, frusta's own reader), into linear RGB floats. */
#ifndef FR_IO_IMAGE_READ_H
#define FR_IO_IMAGE_READ_H
#include <stddef.h>
#include "frusta.h"

/* No image past this many pixels or this side: an environment map of
 * 16K x 8K is the largest in use. */
#define FR_IMAGE_MAX_PIXELS ((size_t)1 << 27)
#define FR_IMAGE_MAX_SIDE 65536

/* *rgb: width*height*3 floats (malloc'd), row 0 at the top. Non-finite
 * values are refused (FR_ERR_FORMAT) and negative ones clamped to 0; so are
 * refused images whose claimed
 * size exceeds the limits above or what the file's bytes could hold. */
fr_error fr_image_read(const char *path, int *width, int *height, float **rgb);
/* An 8-bit image (PNG, JPEG, TGA, BMP; through Debian's stb_image) as
 * linear RGB floats, its sRGB values decoded; its size is checked against
 * the same limits before it is decoded. */
fr_error fr_image_read_ldr(const char *path, int *width, int *height, float **rgb);
/* The same from memory. */
fr_error fr_image_decode_ldr(const char *what, const unsigned char *data, size_t size, int *width, int *height, float **rgb);
/* A Radiance RGBE file held in memory (flat or run-length encoded scanlines). */
fr_error fr_hdr_decode(const char *what, const unsigned char *data, size_t size, int *width, int *height, float **rgb);
#endif
