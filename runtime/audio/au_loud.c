/* Loudness: EBU R128 measurement (libebur128: integrated, range, true
 * peak) and normalization: a gain to the target, then a true-peak limiter.
 *
 * DESIGN: everything here streams, so a track of any length is normalized
 * in a few kilobytes.  The plan (au_norm_plan) reads its source once to
 * measure it and once per pass of the loop below, each time from the
 * start (a replay's source mixes the match again: cheaper than keeping
 * it); the apply (au_norm_stream) reads it once more, through the same
 * gain and limiter, and gives the result out in order.  The limiter looks
 * ahead by holding back LOOK + a block + TAPS frames (AU_LIMITER_DELAY).
 * Per frame it estimates the true (inter-sample)
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
#define BLOCK 64      /* frames whose gain is skipped together when quiet */
/* frames the limiter holds back: a window, a block and the interpolator's reach */
#define AU_LIMITER_DELAY (LOOK + BLOCK + TAPS + 2)

/* ---- the meter: libebur128, fed in pieces ---- */

struct au_meter {
    ebur128_state *st;
    bool peak; /* the true peak measured too: most of libebur128's work */
};

static au_meter *meter_new(bool peak, rs_err *err)
{
    au_meter *m = calloc(1, sizeof *m);
    if (m) {
        m->peak = peak;
        m->st = ebur128_init(AU_CHANNELS, AU_RATE, EBUR128_MODE_I | EBUR128_MODE_LRA | (peak ? EBUR128_MODE_TRUE_PEAK : 0));
    }
    if (!m || !m->st) {
        free(m);
        rs_fail(err, AU_ERR_LOUDNESS, "loudness: libebur128 could not start (out of memory)");
        return NULL;
    }
    return m;
}

au_meter *au_meter_new(rs_err *err)
{
    return meter_new(true, err);
}

bool au_meter_add(au_meter *m, const float *pcm, size_t frames, rs_err *err)
{
    for (size_t at = 0; at < frames;) { /* its frame count is a size_t, its buffers are not */
        size_t n = frames - at < (size_t)AU_RATE * 10 ? frames - at : (size_t)AU_RATE * 10;
        if (ebur128_add_frames_float(m->st, pcm + 2 * at, n) != EBUR128_SUCCESS)
            return rs_fail(err, AU_ERR_LOUDNESS, "loudness: libebur128 failed to measure %zu frames", frames);
        at += n;
    }
    return true;
}

bool au_meter_result(au_meter *m, au_loudness *out, rs_err *err)
{
    double I = -HUGE_VAL, lra = 0, tp = 0;
    bool ok = true;
    for (unsigned c = 0; c < AU_CHANNELS && ok && m->peak; c++) {
        double p;
        ok = ebur128_true_peak(m->st, c, &p) == EBUR128_SUCCESS;
        tp = ok && p > tp ? p : tp;
    }
    ok = ok && ebur128_loudness_global(m->st, &I) == EBUR128_SUCCESS;
    ok = ok && ebur128_loudness_range(m->st, &lra) == EBUR128_SUCCESS;
    if (!ok)
        return rs_fail(err, AU_ERR_LOUDNESS, "loudness: libebur128 failed to measure the track");
    out->integrated = isfinite(I) ? I : -HUGE_VAL;
    out->range = isfinite(lra) ? lra : 0;
    out->true_peak = !m->peak ? NAN : tp > 0 ? 20 * log10(tp) : -HUGE_VAL;
    return true;
}

void au_meter_free(au_meter *m)
{
    if (m)
        ebur128_destroy(&m->st);
    free(m);
}

bool au_loud_measure(const float *pcm, size_t frames, au_loudness *out, rs_err *err)
{
    au_meter *m = au_meter_new(err);
    bool ok = m && au_meter_add(m, pcm, frames, err) && au_meter_result(m, out, err);
    au_meter_free(m);
    return ok;
}

/* ---- the limiter, streaming ---- */

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

#define RING 1024     /* the limiter's window on the track: > its delay + PIECE */
#define PIECE 256     /* frames taken in at a time */
#define AT(x) ((x) & (RING - 1))

typedef struct au_limiter au_limiter;
struct au_limiter {
    double h[OS * TAPS];
    double ceiling;
    size_t total; /* the track's length: its end changes the last frames' gain */
    size_t in;    /* frames taken in */
    size_t rdone; /* r[] (the gain each frame may have) known below this */
    size_t adone; /* r[] with the neighbours' step known below this */
    size_t out;   /* frames given out */
    float pcm[RING * 2], rraw[RING], radj[RING];
    size_t dq[RING], dqh, dqt; /* a window's minimum: indices of increasing radj */
    double mprev, sum;
    float ring[LOOK];
    bool any;
};

