#include "job_render.h"

#include <inttypes.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/util/rs_progress.h" /* rs_now */

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
        return rs_fail(err, 1, "job_render: the replay, the renderer and the target are required");
    if (!d->name)
        d->name = "replay";
    if (!d->end)
        d->end = d->rp->ticks;
    if (!d->every)
        d->every = 1;
    if (d->end > d->rp->ticks)
        return rs_fail(err, 1, "%s: tick %" PRIu64 " is past the replay's end (%" PRIu64 " ticks)", d->name, d->end,
                       d->rp->ticks);
    g_init(&j->cur, d->rp->stage, d->rp->seed);
    while (j->tick < d->first)
        if (!step(j, err))
            return false;
    return true;
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
    bool ok = r_game_draw(d->game, &j->prev, &j->cur, 1.0f, d->target->w, d->target->h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    j->ms_draw += (rs_now() - t0) * 1e3;
    j->frames++;
    if (!ok) {
        rs_fail(err, 1, "frame %" PRIu64 ": %s", at, r_game_error(d->game));
        return -1;
    }
    if (d->cap && !cap_frame(d->cap, d->target->tex, err))
        return -1;
    return 1;
}
