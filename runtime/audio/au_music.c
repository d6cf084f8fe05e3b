/* Background music: one short procedural loop per stage, 8 bars of bass,
 * a pad and percussion, each stage with its own tempo, key, mode, chord
 * progression, patterns and timbres (the table below).
 *
 * A loop is rendered once, on the first request for its stage
 * (pthread_once per stage), into a stereo buffer; the mixer plays frame
 * N % frames at its position N, so the music at frame N of a match is
 * always the same samples, whatever was skipped or seeked.  Sounds that
 * ring past the loop's end are folded back onto its start, so the seam is
 * as smooth as any bar line.  The loop is brought to MUSIC_LUFS with
 * libebur128, so every stage sits at the same level under the effects. */
#include <ebur128.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>

#include "au_local.h"

#define MUSIC_LUFS (-20.0)
#define BARS 8
#define STEPS_PER_BAR 16
#define STEPS (BARS * STEPS_PER_BAR)
#define TAIL_SEC 2.0

enum { WAVE_SAW, WAVE_SQUARE, WAVE_TRI };

typedef struct stage_music {
    int bpm;
    int root;            /* MIDI note of the key's tonic, octave 2 (bass range) */
    int mode[7];         /* scale intervals in semitones from the tonic */
    int chords[4];       /* scale degree (0-based) of each 2-bar chord */
    uint16_t kick, snare, hat, bass; /* 16-step patterns, bit k = step k */
    int bass_wave;
    double pad_lp;       /* pad brightness: its low-pass cutoff, Hz */
    double pad_detune;   /* cents between the pad's left and right saws */
    double swing;        /* delay of odd 16ths, as a fraction of a step */
    uint32_t seed;
} stage_music;

#define MINOR {0, 2, 3, 5, 7, 8, 10}
#define DORIAN {0, 2, 3, 5, 7, 9, 10}
#define MAJOR {0, 2, 4, 5, 7, 9, 11}
#define PHRYGIAN {0, 1, 3, 5, 7, 8, 10}
#define MIXOLYDIAN {0, 2, 4, 5, 7, 9, 10}
#define LYDIAN {0, 2, 4, 6, 7, 9, 11}

/* bit k of a pattern is step k of the bar: 0x0101 = steps 0 and 8 */
static const stage_music music[G_STAGES] = {
    /* dojo: steady minor drive */
    {124, 38, MINOR, {0, 5, 2, 6}, 0x0101, 0x1010, 0x5555, 0x2929, WAVE_SAW, 1400, 9, 0, 101},
    /* harbor: storm, phrygian, busy kick */
    {132, 40, PHRYGIAN, {0, 1, 0, 6}, 0x0909, 0x1010, 0xFFFF, 0x6D6D, WAVE_SQUARE, 1100, 14, 0, 102},
    /* temple: slow dorian, sparse */
    {96, 43, DORIAN, {0, 3, 4, 3}, 0x0001, 0x0100, 0x4444, 0x0101, WAVE_TRI, 2000, 6, 0.12, 103},
    /* shallows: light lydian, swung */
    {108, 41, LYDIAN, {0, 1, 4, 5}, 0x0101, 0x1010, 0x5555, 0x1111, WAVE_TRI, 2600, 11, 0.2, 104},
    /* snowfield: cold major, soft */
    {100, 45, MAJOR, {0, 3, 5, 4}, 0x0101, 0x1000, 0x1111, 0x0505, WAVE_TRI, 1800, 7, 0.1, 105},
    /* mistvale: dark minor, half time */
    {88, 36, MINOR, {0, 3, 5, 4}, 0x0001, 0x0100, 0x2222, 0x0303, WAVE_SAW, 900, 18, 0.08, 106},
    /* plaza: mixolydian groove */
    {116, 42, MIXOLYDIAN, {0, 6, 3, 4}, 0x2121, 0x1010, 0x7777, 0xA5A5, WAVE_SQUARE, 2200, 10, 0.15, 107},
    /* quarry: heavy and fast */
    {140, 33, PHRYGIAN, {0, 1, 5, 0}, 0x0B0B, 0x1010, 0x5555, 0x0F0F, WAVE_SAW, 800, 16, 0, 108},
};

