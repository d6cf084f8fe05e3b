/* The fixed-timestep loop: the game ticks at exactly 60 Hz whatever the
 * display does.
 *
 * Windowed: an accumulator of real time runs as many ticks as are due,
 * then renders once, interpolating between the last two states (alpha).
 * A tick that had to run in the same frame as another missed its own
 * frame: it is counted as late (the target is zero: a hard 60 fps).
 * A stall longer than max_stall (a debugger, a suspended laptop) is cut,
 * so the game never races to catch up with minutes of wall time.
 * A frame time within 0.5 ms of a whole number of ticks counts as exactly
 * that (vsync snapping), so display jitter is not mistaken for lateness.
 * Headless: one tick, one frame, as fast as possible.
 *
 * The loop knows nothing of the game: it calls the interface below.  The
 * simulation never sees wall-clock time; only this loop reads the clock. */
#ifndef LOOP_H
#define LOOP_H

#include <stdbool.h>
#include <stdint.h>

#include "game/g_game.h"

typedef struct lp_game {
    void *user;
    void (*input)(void *user, g_input in[2]);      /* inputs for the next tick */
    void (*step)(void *user, const g_input in[2]); /* advance one tick */
    void (*render)(void *user, float alpha);       /* draw (and present) a frame */
    bool (*running)(void *user);                   /* false ends the loop */
} lp_game;

typedef struct lp_desc {
    bool headless;           /* one tick per frame, no clock */
    int hz;                  /* 0 -> 60 */
    double max_stall;        /* seconds; 0 -> 0.25 */
    int max_ticks_per_frame; /* 0 -> 8; the rest of a longer backlog is dropped */
    double (*now)(void);     /* 0 -> the monotonic clock; tests pass a fake */
} lp_desc;

typedef struct lp_stats {
    uint64_t ticks, frames;
    uint64_t late_ticks;    /* ticks that shared a frame with an earlier tick */
    uint64_t stalls;        /* gaps longer than max_stall that were cut */
    uint64_t dropped_ticks; /* backlog beyond max_ticks_per_frame, not run */
    double seconds;         /* wall time in the loop */
} lp_stats;

void lp_run(const lp_desc *desc, const lp_game *g, lp_stats *stats);

#endif
