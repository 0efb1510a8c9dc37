/* fr_version: the release of the library linked, beside the header's macros. */
#include "frusta.h"

#define FR_STR2(x) #x
#define FR_STR(x) FR_STR2(x)

const char *fr_version(void) {
  return FR_STR(FR_VERSION_MAJOR) "." FR_STR(FR_VERSION_MINOR) " (avx512 avx2 scalar)";
}