static double midi_hz(double note)
{
    return 440.0 * pow(2.0, (note - 69) / 12.0);
}

static int degree_note(const stage_music *m, int degree)
{
    return m->root + 12 * (degree / 7) + m->mode[degree % 7];
}

/* one oscillator sample for phase ph (cycles, 0..1) */
static double wave(int kind, double ph)
{
    switch (kind) {
    case WAVE_SQUARE: return ph < 0.5 ? 0.7 : -0.7;
    case WAVE_TRI: return ph < 0.5 ? 4 * ph - 1 : 3 - 4 * ph;
    default: return 2 * ph - 1;
    }
}

static void add(float *pcm, size_t n, size_t i, double l, double r)
{
    if (i < n) {
        pcm[2 * i] += (float)l;
        pcm[2 * i + 1] += (float)r;
    }
}

static void kick(float *pcm, size_t n, size_t at)
{
    double ph = 0;
    for (size_t i = 0; i < (size_t)(0.3 * AU_RATE); i++) {
        double t = (double)i / AU_RATE, f = 45 + 85 * exp(-t / 0.03);
        ph += 2 * AU_PI * f / AU_RATE;
        double v = 0.9 * exp(-t / 0.11) * sin(ph);
        add(pcm, n, at + i, v, v);
    }
}

static void snare(float *pcm, size_t n, size_t at, au_rng *r)
{
    au_biquad bp;
    au_bq_bandpass(&bp, 1900, 0.9);
    for (size_t i = 0; i < (size_t)(0.2 * AU_RATE); i++) {
        double t = (double)i / AU_RATE;
        double v = 0.9 * exp(-t / 0.05) * au_bq_run(&bp, au_rng_white(r)) + 0.3 * exp(-t / 0.03) * sin(2 * AU_PI * 190 * t);
        add(pcm, n, at + i, v, v);
    }
}

static void hat(float *pcm, size_t n, size_t at, au_rng *r, double pan)
{
    au_biquad hp;
    au_bq_highpass(&hp, 7000, 0.7);
    for (size_t i = 0; i < (size_t)(0.06 * AU_RATE); i++) {
        double t = (double)i / AU_RATE, v = 0.35 * exp(-t / 0.018) * au_bq_run(&hp, au_rng_white(r));
        add(pcm, n, at + i, v * (1 - pan), v * (1 + pan));
    }
}

static void bass(float *pcm, size_t n, size_t at, size_t len, double hz, int kind)
{
    au_biquad lp;
    au_bq_lowpass(&lp, 520, 1.1);
    double ph = 0;
    for (size_t i = 0; i < len + (size_t)(0.02 * AU_RATE); i++) {
        double t = (double)i / AU_RATE, env = (t < 0.004 ? t / 0.004 : 1) * exp(-t / 0.35);
        if (i >= len) /* release */
            env *= 1.0 - (double)(i - len) / (0.02 * AU_RATE);
        ph += hz / AU_RATE;
        ph -= floor(ph);
        double v = 0.55 * env * au_bq_run(&lp, wave(kind, ph) + 0.5 * sin(2 * AU_PI * ph));
        add(pcm, n, at + i, v, v);
    }
}

/* the chord of one 2-bar section: root, third and fifth of the scale
 * degree, two octaves up, as detuned saws spread left and right */
static void pad(float *pcm, size_t n, size_t at, size_t len, const stage_music *m, int degree)
{
    double rel = 0.25 * AU_RATE;
    for (int v = 0; v < 3; v++) {
        double hz = midi_hz(degree_note(m, degree + 2 * v) + 24);
        double dl = pow(2.0, -m->pad_detune / 2400.0), dr = pow(2.0, m->pad_detune / 2400.0);
        au_biquad fl, fr;
        au_bq_lowpass(&fl, m->pad_lp, 0.7);
        au_bq_lowpass(&fr, m->pad_lp, 0.7);
        double pl = 0.13 * v, pr = 0.57 * v; /* different start phases: no comb at the onset */
        for (size_t i = 0; i < len + (size_t)rel; i++) {
            double t = (double)i / AU_RATE, env = t < 0.4 ? t / 0.4 : 1;
            if (i >= len)
                env *= 1.0 - (double)(i - len) / rel;
            pl += hz * dl / AU_RATE;
            pl -= floor(pl);
            pr += hz * dr / AU_RATE;
            pr -= floor(pr);
            double l = au_bq_run(&fl, 2 * pl - 1), r = au_bq_run(&fr, 2 * pr - 1);
            add(pcm, n, at + i, 0.12 * env * l, 0.12 * env * r);
        }
    }
}

