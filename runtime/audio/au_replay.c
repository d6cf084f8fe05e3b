/* A replay's soundtrack: the game simulated from tick 0, each tick's cues
 * mixed into its own AU_TICK_FRAMES frames, the whole match normalized,
 * then the range asked for cut out.
 *
 * Timing, as the renderer's (cmd/job_render.c): video frame t shows the
 * state that step t (the inputs of tick t) produced, so the cues of step t
 * start in frames t * AU_TICK_FRAMES .. (t + 1) * AU_TICK_FRAMES - 1, at
 * their offsets.
 *
 * DESIGN: the loudness of a range depends on the whole match (the gain is
 * the whole match's), so every stream measures the whole match, whatever
 * range it gives; that is what makes the audio of ticks A..B exactly those
 * samples of the full track, and joined segments equal one render.  No
 * track is ever held: the match is simulated and mixed again for every
 * read of it (au_norm_plan's measurement and passes, then the stream),
 * so memory does not grow with the match's length; the mixing takes about
 * 1/4000 of real time, the loudness measurements most of the rest
 * (docs/audio.md has the figures).  Without normalization the stream
 * simulates ticks 0..end-1 once and gives the range. */
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "au_local.h"

/* ---- the match as an au_source: simulated and mixed from tick 0 ---- */

typedef struct mix_src {
    const rp_replay *rp;
    const char *name;
    au_mix_opts mix;
    bool check;
    au_mixer *m;
    g_state st;
    uint64_t tick;                  /* the next tick to mix */
    size_t next;                    /* rp_check_tick's place */
    float buf[AU_TICK_FRAMES * 2];  /* the last tick mixed */
    size_t at;                      /* frames of it given */
} mix_src;

static bool mix_rewind(void *u, rs_err *err)
{
    mix_src *s = u;
    /* a new mixer, as the first read had (au_mixer_reset keeps its music) */
    au_mixer_free(s->m);
    if (!(s->m = au_mixer_new(&s->mix, err)))
        return false;
    g_init(&s->st, s->rp->stage, s->rp->seed);
    s->tick = 0, s->next = 0, s->at = AU_TICK_FRAMES;
    return true;
}

static bool mix_tick(mix_src *s, rs_err *err)
{
    g_state prev = s->st;
    g_events ev;
    uint64_t k = s->tick;
    if (k >= s->rp->ticks)
        return rs_fail(err, AU_ERR_ARG, "%s: read past the replay's end (%" PRIu64 " ticks)", s->name, s->rp->ticks);
    g_step(&s->st, &s->rp->inputs[2 * k], &ev);
    if (s->check && !rp_check_tick(s->rp, &s->st, k + 1, &s->next, s->name, err)) {
        err->code = AU_ERR_DESYNC; /* a desync, or other rules that do not reproduce: the message says which */
        return false;
    }
    au_cue cues[AU_MAX_CUES];
    int n = au_game_cues(&prev, &s->st, &ev, cues, AU_MAX_CUES);
    for (int i = 0; i < n; i++)
        au_mixer_cue(s->m, &cues[i]);
    au_mixer_music(s->m, s->st.stage);
    au_mixer_mix(s->m, s->buf, AU_TICK_FRAMES, NULL, 0);
    s->tick = k + 1;
    s->at = 0;
    return true;
}

static bool mix_read(void *u, float *dst, size_t frames, rs_err *err)
{
    mix_src *s = u;
    while (frames) {
        if (s->at == AU_TICK_FRAMES && !mix_tick(s, err))
            return false;
        size_t n = AU_TICK_FRAMES - s->at < frames ? AU_TICK_FRAMES - s->at : frames;
        memcpy(dst, s->buf + 2 * s->at, n * 2 * sizeof *dst);
        s->at += n, dst += 2 * n, frames -= n;
    }
    return true;
}

struct au_replay_stream {
    mix_src mix;
    au_source src;
    au_norm_stream *norm; /* NULL: not normalized */
    au_track_info info;
    size_t skip, frames, given;
};

