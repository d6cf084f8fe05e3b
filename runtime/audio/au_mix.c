/* The mixer: voices (sounds started by cues) + the stage's music + an
 * outside source (a movie's soundtrack), then a peak limiter.
 *
 * A mixer belongs to one thread (the caller's); the bank and the music
 * loops it reads are read-only after their first build.
 *
 * DESIGN: the limiter has no look-ahead, so a sound's first sample leaves
 * the mixer on the frame it was cued for (the A/V sync contract: a hit's
 * onset lies at tick * AU_TICK_FRAMES + offset) and live output gains no
 * latency.  It is an instant-attack, smooth-release peak limiter: the gain
 * drops at once to what keeps the frame under the ceiling and recovers
 * with an 80 ms time constant.  Levels in the bank keep it idle most of the
 * time; it is there for the pile-up (a KO: hit, body fall, crowd, voice).
 * The offline loudness stage (au_loud.c) does the true-peak limiting with
 * look-ahead on a finished track. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "au_local.h"

#define AU_VOICES 48
#define CEILING 0.8912509f          /* -1 dBFS */
#define RELEASE_SEC 0.08
#define MUSIC_DEFAULT 1.0f

typedef struct voice {
    const au_sound *s; /* NULL: free */
    size_t pos;        /* next sample of s */
    uint64_t delay;    /* frames before it starts, from the next block */
    float gain, gl, gr;
    uint64_t seq;      /* start order: the oldest has the smallest */
} voice;

struct au_mixer {
    au_mix_opts o;
    float music_gain;
    int stage;
    const au_loop *music;
    uint64_t pos, seq;
    float lim_gain, release;
    voice v[AU_VOICES];
};

au_mixer *au_mixer_new(const au_mix_opts *opts, rs_err *err)
{
    au_mixer *m = calloc(1, sizeof *m);
    if (!m) {
        rs_fail(err, AU_ERR_NOMEM, "audio mixer: out of memory");
        return NULL;
    }
    if (opts)
        m->o = *opts;
    if (!(m->o.master > 0) || !isfinite(m->o.master))
        m->o.master = 1;
    m->music_gain = m->o.music < 0 ? 0 : m->o.music > 0 && isfinite(m->o.music) ? m->o.music : MUSIC_DEFAULT;
    m->stage = -1;
    m->lim_gain = 1;
    m->release = (float)(1.0 - exp(-1.0 / (RELEASE_SEC * AU_RATE)));
    return m;
}

void au_mixer_music(au_mixer *m, int stage)
{
    if (stage == m->stage)
        return;
    m->stage = stage;
    m->music = m->music_gain > 0 ? au_music_loop(stage) : NULL;
}

void au_mixer_cue(au_mixer *m, const au_cue *c)
{
    const au_sound *s = au_bank_get(c->sound);
    if (!s || !s->frames || !(c->gain > 0) || !isfinite(c->gain))
        return;
    voice *v = NULL;
    for (int i = 0; i < AU_VOICES && !v; i++)
        if (!m->v[i].s)
            v = &m->v[i];
    if (!v) { /* all busy: the quietest goes, the oldest of equals */
        v = &m->v[0];
        for (int i = 1; i < AU_VOICES; i++)
            if (m->v[i].gain < v->gain || (m->v[i].gain == v->gain && m->v[i].seq < v->seq))
                v = &m->v[i];
    }
    float pan = isfinite(c->pan) ? (c->pan < -1 ? -1 : c->pan > 1 ? 1 : c->pan) : 0;
    double th = (pan + 1) * (AU_PI / 4); /* equal power: gl^2 + gr^2 = 1 */
    v->s = s;
    v->pos = 0;
    v->delay = c->offset > 0 ? (uint64_t)c->offset : 0;
    v->gain = c->gain;
    v->gl = (float)(c->gain * cos(th));
    v->gr = (float)(c->gain * sin(th));
    v->seq = m->seq++;
}

static void mix_voice(voice *v, float *out, int frames)
{
    if (v->delay >= (uint64_t)frames) {
        v->delay -= (uint64_t)frames;
        return;
    }
    int start = (int)v->delay;
    v->delay = 0;
    size_t left = v->s->frames - v->pos, n = (size_t)(frames - start);
    if (n > left)
        n = left;
    const float *s = v->s->samples + v->pos;
    float *o = out + 2 * start;
    for (size_t i = 0; i < n; i++) {
        o[2 * i] += s[i] * v->gl;
        o[2 * i + 1] += s[i] * v->gr;
    }
    v->pos += n;
    if (v->pos >= v->s->frames)
        v->s = NULL;
}

void au_mixer_mix(au_mixer *m, float *out, int frames, const float *ext, float ext_gain)
{
    if (frames <= 0)
        return;
    memset(out, 0, (size_t)frames * 2 * sizeof *out);
    for (int i = 0; i < AU_VOICES; i++)
        if (m->v[i].s)
            mix_voice(&m->v[i], out, frames);
    if (m->music) {
        const float *l = m->music->pcm;
        size_t len = m->music->frames, at = (size_t)(m->pos % len);
        for (int i = 0; i < frames; i++) {
            out[2 * i] += l[2 * at] * m->music_gain;
            out[2 * i + 1] += l[2 * at + 1] * m->music_gain;
            if (++at == len)
                at = 0;
        }
    }
    if (ext && ext_gain > 0 && isfinite(ext_gain))
        for (int i = 0; i < 2 * frames; i++)
            out[i] += isfinite(ext[i]) ? ext[i] * ext_gain : 0;
    float master = m->o.master, g = m->lim_gain;
    for (int i = 0; i < frames; i++) {
        float l = out[2 * i] * master, r = out[2 * i + 1] * master;
        if (!m->o.no_limiter) {
            float peak = fabsf(l) > fabsf(r) ? fabsf(l) : fabsf(r);
            float want = peak > CEILING ? CEILING / peak : 1;
            g = want < g ? want : g + (want - g) * m->release;
            l *= g;
            r *= g;
            /* the gain is exact to a rounding; the clamp makes it a promise */
            l = l > CEILING ? CEILING : l < -CEILING ? -CEILING : l;
            r = r > CEILING ? CEILING : r < -CEILING ? -CEILING : r;
        }
        out[2 * i] = l;
        out[2 * i + 1] = r;
    }
    m->lim_gain = g;
    m->pos += (uint64_t)frames;
}

uint64_t au_mixer_pos(const au_mixer *m)
{
    return m->pos;
}

int au_mixer_voices(const au_mixer *m)
{
    int n = 0;
    for (int i = 0; i < AU_VOICES; i++)
        n += m->v[i].s != NULL;
    return n;
}

void au_mixer_reset(au_mixer *m)
{
    memset(m->v, 0, sizeof m->v);
    m->pos = 0;
    m->seq = 0;
    m->lim_gain = 1;
}

void au_mixer_free(au_mixer *m)
{
    free(m);
}
