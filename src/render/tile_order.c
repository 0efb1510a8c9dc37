#include <stdlib.h>
#include "render/tile.h"

/* order[i]: the i-th tile to trace (y * tiles_x + x), in Morton order, so
 * that the tiles in flight at a time, and those traced one after another,
 * lie close together and share the tree's nodes in the caches (row order
 * sends the threads along a whole row, fetching a large tree's nodes
 * anew). The grid is cut along its long side into squares of a
 * power-of-two side, at least its short side, and each square's codes are
 * walked in order, those outside the grid skipped: at most six codes a
 * tile, and no sort. NULL without memory: the caller keeps row order. */
uint32_t *fr_tile_order(int tiles_x, int tiles_y) {
  const uint32_t nx = (uint32_t)tiles_x, ny = (uint32_t)tiles_y, across = nx >= ny;
  const uint32_t along = across ? nx : ny, short_side = across ? ny : nx;
  uint32_t side = 1;
  while (side < short_side) side *= 2;
  uint32_t *order = malloc((size_t)nx * ny * sizeof *order);
  if (!order) return NULL;
  size_t k = 0;
  for (uint32_t base = 0; base < along; base += side)
    for (uint64_t code = 0; code < (uint64_t)side * side; code++) {
      uint32_t u = 0, v = 0; /* u along the long side, v across */
      for (int bit = 0; (side >> bit) > 1; bit++) {
        u |= (uint32_t)((code >> (2 * bit)) & 1u) << bit;
        v |= (uint32_t)((code >> (2 * bit + 1)) & 1u) << bit;
      }
      const uint32_t x = across ? base + u : v, y = across ? v : base + u;
      if (x < nx && y < ny) order[k++] = y * nx + x;
    }
  return order;
}
