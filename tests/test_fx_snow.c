/* runtime/fx/fx_snow: the snow effect (docs/effects.md, "Snow") — its
 * procedural textures, the displacement map's footprints (lowered where a
 * bone dips in, never below the trampled minimum, restored by a reset),
 * that it shows, and that it keeps the HDR buffer finite. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/game/g_ai.h"
#include "../runtime/game/g_game.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/fx/fx_snow_tex.h"
#include "../runtime/render/r_fx.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_graph.h"
#include "../runtime/render/r_stage.h"
#include "t.h"
#include "t_render.h"

enum { N = R_SNOW_MAP, W = 160, H = 90 };

static int snowfield(void)
{
    for (int i = 0; i < G_STAGES; i++)
        if (!strcmp(g_stages[i].name, "snowfield"))
            return i;
    t_fail(__FILE__, __LINE__, "no game stage snowfield");
}

/* ---- the textures (no GL) ---- */

static void t_height_textures(void)
{
    static float un[N * N], tr[N * N], again[N * N];
    const float halves[] = {4.0f, 4.5f, 3.5f};
    for (size_t k = 0; k < sizeof halves / sizeof halves[0]; k++) {
        fx_snow_tex_untouched(un, N, halves[k]);
        fx_snow_tex_trampled(tr, N, halves[k]);
        float umin = 1, umax = 0, tmin = 1, tmax = 0, gap = 1;
        double sum = 0, sum2 = 0;
        for (int i = 0; i < N * N; i++) {
            T_ASSERTF(isfinite(un[i]) && isfinite(tr[i]), "texel %d", i);
            umin = fminf(umin, un[i]), umax = fmaxf(umax, un[i]);
            tmin = fminf(tmin, tr[i]), tmax = fmaxf(tmax, tr[i]);
            gap = fminf(gap, un[i] - tr[i]);
            sum += tr[i], sum2 += (double)tr[i] * tr[i];
        }
        /* each spans its range exactly, trampled below untouched everywhere */
        T_ASSERTF(umin == R_SNOW_UNTOUCHED_LO && umax == R_SNOW_UNTOUCHED_HI, "untouched %g..%g", umin, umax);
        T_ASSERTF(tmin == R_SNOW_TRAMPLED_LO && tmax == R_SNOW_TRAMPLED_HI, "trampled %g..%g", tmin, tmax);
        T_ASSERTF(gap >= R_SNOW_UNTOUCHED_LO - R_SNOW_TRAMPLED_HI - 1e-6f, "untouched - trampled down to %g", gap);
        /* the trampled floor is uneven: a spread, not two outliers */
        double mean = sum / (N * N), sd = sqrt(sum2 / (N * N) - mean * mean);
        T_ASSERTF(sd > 0.002, "trampled spread %g m", sd);
        /* neighbours are close: drifts, not noise (a 3 cm texel) */
        float step = 0;
        for (int j = 0; j < N; j++)
            for (int i = 0; i + 1 < N; i++)
                step = fmaxf(step, fabsf(un[j * N + i + 1] - un[j * N + i]));
        T_ASSERTF(step < 0.01f, "untouched jumps %g m between neighbours", step);
        /* deterministic */
        fx_snow_tex_untouched(again, N, halves[k]);
        T_ASSERT(!memcmp(un, again, sizeof un));
    }
}

static void t_color_textures(void)
{
    enum { S = R_SNOW_TEX };
    static uint8_t c[S * S * 2], nm[S * S * 4];
    fx_snow_tex_colors(c, S);
    fx_snow_tex_detail_normals(nm, S);
    double fresh = 0, trampled = 0;
    int lo = 255, hi = 0;
    for (int i = 0; i < S * S; i++) {
        const uint8_t *p = c + 2 * i;
        T_ASSERTF(p[0] >= 242, "fresh brightness %d at %d", p[0], i); /* 0.95..1 */
        T_ASSERTF(p[1] >= 160, "trampled brightness %d at %d", p[1], i);
        lo = p[1] < lo ? p[1] : lo, hi = p[1] > hi ? p[1] : hi;
        fresh += p[0], trampled += p[1];
        /* unit tangent-space normals facing out */
        float n[3], l = 0;
        for (int k = 0; k < 3; k++)
            n[k] = nm[4 * i + k] / 255.0f * 2 - 1, l += n[k] * n[k];
        T_ASSERTF(fabsf(sqrtf(l) - 1) < 0.02f && n[2] > 0.5f, "normal %d: (%g %g %g)", i, n[0], n[1], n[2]);
    }
    /* trampled snow is blotchy and darker than fresh on average */
    T_ASSERTF(hi - lo > 40, "trampled brightness %d..%d", lo, hi);
    T_ASSERTF(trampled < fresh * 0.97, "trampled %g, fresh %g", trampled / (S * S), fresh / (S * S));
}

