/* runtime/fx/fx_water*: the water effect (docs/effects.md, "Water").
 *
 *   - the CPU automaton stays bounded for a million forced steps at the
 *     default Courant number, and blows up above the cap when the cap is
 *     bypassed (the cap is what keeps it stable);
 *   - splats: strength proportional to speed, none without motion;
 *   - the GPU automaton matches the CPU reference, splats included, and
 *     both read and write heights under R_WATER_H_TINY as exactly 0;
 *   - on the shallows stage the water changes the picture, a moving fighter
 *     makes waves, standing still makes (almost) none, and a stage without
 *     water runs none of the water passes;
 *   - no NaN or Inf leaves the water passes (fp16 extremes, a poisoned
 *     simulation state). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/game/g_ai.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/fx/fx_water_sim.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_stage.h"
#include "t.h"
#include "t_render.h"

enum { W = 320, H = 180, NN = R_WATER_N * R_WATER_N * 2 };

/* ---- the CPU reference ---- */

/* A 64x64 grid over 2 m (splats a few cells wide), forced every step like
 * the game: the energy after 1000 steps is the steady state of the forcing
 * against the damping; over a million steps it must not grow past it. */
static void t_cpu_bounded_for_a_million_steps(void)
{
    fx_water_sim_params p = {.size = 2.0f};
    fx_water_sim_run run;
    T_ASSERT(fx_water_sim_forced_run(&p, false, 64, 1000000, 1000, &run));
    double ratio = run.e_max / run.e_ref;
    fprintf(stderr, "    C %.3f damping %.3f: energy after 1000 steps %.4g, max over 1e6 steps %.4g (ratio %.3f), last %.4g, "
                    "max |h| %.4f m, %.2f us/step\n",
            fx_water_sim_courant_clamp(0), 0.985, run.e_ref, run.e_max, ratio, run.e_last, run.h_absmax, run.ms * 1000 / run.steps);
    T_ASSERT(run.finite);
    T_ASSERTF(run.e_ref > 1e-6, "the forcing made no waves (energy %g)", run.e_ref);
    T_ASSERTF(ratio < 2.0, "energy grew: max %g vs %g after 1000 steps", run.e_max, run.e_ref);
    T_ASSERTF(run.h_absmax < 0.5f * 0.08f, "waves reach the clamp: %g m", run.h_absmax);
}

/* The same forcing above the CFL limit with the cap bypassed: the
 * checkerboard mode grows every step until the height clamp holds it. */
static void t_cpu_over_the_cap_blows_up(void)
{
    fx_water_sim_params p = {.size = 2.0f, .courant = 0.75f, .damping = 0.985f};
    fx_water_sim_run capped, raw;
    /* through the checked path the request is capped, and stable */
    T_ASSERT(fx_water_sim_forced_run(&p, false, 64, 20000, 1000, &capped));
    T_ASSERTF(capped.finite && capped.e_max / capped.e_ref < 2.0 && capped.h_absmax < 0.5f * 0.08f,
              "C = 0.75 through the cap is unstable: energy ratio %g, max |h| %g m", capped.e_max / capped.e_ref,
              capped.h_absmax);
    T_ASSERT(fx_water_sim_forced_run(&p, true, 64, 20000, 1000, &raw));
    fprintf(stderr, "    C 0.75 capped to %.4f: max energy %.4g, max |h| %.4f m; uncapped: max energy %.4g (x%.3g), max |h| %.4f m\n",
            R_WATER_COURANT_MAX, capped.e_max, capped.h_absmax, raw.e_max, raw.e_max / capped.e_max, raw.h_absmax);
    /* the checkerboard mode grows until the height clamp stops it */
    T_ASSERTF(raw.e_max > 100 * capped.e_max, "C = 0.75 stayed stable (energy x%g)", raw.e_max / capped.e_max);
    T_ASSERTF(raw.h_absmax >= 0.08f * 0.99f, "C = 0.75: heights stayed at %g m", raw.h_absmax);
    /* the cap itself */
    T_ASSERT(R_WATER_COURANT_MAX < R_WATER_CFL);
    const float asks[] = {0.75f, 1.0f, 1e30f, INFINITY};
    for (size_t k = 0; k < sizeof asks / sizeof asks[0]; k++)
        T_ASSERTF(fx_water_sim_courant_clamp(asks[k]) == R_WATER_COURANT_MAX, "%g -> %g", asks[k], fx_water_sim_courant_clamp(asks[k]));
    T_ASSERT(fx_water_sim_courant_clamp(NAN) == fx_water_sim_courant_clamp(0));
    T_ASSERT(fx_water_sim_courant_clamp(-1) == fx_water_sim_courant_clamp(0));
    T_ASSERT(fx_water_sim_courant_clamp(0.3f) == 0.3f);
    fx_water_sim_params q = {.courant = 5, .damping = 7, .h_max = -1};
    fx_water_sim_params_fix(&q);
    T_ASSERT(q.courant == R_WATER_COURANT_MAX && q.damping == 1.0f && q.h_max > 0);
}

