/* runtime/audio: WAV files (round trip, bad files named in the error), the
 * bank (deterministic, levels, lengths), the mixer (pan and gain math,
 * offsets, voice limit, the limiter's ceiling), the game's cues (pan from
 * the picture, state-diff sounds), loudness normalization, and a demo's
 * soundtrack: identical twice, a range equal to that slice of the whole,
 * a hit's onset on its tick, a desync named with its tick. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/audio/au.h"
#include "../runtime/audio/au_local.h"
#include "../runtime/util/rs_file.h"
#include "t.h"

#define DEMO RS_SOURCE_DIR "/demos/temple.rsr"

static void path_in_tmp(char *out, size_t n, const char *name)
{
    snprintf(out, n, "%s/%s", t_tmpdir(), name);
}

static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    T_ASSERT(f && fwrite(data, 1, n, f) == n && fclose(f) == 0);
}

static float peak_of(const float *x, size_t n)
{
    float p = 0;
    for (size_t i = 0; i < n; i++)
        p = fabsf(x[i]) > p ? fabsf(x[i]) : p;
    return p;
}

/* ---- WAV ---- */

static void t_wav_round_trip(void)
{
    enum { N = 1000 };
    float pcm[2 * N];
    for (int i = 0; i < N; i++) {
        pcm[2 * i] = (float)sin(i * 0.05) * 0.9f;
        pcm[2 * i + 1] = i == 7 ? 1.7f : i == 8 ? -1.7f : (float)cos(i * 0.031) * 0.5f; /* two clipped */
    }
    char p16[512], pf[512], ps[512];
    path_in_tmp(p16, sizeof p16, "a16.wav");
    path_in_tmp(pf, sizeof pf, "af.wav");
    path_in_tmp(ps, sizeof ps, "as.wav");
    rs_err err = {0};
    T_ASSERTF(au_wav_write(p16, pcm, N, false, &err), "%s", err.msg);
    T_ASSERTF(au_wav_write(pf, pcm, N, true, &err), "%s", err.msg);
    float *back;
    size_t frames;
    int ch, rate;
    T_ASSERTF(au_wav_read(pf, &back, &frames, &ch, &rate, &err), "%s", err.msg);
    T_EQ(frames, N);
    T_EQ(ch, 2);
    T_EQ(rate, AU_RATE);
    T_ASSERT(memcmp(back, pcm, sizeof pcm) == 0); /* float: bit for bit */
    free(back);
    T_ASSERTF(au_wav_read(p16, &back, &frames, &ch, &rate, &err), "%s", err.msg);
    T_EQ(frames, N);
    for (int i = 0; i < 2 * N; i++) {
        float want = pcm[i] > 1 ? 1 : pcm[i] < -1 ? -1 : pcm[i];
        T_ASSERTF(fabsf(back[i] - want) <= 0.5f / 32768 || (want == 1 && back[i] == 32767.0f / 32768),
                  "sample %d: %f, want %f", i, back[i], want);
    }
    free(back);
    /* the streaming writer, in uneven pieces, writes the same bytes */
    au_wav *w = au_wav_open(ps, false, &err);
    T_ASSERTF(w, "%s", err.msg);
    T_ASSERT(au_wav_append(w, pcm, 1, &err) && au_wav_append(w, pcm + 2, 600, &err) &&
             au_wav_append(w, pcm + 1202, N - 601, &err));
    T_ASSERTF(au_wav_close(w, true, &err), "%s", err.msg);
    size_t la, lb;
    char *a = rs_read_file(p16, 1 << 20, &la, &err), *b = rs_read_file(ps, 1 << 20, &lb, &err);
    T_ASSERT(a && b && la == lb && la == 44 + 4 * N && memcmp(a, b, la) == 0);
    free(a);
    free(b);
    /* an abandoned stream leaves nothing behind */
    char pn[512], part[600];
    path_in_tmp(pn, sizeof pn, "never.wav");
    w = au_wav_open(pn, true, &err);
    T_ASSERT(w && au_wav_append(w, pcm, N, &err));
    T_ASSERT(!au_wav_close(w, false, &err));
    snprintf(part, sizeof part, "%s.part", pn);
    T_ASSERT(fopen(pn, "rb") == NULL && fopen(part, "rb") == NULL);
}