/* ---- GL ---- */

static r_game *game_new(void)
{
    rs_err e = {0};
    r_game *r = t_game_new(false);
    T_ASSERTF(r_game_prepare(r, snowfield(), &e), "%s", e.msg);
    T_ASSERTF(r_game_stage(r)->snow, "stages/snowfield.stage has no snow");
    return r;
}

typedef struct maps {
    float map[N * N], un[N * N], tr[N * N];
} maps;

static void read_maps(r_game *r, maps *m)
{
    T_ASSERT(fx_snow_read(r, "map", m->map));
    T_ASSERT(fx_snow_read(r, "untouched", m->un));
    T_ASSERT(fx_snow_read(r, "trampled", m->tr));
    T_EQ(gl.GetError(), GL_NO_ERROR);
}

/* The map texel under world (x, z) on the snowfield ring. */
static int texel(float x, float z)
{
    float half = fx_to_float(g_stages[snowfield()].ring_half);
    int i = (int)floorf((x + half) / (2 * half) * N), j = (int)floorf((z + half) / (2 * half) * N);
    T_ASSERTF(i >= 0 && i < N && j >= 0 && j < N, "(%g, %g) is off the ring", x, z);
    return j * N + i;
}

/* World x (or z) of the centre of map column (or row) i. */
static float centre(int i)
{
    float half = fx_to_float(g_stages[snowfield()].ring_half);
    return -half + ((float)i + 0.5f) * 2 * half / N;
}

/* Every texel within the bounds the trampled and untouched textures set. */
static void check_bounds(const maps *m, const char *what)
{
    for (int i = 0; i < N * N; i++)
        T_ASSERTF(m->map[i] >= m->tr[i] && m->map[i] <= m->un[i], "%s: texel %d: %g outside %g..%g", what, i, m->map[i],
                  m->tr[i], m->un[i]);
}

/* A bone lying along x at height y (its axis), radius r. */
static r_fx_capsule bone_at(float x, float z, float y, float r)
{
    return (r_fx_capsule){{x - 0.08f, y, z}, {x + 0.08f, y, z}, r};
}

static void t_contacts_lower_the_map(void)
{
    plat *p = t_context("egl");
    r_game *r = game_new();
    t_fb f;
    t_fb_make(&f, W, H);
    g_state st;
    g_init(&st, snowfield(), 1); /* both fighters standing, feet on the ring */
    t_draw(r, &f, &st, &st, W, H);
    T_ASSERT(t_pass_ran(r, "snow_map") && t_pass_ran(r, "snow_light") && t_pass_ran(r, "snow_surface"));
    static maps m;
    read_maps(r, &m);
    check_bounds(&m, "first frame");
    /* under each foot, the snow is trampled to the minimum (the foot
     * reaches the boards); far from both fighters it is untouched */
    for (int i = 0; i < 2; i++) {
        g_capsule c[G_BONES];
        g_fighter_capsules(&st, i, c);
        const int feet[2] = {G_L_FOOT, G_R_FOOT};
        for (int k = 0; k < 2; k++) {
            const g_capsule *b = &c[feet[k]];
            float x = fx_to_float(b->ax + b->bx) / 2, z = fx_to_float(b->z) * (float)st.f[i].facing;
            float y = fminf(fx_to_float(b->ay), fx_to_float(b->by)) - fx_to_float(b->r);
            T_ASSERTF(y < R_SNOW_TRAMPLED_LO, "fighter %d's foot %d stands at %g m", i, k, y);
            int t = texel(x, z);
            T_ASSERTF(m.map[t] == m.tr[t], "fighter %d foot %d at (%g, %g): map %g, trampled %g, untouched %g", i, k, x, z,
                      m.map[t], m.tr[t], m.un[t]);
        }
    }
    int far[] = {texel(-3.5f, -3.5f), texel(3.5f, 3.5f), texel(0, 2.5f), texel(0, -2.5f), texel(-3.9f, 0)};
    for (size_t k = 0; k < sizeof far / sizeof far[0]; k++)
        T_ASSERTF(m.map[far[k]] == m.un[far[k]], "far texel %d: %g, untouched %g", far[k], m.map[far[k]], m.un[far[k]]);

    /* the deeper the contact, the deeper the print: bones whose undersides
     * sit at 0.09 and 0.06 m press the snow down to exactly there */
    const float under[2] = {0.09f, 0.06f}, px[2] = {centre(64), centre(192)}, pz = centre(176);
    for (int k = 0; k < 2; k++) {
        r_fx_capsule b = bone_at(px[k], pz, under[k] + 0.05f, 0.05f);
        fx_snow_stamp(r, &b, 1);
    }
    read_maps(r, &m);
    for (int k = 0; k < 2; k++) {
        int t = texel(px[k], pz);
        T_ASSERTF(fabsf(m.map[t] - under[k]) < 1e-5f, "print %d: %g, want %g", k, m.map[t], under[k]);
        /* beside the bone's axis the print is shallower (its round underside) */
        int side = texel(px[k], centre(177));
        T_ASSERTF(m.map[side] > m.map[t] + 0.005f && m.map[side] < m.un[side], "print %d beside: %g", k, m.map[side]);
    }
    /* a bone above the snow leaves no print */
    r_fx_capsule above = bone_at(0, -1.5f, R_SNOW_UNTOUCHED_HI + 0.06f, 0.05f);
    fx_snow_stamp(r, &above, 1);
    read_maps(r, &m);
    T_ASSERT(m.map[texel(0, -1.5f)] == m.un[texel(0, -1.5f)]);
    check_bounds(&m, "after the prints");
    t_fb_free(&f);
    r_game_destroy(r);
    plat_destroy(p);
}

