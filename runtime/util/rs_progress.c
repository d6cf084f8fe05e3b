/* Progress lines on stderr (rs_progress.h): tty redraws one line, plain
 * appends one every few seconds. */
#include "rs_progress.h"
#include "rs_log.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define HZ 60.0 /* ticks and frames are 1/60 s of game time */

double rs_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec / 1e9;
}

bool rs_progress_parse(const char *arg, rs_progress_mode *mode)
{
    if (!strcmp(arg, "tty"))
        *mode = RS_PROGRESS_TTY;
    else if (!strcmp(arg, "plain"))
        *mode = RS_PROGRESS_PLAIN;
    else if (!strcmp(arg, "off"))
        *mode = RS_PROGRESS_OFF;
    else
        return false;
    return true;
}

void rs_progress_start(rs_progress *p, const char *label, const char *unit, uint64_t total, rs_progress_mode mode)
{
    memset(p, 0, sizeof *p);
    p->label = label;
    p->unit = unit;
    p->total = total;
    p->mode = !rs_log_on(RS_LOG_INFO) ? RS_PROGRESS_OFF /* -q, --loglevel error */
              : mode != RS_PROGRESS_AUTO ? mode
              : isatty(2) ? RS_PROGRESS_TTY
                          : RS_PROGRESS_PLAIN;
    p->start = p->last = rs_now();
    p->interval = 5;
    const char *env = getenv("RS_PROGRESS_INTERVAL"); /* tests shorten it */
    if (env) {
        char *end;
        double v = strtod(env, &end);
        if (end != env && !*end && v >= 0)
            p->interval = v;
    }
}

/* "m:ss", or "h:mm:ss" from an hour on */
static const char *clock_of(double s, char *buf, size_t n)
{
    long t = s > 0 ? (long)(s + 0.5) : 0;
    if (t >= 3600)
        snprintf(buf, n, "%ld:%02ld:%02ld", t / 3600, t / 60 % 60, t % 60);
    else
        snprintf(buf, n, "%ld:%02ld", t / 60, t % 60);
    return buf;
}

static void print_line(rs_progress *p, double now)
{
    double el = now - p->start, rate = el > 0 ? p->done / el : 0;
    double eta = rate > 0 && p->total > p->done ? (p->total - p->done) / rate : 0;
    double pct = p->total ? 100.0 * p->done / p->total : 100.0;
    char rate_unit[32], e1[16], e2[16];
    snprintf(rate_unit, sizeof rate_unit, strcmp(p->unit, "frames") ? "%s/s" : "fps", p->unit);
    if (p->mode == RS_PROGRESS_TTY)
        fprintf(stderr, "\r%s: %llu / %llu %s (%3.0f%%)  %.1f %s  %.2fx  elapsed %s  ETA %s   ", p->label,
                (unsigned long long)p->done, (unsigned long long)p->total, p->unit, pct, rate, rate_unit, rate / HZ,
                clock_of(el, e1, sizeof e1), clock_of(eta, e2, sizeof e2));
    else
        fprintf(stderr, "ringside %s: %llu/%llu %s (%.0f%%), %.1f %s, %.2fx, elapsed %s, ETA %s\n", p->label,
                (unsigned long long)p->done, (unsigned long long)p->total, p->unit, pct, rate, rate_unit, rate / HZ,
                clock_of(el, e1, sizeof e1), clock_of(eta, e2, sizeof e2));
    fflush(stderr);
}

void rs_progress_update(rs_progress *p, uint64_t done)
{
    if (p->mode == RS_PROGRESS_OFF)
        return;
    p->done = done;
    p->printed_done = false;
    double t = rs_now();
    if (p->mode == RS_PROGRESS_TTY ? t - p->last < 0.1 && done < p->total : t - p->last < p->interval)
        return;
    p->last = t;
    p->printed_done = true;
    print_line(p, t);
}

double rs_progress_end(rs_progress *p)
{
    double now = rs_now();
    if (p->mode == RS_PROGRESS_TTY)
        fprintf(stderr, "\r%*s\r", 100, "");
    else if (p->mode == RS_PROGRESS_PLAIN && !p->printed_done)
        print_line(p, now);
    return now - p->start;
}