static au_limiter *au_limiter_new(size_t total, double ceiling)
{
    au_limiter *l = calloc(1, sizeof *l);
    if (!l)
        return NULL;
    make_fir(l->h);
    l->ceiling = ceiling;
    l->total = total;
    l->mprev = 1;
    l->sum = LOOK;
    for (size_t i = 0; i < LOOK; i++)
        l->ring[i] = 1; /* m' before the start: no limiting */
    return l;
}

static void au_limiter_free(au_limiter *l)
{
    free(l);
}

static bool au_limiter_any(const au_limiter *l)
{
    return l->any;
}

/* r[n] for the block b0..b1-1: the gain frame n may have, 1 where it is
 * under the ceiling.  Blocks far below the ceiling are skipped, with their
 * neighbours: an inter-sample peak is never 6 dB over the samples around it */
static void block_gain(au_limiter *l, size_t b0, size_t b1)
{
    size_t lo = b0 > TAPS ? b0 - TAPS : 0, hi = b1 + TAPS < l->total ? b1 + TAPS : l->total;
    float near = 0;
    for (size_t i = lo; i < hi; i++)
        for (int c = 0; c < 2; c++)
            near = fabsf(l->pcm[2 * AT(i) + c]) > near ? fabsf(l->pcm[2 * AT(i) + c]) : near;
    for (size_t n = b0; n < b1; n++)
        l->rraw[AT(n)] = 1;
    if (near < 0.5 * l->ceiling)
        return;
    for (size_t n = b0; n < b1; n++) {
        /* the interpolated points between frames n-1 and n+1 */
        double peak = 0;
        for (int c = 0; c < 2; c++) {
            for (int p = 0; p < OS; p++) {
                double y = 0;
                for (int k = 0; k < TAPS; k++) {
                    long j = (long)n - TAPS / 2 + 1 + k;
                    if (j >= 0 && (size_t)j < l->total)
                        y += l->h[OS * (TAPS - 1 - k) + p] * l->pcm[2 * AT((size_t)j) + c];
                }
                peak = fabs(y) > peak ? fabs(y) : peak;
            }
            double s = fabs(l->pcm[2 * AT(n) + c]);
            peak = s > peak ? s : peak;
        }
        l->rraw[AT(n)] = peak > l->ceiling ? (float)(l->ceiling / peak) : 1;
    }
}

/* Frame k out, its window's minimum m given: the release, the attack's mean */
static void give(au_limiter *l, size_t k, double m, float *out)
{
    double rise = l->mprev + 1.0 / RELEASE;
    m = m < rise ? m : rise;
    l->mprev = m;
    float mf = (float)m;
    l->sum += mf - l->ring[k % LOOK];
    l->ring[k % LOOK] = mf;
    if (k % 4096 == 4095) { /* the running sum drifts by roundings: recount */
        l->sum = 0;
        for (size_t i = 0; i < LOOK; i++)
            l->sum += l->ring[i];
    }
    float g = (float)(l->sum / LOOK), r = l->radj[AT(k)];
    g = g > r ? r : g; /* equal or less in exact arithmetic; a rounding must not cross it */
    out[2 * (k - l->out)] = l->pcm[2 * AT(k)] * g;
    out[2 * (k - l->out) + 1] = l->pcm[2 * AT(k) + 1] * g;
}

/* Everything the frames taken in allow; returns the frames written */
static size_t run(au_limiter *l, float *out)
{
    size_t first = l->out, k = first;
    while (l->rdone < l->total) {
        size_t b0 = l->rdone, b1 = b0 + BLOCK < l->total ? b0 + BLOCK : l->total;
        if (l->in < (b1 + TAPS < l->total ? b1 + TAPS : l->total))
            break;
        block_gain(l, b0, b1);
        l->rdone = b1;
    }
    /* an interpolated point lies between frames: both neighbours honour it */
    while (l->adone < l->rdone && (l->adone + 1 < l->rdone || l->rdone == l->total)) {
        size_t n = l->adone;
        float cur = l->rraw[AT(n)], prev = n > 0 ? l->rraw[AT(n - 1)] : 1, next = n + 1 < l->total ? l->rraw[AT(n + 1)] : 1;
        float m = cur < prev ? cur : prev;
        float a = m < next ? m : next;
        l->radj[AT(n)] = a;
        l->any |= a < 1;
        while (l->dqt > l->dqh && l->radj[AT(l->dq[AT(l->dqt - 1)])] >= a)
            l->dqt--;
        l->dq[AT(l->dqt++)] = n;
        l->adone = n + 1;
        /* m[k] = min(r[k .. k+LOOK-1]): k's window is complete */
        if (n + 1 >= LOOK) {
            size_t kk = n + 1 - LOOK;
            while (l->dq[AT(l->dqh)] < kk)
                l->dqh++;
            give(l, kk, l->radj[AT(l->dq[AT(l->dqh)])], out);
            k = kk + 1;
        }
        if (n + 1 == l->total) {
            /* the last frames: their windows run past the end, and (as the
             * block minimum this replaced had it) stop at the end of the
             * LOOK-aligned block that holds k */
            for (size_t t = l->total > LOOK - 1 ? l->total - LOOK + 1 : 0; t < l->total; t++) {
                size_t b = t - t % LOOK, e = b + LOOK < l->total ? b + LOOK : l->total;
                float mm = l->radj[AT(t)];
                for (size_t i = t + 1; i < e; i++)
                    mm = l->radj[AT(i)] < mm ? l->radj[AT(i)] : mm;
                give(l, t, mm, out);
                k = t + 1;
            }
        }
    }
    size_t n = k - first;
    l->out = k;
    return n;
}