/* A 24-bit mono 44.1 kHz file and an 8-bit stereo one, written by hand. */
static void t_wav_reads_other_formats(void)
{
    uint8_t h24[44 + 9] = "RIFF\0\0\0\0WAVEfmt \x10\0\0\0\x01\0\x01\0\x44\xac\0\0\0\0\0\0\x03\0\x18\0data\x09\0\0\0";
    const uint8_t s24[9] = {0x00, 0x00, 0x40, 0xff, 0xff, 0xff, 0x00, 0x00, 0x80}; /* 0.5, -1/2^23, -1 */
    memcpy(h24 + 44, s24, 9);
    uint8_t h8[44 + 4] = "RIFF\0\0\0\0WAVEfmt \x10\0\0\0\x01\0\x02\0\x00\x7d\0\0\0\0\0\0\x02\0\x08\0data\x04\0\0\0";
    const uint8_t s8[4] = {128, 255, 0, 192};
    memcpy(h8 + 44, s8, 4);
    char a[512], b[512];
    path_in_tmp(a, sizeof a, "s24.wav");
    path_in_tmp(b, sizeof b, "s8.wav");
    write_bytes(a, h24, sizeof h24);
    write_bytes(b, h8, sizeof h8);
    rs_err err = {0};
    float *x;
    size_t n;
    int ch, rate;
    T_ASSERTF(au_wav_read(a, &x, &n, &ch, &rate, &err), "%s", err.msg);
    T_EQ(n, 3);
    T_EQ(ch, 1);
    T_EQ(rate, 44100);
    T_ASSERT(x[0] == 0.5f && x[1] == -1.0f / 8388608 && x[2] == -1.0f);
    free(x);
    T_ASSERTF(au_wav_read(b, &x, &n, &ch, &rate, &err), "%s", err.msg);
    T_EQ(n, 2);
    T_EQ(ch, 2);
    T_EQ(rate, 32000);
    T_ASSERT(x[0] == 0 && x[1] == 127.0f / 128 && x[2] == -1 && x[3] == 0.5f);
    free(x);
    /* WAVE_FORMAT_EXTENSIBLE: 5.1 float at 44.1 kHz, one frame, after an odd-sized chunk */
    uint8_t ext[12 + 8 + 40 + 10 + 8 + 24] = "RIFF\0\0\0\0WAVEfmt \x28\0\0\0\xfe\xff\x06\0\x44\xac\0\0";
    size_t at = 12 + 8;
    ext[at + 14] = 32;                              /* bits */
    ext[at + 16] = 22;                              /* cbSize */
    ext[at + 24] = 3;                               /* sub-format: IEEE float */
    memcpy(ext + at + 40, "odd \x01\0\0\0\x7f\0", 10); /* 1 byte + its pad byte */
    memcpy(ext + at + 50, "data\x18\0\0\0", 8);
    for (int c = 0; c < 6; c++) {
        float v = (float)(c + 1) / 8;
        memcpy(ext + at + 58 + 4 * c, &v, 4);
    }
    path_in_tmp(a, sizeof a, "ext.wav");
    write_bytes(a, ext, sizeof ext);
    T_ASSERTF(au_wav_read(a, &x, &n, &ch, &rate, &err), "%s", err.msg);
    T_ASSERT(n == 1 && ch == 6 && rate == 44100 && x[0] == 0.125f && x[5] == 0.75f);
    free(x);
}

static void expect_bad(const char *name, const void *data, size_t n, const char *words)
{
    char p[512];
    path_in_tmp(p, sizeof p, name);
    write_bytes(p, data, n);
    rs_err err = {0};
    float *x = (float *)1;
    size_t frames;
    int ch, rate;
    T_ASSERTF(!au_wav_read(p, &x, &frames, &ch, &rate, &err), "%s was read", name);
    T_ASSERT(x == NULL);
    T_EQ(err.code, AU_ERR_WAV_FORMAT);
    T_CONTAINS(err.msg, p);
    T_CONTAINS(err.msg, words);
}

static void t_wav_bad_files(void)
{
    uint8_t good[44 + 8] = "RIFF\0\0\0\0WAVEfmt \x10\0\0\0\x01\0\x02\0\x80\xbb\0\0\0\0\0\0\x04\0\x10\0data\x08\0\0\0";
    uint8_t f[sizeof good];
    memcpy(f, good, sizeof f);
    expect_bad("truncated.wav", f, sizeof f - 3, "truncated");
    expect_bad("short.wav", f, 8, "truncated");
    memcpy(f, "RIFX", 4);
    expect_bad("magic.wav", f, sizeof f, "not a RIFF WAVE");
    memcpy(f, good, sizeof f);
    f[22] = 0;
    expect_bad("zero.wav", f, sizeof f, "0 channels");
    memcpy(f, good, sizeof f);
    f[34] = 12;
    expect_bad("bits.wav", f, sizeof f, "12-bit");
    memcpy(f, good, sizeof f);
    memcpy(f + 36, "junk", 4);
    expect_bad("nodata.wav", f, sizeof f, "no data chunk");
    rs_err err = {0};
    float *x;
    size_t n;
    int ch, rate;
    T_ASSERT(!au_wav_read("/nonexistent/x.wav", &x, &n, &ch, &rate, &err));
    T_EQ(err.code, AU_ERR_WAV_OPEN);
    T_CONTAINS(err.msg, "/nonexistent/x.wav");
    T_ASSERT(strcmp(au_error_text(AU_ERR_WAV_FORMAT), "?") != 0);
}

