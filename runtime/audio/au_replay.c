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
 * the whole match's), so every call mixes the whole match, whatever range
 * it returns; that is what makes the audio of ticks A..B exactly those
 * samples of the full track, and joined segments equal one render.  The
 * cost is the whole match per call: the mixing takes about 1/4000 of real
 * time, the loudness measurements most of the rest, about 1/100 in all
 * (docs/audio.md has the figures).  Without normalization only ticks
 * 0..end-1 are simulated and only the range is kept. */
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "au_local.h"

bool au_replay_track(const rp_replay *rp, const char *name, uint64_t first, uint64_t end, const au_replay_opts *o,
                     au_track *t, rs_err *err)
{
    memset(t, 0, sizeof *t);
    au_replay_opts opt = o ? *o : (au_replay_opts){0};
    if (!name)
        name = "replay";
    if (!end)
        end = rp->ticks;
    if (first >= end || end > rp->ticks)
        return rs_fail(err, AU_ERR_ARG, "%s: ticks %" PRIu64 ":%" PRIu64 " are not a range inside the replay's 0:%" PRIu64,
                       name, first, end, rp->ticks);
    bool normalize = !isnan(opt.target_lufs);
    double target = opt.target_lufs == 0 ? -16.0 : opt.target_lufs, peak = opt.peak_dbtp == 0 ? -1.0 : opt.peak_dbtp;
    if (normalize && (!isfinite(target) || target < -70 || target > 0 || !isfinite(peak) || peak > 0 || peak < -30))
        return rs_fail(err, AU_ERR_ARG, "%s: loudness target %.1f LUFS, ceiling %.1f dBTP (expected -70..0 and -30..0)",
                       name, target, peak);
    /* normalizing: the whole match is kept, then the range copied out */
    uint64_t from = normalize ? 0 : first, to = normalize ? rp->ticks : end;
    if ((to - from) > SIZE_MAX / (AU_TICK_FRAMES * 2 * sizeof(float)))
        return rs_fail(err, AU_ERR_NOMEM, "%s: %" PRIu64 " ticks of audio do not fit in memory", name, to - from);
    size_t frames = (size_t)(to - from) * AU_TICK_FRAMES;
    float *pcm = malloc(frames * 2 * sizeof *pcm);
    au_mixer *m = au_mixer_new(&opt.mix, err);
    bool ok = false;
    if (!pcm || !m) {
        rs_fail(err, AU_ERR_NOMEM, "%s: out of memory for %zu frames of audio", name, frames);
        goto done;
    }
    g_state st, prev;
    g_init(&st, rp->stage, rp->seed);
    size_t next = 0;
    float scratch[AU_TICK_FRAMES * 2];
    for (uint64_t k = 0; k < to; k++) {
        g_events ev;
        prev = st;
        g_step(&st, &rp->inputs[2 * k], &ev);
        if (!opt.no_check && !rp_check_tick(rp, &st, k + 1, &next, name, err)) {
            err->code = AU_ERR_DESYNC; /* a desync, or other rules that do not reproduce: the message says which */
            goto done;
        }
        au_cue cues[AU_MAX_CUES];
        int n = au_game_cues(&prev, &st, &ev, cues, AU_MAX_CUES);
        for (int i = 0; i < n; i++)
            au_mixer_cue(m, &cues[i]);
        au_mixer_music(m, st.stage);
        float *dst = k >= from ? pcm + (size_t)(k - from) * AU_TICK_FRAMES * 2 : scratch;
        au_mixer_mix(m, dst, AU_TICK_FRAMES, NULL, 0);
    }
    if (normalize) {
        au_loudness b, a;
        if (!au_loud_normalize(pcm, frames, target, peak, &b, &a, err)) {
            rs_err_prefix(err, "%s", name);
            goto done;
        }
        t->lufs_before = b.integrated;
        t->lufs_after = a.integrated;
        t->peak_before = b.true_peak;
        t->peak_after = a.true_peak;
        t->gain_db = isfinite(b.integrated) ? target - b.integrated : 0;
        size_t keep = (size_t)(end - first) * AU_TICK_FRAMES;
        memmove(pcm, pcm + (size_t)first * AU_TICK_FRAMES * 2, keep * 2 * sizeof *pcm);
        float *shrunk = realloc(pcm, keep * 2 * sizeof *pcm);
        pcm = shrunk ? shrunk : pcm;
        frames = keep;
    } else {
        t->lufs_before = t->lufs_after = t->peak_before = t->peak_after = NAN;
    }
    t->pcm = pcm;
    t->frames = frames;
    t->first = first;
    t->end = end;
    pcm = NULL;
    ok = true;
done:
    free(pcm);
    au_mixer_free(m);
    return ok;
}

void au_track_free(au_track *t)
{
    free(t->pcm);
    memset(t, 0, sizeof *t);
}
