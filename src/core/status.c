/* Status messages and the error record (see include/sph/status.h). */
#include "sph/status.h"

#include "core/check.h"

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

#define ELLIPSIS "\xe2\x80\xa6" /* U+2026, 3 bytes in UTF-8 */

/* Start of the token after the one starting at p (a token is a map key or
 * a [index]; "." and "[" begin the next), or the terminating NUL. */
static const char *next_token(const char *p) {
  if (!*p)
    return p;
  if (*p == '[') {
    const char *close = strchr(p, ']');
    p = close ? close + 1 : p + strlen(p);
  } else {
    p += *p == '.';
    p += strcspn(p, ".[");
  }
  return p;
}

void sph_key_path_fit(char *dst, size_t size, const char *path) {
  if (size == 0)
    return;
  size_t len = path ? strlen(path) : 0;
  if (len < size) {
    copy_str(dst, size, path);
    return;
  }
  /* whole tokens only: the first token, an ellipsis for the tokens left
   * out, then as many of the last tokens as fit, then as many more of the
   * first ones ("bodies.…[2].at", "bodies[0].shape.box.…"); a first token
   * too long is left out too */
  size_t room = size - 1, ell = sizeof ELLIPSIS - 1;
  const char *end = path + len;
  size_t head = (size_t)(next_token(path) - path);
  if (head + 1 + ell > room)
    head = 0;
#define FITS(h, t) ((h) + ((h) ? 1 : 0) + ell + (size_t)(end - (t)) <= room)
  const char *tail = end;
  for (const char *t = path + head; *t; t = next_token(t))
    if (FITS(head, t)) {
      tail = t;
      break;
    }
  if (!FITS(head, tail)) {
    dst[0] = '\0'; /* not even an ellipsis fits */
    return;
  }
  for (const char *t = next_token(path + head); head && t < tail;
       t = next_token(t)) {
    if (!FITS((size_t)(t - path), tail))
      break;
    head = (size_t)(t - path);
  }
#undef FITS
  snprintf(dst, size, "%.*s%s%s%s", (int)head, path, head ? "." : "", ELLIPSIS,
           tail);
}

/* vsnprintf, a message too long cut at a word or key boundary (space,
 * '.', '[', quote, comma, colon) and ended with an ellipsis, never in the
 * middle of a key or word */
static void fit_message(char *dst, size_t size, const char *fmt, va_list ap) {
  int n = vsnprintf(dst, size, fmt, ap);
  size_t ell = sizeof ELLIPSIS - 1;
  if (n < 0 || (size_t)n < size || size <= ell + 1)
    return;
  size_t cut = size - 1 - ell;
  while (cut > 0 && !strchr(" .[',:", dst[cut]))
    --cut;
  memcpy(dst + cut, ELLIPSIS, ell + 1);
}

sph_status sph_error_set(sph_error *err, sph_status code, const char *fmt,
                         ...) {
  if (!err)
    return code;
  sph_error_clear(err);
  err->code = code;
  va_list ap;
  va_start(ap, fmt);
  fit_message(err->message, sizeof err->message, fmt, ap);
  va_end(ap);
  return code;
}

sph_status sph_error_atv(sph_error *err, sph_status code, const char *file,
                         int line, int col, const char *key, const char *fmt,
                         va_list ap) {
  if (!err)
    return code;
  sph_error_clear(err);
  err->code = code;
  copy_str(err->file, sizeof err->file, file);
  sph_key_path_fit(err->key, sizeof err->key, key);
  err->line = line;
  err->col = col;
  fit_message(err->message, sizeof err->message, fmt, ap);
  return code;
}

sph_status sph_error_at(sph_error *err, sph_status code, const char *file,
                        int line, int col, const char *key, const char *fmt,
                        ...) {
  va_list ap;
  va_start(ap, fmt);
  sph_error_atv(err, code, file, line, col, key, fmt, ap);
  va_end(ap);
  return code;
}

sph_status sph_check_failed(sph_error *err, sph_status code, const char *file,
                            int line, const char *fmt, ...) {
  /* the path from the last src/ folder on (the build's paths are absolute) */
  for (const char *p = file; (p = strstr(p, "src/")) != NULL; ++p)
    if (p == file || p[-1] == '/')
      file = p;
  char msg[sizeof err->message];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return sph_error_set(err, code, "%s:%d: %s", file, line, msg);
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