static size_t au_limiter_push(au_limiter *l, const float *in, size_t n, float *out)
{
    size_t written = 0;
    for (size_t at = 0; at < n;) {
        size_t take = n - at < PIECE ? n - at : PIECE;
        if (take > l->total - l->in)
            take = l->total - l->in; /* past the length it was made for: dropped */
        if (!take)
            break;
        for (size_t i = 0; i < take; i++) {
            l->pcm[2 * AT(l->in + i)] = in[2 * (at + i)];
            l->pcm[2 * AT(l->in + i) + 1] = in[2 * (at + i) + 1];
        }
        l->in += take;
        at += take;
        written += run(l, out + 2 * written);
    }
    return written;
}

/* ---- normalization: the plan, then the stream ---- */

struct au_norm_stream {
    const au_source *src;
    au_norm plan;
    au_limiter *l;
    size_t taken;        /* source frames read */
    float *in, *held;    /* a piece of the source; the limiter's output not yet given */
    size_t nheld, at;    /* held frames, the next one to give */
};

#define SPIECE 1024

au_norm_stream *au_norm_stream_new(const au_source *src, const au_norm *plan, rs_err *err)
{
    au_norm_stream *s = calloc(1, sizeof *s);
    if (s) {
        s->in = malloc(SPIECE * 2 * sizeof *s->in);
        s->held = malloc((SPIECE + AU_LIMITER_DELAY) * 2 * sizeof *s->held);
    }
    if (!s || !s->in || !s->held) {
        au_norm_stream_free(s);
        rs_fail(err, AU_ERR_NOMEM, "loudness: out of memory");
        return NULL;
    }
    s->src = src;
    s->plan = *plan;
    if (!au_norm_stream_rewind(s, err)) {
        au_norm_stream_free(s);
        return NULL;
    }
    return s;
}

bool au_norm_stream_rewind(au_norm_stream *s, rs_err *err)
{
    au_limiter_free(s->l);
    s->l = NULL;
    s->taken = s->nheld = s->at = 0;
    if (s->plan.on && !(s->l = au_limiter_new(s->src->frames, s->plan.ceiling)))
        return rs_fail(err, AU_ERR_NOMEM, "loudness: out of memory");
    return s->src->rewind(s->src->u, err);
}

bool au_norm_stream_read(au_norm_stream *s, float *dst, size_t frames, rs_err *err)
{
    while (frames) {
        if (s->at == s->nheld) {
            size_t n = s->src->frames - s->taken < SPIECE ? s->src->frames - s->taken : SPIECE;
            if (!n)
                return rs_fail(err, AU_ERR_ARG, "loudness: read past the end of the track (%zu frames)", s->src->frames);
            if (!s->src->read(s->src->u, s->in, n, err))
                return false;
            s->taken += n;
            s->at = 0;
            if (s->plan.on) {
                for (size_t i = 0; i < 2 * n; i++)
                    s->in[i] *= s->plan.gain;
                s->nheld = au_limiter_push(s->l, s->in, n, s->held);
            } else {
                memcpy(s->held, s->in, n * 2 * sizeof *s->in);
                s->nheld = n;
            }
            continue;
        }
        size_t n = s->nheld - s->at < frames ? s->nheld - s->at : frames;
        memcpy(dst, s->held + 2 * s->at, n * 2 * sizeof *dst);
        s->at += n, dst += 2 * n, frames -= n;
    }
    return true;
}

