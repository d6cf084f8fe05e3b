/* Water: the wave automaton on the CPU (fx_water_sim.h).  The formulas
 * here and in shaders/water_sim.frag, water_splat.frag must stay the same,
 * operation for operation (the build has no FMA contraction). */
#include "fx_water_sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../util/rs_progress.h"

#define PI_F 3.14159265f

static float pick(float v, float def, float lo, float hi)
{
    if (!(v == v) || v == 0) /* NaN or unset */
        return def;
    return v < lo ? lo : v > hi ? hi : v;
}

float fx_water_sim_courant_clamp(float c)
{
    /* above the cap the checkerboard mode grows every step: refuse it */
    return !(c > 0) ? 0.58f : c > R_WATER_COURANT_MAX ? R_WATER_COURANT_MAX : c < 0.01f ? 0.01f : c;
}

void fx_water_sim_params_fix(fx_water_sim_params *p)
{
    p->courant = fx_water_sim_courant_clamp(p->courant);
    p->damping = pick(p->damping, 0.985f, 0.5f, 1.0f);
    p->h_max = pick(p->h_max, 0.08f, 0.001f, 1.0f);
    p->gain = pick(p->gain, 0.0015f, 0.0f, 0.1f);
    p->amp_max = pick(p->amp_max, 0.012f, 0.0f, 0.1f);
    p->splash = pick(p->splash, 1.5f, 0.1f, 8.0f);
    p->size = pick(p->size, 8.0f, 0.1f, 1000.0f);
}

/* h' = damping * ((2 h - h_prev) + C^2 * laplacian), clamped; a NaN
 * becomes 0, so nothing that is not finite survives one step.  Selects,
 * not branches (fx_water_sim_flush, fx_water_sim_height), so a
 * vectorising build can vectorise the inner loop. */
static inline float cell(float c2, float damping, float h_max, float h, float hp, float l, float r, float d, float u)
{
    h = fx_water_sim_flush(h), hp = fx_water_sim_flush(hp);
    l = fx_water_sim_flush(l), r = fx_water_sim_flush(r), d = fx_water_sim_flush(d), u = fx_water_sim_flush(u);
    float lap = ((l + r) + (d + u)) - 4.0f * h;
    return fx_water_sim_height(damping * ((2.0f * h - hp) + c2 * lap), h_max);
}

void fx_water_sim_step_raw(float courant, float damping, float h_max, int n, const float *restrict src, float *restrict dst)
{
    const float c2 = courant * courant;
    for (int j = 0; j < n; j++) {
        const float *restrict row = src + (size_t)j * n * 2;
        const float *restrict down = src + (size_t)(j > 0 ? j - 1 : 0) * n * 2;
        const float *restrict up = src + (size_t)(j < n - 1 ? j + 1 : n - 1) * n * 2;
        float *restrict out = dst + (size_t)j * n * 2;
        /* the edge cells read themselves for the missing neighbour */
        for (int i = 0; i < n; i += i == 0 && n > 1 ? n - 1 : 1) { /* i = 0 and n - 1 */
            int il = i > 0 ? i - 1 : 0, ir = i < n - 1 ? i + 1 : n - 1;
            float h = row[2 * i];
            out[2 * i] = cell(c2, damping, h_max, h, row[2 * i + 1], row[2 * il], row[2 * ir], down[2 * i], up[2 * i]);
            out[2 * i + 1] = fx_water_sim_height(h, h_max); /* the shader's previous height: the input, made safe */
        }
        for (int i = 1; i < n - 1; i++) { /* the inner cells */
            float h = row[2 * i];
            out[2 * i] = cell(c2, damping, h_max, h, row[2 * i + 1], row[2 * i - 2], row[2 * i + 2], down[2 * i], up[2 * i]);
            out[2 * i + 1] = fx_water_sim_height(h, h_max);
        }
    }
}

void fx_water_sim_step(const fx_water_sim_params *p, int n, const float *src, float *dst)
{
    fx_water_sim_params q = *p;
    fx_water_sim_params_fix(&q);
    fx_water_sim_step_raw(q.courant, q.damping, q.h_max, n, src, dst);
}

/* ---- splats ---- */

float fx_water_sim_splat_weight(float d, float radius)
{
    return d < radius ? 0.5f + 0.5f * cosf(PI_F * d / radius) : 0.0f;
}

bool fx_water_sim_splat_for(const fx_water_sim_params *p, int n, float wx, float wz, float cap_radius, float depth, float speed,
                       fx_water_sim_splat *out)
{
    fx_water_sim_params q = *p;
    fx_water_sim_params_fix(&q);
    float cells = (float)n / q.size; /* grid units per metre */
    float x = (wx + q.size * 0.5f) * cells, y = (wz + q.size * 0.5f) * cells;
    if (!(x >= 0 && x < (float)n && y >= 0 && y < (float)n)) /* off the water (or NaN) */
        return false;
    float immersion = cap_radius > 0 ? depth / (2 * cap_radius) : 1.0f;
    immersion = immersion > 1 ? 1 : immersion;
    /* the original's rule: the wave's strength is proportional to the
     * speed of the part that hits the water */
    float amp = q.gain * speed * immersion;
    if (!(amp > 0) || !isfinite(amp))
        return false;
    amp = amp > q.amp_max ? q.amp_max : amp;
    float radius = q.splash * cap_radius * cells;
    radius = !(radius >= 1.0f) ? 1.0f : radius > 16.0f ? 16.0f : radius;
    *out = (fx_water_sim_splat){x, y, radius, -amp}; /* a dent: the part pushes the water away */
    return true;
}

