/* LSPSM shadows in a large world (runtime/fx/fx_lspsm.c, techniques
 * C) on GL: the buildings' shadows show; culling drops casters without
 * changing the map; the auto-focus reads exactly the 20x16 pattern of the
 * depth buffer and uses it the next frame; the fighters do not shadow
 * themselves but receive each other's, and leave the map to their own
 * shadows but on the buildings; light exactly parallel and
 * anti-parallel to the view stays finite and does not pop; fp16 extremes;
 * determinism.  The mathematics alone is tests/test_lspsm.c, the layout
 * tests/test_city.c.  T_DUMP=DIR writes the frames as PPM. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/fx/fx_lspsm.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_lspsm.h"
#include "../runtime/render/r_stage.h"
#include "t.h"
#include "t_render.h"

enum { W = 320, H = 180 };
#define FIGHTERS_APART 60 /* a tick of the dojo demo: both stand, 2.4 m apart */

static r_stage plaza(void)
{
    r_stage st;
    rs_err e = {0};
    T_ASSERTF(r_stage_load(&st, RS_SOURCE_DIR "/stages/plaza.stage", &e), "%s", e.msg);
    T_ASSERT(st.lspsm && st.buildings > 0);
    return st;
}

static void set_stage(r_game *r, const r_stage *st)
{
    rs_err e = {0};
    T_ASSERTF(r_game_set_stage(r, st, &e), "%s", e.msg);
}

static void draw(r_game *r, t_fb *f, const g_state *prev, const g_state *cur)
{
    t_draw(r, f, prev, cur, W, H);
}

static float *hdr(r_game *r)
{
    return t_read(r, "hdr", 4, W, H);
}

static void dump(const char *name, const float *px)
{
    char n[64];
    snprintf(n, sizeof n, "lspsm_%s", name);
    t_dump_hdr(n, px, W, H);
}

static float luma(const float *p)
{
    return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
}

/* Draws `n` consecutive ticks ending at `tick` (the focus and the
 * simulations get their history). */
static void draw_run(r_game *r, t_fb *f, const char *demo, uint64_t tick, int n)
{
    for (int k = n - 1; k >= 0; k--) {
        g_state prev, cur;
        t_state_at(demo, tick - (uint64_t)k, &prev, &cur);
        draw(r, f, &prev, &cur);
    }
}

/* The buildings' shadows are visible: the plaza frame with lspsm = no
 * (same buildings, no map) is brighter, and the map holds scenery. */
static void t_buildings_cast_shadows(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = t_game_new(false);
    r_stage st = plaza();
    set_stage(r, &st);
    draw_run(r, &f, "plaza", 600, 2);
    T_ASSERT(t_pass_ran(r, "lspsm_map") && t_pass_ran(r, "buildings") && t_pass_ran(r, "lspsm_focus"));
    float *on = hdr(r);
    float *map = malloc((size_t)R_LSPSM_MAP * R_LSPSM_MAP * sizeof *map);
    T_ASSERT(map && fx_lspsm_read(r, "map", map));
    size_t scenery = 0;
    for (size_t i = 0; i < (size_t)R_LSPSM_MAP * R_LSPSM_MAP; i++)
        scenery += map[i] < 1;
    st.lspsm = false;
    set_stage(r, &st);
    draw_run(r, &f, "plaza", 600, 2);
    T_ASSERT(!t_pass_ran(r, "lspsm_map") && t_pass_ran(r, "buildings") && !t_pass_ran(r, "lspsm_focus"));
    float *off = hdr(r);
    dump("plaza_on", on), dump("plaza_off", off);
    double sum_on = 0, sum_off = 0;
    int darker = 0, brighter = 0, bad = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        float a = luma(on + 4 * i), b = luma(off + 4 * i);
        sum_on += a, sum_off += b;
        darker += a < 0.7f * b;
        brighter += a > b * 1.001f + 1e-4f;
        bad += !isfinite(a);
    }
    fprintf(stderr, "    plaza@600: mean luminance %.3f with the map, %.3f without; %d of %d pixels darker by 30%%+; "
                    "map: %zu scenery texels\n",
            sum_on / (W * H), sum_off / (W * H), darker, W * H, scenery);
    T_EQ(bad, 0);
    T_ASSERTF(darker > W * H / 20, "only %d pixels in a building's shadow", darker);
    T_ASSERTF(brighter < W * H / 200, "%d pixels got brighter with shadows", brighter);
    T_ASSERT(scenery > 10000); /* the fighters' texels: t_fighters_leave_the_map_to_their_shadows */
    free(on), free(off), free(map);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* Texels of map b nearer the light than a's (fighters), and farther (none
 * should be). */
