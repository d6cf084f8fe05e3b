/* The fog map's mist, CPU side (fx_fog_sim.h). */
#include "fx_fog_sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_game.h"

#define DT (1.0f / (float)G_HZ)

/* v when it is a positive number, else def; then clamped to [lo, hi]
 * (NaN fails v > 0: the default) */
static float pick(float v, float def, float lo, float hi)
{
    if (!(v > 0))
        v = def;
    return v < lo ? lo : v > hi ? hi : v;
}

void fx_fog_sim_defaults(fx_fog_sim_desc *d)
{
    d->count = d->count > 0 ? (d->count > R_FOG_MAX_PARTICLES ? R_FOG_MAX_PARTICLES : d->count) : 3000;
    d->half = pick(d->half, 12.0f, 1.0f, 100.0f);
    if (!d->seed)
        d->seed = 0x6d697374u;
    d->max_speed = pick(d->max_speed, 20.0f, 0.1f, 100.0f);
    if (d->calm)
        d->wind[0] = d->wind[1] = 0;
    else if (!(d->wind[0] != 0 || d->wind[1] != 0)) /* both 0 (or NaN): the default breeze */
        d->wind[0] = 0.5f, d->wind[1] = 0.12f;
    for (int k = 0; k < 2; k++) {
        float w = d->wind[k];
        d->wind[k] = !(w == w) ? 0 : w > d->max_speed ? d->max_speed : w < -d->max_speed ? -d->max_speed : w;
    }
    d->cut_speed = pick(d->cut_speed, 40.0f, d->max_speed, 1e6f);
    d->speed_threshold = pick(d->speed_threshold, 2.5f, 0.01f, 1000.0f);
    d->radius = pick(d->radius, 0.6f, 0.05f, 5.0f);
    d->gain = pick(d->gain, 0.6f, 0.0f, 10.0f);
    d->decay_s = pick(d->decay_s, 0.5f, 0.01f, 60.0f);
    d->cell = pick(d->cell, 0.25f, 0.05f, 4.0f);
    d->life_s = pick(d->life_s, 12.0f, 0.5f, 600.0f);
    d->fade_s = pick(d->fade_s, 1.0f, 0.0f, d->life_s / 3);
}

/* xorshift32: a private stream, the same on every machine */
static float rnd(uint32_t *s)
{
    uint32_t x = *s;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *s = x;
    return (float)(x >> 8) * (1.0f / 16777216.0f); /* [0, 1) */
}

/* Into [-h, h): the mist is a torus.  NaN stays NaN (the caller rebirths). */
static float wrap(float v, float h)
{
    if (v >= -h && v < h)
        return v;
    float w = 2 * h;
    v -= w * floorf((v + h) / w);
    if (v >= h || v < -h) /* rounding at the seam (or an infinite input: NaN, caught below) */
        v = v == v ? -h : v;
    return v;
}

static void born(fx_fog_sim *s, fx_fog_particle *p)
{
    float h = s->d.half;
    p->x = (rnd(&s->rng) * 2 - 1) * h;
    p->z = (rnd(&s->rng) * 2 - 1) * h;
    p->weight = 0.5f + rnd(&s->rng);
    p->life = s->d.life_s * (2.0f / 3 + rnd(&s->rng) * (2.0f / 3)); /* mean life_s */
    p->age = 0;
}

bool fx_fog_sim_init(fx_fog_sim *s, const fx_fog_sim_desc *d)
{
    memset(s, 0, sizeof *s);
    s->d = d ? *d : (fx_fog_sim_desc){0};
    fx_fog_sim_defaults(&s->d);
    int nc = (int)ceilf(2 * s->d.half / s->d.cell);
    s->ncell = nc < 4 ? 4 : nc > R_FOG_MAX_CELLS ? R_FOG_MAX_CELLS : nc;
    s->cell = 2 * s->d.half / (float)s->ncell;
    s->decay = expf(-DT / s->d.decay_s);
    s->n = s->d.count;
    s->p = calloc((size_t)s->n, sizeof *s->p);
    s->wind = calloc((size_t)s->ncell * (size_t)s->ncell, sizeof *s->wind);
    if (!s->p || !s->wind) {
        fx_fog_sim_free(s);
        return false;
    }
    fx_fog_sim_reset(s, 0);
    return true;
}

void fx_fog_sim_free(fx_fog_sim *s)
{
    free(s->p);
    free(s->wind);
    s->p = NULL, s->wind = NULL, s->n = 0;
}

void fx_fog_sim_reset(fx_fog_sim *s, uint64_t tick)
{
    s->rng = s->d.seed;
    s->tick = tick;
    memset(s->wind, 0, (size_t)s->ncell * (size_t)s->ncell * sizeof *s->wind);
    s->active = false;
    s->stirred = 0;
    /* the drift since tick 0, in double: tick x wind can be far larger
     * than the square, and float would lose the remainder */
    double span = 2.0 * s->d.half, secs = (double)tick / G_HZ;
    float shift[2];
    for (int k = 0; k < 2; k++)
        shift[k] = (float)fmod(s->d.wind[k] * secs, span);
    for (int i = 0; i < s->n; i++) {
        fx_fog_particle *p = &s->p[i];
        born(s, p);
        p->age = rnd(&s->rng) * p->life; /* staggered: the steady state, not a wave of births */
        p->x = wrap(p->x + shift[0], s->d.half);
        p->z = wrap(p->z + shift[1], s->d.half);
    }
}

/* The grid cell of index i (any integer) on the torus. */
static int cell_index(const fx_fog_sim *s, int i)
{
    i %= s->ncell;
    return i < 0 ? i + s->ncell : i;
}