/* ---- the bank ---- */

static void t_bank_deterministic(void)
{
    int n = au_bank_count();
    T_ASSERT(n >= 16 + 12);
    int synths = 0;
    for (int id = 0; id < n; id++) {
        const au_sound *s = au_bank_get(id);
        T_ASSERTF(s && s->frames > 0 && s->samples, "sound %d is empty", id);
        T_EQ(au_bank_find(s->name), id);
        float pk = peak_of(s->samples, s->frames);
        T_ASSERTF(pk > 0.05f && pk < 0.75f, "%s: peak %f (expected -26..-2.5 dBFS)", s->name, pk);
        size_t frames;
        float *again = au_bank_synth(id, &frames);
        if (again) { /* a synthesized one: a second build gives the same samples */
            synths++;
            T_EQ(frames, s->frames);
            T_ASSERTF(memcmp(again, s->samples, frames * sizeof *again) == 0, "%s differs between builds", s->name);
            free(again);
        } else {
            float *v = au_voice_build(id - synths, &frames);
            T_ASSERTF(v && frames == s->frames && memcmp(v, s->samples, frames * sizeof *v) == 0,
                      "%s differs between builds", s->name);
            free(v);
        }
    }
    /* lengths: seconds * AU_RATE for synths; the voice resampled 320/147 after trimming */
    T_EQ(au_bank_get(au_bank_find("hit_heavy"))->frames, 26400);
    T_EQ(au_bank_get(au_bank_find("thunder"))->frames, 168000);
    size_t fight = au_bank_get(au_bank_find("voice_fight"))->frames;
    T_ASSERTF(fight > AU_RATE / 4 && fight < AU_RATE, "voice_fight: %zu frames", fight);
    T_EQ(au_bank_find("no_such_sound"), -1);
    T_ASSERT(au_bank_get(n) == NULL && au_bank_get(-1) == NULL);
}

/* ---- the mixer ---- */

static void t_mixer_pan_gain_offset(void)
{
    rs_err err = {0};
    au_mix_opts o = {.music = -1, .no_limiter = true};
    au_mixer *m = au_mixer_new(&o, &err);
    T_ASSERT(m);
    au_mixer_music(m, 0); /* music off by option: stays silent */
    int id = au_bank_find("guard");
    const au_sound *s = au_bank_get(id);
    enum { F = 800 };
    float out[2 * F];
    const struct {
        float pan, gl, gr;
    } cases[] = {{-1, 1, 0},    {0, 0.70710678f, 0.70710678f}, {1, 0, 1}, {0.5f, 0.38268343f, 0.92387953f},
                 {2, 0, 1},     {-2, 1, 0}}; /* past an edge: the edge, not gains off equal power */
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        au_mixer_reset(m);
        au_mixer_cue(m, &(au_cue){id, 100, 0.5f, cases[c].pan});
        T_EQ(au_mixer_voices(m), 1);
        au_mixer_mix(m, out, F, NULL, 0);
        for (int i = 0; i < 100; i++)
            T_ASSERT(out[2 * i] == 0 && out[2 * i + 1] == 0);
        for (int i = 100; i < F; i++) {
            float x = s->samples[i - 100] * 0.5f;
            T_ASSERTF(fabsf(out[2 * i] - x * cases[c].gl) < 1e-6f && fabsf(out[2 * i + 1] - x * cases[c].gr) < 1e-6f,
                      "pan %.2f frame %d: %f %f, want %f %f", cases[c].pan, i, out[2 * i], out[2 * i + 1],
                      x * cases[c].gl, x * cases[c].gr);
        }
    }
    /* an offset past the block starts in a later block, on its frame */
    au_mixer_reset(m);
    au_mixer_cue(m, &(au_cue){id, 1000, 1, -1});
    au_mixer_mix(m, out, F, NULL, 0);
    T_ASSERT(peak_of(out, 2 * F) == 0);
    au_mixer_mix(m, out, F, NULL, 0);
    T_ASSERT(out[2 * 199] == 0 && out[2 * 200] == s->samples[0] && out[2 * 201] == s->samples[1]);
    T_EQ(au_mixer_pos(m), 2 * F);
    /* the sound ends, the voice frees */
    for (int k = 0; k < 20; k++)
        au_mixer_mix(m, out, F, NULL, 0);
    T_EQ(au_mixer_voices(m), 0);
    /* ext: added at its gain */
    float ext[2 * F];
    for (int i = 0; i < 2 * F; i++)
        ext[i] = 0.25f;
    au_mixer_mix(m, out, F, ext, 0.5f);
    T_ASSERT(out[0] == 0.125f && out[2 * F - 1] == 0.125f);
    au_mixer_free(m);
}

