/* runtime/audio/au_out: the null, wav and openal backends, their stats,
 * volume, and the errors that name what is wrong.  The openal cases run on
 * OpenAL Soft's null driver (ALSOFT_DRIVERS=null: no sound card needed),
 * in real time, a second each. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "../runtime/audio/au_out.h"
#include "t.h"

/* Tick t of a test signal: a ramp on the left, its negative on the right,
 * different on every frame so a lost or repeated frame shows. */
static void tick_pcm(int t, float *pcm)
{
    for (int i = 0; i < AU_TICK_FRAMES; i++) {
        float v = (float)((t * AU_TICK_FRAMES + i) % 1000) / 1000.0f - 0.5f;
        pcm[2 * i] = v;
        pcm[2 * i + 1] = -v;
    }
}

static void t_null_counts(void)
{
    rs_err err = {0};
    au_out *o = au_out_open(&(au_out_opts){.backend = AU_OUT_NULL}, &err);
    T_ASSERTF(o, "%s", err.msg);
    T_CONTAINS(au_out_backend_name(o), "null");
    float pcm[AU_TICK_FRAMES * 2];
    for (int t = 0; t < 10; t++) {
        tick_pcm(t, pcm);
        T_ASSERT(au_out_write(o, pcm, AU_TICK_FRAMES, &err));
    }
    au_out_stats st;
    au_out_stats_get(o, &st);
    T_EQ(st.frames, 10 * AU_TICK_FRAMES);
    T_EQ(st.played, 10 * AU_TICK_FRAMES);
    T_EQ(st.underruns, 0);
    T_EQ(st.dropped, 0);
    T_ASSERT(st.write_ms >= 0);
    T_ASSERT(au_out_close(o, true, &err));
}

/* Writes `ticks` ticks through a wav output and reads the file back. */
static float *wav_round_trip(const char *path, float volume, bool flt, int ticks, size_t *frames)
{
    rs_err err = {0};
    au_out *o = au_out_open(&(au_out_opts){.wav_path = path, .wav_float = flt, .volume = volume}, &err);
    T_ASSERTF(o, "%s", err.msg);
    T_CONTAINS(au_out_backend_name(o), "wav");
    T_CONTAINS(au_out_backend_name(o), path);
    float pcm[AU_TICK_FRAMES * 2];
    for (int t = 0; t < ticks; t++) {
        tick_pcm(t, pcm);
        T_ASSERTF(au_out_write(o, pcm, AU_TICK_FRAMES, &err), "%s", err.msg);
    }
    au_out_stats st;
    au_out_stats_get(o, &st);
    T_EQ(st.frames, (uint64_t)ticks * AU_TICK_FRAMES);
    T_EQ(st.played, st.frames);
    T_ASSERTF(au_out_close(o, true, &err), "%s", err.msg);
    float *got = NULL;
    int ch = 0, rate = 0;
    T_ASSERTF(au_wav_read(path, &got, frames, &ch, &rate, &err), "%s", err.msg);
    T_EQ(ch, 2);
    T_EQ(rate, AU_RATE);
    return got;
}

static void t_wav_frame_for_frame(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/out.wav", t_tmpdir());
    size_t frames = 0;
    float *got = wav_round_trip(path, 0, true, 7, &frames);
    T_EQ(frames, 7 * AU_TICK_FRAMES);
    float pcm[AU_TICK_FRAMES * 2];
    for (int t = 0; t < 7; t++) {
        tick_pcm(t, pcm);
        T_ASSERTF(!memcmp(pcm, got + (size_t)t * AU_TICK_FRAMES * 2, sizeof pcm), "tick %d differs", t);
    }
    free(got);
}

static void t_wav_16bit(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/out16.wav", t_tmpdir());
    size_t frames = 0;
    float *got = wav_round_trip(path, 0, false, 3, &frames);
    T_EQ(frames, 3 * AU_TICK_FRAMES);
    float pcm[AU_TICK_FRAMES * 2];
    tick_pcm(2, pcm);
    for (int i = 0; i < AU_TICK_FRAMES * 2; i++)
        T_ASSERTF(fabsf(got[2 * AU_TICK_FRAMES * 2 + i] - pcm[i]) < 2.0f / 32767, "sample %d", i);
    free(got);
}

