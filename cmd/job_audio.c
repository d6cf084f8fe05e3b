/* job_audio: the soundtrack of a render or a join (job_audio.h).
 *
 * DESIGN
 * - The track is mixed before the first frame, whole (au_replay_track
 *   simulates the match from tick 0, measures and normalizes all of it,
 *   then cuts the command's ticks): a render of ticks A..B and a render of
 *   the whole match agree sample for sample on A..B, and the sink can
 *   interleave audio with video as each frame is written.
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
    static const float probe[2];
    if (a->mode == JOB_AUDIO_ON) {
        if (!cap_sink_audio(s, probe, 0, a->bitrate, err))
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
    if (!au_replay_track(rp, name, first, end, &o, &a->track, err))
        return false;
    if (a->mode == JOB_AUDIO_ON) {
        if (!cap_sink_audio(s, a->track.pcm, a->track.frames, a->bitrate, err))
            return false;
        a->muxed = true;
    }
    return true;
}

bool job_audio_commit(job_audio *a, rs_err *err)
{
    return !a->wav || au_wav_write(a->wav, a->track.pcm, a->track.frames, false, err);
}

void job_audio_describe(const job_audio *a, const cap_sink *s, char *out, size_t n)
{
    out[0] = 0;
    if (!a->muxed && !a->wav)
        return;
    char what[64] = "";
    if (a->muxed)
        snprintf(what, sizeof what, "%s %lld kb/s", s->audio_codec, (long long)(s->audio_bitrate / 1000));
    snprintf(out, n, "; audio %s%s%s, %.1f LUFS (%+.1f dB), true peak %.1f dBTP", what, a->muxed && a->wav ? " and " : "",
             a->wav ? a->wav : "", a->track.lufs_after, a->track.gain_db, a->track.peak_after);
}

void job_audio_free(job_audio *a)
{
    if (a->track.pcm)
        au_track_free(&a->track);
}