static void t_mixer_voice_limit_and_limiter(void)
{
    rs_err err = {0};
    au_mixer *m = au_mixer_new(&(au_mix_opts){.music = -1}, &err), *raw = au_mixer_new(&(au_mix_opts){.music = -1, .no_limiter = true}, &err);
    T_ASSERT(m && raw);
    int id = au_bank_find("hit_heavy");
    for (int i = 0; i < 100; i++) {
        au_mixer_cue(m, &(au_cue){id, i % 7, 4, 0});
        au_mixer_cue(raw, &(au_cue){id, i % 7, 4, 0});
    }
    T_EQ(au_mixer_voices(m), 48);
    enum { F = 4800 };
    static float a[2 * F], b[2 * F];
    au_mixer_mix(m, a, F, NULL, 0);
    au_mixer_mix(raw, b, F, NULL, 0);
    T_ASSERTF(peak_of(b, 2 * F) > 4, "raw sum peak %f", peak_of(b, 2 * F));
    /* held at the ceiling (-1 dBFS, 0.8912509), not under it by any margin:
     * 0.8912509 measured; a ceiling at -2 dBFS reads 0.794 */
    T_ASSERTF(peak_of(a, 2 * F) <= 0.8912510f && peak_of(a, 2 * F) >= 0.88f, "limited peak %f: want the ceiling, 0.8912509",
              peak_of(a, 2 * F));
    /* and it lets go: a quiet sound after the pile-up comes back to its level */
    for (int k = 0; k < 20; k++)
        au_mixer_mix(m, a, F, NULL, 0);
    au_mixer_cue(m, &(au_cue){au_bank_find("step"), 0, 1, 0});
    au_mixer_mix(m, a, F, NULL, 0);
    const au_sound *st = au_bank_get(au_bank_find("step"));
    float want = peak_of(st->samples, st->frames) * 0.70710678f;
    T_ASSERTF(fabsf(peak_of(a, 2 * F) - want) < 1e-3f, "after release: %f, want %f", peak_of(a, 2 * F), want);
    au_mixer_free(m);
    au_mixer_free(raw);
}

static void t_mixer_music_phase(void)
{
    /* music at frame N is the same whether the mixer got there in big or small blocks */
    rs_err err = {0};
    au_mixer *a = au_mixer_new(NULL, &err), *b = au_mixer_new(NULL, &err);
    au_mixer_music(a, 2);
    au_mixer_music(b, 2);
    static float x[2 * 4800], y[2 * 4800];
    au_mixer_mix(a, x, 4800, NULL, 0);
    for (int i = 0; i < 6; i++)
        au_mixer_mix(b, y + 2 * 800 * i, 800, NULL, 0);
    T_ASSERT(memcmp(x, y, sizeof x) == 0);
    T_ASSERT(peak_of(x, 2 * 4800) > 0.01f);
    au_mixer_free(a);
    au_mixer_free(b);
}

/* ---- the game's cues ---- */

static int cue_named(const au_cue *c, int n, const char *name)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(au_bank_get(c[i].sound)->name, name))
            return i;
    return -1;
}

static void t_cues_pan_and_diffs(void)
{
    g_state prev, cur;
    g_init(&prev, 0, 1);
    prev.f[0].x = FX(-1.5);
    prev.f[1].x = FX(1.5);
    cur = prev;
    cur.tick = prev.tick + 1;
    g_events ev = {2, {{G_EV_HIT, 1, 20}, {G_EV_BLOCK, 2, 0}}};
    au_cue c[AU_MAX_CUES];
    int n = au_game_cues(&prev, &cur, &ev, c, AU_MAX_CUES);
    int h = cue_named(c, n, "hit_heavy"), g = cue_named(c, n, "guard");
    T_ASSERT(h >= 0 && g >= 0 && cue_named(c, n, "crowd_gasp") >= 0);
    T_ASSERTF(c[h].pan < -0.2f && c[g].pan > 0.2f, "pans %f %f", c[h].pan, c[g].pan);
    T_ASSERT(c[h].pan == -c[g].pan);
    /* light hits are lighter */
    ev = (g_events){1, {{G_EV_HIT, 2, 8}}};
    n = au_game_cues(&prev, &cur, &ev, c, AU_MAX_CUES);
    T_ASSERT(n == 1 && cue_named(c, n, "hit_light") == 0 && c[0].gain < 1);
    /* state diffs: a landing, a step, a whiff, a crater */
    ev.n = 0;
    prev.f[0].y = FX(0.1);
    cur.f[1].move = G_MV_WALK_F;
    cur.f[1].frame = 17;
    prev.f[0].move = G_MV_KICK;
    cur.f[0].move = G_MV_IDLE;
    cur.hole_seq = prev.hole_seq + 1;
    cur.nholes = 1;
    cur.holes[0] = (g_hole){FX(1.0), 0, FX(0.5), 1};
    n = au_game_cues(&prev, &cur, &ev, c, AU_MAX_CUES);
    T_ASSERT(cue_named(c, n, "land") >= 0 && cue_named(c, n, "step") >= 0 && cue_named(c, n, "whiff") >= 0);
    T_ASSERT(cue_named(c, n, "crater") >= 0 && c[cue_named(c, n, "crater")].pan > 0);
    /* the kick that connected is no whiff; nothing is heard between unrelated states */
    prev.f[0].hit_done = 1;
    n = au_game_cues(&prev, &cur, &ev, c, AU_MAX_CUES);
    T_ASSERT(cue_named(c, n, "whiff") < 0);
    cur.tick += 5;
    T_EQ(au_game_cues(&prev, &cur, &ev, c, AU_MAX_CUES), 0);
    T_EQ(au_game_cues(&prev, &cur, &ev, c, 0), 0);
}

