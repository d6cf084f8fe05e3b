#include "loop.h"

#include <string.h>

#include "util/rs_progress.h"

#define SNAP 0.0005 /* seconds */

void lp_run(const lp_desc *desc, const lp_game *g, lp_stats *st)
{
    lp_desc d = *desc;
    if (!d.hz)
        d.hz = G_HZ;
    if (d.max_stall <= 0)
        d.max_stall = 0.25;
    if (d.max_ticks_per_frame <= 0)
        d.max_ticks_per_frame = 8;
    if (!d.now)
        d.now = rs_now;
    memset(st, 0, sizeof *st);
    double start = d.now();

    if (d.headless) {
        while (g->running(g->user)) {
            g_input in[2];
            g->input(g->user, in);
            g->step(g->user, in);
            st->ticks++;
            g->render(g->user, 1.0f);
            st->frames++;
        }
        st->seconds = d.now() - start;
        return;
    }

    /* time is counted in whole ticks plus a fraction, so the accumulator
     * never drifts from the tick counter however long the loop runs */
    const double step = 1.0 / d.hz;
    double prev = start, acc = 0;
    while (g->running(g->user)) {
        double t = d.now(), dt = t - prev;
        prev = t;
        if (dt > d.max_stall) {
            st->stalls++;
            dt = d.max_stall;
        }
        if (dt < 0)
            dt = 0;
        /* vsync snapping: a display at 60 Hz delivers frames 16.6 +- 0.3 ms
         * apart; without this, that jitter alternates 0 and 2 ticks per
         * frame and every other tick would show late */
        for (int k = 1; k <= 4; k++)
            if (dt > k * step - SNAP && dt < k * step + SNAP) {
                dt = k * step;
                break;
            }
        acc += dt;
        int n = 0;
        while (acc >= step && n < d.max_ticks_per_frame && g->running(g->user)) {
            g_input in[2];
            g->input(g->user, in);
            g->step(g->user, in);
            acc -= step;
            st->ticks++;
            n++;
        }
        if (n > 1)
            st->late_ticks += (uint64_t)(n - 1);
        if (acc >= step) { /* still behind after the cap: drop the backlog */
            st->dropped_ticks += (uint64_t)(acc / step);
            acc -= step * (uint64_t)(acc / step);
        }
        g->render(g->user, (float)(acc / step));
        st->frames++;
    }
    st->seconds = d.now() - start;
}