static void render(const stage_music *m, au_loop *out)
{
    size_t step = (size_t)lround(AU_RATE * 60.0 / (m->bpm * 4.0));
    size_t frames = step * STEPS, n = frames + (size_t)(TAIL_SEC * AU_RATE);
    float *pcm = calloc(2 * n, sizeof *pcm);
    if (!pcm)
        return;
    au_rng r;
    au_rng_seed(&r, m->seed);
    for (int s = 0; s < STEPS; s++) {
        int k = s % STEPS_PER_BAR;
        size_t at = (size_t)s * step + (k & 1 ? (size_t)(m->swing * step) : 0);
        int chord = m->chords[s / (2 * STEPS_PER_BAR)];
        if (m->kick >> k & 1)
            kick(pcm, n, at);
        if (m->snare >> k & 1)
            snare(pcm, n, at, &r);
        if (m->hat >> k & 1)
            hat(pcm, n, at, &r, (k & 2) ? 0.3 : -0.3);
        if (m->bass >> k & 1) {
            int len = 1;
            while (k + len < STEPS_PER_BAR && !(m->bass >> (k + len) & 1) && len < 4)
                len++;
            int octave = (s / STEPS_PER_BAR) % 2 && (k == 6 || k == 14) ? 12 : 0;
            bass(pcm, n, at, (size_t)len * step - step / 4, midi_hz(degree_note(m, chord) + octave), m->bass_wave);
        }
        if (s % (2 * STEPS_PER_BAR) == 0)
            pad(pcm, n, at, 2 * STEPS_PER_BAR * step, m, chord);
    }
    for (size_t i = frames; i < n; i++) { /* fold the ringing tail onto the start */
        pcm[2 * (i - frames)] += pcm[2 * i];
        pcm[2 * (i - frames) + 1] += pcm[2 * i + 1];
    }
    double lufs = -HUGE_VAL;
    ebur128_state *st = ebur128_init(2, AU_RATE, EBUR128_MODE_I);
    if (st && ebur128_add_frames_float(st, pcm, frames) == EBUR128_SUCCESS)
        ebur128_loudness_global(st, &lufs);
    if (st)
        ebur128_destroy(&st);
    double g = isfinite(lufs) ? pow(10.0, (MUSIC_LUFS - lufs) / 20.0) : 0.1;
    for (size_t i = 0; i < 2 * frames; i++)
        pcm[i] = (float)(pcm[i] * g);
    out->pcm = pcm;
    out->frames = frames;
}

_Static_assert(G_STAGES == 8, "one loop builder per stage below");

static au_loop loops[G_STAGES];
static pthread_once_t once[G_STAGES] = {PTHREAD_ONCE_INIT, PTHREAD_ONCE_INIT, PTHREAD_ONCE_INIT, PTHREAD_ONCE_INIT,
                                        PTHREAD_ONCE_INIT, PTHREAD_ONCE_INIT, PTHREAD_ONCE_INIT, PTHREAD_ONCE_INIT};
#define ONCE(k) \
    static void build##k(void) { render(&music[k], &loops[k]); }
ONCE(0) ONCE(1) ONCE(2) ONCE(3) ONCE(4) ONCE(5) ONCE(6) ONCE(7)
static void (*const builders[G_STAGES])(void) = {build0, build1, build2, build3, build4, build5, build6, build7};

const au_loop *au_music_loop(int stage)
{
    if (stage < 0 || stage >= G_STAGES)
        return NULL;
    pthread_once(&once[stage], builders[stage]);
    return loops[stage].pcm ? &loops[stage] : NULL;
}
