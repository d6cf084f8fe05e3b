/* Progress for long work, on stderr, in one of two forms:
 *   tty:   "label: done / total unit (pct)  rate  speed  elapsed  ETA",
 *          redrawn in place at most 10 times a second;
 *   plain: one line every RS_PROGRESS_INTERVAL seconds (default 5) and
 *          the last one, for logs (a service manager, CI):
 *          "ringside render: 600/1800 frames (33%), 21.4 fps, 0.36x,
 *          elapsed 0:28, ETA 0:56".
 * Speed is x real time: units are 60 Hz ticks or frames.
 * The default (RS_PROGRESS_AUTO) is tty when stderr is a terminal, else
 * plain; --quiet is RS_PROGRESS_OFF. */
#ifndef RS_PROGRESS_H
#define RS_PROGRESS_H

#include <stdbool.h>
#include <stdint.h>

/* AUTO is 0 and OFF 1, so a caller's `quiet` flag still means what it did */
typedef enum rs_progress_mode { RS_PROGRESS_AUTO = 0, RS_PROGRESS_OFF, RS_PROGRESS_TTY, RS_PROGRESS_PLAIN } rs_progress_mode;

typedef struct rs_progress {
    const char *label, *unit;
    uint64_t total, done;
    rs_progress_mode mode; /* resolved: never AUTO */
    double start, last, interval;
    bool printed_done; /* plain: the line for `done` is out */
} rs_progress;

/* "tty", "plain" or "off"; false for anything else. */
bool rs_progress_parse(const char *arg, rs_progress_mode *mode);
void rs_progress_start(rs_progress *p, const char *label, const char *unit, uint64_t total, rs_progress_mode mode);
void rs_progress_update(rs_progress *p, uint64_t done);
/* tty: clears the line; plain: prints the last line unless it is out.
 * Returns the seconds since start. */
double rs_progress_end(rs_progress *p);
double rs_now(void);

#endif
