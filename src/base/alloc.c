#include "alloc.h"
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#define HUGE_PAGE ((size_t)2 << 20)

void *fr_alloc_aligned(size_t bytes, size_t align) {
  if (bytes == SIZE_MAX) return NULL;
  /* Large blocks (BVH nodes, triangle records) are traversed at random: back
   * them with 2 MiB pages where the kernel allows, or TLB misses dominate. */
  if (bytes >= HUGE_PAGE) align = HUGE_PAGE;
  size_t rounded = (bytes + align - 1) / align * align;
  if (rounded == 0) rounded = align;
  void *p = aligned_alloc(align, rounded);
#ifdef MADV_HUGEPAGE
  if (p && rounded >= HUGE_PAGE) madvise(p, rounded, MADV_HUGEPAGE);
#endif
  return p;
}

void fr_free_aligned(void *p) { free(p); }

void *fr_malloc_array(size_t n, size_t size) {
  size_t bytes;
  return __builtin_mul_overflow(n, size, &bytes) ? NULL : malloc(bytes);
}
