/* job_audio: the soundtrack of a render or a join (job_audio.h).
 *
 * DESIGN
 * - The track is measured before the first frame (au_replay_open
 *   simulates the match from tick 0 and measures all of it) and then read
 *   as the video is written, the match mixed again on the way: a render of
 *   ticks A..B and a render of the whole match agree sample for sample on
 *   A..B, the sink interleaves audio with video as each frame is written,
 *   and the memory does not grow with the match's length.
 * - --audio defaults to on exactly when the output's container carries
 *   audio (cap_sink_audio_codec); Y4M, image sequences and segments get
 *   none, and --wav gives the track to any of them. */
#include "job_audio.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../capture/cap_enc.h"
#include "cli.h"

static bool read_track(void *u, float *dst, size_t frames, rs_err *err)
{
    return au_replay_read(u, dst, frames, err);
}

bool job_audio_option(job_audio *a, const char *cmd, int opt, const char *arg)
{
    char *end;
    switch (opt) {
    case JOB_AUDIO_OPT_AUDIO:
        if (!strcmp(arg, "on"))
            a->mode = JOB_AUDIO_ON;
        else if (!strcmp(arg, "off"))
            a->mode = JOB_AUDIO_OFF;
        else {
            cli_error(cmd, "--audio '%s': expected on or off", arg);
            return false;
        }
        return true;
    case JOB_AUDIO_OPT_BITRATE:
        if (!cap_bitrate_parse(arg, &a->bitrate)) {
            cli_error(cmd, "--audio-bitrate '%s': expected bits a second such as 192k or 128000 (AAC 32k..512k, Opus 16k..510k)",
                      arg);
            return false;
        }
        return true;
    case JOB_AUDIO_OPT_LOUDNESS:
        a->lufs = strtod(arg, &end);
        if (end == arg || *end || !(a->lufs >= JOB_AUDIO_LUFS_MIN && a->lufs <= JOB_AUDIO_LUFS_MAX)) {
            cli_error(cmd, "--loudness '%s': expected an integrated loudness in LUFS from %.0f to %.0f, such as -16", arg,
                      JOB_AUDIO_LUFS_MIN, JOB_AUDIO_LUFS_MAX);
            return false;
        }
        return true;
    case JOB_AUDIO_OPT_WAV:
        a->wav = arg;
        return true;
    default:
        return false;
    }
}

bool job_audio_check(job_audio *a, const char *cmd, cap_sink *s, bool *usage, rs_err *err)
{
    *usage = true;
    const char *codec = cap_sink_audio_codec(s);
    if (a->mode == JOB_AUDIO_ON && !codec)
        return rs_fail(err, CAP_ERR_ENC_SETTING, "--audio on: %s carries no audio (%s); use --wav FILE for the track", s->path,
                       s->segment ? "segments are silent: join --replay mixes the sound once for the whole video"
                                  : ".mp4, .mkv, .nut and .webm do");
    if (a->mode == JOB_AUDIO_AUTO)
        a->mode = codec ? JOB_AUDIO_ON : JOB_AUDIO_OFF;
    if (a->mode == JOB_AUDIO_OFF && a->bitrate)
        return rs_fail(err, CAP_ERR_ENC_SETTING, "--audio-bitrate: %s gets no audio stream%s", s->path,
                       codec ? " (--audio off)" : "");
    /* the bitrate against the container's codec, before anything is mixed (the track comes later) */
    if (a->mode == JOB_AUDIO_ON) {
        if (!cap_sink_audio(s, read_track, NULL, 0, a->bitrate, err))
            return false;
        s->audio = NULL;
    }
    *usage = false; /* an output that exists or has no folder: exit 1, as for the others */
    if (a->wav && !cli_out_ok(cmd, a->wav, a->overwrite)) {
        err->msg[0] = 0; /* said */
        return false;
    }
    return true;
}

bool job_audio_plan(job_audio *a, cap_sink *s, const rp_replay *rp, const char *name, uint64_t first, uint64_t end,
                    rs_err *err)
{
    if (a->mode != JOB_AUDIO_ON && !a->wav)
        return true;
    /* no_check: the render's own loop checks the checkpoints of the ticks it
     * draws and reports a desync its way ("desync TICK" on --progress-fd,
     * which the service reads); join's segments were checked as rendered */
    au_replay_opts o = {.target_lufs = a->lufs ? a->lufs : JOB_AUDIO_LUFS_DEFAULT, .no_check = true};
    if (!(a->track = au_replay_open(rp, name, first, end, &o, err)))
        return false;
    if (a->mode == JOB_AUDIO_ON) {
        if (!cap_sink_audio(s, read_track, a->track, au_replay_info(a->track)->frames, a->bitrate, err))
            return false;
        a->muxed = true;
    }
    return true;
}

bool job_audio_commit(job_audio *a, rs_err *err)
{
    if (!a->wav)
        return true;
    if (a->muxed && !au_replay_rewind(a->track, err))
        return false;
    size_t frames = au_replay_info(a->track)->frames;
    enum { PIECE = AU_TICK_FRAMES * 60 };
    float *buf = malloc(PIECE * 2 * sizeof *buf);
    au_wav *w = buf ? au_wav_open_known(a->wav, false, frames, err) : NULL;
    if (!buf)
        rs_fail(err, AU_ERR_NOMEM, "%s: out of memory", a->wav);
    bool ok = w != NULL;
    for (size_t at = 0; ok && at < frames;) {
        size_t n = frames - at < PIECE ? frames - at : PIECE;
        ok = au_replay_read(a->track, buf, n, err) && au_wav_append(w, buf, n, err);
        at += n;
    }
    if (w)
        ok = au_wav_close(w, ok, ok ? err : &(rs_err){0}) && ok;
    free(buf);
    return ok;
}

void job_audio_describe(const job_audio *a, const cap_sink *s, char *out, size_t n)
{
    out[0] = 0;
    if ((!a->muxed && !a->wav) || !a->track)
        return;
    char what[64] = "";
    if (a->muxed)
        snprintf(what, sizeof what, "%s %lld kb/s", s->audio_codec, (long long)(s->audio_bitrate / 1000));
    snprintf(out, n, "; audio %s%s%s, %.1f LUFS (%+.1f dB), true peak %.1f dBTP", what, a->muxed && a->wav ? " and " : "",
             a->wav ? a->wav : "", au_replay_info(a->track)->lufs_after, au_replay_info(a->track)->gain_db,
             au_replay_info(a->track)->peak_after);
}

void job_audio_free(job_audio *a)
{
    au_replay_close(a->track);
    a->track = NULL;
}
