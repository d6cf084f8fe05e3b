/* The movie soundtrack reader (player/mv_audio.c) against FFmpeg's own
 * decode (`ffmpeg -ac 2 -ar 48000 -f f32le`), on clips made here by the
 * ffmpeg command line: sample formats, rates and layouts; placement on the
 * timeline (audio that starts after the picture); a late read; broken
 * packets; no drift over a 10-minute loop (36000 ticks). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../player/mv_audio.h"
#include "t.h"

#define TICK AU_TICK_FRAMES

static bool have_ffmpeg(void)
{
    return system("ffmpeg -hide_banner -loglevel error -version >/dev/null 2>&1 && "
                  "ffprobe -hide_banner -loglevel error -version >/dev/null 2>&1") == 0;
}

static void need_ffmpeg(void)
{
    if (!have_ffmpeg())
        T_SKIP_INSTALL("no ffmpeg/ffprobe command line (tools/deps.sh test installs them)");
}

static void sh(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void sh(const char *fmt, ...)
{
    char cmd[2048];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    int r = system(cmd);
    T_ASSERTF(r == 0, "command failed (%d): %s", r, cmd);
}

/* ffmpeg's decode of path's audio: stereo float 48 kHz, *frames frames. */
static float *ffmpeg_decode(const char *dir, const char *path, size_t *frames)
{
    char raw[1024];
    snprintf(raw, sizeof raw, "%s/ref.f32", dir);
    sh("ffmpeg -nostdin -hide_banner -loglevel error -y -i '%s' -vn -ac 2 -ar 48000 -f f32le '%s'", path, raw);
    FILE *f = fopen(raw, "rb");
    T_ASSERT(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    float *pcm = malloc((size_t)n + 8);
    T_ASSERT(pcm && fread(pcm, 1, (size_t)n, f) == (size_t)n);
    fclose(f);
    *frames = (size_t)n / 8;
    return pcm;
}

/* The reader's whole track, tick by tick, waiting (headless): ticks * TICK frames. */
static float *read_ticks(const char *path, int64_t ticks, mv_audio_stats *st)
{
    rs_err err = {0};
    mv_audio *a = mv_audio_open(path, &err);
    T_ASSERTF(a, "%s: %s", path, err.msg);
    float *pcm = malloc((size_t)ticks * TICK * 2 * sizeof *pcm);
    T_ASSERT(pcm);
    for (int64_t t = 0; t < ticks; t++)
        T_ASSERT(mv_audio_read(a, t * TICK, pcm + (size_t)t * TICK * 2, TICK, true));
    if (st)
        mv_audio_stats_get(a, st);
    mv_audio_close(a);
    return pcm;
}

/* Normalized cross-correlation of a and b (n stereo frames) at the lag in
 * -maxlag..maxlag (b shifted by lag) where it is highest. */
static double xcorr(const float *a, const float *b, size_t n, int maxlag, int *best_lag)
{
    double best = -2;
    for (int lag = -maxlag; lag <= maxlag; lag++) {
        double ab = 0, aa = 0, bb = 0;
        for (size_t i = 0; i < 2 * n; i++) {
            long j = (long)i + 2L * lag;
            double x = a[i], y = j >= 0 && j < (long)(2 * n) ? b[j] : 0;
            ab += x * y;
            aa += x * x;
            bb += y * y;
        }
        double c = aa > 0 && bb > 0 ? ab / sqrt(aa * bb) : 0;
        if (c > best) {
            best = c;
            *best_lag = lag;
        }
    }
    return best;
}

/* --- formats: every one decodes, resamples and downmixes as ffmpeg does --- */

static void t_formats_match_ffmpeg(void)
{
    need_ffmpeg();
    static const struct {
        const char *name, *src, *out;
    } cases[] = {
        {"mono-s16-44k.mkv", "sine=f=440:sample_rate=44100:d=1", "-ac 1 -c:a pcm_s16le"},
        {"stereo-u8-32k.mkv", "sine=f=300:sample_rate=32000:d=1", "-ac 2 -c:a pcm_u8"},
        {"51-float-48k.mkv",
         "aevalsrc=sin(2*PI*220*t)|0.5*sin(2*PI*330*t)|0.7*sin(2*PI*440*t)|0.3*sin(2*PI*110*t)|"
         "0.4*sin(2*PI*550*t)|0.6*sin(2*PI*660*t):c=5.1:s=48000:d=1",
         "-c:a pcm_f32le"},
        {"s32-22k.mkv", "sine=f=700:sample_rate=22050:d=1", "-c:a pcm_s32le"},
        {"aac-44k.mp4", "sine=f=500:sample_rate=44100:d=1", "-ac 2 -c:a aac -b:a 128k"},
        {"opus.webm", "sine=f=600:sample_rate=48000:d=1", "-ac 2 -c:a libopus"},
        {"mp3-32k.mkv", "sine=f=250:sample_rate=32000:d=1", "-ac 1 -c:a libmp3lame"},
    };
    const char *dir = t_tmpdir();
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, cases[k].name);
        sh("ffmpeg -nostdin -hide_banner -loglevel error -y -f lavfi -i '%s' %s '%s'", cases[k].src, cases[k].out, path);
        size_t n;
        float *ref = ffmpeg_decode(dir, path, &n);
        T_ASSERTF(n > AU_RATE / 2, "%s: ffmpeg decoded only %zu frames", cases[k].name, n);
        int64_t ticks = (int64_t)(n + TICK - 1) / TICK;
        mv_audio_stats st;
        float *got = read_ticks(path, ticks, &st);
        int lag = 99;
        double c = xcorr(ref, got, n, 48, &lag);
        double maxd = 0;
        for (size_t i = 0; i < 2 * n; i++)
            maxd = fmax(maxd, fabs((double)ref[i] - got[i]));
        fprintf(stderr, "    %-20s corr %.6f lag %d max diff %.2g; %lld frames decoded, ffmpeg %zu; late %lld\n",
                cases[k].name, c, lag, maxd, (long long)st.frames, n, (long long)st.late);
        T_ASSERTF(c >= 0.999 && lag == 0, "%s: correlation %.5f at lag %d", cases[k].name, c, lag);
        T_ASSERTF(llabs(st.frames - (int64_t)n) <= TICK, "%s: %lld frames, ffmpeg %zu", cases[k].name,
                  (long long)st.frames, n);
        T_EQ(st.late, 0);
        T_EQ(st.bad_packets, 0);
        free(ref);
        free(got);
    }
}

