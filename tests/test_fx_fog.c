/* The fog map (docs/effects.md, "Fog map"): runtime/fx/fx_fog_sim.c (the mist,
 * pure C) and fx_fog.c with shaders/fog_*.glsl (the map and the scene's
 * height fog), on llvmpipe.
 *
 * The GL cases draw the dojo demo's state with the mistvale look
 * (stages/mistvale.stage, fog = yes).  To look at what they drew, set
 * T_FOG_DUMP=DIR: the fog maps go there as PGM, the frames as PPM. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/game/g_game.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/fx/fx_fog.h"
#include "../runtime/fx/fx_fog_sim.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_stage.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_img.h"
#include "t.h"
#include "t_render.h"

/* ---- the simulation (no GL) ---- */

/* A limb point sweeping along x through the middle, back and forth at speed m/s. */
static void sweep(int t, float speed, float cur[3], float prev[3])
{
    float step = speed / G_HZ, x = -1.5f + step * (float)(t % 40);
    cur[0] = x, cur[1] = 0.8f, cur[2] = 0.1f;
    prev[0] = x - step, prev[1] = 0.8f, prev[2] = 0.1f;
}

static void run_sim(fx_fog_sim *s, int ticks, float speed)
{
    for (int t = 0; t < ticks; t++) {
        float cur[1][3], prev[1][3];
        sweep(t, speed, cur[0], prev[0]);
        fx_fog_sim_stir(s, cur, prev, 1);
        fx_fog_sim_step(s);
    }
}

static void t_sim_deterministic(void)
{
    fx_fog_sim a, b, c;
    T_ASSERT(fx_fog_sim_init(&a, NULL) && fx_fog_sim_init(&b, NULL));
    T_EQ(a.n, 3000);
    run_sim(&a, 900, 6.0f);
    run_sim(&b, 900, 6.0f);
    T_ASSERTF(!memcmp(a.p, b.p, (size_t)a.n * sizeof *a.p), "two runs differ");
    T_ASSERTF(!memcmp(a.wind, b.wind, (size_t)a.ncell * a.ncell * sizeof *a.wind), "local wind differs");
    T_EQ(a.tick, 900);
    /* a reset is a restart: the same bits again */
    fx_fog_sim_reset(&b, 0);
    run_sim(&b, 900, 6.0f);
    T_ASSERT(!memcmp(a.p, b.p, (size_t)a.n * sizeof *a.p));
    /* and another seed is another mist */
    T_ASSERT(fx_fog_sim_init(&c, &(fx_fog_sim_desc){.seed = 7}));
    run_sim(&c, 900, 6.0f);
    T_ASSERT(memcmp(a.p, c.p, (size_t)a.n * sizeof *a.p) != 0);
    fx_fog_sim_free(&a), fx_fog_sim_free(&b), fx_fog_sim_free(&c);
}

static void check_inside(const fx_fog_sim *s, const char *what)
{
    float h = s->d.half;
    for (int i = 0; i < s->n; i++) {
        const fx_fog_particle *p = &s->p[i];
        T_ASSERTF(p->x >= -h && p->x < h && p->z >= -h && p->z < h, "%s: particle %d at %g, %g", what, i, p->x, p->z);
        float w = fx_fog_sim_weight(s, p);
        T_ASSERTF(isfinite(w) && w >= 0 && w <= 1.5f, "%s: particle %d weighs %g", what, i, w);
    }
    for (int k = 0; k < s->ncell * s->ncell; k++)
        for (int a = 0; a < 2; a++)
            T_ASSERTF(isfinite(s->wind[k][a]) && fabsf(s->wind[k][a]) <= s->d.max_speed * 1.0001f, "%s: local wind %g",
                      what, s->wind[k][a]);
}

static void t_sim_stays_inside(void)
{
    fx_fog_sim s;
    /* a gale across a corner, limbs stirring, particles dying and born */
    T_ASSERT(fx_fog_sim_init(&s, &(fx_fog_sim_desc){.wind = {9.0f, -14.0f}, .life_s = 2}));
    for (int k = 0; k < 10; k++) {
        run_sim(&s, 200, 12.0f);
        check_inside(&s, "gale");
    }
    fx_fog_sim_free(&s);
}

/* The minimal-image displacement on the torus. */
static float torus_d(float a, float b, float h)
{
    float d = a - b;
    return d > h ? d - 2 * h : d < -h ? d + 2 * h : d;
}