/* ---- loudness ---- */

static void t_loudness_normalize_holds_peak(void)
{
    /* 10 s of a quiet tone with loud clicks: the gain to -16 LUFS would put
     * the clicks far over the ceiling; the limiter must hold them */
    size_t n = 10 * AU_RATE;
    float *x = malloc(n * 2 * sizeof *x);
    for (size_t i = 0; i < n; i++) {
        double v = 0.02 * sin(2 * 3.14159265 * 440 * i / AU_RATE) + (i % 12000 < 20 ? 0.9 : 0);
        x[2 * i] = x[2 * i + 1] = (float)v;
    }
    rs_err err = {0};
    au_loudness b, a, m;
    T_ASSERTF(au_loud_normalize(x, n, -16, -1, &b, &a, &err), "%s", err.msg);
    T_ASSERT(au_loud_measure(x, n, &m, &err));
    /* held at the ceiling, not under it by any margin: -1.13 dBTP measured */
    T_ASSERTF(m.true_peak <= -1.0 + 0.1 && m.true_peak >= -1.25, "true peak %.2f dBTP", m.true_peak);
    T_ASSERTF(fabs(m.integrated - -16) < 0.2, "integrated %.2f LUFS (before %.2f)", m.integrated, b.integrated);
    T_ASSERT(m.integrated == a.integrated && b.integrated < -25);
    /* silence stays silence */
    memset(x, 0, n * 2 * sizeof *x);
    T_ASSERT(au_loud_normalize(x, n, -16, -1, &b, &a, &err));
    T_ASSERT(peak_of(x, 2 * n) == 0 && isinf(a.integrated));
    T_ASSERT(!au_loud_normalize(x, n, 5, -1, NULL, NULL, &err) && err.code == AU_ERR_ARG);
    free(x);
    /* clicks of 3 samples of alternating sign (+ - +) every 0.2 s over a
     * quiet tone: their true peak between the samples overshoots the
     * limiter's first pass (-0.35 dBTP, measured with the check removed),
     * so the result is measured again and limited again until it holds */
    n = 4 * AU_RATE;
    x = malloc(n * 2 * sizeof *x);
    T_ASSERT(x);
    for (size_t i = 0; i < n; i++) {
        double v = 0.02 * sin(2 * 3.14159265 * 440 * i / AU_RATE);
        if (i % 9600 < 3)
            v = i % 9600 == 1 ? -0.9 : 0.9;
        x[2 * i] = x[2 * i + 1] = (float)v;
    }
    T_ASSERTF(au_loud_normalize(x, n, -16, -1, &b, &a, &err), "%s", err.msg);
    T_ASSERT(au_loud_measure(x, n, &m, &err));
    T_ASSERTF(m.true_peak <= -1.0, "alternating clicks: true peak %.2f dBTP over the -1 ceiling", m.true_peak);
    free(x);
}

/* A loudness known without a meter: BS.1770 gives a stereo 1 kHz sine the
 * loudness of its peak level (its -0.691 takes back the K-weighting's gain
 * at 1 kHz), so EBU Tech 3341's first case, a stereo 1 kHz sine at -23
 * dBFS, reads -23.0 +- 0.1 LUFS.  Normalized to -16 LUFS, with no peak near
 * the ceiling, the sine must come out at -16 dBFS: its sample peak, read
 * here (sample 12 of every 48 is the crest), within 0.1 dB.  A target or a
 * gain 0.5 dB off fails, whatever the meter says. */
