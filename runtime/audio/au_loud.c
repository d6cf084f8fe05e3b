/* Loudness: EBU R128 measurement (libebur128: integrated, range, true
 * peak) and normalization: a gain to the target, then a true-peak limiter.
 *
 * DESIGN: the limiter works on a finished buffer, so it looks ahead for
 * free and adds no delay.  Per frame it estimates the true (inter-sample)
 * peak with a 4x polyphase windowed-sinc interpolator, as BS.1770's
 * true-peak meter does; the gain each frame needs is r[n] = ceiling /
 * peak.  The applied gain is
 *   m[k] = min(r[k .. k+L-1])          (a sliding minimum: look-ahead)
 *   m'[k] = min(m[k], m'[k-1] + step)  (release: a slow linear rise)
 *   g[n] = mean(m'[n-L+1 .. n])        (a smooth attack over L frames)
 * Every m'[k] in g[n]'s window covers r[n], so g[n] <= r[n]: the estimate
 * never goes over the ceiling, and the ramps stay smooth.  The result is
 * measured again with libebur128, whose meter is the judge: a pass with the
 * ceiling lowered by the excess covers a disagreement between the two
 * estimates, and when the limiter cost loudness, the gain is raised by the
 * shortfall and the original limited again (up to 3 times).  The ceiling
 * aimed at is 0.2 dB under the one asked for. */
#include <ebur128.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "au_local.h"

#define OS 4           /* oversampling of the true-peak estimate */
#define TAPS 12        /* per phase */
#define LOOK 96        /* L: look-ahead and attack, frames (2 ms) */
#define RELEASE 4800   /* frames for the gain to recover from 0 to 1 (100 ms) */
#define MARGIN_DB 0.2

bool au_loud_measure(const float *pcm, size_t frames, au_loudness *out, rs_err *err)
{
    ebur128_state *st = ebur128_init(AU_CHANNELS, AU_RATE, EBUR128_MODE_I | EBUR128_MODE_LRA | EBUR128_MODE_TRUE_PEAK);
    if (!st)
        return rs_fail(err, AU_ERR_LOUDNESS, "loudness: libebur128 could not start (out of memory)");
    bool ok = true;
    for (size_t at = 0; at < frames && ok;) { /* in pieces: its frame count is a size_t, its buffers are not */
        size_t n = frames - at < (size_t)AU_RATE * 10 ? frames - at : (size_t)AU_RATE * 10;
        ok = ebur128_add_frames_float(st, pcm + 2 * at, n) == EBUR128_SUCCESS;
        at += n;
    }
    double I = -HUGE_VAL, lra = 0, tp = 0;
    for (unsigned c = 0; c < AU_CHANNELS && ok; c++) {
        double p;
        ok = ebur128_true_peak(st, c, &p) == EBUR128_SUCCESS;
        tp = ok && p > tp ? p : tp;
    }
    ok = ok && ebur128_loudness_global(st, &I) == EBUR128_SUCCESS;
    ok = ok && ebur128_loudness_range(st, &lra) == EBUR128_SUCCESS;
    ebur128_destroy(&st);
    if (!ok)
        return rs_fail(err, AU_ERR_LOUDNESS, "loudness: libebur128 failed to measure %zu frames", frames);
    out->integrated = isfinite(I) ? I : -HUGE_VAL;
    out->range = isfinite(lra) ? lra : 0;
    out->true_peak = tp > 0 ? 20 * log10(tp) : -HUGE_VAL;
    return true;
}

/* The interpolator: a windowed sinc at the original Nyquist, 4x. */
static void make_fir(double h[OS * TAPS])
{
    int n = OS * TAPS;
    for (int i = 0; i < n; i++) {
        double x = (i - (n - 1) / 2.0) / OS;
        double s = x == 0 ? 1 : sin(AU_PI * x) / (AU_PI * x);
        double w = 0.5 - 0.5 * cos(2 * AU_PI * (i + 0.5) / n); /* Hann */
        h[i] = s * w;
    }
}

/* r[n]: the gain frame n may have, 1 where it is under the ceiling. */
static void needed_gain(const float *pcm, size_t frames, double ceiling, float *r)
{
    double h[OS * TAPS];
    make_fir(h);
    const size_t B = 64;
    for (size_t b0 = 0; b0 < frames; b0 += B) {
        size_t b1 = b0 + B < frames ? b0 + B : frames;
        /* skip blocks that are far below the ceiling, their neighbours too:
         * an inter-sample peak is never 6 dB over the samples around it */
        size_t lo = b0 > TAPS ? b0 - TAPS : 0, hi = b1 + TAPS < frames ? b1 + TAPS : frames;
        float near = 0;
        for (size_t i = 2 * lo; i < 2 * hi; i++)
            near = fabsf(pcm[i]) > near ? fabsf(pcm[i]) : near;
        for (size_t n = b0; n < b1; n++)
            r[n] = 1;
        if (near < 0.5 * ceiling)
            continue;
        for (size_t n = b0; n < b1; n++) {
            /* the interpolated points between frames n-1 and n+1 */
            double peak = 0;
            for (int c = 0; c < 2; c++) {
                for (int p = 0; p < OS; p++) {
                    double y = 0;
                    for (int k = 0; k < TAPS; k++) {
                        long j = (long)n - TAPS / 2 + 1 + k;
                        if (j >= 0 && (size_t)j < frames)
                            y += h[OS * (TAPS - 1 - k) + p] * pcm[2 * j + c];
                    }
                    peak = fabs(y) > peak ? fabs(y) : peak;
                }
                double s = fabs(pcm[2 * n + c]);
                peak = s > peak ? s : peak;
            }
            r[n] = peak > ceiling ? (float)(ceiling / peak) : 1;
        }
    }
    /* an interpolated point lies between frames: both neighbours must
     * honour it */
    float prev = 1;
    for (size_t n = 0; n < frames; n++) {
        float cur = r[n], next = n + 1 < frames ? r[n + 1] : 1, m = cur < prev ? cur : prev;
        r[n] = m < next ? m : next;
        prev = cur;
    }
}

