#include "alloc.h"
#include <stdlib.h>

void *fr_alloc_aligned(size_t bytes, size_t align) {
  if (bytes == SIZE_MAX) return NULL;
  size_t rounded = (bytes + align - 1) / align * align;
  if (rounded == 0) rounded = align;
  return aligned_alloc(align, rounded);
}

void fr_free_aligned(void *p) { free(p); }
