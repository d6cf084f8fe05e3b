/* svc_log: the daemon's log lines on stderr,
 *   2026-11-23T10:00:00Z info  job 12: claimed (attempt 1 of 3)
 * with a level filter.  Any thread may log; each line is one write. */
#ifndef SVC_LOG_H
#define SVC_LOG_H

#include <stdint.h>

#include "../runtime/util/rs_err.h"
#include "svc_config.h"

void svc_log_level(int level);
/* job < 0: a line about the daemon, not a job. */
void svc_log(int level, int64_t job, const char *fmt, ...) RS_PRINTF(3, 4);

#endif
