/* fr_image_save: the image writers (io/image_write.h, which check the
 * size and the extension) behind the public call. */
#include "base/error.h"
#include "io/image_write.h"

fr_error fr_image_save(const char *path, int width, int height, const float *rgb) {
  if (!path || !rgb) return fr_fail(FR_ERR_ARG, "fr_image_save: NULL path or image");
  return fr_image_write(path, width, height, rgb);
}