/* The gain curve of the DESIGN note, applied in place; false when no
 * frame needed limiting. */
static bool limit(float *pcm, size_t frames, double ceiling, bool *nomem)
{
    float *r = malloc(frames * sizeof *r), *pre = malloc(frames * sizeof *pre), *suf = malloc(frames * sizeof *suf);
    bool any = false;
    if (!r || !pre || !suf) {
        *nomem = true;
        goto done;
    }
    needed_gain(pcm, frames, ceiling, r);
    for (size_t n = 0; n < frames && !any; n++)
        any = r[n] < 1;
    if (!any)
        goto done;
    /* m[k] = min(r[k..k+L-1]) by blocks of L (van Herk / Gil-Werman): the
     * minimum from k to its block's end, and from the next block's start
     * to k+L-1 */
    for (size_t b = 0; b < frames; b += LOOK) {
        size_t e = b + LOOK < frames ? b + LOOK : frames;
        pre[b] = r[b];
        for (size_t k = b + 1; k < e; k++)
            pre[k] = r[k] < pre[k - 1] ? r[k] : pre[k - 1];
        suf[e - 1] = r[e - 1];
        for (size_t k = e - 1; k-- > b;)
            suf[k] = r[k] < suf[k + 1] ? r[k] : suf[k + 1];
    }
    double mprev = 1, sum = LOOK;
    float ring[LOOK];
    for (size_t i = 0; i < LOOK; i++)
        ring[i] = 1; /* m' before the start: no limiting */
    for (size_t k = 0; k < frames; k++) {
        size_t last = k + LOOK - 1;
        double m = suf[k];
        if (last < frames && last / LOOK != k / LOOK)
            m = pre[last] < m ? pre[last] : m;
        double rise = mprev + 1.0 / RELEASE;
        m = m < rise ? m : rise;
        mprev = m;
        float mf = (float)m;
        sum += mf - ring[k % LOOK];
        ring[k % LOOK] = mf;
        if (k % 4096 == 4095) { /* the running sum drifts by roundings: recount */
            sum = 0;
            for (size_t i = 0; i < LOOK; i++)
                sum += ring[i];
        }
        float g = (float)(sum / LOOK);
        g = g > r[k] ? r[k] : g; /* equal or less in exact arithmetic; a rounding must not cross it */
        pcm[2 * k] *= g;
        pcm[2 * k + 1] *= g;
    }
done:
    free(r);
    free(pre);
    free(suf);
    return any;
}

bool au_loud_normalize(float *pcm, size_t frames, double target_lufs, double peak_dbtp, au_loudness *before,
                       au_loudness *after, rs_err *err)
{
    if (!isfinite(target_lufs) || target_lufs < -70 || target_lufs > 0 || !isfinite(peak_dbtp) || peak_dbtp > 0 ||
        peak_dbtp < -30)
        return rs_fail(err, AU_ERR_ARG, "loudness: target %.1f LUFS, ceiling %.1f dBTP (expected -70..0 and -30..0)",
                       target_lufs, peak_dbtp);
    au_loudness b, a;
    if (!au_loud_measure(pcm, frames, &b, err))
        return false;
    if (before)
        *before = b;
    a = b;
    if (isfinite(b.integrated)) {
        float *orig = malloc(frames * 2 * sizeof *orig);
        if (!orig)
            return rs_fail(err, AU_ERR_NOMEM, "loudness: out of memory for %zu frames", frames);
        memcpy(orig, pcm, frames * 2 * sizeof *orig);
        double gain_db = target_lufs - b.integrated, ceiling_db = peak_dbtp - MARGIN_DB;
        for (int pass = 0; pass < 6; pass++) {
            float g = (float)pow(10.0, gain_db / 20.0);
            for (size_t i = 0; i < 2 * frames; i++)
                pcm[i] = orig[i] * g;
            bool nomem = false;
            bool limited = limit(pcm, frames, pow(10.0, ceiling_db / 20.0), &nomem);
            if (nomem || !au_loud_measure(pcm, frames, &a, err)) {
                free(orig);
                return nomem ? rs_fail(err, AU_ERR_NOMEM, "loudness: out of memory for the limiter (%zu frames)", frames)
                             : false;
            }
            /* the limiter took loudness away: make it up (a few times at
             * most: on programme that is all peaks it cannot be) */
            bool peak_ok = a.true_peak <= peak_dbtp;
            bool loud_ok = !limited || fabs(a.integrated - target_lufs) <= 0.2 || pass >= 3;
            if (peak_ok && loud_ok)
                break;
            if (!peak_ok)
                ceiling_db -= a.true_peak - peak_dbtp + 0.05;
            if (!loud_ok)
                gain_db += target_lufs - a.integrated;
        }
        free(orig);
    }
    if (after)
        *after = a;
    return true;
}
