/* How much a command says on stderr, one level for the whole process
 * (ffmpeg's -loglevel): set once by main from --loglevel, -q or -v
 * (README.md, "How much a command says"), read wherever a line is
 * printed.
 *   quiet    nothing: the exit status alone says how it went
 *   error    why a command failed
 *   warning  and what went on in a degraded way (no sound device, a cache not saved): -q
 *   info     and what was done: the summary lines, progress (the default)
 *   debug    and how: the GL driver, start-up times, the encoder's own log */
#ifndef RS_LOG_H
#define RS_LOG_H

#include <stdbool.h>

enum { RS_LOG_QUIET, RS_LOG_ERROR, RS_LOG_WARNING, RS_LOG_INFO, RS_LOG_DEBUG };

extern int rs_log_level;     /* RS_LOG_INFO unless main set another */
extern bool rs_log_explicit; /* the user chose the level */

/* Whether lines of this level are printed. */
bool rs_log_on(int level);
/* "quiet", "error", "warning", "info" or "debug"; false for anything else. */
bool rs_log_parse(const char *name, int *level);
const char *rs_log_name(int level);

#endif