static void t_volume_at_output(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/half.wav", t_tmpdir());
    size_t frames = 0;
    float *got = wav_round_trip(path, 0.5f, true, 2, &frames);
    float pcm[AU_TICK_FRAMES * 2];
    tick_pcm(1, pcm);
    for (int i = 0; i < AU_TICK_FRAMES * 2; i++)
        T_ASSERTF(got[AU_TICK_FRAMES * 2 + i] == pcm[i] * 0.5f, "sample %d: %g, want %g", i,
                  (double)got[AU_TICK_FRAMES * 2 + i], (double)(pcm[i] * 0.5f));
    free(got);
}

static void t_bad_settings_named(void)
{
    rs_err err = {0};
    T_ASSERT(!au_out_open(&(au_out_opts){.backend = AU_OUT_NULL, .volume = 1.5f}, &err));
    T_EQ(err.code, AU_ERR_ARG);
    T_CONTAINS(err.msg, "volume 1.5");
    T_ASSERT(!au_out_open(&(au_out_opts){.backend = AU_OUT_NULL, .volume = -0.25f}, &err));
    T_EQ(err.code, AU_ERR_ARG);
    T_ASSERT(!au_out_open(&(au_out_opts){.backend = AU_OUT_NULL, .volume = NAN}, &err));
    T_EQ(err.code, AU_ERR_ARG);
    T_ASSERT(!au_out_open(&(au_out_opts){.backend = AU_OUT_NULL, .latency_ms = 3}, &err));
    T_EQ(err.code, AU_ERR_ARG);
    T_CONTAINS(err.msg, "latency 3 ms");
    T_ASSERT(!au_out_open(&(au_out_opts){.backend = AU_OUT_WAV}, &err));
    T_EQ(err.code, AU_ERR_ARG);
}

static void t_wav_bad_path_named(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/no-such-folder/out.wav", t_tmpdir());
    rs_err err = {0};
    T_ASSERT(!au_out_open(&(au_out_opts){.wav_path = path}, &err));
    T_EQ(err.code, AU_ERR_WAV_OPEN);
    T_CONTAINS(err.msg, path);
}

/* A run that failed leaves no file behind (nor its temporary). */
static void t_wav_not_ok_removed(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/failed.wav", t_tmpdir());
    rs_err err = {0};
    au_out *o = au_out_open(&(au_out_opts){.wav_path = path}, &err);
    T_ASSERTF(o, "%s", err.msg);
    float pcm[AU_TICK_FRAMES * 2];
    tick_pcm(0, pcm);
    T_ASSERT(au_out_write(o, pcm, AU_TICK_FRAMES, &err));
    au_out_close(o, false, &err);
    T_ASSERT(access(path, F_OK) != 0);
}

/* ---- openal, on OpenAL Soft's null driver ---- */

static void need_openal(void)
{
#ifndef RS_HAVE_OPENAL
    T_SKIP_INSTALL("built without OpenAL");
#endif
    /* OpenAL Soft reads its settings on the first device opened, so this
     * process (one case) can pick the driver and the period here */
    setenv("ALSOFT_DRIVERS", "null", 1);
    char conf[512];
    snprintf(conf, sizeof conf, "%s/alsoft.conf", t_tmpdir());
    t_write(t_tmpdir(), "alsoft.conf", "[general]\nperiod_size = 256\nperiods = 2\n");
    setenv("ALSOFT_CONF", conf, 1);
}

static void t_openal_no_device_named(void)
{
    need_openal();
    rs_err err = {0};
    T_ASSERT(!au_out_open(&(au_out_opts){.backend = AU_OUT_OPENAL, .device = "no-such-card"}, &err));
    T_EQ(err.code, AU_ERR_DEVICE);
    T_CONTAINS(err.msg, "no-such-card");
}

