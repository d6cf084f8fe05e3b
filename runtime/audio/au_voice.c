/* The announcer: the clips of runtime/audio/voice/ (espeak-ng, rendered
 * once by tools/gen-voice.sh and embedded by au_voice_data.S), decoded,
 * trimmed and resampled to AU_RATE for the bank.
 *
 * DESIGN: resampling is a windowed sinc (Hann, 2 x 16 taps) evaluated
 * from a table of the ratio's phases: out/in = 48000/22050 = 320/147, so
 * output frame n falls on one of 320 fractional positions of the input,
 * and the table makes the whole bank's voices cost ~10^7 multiply-adds
 * and no per-sample sin().  Pure arithmetic: the same samples in every
 * build.  Silence under -45 dBFS is cut from both ends (espeak pads half
 * a second), so a line starts on the tick it is cued for. */
#include <math.h>
#include <stdlib.h>

#include "au_local.h"

#define HALF 16          /* taps each side */
#define TRIM_DB (-45.0)
#define PEAK_DB (-3.0)   /* the announcer speaks over everything */

#define CLIPS(X) \
    X(round1) X(round2) X(round3) X(round4) X(round5) X(fight) X(ko) X(ring_out) X(time) X(draw) X(p1_wins) X(p2_wins)

#define X(n) extern const unsigned char au_vd_##n[], au_vd_##n##_end[];
CLIPS(X)
#undef X

typedef struct clip {
    const char *name;
    const unsigned char *start, *end;
} clip;
static const clip clips[] = {
#define X(n) {"voice_" #n, au_vd_##n, au_vd_##n##_end},
    CLIPS(X)
#undef X
};
#define NCLIPS ((int)(sizeof clips / sizeof clips[0]))

int au_voice_count(void)
{
    return NCLIPS;
}

const char *au_voice_name(int i)
{
    return i >= 0 && i < NCLIPS ? clips[i].name : NULL;
}

static uint64_t gcd(uint64_t a, uint64_t b)
{
    while (b) {
        uint64_t t = a % b;
        a = b;
        b = t;
    }
    return a;
}

/* in (n frames at rate) -> AU_RATE; NULL when out of memory */
static float *resample(const float *in, size_t n, int rate, size_t *out_n)
{
    uint64_t g = gcd((uint64_t)rate, AU_RATE), up = AU_RATE / g, down = (uint64_t)rate / g;
    size_t m = (size_t)((uint64_t)n * up / down);
    double *tab = malloc(up * 2 * HALF * sizeof *tab);
    float *out = malloc((m ? m : 1) * sizeof *out);
    if (!tab || !out) {
        free(tab);
        free(out);
        return NULL;
    }
    /* down-sampling would need the cutoff lowered to the new Nyquist */
    double cut = rate > AU_RATE ? (double)AU_RATE / rate : 1.0;
    for (uint64_t p = 0; p < up; p++) {
        double frac = (double)p / up; /* output sits frac past input frame i */
        for (int k = 0; k < 2 * HALF; k++) {
            double x = (double)(k - HALF + 1) - frac; /* input frame i-HALF+1+k, relative */
            double s = x == 0 ? 1 : sin(AU_PI * x * cut) / (AU_PI * x * cut);
            double w = fabs(x) >= HALF ? 0 : 0.5 + 0.5 * cos(AU_PI * x / HALF);
            tab[p * 2 * HALF + k] = cut * s * w;
        }
    }
    for (size_t j = 0; j < m; j++) {
        uint64_t pos = (uint64_t)j * down;
        long i = (long)(pos / up);
        const double *h = tab + (pos % up) * 2 * HALF;
        double y = 0;
        for (int k = 0; k < 2 * HALF; k++) {
            long at = i - HALF + 1 + k;
            if (at >= 0 && (size_t)at < n)
                y += h[k] * in[at];
        }
        out[j] = (float)y;
    }
    free(tab);
    *out_n = m;
    return out;
}

float *au_voice_build(int i, size_t *frames)
{
    if (i < 0 || i >= NCLIPS)
        return NULL;
    float *pcm;
    size_t n;
    int ch, rate;
    if (!au_wav_parse(clips[i].start, (size_t)(clips[i].end - clips[i].start), clips[i].name, &pcm, &n, &ch, &rate,
                      NULL))
        return NULL;
    /* mono: the first channel (the clips are mono; a stereo one is taken as its left) */
    for (size_t k = 0; k < n; k++)
        pcm[k] = pcm[k * (size_t)ch];
    float floor_ = (float)pow(10.0, TRIM_DB / 20.0);
    size_t a = 0, b = n;
    while (a < b && fabsf(pcm[a]) < floor_)
        a++;
    while (b > a && fabsf(pcm[b - 1]) < floor_)
        b--;
    size_t m = 0;
    float *out = b > a ? resample(pcm + a, b - a, rate, &m) : NULL;
    free(pcm);
    if (!out)
        return NULL;
    au_normalize_peak(out, m, PEAK_DB);
    size_t fade = AU_RATE / 100; /* 10 ms out: the trim cut mid-breath */
    for (size_t k = 0; k < fade && k < m; k++)
        out[m - 1 - k] *= (float)k / (float)fade;
    *frames = m;
    return out;
}