void au_norm_stream_free(au_norm_stream *s)
{
    if (!s)
        return;
    au_limiter_free(s->l);
    free(s->in);
    free(s->held);
    free(s);
}

/* One read of the source from its start through the plan's gain and
 * limiter (the stream that gives the result) into the meter, with the
 * true peak or without (NAN); limited: the limiter had anything to do. */
static bool measure_pass(const au_source *src, const au_norm *p, bool peak, au_loudness *a, bool *limited, rs_err *err)
{
    float *buf = malloc(SPIECE * 2 * sizeof *buf);
    au_norm_stream *s = buf ? au_norm_stream_new(src, p, err) : NULL;
    au_meter *m = s ? meter_new(peak, err) : NULL;
    if (!buf)
        rs_fail(err, AU_ERR_NOMEM, "loudness: out of memory");
    bool ok = m != NULL;
    for (size_t at = 0; ok && at < src->frames;) {
        size_t n = src->frames - at < SPIECE ? src->frames - at : SPIECE;
        ok = au_norm_stream_read(s, buf, n, err) && au_meter_add(m, buf, n, err);
        at += n;
    }
    ok = ok && au_meter_result(m, a, err);
    if (ok && limited)
        *limited = s->l && au_limiter_any(s->l);
    au_meter_free(m);
    au_norm_stream_free(s);
    free(buf);
    return ok;
}

bool au_norm_plan(const au_source *src, double target_lufs, double peak_dbtp, au_norm *plan, rs_err *err)
{
    return au_norm_plan_peak(src, target_lufs, peak_dbtp, true, plan, err);
}

bool au_norm_plan_peak(const au_source *src, double target_lufs, double peak_dbtp, bool before_peak, au_norm *plan,
                       rs_err *err)
{
    memset(plan, 0, sizeof *plan);
    if (!isfinite(target_lufs) || target_lufs < -70 || target_lufs > 0 || !isfinite(peak_dbtp) || peak_dbtp > 0 ||
        peak_dbtp < -30)
        return rs_fail(err, AU_ERR_ARG, "loudness: target %.1f LUFS, ceiling %.1f dBTP (expected -70..0 and -30..0)",
                       target_lufs, peak_dbtp);
    au_loudness b, a;
    if (!measure_pass(src, &(au_norm){.on = false}, before_peak, &b, NULL, err))
        return false;
    plan->before = b;
    a = b;
    if (isfinite(b.integrated)) {
        double gain_db = target_lufs - b.integrated, ceiling_db = peak_dbtp - MARGIN_DB;
        for (int pass = 0; pass < 6; pass++) {
            float g = (float)pow(10.0, gain_db / 20.0);
            double c = pow(10.0, ceiling_db / 20.0);
            bool limited;
            if (!measure_pass(src, &(au_norm){.on = true, .gain = g, .ceiling = c}, true, &a, &limited, err))
                return false;
            plan->on = true, plan->gain = g, plan->ceiling = c;
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
        plan->gain_db = target_lufs - b.integrated;
    }
    plan->after = a;
    return true;
}

/* ---- a buffer normalized in place, through the same stream ---- */

typedef struct buf_src {
    const float *pcm;
    size_t at;
} buf_src;

static bool buf_read(void *u, float *dst, size_t frames, rs_err *err)
{
    (void)err;
    buf_src *b = u;
    memmove(dst, b->pcm + 2 * b->at, frames * 2 * sizeof *dst); /* in place: the output lags the input */
    b->at += frames;
    return true;
}

static bool buf_rewind(void *u, rs_err *err)
{
    (void)err;
    ((buf_src *)u)->at = 0;
    return true;
}

bool au_loud_normalize(float *pcm, size_t frames, double target_lufs, double peak_dbtp, au_loudness *before,
                       au_loudness *after, rs_err *err)
{
    buf_src b = {pcm, 0};
    au_source src = {buf_read, buf_rewind, &b, frames};
    au_norm plan;
    if (!au_norm_plan(&src, target_lufs, peak_dbtp, &plan, err))
        return false;
    if (before)
        *before = plan.before;
    if (after)
        *after = plan.after;
    if (!plan.on)
        return true;
    au_norm_stream *s = au_norm_stream_new(&src, &plan, err);
    if (!s)
        return false;
    /* the stream reads ahead of what it gives, so writing behind it is safe */
    bool ok = true;
    for (size_t at = 0; at < frames && ok;) {
        size_t n = frames - at < SPIECE ? frames - at : SPIECE;
        ok = au_norm_stream_read(s, pcm + 2 * at, n, err);
        at += n;
    }
    au_norm_stream_free(s);
    return ok;
}