/* With 50 ms queued and 256-frame periods a tick may come 11 ms late
 * without a gap (au_out.c).  A machine busy with other work (builds, other
 * tests) can wake us, or OpenAL's mixer thread, tens of ms late: then a
 * gap or a drop is right.  So the real-time cases try three times, judge
 * only runs where every write came within ON_TIME_MS of its time, and
 * fail when none of those was clean. */
#define ON_TIME_MS 4.0

/* Writes `ticks` ticks at 60 Hz, odd ticks `jitter` ms late (pcm: that
 * many ticks, or NULL for the test signal); returns how much later than
 * that the latest write was, in ms. */
static double paced(au_out *o, const float *pcm, int ticks, double jitter)
{
    rs_err err = {0};
    float sig[AU_TICK_FRAMES * 2];
    struct timespec t0, now;
    double late = 0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (int t = 0; t < ticks; t++) {
        double due_ms = t * (1e3 / 60) + (t % 2 ? jitter : 0);
        long ns = t0.tv_nsec + (long)(due_ms * 1e6);
        clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME,
                        &(struct timespec){t0.tv_sec + ns / 1000000000L, ns % 1000000000L}, NULL);
        clock_gettime(CLOCK_MONOTONIC, &now);
        double l = (double)(now.tv_sec - t0.tv_sec) * 1e3 + (now.tv_nsec - t0.tv_nsec) / 1e6 - due_ms;
        late = l > late ? l : late;
        if (!pcm)
            tick_pcm(t, sig);
        T_ASSERTF(au_out_write(o, pcm ? pcm + (size_t)t * AU_TICK_FRAMES * 2 : sig, AU_TICK_FRAMES, &err), "%s",
                  err.msg);
    }
    return late;
}

/* One second of ticks `jitter` ms late every other tick: nothing dropped,
 * no underrun, and (max_ms > 0) no sound later than max_ms at the
 * speaker; the stats of the clean run in *st.  A run whose writer fell
 * behind is tried again (a busy machine); one that kept its times and
 * still had gaps or late sound counts against the output, and failing in
 * every such run fails the test. */
static void realtime(double jitter, double max_ms, au_out_stats *st)
{
    need_openal();
    bool gaps = false, slow = false;
    for (int attempt = 1; attempt <= 3; attempt++) {
        rs_err err = {0};
        au_out *o = au_out_open(&(au_out_opts){.backend = AU_OUT_OPENAL}, &err);
        T_ASSERTF(o, "%s", err.msg);
        T_CONTAINS(au_out_backend_name(o), "openal");
        double late = paced(o, NULL, 60, jitter);
        au_out_stats_get(o, st);
        T_ASSERT(au_out_close(o, true, &err));
        printf("openal null driver, odd ticks %.0f ms late: latency %.1f ms (max %.1f), %llu underruns, %llu dropped, "
               "%.3f ms in writes, writer up to %.1f ms later still\n",
               jitter, st->latency_ms, st->max_latency_ms, (unsigned long long)st->underruns,
               (unsigned long long)st->dropped, st->write_ms, late);
        if (late > ON_TIME_MS)
            continue;
        if (st->underruns || st->dropped) {
            gaps = true;
            continue;
        }
        if (max_ms > 0 && !(st->max_latency_ms > 0 && st->max_latency_ms <= max_ms)) {
            slow = true;
            continue;
        }
        T_EQ(st->frames, 60 * AU_TICK_FRAMES);
        T_ASSERT(st->played > 0 && st->played <= st->frames);
        return;
    }
    T_ASSERTF(!gaps, "underruns or drops in every run, though the writer kept to its times within %.0f ms",
              ON_TIME_MS);
    T_ASSERTF(!slow, "max latency over %.0f ms (last %.1f) in every run the writer kept to its times", max_ms,
              st->max_latency_ms);
    T_SKIP_ENV("the machine is too busy: no run kept 60 Hz within %.0f ms", ON_TIME_MS);
}

/* A steady 60 Hz: a sound reaches the (null) speaker within 50 ms of its
 * tick (the stats count the device's own buffer). */
