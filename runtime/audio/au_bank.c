/* The sound bank: every effect synthesized here at AU_RATE, mono float,
 * plus the announcer's clips (au_voice.c), after them.  Built once on first use
 * (pthread_once), read-only afterwards, so any thread may read it.
 *
 * Determinism: each sound owns a fixed noise seed (xorshift32, au_local.h)
 * and reads no clock, no libc rand and no other sound's output; libm's
 * sin/exp/pow are the only outside code, so two builds of a sound give the
 * same samples (tests/test_audio.c rebuilds each one and compares).
 *
 * Levels: each sound is scaled to a fixed peak (the `peak` column), -20
 * dBFS for a footstep up to -6 dBFS for the heaviest blows, so cue gains
 * near 1 mix into a sum that rarely reaches the limiter.  How each sound is
 * made is described in docs/audio.md. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "au_local.h"

#define SEC(s) ((size_t)((s) * AU_RATE))

static double tsec(size_t i)
{
    return (double)i / AU_RATE;
}

/* A sine whose pitch glides from f0 to f1 with time constant tau, decaying
 * with time constant decay: the body of every thump. */
static void thump(float *b, size_t n, double f0, double f1, double tau, double decay, double amp)
{
    double ph = 0;
    for (size_t i = 0; i < n; i++) {
        double t = tsec(i), f = f1 + (f0 - f1) * exp(-t / tau);
        ph += 2 * AU_PI * f / AU_RATE;
        double attack = t < 0.002 ? t / 0.002 : 1; /* no click at the start */
        b[i] += (float)(amp * attack * exp(-t / decay) * sin(ph));
    }
}

/* Filtered noise with an exponential decay, starting at frame `at`. */
static void noise_burst(float *b, size_t n, size_t at, au_biquad *f, au_rng *r, double decay, double amp)
{
    for (size_t i = at; i < n; i++) {
        double t = tsec(i - at), attack = t < 0.001 ? t / 0.001 : 1;
        b[i] += (float)(amp * attack * exp(-t / decay) * au_bq_run(f, au_rng_white(r)));
    }
}

static void hit(float *b, size_t n, au_rng *r, double f0, double f1, double decay, double lp_hz, double crack)
{
    au_biquad lp, bp;
    thump(b, n, f0, f1, 0.025, decay, 1.0);
    au_bq_lowpass(&lp, lp_hz, 0.8);
    noise_burst(b, n, 0, &lp, r, decay * 0.45, 0.9);
    au_bq_bandpass(&bp, 2600, 1.2); /* the slap on top */
    noise_burst(b, n, 0, &bp, r, 0.008, crack);
}

static void s_hit_light(float *b, size_t n, au_rng *r)
{
    hit(b, n, r, 260, 110, 0.045, 2400, 1.4);
}
static void s_hit_medium(float *b, size_t n, au_rng *r)
{
    hit(b, n, r, 200, 80, 0.07, 1800, 1.1);
}
static void s_hit_heavy(float *b, size_t n, au_rng *r)
{
    hit(b, n, r, 150, 48, 0.12, 1200, 0.9);
    thump(b, n, 70, 38, 0.05, 0.2, 0.6); /* the floor-shaking tail */
}

/* Guard: a sharp, short click over a muffled knock (forearms meeting). */
static void s_guard(float *b, size_t n, au_rng *r)
{
    au_biquad hp, bp;
    au_bq_highpass(&hp, 3500, 0.7);
    noise_burst(b, n, 0, &hp, r, 0.004, 1.2);
    au_bq_bandpass(&bp, 850, 2.0);
    noise_burst(b, n, 0, &bp, r, 0.03, 2.0);
    thump(b, n, 480, 380, 0.01, 0.025, 0.5);
}

/* A swoosh: band-passed noise whose centre sweeps up then down, under a
 * rise-and-fall envelope. */
