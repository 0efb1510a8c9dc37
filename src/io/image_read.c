#include "image_read.h"
#include <OpenEXR/ImfCRgbaFile.h>
#include <stb_image.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/alloc.h"
#include "base/error.h"
#include "io/file_read.h"

#define EXR_MAX_RATIO 1024u /* a claimed image may hold at most this many times the file's bytes (ZIP of flat regions) */

static fr_error check_size(const char *what, long w, long h, size_t file_bytes) {
  if (w <= 0 || h <= 0 || w > FR_IMAGE_MAX_SIDE || h > FR_IMAGE_MAX_SIDE)
    return fr_fail(FR_ERR_FORMAT, "%s: image size %ldx%ld out of range (1..%d per side)", what, w, h, FR_IMAGE_MAX_SIDE);
  const size_t n = (size_t)w * (size_t)h;
  if (n > FR_IMAGE_MAX_PIXELS) return fr_fail(FR_ERR_UNSUPPORTED, "%s: %ldx%ld pixels is too large", what, w, h);
  if (n / EXR_MAX_RATIO > file_bytes + 4096)
    return fr_fail(FR_ERR_FORMAT, "%s: claims %ldx%ld pixels, more than its %zu bytes can hold", what, w, h, file_bytes);
  return FR_OK;
}

/* Refuses non-finite values; clamps negative ones (the ringing of
 * resampled HDR images, a few thousandths at most) to 0. */
static fr_error check_values(const char *what, float *rgb, size_t n) {
  for (size_t i = 0; i < n; i++) {
    if (!isfinite(rgb[i])) return fr_fail(FR_ERR_FORMAT, "%s: pixel %zu has a non-finite value", what, i / 3);
    if (rgb[i] < 0.0f) rgb[i] = 0.0f;
  }
  return FR_OK;
}

/* OpenEXR sizes its line and tile buffers from the header as it opens a
 * file, before a caller can look at the header: so the header is read
 * here first, and files whose buffers would be out of proportion are
 * refused before OpenEXR sees them. OpenEXR reads a value of a type it
 * knows by its type, whatever size the attribute claims, and a channel
 * list up to its end mark: an attribute whose claimed size differs is
 * refused, so that both readers see the same attributes. */
#define EXR_HEADER_MAX 65536          /* bytes of attributes read */
#define EXR_LINE_SAMPLES (1u << 20)   /* width times channels */
#define EXR_TILE_SAMPLES (1u << 22)   /* tile width times height times channels */

static uint32_t le32(const unsigned char *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The size OpenEXR reads for a value of this type given `size` bytes of it
 * (v, within the buffer): a fixed size, the channel list's up to its end
 * mark, a preview's from its width and height; `size` for the rest (read
 * as claimed). channels gets a channel list's count. */
static uint64_t exr_value_size(const char *type, const unsigned char *v, uint32_t size, uint32_t *channels) {
  static const struct { const char *type; uint32_t size; } fixed[] = {
      {"box2i", 16}, {"box2f", 16}, {"chromaticities", 32}, {"compression", 1}, {"double", 8}, {"envmap", 1},
      {"float", 4}, {"int", 4}, {"keycode", 28}, {"lineOrder", 1}, {"m33f", 36}, {"m44f", 64}, {"m33d", 72},
      {"m44d", 128}, {"rational", 8}, {"tiledesc", 9}, {"timecode", 8}, {"v2i", 8}, {"v2f", 8}, {"v2d", 16},
      {"v3i", 12}, {"v3f", 12}, {"v3d", 24}, {"deepImageState", 1}};
  for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++)
    if (!strcmp(type, fixed[i].type)) return fixed[i].size;
  if (!strcmp(type, "chlist")) { /* entries of a name and 16 bytes, then an empty name */
    uint32_t q = 0;
    while (q < size && v[q]) {
      const unsigned char *z = memchr(v + q, 0, size - q);
      if (!z) return (uint64_t)size + 1;
      q = (uint32_t)(z - v) + 17;
      ++*channels;
    }
    return (uint64_t)q + 1;
  }
  if (!strcmp(type, "preview")) return size < 8 ? 8 : 8 + 4 * (uint64_t)le32(v) * le32(v + 4);
  return size;
}