static void t_openal_realtime(void)
{
    au_out_stats st;
    realtime(0, 50, &st);
}

/* A loop whose frames alternate long and short: every other tick 6 ms
 * late, still no gap. */
static void t_openal_jitter(void)
{
    au_out_stats st;
    realtime(6, 0, &st);
}

/* The game stalls for a quarter second: the queue runs dry, that is an
 * underrun, and playback picks up again with the next ticks. */
static void t_openal_underrun_counted(void)
{
    need_openal();
    rs_err err = {0};
    au_out *o = au_out_open(&(au_out_opts){.backend = AU_OUT_OPENAL}, &err);
    T_ASSERTF(o, "%s", err.msg);
    float pcm[AU_TICK_FRAMES * 2];
    for (int t = 0; t < 40; t++) {
        tick_pcm(t, pcm);
        T_ASSERT(au_out_write(o, pcm, AU_TICK_FRAMES, &err));
        nanosleep(&(struct timespec){0, t == 20 ? 250000000L : 16666667L}, NULL);
    }
    au_out_stats st;
    au_out_stats_get(o, &st);
    /* one for the stall; a machine busy with other work may add more */
    T_ASSERTF(st.underruns >= 1, "%llu underruns", (unsigned long long)st.underruns);
    T_ASSERT(au_out_close(o, true, &err));
}

/* Written faster than it plays (a headless loop on a device): the queue
 * stays within its bound and the excess is dropped, the writes never wait. */
static void t_openal_drops_never_blocks(void)
{
    need_openal();
    rs_err err = {0};
    au_out *o = au_out_open(&(au_out_opts){.backend = AU_OUT_OPENAL}, &err);
    T_ASSERTF(o, "%s", err.msg);
    float pcm[AU_TICK_FRAMES * 2];
    for (int t = 0; t < 600; t++) {
        tick_pcm(t, pcm);
        T_ASSERT(au_out_write(o, pcm, AU_TICK_FRAMES, &err));
    }
    au_out_stats st;
    au_out_stats_get(o, &st);
    T_ASSERT(st.dropped > 500 * AU_TICK_FRAMES);
    T_ASSERTF(st.write_ms < 1000, "600 writes took %.0f ms", st.write_ms);
    T_ASSERTF(st.max_latency_ms <= 60, "max latency %.1f ms", st.max_latency_ms);
    au_out_close(o, false, &err);
}

/* The device path end to end: a replay's soundtrack played in real time
 * through OpenAL Soft's wave driver (it writes what the device would have
 * played to a file) is the soundtrack the wav backend writes (the samples
 * au_replay_track mixes, t_wav_frame_for_frame), shifted by the device's
 * start-up.  1.5 s of real time. */