static void swoosh(float *b, size_t n, au_rng *r, double lo, double hi, double q)
{
    au_biquad bp;
    au_bq_bandpass(&bp, lo, q);
    for (size_t i = 0; i < n; i++) {
        double u = (double)i / n, env = sin(AU_PI * u) * sin(AU_PI * u);
        if (i % 32 == 0) { /* new coefficients, same filter memory */
            au_biquad keep = bp;
            au_bq_bandpass(&bp, lo + (hi - lo) * sin(AU_PI * u), q);
            bp.x1 = keep.x1, bp.x2 = keep.x2, bp.y1 = keep.y1, bp.y2 = keep.y2;
        }
        b[i] = (float)(env * au_bq_run(&bp, au_rng_white(r)));
    }
}
static void s_whiff(float *b, size_t n, au_rng *r)
{
    swoosh(b, n, r, 500, 2200, 1.5);
}
static void s_special(float *b, size_t n, au_rng *r)
{
    swoosh(b, n, r, 300, 3200, 2.5);
    double ph = 0;
    for (size_t i = 0; i < n; i++) { /* a rising hum: the palm gathering force */
        double u = (double)i / n;
        ph += 2 * AU_PI * (180 + 420 * u) / AU_RATE;
        b[i] += (float)(0.35 * sin(AU_PI * u) * (sin(ph) + 0.3 * sin(2 * ph)));
    }
}

static void s_step(float *b, size_t n, au_rng *r)
{
    au_biquad lp;
    thump(b, n, 90, 60, 0.02, 0.025, 1.0);
    au_bq_lowpass(&lp, 350, 0.7);
    noise_burst(b, n, 0, &lp, r, 0.02, 1.5);
}
static void s_land(float *b, size_t n, au_rng *r)
{
    au_biquad lp;
    thump(b, n, 80, 50, 0.03, 0.05, 1.0);
    au_bq_lowpass(&lp, 500, 0.7);
    noise_burst(b, n, 0, &lp, r, 0.04, 1.5);
}

/* Body fall: the back hits the mat, then the arms and legs a moment later. */
static void s_knockdown(float *b, size_t n, au_rng *r)
{
    au_biquad lp, lp2;
    thump(b, n, 95, 45, 0.03, 0.12, 1.0);
    au_bq_lowpass(&lp, 800, 0.7);
    noise_burst(b, n, 0, &lp, r, 0.06, 1.2);
    au_bq_lowpass(&lp2, 1400, 0.7);
    noise_burst(b, n, SEC(0.09), &lp2, r, 0.04, 0.7);
    noise_burst(b, n, SEC(0.16), &lp2, r, 0.03, 0.4);
}

/* Ring-out on dry stages: a heavy fall off the ring onto the ground below. */
static void s_ringout_fall(float *b, size_t n, au_rng *r)
{
    au_biquad lp, bp;
    thump(b, n, 70, 34, 0.05, 0.25, 1.0);
    au_bq_lowpass(&lp, 600, 0.7);
    noise_burst(b, n, 0, &lp, r, 0.15, 1.3);
    au_bq_bandpass(&bp, 2200, 3.0); /* gravel rattle */
    for (int k = 0; k < 14; k++) {
        size_t at = SEC(0.05) + au_rng_next(r) % SEC(0.5);
        noise_burst(b, n < at + SEC(0.05) ? n : at + SEC(0.05), at, &bp, r, 0.01, 0.5 * exp(-(double)at / SEC(0.3)));
    }
}

/* Ring-out on the water stages: the smack on the surface, the spray, then
 * droplets (short upward chirps) falling back. */
static void s_ringout_splash(float *b, size_t n, au_rng *r)
{
    au_biquad lp, bp;
    thump(b, n, 110, 50, 0.03, 0.08, 0.7);
    au_bq_lowpass(&lp, 1500, 0.7);
    noise_burst(b, n, 0, &lp, r, 0.12, 1.2);
    au_bq_bandpass(&bp, 3200, 0.8);
    noise_burst(b, n, SEC(0.02), &bp, r, 0.35, 0.8);
    for (int k = 0; k < 40; k++) {
        size_t at = SEC(0.1) + au_rng_next(r) % SEC(0.9), len = SEC(0.025);
        double f = 700 + au_rng_next(r) % 1500, amp = 0.25 * exp(-(double)(at - SEC(0.1)) / SEC(0.5)), ph = 0;
        for (size_t i = 0; i < len && at + i < n; i++) {
            double t = tsec(i);
            ph += 2 * AU_PI * f * (1 + 40 * t) / AU_RATE;
            b[at + i] += (float)(amp * exp(-t / 0.008) * sin(ph));
        }
    }
}

/* Thunder: a crackle of sparse sharp impulses, then a long low rumble of
 * brown noise whose level swells and fades. */