/* The header of the open file f (bytes long) of path. */
static fr_error exr_header_check(const char *path, FILE *f, size_t bytes) {
  unsigned char *h = malloc(EXR_HEADER_MAX);
  if (!h) return fr_fail(FR_ERR_NOMEM, "%s: out of memory", path);
  const size_t n = fseek(f, 0, SEEK_SET) == 0 ? fread(h, 1, EXR_HEADER_MAX, f) : 0;
  fr_error err = FR_OK;
  if (n < 8 || le32(h) != 20000630u) {
    err = fr_fail(FR_ERR_FORMAT, "%s: not an OpenEXR file", path);
  } else if (le32(h + 4) & 0x1800u) { /* deep data, several parts */
    err = fr_fail(FR_ERR_UNSUPPORTED, "%s: deep and multi-part OpenEXR files are not read", path);
  }
  long w = 0, hgt = 0;
  uint32_t channels = 0, tile_w = 1, tile_h = 1;
  int window = 0, ended = 0;
  size_t p = 8;
  while (!err && p < n) { /* attributes: name, type, size, value; an empty name ends them */
    const unsigned char *name = h + p, *z1 = memchr(name, 0, n - p);
    if (!z1) break;
    if (z1 == name) { ended = 1; break; }
    const unsigned char *type = z1 + 1, *z2 = type < h + n ? memchr(type, 0, (size_t)(h + n - type)) : NULL;
    if (!z2 || (size_t)(h + n - (z2 + 1)) < 4) break;
    const uint32_t size = le32(z2 + 1);
    const unsigned char *v = z2 + 5;
    if (size > (size_t)(h + n - v)) break;
    if (exr_value_size((const char *)type, v, size, &channels) != size) {
      err = fr_fail(FR_ERR_FORMAT, "%s: OpenEXR attribute '%s' of type %s claims %u bytes, not what its value takes", path,
                    (const char *)name, (const char *)type, size);
      break;
    }
    if (!strcmp((const char *)name, "dataWindow") && !strcmp((const char *)type, "box2i")) {
      w = (long)(int32_t)le32(v + 8) - (long)(int32_t)le32(v) + 1;
      hgt = (long)(int32_t)le32(v + 12) - (long)(int32_t)le32(v + 4) + 1;
      window = 1;
    } else if (!strcmp((const char *)name, "tiles") && !strcmp((const char *)type, "tiledesc")) {
      tile_w = le32(v), tile_h = le32(v + 4);
    }
    p = (size_t)(v - h) + size;
  }
  if (!err && (!ended || !window))
    err = fr_fail(FR_ERR_FORMAT, "%s: an OpenEXR header %s", path, ended ? "without a data window" : "cut short or over 64 KiB");
  if (!err) err = check_size(path, w, hgt, bytes);
  if (!err && (channels == 0 || (uint64_t)w * channels > EXR_LINE_SAMPLES ||
               (uint64_t)tile_w * tile_h * channels > EXR_TILE_SAMPLES))
    err = fr_fail(FR_ERR_UNSUPPORTED, "%s: %u channels of %ld pixels a line (tiles %ux%u) are out of proportion", path,
                  channels, w, tile_w, tile_h);
  free(h);
  return err;
}

/* path, bytes long, whose header exr_header_check has passed */
static fr_error read_exr(const char *path, size_t bytes, int *width, int *height, float **out) {
  ImfInputFile *in = ImfOpenInputFile(path);
  if (!in) return fr_fail(FR_ERR_FORMAT, "%s: not a readable OpenEXR file (%s)", path, ImfErrorMessage());
  int x0, y0, x1, y1;
  ImfHeaderDataWindow(ImfInputHeader(in), &x0, &y0, &x1, &y1);
  const long w = (long)x1 - x0 + 1, h = (long)y1 - y0 + 1;
  fr_error err = check_size(path, w, h, bytes);
  if (err) { ImfCloseInputFile(in); return err; }
  const size_t n = (size_t)w * (size_t)h;
  ImfRgba *px = calloc(n, sizeof *px);
  float *rgb = malloc(fr_mul_size(n, 3 * sizeof(float)));
  if (!px || !rgb) { free(px); free(rgb); ImfCloseInputFile(in); return fr_fail(FR_ERR_NOMEM, "%s: out of memory", path); }
  /* the frame buffer's origin is pixel (0, 0) of the data window's coordinates */
  const int ok = ImfInputSetFrameBuffer(in, px - x0 - (ptrdiff_t)y0 * w, 1, (size_t)w) && ImfInputReadPixels(in, y0, y1);
  if (!ok) err = fr_fail(FR_ERR_FORMAT, "%s: %s", path, ImfErrorMessage());
  ImfCloseInputFile(in);
  for (size_t i = 0; !err && i < n; i++) {
    rgb[3 * i] = ImfHalfToFloat(px[i].r);
    rgb[3 * i + 1] = ImfHalfToFloat(px[i].g);
    rgb[3 * i + 2] = ImfHalfToFloat(px[i].b);
  }
  free(px);
  if (!err) err = check_values(path, rgb, 3 * n);
  if (err) { free(rgb); return err; }
  *width = (int)w, *height = (int)h, *out = rgb;
  return FR_OK;
}