static void t_sim_wind_moves_the_mist(void)
{
    fx_fog_sim s;
    const float wind[2] = {0.8f, -0.3f};
    T_ASSERT(fx_fog_sim_init(&s, &(fx_fog_sim_desc){.wind = {wind[0], wind[1]}, .immortal = true}));
    fx_fog_particle *start = malloc((size_t)s.n * sizeof *start);
    T_ASSERT(start);
    memcpy(start, s.p, (size_t)s.n * sizeof *start);
    const int ticks = 3 * G_HZ;
    for (int t = 0; t < ticks; t++)
        fx_fog_sim_step(&s);
    /* the mass centre (unwrapped) moved downwind by wind x 3 s */
    double mx = 0, mz = 0;
    for (int i = 0; i < s.n; i++)
        mx += torus_d(s.p[i].x, start[i].x, s.d.half), mz += torus_d(s.p[i].z, start[i].z, s.d.half);
    mx /= s.n, mz /= s.n;
    fprintf(stderr, "    mass centre moved %.5f, %.5f m in 3 s (wind %.2f, %.2f m/s)\n", mx, mz, wind[0], wind[1]);
    T_ASSERTF(fabs(mx - wind[0] * 3) < 1e-3 && fabs(mz - wind[1] * 3) < 1e-3, "moved %.5f, %.5f", mx, mz);
    /* the default breeze blows too, and a reset at tick T finds the mist
     * drifted as far as T ticks of it take it */
    fx_fog_sim d;
    T_ASSERT(fx_fog_sim_init(&d, &(fx_fog_sim_desc){.immortal = true}));
    T_ASSERT(d.d.wind[0] > 0);
    memcpy(start, d.p, (size_t)d.n * sizeof *start);
    fx_fog_sim_reset(&d, 600);
    for (int i = 0; i < d.n; i++)
        T_ASSERTF(fabsf(torus_d(d.p[i].x, start[i].x, d.d.half) - d.d.wind[0] * 10) < 1e-3f, "reset at 600: %g",
                  torus_d(d.p[i].x, start[i].x, d.d.half));
    free(start);
    fx_fog_sim_free(&s), fx_fog_sim_free(&d);
}

/* A cloud of particles round the origin; a limb point crosses it along +x. */
static void cloud(fx_fog_sim *s)
{
    uint32_t q = 12345;
    for (int i = 0; i < s->n; i++) {
        q = q * 1664525u + 1013904223u;
        float a = (float)(q >> 8) / 16777216.0f * 6.2831853f;
        q = q * 1664525u + 1013904223u;
        float r = 0.5f * sqrtf((float)(q >> 8) / 16777216.0f);
        s->p[i].x = r * cosf(a), s->p[i].z = r * sinf(a);
    }
}

/* Mean x and |z| displacement of the cloud after a limb crossed it at speed. */
static int cross_cloud(float speed, double *dx, double *dz, int *backwards, bool *moved)
{
    fx_fog_sim s;
    T_ASSERT(fx_fog_sim_init(&s, &(fx_fog_sim_desc){.count = 400, .calm = true, .immortal = true}));
    cloud(&s);
    fx_fog_particle *start = malloc((size_t)s.n * sizeof *start);
    T_ASSERT(start);
    memcpy(start, s.p, (size_t)s.n * sizeof *start);
    int stirred = 0;
    float step = speed / G_HZ;
    for (float x = -1.0f; x < 1.0f; x += step) { /* at the height of a knee, on the fight plane */
        float cur[1][3] = {{x + step, 0.5f, 0}}, prev[1][3] = {{x, 0.5f, 0}};
        stirred += fx_fog_sim_stir(&s, cur, prev, 1);
        fx_fog_sim_step(&s);
    }
    for (int t = 0; t < 4 * G_HZ; t++) /* the wind it left dies down */
        fx_fog_sim_step(&s);
    T_ASSERTF(!s.active, "the local wind still blows 4 s later");
    *dx = *dz = 0, *backwards = 0, *moved = false;
    for (int i = 0; i < s.n; i++) {
        *dx += s.p[i].x - start[i].x;
        *dz += fabsf(s.p[i].z - start[i].z);
        *backwards += s.p[i].x < start[i].x;
        *moved |= s.p[i].x != start[i].x || s.p[i].z != start[i].z;
    }
    *dx /= s.n, *dz /= s.n;
    free(start);
    fx_fog_sim_free(&s);
    return stirred;
}

static void t_sim_fast_limb_pushes_the_mist(void)
{
    double dx, dz;
    int back;
    bool moved;
    int stirred = cross_cloud(6.0f, &dx, &dz, &back, &moved);
    fprintf(stderr, "    a limb at 6 m/s: %d stirring ticks, the cloud moved %.3f m along, %.4f m across\n", stirred, dx,
            dz);
    T_ASSERT(stirred > 0);
    T_ASSERTF(dx > 0.3, "the cloud moved only %.3f m along the limb's motion", dx);
    T_ASSERTF(dz < 0.01 * dx, "the cloud moved %.4f m across (along: %.3f)", dz, dx);
    T_EQ(back, 0);
    /* below the threshold (2.5 m/s): nothing at all */
    stirred = cross_cloud(1.5f, &dx, &dz, &back, &moved);
    fprintf(stderr, "    a limb at 1.5 m/s: %d stirring ticks\n", stirred);
    T_EQ(stirred, 0);
    T_ASSERTF(!moved, "a slow limb moved the mist (%.4f m)", dx);
}