static void t_never_below_trampled_and_reset(void)
{
    plat *p = t_context("egl");
    r_game *r = game_new();
    t_fb f;
    t_fb_make(&f, W, H);
    g_state st;
    g_init(&st, snowfield(), 1);
    t_draw(r, &f, &st, &st, W, H);
    static maps before, m;
    read_maps(r, &before);
    /* thousands of stamps of a bone sunk deep under the boards, same place */
    r_fx_capsule deep[4];
    for (int k = 0; k < 4; k++)
        deep[k] = bone_at(-2.5f + 0.01f * (float)k, 2.0f, 0.0f, 0.12f);
    for (int n = 0; n < 3000; n++)
        fx_snow_stamp(r, deep, 4);
    read_maps(r, &m);
    check_bounds(&m, "3000 stamps");
    int t = texel(-2.5f, 2.0f), lowered = 0, moved = 0;
    T_ASSERTF(m.map[t] == m.tr[t], "under the bone: %g, trampled %g", m.map[t], m.tr[t]);
    for (int i = 0; i < N * N; i++) {
        lowered += m.map[i] == m.tr[i] && before.map[i] != m.tr[i];
        moved += m.map[i] != before.map[i];
    }
    /* the print has the bone's size (a 0.4 x 0.24 m box at most: ~100 texels),
     * and nothing else moved */
    T_ASSERTF(lowered > 40 && moved < 140 && moved == lowered, "lowered %d, changed %d texels", lowered, moved);
    /* the print is uneven: the trampled minimum is not flat */
    float lo = 1, hi = 0;
    for (int i = 0; i < N * N; i++)
        if (m.map[i] != before.map[i])
            lo = fminf(lo, m.map[i]), hi = fmaxf(hi, m.map[i]);
    T_ASSERTF(hi - lo > 0.002f, "a flat print: %g..%g", lo, hi);

    /* the same tick drawn again: no step, the map is kept */
    t_draw(r, &f, &st, &st, W, H);
    T_ASSERT(!t_pass_ran(r, "snow_map") && t_pass_ran(r, "snow_surface"));
    read_maps(r, &m);
    T_ASSERT(m.map[t] == m.tr[t]);
    /* a seek (more than R_FX_MAX_GAP ticks) restarts from untouched snow */
    g_state later = st;
    later.tick += R_FX_MAX_GAP + 5;
    t_draw(r, &f, &later, &later, W, H);
    T_ASSERT(t_pass_ran(r, "snow_map"));
    static maps after;
    read_maps(r, &after);
    T_ASSERTF(after.map[t] == after.un[t], "after the reset: %g, untouched %g", after.map[t], after.un[t]);
    T_ASSERT(!memcmp(after.map, before.map, sizeof after.map)); /* the fighters stand where they stood */
    t_fb_free(&f);
    r_game_destroy(r);
    plat_destroy(p);
}

