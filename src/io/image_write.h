/* Writes linear RGB float images as PNG (sRGB, 8 bit), EXR (half) or PFM
 * (float), chosen by extension, atomically. */
#ifndef FR_IO_IMAGE_WRITE_H
#define FR_IO_IMAGE_WRITE_H
#include "frusta.h"

/* rgb: width*height*3 floats, row 0 at the top. */
fr_error fr_image_write(const char *path, int width, int height, const float *rgb);
/* 1 if the extension is one fr_image_write knows. */
int fr_image_format_known(const char *path);
#endif
