#include "job_err.h"

const char *job_error_text(int code)
{
    static const char *const text[] = {
#define X(id, t) t,
        JOB_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_JOB, text, (int)(sizeof text / sizeof text[0]));
}
