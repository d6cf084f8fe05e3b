/* movie's and attract's sound options and output (snd_out.h). */
#include "snd_out.h"
#include "../runtime/util/rs_log.h"

#include <stdio.h>
#include <stdlib.h>

#include "../runtime/util/rs_out.h"
#include "cli.h"

bool snd_volume_arg(const char *cmd, const char *arg, snd_opts *o)
{
    char *end;
    double v = strtod(arg, &end);
    if (end == arg || *end || !(v >= 0 && v <= 1)) {
        cli_error(cmd, "--volume '%s': expected a number from 0 (silent) to 1 (full)", arg);
        return false;
    }
    o->volume = (float)v;
    if (v == 0)
        o->mute = true;
    return true;
}

au_out *snd_open(const char *cmd, const snd_opts *o, bool headless, bool overwrite, bool *fatal)
{
    *fatal = false;
    rs_err err = {0};
    if (o->wav) {
        if (!rs_out_check(o->wav, overwrite, &err)) {
            cli_error(cmd, "--audio-out %s", err.msg);
            *fatal = true;
            return NULL;
        }
        au_out *out = au_out_open(&(au_out_opts){.backend = AU_OUT_WAV, .wav_path = o->wav,
                                                 .volume = o->mute ? 1 : o->volume}, &err);
        if (!out) {
            cli_error(cmd, "--audio-out %s", err.msg);
            *fatal = true;
        }
        return out;
    }
    if (o->mute || headless)
        return NULL;
    au_out *out = au_out_open(&(au_out_opts){.backend = AU_OUT_OPENAL, .device = o->device, .volume = o->volume}, &err);
    if (!out)
        cli_warn(cmd, "%s; running silent", err.msg);
    return out;
}

void snd_summary(const char *cmd, const au_out *out, const char *source)
{
    if (!out || !rs_log_on(RS_LOG_INFO))
        return;
    au_out_stats st;
    au_out_stats_get(out, &st);
    fprintf(stderr,
            "ringside %s: audio %s -> %s: %.2f s, latency %.1f ms (max %.1f), %llu underruns, %llu frames dropped\n",
            cmd, source, au_out_backend_name(out), (double)st.frames / AU_RATE, st.latency_ms, st.max_latency_ms,
            (unsigned long long)st.underruns, (unsigned long long)st.dropped);
}

bool snd_close(const char *cmd, au_out *out, bool ok)
{
    if (!out)
        return true;
    rs_err err = {0};
    if (au_out_close(out, ok, &err) || !ok)
        return true;
    cli_error(cmd, "%s", err.msg);
    return false;
}
