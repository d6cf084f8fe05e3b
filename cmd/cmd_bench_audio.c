/* ringside bench audio: what the sound costs on the CPU.  The mixer per
 * tick (AU_TICK_FRAMES frames) on a demo's real cues and on a busy
 * synthetic load (every voice playing, the music and an outside source on),
 * the bank's one-time build, and the time to make a whole replay's
 * soundtrack (simulate, mix, measure, normalize), as a real-time factor.
 *
 * Per-tick figures are medians (and the 99th percentile) over the ticks of
 * one run, each tick timed alone with the monotonic clock; the game's own
 * step is outside the timed part. */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "../runtime/audio/au.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_progress.h"

static void help(void)
{
    printf("usage: ringside bench audio [--replay FILE] [--csv FILE] [-y|-n] [-q|-v]\n\n"
           "Times the sound on the CPU: building the bank, the mixer per tick (800\n"
           "frames) on the replay's own cues and on a busy load with every voice playing,\n"
           "and making the replay's whole soundtrack (simulate, mix, measure, normalize:\n"
           "what render and replay sound do), with its real-time factor.\n\n"
           "  --replay FILE  the replay (default demos/dojo.rsr)\n"
           "  --csv FILE     also write the table as CSV\n"
           "  -y, -n         replace an existing --csv FILE, or refuse it (the default)\n"
           CLI_LOG_HELP);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

typedef struct row {
    const char *what;
    double median_us, p99_us, total_s, rtf; /* rtf: audio seconds per CPU second */
} row;

static row per_tick(const char *what, double *us, size_t n)
{
    qsort(us, n, sizeof *us, cmp_double);
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += us[i];
    return (row){what, us[n / 2], us[n * 99 / 100], sum / 1e6, n / (double)G_HZ / (sum / 1e6)};
}

/* the replay's cues, as au_replay_track mixes them, the mix call timed */
static bool replay_ticks(const rp_replay *rp, double *us, rs_err *err)
{
    au_mixer *m = au_mixer_new(NULL, err);
    if (!m)
        return false;
    g_state st, prev;
    g_init(&st, rp->stage, rp->seed);
    au_mixer_music(m, st.stage); /* the loop is built on first use: not a tick's cost */
    float out[AU_TICK_FRAMES * 2];
    for (uint64_t k = 0; k < rp->ticks; k++) {
        g_events ev;
        prev = st;
        g_step(&st, &rp->inputs[2 * k], &ev);
        au_cue c[AU_MAX_CUES];
        int n = au_game_cues(&prev, &st, &ev, c, AU_MAX_CUES);
        double t0 = rs_now();
        for (int i = 0; i < n; i++)
            au_mixer_cue(m, &c[i]);
        au_mixer_music(m, st.stage);
        au_mixer_mix(m, out, AU_TICK_FRAMES, NULL, 0);
        us[k] = (rs_now() - t0) * 1e6;
    }
    au_mixer_free(m);
    return true;
}

/* every voice busy all the time (a finished one is replaced at once by the
 * longest sounds of the bank), music and an outside source on */
static bool busy_ticks(size_t ticks, double *us, int *voices, rs_err *err)
{
    au_mixer *m = au_mixer_new(NULL, err);
    if (!m)
        return false;
    au_mixer_music(m, 0); /* built by replay_ticks already when the replay is on stage 0 */
    static float ext[AU_TICK_FRAMES * 2], out[AU_TICK_FRAMES * 2];
    for (int i = 0; i < AU_TICK_FRAMES * 2; i++)
        ext[i] = (float)(0.1 * sin(i * 0.01));
    int ids[] = {au_bank_find("thunder"), au_bank_find("crowd_cheer"), au_bank_find("bell")};
    *voices = 0;
    for (size_t k = 0; k < ticks; k++) {
        double t0 = rs_now();
        for (int i = au_mixer_voices(m), j = 0; i < 64; i++, j++)
            au_mixer_cue(m, &(au_cue){ids[j % 3], j % AU_TICK_FRAMES, 0.05f, (j % 9 - 4) / 4.0f});
        au_mixer_mix(m, out, AU_TICK_FRAMES, ext, 0.5f);
        us[k] = (rs_now() - t0) * 1e6;
        *voices = au_mixer_voices(m) > *voices ? au_mixer_voices(m) : *voices;
    }
    au_mixer_free(m);
    return true;
}

int bench_audio(int argc, char **argv)
{
    static const struct option opts[] = {{"replay", required_argument, 0, 'r'}, {"csv", required_argument, 0, 'c'},
                                         {"help", no_argument, 0, 'h'},        {"overwrite", no_argument, 0, 'y'},
                                         {"no-overwrite", no_argument, 0, 'n'}, {0}};
    const char *replay = NULL, *csv = NULL;
    bool overwrite = false;
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "hyn", opts, NULL)) != -1) {
        switch (c) {
        case 'r': replay = optarg; break;
        case 'c': csv = optarg; break;
        case 'y': overwrite = true; break;
        case 'n': overwrite = false; break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("bench", argv);
        }
    }
    if (optind != argc) {
        cli_error("bench", "audio takes no operands ('%s')", argv[optind]);
        return cli_usage_error("bench");
    }
    if (csv && !cli_out_ok("bench", csv, overwrite))
        return RS_EXIT_FAIL;
    rs_err err = {0};
    char demo[4096];
    if (!replay) {
        const char *data = rs_data_dir(&err);
        if (!data) {
            cli_error("bench", "%s", err.msg);
            return RS_EXIT_FAIL;
        }
        snprintf(demo, sizeof demo, "%s/demos/dojo.rsr", data);
        replay = demo;
    }
    rp_replay rp;
    if (!rp_read(replay, &rp, &err)) {
        cli_error("bench", "%s", err.msg);
        return RS_EXIT_FAIL;
    }
    int status = RS_EXIT_FAIL, voices = 0;
    size_t busy_n = 3600;
    double *us = malloc((rp.ticks > busy_n ? rp.ticks : busy_n) * sizeof *us);
    row rows[4];
    au_track t = {0};
    if (!us) {
        cli_error("bench", "out of memory");
        goto done;
    }
    double t0 = rs_now();
    int sounds = au_bank_count();
    double bank_s = rs_now() - t0;
    rows[0] = (row){"bank build (once)", NAN, NAN, bank_s, NAN};
    if (!replay_ticks(&rp, us, &err))
        goto fail;
    rows[1] = per_tick("mix, replay's cues", us, rp.ticks);
    if (!busy_ticks(busy_n, us, &voices, &err))
        goto fail;
    rows[2] = per_tick("mix, busy", us, busy_n);
    t0 = rs_now();
    if (!au_replay_track(&rp, replay, 0, 0, &(au_replay_opts){.before_peak = true}, &t, &err))
        goto fail;
    double track_s = rs_now() - t0;
    rows[3] = (row){"whole track", NAN, NAN, track_s, rp.ticks / (double)G_HZ / track_s};
    printf("bench audio: %s, %llu ticks (%.1f s); %d sounds; busy: %d voices + music + outside source\n", replay,
           (unsigned long long)rp.ticks, rp.ticks / (double)G_HZ, sounds, voices);
    printf("%-20s %10s %10s %10s %12s\n", "step", "median us", "p99 us", "total s", "x real time");
    for (int i = 0; i < 4; i++) {
        char med[32] = "-", p99[32] = "-", rtf[32] = "-";
        if (!isnan(rows[i].median_us)) {
            snprintf(med, sizeof med, "%.2f", rows[i].median_us);
            snprintf(p99, sizeof p99, "%.2f", rows[i].p99_us);
        }
        if (!isnan(rows[i].rtf))
            snprintf(rtf, sizeof rtf, "%.0f", rows[i].rtf);
        printf("%-20s %10s %10s %10.3f %12s\n", rows[i].what, med, p99, rows[i].total_s, rtf);
    }
    printf("track: %.1f LUFS %.1f dBTP -> %.1f LUFS %.1f dBTP\n", t.lufs_before, t.peak_before, t.lufs_after,
           t.peak_after);
    if (csv) {
        FILE *f = cli_text_open("bench", csv, overwrite);
        if (!f)
            goto done;
        fprintf(f, "step,median_us,p99_us,total_s,x_real_time\n");
        for (int i = 0; i < 4; i++)
            fprintf(f, "%s,%.3f,%.3f,%.4f,%.1f\n", rows[i].what, rows[i].median_us, rows[i].p99_us, rows[i].total_s,
                    rows[i].rtf);
        if (!cli_text_close("bench", csv, f))
            goto done;
    }
    status = RS_EXIT_OK;
    goto done;
fail:
    cli_error("bench", "%s", err.msg);
done:
    au_track_free(&t);
    free(us);
    rp_free(&rp);
    return status;
}