/* A match played by two CPU fighters: prints wherever a foot went down,
 * the snow away from the fight line untouched, and the same prints whether
 * every tick is drawn (60 fps) or every other one (30 fps). */
static void t_footprints_where_fighters_walked(void)
{
    plat *p = t_context("egl");
    r_game *every = game_new(), *other = game_new();
    /* lean frames: the prints do not need shadows or bloom */
    r_stage lean = *r_game_stage(every);
    lean.shadows = false, lean.bloom = 0;
    rs_err e = {0};
    T_ASSERTF(r_game_set_stage(every, &lean, &e) && r_game_set_stage(other, &lean, &e), "%s", e.msg);
    t_fb f;
    t_fb_make(&f, W, H);
    g_state prev, cur;
    g_init(&cur, snowfield(), 7);
    g_ai ai[2];
    g_ai_init(&ai[0], 0, 2, 7);
    g_ai_init(&ai[1], 1, 2, 8);
    enum { TICKS = 360 };
    static float foot_x[TICKS][4], foot_z[TICKS][4], foot_y[TICKS][4];
    for (int t = 0; t < TICKS; t++) {
        prev = cur;
        g_input in[2] = {g_ai_input(&ai[0], &cur), g_ai_input(&ai[1], &cur)};
        g_step(&cur, in, NULL);
        for (int i = 0; i < 2; i++) {
            g_capsule c[G_BONES];
            g_fighter_capsules(&cur, i, c);
            for (int k = 0; k < 2; k++) {
                const g_capsule *b = &c[k ? G_R_FOOT : G_L_FOOT];
                foot_x[t][2 * i + k] = fx_to_float(b->ax);
                foot_z[t][2 * i + k] = fx_to_float(b->z) * (float)cur.f[i].facing;
                foot_y[t][2 * i + k] = fx_to_float(b->ay) - fx_to_float(b->r);
            }
        }
        t_draw(every, &f, &prev, &cur, W, H);
        if (t % 2 == 1)
            t_draw(other, &f, &prev, &cur, W, H);
    }
    static maps m, m60;
    read_maps(every, &m60);
    read_maps(other, &m);
    check_bounds(&m, "after the match");
    int differ = 0;
    for (int i = 0; i < N * N; i++)
        differ += m.map[i] != m60.map[i];
    T_ASSERTF(!differ, "%d texels differ between 60 and 30 frames a second", differ);
    /* every place a heel stood on the boards is a print */
    int checked = 0, printed = 0;
    for (int t = 0; t < TICKS; t++)
        for (int k = 0; k < 4; k++)
            if (foot_y[t][k] < 0.005f && fabsf(foot_x[t][k]) < 3.9f) {
                int i = texel(foot_x[t][k], foot_z[t][k]);
                checked++;
                printed += m.map[i] < m.un[i] - 0.04f;
            }
    T_ASSERTF(checked > 100, "only %d heel positions on the ring", checked);
    T_ASSERTF(printed == checked, "%d of %d heel positions left a print", printed, checked);
    /* the fighters stay on the fight line (|z| < 0.5): beyond it the snow is untouched */
    int lowered = 0;
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) {
            if (fabsf(centre(j)) > 0.5f)
                T_ASSERTF(m.map[j * N + i] == m.un[j * N + i], "texel (%d, %d) at z %g lowered", i, j, centre(j));
            else
                lowered += m.map[j * N + i] < m.un[j * N + i];
        }
    T_ASSERTF(lowered > 200, "only %d texels pressed down", lowered);
    t_fb_free(&f);
    r_game_destroy(every);
    r_game_destroy(other);
    plat_destroy(p);
}

static void read_hdr(r_game *r, float *px)
{
    int w, h;
    T_ASSERT(r_game_read_buffer(r, "hdr", px, &w, &h) && w == W && h == H);
}

/* The snow shows over the ring and nowhere else; a stage without it runs
 * none of its passes. */