static void map_minus(const float *a, const float *b, size_t *nearer, size_t *farther)
{
    *nearer = *farther = 0;
    for (size_t i = 0; i < (size_t)R_LSPSM_MAP * R_LSPSM_MAP; i++) {
        *nearer += b[i] < a[i] - 1e-6f;
        *farther += b[i] > a[i] + 1e-6f;
    }
}

/* The same frame drawn again without the buildings' map with the
 * fighters (it must not be drawn then), and how many pixels of `with`
 * are darker (by 10 %+) and brighter than it. */
static float *without_cast(r_game *r, t_fb *f, const r_stage *st, const float *with, int *darker, int *brighter)
{
    fx_lspsm_stats s;
    fx_lspsm_test_no_cast(r, true);
    set_stage(r, st);
    draw_run(r, f, "plaza", 600, 2);
    T_ASSERT(fx_lspsm_stats_get(r, &s) && !s.fighters_cast);
    float *without = hdr(r);
    *darker = *brighter = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        float x = luma(with + 4 * i), y = luma(without + 4 * i);
        *darker += x < 0.9f * y;
        *brighter += x > y * 1.001f + 1e-4f;
    }
    return without;
}

/* With the fighter shadows on, the receivers' map holds the buildings
 * alone (the silhouette casts the fighters on the ring and the mask on
 * each other): with those shadows off it is the same map plus the
 * fighters.  The silhouette stops short of the buildings, so with a light
 * low enough for a fighter's shadow to reach one, the buildings get a map
 * with the fighters drawn in: the facade darkens where the shadow falls,
 * and nothing else changes.  With the stage's own light, or one from
 * above, it is not drawn. */