/* --- the timeline --- */

/* The first frame at or after from whose |sample| exceeds level; -1 none. */
static int64_t onset(const float *pcm, int64_t from, int64_t n, float level)
{
    for (int64_t i = from; i < n; i++)
        if (fabsf(pcm[2 * i]) > level || fabsf(pcm[2 * i + 1]) > level)
            return i;
    return -1;
}

static void t_audio_after_video_is_delayed(void)
{
    need_ffmpeg();
    const char *dir = t_tmpdir();
    char path[1024];
    snprintf(path, sizeof path, "%s/late.mkv", dir);
    /* the picture from 0 s, the tone from 0.25 s */
    sh("ffmpeg -nostdin -hide_banner -loglevel error -y -f lavfi -i testsrc2=size=64x36:rate=30:d=1 "
       "-f lavfi -itsoffset 0.25 -i sine=f=1000:sample_rate=44100:d=0.75 -c:v mpeg4 -c:a pcm_s16le '%s'", path);
    float *pcm = read_ticks(path, 60, NULL);
    int64_t on = onset(pcm, 0, 60 * TICK, 0.01f);
    fprintf(stderr, "    tone starts at frame %lld (want %d)\n", (long long)on, AU_RATE / 4);
    T_ASSERTF(llabs(on - AU_RATE / 4) <= 48, "the tone starts at frame %lld, want %d +- 48", (long long)on,
              AU_RATE / 4);
    free(pcm);
}

static void t_no_audio_is_silence_not_error(void)
{
    need_ffmpeg();
    const char *dir = t_tmpdir();
    char path[1024];
    snprintf(path, sizeof path, "%s/mute.mkv", dir);
    sh("ffmpeg -nostdin -hide_banner -loglevel error -y -f lavfi -i testsrc2=size=64x36:rate=30:d=0.5 -c:v mpeg4 '%s'",
       path);
    rs_err err = {0};
    T_ASSERT(!mv_audio_open(path, &err));
    T_EQ(err.code, 0);
    /* a file that is no movie at all: an error naming it, no crash */
    snprintf(path, sizeof path, "%s/nothing.mkv", dir);
    t_write(dir, "nothing.mkv", "not a movie");
    T_ASSERT(!mv_audio_open(path, &err));
    T_ASSERT(err.code != 0);
    T_CONTAINS(err.msg, "nothing.mkv");
}

/* A click train: one 0.9 impulse at the start of each second of a 44.1
 * kHz track, `seconds` long, as FLAC in dir; its name in path. */