static void t_snow_is_visible(void)
{
    plat *p = t_context("egl");
    r_game *r = game_new();
    t_fb f;
    t_fb_make(&f, W, H);
    g_state st;
    g_init(&st, snowfield(), 1);
    static float with[W * H * 4], without[W * H * 4];
    t_draw(r, &f, &st, &st, W, H);
    read_hdr(r, with);
    const char *passes[] = {"snow_map", "snow_light", "snow_light_blur", "snow_surface"};
    r_stage bare = *r_game_stage(r);
    bare.snow = false;
    rs_err e = {0};
    T_ASSERTF(r_game_set_stage(r, &bare, &e), "%s", e.msg);
    t_draw(r, &f, &st, &st, W, H);
    for (size_t k = 0; k < sizeof passes / sizeof passes[0]; k++)
        T_ASSERTF(!t_pass_ran(r, passes[k]), "'%s' ran without snow", passes[k]);
    read_hdr(r, without);
    /* the ring top fills the bottom rows at the start of a round: snow
     * there is brighter than the boards (albedo 0.9 against 0.4) */
    int brighter = 0, n = 0;
    for (int y = 0; y < H / 8; y++)
        for (int x = 0; x < W; x++, n++) {
            const float *a = with + 4 * (y * W + x), *b = without + 4 * (y * W + x);
            brighter += a[1] > b[1] * 1.5f;
        }
    T_ASSERTF(brighter > n * 9 / 10, "%d of %d ring pixels brighter with snow", brighter, n);
    /* the sky above is the same */
    int same = 0;
    n = 0;
    for (int y = H - H / 8; y < H; y++)
        for (int x = 0; x < W; x++, n++) {
            const float *a = with + 4 * (y * W + x), *b = without + 4 * (y * W + x);
            same += fabsf(a[0] - b[0]) < 1e-3f && fabsf(a[1] - b[1]) < 1e-3f && fabsf(a[2] - b[2]) < 1e-3f;
        }
    T_ASSERTF(same == n, "%d of %d sky pixels changed", n - same, n);
    t_fb_free(&f);
    r_game_destroy(r);
    plat_destroy(p);
}

/* No NaN or Inf leaves the snow's passes whatever the stage's light. */
static void t_fp16_extremes(void)
{
    plat *p = t_context("egl");
    r_game *r = game_new();
    t_fb f;
    t_fb_make(&f, W, H);
    g_state st;
    g_init(&st, snowfield(), 1);
    const r_stage base = *r_game_stage(r);
    static float hdr[W * H * 4];
    const int nl = fx_snow_light_size(r);
    float *light = malloc((size_t)nl * nl * 4 * sizeof *light);
    T_ASSERT(light);
    const struct {
        const char *what;
        float sun, sky, exposure;
        bool blue; /* a pure blue sun and key light: the specular tint's worst case */
    } cases[] = {
        {"sun 65504", 65504, -1, 1, false},
        {"blue sun 65504", 65504, -1, 1, true},
        {"white world 65504", 65504, 65504, 1, false},
        {"blue world 65504", 65504, 65504, 1, true},
        {"black world", 0, 0, 1, false},
        {"exposure 1000", -1, -1, 1000, false},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        r_stage st2 = base;
        if (cases[k].sun >= 0)
            st2.sun_intensity = cases[k].sun;
        if (cases[k].sky >= 0) {
            for (int c = 0; c < 3; c++)
                st2.sky_zenith[c] = st2.sky_horizon[c] = st2.ground[c] = cases[k].sky;
            st2.key.intensity = st2.counter.intensity = cases[k].sky;
        }
        st2.exposure = cases[k].exposure;
        if (cases[k].blue)
            for (int c = 0; c < 3; c++)
                st2.sun_color[c] = st2.key.color[c] = c == 2 ? 1.0f : 0.0f;
        rs_err e = {0};
        T_ASSERTF(r_game_set_stage(r, &st2, &e), "%s: %s", cases[k].what, e.msg);
        t_draw(r, &f, &st, &st, W, H);
        read_hdr(r, hdr);
        for (int i = 0; i < W * H * 4; i++)
            T_ASSERTF(isfinite(hdr[i]) && fabsf(hdr[i]) <= R_HALF_MAX, "%s: hdr[%d] = %g", cases[k].what, i, hdr[i]);
        T_ASSERT(fx_snow_read(r, "light", light));
        for (int i = 0; i < nl * nl * 4; i++)
            T_ASSERTF(isfinite(light[i]) && light[i] >= 0 && light[i] <= R_HALF_MAX, "%s: light[%d] = %g", cases[k].what, i,
                      light[i]);
    }
    free(light);
    t_fb_free(&f);
    r_game_destroy(r);
    plat_destroy(p);
}

