/* Progress for long work: "label: done / total unit (pct)  rate  ETA" on
 * stderr, redrawn at most 10 times a second, only when stderr is a
 * terminal and not --quiet, so scripts and logs stay clean. */
#ifndef RS_PROGRESS_H
#define RS_PROGRESS_H

#include <stdbool.h>
#include <stdint.h>

typedef struct rs_progress {
    const char *label, *unit;
    uint64_t total;
    bool on;
    double start, last;
} rs_progress;

void rs_progress_start(rs_progress *p, const char *label, const char *unit, uint64_t total, bool quiet);
void rs_progress_update(rs_progress *p, uint64_t done);
/* Clears the line; returns the seconds since start. */
double rs_progress_end(rs_progress *p);
double rs_now(void);

#endif
