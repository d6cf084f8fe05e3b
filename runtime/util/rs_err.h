/* rs_err: the error value every ringside function fills instead of exiting.
 *
 * code says what kind of failure it is (an error id, below); 0 means "no
 * error".  The message is one line, names the file or value at fault and
 * what was expected.  Only main() and the daemon decide to exit.
 *
 * Error ids.  A module lists its ids once, each with a short text, in an
 * X-macro list (RP_ERRORS in rp.h, say); the same list makes the enum and
 * the module's *_error_text().  Callers and tests branch on ids, never on
 * message text; the message is for people.
 *
 * Ids of different modules never collide: each module with a list owns a
 * block of RS_ERR_BLOCK codes, allotted once in RS_ERR_MODULES below, and
 * numbers its ids from the block's start + 1.  So RS_ERR_MODULE(code)
 * names the list a code comes from, and an error passed up through other
 * modules keeps its meaning.  Block 0 (codes 1..255) holds the older lists
 * not yet given a block (plat, rgl, rs_file, rs_img, r_shader, r_ibl) and
 * the bare 1 of modules without a list: such a code means something only
 * next to the call that set it.  HTTP statuses and exit codes are not
 * error ids: the service and main() map ids to them in their own tables. */
#ifndef RS_ERR_H
#define RS_ERR_H

#include <stdarg.h>
#include <stddef.h>

#define RS_ERR_MODULES(X)              \
    X(LOCAL, "local")    /* block 0 */ \
    X(RP, "replay")                    \
    X(R_STAGE, "stage")                \
    X(CAP, "capture")                  \
    X(MV, "movie")                     \
    X(SVC_STORE, "queue store")        \
    X(SVC, "service")                  \
    X(AU, "audio")                     \
    X(R, "render")                     \
    X(JOB, "job")                      \
    X(SVC_CONFIG, "service config")

typedef enum rs_err_module {
#define X(id, name) RS_ERR_MOD_##id,
    RS_ERR_MODULES(X)
#undef X
        RS_ERR_MOD_COUNT
} rs_err_module;

#define RS_ERR_BLOCK 256
/* Where a module's enum starts; its first id is one more. */
#define RS_ERR_BASE(mod) ((int)(mod) * RS_ERR_BLOCK)
/* The module whose list code comes from (RS_ERR_MOD_LOCAL for block 0). */
#define RS_ERR_MODULE(code) ((rs_err_module)((unsigned)(code) / RS_ERR_BLOCK))

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

/* "replay", "stage", ... for the module that owns code; "?" when none does. */
const char *rs_err_module_name(int code);
/* The body of every *_error_text: texts[k] is the text of id
 * RS_ERR_BASE(mod) + 1 + k.  "ok" for 0, "?" for a code outside the list. */
const char *rs_err_text_of(int code, rs_err_module mod, const char *const texts[], int n);

#endif
