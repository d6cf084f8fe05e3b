#include "rs_progress.h"

#include <stdio.h>
#include <time.h>
#include <unistd.h>

double rs_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

void rs_progress_start(rs_progress *p, const char *label, const char *unit, uint64_t total, bool quiet)
{
    p->label = label;
    p->unit = unit;
    p->total = total;
    p->on = !quiet && isatty(2);
    p->start = rs_now();
    p->last = 0;
}

void rs_progress_update(rs_progress *p, uint64_t done)
{
    if (!p->on)
        return;
    double t = rs_now();
    if (t - p->last < 0.1 && done < p->total)
        return;
    p->last = t;
    double el = t - p->start, rate = el > 0 ? done / el : 0;
    double eta = rate > 0 && p->total > done ? (p->total - done) / rate : 0;
    fprintf(stderr, "\r%s: %llu / %llu %s (%3.0f%%)  %.0f %s/s  ETA %d:%02d   ", p->label, (unsigned long long)done,
            (unsigned long long)p->total, p->unit, p->total ? 100.0 * done / p->total : 100.0, rate, p->unit,
            (int)eta / 60, (int)eta % 60);
    fflush(stderr);
}

double rs_progress_end(rs_progress *p)
{
    if (p->on)
        fprintf(stderr, "\r%*s\r", 78, "");
    return rs_now() - p->start;
}
