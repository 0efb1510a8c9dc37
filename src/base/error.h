/* Per-thread last error message behind fr_last_error(). */
#ifndef FR_BASE_ERROR_H
#define FR_BASE_ERROR_H
#include "frusta.h"

/* Sets the message (printf-style) and returns e, so callers can write
 * `return fr_fail(FR_ERR_IO, "cannot open %s", path);`. */
fr_error fr_fail(fr_error e, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void fr_clear_error(void);
#endif