static void t_sim_extremes_stay_finite(void)
{
    /* parameters from a fuzzer: defaults or clamps, never NaN */
    fx_fog_sim s;
    T_ASSERT(fx_fog_sim_init(&s, &(fx_fog_sim_desc){.count = -5, .half = INFINITY, .wind = {NAN, 1e30f},
                                                  .speed_threshold = NAN, .radius = 1e9f, .gain = INFINITY,
                                                  .decay_s = -1, .max_speed = NAN, .cell = 1e-9f, .life_s = NAN,
                                                  .fade_s = INFINITY}));
    T_ASSERT(s.n == 3000 && isfinite(s.d.half) && isfinite(s.d.wind[0]) && isfinite(s.d.wind[1]));
    T_ASSERT(s.ncell >= 4 && s.ncell <= R_FOG_MAX_CELLS);
    /* limb points: NaN from a corrupted state, infinities, jumps across
     * the world (a cut, ignored), a point inside the mist at 1e4 m/s (a
     * cut too) and one at 35 m/s (a motion, clamped to 20 m/s) */
    const float big = 1e30f, v35 = 35.0f / G_HZ;
    float cur[7][3] = {{NAN, 1, 0}, {0, INFINITY, 0}, {big, 1, -big}, {0, 1, 0}, {-big, big, big}, {0.5f, NAN, 0.5f},
                       {0.2f, 1, 0}};
    float prev[7][3] = {{0, 1, 0}, {0, 0, 0}, {-big, 1, big}, {-big, 1, 0}, {big, -big, -big}, {0.5f, 1, 0.5f},
                        {0.2f - v35, 1, 0}};
    for (int t = 0; t < 600; t++) {
        int n = fx_fog_sim_stir(&s, cur, prev, 7);
        T_ASSERTF(n == 1, "tick %d: %d points stirred (only the one at 35 m/s may)", t, n);
        fx_fog_sim_step(&s);
    }
    cur[6][0] = 0.2f + 1e4f / G_HZ; /* 1e4 m/s: a cut */
    T_EQ(fx_fog_sim_stir(&s, cur, prev, 7), 0);
    check_inside(&s, "extreme inputs");
    float w[2];
    fx_fog_sim_wind_at(&s, NAN, INFINITY, w);
    T_ASSERT(w[0] == 0 && w[1] == 0);
    fx_fog_sim_wind_at(&s, 0.1f, 0.1f, w);
    T_ASSERTF(isfinite(w[0]) && w[0] > 0.5f * s.d.max_speed && w[0] <= s.d.max_speed, "local wind %g after a 35 m/s limb",
              w[0]);
    /* a particle put somewhere impossible is born again inside */
    s.p[0].x = NAN, s.p[1].z = INFINITY, s.p[2].x = -1e30f;
    fx_fog_sim_step(&s);
    check_inside(&s, "after NaN particles");
    fx_fog_sim_free(&s);
}

/* ---- GL ---- */

enum { W = 320, H = 180 };

static r_game *game_new(const r_stage *st)
{
    rs_err e = {0};
    r_game *r = t_game_new(false);
    if (st)
        T_ASSERTF(r_game_set_stage(r, st, &e), "%s", e.msg);
    return r;
}

static r_stage mistvale(void)
{
    r_stage st;
    rs_err e = {0};
    T_ASSERTF(r_stage_load(&st, RS_SOURCE_DIR "/stages/mistvale.stage", &e), "%s", e.msg);
    T_ASSERT(st.fog);
    return st;
}

static float *read_map(r_game *r, int *n, float *half)
{
    T_ASSERT(fx_fog_read_map(r, NULL, n, half));
    float *m = malloc((size_t)*n * *n * sizeof *m);
    T_ASSERT(m);
    T_ASSERT(fx_fog_read_map(r, m, n, half));
    return m;
}

static void dump_map(const char *name, const float *m, int n, float scale)
{
    const char *dir = getenv("T_FOG_DUMP");
    if (!dir || !*dir)
        return;
    uint8_t *g = malloc((size_t)n * n);
    T_ASSERT(g);
    for (int j = 0; j < n; j++) /* z towards the camera: down the image */
        for (int i = 0; i < n; i++) {
            float v = m[(size_t)j * n + i] * scale;
            g[(size_t)j * n + i] = (uint8_t)(v > 255 ? 255 : v < 0 ? 0 : v);
        }
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.pgm", dir, name);
    rs_err e = {0};
    if (!rs_pnm_write(path, n, n, 1, g, &e))
        fprintf(stderr, "    %s\n", e.msg);
    free(g);
}

static void dump_frame(const char *name, const uint8_t *rgba)
{
    const char *dir = getenv("T_FOG_DUMP");
    if (!dir || !*dir)
        return;
    static uint8_t rgb[W * H * 3];
    for (int i = 0; i < W * H; i++)
        memcpy(rgb + 3 * i, rgba + 4 * i, 3);
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.ppm", dir, name);
    rs_err e = {0};
    if (!rs_pnm_write(path, W, H, 3, rgb, &e))
        fprintf(stderr, "    %s\n", e.msg);
}