static void t_loudness_of_a_sine(void)
{
    size_t n = 5 * AU_RATE;
    float *x = malloc(n * 2 * sizeof *x);
    const double a = pow(10, -23 / 20.0), pi = acos(-1);
    for (size_t i = 0; i < n; i++)
        x[2 * i] = x[2 * i + 1] = (float)(a * sin(2 * pi * 1000 * (double)i / AU_RATE));
    rs_err err = {0};
    au_loudness m, b, after;
    T_ASSERTF(au_loud_measure(x, n, &m, &err), "%s", err.msg);
    T_ASSERTF(fabs(m.integrated - -23) <= 0.1, "a stereo 1 kHz sine at -23 dBFS: %.3f LUFS (EBU Tech 3341: -23.0 +- 0.1)",
              m.integrated);
    T_ASSERTF(fabs(m.true_peak - -23) <= 0.1, "a stereo 1 kHz sine at -23 dBFS: true peak %.3f dBTP", m.true_peak);
    T_ASSERTF(au_loud_normalize(x, n, -16, -1, &b, &after, &err), "%s", err.msg);
    double pk = 20 * log10(peak_of(x, 2 * n));
    fprintf(stderr, "    sine: %.3f LUFS; normalized to -16: peak %.3f dBFS, %.3f LUFS\n", m.integrated, pk,
            after.integrated);
    T_ASSERTF(fabs(pk - -16) <= 0.1, "normalized to -16 LUFS, the sine peaks at %.3f dBFS, not -16", pk);
    free(x);
}

/* The limiter streams: the normalized track read through au_norm_stream in
 * pieces of 1, 97, 800 and 48001 frames is, byte for byte, what
 * au_loud_normalize leaves in one buffer, on a signal the limiter works on
 * all along and hardest in its last 60 frames (where its windows run past
 * the end).  A ring or a delay off by one frame anywhere shows here. */
typedef struct piece_src {
    const float *x;
    size_t at;
} piece_src;
static bool piece_read(void *u, float *dst, size_t frames, rs_err *err)
{
    (void)err;
    piece_src *p = u;
    memcpy(dst, p->x + 2 * p->at, frames * 2 * sizeof *dst);
    p->at += frames;
    return true;
}
static bool piece_rewind(void *u, rs_err *err)
{
    (void)err;
    ((piece_src *)u)->at = 0;
    return true;
}

static void t_loudness_stream_any_pieces(void)
{
    size_t n = 3 * AU_RATE + 37;
    float *x = malloc(n * 2 * sizeof *x), *whole = malloc(n * 2 * sizeof *x), *got = malloc(n * 2 * sizeof *x);
    for (size_t i = 0; i < n; i++) {
        double v = 0.03 * sin(2 * 3.14159265 * 440 * i / AU_RATE) + (i % 7000 < 30 ? 0.8 : 0) + (i > n - 60 ? 0.9 : 0);
        x[2 * i] = (float)v, x[2 * i + 1] = (float)(-0.7 * v);
    }
    memcpy(whole, x, n * 2 * sizeof *x);
    rs_err err = {0};
    au_loudness b, a;
    T_ASSERTF(au_loud_normalize(whole, n, -16, -1, &b, &a, &err), "%s", err.msg);
    /* pinned: the bytes the limiter gave when it worked on a whole buffer
     * (its implementation up to 437b877), FNV-1a 64 */
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n * 2 * sizeof(float); i++)
        h = (h ^ ((const uint8_t *)whole)[i]) * 1099511628211ull;
    T_ASSERTF(h == 0x800496ab15829649ull, "the normalized bytes hash to %016llx, not 800496ab15829649 as before",
              (unsigned long long)h);
    piece_src ps = {x, 0};
    au_source src = {piece_read, piece_rewind, &ps, n};
    au_norm plan;
    T_ASSERTF(au_norm_plan(&src, -16, -1, &plan, &err), "%s", err.msg);
    T_ASSERT(plan.on && plan.after.integrated == a.integrated && plan.after.true_peak == a.true_peak);
    T_ASSERTF(plan.gain > 1.5f, "gain %.3f: the limiter must have work to do", plan.gain);
    /* without the track's own true peak (what a render asks): the same plan */
    au_norm quick;
    T_ASSERTF(au_norm_plan_peak(&src, -16, -1, false, &quick, &err), "%s", err.msg);
    T_ASSERTF(quick.gain == plan.gain && quick.ceiling == plan.ceiling && quick.after.true_peak == plan.after.true_peak &&
                  quick.before.integrated == plan.before.integrated,
              "a plan without the first peak differs: gain %.6f / %.6f, ceiling %.6f / %.6f", quick.gain, plan.gain,
              quick.ceiling, plan.ceiling);
    T_ASSERTF(isnan(quick.before.true_peak) && isfinite(plan.before.true_peak), "before's true peak %.2f / %.2f",
              quick.before.true_peak, plan.before.true_peak);
    au_norm_stream *st = au_norm_stream_new(&src, &plan, &err);
    T_ASSERT(st != NULL);
    static const size_t pieces[] = {1, 97, 800, 48001};
    for (size_t k = 0; k < sizeof pieces / sizeof pieces[0]; k++) {
        T_ASSERT(au_norm_stream_rewind(st, &err));
        for (size_t at = 0; at < n;) {
            size_t m = n - at < pieces[k] ? n - at : pieces[k];
            T_ASSERTF(au_norm_stream_read(st, got + 2 * at, m, &err), "%s", err.msg);
            at += m;
        }
        size_t d = 0, first = n;
        for (size_t i = 0; i < 2 * n; i++)
            if (memcmp(&got[i], &whole[i], sizeof(float))) {
                d++;
                first = i / 2 < first ? i / 2 : first;
            }
        T_ASSERTF(d == 0, "pieces of %zu: %zu samples differ from the buffer's, the first at frame %zu of %zu", pieces[k], d,
                  first, n);
    }
    /* limited: the result is under the ceiling and not the input scaled */
    T_ASSERTF(a.true_peak <= -1.0, "%.2f dBTP", a.true_peak);
    T_ASSERT(!au_norm_stream_read(st, got, 1, &err) && err.code == AU_ERR_ARG); /* past the end */
    au_norm_stream_free(st);
    free(x), free(whole), free(got);
}