/* RGBE: mantissas scaled by 2^(e - 136); e = 0 is black. */
static void rgbe_to_float(const unsigned char *e, float *rgb) {
  if (!e[3]) { rgb[0] = rgb[1] = rgb[2] = 0.0f; return; }
  const float f = ldexpf(1.0f, (int)e[3] - 136);
  for (int c = 0; c < 3; c++) rgb[c] = ((float)e[c] + 0.5f) * f;
}

/* One scanline of w pixels into line (4 bytes each); *p advances. */
static int read_scanline(const unsigned char **p, const unsigned char *end, int w, unsigned char *line) {
  const unsigned char *q = *p;
  if (w >= 8 && w < 32768 && end - q >= 4 && q[0] == 2 && q[1] == 2 && !(q[2] & 0x80)) {
    if (((int)q[2] << 8 | q[3]) != w) return 0;
    q += 4;
    for (int c = 0; c < 4; c++) /* new RLE: each component's run by itself */
      for (int x = 0; x < w;) {
        if (q >= end) return 0;
        int n = *q++;
        if (n > 128) {
          n -= 128;
          if (n > w - x || q >= end) return 0;
          for (const unsigned char v = *q++; n--; x++) line[4 * x + c] = v;
        } else {
          if (n == 0 || n > w - x || end - q < n) return 0;
          while (n--) line[4 * x++ + c] = *q++;
        }
      }
  } else { /* flat pixels (old-style run markers are not written by any tool in use) */
    if ((size_t)(end - q) < 4 * (size_t)w) return 0;
    memcpy(line, q, 4 * (size_t)w);
    q += 4 * (size_t)w;
  }
  *p = q;
  return 1;
}

fr_error fr_hdr_decode(const char *what, const unsigned char *data, size_t size, int *width, int *height, float **out) {
  const unsigned char *p = data, *end = data + size;
  if (size < 2 || p[0] != '#' || p[1] != '?') return fr_fail(FR_ERR_FORMAT, "%s: not a Radiance HDR file", what);
  /* header lines up to an empty one; then "-Y h +X w" */
  int format_ok = 0;
  for (;;) {
    const unsigned char *nl = memchr(p, '\n', (size_t)(end - p));
    if (!nl) return fr_fail(FR_ERR_FORMAT, "%s: header without an end", what);
    if (nl == p) { p = nl + 1; break; }
    if (nl - p >= 22 && !memcmp(p, "FORMAT=32-bit_rle_rgbe", 22)) format_ok = 1;
    if (nl - p >= 7 && !memcmp(p, "FORMAT=", 7) && !format_ok)
      return fr_fail(FR_ERR_UNSUPPORTED, "%s: only the RGBE format is read (not XYZE)", what);
    p = nl + 1;
  }
  const unsigned char *nl = memchr(p, '\n', (size_t)(end - p));
  char res[64];
  if (!nl || nl - p >= (ptrdiff_t)sizeof res) return fr_fail(FR_ERR_FORMAT, "%s: missing resolution line", what);
  memcpy(res, p, (size_t)(nl - p));
  res[nl - p] = 0;
  p = nl + 1;
  long h, w;
  char tail;
  if (sscanf(res, "-Y %ld +X %ld%c", &h, &w, &tail) != 2)
    return fr_fail(FR_ERR_UNSUPPORTED, "%s: resolution line '%s' (only -Y h +X w, top to bottom)", what, res);
  /* a pixel takes at least 4 bytes flat, and RLE at least 2 bytes per 128 values */
  fr_error err = check_size(what, w, h, size);
  if (err) return err;
  if ((size_t)w * (size_t)h / 64 > size) return fr_fail(FR_ERR_FORMAT, "%s: claims %ldx%ld pixels, more than its %zu bytes hold", what, w, h, size);
  const size_t n = (size_t)w * (size_t)h;
  float *rgb = malloc(fr_mul_size(n, 3 * sizeof(float)));
  unsigned char *line = malloc(4 * (size_t)w);
  if (!rgb || !line) { free(rgb); free(line); return fr_fail(FR_ERR_NOMEM, "%s: out of memory", what); }
  for (long y = 0; y < h; y++) {
    if (!read_scanline(&p, end, (int)w, line)) {
      free(rgb); free(line);
      return fr_fail(FR_ERR_FORMAT, "%s: scanline %ld is truncated or malformed", what, y);
    }
    for (long x = 0; x < w; x++) rgbe_to_float(line + 4 * x, rgb + 3 * ((size_t)y * (size_t)w + (size_t)x));
  }
  free(line);
  *width = (int)w, *height = (int)h, *out = rgb;
  return FR_OK;
}

