#include "kernels.h"
#include "base/tuning.h"
#include <cpuid.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "base/error.h"

static _Atomic(const fr_kernels *) active;

/* The AVX2 and AVX-512 kernels are also compiled with BMI, BMI2, LZCNT and
 * POPCNT (CMakeLists.txt), so the compiler may use them anywhere there. */
static int bit_ops_supported(void) {
  /* LZCNT by CPUID (leaf 0x80000001, ECX bit 5): clang's
   * __builtin_cpu_supports knows no "lzcnt" (clang 14 rejects it) */
  unsigned a, b, c, d;
  int lzcnt = __get_cpuid(0x80000001u, &a, &b, &c, &d) && (c >> 5 & 1u);
  return __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") && lzcnt && __builtin_cpu_supports("popcnt");
}

int fr_isa_supported(fr_isa isa) {
  switch (isa) {
  case FR_ISA_SCALAR: return 1;
  case FR_ISA_AVX2: return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && bit_ops_supported();
  case FR_ISA_AVX512:
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("fma") &&
           bit_ops_supported();
  }
  return 0;
}

const char *fr_isa_name(fr_isa isa) {
  switch (isa) {
  case FR_ISA_SCALAR: return "scalar";
  case FR_ISA_AVX2: return "avx2";
  case FR_ISA_AVX512: return "avx512";
  }
  return "unknown";
}

#define FR_KERNELS(isa, ISA)                                                                            \
  static const fr_kernels kernels_##isa = {ISA, &fr_trace_w4_##isa, &fr_trace_w8_##isa,              \
                                           &fr_packet_p8_w4_##isa, &fr_packet_p16_w4_##isa,         \
                                           &fr_packet_p8_w8_##isa, &fr_packet_p16_w8_##isa,        \
                                           &fr_stream_w4_##isa, &fr_stream_w8_##isa, fr_spheres16_##isa};
FR_KERNELS(avx512, FR_ISA_AVX512)
FR_KERNELS(avx2, FR_ISA_AVX2)
FR_KERNELS(scalar, FR_ISA_SCALAR)

static const fr_kernels *table(fr_isa isa) {
  return isa == FR_ISA_AVX512 ? &kernels_avx512 : isa == FR_ISA_AVX2 ? &kernels_avx2 : &kernels_scalar;
}

static const fr_kernels *choose(void) {
  fr_env_tuning env;
  fr_env_tuning_read(&env);
  /* an unknown or unsupported request falls through to the best level */
  if (env.isa_given > 0 && fr_isa_supported(env.isa)) return table(env.isa);
  for (int i = FR_ISA_AVX512; i >= FR_ISA_SCALAR; i--)
    if (fr_isa_supported((fr_isa)i)) return table((fr_isa)i);
  return &kernels_scalar;
}

const fr_kernels *fr_kernels_active(void) {
  const fr_kernels *k = atomic_load_explicit(&active, memory_order_acquire);
  if (!k) {
    k = choose();
    atomic_store_explicit(&active, k, memory_order_release);
  }
  return k;
}

fr_error fr_set_isa(fr_isa isa) {
  if (isa < FR_ISA_SCALAR || isa > FR_ISA_AVX512) return fr_fail(FR_ERR_ARG, "unknown ISA %d", (int)isa);
  if (!fr_isa_supported(isa)) return fr_fail(FR_ERR_UNSUPPORTED, "this CPU does not support %s", fr_isa_name(isa));
  atomic_store_explicit(&active, table(isa), memory_order_release);
  return FR_OK;
}

fr_isa fr_get_isa(void) { return fr_kernels_active()->isa; }