/* Strength proportional to speed; no motion, no wave; nothing off the water. */
static void t_splats_follow_speed(void)
{
    fx_water_sim_params p = {0};
    fx_water_sim_params_fix(&p);
    fx_water_sim_splat a, b;
    T_ASSERT(fx_water_sim_splat_for(&p, R_WATER_N, 0.5f, -0.2f, 0.06f, 0.12f, 1.0f, &a));
    T_ASSERT(fx_water_sim_splat_for(&p, R_WATER_N, 0.5f, -0.2f, 0.06f, 0.12f, 2.0f, &b));
    T_ASSERT(a.amp < 0 && fabsf(b.amp - 2 * a.amp) < 1e-7f);
    T_ASSERT(fabsf(a.x - (0.5f + 4) * 32) < 1e-3f && fabsf(a.y - (-0.2f + 4) * 32) < 1e-3f);
    T_ASSERT(!fx_water_sim_splat_for(&p, R_WATER_N, 0.5f, -0.2f, 0.06f, 0.12f, 0.0f, &a)); /* still */
    T_ASSERT(!fx_water_sim_splat_for(&p, R_WATER_N, 4.5f, 0, 0.06f, 0.12f, 3.0f, &a));     /* off the ring */
    T_ASSERT(!fx_water_sim_splat_for(&p, R_WATER_N, NAN, 0, 0.06f, 0.12f, 3.0f, &a));
    T_ASSERT(!fx_water_sim_splat_for(&p, R_WATER_N, 0, 0, 0.06f, 0.12f, NAN, &a));
    T_ASSERT(fx_water_sim_splat_for(&p, R_WATER_N, 0, 0, 0.06f, 0.12f, 1e9f, &a) && a.amp == -p.amp_max); /* capped */
    /* the bump on the grid: the centre cell gets almost amp, nothing outside the radius */
    static float g[NN];
    fx_water_sim_splat s = {100.5f, 60.5f, 3.0f, -0.01f};
    fx_water_sim_add_splat(R_WATER_N, g, &s);
    T_ASSERT(fabsf(g[(60 * R_WATER_N + 100) * 2] + 0.01f) < 1e-9f);
    T_ASSERT(g[(60 * R_WATER_N + 104) * 2] == 0 && g[(60 * R_WATER_N + 100) * 2 + 1] == 0);
    T_ASSERT(g[(61 * R_WATER_N + 101) * 2] < 0);
}

/* ---- GL ---- */

static int shallows_index(void)
{
    for (int i = 0; i < G_STAGES; i++)
        if (!strcmp(g_stages[i].name, "shallows"))
            return i;
    T_ASSERTF(0, "no game stage 'shallows'");
    return -1;
}

static r_game *game_new(void)
{
    rs_err e = {0};
    r_game *r = t_game_opts(&(r_game_opts){.no_hud = true});
    T_ASSERTF(r_game_prepare(r, shallows_index(), &e), "%s", e.msg);
    T_ASSERT(r_game_stage(r)->water);
    return r;
}

static float grid_absmax(const float *g)
{
    float m = 0;
    for (size_t k = 0; k < NN; k += 2)
        m = fmaxf(m, fabsf(g[k]));
    return m;
}

