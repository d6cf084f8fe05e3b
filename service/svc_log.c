/* svc_log: see svc_log.h. */
#include "svc_log.h"

#include <stdarg.h>
#include <stdio.h>
#include <time.h>
#include <unistd.h>

static int min_level = SVC_LOG_INFO;

void svc_log_level(int level)
{
    min_level = level;
}

void svc_log(int level, int64_t job, const char *fmt, ...)
{
    static const char *const names[] = {"debug", "info ", "warn ", "error"};
    if (level < min_level)
        return;
    char line[2048];
    time_t now = time(NULL);
    struct tm tm;
    gmtime_r(&now, &tm);
    int n = (int)strftime(line, sizeof line, "%Y-%m-%dT%H:%M:%SZ ", &tm);
    n += snprintf(line + n, sizeof line - (size_t)n, "%s ", names[level & 3]);
    if (job >= 0)
        n += snprintf(line + n, sizeof line - (size_t)n, "job %lld: ", (long long)job);
    va_list ap;
    va_start(ap, fmt);
    if (n < (int)sizeof line)
        n += vsnprintf(line + n, sizeof line - (size_t)n, fmt, ap);
    va_end(ap);
    if (n > (int)sizeof line - 2)
        n = (int)sizeof line - 2;
    line[n++] = '\n';
    /* one write: lines from the HTTP threads and the supervisor never interleave */
    ssize_t w = write(STDERR_FILENO, line, (size_t)n);
    (void)w;
}