void fx_water_sim_add_splat(int n, float *grid, const fx_water_sim_splat *s)
{
    /* the cells the shader's point sprite covers that lie within the radius */
    int i0 = (int)floorf(s->x - s->radius), i1 = (int)ceilf(s->x + s->radius);
    int j0 = (int)floorf(s->y - s->radius), j1 = (int)ceilf(s->y + s->radius);
    i0 = i0 < 0 ? 0 : i0, j0 = j0 < 0 ? 0 : j0;
    i1 = i1 > n - 1 ? n - 1 : i1, j1 = j1 > n - 1 ? n - 1 : j1;
    for (int j = j0; j <= j1; j++)
        for (int i = i0; i <= i1; i++) {
            float dx = ((float)i + 0.5f) - s->x, dy = ((float)j + 0.5f) - s->y;
            float d = sqrtf(dx * dx + dy * dy);
            if (d < s->radius)
                grid[((size_t)j * n + i) * 2] += fx_water_sim_flush(s->amp * fx_water_sim_splat_weight(d, s->radius));
        }
}

/* ---- energy and long runs ---- */

double fx_water_sim_energy(float courant, int n, const float *g)
{
    double kin = 0, pot = 0;
    for (int j = 0; j < n; j++) {
        const float *c = g + (size_t)j * n * 2, *next = j + 1 < n ? c + 2 * n : c; /* the last row: no pair upwards */
        float k = 0, p = 0; /* a row in float, the rows in double */
        for (int i = 0; i < n; i++) {
            float v = c[2 * i] - c[2 * i + 1], dy = next[2 * i] - c[2 * i];
            k += v * v;
            p += dy * dy;
        }
        for (int i = 0; i + 1 < n; i++) {
            float dx = c[2 * i + 2] - c[2 * i];
            p += dx * dx;
        }
        kin += k, pot += p;
    }
    double e = kin + (double)courant * courant * pot;
    return e == e ? e : INFINITY;
}

/* The forcing of a long run at step t: up to three contacts, in metres and
 * m/s, made the way r_fx_contacts makes them (speed from the positions one
 * tick apart). */
static int forcing(float size, long t, float pos[3][2], float speed[3])
{
    const float dt = 1.0f / 60.0f, tau = 6.2831853f;
    float p[3][2], q[3][2];
    for (int k = 0; k < 2; k++) {
        float s = (float)(t - k); /* now and one tick earlier */
        float (*o)[2] = k ? q : p;
        /* a foot sweeping sideways, 1.5 s period */
        o[0][0] = size * (-0.2f + 0.12f * sinf(tau * s / 90.0f)), o[0][1] = size * 0.05f;
        /* a foot circling, 2 s per turn */
        o[1][0] = size * (0.2f + 0.08f * cosf(tau * s / 120.0f)), o[1][1] = size * 0.08f * sinf(tau * s / 120.0f);
        /* a stamp: still, then 4 ticks straight down every 45 ticks */
        o[2][0] = size * 0.05f, o[2][1] = size * -0.2f;
    }
    int m = 0;
    for (int c = 0; c < 2; c++, m++) {
        pos[m][0] = p[c][0], pos[m][1] = p[c][1];
        float vx = (p[c][0] - q[c][0]) / dt, vz = (p[c][1] - q[c][1]) / dt;
        speed[m] = sqrtf(vx * vx + vz * vz);
    }
    if (t % 45 < 4) {
        pos[m][0] = p[2][0], pos[m][1] = p[2][1];
        speed[m++] = 3.0f;
    }
    return m;
}