/* 200 steps at 256x256 with moving splats, GPU against CPU. */
static void t_gpu_matches_cpu(void)
{
    plat *p = t_context("egl");
    r_game *r = game_new();
    const fx_water_sim_params *prm = fx_water_params(r);
    T_ASSERT(prm);
    T_ASSERT(fx_water_set_cpu(r, false, NULL)); /* the shaders, also on a software rasteriser */
    static float cpu[NN], tmp[NN], gpu[NN];
    memset(cpu, 0, sizeof cpu);
    T_ASSERT(fx_water_write(r, cpu));
    rgl_error_reset();
    double worst = 0, scale = 0;
    for (int t = 0; t < 200; t++) {
        /* three feet: one sweeping, one circling, one stamping now and then;
         * one splat crosses the grid's edge */
        fx_water_sim_splat s[3];
        int ns = 0;
        s[ns++] = (fx_water_sim_splat){60.0f + 40.0f * sinf(t * 0.07f), 128.3f, 2.7f, -0.004f * (1.2f + cosf(t * 0.07f))};
        s[ns++] = (fx_water_sim_splat){180.0f + 20.0f * cosf(t * 0.05f), 90.0f + 20.0f * sinf(t * 0.05f), 4.5f, -0.003f};
        if (t % 40 < 3)
            s[ns++] = (fx_water_sim_splat){1.2f, 200.7f, 3.0f, -0.008f};
        T_ASSERT(fx_water_gpu_steps(r, s, ns, 1));
        fx_water_sim_step(prm, R_WATER_N, cpu, tmp);
        for (int k = 0; k < ns; k++)
            fx_water_sim_add_splat(R_WATER_N, tmp, &s[k]);
        memcpy(cpu, tmp, sizeof cpu);
    }
    T_ASSERT(fx_water_read(r, gpu));
    T_EQ(rgl_error_count(), 0);
    for (size_t k = 0; k < NN; k++) {
        worst = fmax(worst, fabs((double)gpu[k] - cpu[k]));
        scale = fmax(scale, fabs(cpu[k]));
    }
    /* fp32 on both sides, the same operations; what may differ is the
     * driver's cos() in the splat and a rounding here and there, which
     * the damped scheme does not amplify */
    double tol = 1e-4 * scale;
    fprintf(stderr, "    200 steps at 256x256: max |gpu - cpu| %.3g m, max |h| %.4g m (tolerance %.3g)\n", worst, scale, tol);
    T_ASSERTF(scale > 1e-3, "the splats made no waves (max |h| %g)", scale);
    T_ASSERTF(worst <= tol, "GPU and CPU differ by %g (max |h| %g)", worst, scale);
    r_game_destroy(r);
    plat_destroy(p);
}

/* Heights under R_WATER_H_TINY read and write as 0 on both sides: a lone
 * 1e-25 m bump, a denormal and a splat too weak to matter leave exactly
 * zero, while a real wave far away survives.  Without the flush a dying
 * ripple reaches the denormal range, which llvmpipe's threads flush and
 * other paths do not: a render started mid-way then differed from the
 * full one (docs/effects.md, History). */
