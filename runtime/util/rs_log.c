#include "rs_log.h"

#include <string.h>

int rs_log_level = RS_LOG_INFO;
bool rs_log_explicit;

static const char *const names[] = {"quiet", "error", "warning", "info", "debug"};

bool rs_log_on(int level)
{
    return level <= rs_log_level;
}

bool rs_log_parse(const char *name, int *level)
{
    for (int i = 0; i < (int)(sizeof names / sizeof *names); i++)
        if (!strcmp(name, names[i])) {
            *level = i;
            return true;
        }
    return false;
}

const char *rs_log_name(int level)
{
    return level >= 0 && level <= RS_LOG_DEBUG ? names[level] : "?";
}
