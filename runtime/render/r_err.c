#include "r_err.h"

const char *r_error_text(int code)
{
    static const char *const text[] = {
#define X(id, t) t,
        R_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_R, text, (int)(sizeof text / sizeof text[0]));
}