static void t_tiny_heights_are_zero(void)
{
    plat *p = t_context("egl");
    r_game *r = game_new();
    const fx_water_sim_params *prm = fx_water_params(r);
    T_ASSERT(prm);
    T_ASSERT(fx_water_set_cpu(r, false, NULL)); /* the shaders, also on a software rasteriser */
    static float in[NN], cpu[NN], gpu[NN];
    memset(in, 0, sizeof in);
    float denormal = 1e-39f;
    T_ASSERT(denormal > 0 && denormal < 1.17549435e-38f);
#define AT(i, j) (((size_t)(j) * R_WATER_N + (i)) * 2)
    in[AT(50, 50)] = 1e-25f;        /* a height */
    in[AT(80, 50) + 1] = -3e-21f;   /* a previous height */
    in[AT(110, 50)] = denormal;
    in[AT(200, 200)] = 1e-3f;       /* a real wave */
    /* a splat whose whole bump is under the threshold */
    fx_water_sim_splat weak = {50.5f, 120.5f, 3.0f, -5e-21f};
    T_ASSERT(fx_water_write(r, in));
    T_ASSERT(fx_water_gpu_steps(r, &weak, 1, 1));
    T_ASSERT(fx_water_read(r, gpu));
    fx_water_sim_step(prm, R_WATER_N, in, cpu);
    fx_water_sim_add_splat(R_WATER_N, cpu, &weak);
    int nonzero_cpu = 0, nonzero_gpu = 0;
    for (int j = 40; j < 130; j++)
        for (int i = 40; i < 120; i++)
            for (int c = 0; c < 2; c++) {
                nonzero_cpu += cpu[AT(i, j) + c] != 0.0f;
                nonzero_gpu += gpu[AT(i, j) + c] != 0.0f;
            }
    fprintf(stderr, "    cells (and previous heights) not exactly 0 around the tiny values: cpu %d, gpu %d; "
                    "the real wave: cpu %.4g, gpu %.4g\n",
            nonzero_cpu, nonzero_gpu, cpu[AT(200, 200)], gpu[AT(200, 200)]);
    T_EQ(nonzero_cpu, 0);
    T_EQ(nonzero_gpu, 0);
    T_ASSERT(cpu[AT(200, 200)] > 1e-4f && cpu[AT(201, 200)] > 1e-5f);
    T_ASSERT(gpu[AT(200, 200)] == cpu[AT(200, 200)] && gpu[AT(201, 200)] == cpu[AT(201, 200)]);
#undef AT
    r_game_destroy(r);
    plat_destroy(p);
}

/* A shallows match between two CPU players: ticks 0..end, drawn from
 * `from` on (each frame one tick: one simulation step). */
typedef struct match {
    g_state prev, cur;
    g_ai ai[2];
} match;

static void match_start(match *m)
{
    g_init(&m->cur, shallows_index(), 5);
    g_ai_init(&m->ai[0], 0, 2, 5);
    g_ai_init(&m->ai[1], 1, 2, 6);
    m->prev = m->cur;
}

static void match_tick(match *m)
{
    g_input in[2] = {g_ai_input(&m->ai[0], &m->cur), g_ai_input(&m->ai[1], &m->cur)};
    m->prev = m->cur;
    g_step(&m->cur, in, NULL);
}

/* The intro: the fighters stand; then the fight: they move.  Standing
 * makes almost no wave, moving makes waves; the water changes the
 * picture over the ring; a stage without water runs none of its passes. */
static void t_shallows_waves_and_picture(void)
{
    plat *p = t_context("egl");
    r_game *r = game_new();
    t_fb f;
    t_fb_make(&f, W, H);
    static float g[NN];
    static uint8_t wet[W * H * 4], dry[W * H * 4];
    match m;
    match_start(&m);
    /* the intro: the fighters stand */
    float still = 0;
    for (int t = 0; t < 40; t++) {
        match_tick(&m);
        t_draw_read(r, &f, &m.prev, &m.cur, W, H, NULL, false);
        T_ASSERT(t_pass_ran(r, "water_sim") && t_pass_ran(r, "water_reflect") && t_pass_ran(r, "water_under") && t_pass_ran(r, "water_surface"));
    }
    T_ASSERT(fx_water_read(r, g));
    still = grid_absmax(g);
    /* the fight */
    int most_splats = 0;
    while (m.cur.tick < 420) {
        match_tick(&m);
        if (m.cur.tick < 300)
            continue;
        t_draw_read(r, &f, &m.prev, &m.cur, W, H, NULL, false);
        if (fx_water_last_splats(r) > most_splats)
            most_splats = fx_water_last_splats(r);
    }
    t_draw_read(r, &f, &m.prev, &m.cur, W, H, wet, false);
    T_ASSERT(fx_water_read(r, g));
    float moving = grid_absmax(g);
    fprintf(stderr, "    max |h|: standing (40 ticks of intro) %.2g m, fighting (120 ticks) %.4f m, up to %d splats a tick\n",
            still, moving, most_splats);
    T_ASSERTF(most_splats > 0 && moving > 2e-3f, "moving fighters made no waves (%g m, %d splats)", moving, most_splats);
    T_ASSERTF(still < moving / 20, "standing fighters made waves of %g m (fighting: %g m)", still, moving);
    for (size_t k = 0; k < NN; k++)
        T_ASSERT(isfinite(g[k]));

    /* the same frame with water = no */
    r_stage st = *r_game_stage(r);
    st.water = false;
    rs_err e = {0};
    T_ASSERTF(r_game_set_stage(r, &st, &e), "%s", e.msg);
    t_draw_read(r, &f, &m.prev, &m.cur, W, H, dry, false);
    T_ASSERT(!t_pass_ran(r, "water_sim") && !t_pass_ran(r, "water_reflect") && !t_pass_ran(r, "water_under") && !t_pass_ran(r, "water_surface"));
    /* the ring's top face in front of the fighters: the lower quarter of the picture */
    int differ = 0, n = 0;
    for (int y = 2; y < H / 4; y++)
        for (int x = 0; x < W; x++, n++) {
            const uint8_t *a = wet + ((size_t)y * W + x) * 4, *b = dry + ((size_t)y * W + x) * 4;
            differ += abs(a[0] - b[0]) + abs(a[1] - b[1]) + abs(a[2] - b[2]) > 24;
        }
    fprintf(stderr, "    %d of %d pixels over the ring differ with water on\n", differ, n);
    T_ASSERTF(differ > n / 2, "water on and off look alike over the ring (%d of %d pixels differ)", differ, n);
    t_fb_free(&f);
    r_game_destroy(r);
    plat_destroy(p);
}

