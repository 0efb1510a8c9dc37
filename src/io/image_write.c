#include "image_write.h"
#include <OpenEXR/ImfCRgbaFile.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stb_image_write.h>
#include "base/alloc.h"
#include "base/error.h"
#include "film/tonemap.h"
#include "io/atomic_file.h"
#include "io/file_read.h"

int fr_image_format_known(const char *path) {
  return fr_has_suffix(path, ".png") || fr_has_suffix(path, ".exr") || fr_has_suffix(path, ".pfm");
}

static fr_error write_png(const char *tmp, const char *path, int w, int h, const float *rgb) {
  size_t n = fr_mul_size(fr_mul_size((size_t)w, (size_t)h), 3);
  unsigned char *px = malloc(n);
  if (!px) return fr_fail(FR_ERR_NOMEM, "out of memory for the image");
  for (size_t i = 0; i < n; i++) px[i] = fr_srgb8(rgb[i]);
  int ok = stbi_write_png(tmp, w, h, 3, px, w * 3);
  free(px);
  return ok ? FR_OK : fr_fail(FR_ERR_IO, "%s: PNG write failed", path);
}

static fr_error write_exr(const char *tmp, const char *path, int w, int h, const float *rgb) {
  size_t n = fr_mul_size((size_t)w, (size_t)h);
  ImfRgba *px = malloc(fr_mul_size(n, sizeof(ImfRgba)));
  if (!px) return fr_fail(FR_ERR_NOMEM, "out of memory for the image");
  for (size_t i = 0; i < n; i++) {
    ImfFloatToHalf(rgb[3 * i], &px[i].r);
    ImfFloatToHalf(rgb[3 * i + 1], &px[i].g);
    ImfFloatToHalf(rgb[3 * i + 2], &px[i].b);
    ImfFloatToHalf(1.0f, &px[i].a);
  }
  ImfHeader *hdr = ImfNewHeader();
  ImfHeaderSetDataWindow(hdr, 0, 0, w - 1, h - 1);
  ImfHeaderSetDisplayWindow(hdr, 0, 0, w - 1, h - 1);
  ImfHeaderSetCompression(hdr, IMF_ZIP_COMPRESSION);
  ImfOutputFile *out = ImfOpenOutputFile(tmp, hdr, IMF_WRITE_RGB);
  ImfDeleteHeader(hdr);
  if (!out) { free(px); return fr_fail(FR_ERR_IO, "%s: %s", path, ImfErrorMessage()); }
  int ok = ImfOutputSetFrameBuffer(out, px, 1, (size_t)w) && ImfOutputWritePixels(out, h);
  ok &= ImfCloseOutputFile(out);
  free(px);
  return ok ? FR_OK : fr_fail(FR_ERR_IO, "%s: EXR write failed: %s", path, ImfErrorMessage());
}

static fr_error write_pfm(const char *tmp, const char *path, int w, int h, const float *rgb) {
  FILE *f = fopen(tmp, "wb");
  if (!f) return fr_fail(FR_ERR_IO, "%s: %s", path, strerror(errno));
  /* PFM stores rows bottom to top; a negative scale means little-endian */
  int bad = fprintf(f, "PF\n%d %d\n-1.0\n", w, h) < 0;
  for (int y = h - 1; y >= 0 && !bad; y--) bad = fwrite(rgb + (size_t)y * w * 3, sizeof(float) * 3, (size_t)w, f) != (size_t)w;
  bad |= fclose(f) != 0;
  return bad ? fr_fail(FR_ERR_IO, "%s: PFM write failed", path) : FR_OK;
}

fr_error fr_image_write(const char *path, int w, int h, const float *rgb) {
  if (w <= 0 || h <= 0) return fr_fail(FR_ERR_ARG, "image size %dx%d is empty", w, h);
  if (!fr_image_format_known(path)) return fr_fail(FR_ERR_ARG, "%s: unknown image format (use .png, .exr or .pfm)", path);
  char tmp[4200];
  fr_atomic_tmp_path(path, tmp, sizeof tmp);
  /* the writers below do not say why a file cannot be made (a missing
   * folder, no permission): the reason is found here, for the user's path */
  FILE *probe = fopen(tmp, "wb");
  if (!probe) return fr_fail(FR_ERR_IO, "%s: %s", path, strerror(errno));
  fclose(probe);
  fr_error e = fr_has_suffix(path, ".png") ? write_png(tmp, path, w, h, rgb)
             : fr_has_suffix(path, ".exr") ? write_exr(tmp, path, w, h, rgb)
             : write_pfm(tmp, path, w, h, rgb);
  if (e) { remove(tmp); return e; }
  return fr_atomic_commit(tmp, path);
}