typedef fr_error (*decoder)(const char *, const unsigned char *, size_t, int *, int *, float **);

/* path, at most max bytes of it, through one of the decoders above or below. */
static fr_error read_and_decode(const char *path, size_t max, decoder decode, int *width, int *height, float **rgb) {
  char *data;
  size_t size;
  fr_error err = fr_read_file_max(path, max, &data, &size);
  if (err) return err;
  err = decode(path, (const unsigned char *)data, size, width, height, rgb);
  free(data);
  return err;
}

fr_error fr_image_read(const char *path, int *width, int *height, float **rgb) {
  if (fr_has_suffix(path, ".hdr") || fr_has_suffix(path, ".pic"))
    return read_and_decode(path, (size_t)1 << 30, fr_hdr_decode, width, height, rgb);
  if (!fr_has_suffix(path, ".exr")) return fr_fail(FR_ERR_ARG, "%s: unknown image format (use .exr or .hdr)", path);
  FILE *f = fopen(path, "rb");
  if (!f) return fr_fail(FR_ERR_IO, "%s: cannot open", path);
  long bytes = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
  fr_error err = bytes < 0 ? fr_fail(FR_ERR_IO, "%s: cannot read", path) : exr_header_check(path, f, (size_t)bytes);
  fclose(f);
  return err ? err : read_exr(path, (size_t)bytes, width, height, rgb);
}

static float srgb_to_linear(unsigned char c) {
  const float v = (float)c / 255.0f;
  return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

fr_error fr_image_decode_ldr(const char *what, const unsigned char *data, size_t size, int *width, int *height, float **out) {
  if (size > (size_t)INT32_MAX) return fr_fail(FR_ERR_UNSUPPORTED, "%s: too large", what);
  int w, h, comp;
  if (!stbi_info_from_memory(data, (int)size, &w, &h, &comp))
    return fr_fail(FR_ERR_FORMAT, "%s: not a readable image (%s)", what, stbi_failure_reason());
  fr_error err = check_size(what, w, h, size);
  if (err) return err;
  unsigned char *px = stbi_load_from_memory(data, (int)size, &w, &h, &comp, 3);
  if (!px) return fr_fail(FR_ERR_FORMAT, "%s: cannot decode the image (%s)", what, stbi_failure_reason());
  const size_t n = (size_t)w * (size_t)h * 3;
  float *rgb = malloc(n * sizeof(float));
  if (!rgb) { stbi_image_free(px); return fr_fail(FR_ERR_NOMEM, "%s: out of memory", what); }
  float lut[256];
  for (int i = 0; i < 256; i++) lut[i] = srgb_to_linear((unsigned char)i);
  for (size_t i = 0; i < n; i++) rgb[i] = lut[px[i]];
  stbi_image_free(px);
  *width = w, *height = h, *out = rgb;
  return FR_OK;
}

fr_error fr_image_read_ldr(const char *path, int *width, int *height, float **rgb) {
  return read_and_decode(path, (size_t)256 << 20, fr_image_decode_ldr, width, height, rgb);
}
