/* job_render: the one replay -> draw -> capture loop, shared by `render`,
 * `bench capture` and `bench accuracy`.
 *
 * The game is re-simulated from tick 0 with the replay's inputs; the frame
 * of tick T is drawn after stepping T's inputs, interpolating nothing
 * (prev = the state before T, cur = after, alpha 1), into the target's
 * framebuffer, and handed to the capture if there is one.  Ticks before the
 * first frame are simulated, and those whose effect history reaches frame
 * `first` (r_game_history) are advanced too, so that any frame is the
 * one a render from tick 0 draws, bit for bit.  Unless told not to, every tick is
 * checked against the replay's checkpoints (rp_check_tick), so a replay
 * that desyncs stops at the first tick that differs.
 *
 *   job_render j;
 *   if (!job_render_begin(&j, &desc, err)) ...
 *   while ((r = job_render_next(&j, err)) > 0)
 *       ... j.tick - 1 was drawn (and captured) ...
 *
 * Runs on the thread that owns the GL context; allocates nothing. */
#ifndef JOB_RENDER_H
#define JOB_RENDER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "../capture/cap.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_target.h"
#include "../runtime/replay/rp.h"

/* Zero means default for every field except the three required ones. */
typedef struct job_render_desc {
    const rp_replay *rp;     /* required */
    r_game *game;            /* required: the renderer (its stage is the replay's, or loads on first draw) */
    const r_target *target;  /* required: drawn into; its size is the draw size */
    cap *cap;                /* each frame goes to it; NULL: drawn only.  May be set in j.d after
                                job_render_begin (a benchmark opens it after the untimed seek) */
    const char *name;        /* the replay's path, for messages; NULL: "replay" */
    uint64_t first;          /* the first tick drawn; 0: tick 0 */
    uint64_t end;            /* one past the last tick drawn; 0: the replay's end */
    uint64_t every;          /* draw one tick in `every` from first; 0: every tick */
    bool no_check;           /* skip the checkpoint checks (benchmarks: nothing to prove, no hashing) */
} job_render_desc;

typedef struct job_render {
    job_render_desc d;       /* with the defaults applied */
    g_state prev, cur;
    uint64_t tick;           /* ticks simulated so far */
    uint64_t frames;         /* frames drawn */
    uint64_t desync;         /* 0, or the tick whose state hash did not match */
    double ms_draw;          /* simulate + draw calls of the drawn frames, on this thread, summed */
    /* the warm-up before the first frame (r_game.h): effect history rebuilt
     * from tick warm_from so that frame `first` is the full render's */
    uint64_t warm_from;      /* first tick advanced (= first when no effect carries history) */
    uint64_t warm_drawn;     /* of the warm-up ticks, those drawn (LSPSM's window) */
    double ms_warm;          /* the warm-up's simulate + advance + draw calls, summed */
    size_t next_check;       /* for rp_check_tick */
} job_render;

/* Applies the defaults, simulates up to the first frame and warms the
 * effects up for it.  False with err filled on a desync (j->desync says
 * where), a bad descriptor or a look that does not load. */
bool job_render_begin(job_render *j, const job_render_desc *desc, rs_err *err);

/* Simulates up to the next frame's tick, steps it, draws it and captures it.
 * 1: a frame was drawn; 0: no frames left; -1: err filled (a desync, a
 * frame the renderer could not draw, a capture failure). */
int job_render_next(job_render *j, rs_err *err);

#endif