static void t_openal_wave_driver_plays_the_mix(void)
{
#ifndef RS_HAVE_OPENAL
    T_SKIP_INSTALL("built without OpenAL");
#endif
    char conf[512], dev_wav[512], text[1200];
    snprintf(conf, sizeof conf, "%s/alsoft.conf", t_tmpdir());
    snprintf(dev_wav, sizeof dev_wav, "%s/device.wav", t_tmpdir());
    snprintf(text, sizeof text,
             "[general]\nperiod_size = 256\nperiods = 2\nfrequency = 48000\nchannels = stereo\n"
             "sample-type = float32\n[wave]\nfile = %s\n", dev_wav);
    t_write(t_tmpdir(), "alsoft.conf", text);
    setenv("ALSOFT_DRIVERS", "wave", 1);
    setenv("ALSOFT_CONF", conf, 1);

    rs_err err = {0};
    rp_replay rp = {0};
    T_ASSERTF(rp_read(RS_SOURCE_DIR "/demos/harbor.rsr", &rp, &err), "%s", err.msg);
    au_track tr;
    enum { TICKS = 90 };
    T_ASSERTF(au_replay_track(&rp, "harbor", 0, TICKS, &(au_replay_opts){.target_lufs = NAN}, &tr, &err), "%s",
              err.msg);
    bool gaps = false;
    for (int attempt = 1;; attempt++) {
        au_out *o = au_out_open(&(au_out_opts){.backend = AU_OUT_OPENAL}, &err);
        T_ASSERTF(o, "%s", err.msg);
        double late = paced(o, tr.pcm, TICKS, 0);
        au_out_stats st;
        au_out_stats_get(o, &st);
        T_ASSERT(au_out_close(o, true, &err));
        printf("attempt %d: writer up to %.1f ms late, %llu underruns, %llu frames dropped\n", attempt, late,
               (unsigned long long)st.underruns, (unsigned long long)st.dropped);
        gaps |= late <= ON_TIME_MS && (st.underruns || st.dropped);
        if (late <= ON_TIME_MS && !st.underruns && !st.dropped)
            break;
        T_ASSERTF(attempt < 3 || !gaps, "underruns or drops in every run, though the writer kept 60 Hz within %.0f ms",
                  ON_TIME_MS);
        if (attempt == 3)
            T_SKIP_ENV("the machine is too busy: no run kept 60 Hz within %.0f ms", ON_TIME_MS);
    }

    float *dev = NULL;
    size_t dev_frames = 0;
    int ch = 0, rate = 0;
    T_ASSERTF(au_wav_read(dev_wav, &dev, &dev_frames, &ch, &rate, &err), "%s", err.msg);
    T_EQ(ch, 2);
    T_EQ(rate, AU_RATE);
    /* the lag: where 0.1 s from the middle matches best (normalized, or a
     * louder passage would win), within 0.3 s */
    const size_t win = AU_RATE / 10, at = tr.frames / 2, max_lag = AU_RATE * 3 / 10;
    T_ASSERT(dev_frames > at + win + max_lag);
    size_t lag = 0;
    double best = -2;
    for (size_t l = 0; l <= max_lag; l++) {
        double xy = 0, yy = 0;
        for (size_t i = 2 * at; i < 2 * (at + win); i++) {
            xy += (double)tr.pcm[i] * dev[i + 2 * l];
            yy += (double)dev[i + 2 * l] * dev[i + 2 * l];
        }
        double c = yy > 0 ? xy / sqrt(yy) : -1;
        if (c > best) {
            best = c;
            lag = l;
        }
    }
    /* the correlation over everything both hold at that lag */
    size_t n = dev_frames - lag < tr.frames ? dev_frames - lag : tr.frames;
    double xy = 0, xx = 0, yy = 0, diff = 0;
    for (size_t i = 0; i < 2 * n; i++) {
        double x = tr.pcm[i], y = dev[i + 2 * lag];
        xy += x * y;
        xx += x * x;
        yy += y * y;
        diff = fabs(x - y) > diff ? fabs(x - y) : diff;
    }
    double corr = xy / sqrt(xx * yy);
    printf("openal wave driver: offset %.2f ms, correlation %.7f, largest difference %.2g, over %zu frames\n",
           lag * 1e3 / AU_RATE, corr, diff, n);
    T_ASSERTF(corr >= 0.99, "correlation %.4f at offset %zu frames", corr, lag);
    T_EQ(n, tr.frames); /* the last sound was played out, not cut */
    free(dev);
    au_track_free(&tr);
    rp_free(&rp);
}

T_MAIN({"null_counts", t_null_counts}, {"wav_frame_for_frame", t_wav_frame_for_frame}, {"wav_16bit", t_wav_16bit},
       {"volume_at_output", t_volume_at_output}, {"bad_settings_named", t_bad_settings_named},
       {"wav_bad_path_named", t_wav_bad_path_named}, {"wav_not_ok_removed", t_wav_not_ok_removed},
       {"openal_no_device_named", t_openal_no_device_named}, {"openal_realtime", t_openal_realtime},
       {"openal_jitter", t_openal_jitter},
       {"openal_underrun_counted", t_openal_underrun_counted},
       {"openal_drops_never_blocks", t_openal_drops_never_blocks},
       {"openal_wave_driver_plays_the_mix", t_openal_wave_driver_plays_the_mix})
