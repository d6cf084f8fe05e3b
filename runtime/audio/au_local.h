/* Private to runtime/audio: the synthesis toolkit the bank and the music
 * share, and the hooks between the bank, the music and the mixer.  Nothing
 * outside runtime/audio includes this. */
#ifndef AU_LOCAL_H
#define AU_LOCAL_H

#include <stddef.h>
#include <stdint.h>

#include "au.h"

#define AU_PI 3.14159265358979323846

/* Seeded noise: xorshift32.  Every sound seeds its own generator with a
 * fixed number, so a sound never depends on which was built before it. */
typedef struct au_rng {
    uint32_t s;
} au_rng;
static inline void au_rng_seed(au_rng *r, uint32_t seed)
{
    r->s = seed ? seed : 0x9e3779b9u;
}
static inline uint32_t au_rng_next(au_rng *r)
{
    uint32_t x = r->s;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    return r->s = x;
}
/* white noise in -1..1 */
static inline float au_rng_white(au_rng *r)
{
    return (float)((double)au_rng_next(r) / 2147483648.0 - 1.0);
}

/* RBJ biquad (direct form I, double state: the same numbers at -O0 and -O2
 * because -ffp-contract=off forbids fused multiply-adds). */
typedef struct au_biquad {
    double b0, b1, b2, a1, a2;
    double x1, x2, y1, y2;
} au_biquad;
void au_bq_lowpass(au_biquad *f, double hz, double q);
void au_bq_highpass(au_biquad *f, double hz, double q);
void au_bq_bandpass(au_biquad *f, double hz, double q); /* 0 dB peak gain */
double au_bq_run(au_biquad *f, double x);

/* Scales buf so that its peak is peak_dbfs (silence is left alone). */
void au_normalize_peak(float *buf, size_t n, double peak_dbfs);

/* The music of a stage: a stereo loop (au_music.c), built on first use,
 * read-only afterwards.  Frame N of a match plays loop frame N % frames. */
typedef struct au_loop {
    const float *pcm; /* frames * 2 */
    size_t frames;
} au_loop;
const au_loop *au_music_loop(int stage); /* NULL for a stage outside 0..G_STAGES-1 */

/* A fresh copy of synthesized sound id (au_bank.c's own order, the first
 * ids of the bank), malloc'd; NULL for another id or out of memory.  The
 * bank is built with it; tests compare two builds. */
float *au_bank_synth(int id, size_t *frames);

/* au_wav_read on bytes in memory (name is for messages). */
bool au_wav_parse(const uint8_t *d, size_t len, const char *name, float **pcm, size_t *frames, int *channels,
                  int *rate, rs_err *err);

/* The announcer's clips, embedded in the binary (au_voice.c): count, the
 * bank name of clip i ("voice_round1", ...), and its samples decoded,
 * trimmed of silence and resampled to AU_RATE (malloc'd; NULL when out of
 * memory or not a WAV this build reads). */
int au_voice_count(void);
const char *au_voice_name(int i);
float *au_voice_build(int i, size_t *frames);

#endif
