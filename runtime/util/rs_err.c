#include "rs_err.h"

#include <stdio.h>
#include <string.h>

int rs_vfail(rs_err *e, int code, const char *fmt, va_list ap)
{
    if (!e)
        return 0;
    e->code = code ? code : 1;
    vsnprintf(e->msg, sizeof e->msg, fmt, ap);
    /* one line only: fold newlines coming from driver logs */
    for (char *p = e->msg; *p; p++)
        if (*p == '\n' || *p == '\r')
            *p = ' ';
    return 0;
}

int rs_fail(rs_err *e, int code, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    rs_vfail(e, code, fmt, ap);
    va_end(ap);
    return 0;
}

void rs_err_prefix(rs_err *e, const char *fmt, ...)
{
    if (!e)
        return;
    char pre[256], old[sizeof e->msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(pre, sizeof pre, fmt, ap);
    va_end(ap);
    memcpy(old, e->msg, sizeof old);
    snprintf(e->msg, sizeof e->msg, "%s: %s", pre, old);
}

void rs_err_clear(rs_err *e)
{
    if (e) {
        e->code = 0;
        e->msg[0] = 0;
    }
}

const char *rs_err_module_name(int code)
{
    static const char *const names[] = {
#define X(id, name) name,
        RS_ERR_MODULES(X)
#undef X
    };
    return code >= 0 && RS_ERR_MODULE(code) < RS_ERR_MOD_COUNT ? names[RS_ERR_MODULE(code)] : "?";
}

const char *rs_err_text_of(int code, rs_err_module mod, const char *const texts[], int n)
{
    if (code == 0)
        return "ok";
    int k = code - RS_ERR_BASE(mod) - 1;
    return k >= 0 && k < n ? texts[k] : "?";
}
