/* Status messages and the error record (see include/sph/status.h). */
#include "sph/status.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static const char *const status_messages[] = {
#define SPH_STATUS_MSG(code, msg) msg,
    SPH_STATUS_LIST(SPH_STATUS_MSG)
#undef SPH_STATUS_MSG
};

static const char *const status_names[] = {
#define SPH_STATUS_STR(code, msg) #code,
    SPH_STATUS_LIST(SPH_STATUS_STR)
#undef SPH_STATUS_STR
};

const char *sph_status_message(sph_status code) {
  if ((int)code < 0 || code >= SPH_STATUS_COUNT)
    return "unknown status";
  return status_messages[code];
}

const char *sph_status_name(sph_status code) {
  if ((int)code < 0 || code >= SPH_STATUS_COUNT)
    return "SPH_UNKNOWN";
  return status_names[code];
}

void sph_error_clear(sph_error *err) {
  if (err)
    memset(err, 0, sizeof *err);
}

static void copy_str(char *dst, size_t size, const char *src) {
  if (!src) {
    dst[0] = '\0';
    return;
  }
  snprintf(dst, size, "%s", src);
}

sph_status sph_error_set(sph_error *err, sph_status code, const char *fmt,
                         ...) {
  if (!err)
    return code;
  sph_error_clear(err);
  err->code = code;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err->message, sizeof err->message, fmt, ap);
  va_end(ap);
  return code;
}

sph_status sph_error_at(sph_error *err, sph_status code, const char *file,
                        int line, int col, const char *key, const char *fmt,
                        ...) {
  if (!err)
    return code;
  sph_error_clear(err);
  err->code = code;
  copy_str(err->file, sizeof err->file, file);
  copy_str(err->key, sizeof err->key, key);
  err->line = line;
  err->col = col;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err->message, sizeof err->message, fmt, ap);
  va_end(ap);
  return code;
}

void sph_error_format(const sph_error *err, char *buf, size_t size) {
  size_t n = 0;
  if (size == 0)
    return;
  buf[0] = '\0';
  if (err->file[0]) {
    if (err->line > 0)
      n += (size_t)snprintf(buf + n, size - n, "%s:%d:%d: ", err->file,
                            err->line, err->col > 0 ? err->col : 1);
    else
      n += (size_t)snprintf(buf + n, size - n, "%s: ", err->file);
  }
  if (n < size && err->key[0])
    n += (size_t)snprintf(buf + n, size - n, "%s: ", err->key);
  if (n < size)
    snprintf(buf + n, size - n, "%s",
             err->message[0] ? err->message : sph_status_message(err->code));
}