static void s_thunder(float *b, size_t n, au_rng *r)
{
    au_biquad hp, lp1, lp2;
    au_bq_highpass(&hp, 1800, 0.7);
    for (size_t i = 0; i < SEC(0.5) && i < n; i++) {
        double t = tsec(i), dens = 0.02 * exp(-t / 0.15);
        double x = (au_rng_next(r) % 100000) < dens * 100000 ? au_rng_white(r) * 6 : 0;
        b[i] += (float)(au_bq_run(&hp, x + 0.05 * au_rng_white(r)) * exp(-t / 0.25));
    }
    au_bq_lowpass(&lp1, 160, 0.7);
    au_bq_lowpass(&lp2, 90, 0.7);
    double brown = 0;
    for (size_t i = 0; i < n; i++) {
        double t = tsec(i);
        brown = 0.995 * brown + 0.05 * au_rng_white(r);
        double env = (t < 0.25 ? t / 0.25 : 1) * exp(-t / 1.1) * (1 + 0.5 * sin(2 * AU_PI * 1.7 * t + 1));
        b[i] += (float)(14 * env * au_bq_run(&lp2, au_bq_run(&lp1, brown)));
    }
}

/* A crater breaking: a dull crack, then grains of rubble (band-passed noise
 * bursts) thinning out as the debris settles. */
static void s_crater(float *b, size_t n, au_rng *r)
{
    au_biquad lp, bp;
    thump(b, n, 120, 40, 0.02, 0.1, 0.9);
    au_bq_lowpass(&lp, 2500, 0.7);
    noise_burst(b, n, 0, &lp, r, 0.03, 1.0);
    for (int k = 0; k < 70; k++) {
        double u = (double)(au_rng_next(r) % 10000) / 10000;
        size_t at = (size_t)(u * u * (double)(n - SEC(0.03))), len = SEC(0.004) + au_rng_next(r) % SEC(0.02);
        au_bq_bandpass(&bp, 600 + au_rng_next(r) % 3400, 2.0);
        noise_burst(b, at + len < n ? at + len : n, at, &bp, r, 0.006, 1.2 * (1 - 0.8 * u));
    }
}

/* The boxing bell, struck twice: inharmonic partials of a thick bell, each
 * with its own decay (higher ones die sooner). */
static void s_bell(float *b, size_t n, au_rng *r)
{
    (void)r;
    static const double ratio[] = {1.0, 2.32, 4.25, 6.63, 9.38}, amp[] = {1.0, 0.7, 0.45, 0.3, 0.18};
    static const double decay[] = {1.2, 0.8, 0.45, 0.3, 0.2};
    for (int strike = 0; strike < 2; strike++) {
        size_t at = strike * SEC(0.32);
        for (int p = 0; p < 5; p++)
            for (size_t i = at; i < n; i++) {
                double t = tsec(i - at), attack = t < 0.001 ? t / 0.001 : 1;
                b[i] += (float)(amp[p] * attack * exp(-t / decay[p]) * sin(2 * AU_PI * 780 * ratio[p] * t));
            }
    }
}

/* A crowd: many voices, each a noise source through two vowel formants
 * (detuned per voice), with its own onset and swell; a noise bed under
 * them.  f1/f2: the vowel, attack/hold: the reaction's shape. */
static void crowd(float *b, size_t n, au_rng *r, int voices, double f1, double f2, double attack, double hold)
{
    for (int v = 0; v < voices; v++) {
        double det = 0.8 + 0.4 * (au_rng_next(r) % 1000) / 1000.0, g = 0.5 + (au_rng_next(r) % 1000) / 1000.0;
        size_t at = au_rng_next(r) % SEC(attack);
        double len = hold * (0.6 + 0.8 * (au_rng_next(r) % 1000) / 1000.0);
        au_biquad a, c;
        au_bq_bandpass(&a, f1 * det, 5);
        au_bq_bandpass(&c, f2 * det, 6);
        double buzz = 0, hz = 110 + au_rng_next(r) % 180, ph = 0;
        for (size_t i = at; i < n; i++) {
            double t = tsec(i - at), env = (t < 0.08 ? t / 0.08 : 1) * exp(-t / len);
            ph += 2 * AU_PI * hz * (1 + 0.03 * sin(2 * AU_PI * 5 * t)) / AU_RATE;
            buzz = 0.6 * au_rng_white(r) + 0.4 * (sin(ph) > 0 ? 1 : -1); /* breath + a voiced buzz */
            b[i] += (float)(g * env * (au_bq_run(&a, buzz) + 0.6 * au_bq_run(&c, buzz)));
        }
    }
    au_biquad bed, lp1, lp2;
    au_bq_bandpass(&bed, 900, 0.5);
    for (size_t i = 0; i < n; i++) {
        double t = tsec(i), env = (t < attack ? t / attack : 1) * exp(-t / (hold * 1.2));
        b[i] += (float)(0.8 * env * au_bq_run(&bed, au_rng_white(r)));
    }
    /* a hall full of people, heard from the ring: no hiss above 4 kHz */
    au_bq_lowpass(&lp1, 4000, 0.7);
    au_bq_lowpass(&lp2, 4000, 0.7);
    for (size_t i = 0; i < n; i++)
        b[i] = (float)au_bq_run(&lp2, au_bq_run(&lp1, b[i]));
}
static void s_crowd_cheer(float *b, size_t n, au_rng *r)
{
    crowd(b, n, r, 32, 750, 1250, 0.35, 0.9);
}
static void s_crowd_gasp(float *b, size_t n, au_rng *r)
{
    crowd(b, n, r, 24, 480, 850, 0.08, 0.3);
}