/* ---- a replay's soundtrack ---- */

static void load(rp_replay *rp)
{
    rs_err err = {0};
    T_ASSERTF(rp_read(DEMO, rp, &err), "%s", err.msg);
}

/* The stream gives the same samples as the buffer, in any pieces, again
 * after a rewind, for a range and the whole match */
static void t_track_streamed_equals_buffer(void)
{
    rp_replay rp;
    load(&rp);
    rs_err err = {0};
    au_track t;
    T_ASSERTF(au_replay_track(&rp, DEMO, 500, 900, NULL, &t, &err), "%s", err.msg);
    au_replay_stream *s = au_replay_open(&rp, DEMO, 500, 900, NULL, &err);
    T_ASSERTF(s != NULL, "%s", err.msg);
    T_EQ(au_replay_info(s)->frames, t.frames);
    T_ASSERT(au_replay_info(s)->lufs_after == t.lufs_after && au_replay_info(s)->gain_db == t.gain_db);
    float *got = malloc(t.frames * 2 * sizeof *got);
    static const size_t pieces[] = {1024, 799, 100000};
    for (size_t k = 0; k < 3; k++) {
        T_ASSERT(k == 0 || au_replay_rewind(s, &err));
        for (size_t at = 0; at < t.frames;) {
            size_t m = t.frames - at < pieces[k] ? t.frames - at : pieces[k];
            T_ASSERTF(au_replay_read(s, got + 2 * at, m, &err), "%s", err.msg);
            at += m;
        }
        T_ASSERTF(!memcmp(got, t.pcm, t.frames * 2 * sizeof *got), "pieces of %zu differ", pieces[k]);
    }
    T_ASSERT(!au_replay_read(s, got, 1, &err) && err.code == AU_ERR_ARG);
    au_replay_close(s);
    T_ASSERT(!au_replay_open(&rp, DEMO, 10, 10, NULL, &err) && err.code == AU_ERR_ARG);
    free(got);
    au_track_free(&t);
    rp_free(&rp);
}

static void t_track_identical_and_sliced(void)
{
    rp_replay rp;
    load(&rp);
    rs_err err = {0};
    au_track a, b, s;
    T_ASSERTF(au_replay_track(&rp, DEMO, 0, 0, NULL, &a, &err), "%s", err.msg);
    T_ASSERTF(au_replay_track(&rp, DEMO, 0, 0, NULL, &b, &err), "%s", err.msg);
    T_EQ(a.frames, rp.ticks * AU_TICK_FRAMES);
    T_ASSERT(a.frames == b.frames && memcmp(a.pcm, b.pcm, a.frames * 2 * sizeof(float)) == 0);
    T_ASSERTF(au_replay_track(&rp, DEMO, 600, 660, NULL, &s, &err), "%s", err.msg);
    T_EQ(s.frames, 60 * AU_TICK_FRAMES);
    T_ASSERT(memcmp(s.pcm, a.pcm + 600 * AU_TICK_FRAMES * 2, s.frames * 2 * sizeof(float)) == 0);
    T_ASSERT(s.gain_db == a.gain_db && s.lufs_after == a.lufs_after);
    /* the whole match, measured again from outside: on target, under the ceiling */
    au_loudness l;
    T_ASSERT(au_loud_measure(a.pcm, a.frames, &l, &err));
    /* from both sides, at a tolerance a 0.5 dB change in the target or the
     * ceiling breaks: temple's gain to -16 LUFS takes its peaks over -1 dBTP,
     * so the limiter holds them at the default ceiling (-1.20 dBTP measured
     * by libebur128's 4x true peak, -16.01 LUFS) */
    T_ASSERTF(fabs(l.integrated - -16) <= 0.2, "%.2f LUFS", l.integrated);
    T_ASSERTF(l.true_peak <= -1.0 && l.true_peak >= -1.3, "%.2f dBTP: the limiter's ceiling is -1", l.true_peak);
    au_track_free(&s); /* s is written again below (and left empty by a refusal) */
    T_ASSERT(!au_replay_track(&rp, DEMO, 10, 10, NULL, &s, &err) && err.code == AU_ERR_ARG);
    T_ASSERT(!au_replay_track(&rp, DEMO, 0, rp.ticks + 1, NULL, &s, &err) && err.code == AU_ERR_ARG);
    au_track_free(&a);
    au_track_free(&b);
    au_track_free(&s);
    rp_free(&rp);
}