static void t_fighters_leave_the_map_to_their_shadows(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = t_game_new(false);
    r_stage st = plaza();
    size_t n = (size_t)R_LSPSM_MAP * R_LSPSM_MAP, nearer, farther;
    float *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    T_ASSERT(a && b);
    fx_lspsm_stats s;
    set_stage(r, &st);
    draw_run(r, &f, "plaza", 600, 2);
    T_ASSERT(fx_lspsm_stats_get(r, &s));
    T_ASSERT(!s.fighters_in_map && !s.fighters_cast);
    /* the stage's sun puts the fighters in the tower's shadow, behind it
     * in the map: a light from above shows them */
    const float up[3] = {0, 1, 0};
    fx_lspsm_test_set(r, up, false, false);
    set_stage(r, &st);
    draw_run(r, &f, "plaza", 600, 2);
    T_ASSERT(fx_lspsm_stats_get(r, &s) && fx_lspsm_read(r, "map", a));
    T_ASSERT(!s.fighters_in_map && !s.fighters_cast);
    st.shadows = false;
    set_stage(r, &st);
    draw_run(r, &f, "plaza", 600, 2);
    T_ASSERT(fx_lspsm_stats_get(r, &s) && fx_lspsm_read(r, "map", b));
    T_ASSERT(s.fighters_in_map && !s.fighters_cast);
    map_minus(a, b, &nearer, &farther);
    fprintf(stderr, "    shadows off: %zu fighter texels added to the map, %zu texels farther\n", nearer, farther);
    T_ASSERTF(nearer > 200, "only %zu texels of fighters", nearer);
    T_EQ(farther, 0);

    /* a light 3 degrees up, round the horizon in 16 steps: where the
     * buildings' map is drawn, it is the receivers' plus fighters, and the
     * frame differs from the one without it only by darker pixels; at
     * some azimuth a fighter's shadow shows on a facade */
    st.shadows = true;
    int cast = 0, shown = -1, most = 0;
    for (int k = 0; k < 16; k++) {
        float az = (float)k * 6.2831853f / 16, L[3] = {cosf(az), 0.05f, sinf(az)};
        fx_lspsm_test_set(r, L, false, false);
        fx_lspsm_test_no_cast(r, false);
        set_stage(r, &st);
        draw_run(r, &f, "plaza", 600, 2);
        T_ASSERT(fx_lspsm_stats_get(r, &s));
        if (!s.fighters_cast)
            continue;
        cast++;
        float *with = hdr(r);
        T_ASSERT(fx_lspsm_read(r, "map", a) && fx_lspsm_read(r, "cast", b));
        map_minus(a, b, &nearer, &farther);
        int darker, brighter;
        float *without = without_cast(r, &f, &st, with, &darker, &brighter);
        fprintf(stderr, "    light at azimuth %2d/16: the buildings' map has %zu fighter texels (%zu farther); "
                        "%d pixels darker for it, %d brighter\n", k, nearer, farther, darker, brighter);
        T_EQ(farther, 0);
        T_EQ(brighter, 0);
        if (darker > most && nearer > 20) {
            most = darker, shown = k;
            dump("cast_with", with), dump("cast_without", without);
        }
        free(with), free(without);
    }
    T_ASSERTF(cast > 0, "no light round the horizon casts a fighter onto a building");
    T_ASSERTF(shown >= 0 && most > 10, "%d lights drew the buildings' map, and no fighter's shadow showed on a facade",
              cast);
    fx_lspsm_test_no_cast(r, false);
    free(a), free(b);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* The static layers do the same: the fighters' own shadows on, so the
 * layers hold the buildings alone; with a light low enough, a copy with
 * the fighters is what the buildings look up, and a fighter's shadow
 * shows on a facade (pixels darker, none brighter, against the frame
 * without the copy).  With the fighters' shadows off there are no static
 * layers (the fighters must be in the map): the LSPSM map draws them. */
static void t_static_layers_cast_the_fighters_on_buildings(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = t_game_opts(&(r_game_opts){.q = {.lspsm_static = 512}});
    r_stage st = plaza();
    fx_lspsm_stats s;
    set_stage(r, &st);
    draw_run(r, &f, "plaza", 600, 2);
    T_ASSERT(fx_lspsm_stats_get(r, &s));
    T_ASSERT(s.is_static && !s.fighters_in_map && !s.fighters_cast);
    T_EQ(s.static_draws, 1);
    st.shadows = false;
    set_stage(r, &st);
    draw_run(r, &f, "plaza", 600, 2);
    T_ASSERT(fx_lspsm_stats_get(r, &s));
    T_ASSERT(!s.is_static && s.fighters_in_map && s.static_draws == 0);
    st.shadows = true;
    int cast = 0, most = 0;
    /* the lights of the map's test (16 round the horizon, 3 degrees up)
     * that cast a fighter on a facade there (3/16 and 4/16), and two that
     * do not */
    for (int k = 2; k <= 5; k++) {
        float az = (float)k * 6.2831853f / 16, L[3] = {cosf(az), 0.05f, sinf(az)};
        fx_lspsm_test_set(r, L, false, false);
        fx_lspsm_test_no_cast(r, false);
        set_stage(r, &st);
        draw_run(r, &f, "plaza", 600, 2);
        T_ASSERT(fx_lspsm_stats_get(r, &s) && s.is_static && s.static_draws == 1);
        if (!s.fighters_cast)
            continue;
        cast++;
        float *with = hdr(r);
        int darker, brighter;
        float *without = without_cast(r, &f, &st, with, &darker, &brighter);
        fprintf(stderr, "    static layers, light at azimuth %2d/16: %d pixels darker for the fighters' copy, %d brighter\n", k,
                darker, brighter);
        T_EQ(brighter, 0);
        if (darker > most) {
            most = darker;
            dump("static_cast_with", with), dump("static_cast_without", without);
        }
        free(with), free(without);
    }
    T_ASSERTF(cast > 0 && most > 10, "%d lights drew the fighters' copy of the static layers; at most %d pixels darker",
              cast, most);
    fx_lspsm_test_no_cast(r, false);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* Culling draws fewer casters and the same map. */
static void t_culling_keeps_the_map(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = t_game_new(false);
    r_stage st = plaza();
    set_stage(r, &st);
    size_t n = (size_t)R_LSPSM_MAP * R_LSPSM_MAP;
    float *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b);
    T_ASSERT(a && b);
    const uint64_t ticks[] = {600, 1500, 2400};
    for (size_t t = 0; t < 3; t++) {
        fx_lspsm_stats s1, s2;
        fx_lspsm_test_set(r, NULL, false, false);
        draw_run(r, &f, "plaza", ticks[t], 1);
        T_ASSERT(fx_lspsm_stats_get(r, &s1) && fx_lspsm_read(r, "map", a));
        fx_lspsm_test_set(r, NULL, true, false);
        draw_run(r, &f, "plaza", ticks[t], 1);
        T_ASSERT(fx_lspsm_stats_get(r, &s2) && fx_lspsm_read(r, "map", b));
        fprintf(stderr, "    tick %llu: %d of %d buildings cast into the view\n", (unsigned long long)ticks[t],
                s1.casters_drawn, s1.casters);
        T_EQ(s2.casters_drawn, s2.casters);
        T_ASSERTF(s1.casters_drawn < s1.casters && s1.casters_drawn > 0, "culling kept %d of %d", s1.casters_drawn,
                  s1.casters);
        size_t diff = 0;
        for (size_t i = 0; i < n; i++)
            diff += a[i] != b[i];
        T_ASSERTF(diff == 0, "tick %llu: culling changed %zu texels of the map", (unsigned long long)ticks[t], diff);
    }
    free(a), free(b);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* The focus pass gathers exactly r_lspsm_focus_point's pixels of the depth
 * buffer, and the next frame's range is r_lspsm_focus_update of them; a
 * new stage starts again from the limit. */
static void t_focus_reads_the_pattern_one_frame_late(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = t_game_new(false);
    r_stage st = plaza();
    set_stage(r, &st);
    float *depth = malloc((size_t)W * H * sizeof *depth), samples[R_LSPSM_FOCUS_N], want[R_LSPSM_FOCUS_N];
    T_ASSERT(depth);
    fx_lspsm_stats s;
    g_state prev, cur;
    t_state_at("plaza", 900, &prev, &cur);
    draw(r, &f, &prev, &cur);
    T_ASSERT(fx_lspsm_stats_get(r, &s));
    T_ASSERTF(s.range == R_LSPSM_LIMIT, "first frame: range %g, want the limit", s.range);
    T_ASSERT(fx_lspsm_read(r, "focus", samples));
    int w = 0, h = 0;
    T_ASSERT(r_game_read_buffer(r, "depth", depth, &w, &h));
    T_EQ(w, W);
    r_lspsm_focus_gather(depth, W, H, want);
    int sky = 0, near = 0;
    for (int k = 0; k < R_LSPSM_FOCUS_N; k++) {
        T_ASSERTF(fabsf(samples[k] - want[k]) <= 2e-7f, "sample %d: %.9g on the GPU, %.9g in the buffer", k, samples[k], want[k]);
        sky += want[k] >= 1, near += want[k] < 1;
    }
    T_ASSERT(sky > 0 && near > 0);
    /* the next frame's range is the focus update of these samples, taken
     * with this frame's camera: the focus is a frame late */
    r_mat4 vp = r_game_camera(&cur, W, H, NULL);
    r_lspsm_focus ref = {0};
    float expect = r_lspsm_focus_update(&ref, want, W, H, r_invert(vp));
    g_state next = cur;
    g_input in[2] = {0, 0};
    g_step(&next, in, NULL);
    draw(r, &f, &cur, &next);
    T_ASSERT(fx_lspsm_stats_get(r, &s));
    fprintf(stderr, "    focus: %d samples, farthest %.1f m, range %.1f m (sky in view: %d samples)\n", s.focus_used,
            s.focus_farthest, s.range, sky);
    T_EQ(s.focus_used, R_LSPSM_FOCUS_N);
    T_ASSERTF(fabsf(s.range - expect) < 1e-4f, "range %g, want %g", s.range, expect);
    /* a new look: back to the limit, the pending samples forgotten */
    set_stage(r, &st);
    draw(r, &f, &cur, &next);
    T_ASSERT(fx_lspsm_stats_get(r, &s));
    T_ASSERT(s.range == R_LSPSM_LIMIT);
    free(depth);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* Fighters' pixels: split at the midpoint between them on screen. */
static void fighter_light(const float *px, const g_state *cur, double mean[2], int count[2])
{
    r_mat4 vp = r_game_camera(cur, W, H, NULL);
    float sx[2];
    for (int i = 0; i < 2; i++) {
        float y;
        T_ASSERT(r_project(vp, r_v3(fx_to_float(cur->f[i].x), 1, 0), W, H, &sx[i], &y));
    }
    float mid = (sx[0] + sx[1]) / 2;
    mean[0] = mean[1] = 0, count[0] = count[1] = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            const float *q = px + 4 * ((size_t)y * W + x);
            if (q[3] < 0.99f)
                continue;
            int i = ((float)x < mid) == (sx[0] < mid) ? 0 : 1;
            mean[i] += luma(q), count[i]++;
        }
    for (int i = 0; i < 2; i++)
        mean[i] = count[i] ? mean[i] / count[i] : 0;
}

/* With the stage's A5 shadows off, so that this map casts the fighters.
 * No self-shadow: with no buildings and the light straight above (the
 * fighters apart, so neither is over the other), the fighters look exactly
 * as without the map.  Others' shadows: with the light low along the fight
 * line, the fighter further from it is darker, the nearer one not; and in
 * full shadow a fighter keeps its directional shading (never the flat
 * key-off look: the keep share). */
static void t_fighters_no_self_shadow_but_each_others(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = t_game_new(true);
    r_stage st = plaza();
    st.buildings = 0;
    st.shadows = false; /* with them, the screen-space mask casts the fighters and this map only the scenery */
    g_state prev, cur;
    t_state_at("dojo", FIGHTERS_APART, &prev, &cur);
    float gap = fabsf(fx_to_float(cur.f[0].x) - fx_to_float(cur.f[1].x));
    T_ASSERTF(gap > 1.2f, "the fighters stand %.2f m apart: pick another tick", gap);
    /* above */
    const float up[3] = {0, 1, 0};
    set_stage(r, &st);
    fx_lspsm_test_set(r, up, false, false);
    draw(r, &f, &prev, &cur);
    float *on = hdr(r);
    st.lspsm = false;
    set_stage(r, &st);
    draw(r, &f, &prev, &cur);
    float *off = hdr(r);
    dump("above_on", on), dump("above_off", off);
    int diff = 0, fighter_px = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        if (!(off[4 * i + 3] > 0.99f)) /* the ring gets the fighters' shadows from the map: only fighters count */
            continue;
        fighter_px++;
        for (int c = 0; c < 4; c++)
            diff += fabsf(on[4 * i + c] - off[4 * i + c]) > 1e-4f * (1 + fabsf(off[4 * i + c]));
    }
    fprintf(stderr, "    light above: %d of %d fighter pixels, %d values differ with the map\n", fighter_px, W * H, diff);
    T_ASSERT(fighter_px > 500);
    T_EQ(diff, 0);
    free(on);

    /* low along the fight line, from the side of fighter `near` */
    int near = fx_to_float(cur.f[0].x) > fx_to_float(cur.f[1].x) ? 0 : 1;
    const float side[3] = {1, 0.12f, 0};
    st.lspsm = true;
    set_stage(r, &st);
    fx_lspsm_test_set(r, side, false, false);
    draw(r, &f, &prev, &cur);
    float *lit = hdr(r);
    double m_on[2], m_off[2];
    int n_on[2], n_off[2];
    fighter_light(lit, &cur, m_on, n_on);
    fighter_light(off, &cur, m_off, n_off);
    dump("fighters_side", lit), dump("fighters_off", off);
    fprintf(stderr, "    light low from +x: nearer fighter %.3f -> %.3f, further %.3f -> %.3f (mean luminance)\n",
            m_off[near], m_on[near], m_off[1 - near], m_on[1 - near]);
    T_ASSERTF(m_on[1 - near] < 0.9 * m_off[1 - near], "the further fighter is not in the nearer one's shadow");
    T_ASSERTF(fabs(m_on[near] - m_off[near]) < 0.02 * m_off[near], "the nearer fighter changed: self-shadow?");
    free(lit), free(off);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* Light exactly parallel and anti-parallel to the view, and a sweep through
 * the fallback band: finite pictures, a uniform map at 0 deg, and no step
 * in the picture larger than the steps round it (no pop). */
static void t_parallel_and_antiparallel_light(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = t_game_new(false);
    r_stage st = plaza();
    set_stage(r, &st);
    g_state prev, cur;
    t_state_at("plaza", 600, &prev, &cur);
    r_vec3 eye;
    r_mat4 view, proj;
    r_game_camera_parts(&cur, W, H, &view, &proj, &eye);
    r_lspsm_camera cam = r_lspsm_camera_from(view, proj);
    r_vec3 v = r_norm(cam.dir), side = r_norm(r_cross(v, r_v3(0, 1, 0)));
    /* exactly parallel (light behind the camera) and anti-parallel */
    for (int s = 0; s < 2; s++) {
        float L[3] = {s ? v.x : -v.x, s ? v.y : -v.y, s ? v.z : -v.z};
        fx_lspsm_test_set(r, L, false, false);
        draw(r, &f, &prev, &cur);
        fx_lspsm_stats k;
        T_ASSERT(fx_lspsm_stats_get(r, &k));
        float *px = hdr(r);
        int bad = 0;
        for (size_t i = 0; i < (size_t)W * H * 4; i++)
            bad += !isfinite(px[i]);
        float shadow[16];
        T_ASSERT(fx_lspsm_read(r, "shadow", shadow));
        for (int i = 0; i < 16; i++)
            bad += !isfinite(shadow[i]);
        fprintf(stderr, "    %s: angle %.4f rad, warp %g\n", s ? "anti-parallel" : "parallel", k.gamma, k.warp);
        T_EQ(bad, 0);
        T_ASSERT(k.warp == 0); /* uniform shadow mapping at the end of the band */
        free(px);
    }
    /* the sweep: 0 to 60 deg off the view direction (behind the camera),
     * half-degree steps.  The warp fades in continuously (a switch from
     * uniform to warped would be a pop): it is 0 inside the band's end and
     * never jumps by more than a tenth of its full strength in a step; the
     * pictures stay finite all the way */
    enum { STEPS = 121 };
    float warp[STEPS];
    int bad = 0;
    for (int k = 0; k < STEPS; k++) {
        double a = k * 0.5 * 3.14159265358979 / 180;
        float L[3] = {(float)(-v.x * cos(a) + side.x * sin(a)), (float)(-v.y * cos(a) + side.y * sin(a)),
                      (float)(-v.z * cos(a) + side.z * sin(a))};
        fx_lspsm_test_set(r, L, false, false);
        draw(r, &f, &prev, &cur);
        fx_lspsm_stats st2;
        T_ASSERT(fx_lspsm_stats_get(r, &st2));
        warp[k] = st2.warp;
        if (k % 10 == 0) {
            float *px = hdr(r);
            for (size_t i = 0; i < (size_t)W * H * 4; i++)
                bad += !isfinite(px[i]);
            free(px);
        }
    }
    float most = 0, jump = 0;
    int at = 0, first = -1;
    for (int k = 0; k < STEPS; k++) {
        T_ASSERTF(isfinite(warp[k]) && warp[k] >= 0, "%.1f deg: warp %g", k * 0.5, warp[k]);
        most = fmaxf(most, warp[k]);
        if (first < 0 && warp[k] > 0)
            first = k;
        if (k && fabsf(warp[k] - warp[k - 1]) > jump)
            jump = fabsf(warp[k] - warp[k - 1]), at = k;
    }
    fprintf(stderr, "    sweep: warp 0 up to %.1f deg, %.3f /m at 60 deg; largest change in half a degree %.4f (at %.1f deg)\n",
            (first - 1) * 0.5, warp[STEPS - 1], jump, at * 0.5);
    T_EQ(bad, 0);
    for (int k = 0; k * 0.5 * 3.14159265358979 / 180 <= R_LSPSM_BAND_END + 1e-6; k++)
        T_ASSERTF(warp[k] == 0, "%.1f deg: warped inside the band's end", k * 0.5);
    T_ASSERTF(most > 0, "the warp never came in");
    T_ASSERTF(jump <= 0.1f * most, "a pop: the warp jumps by %.4f at %.1f deg (full strength %.4f)", jump, at * 0.5, most);
    fx_lspsm_test_set(r, NULL, false, false);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* fp16 extremes through the map and the receivers. */
static void t_fp16_extremes(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    r_game *r = t_game_new(false);
    r_stage st = plaza();
    t_stage_extremes(&st);
    st.buildings = R_STAGE_MAX_BUILDINGS;
    set_stage(r, &st);
    draw_run(r, &f, "plaza", 1500, 2);
    T_ASSERT(t_pass_ran(r, "lspsm_map") && t_pass_ran(r, "buildings"));
    float *px = hdr(r);
    int bad = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; i++)
        bad += !isfinite(px[i]) || px[i] < 0;
    T_EQ(bad, 0);
    free(px);
    r_game_destroy(r);
    t_fb_free(&f);
    plat_destroy(p);
}

/* The same ticks drawn twice by two renderers: the same picture (the focus
 * readback makes each frame depend on the one before). */
static void t_deterministic(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    float *px[2];
    for (int k = 0; k < 2; k++) {
        r_game *r = t_game_new(false);
        r_stage st = plaza();
        set_stage(r, &st);
        draw_run(r, &f, "plaza", 1200, 5);
        px[k] = hdr(r);
        r_game_destroy(r);
    }
    T_ASSERT(!memcmp(px[0], px[1], (size_t)W * H * 4 * sizeof(float)));
    free(px[0]), free(px[1]);
    t_fb_free(&f);
    plat_destroy(p);
}

/* plaza@1500 at 640x360 (the default job), RGBA8 top-down, with the knobs q. */
static uint8_t *plaza_frame_q(r_quality q, bool lspsm, float **depth, fx_lspsm_stats *stats)
{
    enum { FW = 640, FH = 360 };
    t_fb f;
    t_fb_make(&f, FW, FH);
    r_game *r = t_game_opts(&(r_game_opts){.q = q});
    r_stage st = plaza();
    st.lspsm = lspsm;
    set_stage(r, &st);
    uint8_t *px = malloc((size_t)FW * FH * 4);
    T_ASSERT(px);
    for (uint64_t t = 1498; t <= 1500; t++) {
        g_state prev, cur;
        t_state_at("plaza", t, &prev, &cur);
        t_draw_read(r, &f, &prev, &cur, FW, FH, px, false);
    }
    if (depth)
        *depth = t_read(r, "depth", 1, FW, FH);
    if (stats)
        T_ASSERT(fx_lspsm_stats_get(r, stats));
    r_game_destroy(r);
    t_fb_free(&f);
    return px;
}

/* The same with map edge `size` (0: default). */
static uint8_t *plaza_frame(int size, bool lspsm, float **depth)
{
    return plaza_frame_q((r_quality){.lspsm_size = size}, lspsm, depth, NULL);
}

static double luma8(const uint8_t *p)
{
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

/* The far shadow edges are smooth at the default 1024 map: on the ground
 * beyond 25 m, where the buildings' shadows fall (a pixel darker by 10 %+
 * than without the map in either render), the frame is close to the one
 * drawn with a 4096 map.  The warp tuned for the camera's 0.1 m near plane
 * left 2 m texels at 80 m along the view, and one bilinear tap drew them as
 * a staircase along every far edge: 30.6 dB here, where this wants 33. */
static void t_far_shadow_edges_smooth(void)
{
    enum { FW = 640, FH = 360 };
    plat *p = t_context("egl");
    float *depth = NULL;
    uint8_t *a = plaza_frame(0, true, &depth), *b = plaza_frame(4096, true, NULL), *off = plaza_frame(0, false, NULL);
    T_ASSERT(depth);
    double se = 0;
    int n = 0;
    for (int i = 0; i < FW * FH; i++) {
        /* view depth from window depth: the game camera's 0.1 .. 200 m */
        double zn = 2.0 * depth[i] - 1, dist = 2 * 0.1 * 200 / (200 + 0.1 - zn * (200 - 0.1));
        double la = luma8(a + 4 * i), lb = luma8(b + 4 * i), lo = luma8(off + 4 * i);
        if (!(depth[i] < 1) || dist < 25 || (la > 0.9 * lo && lb > 0.9 * lo))
            continue;
        se += (la - lb) * (la - lb);
        n++;
    }
    double psnr = n ? 10 * log10(255.0 * 255.0 / fmax(se / n, 1e-9)) : 0;
    fprintf(stderr, "    plaza@1500 640x360, far shadows (%d pixels): 1024 map vs 4096, PSNR %.2f dB\n", n, psnr);
    T_ASSERTF(n > FW * FH / 100, "only %d pixels of far shadow", n);
    T_ASSERTF(psnr > 33, "far shadow edges: PSNR %.2f dB against the 4096 map", psnr);
    free(a), free(b), free(off), free(depth);
    plat_destroy(p);
}

/* The static layers (r_quality.lspsm_static, the standard preset's) stand
 * in for the map on plaza: drawn once for three frames, and the frame close
 * to the one drawn with a 4096 LSPSM map, on the whole and where the
 * buildings' shadows fall (a pixel darker by 10 %+ than without the map in
 * either render), with as many shadowed pixels.  Measured: 45.6 dB
 * whole, 41.9 dB on the shadowed pixels (98,854 against 98,780); the
 * lookup moved by two texels (a bug's size) gives 30.6 and 27.5 dB and
 * 114,105 pixels. */
static void t_static_layers_stand_in_for_the_map(void)
{
    enum { FW = 640, FH = 360 };
    plat *p = t_context("egl");
    fx_lspsm_stats sa, sb;
    uint8_t *a = plaza_frame_q((r_quality){.lspsm_static = 2048}, true, NULL, &sa),
            *b = plaza_frame_q((r_quality){.lspsm_size = 4096}, true, NULL, &sb), *off = plaza_frame(0, false, NULL);
    T_ASSERT(sa.is_static && !sb.is_static);
    T_EQ(sa.static_draws, 1);
    T_ASSERTF(sa.static_texel[0] > 0.005f && sa.static_texel[0] < 0.03f && sa.static_texel[1] > 0.05f &&
                  sa.static_texel[1] < 0.3f,
              "static texels %.4f m and %.4f m", sa.static_texel[0], sa.static_texel[1]);
    double se = 0, se_shadow = 0;
    int na = 0, nb = 0, n = 0;
    for (int i = 0; i < FW * FH; i++) {
        double la = luma8(a + 4 * i), lb = luma8(b + 4 * i), lo = luma8(off + 4 * i);
        for (int c = 0; c < 3; c++)
            se += (double)(a[4 * i + c] - b[4 * i + c]) * (a[4 * i + c] - b[4 * i + c]);
        na += la < 0.9 * lo, nb += lb < 0.9 * lo;
        if (la > 0.9 * lo && lb > 0.9 * lo)
            continue;
        se_shadow += (la - lb) * (la - lb);
        n++;
    }
    double psnr = 10 * log10(255.0 * 255.0 * FW * FH * 3 / fmax(se, 1e-9)),
           psnr_shadow = n ? 10 * log10(255.0 * 255.0 * n / fmax(se_shadow, 1e-9)) : 0;
    fprintf(stderr, "    plaza@1500 640x360: static layers vs the 4096 map, %.2f dB; shadowed (%d and %d px) %.2f dB\n", psnr,
            na, nb, psnr_shadow);
    T_ASSERTF(nb > FW * FH / 20 && fabs((double)na - nb) < 0.03 * nb, "shadowed pixels: %d static, %d map", na, nb);
    T_ASSERTF(psnr > 42, "static layers vs the 4096 map: %.2f dB", psnr);
    T_ASSERTF(psnr_shadow > 30, "static layers vs the 4096 map where shadows fall: %.2f dB", psnr_shadow);
    free(a), free(b), free(off);
    plat_destroy(p);
}

/* r_quality.lspsm_size sizes the map: 512 reads back
 * as 512x512, 0 as R_LSPSM_MAP, out-of-range values clamp to 256..4096. */
static void t_map_size_knob(void)
{
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, W, H);
    const int ask[] = {512, 0, 100, 9000}, want[] = {512, R_LSPSM_MAP, 256, 4096};
    for (int k = 0; k < 4; k++) {
        r_game *r = t_game_opts(&(r_game_opts){.q = {.lspsm_size = ask[k]}});
        r_stage st = plaza();
        set_stage(r, &st);
        draw_run(r, &f, "plaza", 600, 1);
        float size[4] = {0};
        T_ASSERT(fx_lspsm_read(r, "size", size));
        T_ASSERTF(size[0] == want[k] && size[1] == want[k] && size[2] == want[k] && size[3] == want[k],
                  "lspsm_size %d: map %gx%g, %gx%g, want %d", ask[k], size[0], size[1], size[2], size[3], want[k]);
        if (k == 0) { /* the map reads back as exactly 512x512 floats, scenery in it */
            size_t n = 512 * 512;
            float *map = malloc((n + 16) * sizeof *map);
            T_ASSERT(map);
            for (size_t i = 0; i < n + 16; i++)
                map[i] = -1;
            T_ASSERT(fx_lspsm_read(r, "map", map));
            size_t scenery = 0, untouched = 0;
            for (size_t i = 0; i < n; i++)
                scenery += map[i] >= 0 && map[i] < 1;
            for (size_t i = n; i < n + 16; i++)
                untouched += map[i] == -1;
            T_EQ(untouched, 16);
            T_ASSERTF(scenery > n / 40, "%zu scenery texels", scenery);
            free(map);
        }
        r_game_destroy(r);
    }
    t_fb_free(&f);
    plat_destroy(p);
}

T_MAIN({"buildings_cast_shadows", t_buildings_cast_shadows}, {"static_layers_stand_in_for_the_map", t_static_layers_stand_in_for_the_map},
       {"static_layers_cast_the_fighters_on_buildings", t_static_layers_cast_the_fighters_on_buildings}, {"culling_keeps_the_map", t_culling_keeps_the_map},
       {"focus_reads_the_pattern_one_frame_late", t_focus_reads_the_pattern_one_frame_late},
       {"fighters_no_self_shadow_but_each_others", t_fighters_no_self_shadow_but_each_others},
       {"fighters_leave_the_map_to_their_shadows", t_fighters_leave_the_map_to_their_shadows},
       {"parallel_and_antiparallel_light", t_parallel_and_antiparallel_light}, {"fp16_extremes", t_fp16_extremes},
       {"deterministic", t_deterministic}, {"far_shadow_edges_smooth", t_far_shadow_edges_smooth},
       {"map_size_knob", t_map_size_knob})