static void click_track(const char *dir, int seconds, char *path, size_t size)
{
    char one[1024];
    snprintf(one, sizeof one, "%s/click.wav", dir);
    snprintf(path, size, "%s/clicks.mka", dir);
    sh("ffmpeg -nostdin -hide_banner -loglevel error -y -f lavfi -i 'aevalsrc=if(eq(n\\,0)\\,0.9\\,0):s=44100:d=1' "
       "-c:a pcm_s16le '%s'", one);
    sh("ffmpeg -nostdin -hide_banner -loglevel error -y -stream_loop -1 -i '%s' -t %d -c:a flac '%s'", one, seconds,
       path);
}

/* A click train: one impulse each second of a 44.1 kHz track, looped for
 * ten minutes; read as 36000 ticks, each click must sit on its second. */
static void t_no_drift_over_36000_ticks(void)
{
    need_ffmpeg();
    const char *dir = t_tmpdir();
    char path[1024];
    click_track(dir, 600, path, sizeof path);
    const int64_t ticks = 36000;
    mv_audio_stats st;
    clock_t c0 = clock();
    float *pcm = read_ticks(path, ticks, &st);
    double wall = (double)(clock() - c0) / CLOCKS_PER_SEC;
    int64_t worst = 0, last = -1;
    for (int64_t s = 0; s < 600; s++) {
        int64_t want = s * AU_RATE, from = want - TICK / 2 > 0 ? want - TICK / 2 : 0, peak = from;
        for (int64_t i = from; i < want + TICK / 2 && i < ticks * TICK; i++)
            if (fabsf(pcm[2 * i]) > fabsf(pcm[2 * peak]))
                peak = i;
        T_ASSERTF(fabsf(pcm[2 * peak]) > 0.3f, "no click near second %lld", (long long)s);
        worst = llabs(peak - want) > worst ? llabs(peak - want) : worst;
        last = peak - want;
    }
    fprintf(stderr, "    36000 ticks: worst click offset %lld frames, last (599 s) %lld; decode+resample %.4f ms CPU "
                    "per tick (%.1f ms in all, process %.2f s)\n",
            (long long)worst, (long long)last, st.cpu_ms / ticks, st.cpu_ms, wall);
    T_ASSERTF(worst <= 1, "a click is %lld frames off its second (drift)", (long long)worst);
    T_EQ(st.late, 0);
    free(pcm);
}

/* A read the decoder cannot have reached: silence at once, counted late;
 * the decoder then catches up to the reader, and the clicks are in place. */
static void t_late_read_is_silent_and_moves_on(void)
{
    need_ffmpeg();
    const char *dir = t_tmpdir();
    char path[1024];
    click_track(dir, 300, path, sizeof path);
    rs_err err = {0};
    mv_audio *a = mv_audio_open(path, &err);
    T_ASSERTF(a, "%s", err.msg);
    float buf[2 * TICK];
    /* 250 s in: five minutes of FLAC are not decoded in the microseconds since open */
    int64_t pos = 250LL * AU_RATE - TICK / 2;
    T_ASSERT(!mv_audio_read(a, pos, buf, TICK, false));
    for (int i = 0; i < 2 * TICK; i++)
        T_ASSERT(buf[i] == 0);
    /* the next second's click, waiting this time: in its place */
    pos = 251LL * AU_RATE - TICK / 2;
    T_ASSERT(mv_audio_read(a, pos, buf, TICK, true));
    int peak = 0;
    for (int i = 0; i < TICK; i++)
        if (fabsf(buf[2 * i]) > fabsf(buf[2 * peak]))
            peak = i;
    T_ASSERTF(fabsf(buf[2 * peak]) > 0.3f && abs(peak - TICK / 2) <= 1, "click at %d (%.3f), want %d", peak,
              buf[2 * peak], TICK / 2);
    mv_audio_stats st;
    mv_audio_stats_get(a, &st);
    T_EQ(st.late, 1);
    T_EQ(st.reads, 2);
    T_ASSERT(st.discarded > 200LL * AU_RATE); /* what the reader had passed was dropped, not queued */
    mv_audio_close(a);
}

T_MAIN({"formats_match_ffmpeg", t_formats_match_ffmpeg}, {"audio_after_video_is_delayed", t_audio_after_video_is_delayed},
       {"no_audio_is_silence_not_error", t_no_audio_is_silence_not_error},
       {"no_drift_over_36000_ticks", t_no_drift_over_36000_ticks},
       {"late_read_is_silent_and_moves_on", t_late_read_is_silent_and_moves_on})