/* The surface's two grids (fx_snow.c, snow_grid_lod: the coarse one
 * below 540 rows drawn, the fine one the options ask for) draw the same
 * snow with prints, within what a grid of every 4th column instead of
 * every 2nd moves: 53 dB between them at 640x360 over 120 frames of the
 * demo; here one frame with prints at 320x180, 46.7 dB. */
static void t_grids_agree(void)
{
    enum { GW = 320, GH = 180 };
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, GW, GH);
    g_state prev, cur;
    t_state_at("snowfield", 1260, &prev, &cur);
    static uint8_t px[2][GW * GH * 4];
    int tris[2];
    for (int fine = 0; fine < 2; fine++) {
        r_game *r = t_game_opts(&(r_game_opts){.fine_mesh = fine == 1});
        rs_err e = {0};
        T_ASSERTF(r_game_prepare(r, snowfield(), &e), "%s", e.msg);
        t_draw_read(r, &f, &prev, &cur, GW, GH, px[fine], false);
        T_ASSERT(t_pass_ran(r, "snow_surface"));
        tris[fine] = fx_snow_grid_drawn(r);
        r_game_destroy(r);
    }
    double se = 0;
    int differ = 0;
    for (int i = 0; i < GW * GH * 4; i++)
        if (i % 4 != 3) {
            double d = (double)px[0][i] - px[1][i];
            se += d * d, differ += d != 0;
        }
    double psnr = 10 * log10(255.0 * 255.0 / fmax(se / (GW * GH * 3), 1e-12));
    fprintf(stderr, "    coarse grid (%d triangles) against fine (%d): %.1f dB, %d of %d bytes differ\n", tris[0], tris[1],
            psnr, differ, GW * GH * 3);
    T_ASSERTF(tris[0] > 0 && tris[0] < tris[1] * 6 / 10, "%d triangles at 180 rows against %d with the fine mesh", tris[0],
              tris[1]);
    T_ASSERTF(psnr > 42, "the coarse grid's frame is %.1f dB from the fine one's", psnr);
    t_fb_free(&f);
    plat_destroy(p);
}

/* The scene leaves the ring's top face to the snow (fx_snow.c,
 * snow_draw_ring): the snow covers it whole (no height below the top:
 * snow_height clamps at 0), at either grid and two ticks, so the frame is
 * the same byte for byte as with the top drawn under the snow. */
static void t_ring_top_left_to_the_snow(void)
{
    enum { GW = 320, GH = 180 };
    plat *p = t_context("egl");
    t_fb f;
    t_fb_make(&f, GW, GH);
    static uint8_t px[2][GW * GH * 4];
    const uint64_t ticks[] = {300, 2600};
    for (int fine = 0; fine < 2; fine++)
        for (int t = 0; t < 2; t++) {
            g_state prev, cur;
            t_state_at("snowfield", ticks[t], &prev, &cur);
            r_game *r = t_game_opts(&(r_game_opts){.fine_mesh = fine == 1});
            rs_err e = {0};
            T_ASSERTF(r_game_prepare(r, snowfield(), &e), "%s", e.msg);
            for (int keep = 0; keep < 2; keep++) {
                fx_snow_test_keep_ring_top(r, keep == 1);
                t_draw_read(r, &f, &prev, &cur, GW, GH, px[keep], false);
                T_ASSERT(t_pass_ran(r, "snow_surface"));
            }
            int differ = 0;
            for (int i = 0; i < GW * GH * 4; i++)
                differ += px[0][i] != px[1][i];
            fprintf(stderr, "    %s grid, tick %llu: %d bytes differ without the ring's top\n", fine ? "fine" : "coarse",
                    (unsigned long long)ticks[t], differ);
            T_EQ(differ, 0);
            r_game_destroy(r);
        }
    t_fb_free(&f);
    plat_destroy(p);
}

T_MAIN({"height_textures", t_height_textures}, {"color_textures", t_color_textures},
       {"contacts_lower_the_map", t_contacts_lower_the_map}, {"never_below_trampled_and_reset", t_never_below_trampled_and_reset},
       {"footprints_where_fighters_walked", t_footprints_where_fighters_walked}, {"snow_is_visible", t_snow_is_visible},
       {"fp16_extremes", t_fp16_extremes}, {"grids_agree", t_grids_agree},
       {"ring_top_left_to_the_snow", t_ring_top_left_to_the_snow})