/* On a software rasteriser the automaton and the normal map run in C
 * (cpu_steps, cpu_normal_map) by default: a match drawn that way and one
 * drawn with the shaders keep the same waves (the steps' arithmetic is
 * the same; the splat's cos() may round differently) and the same
 * picture. */
static void t_cpu_path_matches_shaders(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    static float g[2][NN];
    static uint8_t px[2][W * H * 4];
    for (int way = 0; way < 2; way++) {
        r_game *r = game_new();
        bool was = false;
        T_ASSERT(fx_water_set_cpu(r, way == 0, &was));
        T_ASSERTF(was, "llvmpipe's default is not the automaton in C");
        match m;
        match_start(&m);
        while (m.cur.tick < 380) {
            match_tick(&m);
            if (m.cur.tick >= 300)
                t_draw_read(r, &f, &m.prev, &m.cur, W, H, px[way], false);
        }
        T_ASSERT(fx_water_read(r, g[way]));
        r_game_destroy(r);
    }
    double worst = 0, scale = 0;
    for (size_t k = 0; k < NN; k++)
        worst = fmax(worst, fabs((double)g[0][k] - g[1][k])), scale = fmax(scale, fabs(g[1][k]));
    int differ = 0;
    for (int k = 0; k < W * H * 4; k++)
        differ += abs(px[0][k] - px[1][k]) > 2;
    fprintf(stderr, "    80 frames: max |c - shaders| %.3g m, max |h| %.4g m; %d of %d bytes more than 2 apart\n", worst,
            scale, differ, W * H * 4);
    T_ASSERTF(scale > 1e-3, "the fight made no waves (max |h| %g)", scale);
    T_ASSERTF(worst <= 1e-4 * scale, "C and shaders differ by %g m (max |h| %g)", worst, scale);
    T_ASSERTF(differ <= W * H * 4 / 1000, "%d bytes of the frame differ by more than 2", differ);
    t_fb_free(&f);
    plat_destroy(p);
}

static void check_finite(r_game *r, const char *what, bool stepped)
{
    static float buf[W * H * 4], g[NN];
    int w = 0, h = 0;
    T_ASSERT(r_game_read_buffer(r, "hdr", NULL, &w, &h) && w == W && h == H);
    T_ASSERT(r_game_read_buffer(r, "hdr", buf, &w, &h));
    for (size_t k = 0; k < (size_t)W * H * 4; k++)
        T_ASSERTF(isfinite(buf[k]) && fabsf(buf[k]) <= R_HALF_MAX, "%s: hdr[%zu] = %g", what, k, buf[k]);
    if (!stepped)
        return;
    T_ASSERT(fx_water_read(r, g)); /* a step made every cell finite again */
    for (size_t k = 0; k < NN; k++)
        T_ASSERTF(isfinite(g[k]) && fabsf(g[k]) <= 1.0f, "%s: simulation[%zu] = %g", what, k, g[k]);
}