/* Replaces the mist with these particles (full weight, mid-life) and
 * draws the same tick again: no step, so the map holds exactly them. */
static void place(r_game *r, t_fb *f, const g_state *prev, const g_state *cur, const float (*xz)[2], int n)
{
    fx_fog_sim *s = fx_fog_get_sim(r);
    T_ASSERT(s && n <= s->d.count);
    s->n = n;
    for (int i = 0; i < n; i++)
        s->p[i] = (fx_fog_particle){xz[i][0], xz[i][1], 1.0f, 5.0f, 10.0f};
    t_draw_read(r, f, prev, cur, W, H, NULL, true);
}

/* Mistvale's look over dojo's tick 900, drawn once into a new f: the
 * seeded mist's map. */
static r_game *seeded_mist(t_fb *f, g_state *prev, g_state *cur)
{
    t_state_at("dojo", 900, prev, cur);
    r_stage st = mistvale();
    r_game *r = game_new(&st);
    t_fb_make(f, W, H);
    t_draw_read(r, f, prev, cur, W, H, NULL, true);
    T_ASSERT(t_pass_ran(r, "fog_map"));
    return r;
}

/* The map is the particles' sprites: the right height where each is,
 * exactly zero beyond their reach, wrapping round the edge, mean 1. */
static void t_map_is_where_particles_are(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    t_fb f;
    r_game *r = seeded_mist(&f, &prev, &cur);
    int n;
    float h;
    float *m = read_map(r, &n, &h);
    T_EQ(n, 128);
    dump_map("map_mistvale", m, n, 100);
    free(m);
    /* three particles at texel centres, the last one across the +x edge */
    float texel = 2 * h / n, R = 1.0f;
    const int at[3][2] = {{40, 60}, {90, 30}, {126, 100}};
    float xz[3][2];
    for (int k = 0; k < 3; k++)
        xz[k][0] = -h + ((float)at[k][0] + 0.5f) * texel, xz[k][1] = -h + ((float)at[k][1] + 0.5f) * texel;
    place(r, &f, &prev, &cur, xz, 3);
    m = read_map(r, &n, &h);
    dump_map("map_three", m, n, 1);
    float peak = 4 * h * h * 3 / (3.14159265f * R * R * 3); /* mean 1 over the map */
    double sum = 0;
    int lit = 0, stray = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            float v = m[(size_t)j * n + i];
            T_ASSERT(isfinite(v) && v >= 0);
            sum += v;
            /* the distance to the nearest particle, round the torus */
            float cx = -h + ((float)i + 0.5f) * texel, cz = -h + ((float)j + 0.5f) * texel, best = 1e9f;
            for (int k = 0; k < 3; k++) {
                float dx = fabsf(cx - xz[k][0]), dz = fabsf(cz - xz[k][1]);
                dx = fminf(dx, 2 * h - dx), dz = fminf(dz, 2 * h - dz);
                best = fminf(best, sqrtf(dx * dx + dz * dz));
            }
            if (best > R + 0.01f)
                stray += v != 0;
            else if (best < 0.8f * R)
                lit += v > 0;
        }
    for (int k = 0; k < 3; k++) {
        float v = m[(size_t)at[k][1] * n + at[k][0]];
        T_ASSERTF(fabsf(v - peak) < 0.01f * peak, "particle %d: %.2f where it is, want %.2f", k, v, peak);
    }
    /* the one at the +x edge shows on the -x side too */
    T_ASSERTF(m[(size_t)100 * n + 1] > 0.3f * peak, "no wrapped sprite at the -x edge (%.2f)", m[(size_t)100 * n + 1]);
    T_EQ(stray, 0);
    T_ASSERTF(lit > 3 * 50, "only %d texels lit near the particles", lit); /* ~57 each within 0.8 R */
    double mean = sum / ((double)n * n);
    fprintf(stderr, "    peak %.2f (want %.2f), mean %.4f, %d texels lit\n", m[(size_t)60 * n + 40], peak, mean, lit);
    T_ASSERTF(fabs(mean - 1) < 0.02, "the map's mean is %.4f, want 1", mean);
    free(m);
    /* no particles: an empty map, and the scene as without fog */
    place(r, &f, &prev, &cur, xz, 0);
    m = read_map(r, &n, &h);
    for (int k = 0; k < n * n; k++)
        T_ASSERTF(m[k] == 0, "texel %d = %g with no particles", k, m[k]);
    free(m);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* The largest difference between two maps, relative to max(1, |b|), and
 * (mean) the mean of that difference. */
static double map_diff(const float *a, const float *b, int n, int *at, double *mean)
{
    double worst = 0, sum = 0;
    for (int k = 0; k < n * n; k++) {
        double d = fabs((double)a[k] - b[k]) / fmax(1.0, fabs((double)b[k]));
        d = isfinite(d) ? d : 1e30;
        sum += d;
        if (d > worst)
            worst = d, *at = k;
    }
    *mean = sum / ((double)n * n);
    return worst;
}

