/* Aligned allocation and overflow-checked sizes. */
#ifndef FR_BASE_ALLOC_H
#define FR_BASE_ALLOC_H
#include <stddef.h>
#include <stdint.h>

void *fr_alloc_aligned(size_t bytes, size_t align); /* NULL on failure; bytes may be 0 */
void fr_free_aligned(void *p);

/* a*b, or SIZE_MAX if it would overflow (so the allocation then fails). */
static inline size_t fr_mul_size(size_t a, size_t b) {
  size_t r;
  return __builtin_mul_overflow(a, b, &r) ? SIZE_MAX : r;
}

/* malloc of n elements of size bytes; NULL where n * size overflows, without
 * asking malloc for SIZE_MAX (which GCC warns of where it can see it). */
void *fr_malloc_array(size_t n, size_t size);
#endif
