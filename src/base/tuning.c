#include "tuning.h"
#include <stdlib.h>
#include <string.h>
#include "base/error.h"

void fr_tuning_default(fr_tuning *t) {
  t->mode = FR_TRACE_AUTO;
  t->hybrid_threshold = 7;
  t->packet_bvh_width = 8;
  t->mailbox = 0;
  t->axis_aligned = 1;
  t->ia_cull = 1;
  t->quad_leaves = 1;
  t->prefetch = -1;
  t->stream_spread = FR_STREAM_SPREAD_DEFAULT;
  /* coherent packets keep their lanes busy down to few rays: 2, as Embree's
   * coherent packets (docs/design.md, "The hybrid") */
  t->coherent_threshold = 2;
  t->occluder_cache = 1;
  t->anyhit_order = -1;
}

fr_error fr_tuning_check(const fr_tuning *t) {
  if (t->mode < FR_TRACE_AUTO || t->mode > FR_TRACE_RAYSTREAM) return fr_fail(FR_ERR_ARG, "unknown trace mode %d", (int)t->mode);
  if (t->hybrid_threshold < 0 || t->hybrid_threshold > 16)
    return fr_fail(FR_ERR_ARG, "hybrid threshold %d (0..16)", t->hybrid_threshold);
  if (t->packet_bvh_width != 4 && t->packet_bvh_width != 8)
    return fr_fail(FR_ERR_ARG, "packet BVH width %d (4 or 8)", t->packet_bvh_width);
  if (t->quad_leaves != 0 && t->quad_leaves != 1) return fr_fail(FR_ERR_ARG, "quad leaves %d (0 or 1)", t->quad_leaves);
  if (t->prefetch < -1 || t->prefetch > 1) return fr_fail(FR_ERR_ARG, "prefetch %d (-1, 0 or 1)", t->prefetch);
  if (!(t->stream_spread >= 0.0f && t->stream_spread <= 2.0f))
    return fr_fail(FR_ERR_ARG, "stream spread %g (0..2)", (double)t->stream_spread);
  if (t->coherent_threshold < 0 || t->coherent_threshold > 16)
    return fr_fail(FR_ERR_ARG, "coherent threshold %d (0..16)", t->coherent_threshold);
  if (t->occluder_cache != 0 && t->occluder_cache != 1)
    return fr_fail(FR_ERR_ARG, "occluder cache %d (0 or 1)", t->occluder_cache);
  if (t->anyhit_order < -1 || t->anyhit_order > 1)
    return fr_fail(FR_ERR_ARG, "any-hit order %d (-1, 0 or 1)", t->anyhit_order);
  return FR_OK;
}

static int env_is(const char *name, const char *value) {
  const char *v = getenv(name);
  return v && !strcmp(v, value);
}

void fr_env_tuning_read(fr_env_tuning *e) {
  memset(e, 0, sizeof *e);
  const char *isa = getenv("FRUSTA_ISA");
  if (isa && *isa) {
    e->isa_given = -1;
    static const char *names[] = {"scalar", "avx2", "avx512"}; /* fr_isa order */
    for (int i = FR_ISA_SCALAR; i <= FR_ISA_AVX512; i++)
      if (!strcmp(isa, names[i])) { e->isa = (fr_isa)i; e->isa_given = 1; }
  }
  e->bvh_width = env_is("FRUSTA_BVH_WIDTH", "4") ? 4 : 8;
  e->presplit = env_is("FRUSTA_PRESPLIT", "off") ? 0 : env_is("FRUSTA_PRESPLIT", "on") ? 1 : -1;
  e->planes = !env_is("FRUSTA_PLANES", "off");
  const char *lb = getenv("FRUSTA_LEAF_BLOCKS");
  if (lb && lb[0] >= '1' && lb[0] <= '8' && !lb[1]) e->leaf_blocks = lb[0] - '0';
  e->greedy_collapse = env_is("FRUSTA_COLLAPSE", "greedy");
  e->tree_child_order = env_is("FRUSTA_CHILD_ORDER", "tree");
}