bool fx_water_sim_forced_run(const fx_water_sim_params *p, bool raw, int n, long steps, long ref_steps, fx_water_sim_run *out)
{
    memset(out, 0, sizeof *out);
    fx_water_sim_params q = *p;
    if (!raw)
        fx_water_sim_params_fix(&q);
    else { /* the splat parameters still take their defaults; C and damping stay as given */
        fx_water_sim_params d = q;
        fx_water_sim_params_fix(&d);
        d.courant = q.courant, d.damping = q.damping;
        q = d;
    }
    float *a = calloc((size_t)n * n * 2, sizeof *a), *b = calloc((size_t)n * n * 2, sizeof *b);
    if (!a || !b) {
        free(a), free(b);
        return false;
    }
    out->finite = true;
    double t0 = rs_now();
    for (long t = 0; t < steps; t++) {
        fx_water_sim_step_raw(q.courant, q.damping, q.h_max, n, a, b);
        float pos[3][2], speed[3];
        int m = forcing(q.size, t, pos, speed);
        for (int k = 0; k < m; k++) {
            fx_water_sim_splat s;
            if (fx_water_sim_splat_for(&q, n, pos[k][0], pos[k][1], 0.06f, 0.12f, speed[k], &s))
                fx_water_sim_add_splat(n, b, &s);
        }
        float *tmp = a;
        a = b, b = tmp;
        if ((t + 1) % R_WATER_RUN_SAMPLE && t + 1 != ref_steps && t + 1 != steps)
            continue;
        double e = fx_water_sim_energy(q.courant, n, a);
        if (!isfinite(e))
            out->finite = false;
        if (e > out->e_max || !isfinite(e))
            out->e_max = e;
        if (t + 1 == ref_steps)
            out->e_ref = e;
        out->e_last = e;
    }
    out->ms = (rs_now() - t0) * 1000;
    for (size_t k = 0; k < (size_t)n * n * 2; k++) {
        if (!isfinite(a[k]))
            out->finite = false;
        else if (fabsf(a[k]) > out->h_absmax)
            out->h_absmax = fabsf(a[k]);
    }
    out->steps = steps;
    free(a), free(b);
    return true;
}

/* ---- bench accuracy ---- */

/* The largest |z| over the modes of the damped scheme: a mode whose
 * Laplacian eigenvalue is -s/C^2 (s in 0 .. 8 C^2) follows
 * z^2 - d (2 - s) z + d = 0. */
static double worst_growth(double c, double d)
{
    double worst = 0;
    for (int k = 0; k <= 1000; k++) {
        double s = 8 * c * c * k / 1000.0, b = d * (2 - s), disc = b * b - 4 * d;
        double z = disc < 0 ? sqrt(d) : (fabs(b) + sqrt(disc)) / 2;
        worst = z > worst ? z : worst;
    }
    return worst;
}

void fx_water_sim_accuracy_rows(FILE *out)
{
    static const struct {
        float c;
        bool raw;
    } rows[] = {{0.25f, false}, {0.5f, false}, {0.58f, false},   {0.6f, false},   {0.7f, false},
                {0.7071f, false}, {0.75f, false}, {0.7071f, true}, {0.75f, true}};
    enum { N = 64, STEPS = 100000, REF = 1000, TN = R_WATER_N, TSTEPS = 200 };
    fx_water_sim_params def = {0};
    fx_water_sim_params_fix(&def);
    /* the game's step: 256 x 256 on the CPU (the GPU does it in the game) */
    float *a = calloc((size_t)TN * TN * 2, sizeof *a), *b = calloc((size_t)TN * TN * 2, sizeof *b);
    double us = 0;
    if (a && b) {
        double t0 = rs_now();
        for (int t = 0; t < TSTEPS; t++) {
            fx_water_sim_step(&def, TN, a, b);
            float *tmp = a;
            a = b, b = tmp;
        }
        us = (rs_now() - t0) * 1e6 / TSTEPS;
    }
    free(a), free(b);
    fx_water_sim_params small = def;
    small.size = 2.0f; /* 64 cells over 2 m: splats a few cells wide, as in the game */
    fx_water_sim_run base;
    if (!fx_water_sim_forced_run(&small, false, N, STEPS, REF, &base))
        return;
    fprintf(out,
            "\nWater automaton (docs/effects.md, Water): Courant number C = c dt / dx against stability.  Damping %.3f;\n"
            "a %dx%d grid forced like the game (two sweeping feet and a stamp, splats every step), %d steps.\n"
            "margin = cap / C used (cap %.4f; the 2D CFL limit is 1/sqrt(2) = %.4f); growth = the worst mode's\n"
            "amplitude factor per step (analytic, < 1 decays); E max / E 1000 = the run's largest energy over its\n"
            "energy after %d steps (1: no growth); vs default = its largest energy over the default C's.\n"
            "One %dx%d step on the CPU: %.0f us (the game steps on the GPU).\n",
            def.damping, N, N, STEPS, R_WATER_COURANT_MAX, R_WATER_CFL, REF, TN, TN, us);
    fprintf(out, "%9s %8s %8s %10s %12s %12s %10s %7s\n", "C asked", "C used", "margin", "growth", "E max/E 1000",
            "vs default", "max |h| m", "finite");
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        fx_water_sim_params p = small;
        p.courant = rows[k].raw ? rows[k].c : fx_water_sim_courant_clamp(rows[k].c);
        fx_water_sim_run run;
        if (!fx_water_sim_forced_run(&p, rows[k].raw, N, STEPS, REF, &run))
            return;
        fprintf(out, "%9.4f %8.4f %8.4f %10.6f %12.3f %12.3g %10.4f %7s%s\n", rows[k].c, p.courant,
                R_WATER_COURANT_MAX / p.courant, worst_growth(p.courant, p.damping),
                run.e_ref > 0 ? run.e_max / run.e_ref : INFINITY, base.e_max > 0 ? run.e_max / base.e_max : INFINITY,
                run.h_absmax, run.finite ? "yes" : "NO",
                rows[k].raw ? "   cap bypassed" : p.courant == def.courant ? "   <- default" : "");
    }
}