/* On a software rasteriser the map is summed on the CPU (splat_cpu) in
 * place of the sprites: the same map as the sprites give within half
 * float's rounding (the blend rounds every sum to fp16: a texel under a
 * dozen sprites of about 1 gathers a dozen roundings of up to 1e-3; the
 * seeded mist measured 2.7e-3 mean, 8.4e-3 largest), for the seeded
 * mist and for sprites across an edge, in a corner (copies both ways)
 * and beyond the map (|x| up to 2 half), and a pile of them. */
#define MAP_MAX_DIFF 2e-2
#define MAP_MEAN_DIFF 5e-3
static void t_map_cpu_matches_sprites(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    t_fb f;
    r_game *r = seeded_mist(&f, &prev, &cur);
    int n, at = 0;
    float h;
    float *def = read_map(r, &n, &h);
    T_ASSERT(fx_fog_set_cpu(r, true));
    t_draw_read(r, &f, &prev, &cur, W, H, NULL, true);
    float *cpu = read_map(r, &n, &h);
    T_ASSERTF(!memcmp(def, cpu, (size_t)n * n * sizeof *def), "llvmpipe's default is not the CPU's map");
    T_ASSERT(fx_fog_set_cpu(r, false));
    t_draw_read(r, &f, &prev, &cur, W, H, NULL, true);
    float *gl_map = read_map(r, &n, &h);
    double mean, d = map_diff(cpu, gl_map, n, &at, &mean);
    fprintf(stderr, "    seeded mist: difference %.2e mean, %.2e largest (texel %d: %.4f cpu, %.4f sprites)\n", mean, d,
            at, cpu[at], gl_map[at]);
    T_ASSERTF(d < MAP_MAX_DIFF && mean < MAP_MEAN_DIFF, "the CPU's map is %.2e (mean %.2e) from the sprites' at texel %d (%.4f against %.4f)", d,
              mean, at, cpu[at], gl_map[at]);
    free(def), free(cpu), free(gl_map);
    /* edges, a corner, beyond the map, and a pile of ten at one place */
    float xz[16][2] = {{h - 0.3f, 0.0f}, {-h + 0.1f, 3.0f}, {h - 0.2f, -h + 0.4f}, {1.5f * h, -2.0f}, {0.0f, -1.9f * h},
                       {2.5f, 2.5f}};
    for (int k = 6; k < 16; k++)
        xz[k][0] = -4.0f + 0.01f * (float)k, xz[k][1] = 5.0f;
    float *maps[2];
    for (int c = 0; c < 2; c++) {
        T_ASSERT(fx_fog_set_cpu(r, c == 0));
        place(r, &f, &prev, &cur, xz, 16);
        maps[c] = read_map(r, &n, &h);
    }
    d = map_diff(maps[0], maps[1], n, &at, &mean);
    fprintf(stderr, "    placed sprites: difference %.2e mean, %.2e largest (texel %d: %.4f cpu, %.4f sprites)\n", mean,
            d, at, maps[0][at], maps[1][at]);
    T_ASSERTF(d < MAP_MAX_DIFF && mean < MAP_MEAN_DIFF, "the CPU's map is %.2e (mean %.2e) from the sprites' at texel %d (%.4f against %.4f)", d,
              mean, at, maps[0][at], maps[1][at]);
    free(maps[0]), free(maps[1]);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* A video of a replay is reproducible: two renderers drawing the same
 * ticks of the demo get the same map, bit for bit, whether or not a tick
 * is drawn twice (steps 0); and the fighters' fast limbs do stir it. */
static void t_map_follows_the_game(void)
{
    plat *p = t_context("egl");
    r_stage st = mistvale();
    t_fb f;
    t_fb_make(&f, W, H);
    rp_replay rp;
    rs_err e = {0};
    T_ASSERTF(rp_read(RS_SOURCE_DIR "/demos/dojo.rsr", &rp, &e), "%s", e.msg);
    const uint64_t from = 700, to = 1000;
    T_ASSERT(to <= rp.ticks);
    float *maps[2];
    int n, stirred = 0;
    float h;
    for (int run = 0; run < 2; run++) {
        r_game *r = game_new(&st);
        g_state prev, cur;
        g_init(&cur, rp.stage, rp.seed);
        prev = cur;
        for (uint64_t t = 0; t < to; t++) {
            if (t >= from) {
                t_draw_read(r, &f, &prev, &cur, W, H, NULL, true);
                if (run == 1 && t % 7 == 0) /* drawn again: steps 0 */
                    t_draw_read(r, &f, &prev, &cur, W, H, NULL, true);
                stirred += run == 0 ? fx_fog_get_sim(r)->stirred : 0;
            }
            prev = cur;
            g_step(&cur, &rp.inputs[2 * t], NULL);
        }
        maps[run] = read_map(r, &n, &h);
        r_game_destroy(r);
    }
    dump_map("map_dojo_1000", maps[0], n, 100);
    fprintf(stderr, "    %d limb points stirred the mist over ticks %llu..%llu\n", stirred, (unsigned long long)from,
            (unsigned long long)to);
    T_ASSERTF(stirred > 0, "no fast limb in %llu ticks of a fight", (unsigned long long)(to - from));
    T_ASSERTF(!memcmp(maps[0], maps[1], (size_t)n * n * sizeof(float)), "two renders of the same ticks differ");
    free(maps[0]), free(maps[1]);
    rp_free(&rp);
    t_fb_free(&f);
    plat_destroy(p);
}

static float luma(const float *c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

static const float *hdr_at(const float *hdr, float x, float y)
{
    int i = (int)x, j = (int)y;
    T_ASSERTF(i >= 0 && j >= 0 && i < W && j < H, "%d,%d off screen", i, j);
    return hdr + ((size_t)j * W + i) * 4;
}

/* Fog varies at equal height: mist only on the -x side of the ring; two
 * floor points at the same height and distance, one on each side. */
static void t_fog_varies_at_equal_height(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    t_state_at("dojo", 900, &prev, &cur);
    r_stage st = mistvale();
    st.bloom = 0, st.flare = false; /* nothing that spreads light between the two points */
    static float with[W * H * 4], without[W * H * 4];
    int w, h;
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = game_new(&st);
    t_draw_read(r, &f, &prev, &cur, W, H, NULL, true);
    r_vec3 eye;
    r_mat4 vp = r_game_camera(&cur, W, H, &eye);
    float mid = eye.x, cut = mid - 1.2f;
    /* 2000 particles, uniform over x < cut (their sprites reach cut + 1 m) */
    static float xz[2000][2];
    uint32_t q = 99;
    float h12 = fx_fog_get_sim(r)->d.half;
    for (int i = 0; i < 2000; i++) {
        q = q * 1664525u + 1013904223u;
        xz[i][0] = -h12 + 1.0f + (cut - (-h12 + 1.0f)) * (float)(q >> 8) / 16777216.0f;
        q = q * 1664525u + 1013904223u;
        xz[i][1] = -h12 + 2 * h12 * (float)(q >> 8) / 16777216.0f;
    }
    place(r, &f, &prev, &cur, (const float(*)[2])xz, 2000);
    T_ASSERT(r_game_read_buffer(r, "hdr", with, &w, &h));
    int n;
    float hh;
    float *m = read_map(r, &n, &hh);
    dump_map("map_half", m, n, 100);
    free(m);
    st.fog = false;
    rs_err e = {0};
    T_ASSERTF(r_game_set_stage(r, &st, &e), "%s", e.msg);
    t_draw_read(r, &f, &prev, &cur, W, H, NULL, true);
    T_ASSERT(!t_pass_ran(r, "fog_map"));
    T_ASSERT(r_game_read_buffer(r, "hdr", without, &w, &h));
    /* the floor 1 m in front of the fight plane, 1.8 m to either side;
     * the clear one's whole view ray is over x >= mid: no mist at all */
    float dense[2], clear[2];
    T_ASSERT(r_project(vp, r_v3(mid - 1.8f, 0, 1.0f), W, H, &dense[0], &dense[1]));
    T_ASSERT(r_project(vp, r_v3(mid + 1.8f, 0, 1.0f), W, H, &clear[0], &clear[1]));
    const float *dw = hdr_at(with, dense[0], dense[1]), *dn = hdr_at(without, dense[0], dense[1]);
    const float *cw = hdr_at(with, clear[0], clear[1]), *cn = hdr_at(without, clear[0], clear[1]);
    fprintf(stderr, "    floor at x %+.1f (mist): %.4f -> %.4f; at x %+.1f (clear): %.4f -> %.4f\n", mid - 1.8f, luma(dn),
            luma(dw), mid + 1.8f, luma(cn), luma(cw));
    T_ASSERTF(dw[3] == 0 && cw[3] == 0, "a fighter covers a test point");
    for (int c = 0; c < 3; c++)
        T_ASSERTF(fabsf(cw[c] - cn[c]) <= 1e-3f * cn[c] + 1e-5f, "the clear side changed: %.5f vs %.5f", cw[c], cn[c]);
    T_ASSERTF(fabsf(luma(dw) - luma(dn)) > 0.1f * luma(dn), "the misty side hardly changed: %.4f vs %.4f", luma(dw),
              luma(dn));
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* The effect is visible: mistvale against the same look with fog = no. */
static void t_fog_is_visible(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    t_state_at("dojo", 900, &prev, &cur);
    r_stage st = mistvale();
    static uint8_t a[W * H * 4], b[W * H * 4];
    static float ha[W * H * 4], hb[W * H * 4];
    int w, h;
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = game_new(&st);
    t_draw_read(r, &f, &prev, &cur, W, H, a, true);
    T_ASSERT(t_pass_ran(r, "fog_map"));
    T_ASSERT(r_game_read_buffer(r, "hdr", ha, &w, &h));
    st.fog = false;
    rs_err e = {0};
    T_ASSERTF(r_game_set_stage(r, &st, &e), "%s", e.msg);
    t_draw_read(r, &f, &prev, &cur, W, H, b, true);
    T_ASSERT(!t_pass_ran(r, "fog_map"));
    T_ASSERT(r_game_read_buffer(r, "hdr", hb, &w, &h));
    dump_frame("mistvale_fog", a);
    dump_frame("mistvale_nofog", b);
    double diff = 0;
    for (int i = 0; i < W * H; i++)
        for (int c = 0; c < 3; c++)
            diff += abs((int)a[4 * i + c] - (int)b[4 * i + c]);
    diff /= 3.0 * W * H;
    /* the fighters (HDR alpha 1) are fogged too: vertex fog */
    int fighter = 0, fogged = 0;
    for (int i = 0; i < W * H; i++)
        if (ha[4 * i + 3] == 1.0f) {
            fighter++;
            fogged += memcmp(ha + 4 * i, hb + 4 * i, 3 * sizeof(float)) != 0;
        }
    /* the ground far below, beyond the ring: all but the fog's light */
    r_vec3 eye;
    r_mat4 vp = r_game_camera(&cur, W, H, &eye);
    float gx, gy;
    T_ASSERT(r_project(vp, r_v3(eye.x, -3.0f, -30.0f), W, H, &gx, &gy));
    const float *ga = hdr_at(ha, gx, gy), *gb = hdr_at(hb, gx, gy);
    fprintf(stderr, "    mean difference %.1f levels; %d of %d fighter pixels fogged; far ground %.3f -> %.3f\n", diff,
            fogged, fighter, luma(gb), luma(ga));
    T_ASSERTF(diff > 8, "fog on and off differ by %.2f levels on average", diff);
    T_ASSERTF(fighter > 100 && fogged > fighter / 2, "%d of %d fighter pixels fogged", fogged, fighter);
    /* the fog's light there is the horizon's (0.95 0.78 0.66) plus the
     * sun scattered forward: brighter than the grass, warm */
    T_ASSERTF(luma(ga) > 2 * luma(gb) && ga[0] > ga[2], "far ground %.3f %.3f %.3f", ga[0], ga[1], ga[2]);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* Fog off draws the old pictures: the dojo golden image of test_render
 * (its tolerance), and the fog pass does not run. */
static void t_fog_off_keeps_the_golden_image(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    t_state_at("dojo", 1200, &prev, &cur);
    static uint8_t px[W * H * 4];
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = game_new(NULL);
    t_draw_read(r, &f, &prev, &cur, W, H, px, true);
    T_ASSERT(!t_pass_ran(r, "fog_map"));
    rs_image g;
    rs_err e = {0};
    T_ASSERTF(rs_pnm_read(RS_SOURCE_DIR "/tests/golden/render_dojo_1200.ppm", &g, &e), "%s", e.msg);
    T_ASSERT(g.w == W && g.h == H && g.channels == 3);
    int bad = 0, most = 0;
    double se = 0;
    for (int i = 0; i < W * H; i++) {
        bool off = false;
        for (int c = 0; c < 3; c++) {
            int d = abs((int)px[4 * i + c] - (int)g.px[3 * i + c]);
            se += (double)d * d;
            off |= d > 24;
            most = d > most ? d : most;
        }
        bad += off;
    }
    double mse = se / (W * H * 3), psnr = mse > 0 ? 10 * log10(255.0 * 255.0 / mse) : 99;
    fprintf(stderr, "    dojo@1200 against its golden image: PSNR %.1f dB, largest difference %d levels\n", psnr, most);
    T_ASSERTF(psnr >= 30 && bad <= W * H / 100, "PSNR %.1f dB, %d pixels more than 24 off", psnr, bad);
    rs_image_free(&g);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

static void check_finite(r_game *r, const char *what)
{
    static float buf[W * H * 4];
    int w, h;
    T_ASSERT(r_game_read_buffer(r, "hdr", buf, &w, &h));
    for (size_t k = 0; k < (size_t)w * h * 4; k++)
        T_ASSERTF(isfinite(buf[k]) && fabsf(buf[k]) <= R_HALF_MAX, "%s: hdr[%zu] = %g", what, k, buf[k]);
    int n;
    float half;
    float *m = read_map(r, &n, &half);
    for (int k = 0; k < n * n; k++)
        T_ASSERTF(isfinite(m[k]) && m[k] >= 0, "%s: fog map[%d] = %g", what, k, m[k]);
    free(m);
}

/* fp16 extremes: the brightest stage the parser allows, a black one, a
 * fighter teleported across the world (a limb speed of kilometres per
 * second), all the mist piled on one spot. */
static void t_fp16_extremes(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    t_state_at("dojo", 900, &prev, &cur);
    const r_stage base = mistvale();
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = game_new(&base);
    struct {
        const char *what;
        float sky, sun, key;
    } cases[] = {{"white 65504", R_HALF_MAX, R_HALF_MAX, R_HALF_MAX}, {"black", 0, 0, 0}, {"sun 65504", -1, R_HALF_MAX, -1}};
    rs_err e = {0};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        r_stage st = base;
        if (cases[k].sky >= 0)
            for (int c = 0; c < 3; c++)
                st.sky_zenith[c] = st.sky_horizon[c] = st.ground[c] = cases[k].sky;
        if (cases[k].sun >= 0)
            st.sun_intensity = cases[k].sun;
        if (cases[k].key >= 0)
            st.key.intensity = st.counter.intensity = cases[k].key;
        T_ASSERTF(r_game_set_stage(r, &st, &e), "%s: %s", cases[k].what, e.msg);
        t_draw_read(r, &f, &prev, &cur, W, H, NULL, true);
        T_ASSERT(t_pass_ran(r, "fog_map"));
        check_finite(r, cases[k].what);
        if (cases[k].sky == 0) { /* no light anywhere: the fog has none to scatter either */
            static float hdr[W * H * 4];
            int w, h;
            T_ASSERT(r_game_read_buffer(r, "hdr", hdr, &w, &h));
            float most = 0;
            for (int i = 0; i < W * H; i++)
                most = fmaxf(most, luma(hdr + 4 * (size_t)i));
            T_ASSERTF(most < 0.01f, "%s: HDR %.3f somewhere", cases[k].what, most);
        }
    }
    /* a teleport: the next tick's fighter 1 is 30 km away */
    g_state far = cur;
    far.tick = cur.tick + 1;
    far.f[0].x = FX(30000);
    t_draw_read(r, &f, &cur, &far, W, H, NULL, true);
    check_finite(r, "teleport");
    g_state back = cur;
    back.tick = far.tick + 1;
    t_draw_read(r, &f, &far, &back, W, H, NULL, true);
    check_finite(r, "teleport back");
    /* every particle on one spot */
    static float xz[3000][2];
    place(r, &f, &cur, &back, (const float(*)[2])xz, 3000);
    check_finite(r, "one pile");
    /* a corrupted mist: weights and places no simulation makes */
    fx_fog_sim *s = fx_fog_get_sim(r);
    s->p[0].weight = INFINITY, s->p[1].weight = NAN, s->p[2].weight = 1e30f, s->p[3].x = NAN, s->p[4].z = -INFINITY;
    t_draw_read(r, &f, &cur, &back, W, H, NULL, true);
    check_finite(r, "corrupted particles");
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* bench accuracy's "fog-map resolution vs time" rows: five sizes, the
 * error falls as the map grows, the default is close to the reference. */
static void t_accuracy_rows(void)
{
    plat *p = t_context("egl");
    char path[1024];
    snprintf(path, sizeof path, "%s/rows.txt", t_tmpdir());
    FILE *out = fopen(path, "w+");
    T_ASSERT(out);
    rs_err e = {0};
    T_ASSERTF(fx_fog_accuracy_rows(out, &e), "%s", e.msg);
    rewind(out);
    char line[256];
    int n = 0, size[8];
    double ms[8], rms[8], mx[8], bms[8], brms[8], bmx[8];
    while (fgets(line, sizeof line, out)) {
        fputs(line, stderr);
        if (n < 8 && sscanf(line, "%d %lf %lf %lf %lf %lf %lf", &size[n], &ms[n], &rms[n], &mx[n], &bms[n], &brms[n],
                            &bmx[n]) == 7)
            n++;
    }
    fclose(out);
    T_EQ(n, 5);
    for (int k = 0; k < n; k++)
        T_ASSERTF(ms[k] > 0 && isfinite(rms[k]) && mx[k] >= rms[k] && bms[k] > 0 && bmx[k] >= brms[k],
                  "row %d: %g ms, rms %g, max %g; blurred %g ms, rms %g, max %g", size[k], ms[k], rms[k], mx[k], bms[k],
                  brms[k], bmx[k]);
    T_ASSERTF(rms[4] < rms[0] / 4, "512: rms %.4f, 32: %.4f", rms[4], rms[0]);
    T_ASSERTF(size[2] == 128 && rms[2] < 0.05, "the default map (128) is %.4f off", rms[2]);
    plat_destroy(p);
}

T_MAIN({"sim_deterministic", t_sim_deterministic}, {"sim_stays_inside", t_sim_stays_inside},
       {"sim_wind_moves_the_mist", t_sim_wind_moves_the_mist},
       {"sim_fast_limb_pushes_the_mist", t_sim_fast_limb_pushes_the_mist},
       {"sim_extremes_stay_finite", t_sim_extremes_stay_finite},
       {"map_is_where_particles_are", t_map_is_where_particles_are}, {"map_follows_the_game", t_map_follows_the_game},
       {"map_cpu_matches_sprites", t_map_cpu_matches_sprites},
       {"fog_varies_at_equal_height", t_fog_varies_at_equal_height}, {"fog_is_visible", t_fog_is_visible},
       {"fog_off_keeps_the_golden_image", t_fog_off_keeps_the_golden_image}, {"fp16_extremes", t_fp16_extremes},
       {"accuracy_rows", t_accuracy_rows})
