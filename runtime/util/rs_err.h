/* rs_err: the error value every ringside function fills instead of exiting.
 *
 * A module defines its codes with an X-macro list (see plat.h); code 0 means
 * "no error".  The message is one line, names the file or value at fault and
 * what was expected.  Only main() and the daemon decide to exit. */
#ifndef RS_ERR_H
#define RS_ERR_H

#include <stdarg.h>
#include <stddef.h>

typedef struct rs_err {
    int code;
    char msg[768];
} rs_err;

#if defined(__GNUC__)
#define RS_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define RS_PRINTF(a, b)
#endif

/* Sets code and message; a NULL err is allowed (the caller does not care).
 * Always returns false so callers can write `return rs_fail(e, ...)`. */
int rs_fail(rs_err *e, int code, const char *fmt, ...) RS_PRINTF(3, 4);
int rs_vfail(rs_err *e, int code, const char *fmt, va_list ap);
/* Prepends "prefix: " to an existing message (adds context on the way up). */
void rs_err_prefix(rs_err *e, const char *fmt, ...) RS_PRINTF(2, 3);
void rs_err_clear(rs_err *e);

#endif