int fx_fog_sim_stir(fx_fog_sim *s, const float (*cur)[3], const float (*prev)[3], int n)
{
    const fx_fog_sim_desc *d = &s->d;
    float R = d->radius, h = d->half;
    int reach = (int)ceilf(R / s->cell) + 1;
    if (reach > s->ncell / 2) /* never visit a cell twice round the torus */
        reach = s->ncell / 2;
    s->stirred = 0;
    for (int i = 0; i < n; i++) {
        /* the point's velocity over the last tick, in double so that no
         * finite input can overflow it; anything not finite is ignored */
        double v[3], sp = 0;
        bool ok = true;
        for (int a = 0; a < 3; a++) {
            ok = ok && isfinite(cur[i][a]) && isfinite(prev[i][a]);
            v[a] = ((double)cur[i][a] - (double)prev[i][a]) * G_HZ;
            sp += v[a] * v[a];
        }
        sp = sqrt(sp);
        if (!ok || !(sp > d->speed_threshold) || sp > d->cut_speed)
            continue;
        if (!(fabsf(cur[i][0]) <= h + R && fabsf(cur[i][2]) <= h + R)) /* outside the mist: no stirring */
            continue;
        /* it pushes along its horizontal motion, no faster than max_speed */
        double hs = sqrt(v[0] * v[0] + v[2] * v[2]), k = hs > d->max_speed ? d->max_speed / hs : 1.0;
        float vx = (float)(v[0] * k), vz = (float)(v[2] * k);
        float px = wrap(cur[i][0], h), pz = wrap(cur[i][2], h);
        int ci = (int)floorf((px + h) / s->cell), cj = (int)floorf((pz + h) / s->cell);
        for (int dj = -reach; dj <= reach; dj++)
            for (int di = -reach; di <= reach; di++) {
                /* distance to the cell's centre, unwrapped; the cell stored wrapped */
                float cx = -h + ((float)(ci + di) + 0.5f) * s->cell - px;
                float cz = -h + ((float)(cj + dj) + 0.5f) * s->cell - pz;
                float q = 1 - (cx * cx + cz * cz) / (R * R);
                if (!(q > 0))
                    continue;
                float w = q * q; /* smooth to zero at the radius */
                float *c = s->wind[(size_t)cell_index(s, cj + dj) * (size_t)s->ncell + (size_t)cell_index(s, ci + di)];
                c[0] += (vx - c[0]) * w; /* towards the limb's velocity: repeated passes never exceed it */
                c[1] += (vz - c[1]) * w;
            }
        s->stirred++;
        s->active = true;
    }
    return s->stirred;
}

void fx_fog_sim_wind_at(const fx_fog_sim *s, float x, float z, float out[2])
{
    out[0] = out[1] = 0;
    if (!s->active || !isfinite(x) || !isfinite(z))
        return;
    float gx = (wrap(x, s->d.half) + s->d.half) / s->cell - 0.5f;
    float gz = (wrap(z, s->d.half) + s->d.half) / s->cell - 0.5f;
    float fx0 = floorf(gx), fz0 = floorf(gz), tx = gx - fx0, tz = gz - fz0;
    int i0 = cell_index(s, (int)fx0), j0 = cell_index(s, (int)fz0);
    int i1 = cell_index(s, i0 + 1), j1 = cell_index(s, j0 + 1);
    const float *a = s->wind[(size_t)j0 * s->ncell + i0], *b = s->wind[(size_t)j0 * s->ncell + i1];
    const float *c = s->wind[(size_t)j1 * s->ncell + i0], *e = s->wind[(size_t)j1 * s->ncell + i1];
    for (int k = 0; k < 2; k++) {
        float lo = a[k] + (b[k] - a[k]) * tx, hi = c[k] + (e[k] - c[k]) * tx;
        out[k] = lo + (hi - lo) * tz;
    }
}

void fx_fog_sim_step(fx_fog_sim *s)
{
    const fx_fog_sim_desc *d = &s->d;
    /* the local wind dies down; once it is all but gone, the grid is
     * cleared and particles skip it until a limb stirs again */
    if (s->active) {
        float most = 0;
        size_t nc = (size_t)s->ncell * (size_t)s->ncell;
        for (size_t i = 0; i < nc; i++) {
            s->wind[i][0] *= s->decay, s->wind[i][1] *= s->decay;
            most = fmaxf(most, fmaxf(fabsf(s->wind[i][0]), fabsf(s->wind[i][1])));
        }
        if (most < 0.01f) { /* 1 cm/s: a sixth of a millimetre a tick */
            memset(s->wind, 0, nc * sizeof *s->wind);
            s->active = false;
        }
    }
    float vmax = d->max_speed;
    for (int i = 0; i < s->n; i++) {
        fx_fog_particle *p = &s->p[i];
        float w[2];
        fx_fog_sim_wind_at(s, p->x, p->z, w);
        float vx = d->wind[0] + d->gain * w[0], vz = d->wind[1] + d->gain * w[1];
        float sp = sqrtf(vx * vx + vz * vz);
        if (sp > vmax)
            vx *= vmax / sp, vz *= vmax / sp;
        p->x = wrap(p->x + vx * DT, d->half);
        p->z = wrap(p->z + vz * DT, d->half);
        p->age += DT;
        bool odd = !(p->x >= -d->half && p->x < d->half && p->z >= -d->half && p->z < d->half);
        if (odd || (!d->immortal && p->age >= p->life))
            born(s, p);
    }
    s->tick++;
}

static float smooth01(float t)
{
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

float fx_fog_sim_weight(const fx_fog_sim *s, const fx_fog_particle *p)
{
    if (s->d.immortal || !(s->d.fade_s > 0))
        return p->weight;
    float in = smooth01(p->age / s->d.fade_s), out = smooth01((p->life - p->age) / s->d.fade_s);
    return p->weight * (in < out ? in : out);
}