/* fp16 extremes in the light, and NaN / Inf / huge values in the
 * simulation state: nothing that is not finite reaches the HDR buffer. */
static void t_no_nan_or_inf(void)
{
    plat *p = t_context("egl");
    r_game *r = game_new();
    t_fb f;
    t_fb_make(&f, W, H);
    match m;
    match_start(&m);
    while (m.cur.tick < 330)
        match_tick(&m);
    const r_stage base = *r_game_stage(r);
    static float g[NN];
    /* a sun where the water in front of the fighters mirrors it: the glint at full strength */
    r_vec3 eye;
    r_game_camera(&m.cur, W, H, &eye);
    float mx = (fx_to_float(m.cur.f[0].x) + fx_to_float(m.cur.f[1].x)) / 2;
    r_vec3 d = r_norm(r_v3(mx - eye.x, 0.12f - eye.y, 1.0f - eye.z));
    struct {
        const char *what;
        float sun, sky;
        int poison; /* 0 none, 1 NaN, 2 +-Inf, 3 +-1e30 */
        bool glint;
    } cases[] = {
        {"sun 65504", 65504, -1, 0, false},        {"sun 65504 in the mirror", 65504, -1, 0, true},
        {"white world 65504", 65504, 65504, 0, true}, {"black world", 0, 0, 0, false},
        {"NaN heights", -1, -1, 1, false},         {"Inf heights", -1, -1, 2, false},
        {"1e30 heights", -1, -1, 3, false},        {"sun 65504 in the mirror + Inf", 65504, 65504, 2, true},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        r_stage st = base;
        if (cases[k].sun >= 0)
            st.sun_intensity = cases[k].sun;
        if (cases[k].glint)
            st.sun_dir[0] = d.x, st.sun_dir[1] = -d.y, st.sun_dir[2] = d.z;
        if (cases[k].sky >= 0) {
            for (int c = 0; c < 3; c++)
                st.sky_zenith[c] = st.sky_horizon[c] = st.ground[c] = cases[k].sky;
            st.key.intensity = st.counter.intensity = cases[k].sky;
        }
        rs_err e = {0};
        T_ASSERTF(r_game_set_stage(r, &st, &e), "%s: %s", cases[k].what, e.msg);
        for (int t = 0; t < 3; t++) {
            if (t == 1 && cases[k].poison) { /* after the reset of a new look */
                for (size_t i = 0; i < NN; i++) {
                    float v = cases[k].poison == 1 ? NAN : cases[k].poison == 2 ? INFINITY : 1e30f;
                    g[i] = (i / 2 + i / (2 * R_WATER_N)) & 1 ? v : -v; /* a checkerboard of both signs */
                }
                T_ASSERT(fx_water_write(r, g));
                t_draw_read(r, &f, &m.cur, &m.cur, W, H, NULL, false); /* the same tick again: the surface reads the raw state */
                check_finite(r, cases[k].what, false);
            }
            match_tick(&m);
            t_draw_read(r, &f, &m.prev, &m.cur, W, H, NULL, false);
            check_finite(r, cases[k].what, true);
        }
    }
    t_fb_free(&f);
    r_game_destroy(r);
    plat_destroy(p);
}

T_MAIN({"cpu_bounded_for_a_million_steps", t_cpu_bounded_for_a_million_steps},
       {"cpu_over_the_cap_blows_up", t_cpu_over_the_cap_blows_up},
       {"splats_follow_speed", t_splats_follow_speed},
       {"gpu_matches_cpu", t_gpu_matches_cpu},
       {"tiny_heights_are_zero", t_tiny_heights_are_zero},
       {"shallows_waves_and_picture", t_shallows_waves_and_picture},
       {"cpu_path_matches_shaders", t_cpu_path_matches_shaders}, {"no_nan_or_inf", t_no_nan_or_inf})
