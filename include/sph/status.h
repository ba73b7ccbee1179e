/* Status codes and the error record every library call fills.
 *
 * One X-macro list gives the codes and their messages; the library never
 * prints or exits, it returns a code and fills an sph_error that only the
 * command-line front end reports. */
#ifndef SPH_STATUS_H
#define SPH_STATUS_H

#include <stdarg.h>
#include <stddef.h>

/* Marks a function libsph.so exports (the library is built with hidden
 * visibility; tests/lib/check_exports.sh holds the exports to this list). */
#if defined(__GNUC__)
#define SPH_API __attribute__((visibility("default")))
#else
#define SPH_API
#endif

#define SPH_STATUS_LIST(X)                                                     \
  X(SPH_OK, "ok")                                                              \
  X(SPH_ERR_NOMEM, "out of memory")                                            \
  X(SPH_ERR_IO, "input/output error")                                          \
  X(SPH_ERR_ARG, "invalid argument")                                           \
  X(SPH_ERR_SYNTAX, "syntax error")                                            \
  X(SPH_ERR_UNKNOWN_KEY, "unknown key")                                        \
  X(SPH_ERR_DUPLICATE_KEY, "duplicate key")                                    \
  X(SPH_ERR_TYPE, "wrong type")                                                \
  X(SPH_ERR_MISSING_KEY, "missing required key")                               \
  X(SPH_ERR_RANGE, "value out of range")                                       \
  X(SPH_ERR_GEOMETRY, "invalid geometry")                                      \
  X(SPH_ERR_SINGULAR, "singular moment matrix")                                \
  X(SPH_ERR_UNSUPPORTED, "not supported")                                      \
  X(SPH_ERR_NUMERIC, "non-finite value")                                       \
  X(SPH_ERR_INTERNAL, "internal invariant violated")

typedef enum sph_status {
#define SPH_STATUS_ENUM(code, msg) code,
  SPH_STATUS_LIST(SPH_STATUS_ENUM)
#undef SPH_STATUS_ENUM
      SPH_STATUS_COUNT
} sph_status;

/* Where and why a call failed. `file`, `line`, `col` and `key` locate the
 * offending input when there is one (line and col are 1-based, 0 = unknown). */
typedef struct sph_error {
  sph_status code;
  char file[256];
  int line;
  int col;
  char key[128];
  char message[768];
} sph_error;

SPH_API const char *sph_status_message(sph_status code);
SPH_API const char *sph_status_name(sph_status code);

/* Clears the record (code SPH_OK, empty strings). Accepts NULL. */
SPH_API void sph_error_clear(sph_error *err);

/* Fills the record and returns `code`; printf-style message. Accepts NULL. */
SPH_API sph_status sph_error_set(sph_error *err, sph_status code,
                                 const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* As sph_error_set, with an input location and key (a key path too long
 * for the record shortened by sph_key_path_fit). A message too long for
 * the record is cut at a word or key boundary and ends with an ellipsis. */
SPH_API sph_status sph_error_at(sph_error *err, sph_status code,
                                const char *file, int line, int col,
                                const char *key, const char *fmt, ...)
    __attribute__((format(printf, 7, 8)));

/* Copies the key path `path` ("bodies[0].shape.box.min") into dst; one
 * too long is shortened at token boundaries (a key or an [index]), the
 * tokens left out shown as one ellipsis: "bodies.…[3].at". Never cuts a
 * token. NULL copies "". */
SPH_API void sph_key_path_fit(char *dst, size_t size, const char *path);

/* sph_error_at with a va_list. */
SPH_API sph_status sph_error_atv(sph_error *err, sph_status code,
                                 const char *file, int line, int col,
                                 const char *key, const char *fmt, va_list ap);

/* Returns from the calling function when `expr` is not SPH_OK. */
#define SPH_TRY(expr)                                                          \
  do {                                                                         \
    sph_status sph_try_status_ = (expr);                                       \
    if (sph_try_status_ != SPH_OK)                                             \
      return sph_try_status_;                                                  \
  } while (0)

/* Writes "file:line:col: key: message" (parts present only) into buf. */
SPH_API void sph_error_format(const sph_error *err, char *buf, size_t size);

#endif
