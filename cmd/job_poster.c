/* job_poster: the poster frame of a replay (job_poster.h). */
#include "job_poster.h"

#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../capture/cap.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/util/rs_img.h"
#include "job_err.h"

uint64_t job_poster_tick(const rp_replay *rp, int *why)
{
    g_state st;
    g_init(&st, rp->stage, rp->seed);
    uint64_t ko = 0, win = 0;
    int ko_why = -1;
    bool won = false;
    for (uint64_t t = 0; t < rp->ticks; t++) {
        g_events ev = {0};
        g_step(&st, &rp->inputs[2 * t], &ev);
        for (int i = 0; i < ev.n; i++) {
            if (ev.ev[i].type == G_EV_KO || ev.ev[i].type == G_EV_RING_OUT) {
                ko = t; /* this step's frame is frame t */
                ko_why = ev.ev[i].type == G_EV_KO ? JOB_POSTER_KO : JOB_POSTER_RING_OUT;
            } else if (ev.ev[i].type == G_EV_MATCH_WIN || ev.ev[i].type == G_EV_DRAW) {
                win = t;
                won = true;
            }
        }
    }
    uint64_t pick;
    int w;
    if (ko_why >= 0)
        pick = ko + JOB_POSTER_AFTER_KO, w = ko_why;
    else if (won)
        pick = win + JOB_POSTER_AFTER_WIN, w = JOB_POSTER_MATCH_END;
    else
        pick = rp->ticks / 2, w = JOB_POSTER_MIDDLE;
    if (pick >= rp->ticks)
        pick = rp->ticks - 1;
    if (why)
        *why = w;
    return pick;
}

const char *job_poster_why_name(int why)
{
    static const char *const names[] = {"the last knock-out", "the last ring-out", "the match end", "the middle"};
    return why >= 0 && why <= JOB_POSTER_MIDDLE ? names[why] : "?";
}

bool job_poster_write(const char *path, const r_target *t, int w, int h, rs_err *err)
{
    size_t full = (size_t)t->w * (size_t)t->h * 4, small = (size_t)w * (size_t)h * 4;
    uint8_t *src = malloc(full), *dst = malloc(small);
    bool ok = false;
    if (!src || !dst) {
        rs_fail(err, JOB_ERR_NOMEM, "%s: out of memory for the poster", path);
        goto done;
    }
    /* one synchronous read for one frame: the stall is a few milliseconds once per render */
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, t->w, t->h, GL_RGBA, GL_UNSIGNED_BYTE, src);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    cap_cpu_downscale(src, t->w, t->h, dst, w, h); /* bottom-up in, top-down out */
    /* RGB: the game's alpha is not meant to be seen */
    for (size_t i = 0, n = (size_t)w * (size_t)h; i < n; i++)
        dst[3 * i] = dst[4 * i], dst[3 * i + 1] = dst[4 * i + 1], dst[3 * i + 2] = dst[4 * i + 2];
    ok = rs_png_write(path, w, h, 3, dst, err);
done:
    free(src);
    free(dst);
    return ok;
}

bool job_poster_plan(job_poster *p, const char *path, const rp_replay *rp, uint64_t first, uint64_t end, rs_err *err)
{
    memset(p, 0, sizeof *p);
    if (!path)
        return true;
    p->path = path;
    char dir[1100];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash) {
        slash[slash == dir] = 0; /* "/x.png" -> "/" */
        struct stat st;
        if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
            return rs_fail(err, JOB_ERR_CREATE, "%s: the folder %s does not exist (--poster)", path, dir);
    }
    p->tick = job_poster_tick(rp, &p->why);
    p->due = p->tick >= first && p->tick < end;
    snprintf(p->part, sizeof p->part, "%s.part", path);
    return true;
}

bool job_poster_frame(job_poster *p, uint64_t tick, const r_target *t, int w, int h, rs_err *err)
{
    if (!p->due || p->written || tick != p->tick)
        return true;
    if (!job_poster_write(p->part, t, w, h, err)) {
        unlink(p->part);
        /* the poster's own name, as the user gave it */
        size_t k = strlen(p->part);
        if (err && !strncmp(err->msg, p->part, k) && !strncmp(err->msg + k, ": ", 2)) {
            char why[sizeof err->msg];
            snprintf(why, sizeof why, "%s", err->msg + k + 2);
            snprintf(err->msg, sizeof err->msg, "%s: %s (the poster, tick %" PRIu64 ")", p->path, why, tick);
        }
        return false;
    }
    p->written = true;
    return true;
}

bool job_poster_commit(job_poster *p, rs_err *err)
{
    if (!p->written)
        return true;
    if (rename(p->part, p->path) != 0) {
        int e = errno;
        job_poster_abandon(p);
        return rs_fail(err, JOB_ERR_WRITE, "%s: cannot put the poster in place: %s", p->path, strerror(e));
    }
    p->written = false;
    return true;
}

void job_poster_abandon(job_poster *p)
{
    if (p->written)
        unlink(p->part);
    p->written = false;
}
