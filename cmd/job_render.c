#include "job_render.h"

#include <inttypes.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/util/rs_progress.h" /* rs_now */
#include "job_err.h"

/* One tick: inputs, then the replay's proof of it. */
static bool step(job_render *j, rs_err *err)
{
    g_step(&j->cur, &j->d.rp->inputs[2 * j->tick], NULL);
    j->tick++;
    if (j->d.no_check || rp_check_tick(j->d.rp, &j->cur, j->tick, &j->next_check, j->d.name, err))
        return true;
    j->desync = j->tick;
    return false;
}

bool job_render_begin(job_render *j, const job_render_desc *desc, rs_err *err)
{
    *j = (job_render){.d = *desc};
    job_render_desc *d = &j->d;
    if (!d->rp || !d->game || !d->target)
        return rs_fail(err, JOB_ERR_ARG, "job_render: the replay, the renderer and the target are required");
    if (!d->name)
        d->name = "replay";
    if (!d->end)
        d->end = d->rp->ticks;
    if (!d->every)
        d->every = 1;
    if (d->end > d->rp->ticks)
        return rs_fail(err, JOB_ERR_TICKS, "%s: tick %" PRIu64 " is past the replay's end (%" PRIu64 " ticks)", d->name, d->end,
                       d->rp->ticks);
    g_init(&j->cur, d->rp->stage, d->rp->seed);
    j->warm_from = d->first;
    r_game_restart(d->game); /* tick 0, or the warm-up's first tick, starts a sequence */
    if (d->first > 0) {
        int64_t h = r_game_history(d->game, j->cur.stage, err);
        if (h < R_GAME_FROM_START)
            return false;
        j->warm_from = h == R_GAME_FROM_START || (uint64_t)h >= d->first ? 0 : d->first - (uint64_t)h;
    }
    while (j->tick < j->warm_from)
        if (!step(j, err))
            return false;
    double t0 = rs_now();
    gl.BindFramebuffer(GL_FRAMEBUFFER, d->target->fbo);
    bool ok = true;
    while (ok && j->tick < d->first) {
        j->prev = j->cur;
        if (!(ok = step(j, err)))
            break;
        bool drew = false;
        if (!(ok = r_game_advance(d->game, &j->prev, &j->cur, d->target->w, d->target->h, d->first - j->tick + 1, &drew,
                                  err)))
            rs_err_prefix(err, "warming up for tick %" PRIu64, d->first);
        j->warm_drawn += drew;
    }
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    j->ms_warm = (rs_now() - t0) * 1e3;
    return ok;
}

int job_render_next(job_render *j, rs_err *err)
{
    const job_render_desc *d = &j->d;
    uint64_t at = d->first + j->frames * d->every; /* this frame's tick */
    if (at >= d->end)
        return 0;
    while (j->tick < at)
        if (!step(j, err))
            return -1;
    double t0 = rs_now();
    j->prev = j->cur;
    if (!step(j, err))
        return -1;
    gl.BindFramebuffer(GL_FRAMEBUFFER, d->target->fbo);
    bool ok = r_game_draw(d->game, &j->prev, &j->cur, 1.0f, d->target->w, d->target->h, err);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    j->ms_draw += (rs_now() - t0) * 1e3;
    j->frames++;
    if (!ok) {
        rs_err_prefix(err, "frame %" PRIu64, at);
        return -1;
    }
    if (d->cap && !cap_frame(d->cap, d->target->tex, err))
        return -1;
    return 1;
}
