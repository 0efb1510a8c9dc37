/* fr_image_save: the image writers (io/image_write.h) behind the public call. */
#include "base/error.h"
#include "io/image_write.h"

fr_error fr_image_save(const char *path, int width, int height, const float *rgb) {
  if (!path || !rgb) return fr_fail(FR_ERR_ARG, "fr_image_save: NULL path or image");
  if (width <= 0 || height <= 0) return fr_fail(FR_ERR_ARG, "fr_image_save: a %dx%d image", width, height);
  if (!fr_image_format_known(path)) return fr_fail(FR_ERR_ARG, "%s: unknown image format (use .png, .exr or .pfm)", path);
  return fr_image_write(path, width, height, rgb);
}