static void t_track_hit_onset_on_its_tick(void)
{
    rp_replay rp;
    load(&rp);
    /* the first hit with no other sound started in the 40 ticks before it */
    g_state st, prev;
    g_init(&st, rp.stage, rp.seed);
    uint64_t hit = 0, quiet_from = 0; /* every sound started so far has ended by quiet_from */
    for (uint64_t k = 0; k < rp.ticks && !hit; k++) {
        g_events ev;
        prev = st;
        g_step(&st, &rp.inputs[2 * k], &ev);
        au_cue c[AU_MAX_CUES];
        int n = au_game_cues(&prev, &st, &ev, c, AU_MAX_CUES);
        if (n && !strncmp(au_bank_get(c[0].sound)->name, "hit_", 4) && k >= quiet_from + 2)
            hit = k;
        for (int i = 0; i < n; i++) {
            uint64_t end = k + 1 + au_bank_get(c[i].sound)->frames / AU_TICK_FRAMES;
            quiet_from = end > quiet_from ? end : quiet_from;
        }
    }
    T_ASSERTF(hit, "no lone hit in %s", DEMO);
    rs_err err = {0};
    au_replay_opts o = {.mix = {.music = -1}, .target_lufs = NAN};
    au_track t;
    T_ASSERTF(au_replay_track(&rp, DEMO, hit - 2, hit + 2, &o, &t, &err), "%s", err.msg);
    /* silent up to the tick's first frame, loud within 1 ms (48 frames) of it */
    size_t at = 2 * AU_TICK_FRAMES, onset = t.frames;
    T_ASSERT(peak_of(t.pcm, 2 * at) == 0);
    for (size_t i = 0; i < t.frames && onset == t.frames; i++)
        if (fabsf(t.pcm[2 * i]) > 0.003f || fabsf(t.pcm[2 * i + 1]) > 0.003f)
            onset = i;
    T_ASSERTF(onset >= at && onset < at + 48, "hit at tick %llu: onset at frame %zu of the tick range, want %zu..%zu",
              (unsigned long long)hit, onset, at, at + 47);
    au_track_free(&t);
    rp_free(&rp);
}

static void t_track_desync_names_tick(void)
{
    rp_replay rp;
    load(&rp);
    rp.inputs[2 * 100] ^= G_IN_GUARD; /* tick 100 of P1, in the round's intro */
    rs_err err = {0};
    au_track t;
    T_ASSERT(!au_replay_track(&rp, DEMO, 0, 200, NULL, &t, &err));
    T_EQ(err.code, AU_ERR_DESYNC);
    T_CONTAINS(err.msg, "desync at tick 120");
    T_ASSERT(t.pcm == NULL);
    au_replay_opts o = {.no_check = true, .target_lufs = NAN};
    T_ASSERTF(au_replay_track(&rp, DEMO, 0, 200, &o, &t, &err), "%s", err.msg);
    au_track_free(&t);
    rp_free(&rp);
}

T_MAIN({"wav_round_trip", t_wav_round_trip}, {"wav_reads_other_formats", t_wav_reads_other_formats},
       {"wav_bad_files", t_wav_bad_files}, {"bank_deterministic", t_bank_deterministic},
       {"mixer_pan_gain_offset", t_mixer_pan_gain_offset},
       {"mixer_voice_limit_and_limiter", t_mixer_voice_limit_and_limiter}, {"mixer_music_phase", t_mixer_music_phase},
       {"cues_pan_and_diffs", t_cues_pan_and_diffs}, {"loudness_normalize_holds_peak", t_loudness_normalize_holds_peak},
       {"loudness_of_a_sine", t_loudness_of_a_sine},
       {"loudness_stream_any_pieces", t_loudness_stream_any_pieces},
       {"track_streamed_equals_buffer", t_track_streamed_equals_buffer},
       {"track_identical_and_sliced", t_track_identical_and_sliced},
       {"track_hit_onset_on_its_tick", t_track_hit_onset_on_its_tick},
       {"track_desync_names_tick", t_track_desync_names_tick})
