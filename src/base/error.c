#include "error.h"
#include <stdarg.h>
#include <stdio.h>

static _Thread_local char last_msg[512];

fr_error fr_fail(fr_error e, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(last_msg, sizeof last_msg, fmt, ap);
  va_end(ap);
  /* one line: a message never carries a newline from a file name or format */
  for (char *p = last_msg; *p; p++)
    if (*p == '\n' || *p == '\r') *p = ' ';
  return e;
}

void fr_clear_error(void) { last_msg[0] = 0; }

const char *fr_last_error(void) { return last_msg; }

const char *fr_error_name(fr_error e) {
  switch (e) {
  case FR_OK: return "ok";
  case FR_ERR_ARG: return "invalid argument";
  case FR_ERR_IO: return "i/o error";
  case FR_ERR_FORMAT: return "malformed input";
  case FR_ERR_NOMEM: return "out of memory";
  case FR_ERR_UNSUPPORTED: return "unsupported";
  case FR_ERR_STATE: return "wrong state";
  }
  return "unknown error";
}
