/* job_poster: one frame of a replay worth showing (render --poster): which
 * tick, chosen by simulating the replay before anything is drawn, and the
 * PNG of it, read back from the render target and downscaled to the
 * output size.
 *
 *   int why;
 *   uint64_t t = job_poster_tick(&rp, &why);
 *   ... draw tick t into target ...
 *   job_poster_write(path, &target, w, h, err);
 *
 * The choice (DESIGN): a fight's most telling moment is its end.  The last
 * knock-out or ring-out, JOB_POSTER_AFTER_KO ticks on, so the fallen
 * fighter lies on the floor (or is over the edge) with the winner still
 * standing; else the last match's end (a time-up), JOB_POSTER_AFTER_WIN
 * ticks on, where the winner poses; else (an unfinished replay) the middle
 * tick.  Always a tick of the replay: clamped to its last. */
#ifndef JOB_POSTER_H
#define JOB_POSTER_H

#include <stdbool.h>
#include <stdint.h>

#include "../runtime/render/r_target.h"
#include "../runtime/replay/rp.h"

#define JOB_POSTER_AFTER_KO 45  /* 0.75 s: the KO fall is over, the round-end banner up */
#define JOB_POSTER_AFTER_WIN 60 /* 1 s into the match-end announcement */

typedef enum job_poster_why { JOB_POSTER_KO, JOB_POSTER_RING_OUT, JOB_POSTER_MATCH_END, JOB_POSTER_MIDDLE } job_poster_why;

/* The frame index (the tick whose frame a render writes: 0..ticks-1) of
 * the poster; *why (may be NULL) says what it shows.  rp->ticks > 0. */
uint64_t job_poster_tick(const rp_replay *rp, int *why);
const char *job_poster_why_name(int why);

/* A render's poster: planned before drawing, written when its tick is
 * drawn (as PATH.part), put in place when the render succeeds. */
typedef struct job_poster {
    const char *path;  /* NULL: no poster asked for */
    uint64_t tick;     /* the chosen frame */
    int why;           /* job_poster_why */
    bool due;          /* tick lies in the ticks this render draws */
    bool written;      /* PATH.part holds it */
    char part[1100];
} job_poster;

/* Chooses the tick; due only when it lies in first..end-1 (--ticks), so
 * each segment of a split render may be given --poster and the one that
 * draws the tick writes it.  False (err names the path) when the folder
 * does not exist. */
bool job_poster_plan(job_poster *p, const char *path, const rp_replay *rp, uint64_t first, uint64_t end, rs_err *err);
/* After drawing frame `tick` into t: writes the poster if this is its tick. */
bool job_poster_frame(job_poster *p, uint64_t tick, const r_target *t, int w, int h, rs_err *err);
/* The render succeeded: PATH.part becomes PATH.  Or it failed: PATH.part goes. */
bool job_poster_commit(job_poster *p, rs_err *err);
void job_poster_abandon(job_poster *p);

/* Reads target t (as drawn: bottom-up RGBA), downscales it to w x h by
 * the capture's CPU area average and writes it as an RGB PNG. */
bool job_poster_write(const char *path, const r_target *t, int w, int h, rs_err *err);

#endif