typedef struct synth_def {
    const char *name;
    void (*make)(float *b, size_t n, au_rng *r);
    double seconds, peak_db;
    uint32_t seed;
} synth_def;

static const synth_def synths[] = {
    {"hit_light", s_hit_light, 0.18, -10, 11},
    {"hit_medium", s_hit_medium, 0.28, -8, 12},
    {"hit_heavy", s_hit_heavy, 0.55, -6, 13},
    {"guard", s_guard, 0.14, -10, 14},
    {"whiff", s_whiff, 0.2, -16, 15},
    {"special", s_special, 0.5, -12, 16},
    {"step", s_step, 0.1, -22, 17},
    {"land", s_land, 0.18, -15, 18},
    {"knockdown", s_knockdown, 0.6, -8, 19},
    {"ringout_fall", s_ringout_fall, 0.9, -6, 20},
    {"ringout_splash", s_ringout_splash, 1.2, -7, 21},
    {"thunder", s_thunder, 3.5, -7, 22},
    {"crater", s_crater, 0.8, -9, 23},
    {"bell", s_bell, 2.4, -9, 24},
    {"crowd_cheer", s_crowd_cheer, 2.6, -13, 25},
    {"crowd_gasp", s_crowd_gasp, 1.0, -15, 26},
};
#define NSYNTH ((int)(sizeof synths / sizeof synths[0]))

float *au_bank_synth(int id, size_t *frames)
{
    if (id < 0 || id >= NSYNTH)
        return NULL;
    const synth_def *d = &synths[id];
    size_t n = SEC(d->seconds);
    float *b = calloc(n, sizeof *b);
    if (!b)
        return NULL;
    au_rng r;
    au_rng_seed(&r, d->seed);
    d->make(b, n, &r);
    au_normalize_peak(b, n, d->peak_db);
    /* a short fade out: no sound ends on a step */
    size_t fade = SEC(0.005);
    for (size_t i = 0; i < fade && i < n; i++)
        b[n - 1 - i] *= (float)i / (float)fade;
    *frames = n;
    return b;
}

static au_sound *bank;
static int bank_n;
static pthread_once_t bank_once = PTHREAD_ONCE_INIT;

/* The synthesized sounds, then the announcer's clips.  A sound that cannot
 * be built (out of memory at start-up) stays in the bank as silence of
 * length 0: the game plays on without it. */
static void build(void)
{
    int n = NSYNTH + au_voice_count();
    bank = calloc((size_t)n, sizeof *bank);
    if (!bank)
        return;
    for (int i = 0; i < n; i++) {
        size_t frames = 0;
        bool synth = i < NSYNTH;
        bank[i].name = synth ? synths[i].name : au_voice_name(i - NSYNTH);
        bank[i].samples = synth ? au_bank_synth(i, &frames) : au_voice_build(i - NSYNTH, &frames);
        bank[i].frames = bank[i].samples ? frames : 0;
    }
    bank_n = n;
}

int au_bank_count(void)
{
    pthread_once(&bank_once, build);
    return bank_n;
}

const au_sound *au_bank_get(int id)
{
    pthread_once(&bank_once, build);
    return id >= 0 && id < bank_n ? &bank[id] : NULL;
}

int au_bank_find(const char *name)
{
    pthread_once(&bank_once, build);
    for (int i = 0; i < bank_n; i++)
        if (!strcmp(bank[i].name, name))
            return i;
    return -1;
}