au_replay_stream *au_replay_open(const rp_replay *rp, const char *name, uint64_t first, uint64_t end,
                                 const au_replay_opts *o, rs_err *err)
{
    au_replay_opts opt = o ? *o : (au_replay_opts){0};
    if (!name)
        name = "replay";
    if (!end)
        end = rp->ticks;
    if (first >= end || end > rp->ticks) {
        rs_fail(err, AU_ERR_ARG, "%s: ticks %" PRIu64 ":%" PRIu64 " are not a range inside the replay's 0:%" PRIu64, name,
                first, end, rp->ticks);
        return NULL;
    }
    bool normalize = !isnan(opt.target_lufs);
    double target = opt.target_lufs == 0 ? -16.0 : opt.target_lufs, peak = opt.peak_dbtp == 0 ? -1.0 : opt.peak_dbtp;
    if (normalize && (!isfinite(target) || target < -70 || target > 0 || !isfinite(peak) || peak > 0 || peak < -30)) {
        rs_fail(err, AU_ERR_ARG, "%s: loudness target %.1f LUFS, ceiling %.1f dBTP (expected -70..0 and -30..0)", name,
                target, peak);
        return NULL;
    }
    /* normalizing: the whole match is the source, then the range read out */
    uint64_t to = normalize ? rp->ticks : end;
    if (to > SIZE_MAX / AU_TICK_FRAMES / 2) {
        rs_fail(err, AU_ERR_ARG, "%s: %" PRIu64 " ticks of audio are too many to count", name, to);
        return NULL;
    }
    au_replay_stream *s = calloc(1, sizeof *s);
    if (!s) {
        rs_fail(err, AU_ERR_NOMEM, "%s: out of memory for the audio", name);
        return NULL;
    }
    s->mix = (mix_src){.rp = rp, .name = name, .mix = opt.mix, .check = !opt.no_check};
    s->src = (au_source){mix_read, mix_rewind, &s->mix, (size_t)to * AU_TICK_FRAMES};
    s->skip = (size_t)first * AU_TICK_FRAMES;
    s->frames = (size_t)(end - first) * AU_TICK_FRAMES;
    s->info = (au_track_info){.frames = s->frames, .first = first, .end = end};
    bool ok;
    if (normalize) {
        au_norm plan;
        ok = au_norm_plan_peak(&s->src, target, peak, opt.before_peak, &plan, err) && (s->norm = au_norm_stream_new(&s->src, &plan, err));
        if (!ok)
            rs_err_prefix(err, "%s", name);
        s->info.lufs_before = plan.before.integrated;
        s->info.lufs_after = plan.after.integrated;
        s->info.peak_before = plan.before.true_peak;
        s->info.peak_after = plan.after.true_peak;
        s->info.gain_db = plan.on ? plan.gain_db : 0;
    } else {
        s->info.lufs_before = s->info.lufs_after = s->info.peak_before = s->info.peak_after = NAN;
        ok = true;
    }
    ok = ok && au_replay_rewind(s, err);
    if (!ok) {
        au_replay_close(s);
        return NULL;
    }
    return s;
}

const au_track_info *au_replay_info(const au_replay_stream *s)
{
    return &s->info;
}

bool au_replay_rewind(au_replay_stream *s, rs_err *err)
{
    s->given = 0;
    if (!(s->norm ? au_norm_stream_rewind(s->norm, err) : s->src.rewind(s->src.u, err)))
        return false;
    /* up to the range's first frame: read and dropped */
    float drop[AU_TICK_FRAMES * 2];
    for (size_t at = 0; at < s->skip;) {
        size_t n = s->skip - at < AU_TICK_FRAMES ? s->skip - at : AU_TICK_FRAMES;
        if (!(s->norm ? au_norm_stream_read(s->norm, drop, n, err) : s->src.read(s->src.u, drop, n, err)))
            return false;
        at += n;
    }
    return true;
}

bool au_replay_read(au_replay_stream *s, float *dst, size_t frames, rs_err *err)
{
    if (frames > s->frames - s->given)
        return rs_fail(err, AU_ERR_ARG, "%s: audio read past ticks %" PRIu64 ":%" PRIu64, s->mix.name, s->info.first,
                       s->info.end);
    s->given += frames;
    return s->norm ? au_norm_stream_read(s->norm, dst, frames, err) : s->src.read(s->src.u, dst, frames, err);
}

void au_replay_close(au_replay_stream *s)
{
    if (!s)
        return;
    au_norm_stream_free(s->norm);
    au_mixer_free(s->mix.m);
    free(s);
}

bool au_replay_track(const rp_replay *rp, const char *name, uint64_t first, uint64_t end, const au_replay_opts *o,
                     au_track *t, rs_err *err)
{
    memset(t, 0, sizeof *t);
    au_replay_stream *s = au_replay_open(rp, name, first, end, o, err);
    if (!s)
        return false;
    const au_track_info *in = au_replay_info(s);
    t->frames = in->frames, t->first = in->first, t->end = in->end, t->gain_db = in->gain_db;
    t->lufs_before = in->lufs_before, t->lufs_after = in->lufs_after;
    t->peak_before = in->peak_before, t->peak_after = in->peak_after;
    bool ok = (t->pcm = malloc(t->frames * 2 * sizeof *t->pcm)) != NULL;
    if (!ok)
        rs_fail(err, AU_ERR_NOMEM, "%s: out of memory for %zu frames of audio", name ? name : "replay", t->frames);
    ok = ok && au_replay_read(s, t->pcm, t->frames, err);
    au_replay_close(s);
    if (!ok)
        au_track_free(t);
    return ok;
}

void au_track_free(au_track *t)
{
    free(t->pcm);
    memset(t, 0, sizeof *t);
}
